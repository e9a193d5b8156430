//! What sensitivities cost beside the solve they differentiate: for a scene at several grid sizes,
//! the solve's wall time, the factor of the exact Hessian at the equilibrium, and each key's
//! sensitivity (two model builds and gradients for ∂g/∂θ, one back-substitution), as a table.
//! Medians of `R` repetitions (default 3), each solve from the scene's own start.
//!
//! cargo run --release -p drapelab-core --example sensitivity_cost -- datasets/scenes/hang4.toml \
//!     material.mass_spring.stiffness_N_per_m [SIDES=11,41,81] [R=3]

use drapelab_core::benchmark::min_median_max;
use drapelab_core::scene::Scene;
use drapelab_core::sensitivity::Equilibrium;
use drapelab_core::simulate::solve_scene;
use drapelab_core::solve::NoObserver;
use std::time::Instant;

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (Some(path), Some(key)) = (args.first(), args.get(1)) else {
        anyhow::bail!("usage: sensitivity_cost SCENE.toml KEY [SIDES=11,41,81] [R=3]");
    };
    let sides: Vec<usize> = args
        .get(2)
        .map_or("11,41,81", String::as_str)
        .split(',')
        .map(str::parse)
        .collect::<Result<_, _>>()?;
    let reps: usize = args.get(3).map(|s| s.parse()).transpose()?.unwrap_or(3);
    println!("scene {path}, key {key}, medians of {reps}\n");
    println!("| side | particles | solve s | factor s | one key s | factor + key / solve |");
    println!("|---:|---:|---:|---:|---:|---:|");
    for n in sides {
        let set = [
            ("cloth.nx".to_string(), toml::Value::Integer(n as i64)),
            ("cloth.ny".to_string(), toml::Value::Integer(n as i64)),
        ];
        let scene = Scene::load(std::path::Path::new(path), &set)?.scene;
        let (mut solve, mut factor, mut one) = (Vec::new(), Vec::new(), Vec::new());
        let mut particles = 0;
        for _ in 0..reps {
            let t = Instant::now();
            let sol = solve_scene(&scene, &mut NoObserver);
            solve.push(t.elapsed().as_secs_f64());
            particles = sol.grid.len();
            let t = Instant::now();
            let mut eq = Equilibrium::new(&scene, &sol.model, &sol.x, &sol.report, "--key")
                .map_err(|e| anyhow::anyhow!("{e}"))?;
            factor.push(t.elapsed().as_secs_f64());
            let t = Instant::now();
            eq.sensitivity(key).map_err(|e| anyhow::anyhow!("{e}"))?;
            one.push(t.elapsed().as_secs_f64());
        }
        let m = |v: &[f64]| min_median_max(v).1;
        let (s, f, k) = (m(&solve), m(&factor), m(&one));
        println!(
            "| {n} | {particles} | {s:.3} | {f:.4} | {k:.4} | {:.1} % |",
            100.0 * (f + k) / s
        );
    }
    Ok(())
}
