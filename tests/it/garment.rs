//! Issue 77's chain, from the drape tester to a garment on a body: `pipelines/garment.toml`
//! calibrates two Cusick fabrics, writes their fabric files and drapes the three-gore skirt on the
//! dress form in each (here at the pattern file's resolution and with fewer seeds, so that it runs
//! in a test).

use crate::support::{root, run_plan, run_python, temp_project};
use drapelab::scene::Fabric;

/// The pipeline at test size: two calibration and prediction seeds, the skirt unrefined, small
/// pictures.
fn quick_pipeline() -> String {
    std::fs::read_to_string(root().join("pipelines/garment.toml"))
        .unwrap()
        .replace(
            "params.fabrics = [3, 5]",
            "params.fabrics = [3, 5]\nparams.seeds = 2\nparams.calibration = { calibration_seeds = 2 }",
        )
        .replace(
            "kind = \"garment\"",
            "kind = \"garment\"\nparams.set = { \"cloth.mesh_refine\" = 0 }",
        )
        .replace(
            "params.view_deg = [-60, 10]",
            "params.view_deg = [-60, 10]\nparams.resolution = 40\nparams.picture_px = [320, 240]",
        )
}

/// The fabric files hold the calibration: bending warp and weft w g c³ (their product (w g c³)²,
/// c the calibrated bending length) with 2σ intervals around them, calibrated; tensile and shear
/// stated, not calibrated; the dataset's areal density. Each garment converged, uncrossed; the
/// limp fabric's hem flares less than the stiff one's, each inside its own interval; the glb files
/// pass the Khronos validator, the recordings open in the rerun SDK, the report names both.
#[test]
fn the_garment_pipeline_drapes_a_skirt_in_two_calibrated_fabrics() {
    let (tmp, file) = temp_project(
        &[
            "datasets/cusick/*.*",
            "datasets/cusick/fabric_03/silhouettes/*.jpg",
            "datasets/cusick/fabric_05/silhouettes/*.jpg",
            "datasets/bodies/*",
            "datasets/patterns/three_gore_skirt.obj",
        ],
        "garment.toml",
        &quick_pipeline(),
    );
    crate::cusick::keep_fabrics(&tmp.path().join("datasets/cusick"), &["3", "5"]);
    run_plan(&file);
    let run = tmp.path().join("runs/garment");
    let predictions: Vec<drapelab::stages::PredictionRow> =
        drapelab::io::read_table(&run.join("calibrate/predictions.parquet")).unwrap();
    let mut flares = Vec::new();
    for (name, fabric, density) in [("limp", 3, 0.213), ("stiff", 5, 0.274)] {
        let file = match name {
            "limp" => "viscose_white.toml",
            _ => "wool_red.toml",
        };
        let f = Fabric::read(&run.join("fabrics").join(file)).unwrap();
        assert_eq!(f.areal_density_kg_per_m2, Some(density));
        let row = predictions.iter().find(|r| r.fabric == fabric).unwrap();
        let c = row.bending_length_mean_m.unwrap();
        let m = f.continuum.as_ref().unwrap();
        let (bw, bf) = (m.bending_warp_N_m.unwrap(), m.bending_weft_N_m.unwrap());
        let b = density * 9.81 * c.powi(3);
        assert!(((bw * bf).sqrt() / b - 1.0).abs() < 1e-9, "{bw} {bf} {b}");
        for (k, v) in [("bending_warp_N_m", bw), ("bending_weft_N_m", bf)] {
            assert!(f.calibrated.contains(&k.to_string()));
            let [lo, hi] = f.intervals[k];
            assert!(lo < v && v < hi, "{k}: {lo} {v} {hi}");
        }
        assert!(
            !f.calibrated
                .iter()
                .any(|k| k.starts_with("tensile") || k.starts_with("shear"))
        );
        assert!(m.tensile_warp_N_per_m.is_some() && m.shear_N_per_m.is_some());
        let g: Vec<drapelab::app::garment::GarmentRow> =
            drapelab::io::read_table(&run.join(name).join("garment.parquet")).unwrap();
        let g = &g[0];
        assert_eq!(
            (g.status.as_str(), g.crossing_edges),
            ("converged", Some(0)),
            "{g:?}"
        );
        let (r, lo, hi) = (
            g.hem_radius_m.unwrap(),
            g.hem_radius_lo_m.unwrap(),
            g.hem_radius_hi_m.unwrap(),
        );
        assert!(lo <= r && r <= hi && lo < hi, "{g:?}");
        // A stiffer fabric flares more: the flare grows with the bending rigidity.
        assert!(g.hem_radius_per_ln_bending_m.unwrap() > 0.0, "{g:?}");
        flares.push(r);
        let glb = run.join(name).join("drape.glb");
        let report = crate::surface::gltf_validate(&glb);
        assert_eq!(report["issues"]["numErrors"], 0, "{report}");
    }
    assert!(flares[0] < flares[1], "{flares:?}");
    let out = run_python(
        r#"
import sys
from rerun.experimental import RrdReader
for p in sys.argv[1:]:
    chunks = list(RrdReader(p).stream().to_chunks())
    assert chunks, p
print("ok")
"#,
        &[&run.join("limp/drape.rrd"), &run.join("stiff/drape.rrd")],
    );
    assert!(out.contains("ok"), "{out}");
    let md = std::fs::read_to_string(tmp.path().join("reports/garment.md")).unwrap();
    assert!(
        md.contains("viscose_white") && md.contains("wool_red"),
        "{md}"
    );
    assert!(tmp.path().join("reports/garment_limp.png").is_file());
}
