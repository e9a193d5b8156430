//! The static solve of one scene, iteration by iteration: the largest residual force (N) and the
//! energy (J) of every Newton iterate, then the solve's report and the particles with the largest
//! residual at its end (where a solve spends its last iterations). The solve is the one
//! `drapelab simulate` runs (`simulate::solve_scene`), without writing anything.
//!
//! cargo run --release -p drapelab-core --example newton_trace -- datasets/scenes/hang2.toml [key=value ...]
//!
//! `key=value` overrides any scene key (as `drapelab simulate --set`); QUIET=1 prints the report only.

use drapelab_core::scene::Scene;
use drapelab_core::simulate::{Solution, solve_scene};
use drapelab_core::solve::{Observer, StateEvent};

/// Prints each iterate's residual and energy.
struct Trace {
    quiet: bool,
}

impl Observer for Trace {
    fn wants(&self, _: usize) -> bool {
        !self.quiet
    }
    fn observe(&mut self, e: &StateEvent<'_>) -> anyhow::Result<()> {
        println!(
            "iteration {:4}  residual {:.3e} N  energy {:.9e} J",
            e.index, e.max_residual_N, e.energy_J
        );
        Ok(())
    }
}

/// The `n` free particles with the largest residual force at the end of the solve.
fn worst(sol: &Solution, n: usize) {
    let mut g = Vec::new();
    sol.model.gradient(&sol.x, 1.0, &mut g);
    let mut r: Vec<(f64, usize)> = (0..sol.x.len())
        .filter(|&p| !sol.model.fixed[p])
        .map(|p| (g[p].norm(), p))
        .collect();
    r.sort_by(|a, b| b.0.total_cmp(&a.0));
    let nx = sol.grid.nx.max(1);
    for &(f, p) in r.iter().take(n) {
        let x = sol.x[p];
        println!(
            "particle {p} (i {}, j {}): residual {f:.3e} N at ({:.5}, {:.5}, {:.5}) m",
            p % nx,
            p / nx,
            x.x,
            x.y,
            x.z
        );
    }
}

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(path) = args.first() else {
        anyhow::bail!("usage: newton_trace SCENE.toml [key=value ...]");
    };
    let mut sets = Vec::new();
    for a in &args[1..] {
        let (k, v) = a
            .split_once('=')
            .ok_or_else(|| anyhow::anyhow!("{a}: expected key=value"))?;
        let value = v
            .parse::<toml::Value>()
            .unwrap_or_else(|_| toml::Value::String(v.into()));
        sets.push((k.to_string(), value));
    }
    let scene = Scene::load(std::path::Path::new(path), &sets)?.scene;
    let quiet = std::env::var_os("QUIET").is_some();
    let sol = solve_scene(&scene, &mut Trace { quiet });
    let r = &sol.report;
    println!(
        "{path}: {:?}, {} iterations, {} factorizations, {:.3} s ({:.3} s factorizing), energy {:.9e} J",
        r.status, r.iterations, r.factorizations, r.wall_time_s, r.factor_time_s, r.energy_J
    );
    println!("{:?}; {}", r.globalization, r.message);
    if !quiet {
        worst(&sol, 8);
    }
    Ok(())
}
