//! Dynamics that settle (issue 19): implicit Euler as a minimisation of the incremental potential
//! lands on the static drape, the explicit integrators stop with a status at contact they cannot
//! resolve, and a timeline recorded at a frame rate has one frame per interval of simulated time.

use crate::support::{run_python, scene};
use drapelab::simulate::solve_scene;
use drapelab::solve::{NoObserver, Status, StopReason};

/// Largest distance between two drapes' particles, m.
fn largest_distance(a: &drapelab::simulate::Solution, b: &drapelab::simulate::Solution) -> f64 {
    a.x[..a.grid.len()]
        .iter()
        .zip(&b.x)
        .map(|(p, q)| (p - q).norm())
        .fold(0.0, f64::max)
}

#[test]
fn implicit_euler_settles_on_the_static_drape_of_hang4_and_the_cantilever() {
    for (file, sets) in [
        ("hang4.toml", vec!["cloth.nx=21", "cloth.ny=21"]),
        ("cantilever_wool_warp.toml", vec![]),
    ] {
        let stat = solve_scene(&scene(file, &sets), &mut NoObserver);
        assert!(
            stat.report.is_converged(),
            "{file}: {}",
            stat.report.message
        );
        let mut dynamic_sets = sets.clone();
        dynamic_sets.extend([
            "solver.kind=implicit-euler",
            "solver.dynamic.dt_s=0.01",
            "solver.dynamic.max_dt_s=10",
            "solver.dynamic.max_time_s=200",
        ]);
        let dynamic = solve_scene(&scene(file, &dynamic_sets), &mut NoObserver);
        let d = largest_distance(&dynamic, &stat);
        eprintln!(
            "{file}: {} ({} steps, {:.3} s wall, {} factorizations); largest distance to the static drape {d:.2e} m",
            dynamic.report.message,
            dynamic.report.iterations,
            dynamic.report.wall_time_s,
            dynamic.report.factorizations
        );
        assert_eq!(dynamic.report.status, Status::Converged, "{file}");
        assert_eq!(dynamic.report.solver, "implicit-euler");
        assert!(dynamic.report.iterations > 5, "{file}: a fall takes steps");
        assert!(d < 1e-4, "{file}: {d} m from the static drape");
    }
}

#[test]
fn the_adaptive_step_grows_while_newton_converges_and_is_capped() {
    let base = ["cloth.nx=11", "cloth.ny=11", "solver.kind=implicit-euler"];
    let run = |extra: &[&str]| {
        let mut sets = base.to_vec();
        sets.extend_from_slice(extra);
        solve_scene(&scene("hang4.toml", &sets), &mut NoObserver).report
    };
    let adaptive = run(&["solver.dynamic.dt_s=0.001", "solver.dynamic.max_dt_s=2"]);
    let fixed = run(&[
        "solver.dynamic.dt_s=0.001",
        "solver.dynamic.adaptive_dt=false",
        "solver.dynamic.max_time_s=1",
    ]);
    eprintln!("adaptive: {}; fixed: {}", adaptive.message, fixed.message);
    assert_eq!(adaptive.status, Status::Converged);
    // The largest step reached the cap; fixed steps of 1 ms did not settle within 1 s (1000 steps).
    assert_eq!(adaptive.dt_s, Some(2.0));
    assert!(adaptive.iterations < 100, "{} steps", adaptive.iterations);
    assert_eq!(fixed.iterations, 1000);
    assert_eq!(fixed.dt_s, Some(0.001));
    assert_eq!(fixed.status, Status::MaxIterations);
}

#[test]
fn explicit_euler_on_the_rod_stops_with_the_contact_status_not_a_divergence() {
    for kind in ["explicit-euler", "symplectic-euler"] {
        let s = scene(
            "rod_polyester.toml",
            &[
                &format!("solver.kind={kind}"),
                "solver.dynamic.auto_dt_fraction=0.8",
                "solver.dynamic.max_time_s=5",
            ],
        );
        let sol = solve_scene(&s, &mut NoObserver);
        eprintln!(
            "{kind}: {} — {}",
            sol.report.status.as_str(),
            sol.report.message
        );
        assert_eq!(sol.report.stop, StopReason::ContactTooStiff, "{kind}");
        assert_ne!(sol.report.status, Status::Diverged);
        assert_ne!(sol.report.status, Status::Converged);
        assert!(sol.report.message.contains("use implicit-euler"));
    }
}

#[test]
fn a_timeline_recorded_at_a_frame_rate_has_one_frame_per_interval() {
    let (tmp, o) = crate::recordings::simulate_hang4_recorded(&[
        "--set",
        "solver.kind=implicit-euler",
        "--set",
        "solver.dynamic.dt_s=0.005",
        "--set",
        "solver.dynamic.max_time_s=0.6",
        "--set",
        "record.frame_rate_hz=50",
    ]);
    let out = tmp.path().join("o");
    // 0.6 s is not enough to settle: the run ends with status max-iterations (exit 1), its
    // recordings written all the same.
    assert_eq!(
        o.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let py = run_python(
        r#"
import sys, json
from mcap.reader import make_reader
times = []
with open(sys.argv[1], "rb") as f:
    for schema, channel, message in make_reader(f).iter_messages(topics=["/drapelab/cloth"]):
        times.append(message.log_time)
steps = sorted(set(b - a for a, b in zip(times, times[1:])))
print(len(times), steps[0], steps[-1])
from rerun.experimental import RrdReader
assert len(RrdReader(sys.argv[2]).recordings()) == 1
"#,
        &[&out.join("timeline.mcap"), &out.join("drape.rrd")],
    );
    let v: Vec<u64> = py.split_whitespace().map(|s| s.parse().unwrap()).collect();
    // 0, 20, …, 600 ms: 31 frames, every interval 20 ms of simulated time.
    assert_eq!(v, vec![31, 20_000_000, 20_000_000], "{py}");
}
