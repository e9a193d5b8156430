//! The starts of a static solve that are solves themselves: a slack net's taut drape and the
//! coarse grid's drape interpolated to the scene's grid.

use super::solve_scene;
use crate::cloth::Grid;
use crate::scene::Scene;
use crate::solve::SolveReport;
use nalgebra::Vector3;

/// A slack net's start: its drape with every spring's rest length equal to its initial length (the
/// taut net of the same grid, which sags into a smooth bag from the shaped start), from which the
/// solve at the natural length (seed 000 Table 3, longer than the spacing: the springs start in
/// compression) is one continuation step. From the flat sheet itself, a compressed net crumples
/// and its folds jam against the self-contact barrier: 9 of the stress box's 50 static runs
/// stopped at 300 iterations with 18 N of residual (issue 47). Only for a mass-spring net whose
/// natural length exceeds its shortest initial spring length; none where the taut net does not
/// converge.
pub(super) fn taut_start(scene: &Scene, x: &mut [Vector3<f64>]) -> Option<SolveReport> {
    let ms = scene.material.mass_spring.as_ref()?;
    let natural = ms.natural_length_m?;
    let grid = scene.grid();
    if scene.pattern().is_some() || natural <= grid.min_spacing_m() {
        return None;
    }
    let mut taut = scene.clone();
    if let Some(m) = taut.material.mass_spring.as_mut() {
        m.natural_length_m = None;
    }
    let sol = solve_scene(&taut, &mut crate::solve::NoObserver);
    if !sol.report.is_converged() || sol.x.len() != x.len() {
        return None;
    }
    x.copy_from_slice(&sol.x);
    Some(sol.report)
}

/// Solves the scene on the grid with every other line and writes the interpolated positions into
/// the free particles of `x` (with a note saying so). Only when both sides have an odd count ≥ 21, the coarse solve converges,
/// no absolute natural length ties the springs to the fine spacing, and no hold or point load names
/// particles of the fine grid.
pub(super) fn coarse_start(
    scene: &Scene,
    grid: &Grid,
    x: &mut [Vector3<f64>],
) -> Option<(SolveReport, String)> {
    let (nx, ny) = (grid.nx, grid.ny);
    let natural = scene
        .material
        .mass_spring
        .as_ref()
        .is_some_and(|m| m.natural_length_m.is_some());
    if !scene.solver.static_.start.is_nested()
        || natural
        || !scene.obstacles.is_empty()
        || !scene.boundary.holds.is_empty()
        || !scene.loads.is_empty()
        || nx < 21
        || ny < 21
        || nx % 2 == 0
        || ny % 2 == 0
    {
        return None;
    }
    if scene
        .boundary
        .pin_particles
        .iter()
        .any(|p| p[0] % 2 == 1 || p[1] % 2 == 1)
    {
        return None;
    }
    let c = scene.regridded(nx.div_ceil(2), ny.div_ceil(2));
    let coarse = solve_scene(&c, &mut crate::solve::NoObserver);
    if !coarse.report.is_converged() {
        return None;
    }
    let cg = &coarse.grid;
    let at = |i: usize, j: usize| coarse.x[cg.index(i, j)];
    for j in 0..ny {
        for i in 0..nx {
            let p = grid.index(i, j);
            let (i0, j0) = (i / 2, j / 2);
            let (i1, j1) = (i0 + i % 2, j0 + j % 2);
            x[p] = (at(i0, j0) + at(i1, j0) + at(i0, j1) + at(i1, j1)) * 0.25;
        }
    }
    let note = format!("from a {}×{} start", cg.nx, cg.ny);
    Some((coarse.report, note))
}

/// Points a side from which a disc starts from the coarser disc's drape ([`Start::NestedDisc`]):
/// the coarser grid then has at least 41.
///
/// [`Start::NestedDisc`]: crate::solve::Start::NestedDisc
const NESTED_DISC_MIN_POINTS: usize = 77;

/// The coarser disc keeps this many times the contact distance from obstacles: room for the finer
/// mesh's points on its chords, which cut into a convex obstacle.
const COARSE_DISTANCE_FACTOR: f64 = 2.0;

/// The disc of `scene` one coarse spacing larger in radius on the grid of twice the spacing: fine
/// point (i, j) lies on coarse point (i/2 + 1, j/2 + 1). None where the scene is not a uniform
/// disc grid of odd sides from [`NESTED_DISC_MIN_POINTS`].
fn larger_coarse_disc(scene: &Scene) -> Option<Scene> {
    let c = &scene.cloth;
    let sides_ok = |n: usize| n >= NESTED_DISC_MIN_POINTS && n % 2 == 1;
    if !scene.solver.static_.start.is_nested_disc()
        || c.shape != crate::scene::SheetShape::Disc
        || c.spacing != crate::cloth::Spacing::Uniform
        || c.pattern.is_some()
        || c.mesh.is_some()
        || !sides_ok(c.nx)
        || !sides_ok(c.ny)
        || !scene.boundary.pin_particles.is_empty()
        || !scene.boundary.holds.is_empty()
        || !scene.loads.is_empty()
    {
        return None;
    }
    let (nx, ny) = ((c.nx - 1) / 2 + 3, (c.ny - 1) / 2 + 3);
    let (hx, hy) = (
        2.0 * c.size_x_m / (c.nx - 1) as f64,
        2.0 * c.size_y_m / (c.ny - 1) as f64,
    );
    let mut coarse = scene.regridded(nx, ny);
    let k = &mut coarse.cloth;
    k.size_x_m += 2.0 * hx;
    k.size_y_m += 2.0 * hy;
    k.origin_m[0] -= hx;
    k.origin_m[1] -= hy;
    coarse.contact.distance_m *= COARSE_DISTANCE_FACTOR;
    Some(coarse)
}

/// Fine point (i, j)'s place on the coarse drape's triangles (`at` gives a coarse point, offset by
/// one line): a coarse point, a coarse edge's midpoint, or the midpoint of a cell's diagonal from
/// (i, j) to (i + 1, j + 1), the diagonal [`crate::cloth::cell_triangles`] splits cells along.
fn on_coarse_triangles(
    i: usize,
    j: usize,
    at: impl Fn(usize, usize) -> Vector3<f64>,
) -> Vector3<f64> {
    let (i0, j0) = (i / 2 + 1, j / 2 + 1);
    match (i % 2, j % 2) {
        (0, 0) => at(i0, j0),
        (1, 0) => 0.5 * (at(i0, j0) + at(i0 + 1, j0)),
        (0, _) => 0.5 * (at(i0, j0) + at(i0, j0 + 1)),
        _ => 0.5 * (at(i0, j0) + at(i0 + 1, j0 + 1)),
    }
}

/// [`Start::NestedDisc`]'s start: the larger disc solved on the coarser grid (itself so started),
/// its drape carried onto the free particles of `x` by [`on_coarse_triangles`], those within a
/// tenth of the contact distance of an obstacle pushed out to it. None, `x` untouched, where the
/// scene has no such start, the coarse solve does not converge, or the start it gives has
/// infinite energy or crosses itself.
///
/// [`Start::NestedDisc`]: crate::solve::Start::NestedDisc
pub(super) fn disc_coarse_start(
    scene: &Scene,
    grid: &Grid,
    model: &crate::physics::Model,
    x: &mut [Vector3<f64>],
) -> Option<(SolveReport, String)> {
    let c = larger_coarse_disc(scene)?;
    let coarse = solve_scene(&c, &mut crate::solve::NoObserver);
    if !coarse.report.is_converged() {
        return None;
    }
    let cg = &coarse.grid;
    let clearance = 0.1 * scene.contact.distance_m;
    let mut start = x.to_vec();
    for j in 0..grid.ny {
        for i in 0..grid.nx {
            let p = grid.index(i, j);
            if model.fixed[p] {
                continue;
            }
            let mut q = on_coarse_triangles(i, j, |a, b| coarse.x[cg.index(a, b)]);
            for o in &scene.obstacles {
                let (d, n) = o.signed_distance(&q);
                if d < clearance {
                    q += (clearance - d) * n;
                }
            }
            start[p] = q;
        }
    }
    let topo = crate::proximity::MeshTopology::from_triangles(crate::build::scene_triangles(scene));
    let xi = crate::build::self_thickness_m(scene);
    if model.models_self_contact() && !separate_close_pairs(&topo, &model.fixed, xi, &mut start) {
        return None;
    }
    let crossings = crate::proximity::edge_triangle_crossings(&topo, &start);
    if !model.energy(&start, 1.0).is_finite() || !crossings.is_empty() {
        return None;
    }
    x.copy_from_slice(&start);
    let larger = 0.5 * (c.cloth.size_x_m - scene.cloth.size_x_m);
    let note = format!(
        "from the {}×{} drape of a disc {:.1} mm larger in radius",
        cg.nx,
        cg.ny,
        larger * 1e3
    );
    Some((coarse.report, note))
}

/// Rounds of [`separate_close_pairs`] at most.
const SEPARATION_ROUNDS: usize = 20;

/// Moves the free particles of pairs of primitives (sharing no vertex) nearer than 1.5 `xi` apart
/// along the line between their closest points towards 1.5 `xi`, until every pair is at least
/// 1.25 `xi` apart (the barrier is infinite at `xi`): where the
/// coarser drape folded sharply between two of its triangles (a pair its own barrier never saw),
/// the finer mesh's primitives on either side of the crease may lie within the sheet's thickness.
/// Each round moves each particle by the mean of its pairs' pushes. Whether it got there.
fn separate_close_pairs(
    topo: &crate::proximity::MeshTopology,
    fixed: &[bool],
    xi: f64,
    x: &mut [Vector3<f64>],
) -> bool {
    let (target, enough) = (1.1 * xi, 1.02 * xi);
    for _ in 0..SEPARATION_ROUNDS {
        let close = crate::proximity::pairs_within(topo, x, target);
        if close.iter().all(|&(_, d)| d >= enough) {
            return true;
        }
        let mut push = vec![(Vector3::zeros(), 0usize); x.len()];
        for (pair, d) in close {
            let idx = pair.vertices(topo);
            let (_, c) =
                crate::proximity::pair_distance(pair.is_point_triangle(), &idx.map(|k| x[k]));
            let r: Vector3<f64> = (0..4).map(|k| x[idx[k]] * c[k]).sum();
            let Some(n) = r.try_normalize(1e-15) else {
                continue;
            };
            // The first primitive's vertices (positive coefficients) move along n, the other's back.
            for (&k, &ck) in idx.iter().zip(&c) {
                push[k].0 += 0.5 * (target - d) * ck.signum() * n;
                push[k].1 += 1;
            }
        }
        for (k, (v, count)) in push.into_iter().enumerate() {
            if count > 0 && !fixed[k] {
                x[k] += v / count as f64;
            }
        }
    }
    crate::proximity::pairs_within(topo, x, enough).is_empty()
}
