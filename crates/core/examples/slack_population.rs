//! Seed 000's slack-net population as the calibration solves it (the benchmark stage's second
//! population table): the 14 × 14 net of a scene at `N` Latin-hypercube points of Table 3's box,
//! each from the nearest drape of the calibration's warm-start lattice, then from that drape's
//! tangent prediction (the lattice stores each node's sensitivities). Prints both tables, the
//! lattice's own solve time, and the floor of one solve: the time of one numeric factorization of
//! the net's Hessian and of one whole iteration's assembly (medians of 200).
//!
//! cargo run --release -p drapelab-core --example slack_population -- datasets/scenes/hang4.toml [N]

use drapelab_core::benchmark::{min_median_max, population_table, warm_start_population_with};
use drapelab_core::physics::HessianBlocks;
use drapelab_core::scene::Scene;
use drapelab_core::simulate::solve_scene;
use drapelab_core::solve::{DofMap, NoObserver, SparseSpd};
use std::time::Instant;

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let path = args
        .first()
        .ok_or_else(|| anyhow::anyhow!("usage: slack_population SCENE.toml [N]"))?;
    let n: usize = args.get(1).map(|s| s.parse()).transpose()?.unwrap_or(50);
    let scene = Scene::load(std::path::Path::new(path), &[])?.scene;
    for (tangent, what) in [
        (false, "from the nearest lattice node's drape"),
        (
            true,
            "from the nearest node's tangent prediction x(θ₀) + (dx/dθ)(θ − θ₀)",
        ),
    ] {
        let (rows, lattice_s) = warm_start_population_with(&scene, n, 9, tangent);
        println!("\n### Each solve {what}\n\nlattice solved in {lattice_s:.3} s\n");
        print!("{}", population_table(&rows));
    }
    floor(&scene);
    Ok(())
}

/// Median time of one factorization and of one assembly (energy, gradient, Hessian) of the 14 × 14
/// net at its drape.
fn floor(scene: &Scene) {
    let net = scene.regridded(14, 14);
    let sol = solve_scene(&net, &mut NoObserver);
    let (model, x) = (&sol.model, &sol.x);
    let dofs = DofMap::new(&model.fixed);
    let mut h = HessianBlocks::default();
    let mut g = Vec::new();
    let time = |f: &mut dyn FnMut()| {
        let t: Vec<f64> = (0..200)
            .map(|_| {
                let s = Instant::now();
                f();
                s.elapsed().as_secs_f64() * 1e3
            })
            .collect();
        min_median_max(&t).1
    };
    let assembly = time(&mut || {
        std::hint::black_box(model.energy(x, 1.0));
        model.gradient(x, 1.0, &mut g);
        model.hessian(x, &mut h, false);
    });
    let shift = vec![1e-6; dofs.n];
    let mut spd = SparseSpd::new();
    let factor = time(&mut || {
        spd.factorize(&dofs, &h, &shift);
    });
    println!(
        "\nfloor on the 14 × 14 net ({} DOFs): one factorization {factor:.3} ms, one assembly of energy, gradient and Hessian {assembly:.3} ms (medians of 200)",
        dofs.n
    );
}
