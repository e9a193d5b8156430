//! Issue 92, item 1: a restart continues the run it restarts. What a solve adapted in its model
//! (the self-contact κ growth) is written with the drape and taken up by `--start`, so that a
//! converged drape restarted at its own parameters comes back unchanged in 0 iterations, and
//! differences of restarted drapes are the derivative `--sensitivity` gives of the model that
//! made the drape.

use crate::support::{root, run_json, simulate_ok as simulate};
use drapelab::io::{read_particles, read_sensitivities};

const BEND: &str = "material.continuum.bending_warp_gf_cm2_per_cm";

type V3 = nalgebra::Vector3<f64>;

/// Σ aᵢ · bᵢ over particles.
fn dot(a: &[V3], b: &[V3]) -> f64 {
    a.iter().zip(b).map(|(u, w)| u.dot(w)).sum()
}

fn sphere_wool() -> std::path::PathBuf {
    root().join("datasets/scenes/sphere_wool.toml")
}

#[test]
fn a_restart_at_the_same_parameters_returns_the_drape_in_zero_iterations() {
    let tmp = tempfile::tempdir().unwrap();
    let (a, b) = (tmp.path().join("a"), tmp.path().join("b"));
    simulate(&sphere_wool(), &a, &[]);
    let growth = run_json(&a)["self_contact"]["kappa_growth"]
        .as_f64()
        .unwrap();
    // The case the issue found: the solve stiffened κ where layers pressed.
    assert!(growth > 1.0, "κ growth {growth}");
    let saved = a.join("particles.parquet");
    simulate(&sphere_wool(), &b, &["--start", saved.to_str().unwrap()]);
    let rb = run_json(&b);
    assert_eq!(rb["report"]["iterations"], 0, "{}", rb["report"]["message"]);
    assert_eq!(rb["start"]["kappa_growth_taken_up"].as_f64(), Some(growth));
    assert_eq!(rb["self_contact"]["kappa_growth"].as_f64(), Some(growth));
    let (pa, pb) = (
        read_particles(&saved).unwrap(),
        read_particles(&b.join("particles.parquet")).unwrap(),
    );
    let moved = pa
        .iter()
        .zip(&pb)
        .map(|(p, q)| (p.2 - q.2).norm())
        .fold(0.0, f64::max);
    assert!(moved <= 1e-12, "the restart moved the drape by {moved:e} m");
}

/// A table written elsewhere (no drapelab metadata) starts the model as built and run.json says so.
#[test]
fn a_start_without_solve_state_starts_the_model_as_built_and_says_so() {
    let tmp = tempfile::tempdir().unwrap();
    let (a, b) = (tmp.path().join("a"), tmp.path().join("b"));
    simulate(&sphere_wool(), &a, &[]);
    let bare = tmp.path().join("bare.parquet");
    let rows = read_particles(&a.join("particles.parquet")).unwrap();
    let x: Vec<_> = rows.iter().map(|r| r.2).collect();
    let grid = crate::support::scene("sphere_wool.toml", &[]).grid();
    assert_eq!(grid.len(), x.len());
    drapelab::io::write_particles(&bare, &grid, &x, &[], &[]).unwrap();
    simulate(&sphere_wool(), &b, &["--start", bare.to_str().unwrap()]);
    let rb = run_json(&b);
    assert_eq!(rb["start"]["kappa_growth_taken_up"].as_f64(), Some(1.0));
    let note = rb["start"]["note"].as_str().unwrap();
    assert!(note.contains("no solve state"), "{note}");
}

/// Central differences of drapes restarted from the drape at θ(1 ± 10⁻⁴) agree with
/// `--sensitivity` of that drape within 10⁻⁴ (measured 1.0e-5), orthogonal to the free turn about
/// the sphere's axis (they disagreed when the restarts began at κ growth 1 while the drape's own
/// solve had grown it 4×).
#[test]
fn differences_of_restarted_drapes_are_the_sensitivity() {
    let tmp = tempfile::tempdir().unwrap();
    let a = tmp.path().join("a");
    simulate(&sphere_wool(), &a, &["--sensitivity", BEND]);
    let saved = a.join("particles.parquet");
    let theta = 0.083;
    let h = 1e-4 * theta;
    let side = |t: f64, name: &str| {
        let out = tmp.path().join(name);
        let set = format!("{BEND}={t}");
        let start = saved.to_str().unwrap();
        simulate(&sphere_wool(), &out, &["--start", start, "--set", &set]);
        read_particles(&out.join("particles.parquet")).unwrap()
    };
    let (hi, lo) = (side(theta + h, "hi"), side(theta - h, "lo"));
    let rows = read_sensitivities(&a.join("sensitivity.parquet")).unwrap();
    let x = read_particles(&saved).unwrap();
    let fd: Vec<V3> = (0..x.len())
        .map(|p| (hi[p].2 - lo[p].2) / (2.0 * h))
        .collect();
    let d: Vec<V3> = rows
        .iter()
        .map(|r| V3::new(r.dx_m_per_unit, r.dy_m_per_unit, r.dz_m_per_unit))
        .collect();
    // The sheet on a frictionless sphere is free to turn about z (run.json's neutral mode): the
    // sensitivity is the derivative orthogonal to that turn, and a restarted drape may turn along
    // it; compare the parts orthogonal to it.
    let modes = run_json(&a)["neutral_modes"].as_array().unwrap().clone();
    assert_eq!(modes.len(), 1, "{modes:?}");
    let v3 = |j: &serde_json::Value| {
        V3::new(
            j[0].as_f64().unwrap(),
            j[1].as_f64().unwrap(),
            j[2].as_f64().unwrap(),
        )
    };
    let (axis, through) = (v3(&modes[0]["axis"]), v3(&modes[0]["through_m"]));
    let turn: Vec<V3> = x.iter().map(|p| axis.cross(&(p.2 - through))).collect();
    let along = |v: &[V3]| -> Vec<V3> {
        let c = dot(v, &turn) / dot(&turn, &turn);
        v.iter().zip(&turn).map(|(a, t)| a - t * c).collect()
    };
    let (d, fd) = (along(&d), along(&fd));
    let diff: Vec<V3> = d.iter().zip(&fd).map(|(a, b)| a - b).collect();
    let rel = (dot(&diff, &diff) / dot(&fd, &fd)).sqrt();
    eprintln!("restarted differences against --sensitivity: {rel:.2e}");
    assert!(rel <= 1e-4, "{rel:e}");
}
