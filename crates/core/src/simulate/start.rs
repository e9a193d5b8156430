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
/// the free particles of `x`. Only when both sides have an odd count ≥ 21, the coarse solve converges,
/// no absolute natural length ties the springs to the fine spacing, and no hold or point load names
/// particles of the fine grid.
pub(super) fn coarse_start(
    scene: &Scene,
    grid: &Grid,
    x: &mut [Vector3<f64>],
) -> Option<(SolveReport, ())> {
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
    Some((coarse.report, ()))
}
