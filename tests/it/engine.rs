//! Physics of the engine: force balance, symmetry, solver agreement, the exact elastica, energy
//! behaviour of the integrators. A failure here means drapelab's equilibria are wrong.

use crate::support::scene;
use drapelab::scene::Scene;
use drapelab::simulate::{Solution, solve_scene};
use drapelab::solve::{
    DynamicOptions, Integrator, NoObserver, Status, solve_dynamic, stability_limit_dt,
};
use nalgebra::Vector3;

fn solve(s: &Scene) -> Solution {
    let sol = solve_scene(s, &mut NoObserver);
    assert_eq!(
        sol.report.status,
        Status::Converged,
        "{}: {:?}",
        s.name,
        sol.report
    );
    sol
}

/// Largest force on a free particle recomputed from the model, over the lightest particle's weight.
fn residual_over_weight(sol: &Solution) -> f64 {
    let mut g = Vec::new();
    sol.model.gradient(&sol.x, 1.0, &mut g);
    sol.model.max_residual(&g) / sol.model.reference_weight()
}

#[test]
fn hang4_and_hang2_static_solutions_balance_forces() {
    for name in ["hang4.toml", "hang2.toml"] {
        for n in ["11", "21"] {
            let s = scene(name, &[&format!("cloth.nx={n}"), &format!("cloth.ny={n}")]);
            let sol = solve(&s);
            let r = residual_over_weight(&sol);
            assert!(
                r < 1e-6,
                "{name} {n}: residual {r:e} of a particle's weight"
            );
            // And the sheet really sags: not the trivial flat state.
            let zmin = sol.grid_positions().iter().map(|p| p.z).fold(0.0, f64::min);
            assert!(zmin < -1e-3, "{name}: no sag ({zmin})");
        }
    }
}

#[test]
fn hang4_keeps_the_symmetries_of_the_square() {
    let s = scene("hang4.toml", &["cloth.nx=21", "cloth.ny=21"]);
    let sol = solve(&s);
    let n = 21;
    let l = 0.5;
    let mut worst: f64 = 0.0;
    for j in 0..n {
        for i in 0..n {
            let p = sol.at(i, j);
            // mirror x → L − x
            let q = sol.at(n - 1 - i, j);
            worst = worst.max((Vector3::new(l - q.x, q.y, q.z) - p).norm());
            // mirror y → L − y
            let q = sol.at(i, n - 1 - j);
            worst = worst.max((Vector3::new(q.x, l - q.y, q.z) - p).norm());
            // diagonal x ↔ y
            let q = sol.at(j, i);
            worst = worst.max((Vector3::new(q.y, q.x, q.z) - p).norm());
        }
    }
    assert!(worst < 1e-9, "symmetry broken by {worst:e} m");
}

#[test]
fn static_and_every_dynamic_integrator_agree_on_hang4() {
    for n in [11usize, 21] {
        let ns = [format!("cloth.nx={n}"), format!("cloth.ny={n}")];
        let base = scene("hang4.toml", &[&ns[0], &ns[1]]);
        let reference = solve(&base);
        for kind in ["implicit-euler", "symplectic-euler", "explicit-euler"] {
            let kind_set = format!("solver.kind=\"{kind}\"");
            // Implicit Euler takes large steps; the explicit ones run at 0.8 of their estimated
            // stability limit. Explicit Euler converges like gradient descent, (ω_max/ω_min)² steps,
            // so it stops at a looser force tolerance (still ~1e-6 m from equilibrium, see below).
            let sets: Vec<String> = match kind {
                "implicit-euler" => vec!["solver.dynamic.dt_s=0.01".into()],
                "symplectic-euler" => vec!["solver.dynamic.auto_dt_fraction=0.8".into()],
                _ => vec![
                    "solver.dynamic.auto_dt_fraction=0.8".into(),
                    "solver.dynamic.residual_tol_rel=1e-3".into(),
                    "solver.dynamic.speed_tol_m_per_s=1e-4".into(),
                ],
            };
            let mut all: Vec<&str> = vec![&ns[0], &ns[1], &kind_set];
            all.extend(sets.iter().map(String::as_str));
            let s = scene("hang4.toml", &all);
            let sol = solve(&s);
            let d = drapelab::benchmark::distance_to(&sol, &reference);
            assert!(d < 1e-4, "{kind} at {n}×{n} differs from static by {d:e} m");
        }
    }
}

#[test]
fn cantilever_converges_to_the_exact_elastica() {
    let base = scene("cantilever_wool_warp.toml", &[]);
    let l = base.cloth.size_x_m;
    let elastica = drapelab::elastica::HeavyElastica::of_cantilever(&base).expect("a cantilever");
    let (xe, ze) = elastica.tip();
    // The exact solution is a large deflection: the free end drops by most of the length.
    assert!(ze < -0.5 * l, "elastica tip z = {ze}");
    let mut errors = Vec::new();
    let mut curve = Vec::new();
    for n in [11usize, 21, 41, 81] {
        let s = scene("cantilever_wool_warp.toml", &[&format!("cloth.nx={n}")]);
        let sol = solve(&s);
        let tip = sol.at(n - 1, 1);
        let disp_exact = ((xe - l).powi(2) + ze * ze).sqrt();
        let err = ((tip.x - xe).powi(2) + (tip.z - ze).powi(2)).sqrt() / disp_exact;
        errors.push(err);
        curve.push(elastica.distance(&sol));
    }
    // The whole strip, not just its tip, approaches the elastica.
    assert!(
        curve.windows(2).all(|w| w[1] < w[0]) && curve[3] < 0.01 * l,
        "largest distance of the strip to the elastica, m: {curve:?}"
    );
    eprintln!(
        "cantilever tip error relative to the exact elastica displacement, nx = 11, 21, 41, 81: {errors:?}"
    );
    for w in errors.windows(2) {
        assert!(
            w[1] < w[0],
            "error does not fall with refinement: {errors:?}"
        );
    }
    assert!(
        *errors.last().unwrap() < 0.01,
        "finest grid error {:?}",
        errors
    );
}

#[test]
fn symplectic_euler_without_damping_conserves_energy() {
    let s = scene("hang4.toml", &["cloth.nx=5", "cloth.ny=5"]);
    let mut built = crate::support::built(&s);
    let mut x = built.x0.clone();
    let mut v = vec![Vector3::zeros(); x.len()];
    let energy = |model: &drapelab::physics::Model, x: &[Vector3<f64>], v: &[Vector3<f64>]| {
        model.energy(x, 1.0)
            + model
                .masses
                .iter()
                .zip(v)
                .map(|(m, v)| 0.5 * m * v.norm_squared())
                .sum::<f64>()
    };
    let e0 = energy(&built.model, &x, &v);
    // Energy scale: the potential energy released by the sag.
    let opts = DynamicOptions {
        dt_s: 2e-5,
        max_time_s: 2e-5 * 10_000.0,
        damping: false,
        residual_tol_rel: 1e-300,
        speed_tol_m_per_s: 1e-300,
        ..Default::default()
    };
    let rep = solve_dynamic(
        &mut built.model,
        Integrator::SymplecticEuler,
        &mut x,
        &mut v,
        &opts,
        &mut NoObserver,
    );
    assert_eq!(rep.status, Status::MaxIterations);
    assert!(rep.iterations >= 10_000);
    let e1 = energy(&built.model, &x, &v);
    let released = built.model.energy(&built.x0, 1.0) - built.model.energy(&solve(&s).x, 1.0);
    assert!(released > 0.0);
    assert!(
        (e1 - e0).abs() < 0.01 * released,
        "energy drift {:e} J of {:e} J",
        e1 - e0,
        released
    );
    // The motion is real: kinetic energy is a sizeable part of the released energy.
    let ke: f64 = built
        .model
        .masses
        .iter()
        .zip(&v)
        .map(|(m, v)| 0.5 * m * v.norm_squared())
        .sum();
    assert!(ke > 1e-3 * released);
}

#[test]
fn explicit_integrators_above_their_stability_limit_report_divergence() {
    for (kind, integ) in [
        ("explicit-euler", Integrator::ExplicitEuler),
        ("symplectic-euler", Integrator::SymplecticEuler),
    ] {
        let s = scene("hang4.toml", &["cloth.nx=11", "cloth.ny=11"]);
        let built = crate::support::built(&s);
        let limit =
            stability_limit_dt(&built.model, &built.x0, integ, built.model.damping_Ns_per_m)
                .unwrap();
        assert!(limit > 0.0 && limit < 1e-3, "{kind}: limit {limit}");
        let dt = format!("solver.dynamic.dt_s={}", 4.0 * limit);
        let kind_set = format!("solver.kind=\"{kind}\"");
        let s = scene(
            "hang4.toml",
            &[
                "cloth.nx=11",
                "cloth.ny=11",
                &kind_set,
                &dt,
                "solver.dynamic.max_time_s=1",
            ],
        );
        let sol = solve_scene(&s, &mut NoObserver);
        assert_eq!(
            sol.report.status,
            Status::Diverged,
            "{kind}: {:?}",
            sol.report
        );
        let div = sol.report.divergence.expect("divergence details");
        assert_eq!(div.dt_s, Some(4.0 * limit));
        assert!(!div.reason.to_string().is_empty());
    }
}

#[test]
fn topology_b_builds_no_bend_terms_and_c_no_shear() {
    let b = crate::support::built(&scene(
        "hang4.toml",
        &["material.mass_spring.topology=\"b\""],
    ));
    let names = b.model.term_names();
    assert!(
        names.iter().any(|n| n.contains("shear")) && !names.iter().any(|n| n.contains("bend")),
        "{names:?}"
    );
    let c = crate::support::built(&scene(
        "hang4.toml",
        &["material.mass_spring.topology=\"c\""],
    ));
    let names = c.model.term_names();
    assert!(
        !names.iter().any(|n| n.contains("shear")) && names.iter().any(|n| n.contains("bend")),
        "{names:?}"
    );
}

#[test]
fn incremental_loading_reaches_the_same_equilibrium_as_one_step() {
    let one = solve(&scene("cantilever_wool_warp.toml", &["cloth.nx=21"]));
    let five = solve(&scene(
        "cantilever_wool_warp.toml",
        &["cloth.nx=21", "solver.static.load_steps=5"],
    ));
    let d = one
        .grid_positions()
        .iter()
        .zip(five.grid_positions())
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max);
    assert!(d < 1e-9, "load stepping changed the equilibrium by {d:e} m");
    assert!(
        five.report.iterations > one.report.iterations / 2,
        "five load steps cannot be cheaper than half of one"
    );
}

#[test]
fn a_strip_compressed_past_eulers_load_is_reported_as_unstable() {
    // Euler buckling of a clamped–free strip: the straight state under an axial end load P is a
    // minimum for P < P_cr = π² D b / (4 L²) and a saddle above it. Gravity off; the load is spread
    // over the three particles of the free end by their tributary widths (¼, ½, ¼).
    let base = scene("cantilever_wool_warp.toml", &["gravity.g_m_per_s2=0.0"]);
    let r = base
        .material
        .continuum
        .as_ref()
        .unwrap()
        .rigidities()
        .unwrap();
    let (l, b) = (base.cloth.size_x_m, base.cloth.size_y_m);
    let p_cr = std::f64::consts::PI.powi(2) * r.bending_warp_N_m * b / (4.0 * l * l);
    let straight = |factor: f64| {
        let p = factor * p_cr;
        let loads = format!(
            "loads=[{{ particle = [40, 0], direction = [-1.0, 0.0, 0.0], magnitude_N = {} }}, \
             {{ particle = [40, 1], direction = [-1.0, 0.0, 0.0], magnitude_N = {} }}, \
             {{ particle = [40, 2], direction = [-1.0, 0.0, 0.0], magnitude_N = {} }}]",
            p / 4.0,
            p / 2.0,
            p / 4.0
        );
        let s = scene(
            "cantilever_wool_warp.toml",
            &["gravity.g_m_per_s2=0.0", &loads],
        );
        let sol = solve(&s);
        let lift = sol
            .grid_positions()
            .iter()
            .map(|q| q.z.abs())
            .fold(0.0, f64::max);
        assert!(lift < 1e-12, "the straight strip left its line by {lift} m");
        sol.report.minimum
    };
    assert_eq!(straight(0.9), Some(true), "below Euler's load");
    assert_eq!(straight(1.1), Some(false), "above Euler's load");
}

/// An observer whose disk is full from its third state on.
struct Failing;

impl drapelab::solve::Observer for Failing {
    fn wants(&self, index: usize) -> bool {
        index >= 2
    }
    fn observe(&mut self, _: &drapelab::solve::StateEvent<'_>) -> anyhow::Result<()> {
        anyhow::bail!("no space left on device")
    }
}

#[test]
fn a_failing_observer_stops_the_solve_with_its_reason_and_no_result() {
    use drapelab::solve::{Status, StopReason};
    for kind in ["static", "implicit-euler"] {
        let s = scene(
            "hang4.toml",
            &[
                "cloth.nx=11",
                "cloth.ny=11",
                &format!("solver.kind={kind}"),
                "solver.dynamic.dt_s=0.01",
            ],
        );
        let sol = drapelab::simulate::solve_scene(&s, &mut Failing);
        assert_eq!(sol.report.stop, StopReason::Observer, "{kind}");
        assert_eq!(sol.report.status, Status::Invalid, "{kind}");
        assert!(!sol.report.is_converged());
        assert!(
            sol.report.message.contains("no space left on device"),
            "{kind}: {}",
            sol.report.message
        );
        assert_eq!(sol.report.iterations, 2, "{kind}: stopped where it failed");
    }
}

#[test]
fn a_scene_made_invalid_in_code_solves_to_an_invalid_status_naming_the_key() {
    use drapelab::solve::{Status, StopReason};
    // Only a checked scene reaches the model builder: a scene changed in code after loading is
    // checked again by the solve, and a bad value is a status with the key, not a panic.
    let mut s = scene("hang4.toml", &["cloth.nx=11", "cloth.ny=11"]);
    s.cloth.nx = 1;
    let sol = solve_scene(&s, &mut drapelab::solve::NoObserver);
    assert_eq!(sol.report.status, Status::Invalid);
    assert_eq!(sol.report.stop, StopReason::Invalid);
    assert!(
        sol.report.message.contains("cloth.nx"),
        "{}",
        sol.report.message
    );
    assert!(sol.x.is_empty() && sol.grid.is_empty());
    let mut t = scene("hang4.toml", &["cloth.nx=11", "cloth.ny=11"]);
    t.material.mass_spring.as_mut().unwrap().stiffness_N_per_m = f64::NAN;
    let sol = solve_scene(&t, &mut drapelab::solve::NoObserver);
    assert_eq!(sol.report.status, Status::Invalid);
    assert!(
        sol.report.message.contains("stiffness_N_per_m"),
        "{}",
        sol.report.message
    );
    // The checked scene reads as the scene it wraps, and a change through it is checked.
    let v = scene("hang4.toml", &["cloth.nx=11", "cloth.ny=11"])
        .validated()
        .unwrap();
    assert_eq!(v.cloth.nx, 11);
    assert!(v.modify(|s| s.cloth.ny = 0).is_err());
    assert_eq!(v.modify(|s| s.cloth.ny = 21).unwrap().cloth.ny, 21);
}

/// Seed 003's studies as two stages: `seed003-solve` writes tables and `seed003-report` reads them.
/// On the Table 10.1 cantilever: loading in increments ends on the single step's equilibrium (two
/// paths to one minimum) with the deflection growing at every step; the free end converges on the
/// exact elastica at second order as the uniform grid refines; the report shows what the tables hold.
#[test]
fn seed003_solve_writes_the_cantilevers_tables_and_the_report_reads_them() {
    use drapelab::app::seed003::tables::{
        CantileverGridRow, DrapeParticleRow, LoadStepRow, Loading, Seed003SceneRow,
    };
    let pipeline = r#"
name = "t"
[stages.solve]
kind = "seed003-solve"
inputs.scenes = ["datasets/scenes/cantilever_wool_warp.toml"]
inputs.cantilever = "datasets/scenes/cantilever_wool_warp.toml"
outputs.scenes = "{run}/solve/scenes.parquet"
outputs.drapes = "{run}/solve/drapes.parquet"
outputs.load_displacement = "{run}/solve/load_displacement.parquet"
outputs.cantilever_grid = "{run}/solve/cantilever_grid.parquet"
params = { load_steps = 10 }

[stages.report]
kind = "seed003-report"
inputs.scenes = "{run}/solve/scenes.parquet"
inputs.drapes = "{run}/solve/drapes.parquet"
inputs.load_displacement = "{run}/solve/load_displacement.parquet"
inputs.cantilever_grid = "{run}/solve/cantilever_grid.parquet"
inputs.cantilever_reference = "datasets/seed003/fvm_cantilever_convergence.csv"
outputs.markdown = "{run}/report/seed003.md"
outputs.drapes = "{run}/report/seed003_drapes.svg"
params = { title = "t" }
"#;
    let (tmp, file) = crate::support::temp_project(
        &[
            "datasets/scenes/cantilever_wool_warp.toml",
            "datasets/seed003/fvm_cantilever_convergence.csv",
        ],
        "t.toml",
        pipeline,
    );
    crate::support::run_plan(&file);
    let run = tmp.path().join("runs/t/solve");
    let read = |name: &str| run.join(name);
    let scenes: Vec<Seed003SceneRow> = drapelab::io::read_table(&read("scenes.parquet")).unwrap();
    assert_eq!(scenes.len(), 1);
    let s = &scenes[0];
    assert_eq!(
        (s.status, s.fine_status),
        (Status::Converged, Status::Converged)
    );
    let gap = s.grid_gap_m.unwrap();
    assert!(gap > 0.0 && gap < 1e-3, "grid gap {gap} m");
    let drape: Vec<DrapeParticleRow> = drapelab::io::read_table(&read("drapes.parquet")).unwrap();
    assert_eq!(drape.len() as u32, s.nx * s.ny);
    let steps: Vec<LoadStepRow> =
        drapelab::io::read_table(&read("load_displacement.parquet")).unwrap();
    let inc: Vec<&LoadStepRow> = steps
        .iter()
        .filter(|r| r.loading == Loading::Increments)
        .collect();
    assert_eq!(inc.len(), 10);
    assert!(
        inc.windows(2)
            .all(|w| w[1].tip_deflection_m > w[0].tip_deflection_m)
    );
    let single = steps
        .iter()
        .find(|r| r.loading == Loading::SingleStep)
        .unwrap();
    let last = inc.last().unwrap();
    assert!(
        (last.tip_deflection_m - single.tip_deflection_m).abs() < 1e-6 * single.tip_deflection_m,
        "increments {} m, single step {} m",
        last.tip_deflection_m,
        single.tip_deflection_m
    );
    let grids: Vec<CantileverGridRow> =
        drapelab::io::read_table(&read("cantilever_grid.parquet")).unwrap();
    let off = |label: &str| {
        let g = grids.iter().find(|g| g.grid == label).unwrap();
        assert_eq!(g.status, Status::Converged, "{label}");
        (g.minus_u_m - g.exact_minus_u_m).hypot(g.w_m - g.exact_w_m)
    };
    // The grid's error falls about fourfold per halving of the spacing (second order).
    let errors: Vec<f64> = [10, 20, 40, 80]
        .iter()
        .map(|k| off(&format!("uniform {k}x1")))
        .collect();
    assert!(
        errors.windows(2).all(|w| w[0] > 3.0 * w[1]),
        "distances to the elastica on 10, 20, 40, 80 intervals: {errors:?} m"
    );
    let md = std::fs::read_to_string(tmp.path().join("runs/t/report/seed003.md")).unwrap();
    assert!(md.contains("## Table 10.1") && md.contains("## Load–displacement"));
    assert!(
        md.contains(&format!("{:.4}", single.tip_deflection_m * 100.0)),
        "{md}"
    );
}
