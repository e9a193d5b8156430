//! Sheets the terms' unit tests share.

use super::{EnergyTerm, Gravity, Model, SelfContact, SpringFamily, Springs};
use nalgebra::Vector3;

/// A grid of `n` × `n` vertices, spacing h, split along one diagonal or alternating ones.
pub fn grid(n: usize, h: f64, alternate: bool) -> (Vec<[f64; 2]>, Vec<[usize; 3]>) {
    let rest = (0..n * n)
        .map(|k| [(k % n) as f64 * h, (k / n) as f64 * h])
        .collect();
    let mut tris = Vec::new();
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let (a, b, c, d) = (
                j * n + i,
                j * n + i + 1,
                (j + 1) * n + i + 1,
                (j + 1) * n + i,
            );
            if alternate && (i + j) % 2 == 1 {
                tris.extend([[a, b, d], [b, c, d]]);
            } else {
                tris.extend([[a, b, c], [a, c, d]]);
            }
        }
    }
    (rest, tris)
}

/// A 4 × 4 sheet held by structural springs lying `gap` above a fixed 4 × 4 sheet (spacing
/// 1 cm, the upper one shifted by a third of a cell), self-contact with thickness 0.5 mm and band
/// 1 mm, under gravity, its particles held horizontally (they settle straight down): the model and
/// its positions.
pub fn two_layers(gap: f64) -> (Model, Vec<Vector3<f64>>) {
    let (n, h) = (4usize, 0.01);
    let mut x = Vec::new();
    let mut tris = Vec::new();
    let mut springs = Vec::new();
    for layer in 0..2usize {
        let (shift, z) = (layer as f64 * h / 3.0, layer as f64 * gap);
        let base = layer * n * n;
        for j in 0..n {
            for i in 0..n {
                x.push(Vector3::new(i as f64 * h + shift, j as f64 * h + shift, z));
                let p = base + j * n + i;
                if i + 1 < n && j + 1 < n {
                    let q = p as u32;
                    let m = n as u32;
                    tris.extend([[q, q + 1, q + m + 1], [q, q + m + 1, q + m]]);
                }
                if layer == 1 && i + 1 < n {
                    springs.push((p, p + 1));
                }
                if layer == 1 && j + 1 < n {
                    springs.push((p, p + n));
                }
            }
        }
    }
    let masses = vec![1e-4; x.len()];
    let contact = SelfContact::new(tris, &x, 5e-4, 1e-3, 1e-4 * 9.81);
    let rest = vec![h; springs.len()];
    let k = vec![50.0; springs.len()];
    let terms: Vec<Box<dyn EnergyTerm>> = vec![
        Box::new(Springs::new(SpringFamily::Structural, springs, rest, k)),
        Box::new(Gravity::new(masses.clone(), 9.81)),
        Box::new(contact),
    ];
    let model = Model {
        fixed: (0..x.len()).map(|p| p < n * n).collect(),
        masses,
        held_components: (0..x.len())
            .map(|p| [p >= n * n, p >= n * n, false])
            .collect(),
        n_grid: x.len(),
        terms,
        gravity_m_per_s2: 9.81,
        damping_Ns_per_m: 0.0,
        elongation_rate: None,
        constant_hessian: Default::default(),
    };
    (model, x)
}
