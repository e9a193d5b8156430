//! What hinge bending charges for each constant curvature on a triangulated grid (issue 49): the
//! energy of `orthotropic_hinge_bending` (B = 1 N·m both ways) on a 60 × 60 grid of 5 mm cells, one
//! diagonal per cell or alternating diagonals, bent to z = ½ xᵀ κ x for a cylinder along x, along y,
//! a twist and a cylinder along the diagonal, against the plate's ½ B (κ₁₁² + κ₂₂² + 2 κ₁₂²) over the
//! area its hinges hold (Poisson coupling 0). A ratio of 1 is the plate. A second table splits each
//! ratio between the hinges on the grid's lines and those on the cells' diagonals (the same
//! cotangent weights, recomputed here): the weights that would make the hinges a plate.
//!
//! cargo run --release -p drapelab-core --example hinge_tensor

use drapelab_core::physics::{EnergyTerm, orthotropic_hinge_bending};
use nalgebra::Vector3;
use std::collections::BTreeMap;

/// Constant curvatures (κ₁₁, κ₂₂, κ₁₂): cylinders along x and y, a twist, a cylinder along the diagonal.
fn modes(k: f64) -> [(f64, f64, f64); 4] {
    [
        (k, 0.0, 0.0),
        (0.0, k, 0.0),
        (0.0, 0.0, k),
        (0.5 * k, 0.5 * k, 0.5 * k),
    ]
}

/// The hinges' energy per mode split between edges on the grid's lines and on the diagonals.
fn split(rest: &[[f64; 2]], tris: &[[usize; 3]], k: f64) -> [[f64; 2]; 4] {
    let p3 = |v: usize| Vector3::new(rest[v][0], rest[v][1], 0.0);
    let cot = |a: Vector3<f64>, b: Vector3<f64>| a.dot(&b) / a.cross(&b).norm();
    let mut sides: BTreeMap<(usize, usize), Vec<(usize, f64)>> = BTreeMap::new();
    for t in tris {
        let a = 0.5 * (p3(t[1]) - p3(t[0])).cross(&(p3(t[2]) - p3(t[0]))).norm();
        for q in 0..3 {
            let (i, j, o) = (t[q], t[(q + 1) % 3], t[(q + 2) % 3]);
            sides.entry((i.min(j), i.max(j))).or_default().push((o, a));
        }
    }
    let mut e = [[0.0; 2]; 4];
    for (&(i0, i1), opp) in &sides {
        let [(i2, a0), (i3, a1)] = opp.as_slice() else {
            continue;
        };
        let (x0, x1, x2, x3) = (p3(i0), p3(i1), p3(*i2), p3(*i3));
        let (e0, e1, e2, e3, e4) = (x1 - x0, x2 - x0, x3 - x0, x2 - x1, x3 - x1);
        let (c01, c02, c03, c04) = (cot(e0, e1), cot(e0, e2), cot(-e0, e3), cot(-e0, e4));
        let kk = [c03 + c04, c01 + c02, -c01 - c03, -c02 - c04];
        let diagonal = e0.x.abs() > 1e-12 && e0.y.abs() > 1e-12;
        for (m, &(k11, k22, k12)) in modes(k).iter().enumerate() {
            let z = |v: usize| {
                let (u, w) = (rest[v][0] - 0.15, rest[v][1] - 0.15);
                0.5 * (k11 * u * u + k22 * w * w) + k12 * u * w
            };
            let u = kk[0] * z(i0) + kk[1] * z(i1) + kk[2] * z(*i2) + kk[3] * z(*i3);
            e[m][diagonal as usize] += 0.5 * u * u / (a0 + a1);
        }
    }
    e
}

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
        let ratios: Vec<String> = modes(k)
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
        let parts = split(&rest, &tris, k);
        let plate = |(a, b, c): (f64, f64, f64)| 0.5 * (a * a + b * b + 2.0 * c * c) * area;
        let shares: Vec<String> = modes(k)
            .iter()
            .zip(&parts)
            .map(|(&m, e)| format!("{:.3} + {:.3}", e[0] / plate(m), e[1] / plate(m)))
            .collect();
        println!("| … lines + diagonals | {} |", shares.join(" | "));
    }
}
