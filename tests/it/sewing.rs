//! Issue 91: garments sewn from GarmentCode patterns (`cloth.pattern`) — a pattern sewn round the
//! bundled body without crossing, welded and draped to a verified minimum; bad patterns refused
//! naming the file and key, exit 2, nothing left behind.

use crate::support::{assert_bad_input, root, run_json, simulate_ok};
use std::path::PathBuf;

fn sew_scene() -> PathBuf {
    root().join("datasets/garments/sew.toml")
}

#[test]
fn the_bundled_skirt_is_sewn_round_the_body_and_drapes_to_a_verified_minimum() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("o");
    let args = [
        "--set",
        "cloth.pattern=\"skirt_2panel_specification.json\"",
        "--set",
        "cloth.resolution_m=0.02",
        "--set",
        "record.rerun=true",
    ];
    simulate_ok(&sew_scene(), &out, &args);
    let r = run_json(&out);
    assert_eq!(r["status"], "converged", "{}", r["report"]["message"]);
    assert_eq!(r["report"]["minimum"], true);
    let sewing = &r["sewing"];
    // Every seam closed below the tolerance before welding, the welded garment crosses itself
    // nowhere (an independent edge–triangle test) and nothing entered the body.
    assert!(
        sewing["gap_before_weld_m"].as_f64().unwrap() < 1e-3,
        "{sewing}"
    );
    assert!(sewing["start_gap_m"].as_f64().unwrap() > 0.3, "{sewing}");
    assert_eq!(sewing["crossing_edges"], 0);
    assert_eq!(sewing["penetration_m"], 0.0);
    assert_eq!(r["self_contact"]["crossing_edges"], 0);
    assert_eq!(r["drape"]["max_penetration_m"], 0.0);
    // The body beside the garment, in its frame: GarmentCode's mean body, 47,500 triangles.
    let body = std::fs::read_to_string(out.join("body.obj")).unwrap();
    assert_eq!(body.lines().filter(|l| l.starts_with("f ")).count(), 47_500);
    // Held by the body alone (no pin): it rests on the hips, its hem hanging below the waist.
    let p = polars_free_z(&out);
    let (lo, hi) = p
        .iter()
        .fold((f64::MAX, f64::MIN), |(l, h), z| (l.min(*z), h.max(*z)));
    assert!(hi > 0.9 && hi < 1.15, "waist at {hi} m");
    assert!(hi - lo > 0.5, "skirt {} m long", hi - lo);
    sewing_stages_are_recorded(
        &out.join("drape.rrd"),
        sewing["stages"].as_array().unwrap().len(),
    );
}

/// rerun-sdk reads the recording's sewing: the pieces at the start and after each stage on the
/// `sewing_stage` timeline, with the largest gap per stage, before the drape's iterations.
fn sewing_stages_are_recorded(rrd: &std::path::Path, stages: usize) {
    let out = crate::support::run_python(
        r#"
import sys
from rerun.experimental import RrdReader
rows, gaps = 0, 0
for chunk in RrdReader(sys.argv[1]).stream().to_chunks():
    if "sewing_stage" not in chunk.timeline_names:
        continue
    if chunk.entity_path == "/sewing/pieces":
        rows += chunk.num_rows
    if chunk.entity_path == "/sewing/largest_gap_m":
        gaps += chunk.num_rows
print(rows, gaps)
"#,
        &[rrd],
    );
    let counts: Vec<usize> = out.split_whitespace().map(|t| t.parse().unwrap()).collect();
    assert_eq!(counts, [stages + 1, stages], "{out}");
}

/// The particles' heights of a run folder's particles.parquet.
fn polars_free_z(out: &std::path::Path) -> Vec<f64> {
    let t = drapelab_record::read_particles(&out.join("particles.parquet")).unwrap();
    t.iter().map(|p| p.2.z).collect()
}

/// The bundled skirt's pattern with `edit` applied, written into `tmp`; the scene's `--set`.
fn edited_pattern(tmp: &std::path::Path, edit: impl Fn(String) -> String) -> String {
    let text =
        std::fs::read_to_string(root().join("datasets/garments/skirt_2panel_specification.json"))
            .unwrap();
    let path = tmp.join("bad_specification.json");
    std::fs::write(&path, edit(text)).unwrap();
    format!("cloth.pattern=\"{}\"", path.display())
}

fn refused_with(set: &str, names: &[&str]) {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("o");
    let scene = sew_scene();
    let args = [
        "simulate",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--set",
        set,
    ];
    assert_bad_input(args, names);
    assert!(!out.exists(), "{names:?}: {} left behind", out.display());
}

#[test]
fn a_pattern_with_a_bad_stitch_is_refused_naming_it() {
    let tmp = tempfile::tempdir().unwrap();
    // A stitch naming a panel the pattern does not have.
    let unknown = edited_pattern(tmp.path(), |t| {
        t.replacen("\"panel\": \"skirt_back\"", "\"panel\": \"sleeve\"", 1)
    });
    refused_with(
        &unknown,
        &[
            "bad_specification.json",
            "pattern.stitches.0.1.panel",
            "sleeve",
        ],
    );
    // An edge in two stitches.
    let twice = edited_pattern(tmp.path(), |t| t.replacen("\"edge\": 3", "\"edge\": 1", 1));
    refused_with(
        &twice,
        &[
            "bad_specification.json",
            "pattern.stitches.1.0",
            "already sewn by stitch 0",
        ],
    );
    // An edge index the panel does not have.
    let edge = edited_pattern(tmp.path(), |t| t.replacen("\"edge\": 2", "\"edge\": 7", 1));
    refused_with(
        &edge,
        &["bad_specification.json", "pattern.stitches.0.1.edge"],
    );
    // Not JSON.
    let broken = edited_pattern(tmp.path(), |t| t.replacen('{', "", 1));
    refused_with(&broken, &["bad_specification.json", "not JSON"]);
}

#[test]
fn sewing_keys_out_of_range_are_refused() {
    refused_with("cloth.resolution_m=0", &["sew.toml", "cloth.resolution_m"]);
    refused_with("cloth.resolution_m=5", &["sew.toml", "cloth.resolution_m"]);
    refused_with(
        "cloth.mesh=\"../patterns/skirt.obj\"",
        &["sew.toml", "cloth.pattern"],
    );
    refused_with(
        "cloth.pattern=\"missing_specification.json\"",
        &["cloth.pattern", "missing_specification.json"],
    );
}

/// The sensitivity of a sewn skirt's hem to its fabric's bending (`--sensitivity`, from the factor
/// of the exact Hessian at the drape) against the central difference of drapes solved tightly at
/// θ(1 ± 10⁻³) from it: the hem's particles (within 1 cm of the lowest) agree to 10⁻⁴ in 2-norm
/// (measured: 3.2·10⁻⁷).
#[test]
fn a_sewn_skirts_hem_sensitivity_to_bending_matches_central_differences() {
    use drapelab::config::parse_override;
    use drapelab::params::{value, with_value};
    use drapelab::simulate::solve_scene_from;
    use drapelab::solve::NoObserver;
    const BEND: &str = "material.continuum.bending_warp_gf_cm2_per_cm";
    let sets = [
        "cloth.pattern=\"skirt_2panel_specification.json\"",
        "cloth.resolution_m=0.02",
    ];
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("o");
    let mut args: Vec<&str> = sets.iter().flat_map(|s| ["--set", s]).collect();
    args.extend(["--sensitivity", BEND]);
    simulate_ok(&sew_scene(), &out, &args);
    let rows = drapelab::io::read_sensitivities(&out.join("sensitivity.parquet")).unwrap();
    let x = drapelab_record::read_particles(&out.join("particles.parquet")).unwrap();
    let lowest = x.iter().map(|p| p.2.z).fold(f64::MAX, f64::min);
    let hem: Vec<usize> = (0..x.len()).filter(|&p| x[p].2.z < lowest + 0.01).collect();
    assert!(hem.len() > 20, "{} hem particles", hem.len());
    let mut overrides: Vec<_> = sets.iter().map(|s| parse_override(s).unwrap()).collect();
    overrides.push(parse_override("solver.static.residual_tol_rel=1e-10").unwrap());
    let scene = drapelab::scene::Scene::load(&sew_scene(), &overrides)
        .unwrap()
        .scene;
    let start: Vec<nalgebra::Vector3<f64>> = x.iter().map(|p| p.2).collect();
    let theta = value(&scene, BEND, "t").unwrap();
    let h = 1e-3 * theta;
    let side = |t: f64| {
        let s = with_value(&scene, BEND, t, "t").unwrap();
        let r = solve_scene_from(&s, &start, &mut NoObserver);
        assert!(r.report.is_converged(), "{}", r.report.message);
        r.x
    };
    let (hi, lo) = (side(theta + h), side(theta - h));
    let (mut diff, mut scale) = (0.0, 0.0);
    for &p in &hem {
        let fd = (hi[p] - lo[p]) / (2.0 * h);
        let r = &rows[p];
        let d = nalgebra::Vector3::new(r.dx_m_per_unit, r.dy_m_per_unit, r.dz_m_per_unit);
        diff += (d - fd).norm_squared();
        scale += fd.norm_squared();
    }
    let rel = (diff / scale).sqrt();
    assert!(scale > 0.0 && rel <= 1e-4, "{rel:e}");
    eprintln!("hem sensitivity to bending against central differences: {rel:.2e}");
}
