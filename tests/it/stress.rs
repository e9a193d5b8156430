//! The stability stress test at a small size (issue 8): every status of every solver is reached, and a
//! Latin hypercube over Table 3's box with dt up to 10 times the stability limit ends every run in a
//! status, with no divergence passed off as a result. A failure means a solver can report garbage.

use crate::support::scene;
use drapelab::simulate::solve_scene;
use drapelab::solve::{NoObserver, Status};

#[test]
fn every_solver_reaches_every_status() {
    for kind in [
        "static",
        "explicit-euler",
        "symplectic-euler",
        "implicit-euler",
    ] {
        let k = format!("solver.kind=\"{kind}\"");
        let base = [k.as_str(), "cloth.nx=8", "cloth.ny=8"];
        let dynamic = kind != "static";
        let cases: Vec<(Status, Vec<&str>)> = vec![
            (
                Status::Converged,
                if kind == "explicit-euler" || kind == "symplectic-euler" {
                    vec![
                        "solver.dynamic.auto_dt_fraction=0.5",
                        "solver.dynamic.residual_tol_rel=1e-3",
                    ]
                } else {
                    vec![
                        "solver.dynamic.dt_s=0.01",
                        "solver.dynamic.residual_tol_rel=1e-3",
                    ]
                },
            ),
            (
                Status::MaxIterations,
                if dynamic {
                    vec![
                        "solver.dynamic.max_time_s=0.001",
                        "solver.dynamic.dt_s=1e-5",
                    ]
                } else {
                    vec!["solver.static.max_iterations=1"]
                },
            ),
            (
                Status::Diverged,
                match kind {
                    "explicit-euler" | "symplectic-euler" => {
                        vec!["solver.dynamic.auto_dt_fraction=5.0"]
                    }
                    "implicit-euler" => vec![
                        "solver.dynamic.dt_s=0.01",
                        "solver.dynamic.strain_bound=1e-9",
                    ],
                    _ => vec!["solver.static.strain_bound=1e-9"],
                },
            ),
            (
                Status::Invalid,
                vec!["cloth.nx=2", "cloth.ny=2", "solver.dynamic.dt_s=0.01"],
            ),
        ];
        for (want, sets) in cases {
            let mut all: Vec<&str> = base.to_vec();
            all.extend(sets);
            let s = scene("hang4.toml", &all);
            let sol = solve_scene(&s, &mut NoObserver);
            assert_eq!(
                sol.report.status, want,
                "{kind} with {all:?}: {}",
                sol.report.message
            );
            if want == Status::Converged {
                assert!(sol.x.iter().all(|p| p.iter().all(|c| c.is_finite())));
            }
        }
    }
}

#[test]
fn a_small_stress_sweep_finds_no_undetected_divergence() {
    let (tmp, file) = crate::support::temp_project(
        &["datasets/scenes/hang4.toml"],
        "s.toml",
        r#"
name = "s"
[stages.sweep]
kind = "sweep"
inputs.scenes = ["datasets/scenes/hang4.toml"]
outputs.table = "{run}/sweep/sweep.parquet"
[stages.sweep.params]
design = "lhs"
samples = 40
seed = 3
set = { "cloth.nx" = 8, "cloth.ny" = 8, "solver.dynamic.max_time_s" = 1.0, "solver.static.max_iterations" = 200 }
[stages.sweep.params.axes]
"material.mass_spring.stiffness_N_per_m" = { min = 500.0, max = 1200.0 }
"material.mass_spring.damping_Ns_per_m" = { min = 10.0, max = 20.0 }
"material.mass_spring.elongation_rate" = { min = 0.05, max = 0.20 }
"material.mass_spring.natural_length_m" = { min = 0.04, max = 0.06 }
"material.mass_spring.topology" = ["a", "b", "c"]
"cloth.areal_density_kg_per_m2" = { min = 0.0276, max = 0.05826 }
"solver.kind" = ["static", "explicit-euler", "symplectic-euler", "implicit-euler"]
"solver.dynamic.auto_dt_fraction" = { min = 0.05, max = 10.0 }
"cloth.initial_perturbation_m" = [0.0, 0.01]
"#,
    );
    crate::support::run_plan(&file);
    let code = r#"
import sys, polars as pl
t = pl.read_parquet(sys.argv[1])
assert t.height == 40, t.height
assert set(t["status"].unique()) <= {"converged", "max-iterations", "diverged", "invalid"}, t["status"].unique()
# A run that did not diverge carries finite numbers of a plausible size: no NaN, no exploded sheet.
ok = t.filter(pl.col("status") != "diverged")
for c in ["max_residual_N"]:
    assert ok[c].is_finite().all(), ok.filter(~pl.col(c).is_finite())
conv = t.filter(pl.col("status") == "converged")
assert conv.height > 0
assert conv["min_z_m"].is_finite().all() and (conv["min_z_m"].abs() < 1.0).all(), conv
# Far beyond the stability limit the explicit integrators must be caught diverging.
far = t.filter(pl.col("solver.kind").is_in(["explicit-euler", "symplectic-euler"])
               & (pl.col("solver.dynamic.auto_dt_fraction") > 3.0))
assert far.height > 0 and (far["status"] == "diverged").all(), far.select("solver.kind", "solver.dynamic.auto_dt_fraction", "status")
print(t.group_by("solver.kind", "status").len().sort("solver.kind"))
"#;
    let out = crate::support::run_python(code, &[&tmp.path().join("runs/s/sweep/sweep.parquet")]);
    eprintln!("{out}");
}

#[test]
fn a_dynamic_solve_past_its_wall_time_budget_ends_as_max_iterations() {
    // hang2's sway takes explicit Euler minutes to settle; a 0.2 s budget stops it with its status.
    let s = scene(
        "hang2.toml",
        &[
            "cloth.nx=11",
            "cloth.ny=11",
            "solver.kind=\"explicit-euler\"",
            "solver.dynamic.auto_dt_fraction=0.8",
            "solver.dynamic.max_time_s=1000.0",
            "solver.dynamic.max_wall_time_s=0.2",
        ],
    );
    let t = std::time::Instant::now();
    let sol = solve_scene(&s, &mut NoObserver);
    assert_eq!(
        sol.report.status,
        Status::MaxIterations,
        "{}",
        sol.report.message
    );
    assert!(
        sol.report.message.contains("wall-time budget"),
        "{}",
        sol.report.message
    );
    // It stopped near its budget, not after the 1000 s of simulated time.
    assert!(t.elapsed().as_secs_f64() < 20.0);
}
