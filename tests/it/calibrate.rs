//! Calibration against a bundled photo: ICA over Table 3's box recovers the natural length used to
//! make the synthetic sample. A failure means calibration cannot find a known answer.

use crate::support::{root, scene};
use drapelab::calibrate::Problem;
use drapelab::cli::edges::read_camera;
use drapelab::edges::{Calibration, FitImageOptions, fit_image, read_gray};
use drapelab::optim::IcaSettings;

#[test]
fn ica_recovers_the_natural_length_of_a_synthetic_sample() {
    // Sample 8: 54.41 g/m², 1100 N/m, natural length 55 mm (datasets/knitted/README.md).
    let dir = root().join("datasets/knitted/sample_08/hang4");
    let cam = read_camera(&dir.join("camera.json")).unwrap();
    let photo = dir.join("photo.png");
    let img = read_gray(&photo).unwrap();
    let measured = fit_image(
        &img,
        &FitImageOptions {
            view: cam.view,
            degree: 4,
            calibration: Calibration::Given {
                px_per_cm: cam.px_per_cm,
                corners: cam.corners_px,
            },
        },
        &photo,
    )
    .unwrap()
    .edges;
    let s = scene(
        "hang4.toml",
        &[
            "cloth.nx=14",
            "cloth.ny=14",
            "cloth.areal_density_kg_per_m2=0.05441",
        ],
    );
    let problem = Problem::new(s, measured, 50.0);
    let settings = IcaSettings {
        decades: 12,
        countries: 16,
        imperialists: 3,
        beta: 2.0,
        gamma: 0.5,
        revolution_rate: 0.2,
        xi: 0.1,
        seed: 5,
    };
    let (best, report) = problem.run_ica(&settings);
    let sims = problem
        .simulations
        .load(std::sync::atomic::Ordering::Relaxed);
    eprintln!(
        "best {best:?}, cost {:.4} % of side, {} evaluations, {sims} simulations",
        report.best_cost, report.evaluations
    );
    assert!(
        (best.natural_length_m - 0.055).abs() < 0.05 * 0.055,
        "natural length {} vs 0.055",
        best.natural_length_m
    );
    assert!(
        report.best_cost < 0.2,
        "curve distance {} % of the side",
        report.best_cost
    );
}

#[test]
fn bad_calibration_configs_exit_2_naming_the_key() {
    let base = r#"
name = "knitted"
[stages.calibrate]
kind = "calibrate"
inputs = ["edges.parquet", "knitted_samples.csv", "hang4.toml"]
outputs = ["{run}/results.parquet"]
[stages.calibrate.params]
runs = 2
ica = { decades = 12, countries = 16, imperialists = 3, beta = 2.0, gamma = 0.5, revolution_rate = 0.2, xi = 0.1, seed = 1 }
"#;
    for (from, to, key) in [
        (
            "countries = 16",
            "countries = 0",
            "stages.calibrate.params.ica.countries",
        ),
        (
            "imperialists = 3",
            "imperialists = 30",
            "stages.calibrate.params.ica.imperialists",
        ),
        (
            "beta = 2.0",
            "beta = -1.0",
            "stages.calibrate.params.ica.beta",
        ),
        ("runs = 2", "runs = 0", "stages.calibrate.params.runs"),
        (
            "xi = 0.1,",
            "xi = 0.1, topology = \"d\",",
            "stages.calibrate.params.ica.topology",
        ),
        (
            "ica = {",
            "ica_from = \"x.json\"\nica = {",
            "stages.calibrate.params.ica",
        ),
    ] {
        assert!(base.contains(from), "{from}");
        let tmp = tempfile::tempdir().unwrap();
        std::fs::create_dir_all(tmp.path().join("pipelines")).unwrap();
        let file = tmp.path().join("pipelines/knitted.toml");
        std::fs::write(&file, base.replace(from, to)).unwrap();
        let o = crate::support::drapelab()
            .arg("run")
            .arg(&file)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{key}: {err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.contains(key), "{key} not named: {err}");
    }
}
