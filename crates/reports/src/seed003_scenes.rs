//! Seed 003's scenes, each solved at its grid and at twice its resolution, with the gap between the
//! two drapes: what the report's sections, the rod's table and the drawings read.

use anyhow::Result;
use drapelab_core::scene::Scene;
use drapelab_core::simulate::{Solution, solve_scene};
use drapelab_core::solve::NoObserver;
use std::path::Path;

/// The scene on a grid twice as fine (2n − 1 lines per side; pinned particles moved with it).
pub fn refined(scene: &Scene) -> Scene {
    scene.regridded(2 * scene.cloth.nx - 1, 2 * scene.cloth.ny - 1)
}

/// A scene solved on its grid and on one twice as fine, with the gap between the two drapes.
pub struct Solved {
    pub(crate) scene: Scene,
    pub(crate) coarse: Solution,
    pub(crate) fine: Solution,
    pub(crate) gap_m: f64,
}

/// Solves a scene on its grid and on [`refined`]'s.
pub fn solve_pair(scene: &Scene) -> Solved {
    let coarse = solve_scene(scene, &mut NoObserver);
    let fine = solve_scene(&refined(scene), &mut NoObserver);
    let gap_m = if coarse.report.is_converged() && fine.report.is_converged() {
        let g = &coarse.grid;
        (0..g.ny)
            .flat_map(|j| (0..g.nx).map(move |i| (i, j)))
            .map(|(i, j)| (coarse.at(i, j) - fine.at_material(g.xs[i], g.ys[j])).norm())
            .fold(0.0, f64::max)
    } else {
        f64::NAN
    };
    Solved {
        scene: scene.clone(),
        coarse,
        fine,
        gap_m,
    }
}

/// Loads a seed 003 scene.
pub fn load(path: &Path) -> Result<Scene> {
    Ok(Scene::load(path, &[])?.scene.into_inner())
}
