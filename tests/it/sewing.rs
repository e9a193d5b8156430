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
    simulate_ok(&sew_scene(), &out, &["--set", "cloth.resolution_m=0.02"]);
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
