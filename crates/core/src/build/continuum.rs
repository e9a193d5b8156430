//! The continuum model on a grid (seed 003 §10.2–10.4): tensile springs along grid lines, cell
//! shear and twist, quadratic bending along grid lines with clamped edges mirrored, and the
//! symmetry planes of a quarter or half model.

use crate::cloth::{Grid, tributary_lengths};
use crate::material::Rigidities;
use crate::physics::{
    CellShear, CellTwist, EnergyTerm, LinearBending, ModelBuilder, SpringFamily, Springs,
};
use nalgebra::Vector3;

/// Symmetry planes along grid edges (a quarter or half model, seed 003 §10.4.2): the particles on the
/// edge keep their coordinate normal to it, and the bending across the plane is kept by
/// [`MirrorBending`](crate::physics::MirrorBending). Tensile, shear and gravity need nothing: the edge's
/// tributary widths already halve what lies on the plane.
pub(super) fn symmetry_planes(
    grid: &Grid,
    r: &Rigidities,
    edges: &[crate::cloth::Edge],
    x0: &[Vector3<f64>],
    held: &mut Vec<[bool; 3]>,
    terms: &mut Vec<Box<dyn EnergyTerm>>,
) {
    if edges.is_empty() {
        return;
    }
    held.resize(grid.len(), [false; 3]);
    let wx = tributary_lengths(&grid.xs);
    let wy = tributary_lengths(&grid.ys);
    for edge in edges {
        let (on, next) = edge.lines(grid);
        let (axis, d) = match edge {
            crate::cloth::Edge::Xmin | crate::cloth::Edge::Xmax => (0, r.bending_warp_N_m),
            crate::cloth::Edge::Ymin | crate::cloth::Edge::Ymax => (1, r.bending_weft_N_m),
        };
        let mut pairs = Vec::new();
        let (mut hs, mut ks) = (Vec::new(), Vec::new());
        for (k, (&p, &q)) in on.iter().zip(&next).enumerate() {
            held[p][axis] = true;
            let h = (x0[q] - x0[p]).norm();
            let w = if axis == 0 { wy[k] } else { wx[k] };
            pairs.push((p, q));
            hs.push(h);
            ks.push(d * w / h);
        }
        terms.push(Box::new(crate::physics::MirrorBending::new(
            pairs, axis, &hs, &ks,
        )));
    }
}

/// The grid cells (p₀₀, p₁₀, p₀₁, p₁₁) whose four corners are all present, with their rest sides (h_x, h_y) in m.
fn present_cells(grid: &Grid, absent: &[bool]) -> (Vec<[usize; 4]>, Vec<(f64, f64)>) {
    let mut cells = Vec::new();
    let mut sides = Vec::new();
    for j in 0..grid.ny - 1 {
        for i in 0..grid.nx - 1 {
            let cell = [
                grid.index(i, j),
                grid.index(i + 1, j),
                grid.index(i, j + 1),
                grid.index(i + 1, j + 1),
            ];
            if cell.iter().any(|&p| absent[p]) {
                continue;
            }
            cells.push(cell);
            sides.push((grid.xs[i + 1] - grid.xs[i], grid.ys[j + 1] - grid.ys[j]));
        }
    }
    (cells, sides)
}

/// The continuum sheet's tensile springs (seed 003 §10.3): one per grid segment of present
/// particles, its stiffness the tensile rigidity times the tributary width over the length.
fn tensile_springs(grid: &Grid, r: &Rigidities, absent: &[bool]) -> Springs {
    let (nx, ny) = (grid.nx, grid.ny);
    let wx = tributary_lengths(&grid.xs);
    let wy = tributary_lengths(&grid.ys);
    let mut pairs = Vec::new();
    let mut rest = Vec::new();
    let mut k = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            if i + 1 < nx && !absent[grid.index(i, j)] && !absent[grid.index(i + 1, j)] {
                let h = grid.xs[i + 1] - grid.xs[i];
                pairs.push((grid.index(i, j), grid.index(i + 1, j)));
                rest.push(h);
                k.push(r.tensile_warp_N_per_m * wy[j] / h);
            }
            if j + 1 < ny && !absent[grid.index(i, j)] && !absent[grid.index(i, j + 1)] {
                let h = grid.ys[j + 1] - grid.ys[j];
                pairs.push((grid.index(i, j), grid.index(i, j + 1)));
                rest.push(h);
                k.push(r.tensile_weft_N_per_m * wx[i] / h);
            }
        }
    }
    Springs::new(SpringFamily::Tensile, pairs, rest, k)
}

/// The continuum model on the grid: tensile springs along grid lines (k = E·w/h), cell shear (G) and
/// quadratic bending along grid lines (k = D·w/h̄) and cell twist (D_t). A clamped edge pins its particles and adds
/// virtual fixed points mirrored across it, so the bending term sees a zero slope at the edge.
pub(super) fn continuum_terms(
    grid: &Grid,
    r: &Rigidities,
    absent: &[bool],
    clamps: &[crate::cloth::Edge],
    b: &mut ModelBuilder,
    x0: &mut Vec<Vector3<f64>>,
) {
    let terms = &mut b.terms;
    terms.push(Box::new(tensile_springs(grid, r, absent)));
    // Shear.
    if r.shear_N_per_m > 0.0 {
        let (cells, sides) = present_cells(grid, absent);
        terms.push(Box::new(CellShear::new(cells, sides, r.shear_N_per_m)));
    }
    // Twist of each cell (plate energy D_t κ_xy²).
    if r.bending_twist_N_m > 0.0 {
        let (cells, sides) = present_cells(grid, absent);
        terms.push(Box::new(CellTwist::cells(
            cells,
            &sides,
            r.bending_twist_N_m,
        )));
    }
    line_bending(grid, r, absent, clamps, b, x0);
}

/// Quadratic bending along grid lines (warp along x, weft along y; k = D·w/h̄), a clamped edge's
/// particles pinned with virtual fixed points mirrored across it (zero slope at the edge).
#[allow(clippy::needless_range_loop)] // grid loops index several parallel arrays
fn line_bending(
    grid: &Grid,
    r: &Rigidities,
    absent: &[bool],
    clamps: &[crate::cloth::Edge],
    b: &mut ModelBuilder,
    x0: &mut Vec<Vector3<f64>>,
) {
    let (nx, ny) = (grid.nx, grid.ny);
    let (fixed, masses, terms) = (&mut b.fixed, &mut b.masses, &mut b.terms);
    let wx = tributary_lengths(&grid.xs);
    let wy = tributary_lengths(&grid.ys);
    // Bending along x lines (warp) and y lines (weft).
    let mut triples = Vec::new();
    let mut coef = Vec::new();
    let mut stiff = Vec::new();
    let mut add = |a: usize, b: usize, c: usize, h1: f64, h2: f64, d: f64, w: f64, weight: f64| {
        if [a, b, c]
            .iter()
            .any(|&p| absent.get(p).copied().unwrap_or(false))
        {
            return;
        }
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
            crate::cloth::Edge::Xmin | crate::cloth::Edge::Xmax => (r.bending_warp_N_m, true),
            crate::cloth::Edge::Ymin | crate::cloth::Edge::Ymax => (r.bending_weft_N_m, false),
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
