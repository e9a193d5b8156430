//! From a scene to a [`Model`]: the springs the topology asks for, or the continuum terms, the
//! lumped masses, pins and clamps. Terms a scene does not need are never built.

use super::{Grid, tributary_lengths};
use crate::material::Rigidities;
use crate::physics::{CellShear, EnergyTerm, Gravity, LinearBending, Model, SpringFamily, Springs};
use crate::scene::Scene;
use nalgebra::Vector3;

/// A scene turned into a model with its grid and initial positions.
pub struct BuiltScene {
    /// The grid of real particles.
    pub grid: Grid,
    /// The model (possibly with virtual clamp points after the grid particles).
    pub model: Model,
    /// Initial positions of all particles in m.
    pub x0: Vec<Vector3<f64>>,
}

/// Builds the model of a validated scene.
pub fn build_scene(scene: &Scene) -> BuiltScene {
    let c = &scene.cloth;
    let grid = Grid::new(
        c.nx,
        c.ny,
        c.size_x_m,
        c.size_y_m,
        c.spacing,
        if c.spacing == super::Spacing::Graded {
            c.grading
        } else {
            0.0
        },
    );
    let flat = grid.flat_positions();
    let mut x0 = flat.clone();
    if c.initial_perturbation_m != 0.0 {
        use std::f64::consts::PI;
        for p in x0.iter_mut() {
            let (u, w) = (p.x / c.size_x_m, p.y / c.size_y_m);
            p.z += c.initial_perturbation_m * (PI * u).sin() * (PI * w).sin() * w;
        }
    }
    let mut masses = grid.lumped_masses(c.areal_density_kg_per_m2);
    let mut fixed = vec![false; grid.len()];
    for corner in &scene.boundary.pin_corners {
        let (i, j) = corner.ij(&grid);
        fixed[grid.index(i, j)] = true;
    }
    for p in &scene.boundary.pin_particles {
        fixed[grid.index(p[0], p[1])] = true;
    }
    let mut terms: Vec<Box<dyn EnergyTerm>> = Vec::new();
    let g = scene.gravity.g_m_per_s2;
    let (damping, elongation) = match &scene.material.mass_spring {
        Some(ms) => (ms.damping_Ns_per_m, Some(ms.elongation_rate)),
        None => (0.0, None),
    };
    if let Some(ms) = &scene.material.mass_spring {
        for edge in &scene.boundary.clamp_edges {
            // A mass-spring net has no rotational degrees of freedom: clamp = pin the edge and the next line.
            let (on, next) = edge.lines(&grid);
            for p in on.into_iter().chain(next) {
                fixed[p] = true;
            }
        }
        let rest = |a: usize, b: usize, factor: f64| match ms.natural_length_m {
            Some(l0) => l0 * factor,
            None => (flat[b] - flat[a]).norm(),
        };
        let mut family = |fam: SpringFamily, k: f64, offsets: &[(usize, usize)], factor: f64| {
            let mut pairs = Vec::new();
            for j in 0..grid.ny {
                for i in 0..grid.nx {
                    for &(di, dj) in offsets {
                        if i + di < grid.nx && j + dj < grid.ny {
                            pairs.push((grid.index(i, j), grid.index(i + di, j + dj)));
                        }
                    }
                }
            }
            // The anti-diagonal of each cell for shear springs.
            if fam == SpringFamily::Shear {
                for j in 0..grid.ny - 1 {
                    for i in 0..grid.nx - 1 {
                        pairs.push((grid.index(i + 1, j), grid.index(i, j + 1)));
                    }
                }
            }
            let rests: Vec<f64> = pairs.iter().map(|&(a, b)| rest(a, b, factor)).collect();
            let n = pairs.len();
            if n > 0 {
                terms.push(Box::new(Springs::new(fam, pairs, rests, vec![k; n])));
            }
        };
        family(
            SpringFamily::Structural,
            ms.structural(),
            &[(1, 0), (0, 1)],
            1.0,
        );
        if ms.topology.has_shear() {
            family(
                SpringFamily::Shear,
                ms.shear(),
                &[(1, 1)],
                std::f64::consts::SQRT_2,
            );
        }
        if ms.topology.has_bend() {
            family(SpringFamily::Bend, ms.bend(), &[(2, 0), (0, 2)], 2.0);
        }
    }
    if let Some(cont) = &scene.material.continuum {
        let r = cont.rigidities().expect("validated scene");
        continuum_terms(
            &grid,
            &r,
            &scene.boundary.clamp_edges,
            &mut fixed,
            &mut masses,
            &mut x0,
            &mut terms,
        );
    }
    if g > 0.0 {
        terms.push(Box::new(Gravity::new(masses.clone(), g)));
    }
    let model = Model {
        n_grid: grid.len(),
        masses,
        fixed,
        terms,
        gravity_m_per_s2: g,
        damping_Ns_per_m: damping,
        elongation_rate: elongation,
    };
    BuiltScene { grid, model, x0 }
}

/// The continuum model on the grid: tensile springs along grid lines (k = E·w/h), cell shear (G) and
/// quadratic bending along grid lines (k = D·w/h̄). A clamped edge pins its particles and adds
/// virtual fixed points mirrored across it, so the bending term sees a zero slope at the edge.
#[allow(clippy::needless_range_loop)] // grid loops index several parallel arrays
fn continuum_terms(
    grid: &Grid,
    r: &Rigidities,
    clamps: &[super::Edge],
    fixed: &mut Vec<bool>,
    masses: &mut Vec<f64>,
    x0: &mut Vec<Vector3<f64>>,
    terms: &mut Vec<Box<dyn EnergyTerm>>,
) {
    let (nx, ny) = (grid.nx, grid.ny);
    let wx = tributary_lengths(&grid.xs);
    let wy = tributary_lengths(&grid.ys);
    // Tensile springs.
    let mut pairs = Vec::new();
    let mut rest = Vec::new();
    let mut k = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            if i + 1 < nx {
                let h = grid.xs[i + 1] - grid.xs[i];
                pairs.push((grid.index(i, j), grid.index(i + 1, j)));
                rest.push(h);
                k.push(r.tensile_warp_N_per_m * wy[j] / h);
            }
            if j + 1 < ny {
                let h = grid.ys[j + 1] - grid.ys[j];
                pairs.push((grid.index(i, j), grid.index(i, j + 1)));
                rest.push(h);
                k.push(r.tensile_weft_N_per_m * wx[i] / h);
            }
        }
    }
    terms.push(Box::new(Springs::new(
        SpringFamily::Tensile,
        pairs,
        rest,
        k,
    )));
    // Shear.
    if r.shear_N_per_m > 0.0 {
        let mut cells = Vec::new();
        let mut sides = Vec::new();
        for j in 0..ny - 1 {
            for i in 0..nx - 1 {
                cells.push([
                    grid.index(i, j),
                    grid.index(i + 1, j),
                    grid.index(i, j + 1),
                    grid.index(i + 1, j + 1),
                ]);
                sides.push((grid.xs[i + 1] - grid.xs[i], grid.ys[j + 1] - grid.ys[j]));
            }
        }
        terms.push(Box::new(CellShear::new(cells, sides, r.shear_N_per_m)));
    }
    // Bending along x lines (warp) and y lines (weft).
    let mut triples = Vec::new();
    let mut coef = Vec::new();
    let mut stiff = Vec::new();
    let mut add = |a: usize, b: usize, c: usize, h1: f64, h2: f64, d: f64, w: f64, weight: f64| {
        triples.push([a, b, c]);
        coef.push([1.0 / h1, -1.0 / h1 - 1.0 / h2, 1.0 / h2]);
        stiff.push(weight * d * w / (0.5 * (h1 + h2)));
    };
    for j in 0..ny {
        for i in 1..nx - 1 {
            let (h1, h2) = (grid.xs[i] - grid.xs[i - 1], grid.xs[i + 1] - grid.xs[i]);
            add(
                grid.index(i - 1, j),
                grid.index(i, j),
                grid.index(i + 1, j),
                h1,
                h2,
                r.bending_warp_N_m,
                wy[j],
                1.0,
            );
        }
    }
    for i in 0..nx {
        for j in 1..ny - 1 {
            let (h1, h2) = (grid.ys[j] - grid.ys[j - 1], grid.ys[j + 1] - grid.ys[j]);
            add(
                grid.index(i, j - 1),
                grid.index(i, j),
                grid.index(i, j + 1),
                h1,
                h2,
                r.bending_weft_N_m,
                wx[i],
                1.0,
            );
        }
    }
    for edge in clamps {
        let (on, next) = edge.lines(grid);
        let (d, along_x) = match edge {
            super::Edge::Xmin | super::Edge::Xmax => (r.bending_warp_N_m, true),
            super::Edge::Ymin | super::Edge::Ymax => (r.bending_weft_N_m, false),
        };
        for (k, (&p, &q)) in on.iter().zip(&next).enumerate() {
            fixed[p] = true;
            let ghost = x0.len();
            x0.push(x0[p] * 2.0 - x0[q]);
            masses.push(0.0);
            fixed.push(true);
            let h = (x0[q] - x0[p]).norm();
            let w = if along_x { wy[k] } else { wx[k] };
            // The turning angle at the clamp node happens over h/2 (clamp tangent to the first
            // segment's midpoint), not h̄ = h: k = D w/(h/2), weight 2.
            add(ghost, p, q, h, h, d, w, 2.0);
        }
    }
    if !triples.is_empty() {
        terms.push(Box::new(LinearBending::new(triples, coef, stiff)));
    }
}
