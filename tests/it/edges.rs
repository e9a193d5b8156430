//! From photos to edge polynomials (seed 000 Figs 3, 11, 12) and the objective of Eq. 5. A failure
//! here means measured drape is wrong before any calibration starts.

use crate::support::{drapelab, root};
use drapelab::config::parse_override;
use drapelab::edges::score_edges;
use drapelab::edges::{
    Calibration, EdgeFit, FitImageOptions, RenderOptions, View, curve_distance_pct,
    eq5_objective_pct, fit_image,
};
use drapelab::io::{read_edges, render_scene};
use drapelab::scene::Scene;
use image::{Rgb, RgbImage};
use std::path::Path;

/// Largest vertical distance between two fitted curves over the photo fit's x range.
fn max_gap(a: &EdgeFit, b: &EdgeFit) -> f64 {
    (0..=200)
        .map(|k| a.x_min_cm + (a.x_max_cm - a.x_min_cm) * k as f64 / 200.0)
        .map(|x| (a.eval(x) - b.eval(x)).abs())
        .fold(0.0, f64::max)
}

fn rendered(
    dir: &Path,
    sets: &[&str],
    opts: &RenderOptions,
    jpeg: Option<u8>,
) -> (Vec<EdgeFit>, Vec<EdgeFit>) {
    let overrides: Vec<_> = sets.iter().map(|s| parse_override(s).unwrap()).collect();
    let loaded = Scene::load(&root().join("datasets/scenes/hang4.toml"), &overrides).unwrap();
    let photo = render_scene(&loaded, dir, opts, jpeg, 4).unwrap();
    let cam: drapelab::edges::CameraFile =
        serde_json::from_slice(&std::fs::read(dir.join("camera.json")).unwrap()).unwrap();
    let img = image::open(&photo).unwrap().to_rgb8();
    let fit = fit_image(
        &img,
        &FitImageOptions {
            view: View::Hang4,
            degree: 4,
            calibration: cam.calibration(&dir.join("camera.json")).unwrap(),
            pinhole: cam.pinhole,
        },
        &photo,
    )
    .unwrap();
    (
        fit.edges,
        read_edges(&dir.join("edges_truth.parquet"))
            .unwrap()
            .into_iter()
            .map(|(_, f)| f)
            .collect(),
    )
}

#[test]
fn fit_edges_recovers_a_known_polynomial_within_half_a_pixel() {
    // A sagging curve v(u) = v0 + f(u) between corners at u1 and u2 (same v0); fabric above it,
    // drawn with exact area coverage (8 sub-columns per pixel; pixel centres at integers).
    let (w, h, u1, u2, v0) = (520u32, 320u32, 30.0, 490.0, 60.0);
    let f = |u: f64| {
        let s = (u - u1) / (u2 - u1);
        150.0 * s * (1.0 - s) * (1.0 + 0.6 * s - 0.9 * s * s)
    };
    let mut img = RgbImage::from_pixel(w, h, Rgb([232, 232, 232]));
    for u in 0..w {
        for v in 0..h {
            let mut c = 0.0;
            for k in 0..8 {
                let uu = u as f64 - 0.5 + (k as f64 + 0.5) / 8.0;
                let edge = if (u1..=u2).contains(&uu) {
                    v0 + f(uu)
                } else {
                    v0
                };
                // Fabric spans from v0 − 30 down to the curve.
                let top = v0 - 30.0;
                c += (edge.min(v as f64 + 0.5) - top.max(v as f64 - 0.5)).clamp(0.0, 1.0) / 8.0;
            }
            let g = (232.0 * (1.0 - c) + 90.0 * c).round() as u8;
            img.put_pixel(u, v, Rgb([g, g, g]));
        }
    }
    let opts = FitImageOptions {
        view: View::Hang4,
        degree: 4,
        calibration: Calibration::Given {
            px_per_cm: 1.0,
            corners: [(u1, v0), (u2, v0)],
        },
        pinhole: None,
    };
    let fit = fit_image(&img, &opts, Path::new("synthetic.png")).unwrap();
    let e = &fit.edges[0];
    // In line coordinates (1 px = 1 cm here) the truth is y(x) = −f(u1 + x).
    let n = 400;
    let rms = ((0..n)
        .map(|k| e.x_min_cm + (e.x_max_cm - e.x_min_cm) * k as f64 / (n - 1) as f64)
        .map(|x| (e.eval(x) + f(u1 + x)).powi(2))
        .sum::<f64>()
        / n as f64)
        .sqrt();
    assert!(rms < 0.5, "RMS {rms} px along the edge");
    assert!(e.n_points > 400);
}

#[test]
fn photo_fit_agrees_with_the_particle_fit_and_survives_noise_rotation_and_jpeg() {
    let sets = ["cloth.nx=21", "cloth.ny=21"];
    let tmp = tempfile::tempdir().unwrap();
    let clean = RenderOptions {
        px_per_cm: 8.0,
        ..Default::default()
    };
    let (photo, truth) = rendered(&tmp.path().join("clean"), &sets, &clean, None);
    let sag = truth[0]
        .coefficients
        .iter()
        .enumerate()
        .map(|(p, c)| c * 25f64.powi(p as i32))
        .sum::<f64>()
        .abs();
    assert!(sag > 1.0, "hang4 sags {sag} cm at its middle");
    let gap = max_gap(&photo[0], &truth[0]);
    eprintln!(
        "clean photo vs particle fit: largest gap {gap:.4} cm = {:.3} % of the sag {sag:.3} cm",
        100.0 * gap / sag
    );
    assert!(gap < 0.01 * sag, "clean: {gap} cm of a {sag} cm sag");
    // Stated tolerance under perturbations: 2 % of the sag.
    let cases: [(&str, RenderOptions, Option<u8>); 3] = [
        (
            "noise σ = 6",
            RenderOptions {
                noise_sigma: 6.0,
                ..clean.clone()
            },
            None,
        ),
        (
            "rotation 1.5°",
            RenderOptions {
                rotation_deg: 1.5,
                ..clean.clone()
            },
            None,
        ),
        ("JPEG q = 80", clean.clone(), Some(80)),
    ];
    for (name, opts, jpeg) in cases {
        let (photo, truth) = rendered(&tmp.path().join(name.replace(' ', "_")), &sets, &opts, jpeg);
        let gap = max_gap(&photo[0], &truth[0]);
        eprintln!(
            "{name}: largest gap {gap:.4} cm = {:.3} % of the sag",
            100.0 * gap / sag
        );
        assert!(gap < 0.02 * sag, "{name}: {gap} cm of a {sag} cm sag");
    }
}

#[test]
fn markers_give_the_same_fit_as_known_corners() {
    let tmp = tempfile::tempdir().unwrap();
    let opts = RenderOptions {
        px_per_cm: 8.0,
        marker_radius_px: 4.0,
        ..Default::default()
    };
    let (given, truth) = rendered(tmp.path(), &["cloth.nx=21", "cloth.ny=21"], &opts, None);
    let img = image::open(tmp.path().join("photo.png")).unwrap().to_rgb8();
    let found = fit_image(
        &img,
        &FitImageOptions {
            view: View::Hang4,
            degree: 4,
            calibration: Calibration::Markers { side_cm: 50.0 },
            pinhole: None,
        },
        Path::new("photo.png"),
    )
    .unwrap();
    assert!(
        max_gap(&found.edges[0], &given[0]) < 0.05,
        "markers moved the curve"
    );
    assert!(max_gap(&found.edges[0], &truth[0]) < 0.05);
}

fn assert_bad_image(bytes: Option<Vec<u8>>, corners: &str, what: &str) {
    let tmp = tempfile::tempdir().unwrap();
    let photo = tmp.path().join("p.png");
    if let Some(b) = bytes {
        std::fs::write(&photo, b).unwrap();
    }
    let out = tmp.path().join("out");
    let o = drapelab()
        .arg("fit-edges")
        .arg(&photo)
        .arg("--out")
        .arg(&out)
        .args(["--px-per-cm", "8", "--corners", corners])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{what}: {err}");
    assert_eq!(
        err.lines().filter(|l| !l.trim().is_empty()).count(),
        1,
        "{what}: {err}"
    );
    assert!(
        !out.join("edges.parquet").exists(),
        "{what}: edges.parquet left behind"
    );
}

fn png(img: &RgbImage) -> Vec<u8> {
    let mut v = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut v), image::ImageFormat::Png)
        .unwrap();
    v
}

#[test]
fn bad_images_exit_2_and_write_nothing() {
    assert_bad_image(Some(Vec::new()), "10,10,100,10", "empty file");
    let mut corrupt = png(&RgbImage::from_pixel(50, 50, Rgb([200, 200, 200])));
    corrupt.truncate(corrupt.len() / 2);
    corrupt[20] ^= 0xff;
    assert_bad_image(Some(corrupt), "10,10,40,10", "corrupt PNG");
    assert_bad_image(
        Some(png(&RgbImage::from_pixel(200, 100, Rgb([230, 230, 230])))),
        "10,10,190,10",
        "all background",
    );
    // Fabric in the lower half only; corners in the empty upper half.
    let mut half = RgbImage::from_pixel(200, 100, Rgb([230, 230, 230]));
    for v in 60..100 {
        for u in 0..200 {
            half.put_pixel(u, v, Rgb([80, 80, 80]));
        }
    }
    assert_bad_image(
        Some(png(&half)),
        "10,10,190,10",
        "fabric touching no corner",
    );
    assert_bad_image(Some(png(&half)), "10,60,250,60", "corner outside the image");
}

#[test]
fn score_is_zero_for_identical_curves_symmetric_and_follows_its_formula() {
    let a = EdgeFit {
        edge: "bottom".into(),
        coefficients: vec![0.0, -0.2, 0.004, -1e-5, 2e-7],
        rms_residual_cm: 0.0,
        n_points: 50,
        x_min_cm: 0.0,
        x_max_cm: 50.0,
        systematic_pct: None,
        projection: Default::default(),
    };
    let mut b = a.clone();
    b.coefficients[2] += 0.001;
    b.coefficients[4] -= 1e-7;
    let l = 50.0;
    assert_eq!(eq5_objective_pct(&a, &a, l), 0.0);
    assert_eq!(curve_distance_pct(&a, &a, l, l), 0.0);
    assert_eq!(eq5_objective_pct(&a, &b, l), eq5_objective_pct(&b, &a, l));
    assert_eq!(
        curve_distance_pct(&a, &b, l, l),
        curve_distance_pct(&b, &a, l, l)
    );
    // A constant offset c (cm): only a₀ changes, by c, i.e. c/L normalised: Eq. 5 = 100 (c/L)/√5 and the
    // curve distance is 100 c/L.
    for c in [0.1, 0.5, 2.0] {
        let mut s = a.clone();
        s.coefficients[0] += c;
        let eq5 = eq5_objective_pct(&a, &s, l);
        assert!((eq5 - 100.0 * c / l / 5f64.sqrt()).abs() < 1e-9, "{eq5}");
        assert!((curve_distance_pct(&a, &s, l, l) - 100.0 * c / l).abs() < 1e-9);
        let rows = score_edges(&[("x".to_string(), a.clone())], &[("y".to_string(), s)], l);
        assert_eq!(rows.len(), 1);
        assert!((rows[0].objective_pct - eq5).abs() < 1e-12);
    }
}

#[test]
fn bundled_knitted_photos_measure_the_simulated_drapes() {
    // The fit-edges and score stages on the bundled synthetic dataset: every photo's curves lie within
    // 0.1 % of the side (0.05 cm) of the fits made straight from the simulated particles.
    let (tmp, file) = crate::support::temp_project(
        &["datasets/knitted/*/hang*/*"],
        "k.toml",
        r#"
name = "k"
[stages.fit2]
kind = "fit-edges"
inputs.photos = ["datasets/knitted/*/hang2/photo.png"]
inputs.cameras = ["datasets/knitted/*/hang2/camera.json"]
outputs.edges = "{run}/fit2/edges.parquet"
[stages.err2]
kind = "score"
inputs.measured = "{run}/fit2/edges.parquet"
inputs.simulated = ["datasets/knitted/*/hang2/edges_truth.parquet"]
outputs.score = "{run}/err2/score.parquet"
params = { side_cm = 50.0 }
[stages.fit4]
kind = "fit-edges"
inputs.photos = ["datasets/knitted/*/hang4/photo.png"]
inputs.cameras = ["datasets/knitted/*/hang4/camera.json"]
outputs.edges = "{run}/fit4/edges.parquet"
[stages.err4]
kind = "score"
inputs.measured = "{run}/fit4/edges.parquet"
inputs.simulated = ["datasets/knitted/*/hang4/edges_truth.parquet"]
outputs.score = "{run}/err4/score.parquet"
params = { side_cm = 50.0 }
"#,
    );
    crate::support::run_plan(&file);
    let code = r#"
import sys, polars as pl
four = pl.read_parquet(sys.argv[1]); two = pl.read_parquet(sys.argv[2])
assert four.height == 9 and two.height == 36, (four.height, two.height)
assert set(two["edge"]) == {"top", "bottom", "left", "right"}
worst = max(four["curve_distance_pct"].max(), two["curve_distance_pct"].max())
assert worst < 0.1, worst
print(worst)
"#;
    let out = crate::support::run_python(
        code,
        &[
            &tmp.path().join("runs/k/err4/score.parquet"),
            &tmp.path().join("runs/k/err2/score.parquet"),
        ],
    );
    eprintln!(
        "worst photo-vs-simulation curve distance: {}% of the side",
        out.trim()
    );
}
