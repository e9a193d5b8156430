//! The static equilibria of the reference scenes stay where they were before the faster Newton
//! (issue 14): `datasets/equilibria/*.csv` hold the positions that the solver of commit d2b0225 found
//! (written once by `DRAPELAB_WRITE_EQUILIBRIA=1 cargo test --release -- equilibria`); the solver of
//! today must land on the same points (largest particle distance below 1e-8 m), or, for a scene with
//! mirror pairs, on the mirror image, a minimum of the energy. A scene with several minima (a drape
//! folding on the pedestal, a sheet rolling off the rod: which one Newton lands on depends on its
//! path, issue 34) must land on a minimum, and the reference must still be an equilibrium of
//! today's model; the test prints which of the two has the lower energy.

use crate::support::{root, scene};
use drapelab::simulate::{Solution, solve_scene};
use drapelab::solve::NoObserver;
use nalgebra::Vector3;

/// A symmetry of a scene that maps one equilibrium onto another.
#[derive(Clone, Copy)]
enum Symmetry {
    /// Reflection of every particle's position in the plane x[axis] = c.
    Reflect(usize, f64),
    /// Half turn about the vertical axis through the origin, particle (i, j) → (n−1−i, n−1−j).
    HalfTurn,
}

/// (reference file, scene, overrides, the scene's symmetry when it has mirror pairs, whether it
/// has several minima that Newton's path chooses between).
type Case = (
    &'static str,
    &'static str,
    &'static [&'static str],
    Option<Symmetry>,
    bool,
);

const CASES: [Case; 6] = [
    (
        "hang4_21",
        "hang4.toml",
        &["cloth.nx=21", "cloth.ny=21"],
        None,
        false,
    ),
    (
        "hang4_41",
        "hang4.toml",
        &["cloth.nx=41", "cloth.ny=41"],
        None,
        false,
    ),
    // The 2-corner hang can curl to either side of the vertical plane through its pinned edge.
    (
        "hang2_21",
        "hang2.toml",
        &["cloth.nx=21", "cloth.ny=21"],
        Some(Symmetry::Reflect(1, 0.5)),
        false,
    ),
    (
        "cantilever_wool_warp",
        "cantilever_wool_warp.toml",
        &[],
        None,
        false,
    ),
    // The drape folds on the pedestal: where the folds fall depends on Newton's path.
    (
        "pedestal_wool_21",
        "pedestal_wool.toml",
        &["cloth.nx=21", "cloth.ny=21"],
        None,
        true,
    ),
    // Without friction the sheet rolls off the rod's crest to one side or the other: the scene is
    // symmetric under a half turn about the vertical (pins, rod axis and warp/weft all map onto
    // themselves), so its equilibria come in pairs.
    (
        "rod_polyester",
        "rod_polyester.toml",
        &[],
        Some(Symmetry::HalfTurn),
        true,
    ),
];

/// The tolerance both the reference and today's solve converge to (tighter than the scenes' own, so
/// that positions are fixed to far below 1e-8 m).
const TOL: &str = "solver.static.residual_tol_rel=1e-10";
const TOL_ROD: &str = "solver.static.residual_tol_rel=1e-8";

fn read_csv(path: &std::path::Path) -> Vec<Vector3<f64>> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("particle"))
        .map(|l| {
            let v: Vec<f64> = l
                .split(',')
                .skip(1)
                .map(|s| s.parse().expect("number"))
                .collect();
            Vector3::new(v[0], v[1], v[2])
        })
        .collect()
}

fn write_csv(path: &std::path::Path, x: &[Vector3<f64>]) {
    let mut s = String::from(
        "# Static equilibrium solved by drapelab at commit d2b0225 (before issue 14's Newton changes), \
residual_tol_rel 1e-10; written by tests/it/equilibria.rs with DRAPELAB_WRITE_EQUILIBRIA=1.\n\
particle,x_m,y_m,z_m\n",
    );
    for (p, v) in x.iter().enumerate() {
        s += &format!("{p},{:.17e},{:.17e},{:.17e}\n", v.x, v.y, v.z);
    }
    std::fs::create_dir_all(path.parent().expect("parent")).expect("mkdir");
    std::fs::write(path, s).expect("write");
}

fn largest_distance(a: &[Vector3<f64>], b: &[Vector3<f64>]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(p, q)| (p - q).norm())
        .fold(0.0, f64::max)
}

#[test]
fn equilibria_are_the_same_as_before_the_faster_newton() {
    let write = std::env::var("DRAPELAB_WRITE_EQUILIBRIA").is_ok();
    let mut failures = Vec::new();
    for (file, name, sets, mirror, several) in CASES {
        let mut sets = sets.to_vec();
        // The rod (barrier contact, 33² with its pins by index) stalls short of 1e-10 with the old
        // solver; 1e-8 still fixes its positions far below 1e-8 m.
        sets.push(if name.starts_with("rod") {
            TOL_ROD
        } else {
            TOL
        });
        let s = scene(name, &sets);
        let sol = solve_scene(&s, &mut NoObserver);
        assert!(sol.report.is_converged(), "{file}: {}", sol.report.message);
        let x = sol.grid_positions();
        let path = root()
            .join("datasets/equilibria")
            .join(format!("{file}.csv"));
        if write {
            write_csv(&path, x);
            continue;
        }
        let reference = read_csv(&path);
        assert_eq!(reference.len(), x.len(), "{file}: particle count");
        let mut d = largest_distance(x, &reference);
        if let Some(sym) = mirror {
            let n = reference.len();
            let mirrored: Vec<_> = (0..n)
                .map(|p| match sym {
                    Symmetry::Reflect(axis, c) => {
                        let mut q = reference[p];
                        q[axis] = 2.0 * c - q[axis];
                        q
                    }
                    Symmetry::HalfTurn => {
                        let q = reference[n - 1 - p];
                        Vector3::new(-q.x, -q.y, q.z)
                    }
                })
                .collect();
            let dm = largest_distance(x, &mirrored);
            if dm < d {
                // The mirror image: the same energy, and a minimum.
                assert_eq!(sol.report.minimum, Some(true), "{file}: not a minimum");
                d = dm;
            }
        }
        eprintln!(
            "{file}: largest distance {d:.2e} m, {} iterations, {} linear solves",
            sol.report.iterations, sol.report.linear_solves
        );
        if d >= 1e-8 && several {
            another_minimum(file, &sol, &reference, &mut failures);
        } else if d >= 1e-8 {
            failures.push(format!("{file}: {d:.3e} m from the reference"));
        }
    }
    assert!(failures.is_empty(), "{failures:?}");
}

/// A scene with several minima that landed away from its reference: today's state must be a
/// minimum, and the reference an equilibrium of today's model (its largest residual force within
/// 1e-6 of a particle's weight); prints which has the lower energy.
fn another_minimum(
    file: &str,
    sol: &drapelab::simulate::Solution,
    reference: &[Vector3<f64>],
    failures: &mut Vec<String>,
) {
    if sol.report.minimum != Some(true) {
        failures.push(format!("{file}: another equilibrium, not a minimum"));
        return;
    }
    let mut x_ref = sol.x.clone();
    x_ref[..reference.len()].copy_from_slice(reference);
    let mut g = Vec::new();
    sol.model.gradient(&x_ref, 1.0, &mut g);
    let r_rel = sol.model.max_residual(&g) / sol.model.reference_weight();
    let (e_ref, e_now) = (sol.model.energy(&x_ref, 1.0), sol.model.energy(&sol.x, 1.0));
    eprintln!(
        "{file}: another minimum; energy {e_now:.9e} J against the reference's {e_ref:.9e} J ({}), \
the reference's residual {r_rel:.1e} of a weight",
        if e_now < e_ref { "lower" } else { "higher" }
    );
    if r_rel > 1e-6 {
        failures.push(format!(
            "{file}: the reference is no longer an equilibrium (residual {r_rel:.2e} of a weight)"
        ));
    }
}

#[test]
fn the_curved_step_lands_on_the_same_equilibrium_in_fewer_iterations() {
    // The cantilever has one equilibrium: straight and curved steps (geodesic acceleration) must
    // land on it alike, the curved ones in fewer iterations (the strip turns about its clamp); the
    // report's steps add up to its iterations.
    let curved = solve_scene(&scene("cantilever_wool_warp.toml", &[TOL]), &mut NoObserver);
    let straight = solve_scene(
        &scene(
            "cantilever_wool_warp.toml",
            &[TOL, "solver.static.direction=straight"],
        ),
        &mut NoObserver,
    );
    assert!(curved.report.is_converged() && straight.report.is_converged());
    let d = largest_distance(curved.grid_positions(), straight.grid_positions());
    assert!(d < 1e-8, "{d} m apart");
    let (c, s) = (&curved.report, &straight.report);
    eprintln!(
        "cantilever: {} iterations curved, {} straight",
        c.iterations, s.iterations
    );
    assert!(c.iterations < s.iterations);
    assert!(c.globalization.curved_steps > 0 && s.globalization.curved_steps == 0);
    for r in [c, s] {
        let g = &r.globalization;
        assert_eq!(
            g.full_steps + g.shortened_steps + g.bounded_steps,
            r.iterations
        );
    }
}

#[test]
fn the_folded_start_lands_on_the_same_hang_in_fewer_iterations() {
    // Sheets pinned along one line swing down about it: the folded start (start = "nested", the
    // default) and the flat start ("nested-flat") must reach the same equilibrium (or its mirror image, a curl to the other
    // side), a minimum, the folded one in fewer Newton iterations.
    for (name, mirror) in [
        ("hang2.toml", Some(Symmetry::Reflect(1, 0.5))),
        ("diagonal_corners_wool.toml", None),
    ] {
        let folded = solve_scene(&scene(name, &[TOL]), &mut NoObserver);
        let flat = solve_scene(
            &scene(name, &[TOL, "solver.static.start=nested-flat"]),
            &mut NoObserver,
        );
        let mut d = both_converged_apart(name, &folded, &flat);
        let (a, b) = (&folded.report, &flat.report);
        assert_eq!(a.minimum, Some(true), "{name}");
        let (x, y) = (folded.grid_positions(), flat.grid_positions());
        if let Some(Symmetry::Reflect(axis, c)) = mirror {
            let m: Vec<_> = y
                .iter()
                .map(|q| {
                    let mut q = *q;
                    q[axis] = 2.0 * c - q[axis];
                    q
                })
                .collect();
            d = d.min(largest_distance(x, &m));
        }
        eprintln!(
            "{name}: {} iterations folded, {} flat, {d:.1e} m apart",
            a.iterations, b.iterations
        );
        assert!(d < 1e-8, "{name}: {d} m apart");
        assert!(a.iterations < b.iterations, "{name}");
    }
}

/// Asserts that both solves converged (naming `what` and their messages); how far apart their
/// drapes are (m).
fn both_converged_apart(what: &str, first: &Solution, second: &Solution) -> f64 {
    let (a, b) = (&first.report, &second.report);
    assert!(
        a.is_converged() && b.is_converged(),
        "{what}: {} / {}",
        a.message,
        b.message
    );
    largest_distance(first.grid_positions(), second.grid_positions())
}

/// hang4 on 81 × 81 (from the 41 × 41 drape, itself from 21 × 21 and 11 × 11) solved with
/// either of two settings: both converged, the second a minimum, the same unique hang within
/// 10⁻⁸ m; with how far apart their drapes are (m).
fn hang4_81_two_ways(a: &str, b: &str) -> (Solution, Solution, f64) {
    let at = |setting: &str| {
        let s = scene("hang4.toml", &[TOL, "cloth.nx=81", "cloth.ny=81", setting]);
        solve_scene(&s, &mut NoObserver)
    };
    let (first, second) = (at(a), at(b));
    let d = both_converged_apart("hang4 81²", &first, &second);
    let (ra, rb) = (&first.report, &second.report);
    eprintln!(
        "hang4 81², {a} / {b}: {} / {} factorizations, {d:.1e} m apart",
        ra.factorizations, rb.factorizations
    );
    assert_eq!(rb.minimum, Some(true));
    assert!(d < 1e-8, "{d} m apart");
    (first, second, d)
}

#[test]
fn a_warm_nested_path_lands_on_the_same_hang_with_fewer_factorizations() {
    // With `nested_path = "warm"` the finer grids take straight steps with the damping carried
    // on. The same equilibrium (a unique hang), a minimum, with fewer factorizations.
    let (given, warm, _) = hang4_81_two_ways(
        "solver.static.nested_path=as-given",
        "solver.static.nested_path=warm",
    );
    assert!(warm.report.factorizations < given.report.factorizations);
}

#[test]
fn nested_dissection_and_amd_land_on_the_same_hang() {
    // The fill-reducing ordering changes round-off only: the same unique hang, a minimum; not
    // the same bits (the key reached the factorization).
    let (_, _, d) = hang4_81_two_ways(
        "solver.static.ordering=amd",
        "solver.static.ordering=nested-dissection",
    );
    assert!(
        d > 0.0,
        "the same bits: the ordering key did not reach the factorization"
    );
}

#[test]
fn a_shift_that_fails_means_every_smaller_one_fails() {
    // The static solve skips the ladder of shifts of an indefinite exact Hessian when its top
    // fails: that is the same step only if positive definiteness grows with the shift. Check it on
    // a compressed hang4 (every spring shorter than its rest length: an indefinite Hessian).
    use drapelab::physics::HessianBlocks;
    use drapelab::solve::{DofMap, SparseSpd};
    let s = scene("hang4.toml", &["cloth.nx=21", "cloth.ny=21"]);
    let built = drapelab::build::build_scene(&s.validated().expect("valid"));
    let (model, mut x) = (built.model, built.x0);
    for p in &mut x {
        p.x *= 0.9;
        p.y *= 0.9;
    }
    let mut h = HessianBlocks::default();
    model.hessian(&x, &mut h, drapelab::physics::HessianMode::NEWTON);
    let dofs = DofMap::new(&model.fixed);
    let mean = h
        .diagonal(model.len())
        .iter()
        .map(|d| d.trace())
        .sum::<f64>()
        / dofs.n as f64;
    let mut spd = SparseSpd::new();
    let pd: Vec<bool> = (-12..=1)
        .map(|k| spd.factorize(&dofs, &h, &vec![10f64.powi(k) * mean; dofs.n]))
        .collect();
    eprintln!("positive definite from 1e-12 to 1e1 of the mean diagonal: {pd:?}");
    assert!(!pd[0] && pd[pd.len() - 1], "{pd:?}");
    let first = pd.iter().position(|&ok| ok).expect("one shift works");
    assert!(pd[first..].iter().all(|&ok| ok), "{pd:?}");
}

#[test]
fn reusing_the_factorization_lands_on_the_same_equilibrium_with_fewer_factorizations() {
    // Chord steps (the factor at hand reused while whole steps halve the residual) change the
    // path's last iterations only: from a warm start near the answer (the drape at 98 % of the
    // weight), as the calibration uses them, the same equilibrium to 1e-8 m, never more
    // factorizations and fewer over the three (hang4 21²: 7 → 2), every chord step a whole one.
    let reuse = "solver.static.factor_reuse=chord";
    let (mut reusing, mut not) = (0, 0);
    for (name, sets, lighter) in [
        (
            "hang4.toml",
            [TOL, "cloth.nx=21", "cloth.ny=21"],
            "cloth.areal_density_kg_per_m2=0.0441",
        ),
        (
            "hang2.toml",
            [TOL, "cloth.nx=21", "cloth.ny=21"],
            "cloth.areal_density_kg_per_m2=0.0441",
        ),
        (
            "cantilever_wool_warp.toml",
            [TOL, "cloth.nx=41", "cloth.ny=3"],
            "cloth.areal_density_kg_per_m2=0.1862",
        ),
    ] {
        let near = solve_scene(
            &scene(name, &[&sets[..], &[lighter]].concat()),
            &mut NoObserver,
        );
        assert!(
            near.report.is_converged(),
            "{name}: {}",
            near.report.message
        );
        let warm = |extra: &[&str]| {
            let s = scene(name, &[&sets[..], extra].concat());
            drapelab::simulate::solve_scene_from(&s, &near.x, &mut NoObserver)
        };
        let (with, without) = (warm(&[reuse]), warm(&[]));
        let d = both_converged_apart(name, &with, &without);
        let (a, b) = (&with.report, &without.report);
        eprintln!(
            "{name}: {} factorizations, {} iterations ({} chord steps) reusing; {} and {} not; {d:.1e} m apart",
            a.factorizations,
            a.iterations,
            a.globalization.chord_steps,
            b.factorizations,
            b.iterations
        );
        assert!(d < 1e-8, "{name}: {d} m apart");
        assert!(
            a.globalization.chord_steps > 0 && b.globalization.chord_steps == 0,
            "{name}"
        );
        assert!(a.factorizations <= b.factorizations, "{name}");
        (reusing, not) = (reusing + a.factorizations, not + b.factorizations);
        let g = &a.globalization;
        assert_eq!(
            g.full_steps + g.shortened_steps + g.bounded_steps,
            a.iterations,
            "{name}"
        );
    }
    assert!(reusing < not, "{reusing} factorizations reusing, {not} not");
}
