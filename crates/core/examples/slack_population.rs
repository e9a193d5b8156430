//! Seed 000's slack-net population as the calibration solves it (the benchmark stage's second
//! population table): the 14 × 14 net of a scene at `N` Latin-hypercube points of Table 3's box,
//! each from the nearest drape of the calibration's warm-start lattice. Prints the table and the
//! lattice's own solve time.
//!
//! cargo run --release -p drapelab-core --example slack_population -- datasets/scenes/hang4.toml [N]

use drapelab_core::benchmark::{population_table, warm_start_population};
use drapelab_core::scene::Scene;

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let path = args
        .first()
        .ok_or_else(|| anyhow::anyhow!("usage: slack_population SCENE.toml [N]"))?;
    let n: usize = args.get(1).map(|s| s.parse()).transpose()?.unwrap_or(50);
    let scene = Scene::load(std::path::Path::new(path), &[])?.scene;
    let (rows, lattice_s) = warm_start_population(&scene, n, 9);
    println!("lattice solved in {lattice_s:.3} s\n");
    print!("{}", population_table(&rows));
    Ok(())
}
