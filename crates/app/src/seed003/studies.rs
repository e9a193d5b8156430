//! The studies a `seed003-solve` stage sets beside seed 003's tables: each scene at its grid and at
//! twice its resolution, Table 10.2's edge points of
//! the quarter table, Table 10.4's rod corners under every contact treatment and material with their
//! grid study, Table 10.1's cantilever against the grid, and §10.3.3's load–displacement curve.

use crate::seed003::tables::{
    CantileverGridRow, LoadStepRow, Loading, RodCornerRow, RodGridRow, RodMaterial, TableEdgeRow,
};
use anyhow::Result;
use drapelab_core::cloth::Spacing;
use drapelab_core::scene::{ContactMethod, Scene, SolverKind};
use drapelab_core::simulate::{Solution, solve_scene};
use drapelab_core::solve::{NoObserver, solve_static_loads};
use nalgebra::Vector3;
use rayon::prelude::*;
use std::path::Path;
use std::time::Instant;

/// A scene solved on its grid and on one twice as fine, with the gap between the two drapes.
pub struct Solved {
    /// The scene.
    pub scene: Scene,
    /// Its drape at its grid.
    pub coarse: Solution,
    /// Its drape on the grid twice as fine.
    pub fine: Solution,
    /// Largest distance between a particle and the same material point of the finer drape, m (NaN
    /// unless both converged).
    pub gap_m: f64,
}

/// The scene on a grid twice as fine (2n − 1 lines per side; pinned particles moved with it).
pub fn refined(scene: &Scene) -> Scene {
    scene.regridded(2 * scene.cloth.nx - 1, 2 * scene.cloth.ny - 1)
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

/// Table 10.2: where the quarter table's drape puts each edge point of `file`
/// (fvm_table_drape_edges.csv: `point`, `x0_cm`, `y0_cm`), interpolated at the material point.
pub fn table_edge_rows(q: &Solved, file: &Path) -> Result<Vec<TableEdgeRow>> {
    let rows: Vec<std::collections::BTreeMap<String, String>> = drapelab_record::read_csv(file)?;
    Ok(rows
        .iter()
        .map(|row| {
            let f = |k: &str| {
                row.get(k)
                    .and_then(|v| v.parse::<f64>().ok())
                    .unwrap_or(f64::NAN)
            };
            let (u_m, v_m) = (f("x0_cm") / 100.0, f("y0_cm") / 100.0);
            let pt = q.coarse.at_material(u_m, v_m);
            TableEdgeRow {
                point: row.get("point").cloned().unwrap_or_default(),
                u_m,
                v_m,
                x_m: pt.x,
                y_m: pt.y,
                drop_m: -pt.z,
            }
        })
        .collect())
}

/// The rod drape's corner A (x, y, drop) and corner B turned by 180° about the vertical, m.
pub fn corner_a(sol: &Solution) -> (Vector3<f64>, Vector3<f64>) {
    let n = sol.grid.nx;
    let (a, b) = (sol.at(n - 1, n - 1), sol.at(0, 0));
    (Vector3::new(a.x, a.y, -a.z), Vector3::new(-b.x, -b.y, -b.z))
}

/// Table 10.4: the rod's corners at the seed's grid under every treatment and material: the solved
/// scene (its own contact, Table 10.3's material) first, then [`rod_variants`].
pub fn rod_rows(r: &Solved) -> Vec<RodCornerRow> {
    let variants = rod_variants(&rod_materials(&r.scene));
    let solved: Vec<(RodMaterial, &Scene, Solution)> = variants
        .par_iter()
        .map(|(m, s)| (*m, s, solve_scene(s, &mut NoObserver)))
        .collect();
    std::iter::once((RodMaterial::Table103, &r.scene, &r.coarse))
        .chain(solved.iter().map(|(m, s, sol)| (*m, *s, sol)))
        .map(|(material, scene, sol)| {
            let (a, b) = corner_a(sol);
            RodCornerRow {
                material,
                contact: scene.contact.method,
                friction_coefficient: scene.contact.friction_coefficient,
                status: sol.report.status,
                corner_a_x_m: a.x,
                corner_a_y_m: a.y,
                corner_a_drop_m: a.z,
                corner_b_x_m: b.x,
                corner_b_y_m: b.y,
                corner_b_drop_m: b.z,
            }
        })
        .collect()
}

/// Each rod material under the sticky vertical gap and under the barrier with lagged friction
/// μ = 0.3.
pub fn rod_variants(materials: &[(RodMaterial, Scene)]) -> Vec<(RodMaterial, Scene)> {
    materials
        .iter()
        .flat_map(|(m, base)| {
            let mut vg = base.clone();
            vg.contact.method = ContactMethod::VerticalGap;
            let mut fr = base.clone();
            fr.contact.friction_coefficient = 0.3;
            [(*m, vg), (*m, fr)]
        })
        .collect()
}

/// Grid convergence of the rod's corner A (Table 10.1 style): the friction barrier (μ = 0.3) for
/// each material, the vertical gap for Table 10.3's and Deng's, on 17–49 lines per side.
pub fn rod_grid_rows(scene: &Scene) -> Vec<RodGridRow> {
    let materials = rod_materials(scene);
    let sides = [17usize, 25, 33, 41, 49];
    let last = materials.len() - 1;
    let cases: Vec<(usize, bool, usize)> = (0..materials.len())
        .flat_map(|m| [(m, false), (m, true)])
        .filter(|&(m, vg)| !vg || m == 0 || m == last)
        .flat_map(|(m, vg)| sides.iter().map(move |&n| (m, vg, n)))
        .collect();
    cases
        .par_iter()
        .map(|&(m, vg, n)| {
            let mut base = materials[m].1.clone();
            if vg {
                base.contact.method = ContactMethod::VerticalGap;
            } else {
                base.contact.friction_coefficient = 0.3;
            }
            let tol = base.solver.static_.residual_tol_rel;
            let s = drapelab_core::benchmark::bench_scene(&base, n, SolverKind::Static, tol);
            let t = Instant::now();
            let sol = solve_scene(&s, &mut NoObserver);
            let wall_time_s = t.elapsed().as_secs_f64();
            let (a, _) = corner_a(&sol);
            RodGridRow {
                material: materials[m].0,
                contact: s.contact.method,
                friction_coefficient: s.contact.friction_coefficient,
                grid: n as u32,
                status: sol.report.status,
                iterations: sol.report.iterations as u64,
                wall_time_s,
                corner_a_x_m: a.x,
                corner_a_y_m: a.y,
                corner_a_drop_m: a.z,
            }
        })
        .collect()
}

/// The rod's materials: Table 10.3 as the seed takes it (no twist rigidity), with an isotropic
/// plate's twist rigidity √(D_warp D_weft) (which the KES data do not give), and Deng's (1994)
/// finite-element material: isotropic, the warp bending rigidity in every direction (D_weft = D_t =
/// D_warp; Poisson's ratio 0 here, 0.3 there).
pub fn rod_materials(scene: &Scene) -> Vec<(RodMaterial, Scene)> {
    let with = |f: &dyn Fn(&mut drapelab_core::material::Continuum, f64, f64)| {
        let mut s = scene.clone();
        if let Some(c) = s.material.continuum.as_mut()
            && let Ok(r) = c.rigidities()
        {
            f(c, r.bending_warp_N_m, r.bending_weft_N_m);
        }
        s
    };
    vec![
        (RodMaterial::Table103, scene.clone()),
        (
            RodMaterial::Table103Twist,
            with(&|c, dw, df| c.bending_twist_N_m = Some((dw * df).sqrt())),
        ),
        (
            RodMaterial::DengFe,
            with(&|c, dw, _| {
                c.bending_weft_gf_cm2_per_cm = None;
                c.bending_weft_N_m = Some(dw);
                c.bending_twist_gf_cm2_per_cm = None;
                c.bending_twist_N_m = Some(dw);
            }),
        ),
    ]
}

/// Table 10.1: the cantilever's free end on uniform and graded grids beside the exact elastica
/// (none when the scene is not a cantilever the elastica solves).
pub fn cantilever_rows(c: &Scene) -> Vec<CantileverGridRow> {
    let Some(exact) = drapelab_core::elastica::HeavyElastica::of_cantilever(c) else {
        return Vec::new();
    };
    let l = c.cloth.size_x_m;
    let (xe, ze) = exact.tip();
    cantilever_grids()
        .par_iter()
        .map(|(label, k, spacing)| {
            let mut s = c.regridded(k + 1, c.cloth.ny);
            s.cloth.spacing = *spacing;
            // Fine strips take more Newton iterations from flat than the scene allows at its grid.
            s.solver.static_.max_iterations = s.solver.static_.max_iterations.max(5000);
            let sol = solve_scene(&s, &mut NoObserver);
            let q = sol.at(sol.grid.nx - 1, sol.grid.ny / 2) - sol.at(0, sol.grid.ny / 2);
            CantileverGridRow {
                scene: c.name.clone(),
                grid: label.clone(),
                grading: c.cloth.grading,
                status: sol.report.status,
                minus_u_m: l - q.x,
                w_m: -q.z,
                exact_minus_u_m: l - xe,
                exact_w_m: -ze,
            }
        })
        .collect()
}

/// Table 10.1's grids: (label, intervals along the strip, spacing), uniform 5–320 and graded 56, 112.
fn cantilever_grids() -> Vec<(String, usize, Spacing)> {
    [5usize, 10, 20, 40, 80, 160, 320]
        .iter()
        .map(|&k| (format!("uniform {k}x1"), k, Spacing::Uniform))
        .chain(
            [56usize, 112]
                .iter()
                .map(|&k| (format!("non-uniform {k}x1"), k, Spacing::Graded)),
        )
        .collect()
}

/// §10.3.3: the cantilever loaded in `steps` equal increments, each solve starting from the last,
/// then in a single step; one row per step, the single step last.
pub fn load_steps(c: &Scene, steps: usize) -> Result<Vec<LoadStepRow>> {
    let mut built = drapelab_core::build::build_scene(&c.clone().validated()?);
    let tip = built.grid.index(built.grid.nx - 1, built.grid.ny / 2);
    let (opts, z0) = (&c.solver.static_, built.x0[tip].z);
    let row =
        |loading, load_factor, x: &[Vector3<f64>], status, iterations, t: Instant| LoadStepRow {
            scene: c.name.clone(),
            loading,
            load_factor,
            tip_deflection_m: z0 - x[tip].z,
            status,
            iterations: iterations as u64,
            wall_time_s: t.elapsed().as_secs_f64(),
        };
    let mut rows = Vec::with_capacity(steps + 1);
    let mut x = built.x0.clone();
    let (t0, mut iters) = (Instant::now(), 0);
    for k in 1..=steps {
        let load = k as f64 / steps as f64;
        let r = solve_static_loads(&mut built.model, &mut x, opts, &[load], &mut NoObserver);
        iters += r.iterations;
        rows.push(row(Loading::Increments, load, &x, r.status, iters, t0));
    }
    let mut y = built.x0.clone();
    let t1 = Instant::now();
    let r = solve_static_loads(&mut built.model, &mut y, opts, &[1.0], &mut NoObserver);
    rows.push(row(
        Loading::SingleStep,
        1.0,
        &y,
        r.status,
        r.iterations,
        t1,
    ));
    Ok(rows)
}
