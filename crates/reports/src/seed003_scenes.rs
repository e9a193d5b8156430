//! Seed 003's drapes read back from a `seed003-solve` stage's tables: each scene's grid, positions
//! and sheet particles, what the drawings and the montage show.

use anyhow::{Result, bail};
use drapelab_app::seed003::tables::{DrapeParticleRow, Seed003SceneRow};
use drapelab_core::cloth::Grid;
use nalgebra::Vector3;

/// One scene's drape at its grid.
pub struct Drape {
    /// The scene's name.
    pub name: String,
    /// Its grid (lines at the material coordinates of the table).
    pub grid: Grid,
    /// Positions in grid order, m.
    pub x: Vec<Vector3<f64>>,
    /// Which particles belong to the sheet.
    pub present: Vec<bool>,
    /// Also show it from above (a drape on a table or pedestal).
    pub from_above: bool,
}

/// Each scene's drape, in the scenes table's order, from the drapes table's particles.
pub fn drapes(scenes: &[Seed003SceneRow], particles: &[DrapeParticleRow]) -> Result<Vec<Drape>> {
    scenes
        .iter()
        .map(|s| {
            let rows: Vec<&DrapeParticleRow> =
                particles.iter().filter(|p| p.scene == s.scene).collect();
            let (nx, ny) = (s.nx as usize, s.ny as usize);
            if rows.len() != nx * ny {
                bail!(
                    "scene `{}`: {} particles in the drapes table, its grid has {nx} × {ny}",
                    s.scene,
                    rows.len()
                );
            }
            let mut grid = Grid {
                nx,
                ny,
                xs: vec![0.0; nx],
                ys: vec![0.0; ny],
            };
            let mut x = vec![Vector3::zeros(); nx * ny];
            let mut present = vec![true; nx * ny];
            for p in rows {
                let (i, j) = (p.i as usize, p.j as usize);
                grid.xs[i] = p.u_m;
                grid.ys[j] = p.v_m;
                let k = grid.index(i, j);
                x[k] = Vector3::new(p.x_m, p.y_m, p.z_m);
                present[k] = p.present;
            }
            Ok(Drape {
                name: s.scene.clone(),
                grid,
                x,
                present,
                from_above: s.from_above,
            })
        })
        .collect()
}
