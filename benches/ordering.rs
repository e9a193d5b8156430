//! `cargo bench --bench ordering [-- SCENE "N1 N2 …"]`: the Cholesky factor of a sheet's
//! Hessian under AMD and under nested dissection of its particles (`FillOrdering`), printed as a
//! Markdown table: non-zeros of the factor and the best of three numeric factorizations. The
//! Hessian is the projected one at the scene's start on an N × N grid, shifted by 10⁻⁶ of its mean
//! diagonal. Defaults: hang4 on 41, 81, 161 and 321 a side. Run it alone: the times are wall times.

use drapelab::physics::HessianBlocks;
use drapelab::solve::{DofMap, FillOrdering, SparseSpd};
use std::time::Instant;

fn main() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| a != "--bench")
        .collect();
    let scene = args
        .first()
        .cloned()
        .unwrap_or("datasets/scenes/hang4.toml".into());
    let sizes: Vec<usize> = args.get(1).map_or(vec![41, 81, 161, 321], |s| {
        s.split_whitespace()
            .map(|n| n.parse().expect("grid size"))
            .collect()
    });
    println!(
        "| scene | grid | free particles | ordering | factor non-zeros | ms a factorization |"
    );
    println!("|---|---|---:|---|---:|---:|");
    for n in sizes {
        let set = |k: &str| (k.to_string(), toml::Value::Integer(n as i64));
        let loaded =
            drapelab::scene::Scene::load(&root.join(&scene), &[set("cloth.nx"), set("cloth.ny")])
                .expect("a bundled scene");
        let built = drapelab::build::build_scene(&loaded.scene);
        let mut h = HessianBlocks::default();
        built
            .model
            .hessian(&built.x0, &mut h, drapelab::physics::HessianMode::Projected);
        let dofs = DofMap::new(&built.model.fixed);
        let diagonal = h.diagonal(built.x0.len());
        let free = (0..built.x0.len()).filter(|&p| dofs.dof(p).is_some());
        let mean = free.map(|p| diagonal[p].trace()).sum::<f64>() / dofs.n.max(1) as f64;
        let shift = vec![1e-6 * mean; dofs.n];
        for ordering in [FillOrdering::Amd, FillOrdering::NestedDissection] {
            let mut spd = SparseSpd::with_ordering(ordering);
            let mut best = f64::INFINITY;
            let mut ok = true;
            for _ in 0..3 {
                let t = Instant::now();
                ok &= spd.factorize(&dofs, &h, &shift);
                best = best.min(t.elapsed().as_secs_f64());
            }
            let ms = if ok {
                format!("{:.1}", 1e3 * best)
            } else {
                "not SPD".into()
            };
            let name = std::path::Path::new(&scene)
                .file_stem()
                .unwrap()
                .to_string_lossy()
                .to_string();
            println!(
                "| {name} | {n}² | {} | {ordering:?} | {} | {ms} |",
                dofs.n / 3,
                spd.factor_nonzeros()
            );
        }
    }
}
