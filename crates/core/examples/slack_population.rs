//! Seed 000's slack-net population as the calibration solves it (the benchmark stage's second
//! population table): the 14 × 14 net of a scene at `N` Latin-hypercube points of Table 3's box,
//! each from the nearest drape of the calibration's warm-start lattice, then from the lowest-energy
//! of that drape, its tangent prediction and the cubic Hermite prediction between the two length
//! nodes around the point (the lattice stores each node's sensitivities). Prints both tables, the
//! lattice's own solve time, and the floor of one solve: the time of one numeric factorization of
//! the net's Hessian and of one whole iteration's assembly (medians of 200); last, how far the
//! evaluations' drapes, solved to the calibration's looser evaluation tolerance, lie from the same
//! drapes solved to the scene's own.
//!
//! cargo run --release -p drapelab-core --example slack_population -- datasets/scenes/hang4.toml [N]

use drapelab_core::benchmark::{min_median_max, population_table, warm_start_population_with};
use drapelab_core::calibrate::EVALUATION_TOL_REL;
use drapelab_core::physics::HessianBlocks;
use drapelab_core::scene::Scene;
use drapelab_core::simulate::{solve_scene, solve_scene_from};
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
            "from the nearest node's tangent prediction x(θ₀) + (dx/dθ)(θ − θ₀) or the Hermite prediction between its two length nodes",
        ),
    ] {
        let (rows, lattice_s) = warm_start_population_with(&scene, n, 9, tangent);
        println!("\n### Each solve {what}\n\nlattice solved in {lattice_s:.3} s\n");
        print!("{}", population_table(&rows));
    }
    floor(&scene);
    tolerance_error(&scene, n);
    Ok(())
}

/// How far an evaluation's drape, solved to the calibration's evaluation tolerance
/// ([`EVALUATION_TOL_REL`]), lies from the same drape solved on to the scene's own tolerance.
fn tolerance_error(scene: &Scene, n: usize) {
    let mut net = scene.regridded(14, 14);
    net.solver.kind = drapelab_core::scene::SolverKind::Static;
    let problem = drapelab_core::calibrate::Problem::new(net.clone(), vec![], 50.0);
    let design = drapelab_core::optim::latin_hypercube(n, 3, 9);
    let worst = (0..n)
        .filter_map(|k| {
            let mut u = vec![0.5; 5];
            for (axis, &dim) in design.iter().zip(&[0usize, 3, 4]) {
                u[dim] = axis[k];
            }
            let (sol, _) = problem.drape(&u);
            let tight = problem.scene_for(&problem.bounds.decode(&u));
            let fine = solve_scene_from(&tight, &sol.x, &mut NoObserver);
            (sol.report.is_converged() && fine.report.is_converged()).then(|| {
                sol.x
                    .iter()
                    .zip(&fine.x)
                    .map(|(a, b)| (a - b).norm())
                    .fold(0.0, f64::max)
            })
        })
        .fold(0.0, f64::max);
    println!(
        "\nevaluation tolerance {EVALUATION_TOL_REL:e} of the lightest weight against the scene's {:e}: largest particle distance {worst:.2e} m over {n} points",
        net.solver.static_.residual_tol_rel
    );
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
        model.hessian(x, &mut h, drapelab_core::physics::HessianMode::NEWTON);
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
