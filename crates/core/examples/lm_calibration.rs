//! Calibration by gradients on the nine knitted samples: Levenberg–Marquardt over (stiffness,
//! natural length) per topology on the edge-curve residuals of each sample's bundled 4-corner photo,
//! the Jacobian from the drapes' sensitivities; a table of what it recovers against the ground
//! truth, its curve distance and its equilibrium solves (the warm-start lattice, shared with ICA,
//! solved once per sample beforehand and not counted).
//!
//! cargo run --release -p drapelab-core --example lm_calibration [-- SAMPLES=1,2,...,9]

use drapelab_core::calibrate::{LmSettings, Problem};
use drapelab_core::edges::{FitImageOptions, fit_image, read_camera, read_gray};
use drapelab_core::scene::Scene;
use std::path::Path;
use std::time::Instant;

fn main() -> anyhow::Result<()> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let samples: Vec<u32> = std::env::args()
        .nth(1)
        .map_or("1,2,3,4,5,6,7,8,9".into(), |s| s)
        .split(',')
        .map(str::parse)
        .collect::<Result<_, _>>()?;
    let truth = std::fs::read_to_string(root.join("datasets/knitted/ground_truth.csv"))?;
    println!(
        "| sample | truth k N/m | truth L mm | LM topology | LM k N/m | LM L mm | curve distance % | solves | lattice s | LM s |"
    );
    println!("|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|");
    for n in samples {
        let row: Vec<f64> = truth
            .lines()
            .filter(|l| !l.starts_with('#') && !l.starts_with("sample"))
            .map(|l| {
                l.split(',')
                    .map(|v| v.trim().parse().unwrap_or(f64::NAN))
                    .collect::<Vec<f64>>()
            })
            .find(|r| r[0] == n as f64)
            .ok_or_else(|| anyhow::anyhow!("sample {n} not in ground_truth.csv"))?;
        let dir = root.join(format!("datasets/knitted/sample_{n:02}/hang4"));
        let cam = read_camera(&dir.join("camera.json"))?;
        let photo = dir.join("photo.png");
        let edges = fit_image(
            &read_gray(&photo)?,
            &FitImageOptions {
                view: cam.view,
                degree: 4,
                calibration: cam.calibration(&dir.join("camera.json"))?,
                pinhole: cam.pinhole,
            },
            &photo,
        )?
        .edges;
        let set = [
            ("cloth.nx".to_string(), toml::Value::Integer(14)),
            ("cloth.ny".to_string(), toml::Value::Integer(14)),
            (
                "cloth.areal_density_kg_per_m2".to_string(),
                toml::Value::Float(row[1]),
            ),
        ];
        let scene = Scene::load(&root.join("datasets/scenes/hang4.toml"), &set)?.scene;
        let problem = Problem::new((*scene).clone(), edges, 50.0);
        let t = Instant::now();
        problem.warm_start_lattice();
        let lattice_s = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let r = problem.run_lm(&LmSettings::default());
        println!(
            "| {n} | {:.0} | {:.1} | {:?} | {:.0} | {:.2} | {:.3} | {} | {lattice_s:.1} | {:.2} |",
            row[2],
            row[3] * 1e3,
            r.best.topology,
            r.best.stiffness_N_per_m,
            r.best.natural_length_m * 1e3,
            r.best_cost_pct,
            r.solves,
            t.elapsed().as_secs_f64()
        );
    }
    Ok(())
}
