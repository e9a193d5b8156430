//! What hinge bending charges for each constant curvature on a triangulated grid (issue 49): the
//! energy of `orthotropic_hinge_bending` (B = 1 N·m both ways) on a 60 × 60 grid of 5 mm cells, one
//! diagonal per cell or alternating diagonals, bent to z = ½ xᵀ κ x for a cylinder along x, along y,
//! a twist and a cylinder along the diagonal, against the plate's ½ B (κ₁₁² + κ₂₂² + 2 κ₁₂²) over the
//! area its hinges hold (Poisson coupling 0, as the grid sheet's bending). A ratio of 1 is the plate.
//!
//! cargo run --release -p drapelab-core --example hinge_tensor

use drapelab_core::physics::{EnergyTerm, orthotropic_hinge_bending};
use nalgebra::Vector3;

fn main() {
    let (n, h, k) = (60usize, 0.005, 0.5);
    let rest: Vec<[f64; 2]> = (0..(n + 1) * (n + 1))
        .map(|v| [(v % (n + 1)) as f64 * h, (v / (n + 1)) as f64 * h])
        .collect();
    // Every hinge holds a third of its two triangles; the hem's edges have none.
    let area = (n as f64 * h).powi(2) - 4.0 * n as f64 * h * h / 6.0;
    println!("| triangulation | cylinder along x | along y | twist | along the diagonal |");
    println!("|---|---:|---:|---:|---:|");
    for alternate in [false, true] {
        let mut tris = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let (a, b) = (j * (n + 1) + i, j * (n + 1) + i + 1);
                let (c, d) = (b + n + 1, a + n + 1);
                match alternate && (i + j) % 2 == 1 {
                    true => tris.extend([[a, b, d], [b, c, d]]),
                    false => tris.extend([[a, b, c], [a, c, d]]),
                }
            }
        }
        let term = orthotropic_hinge_bending(&rest, &tris, [1.0, 1.0], 0.0);
        let ratios: Vec<String> = [
            (k, 0.0, 0.0),
            (0.0, k, 0.0),
            (0.0, 0.0, k),
            (0.5 * k, 0.5 * k, 0.5 * k),
        ]
        .iter()
        .map(|&(k11, k22, k12)| {
            let x: Vec<Vector3<f64>> = rest
                .iter()
                .map(|p| {
                    let (u, v) = (p[0] - 0.15, p[1] - 0.15);
                    let z = 0.5 * (k11 * u * u + k22 * v * v) + k12 * u * v;
                    Vector3::new(p[0], p[1], z)
                })
                .collect();
            let plate = 0.5 * (k11 * k11 + k22 * k22 + 2.0 * k12 * k12) * area;
            format!("{:.3}", term.energy(&x) / plate)
        })
        .collect();
        let name = if alternate {
            "alternating diagonals"
        } else {
            "one diagonal"
        };
        println!("| {name} | {} |", ratios.join(" | "));
    }
}
