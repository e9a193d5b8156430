//! Tension-field wrinkles (seed 002): the trends the seed states on its own Tables I–IV, Simpson's rule
//! against closed forms, convergence of the iteration, the mesh's folds, real readers of the outputs,
//! and bad inputs. A failure means the wrinkle model no longer behaves as the theory says.

use crate::support::{drapelab, root};
use drapelab::wrinkles::{
    WrinkleConfig, WrinkleResult, boundary_length_m, count_folds, load_config, simpson, solve,
    wrinkle_mesh,
};

fn seed_tables() -> WrinkleConfig {
    load_config(&root().join("datasets/wrinkles/seed_tables.toml")).unwrap()
}

fn solved(cfg: &WrinkleConfig, prefix: &str) -> Vec<WrinkleResult> {
    cfg.cases
        .iter()
        .filter(|c| c.case.starts_with(prefix))
        .map(|c| solve(&c.inputs(&cfg.defaults)))
        .collect()
}

#[test]
fn wrinkles_follow_the_trends_the_seed_states() {
    let cfg = seed_tables();
    let (t1, t2, t3, t4) = (
        solved(&cfg, "I-"),
        solved(&cfg, "II-"),
        solved(&cfg, "III-"),
        solved(&cfg, "IV-"),
    );
    for t in [&t1, &t2, &t3, &t4] {
        assert_eq!(t.len(), 3);
        assert!(t.iter().all(|r| r.converged), "{t:?}");
    }
    let n = |t: &[WrinkleResult]| t.iter().map(|r| r.n).collect::<Vec<_>>();
    let q = |t: &[WrinkleResult]| t.iter().map(|r| r.q).collect::<Vec<_>>();
    let rising = |v: &[usize]| v.windows(2).all(|w| w[1] > w[0]);
    let falling = |v: &[usize]| v.windows(2).all(|w| w[1] < w[0]);
    // n grows with h (Table I) and with w (Table II), falls with t (III) and with E (IV).
    assert!(rising(&n(&t1)), "n against h: {:?}", n(&t1));
    assert!(rising(&n(&t2)), "n against w: {:?}", n(&t2));
    assert!(falling(&n(&t3)), "n against t: {:?}", n(&t3));
    assert!(falling(&n(&t4)), "n against E: {:?}", n(&t4));
    // Q falls as w grows, rises with t, and is higher at Table IV's highest E than at its lowest.
    let (q2, q3, q4) = (q(&t2), q(&t3), q(&t4));
    assert!(q2.windows(2).all(|w| w[1] < w[0]), "Q against w: {q2:?}");
    assert!(q3.windows(2).all(|w| w[1] > w[0]), "Q against t: {q3:?}");
    assert!(q4[2] > q4[0], "Q against E: {q4:?}");
}

#[test]
fn simpson_matches_closed_forms() {
    use std::f64::consts::PI;
    // Exact for cubics; fourth order for smooth functions.
    let cubic = simpson(|x| 2.0 * x * x * x - x + 1.0, -1.0, 2.0, 2);
    assert!((cubic - (0.5 * 16.0 - 2.0 + 2.0 - (0.5 - 0.5 - 1.0))).abs() < 1e-12);
    let e1 = (simpson(f64::sin, 0.0, PI, 10) - 2.0).abs();
    let e2 = (simpson(f64::sin, 0.0, PI, 20) - 2.0).abs();
    assert!(e1 < 2e-4 && e2 < e1 / 14.0, "{e1} {e2}");
    // Eq. 8 with no wrinkle is the span itself; with a small amplitude A the boundary's length is
    // l (1 + m/4 − 3m²/64 + 5m³/256 − 175m⁴/16384 + …), m = (πA/l)² (the series of the complete elliptic integral).
    let l = 1.2;
    assert!((boundary_length_m(0.0, 0.0, l, 200) - l).abs() < 1e-14);
    let (a, z) = (0.03, 0.04);
    let m = (PI * 0.05 / l).powi(2);
    let series = l
        * (1.0 + m / 4.0 - 3.0 * m * m / 64.0 + 5.0 * m.powi(3) / 256.0
            - 175.0 * m.powi(4) / 16384.0);
    let got = boundary_length_m(a, z, l, 200);
    assert!((got - series).abs() < 1e-10, "{got} {series}");
}

#[test]
fn the_iteration_converges_to_any_tolerance_and_reports_it() {
    let mut cfg = seed_tables();
    for tol in [0.05, 1e-3, 1e-5] {
        cfg.defaults.tolerance_rel = tol;
        cfg.defaults.max_iterations = 500;
        for c in &cfg.cases {
            let r = solve(&c.inputs(&cfg.defaults));
            assert!(r.converged, "{} at {tol}: {}", c.case, r.message);
            assert!(
                r.length_error_rel <= tol,
                "{} {}",
                c.case,
                r.length_error_rel
            );
            // Eq. 9 holds at the end: the centre fibre keeps the sheet's height.
            if r.n > 0 && tol < 1e-3 {
                let h: f64 = r
                    .amplitudes_m
                    .windows(2)
                    .map(|w| ((w[0] - w[1]).powi(2) + 4.0 * r.zmax_m.powi(2)).sqrt())
                    .sum();
                let want = c.height_m;
                assert!((h - want).abs() < 0.01 * want, "{}: {h} vs {want}", c.case);
            }
        }
    }
    // Too few iterations: a status, not a result passed off as converged.
    cfg.defaults.tolerance_rel = 1e-9;
    cfg.defaults.max_iterations = 2;
    let r = solve(&cfg.cases[1].inputs(&cfg.defaults));
    assert!(!r.converged && r.message.contains("not converged"), "{r:?}");
}

#[test]
fn the_mesh_has_n_folds_and_passes_through_the_supports() {
    let cfg = seed_tables();
    for c in &cfg.cases {
        let inp = c.inputs(&cfg.defaults);
        let r = solve(&inp);
        let m = wrinkle_mesh(&inp, &r, 41, 20 * r.n.max(1) + 1);
        assert_eq!(count_folds(&m), r.n, "{}", c.case);
        // Every point of the end columns sits at a support (y = 0, z = 0) up to round-off.
        for j in 0..m.ny {
            for i in [0, m.nx - 1] {
                let p = m.at(i, j);
                assert!(p[1].abs() < 1e-12 && p[2].abs() < 1e-12, "{p:?}");
            }
        }
        // The centre column runs from the upper boundary a_n down to the lower one a₀ = h.
        if r.n > 0 {
            let (top, bottom) = (m.at(20, 0), m.at(20, m.ny - 1));
            assert!((top[1] - r.amplitudes_m[r.n]).abs() < 1e-12);
            assert!((bottom[1] - c.height_m).abs() < 1e-12);
        }
    }
}

#[test]
fn wrinkles_command_writes_tables_and_a_recording_read_by_polars_and_rerun() {
    let tmp = tempfile::tempdir().unwrap();
    let o = drapelab()
        .arg("wrinkles")
        .arg(root().join("datasets/wrinkles/seed_tables.toml"))
        .arg("--out")
        .arg(tmp.path())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let code = r#"
import sys, polars as pl
from rerun.experimental import RrdReader
meshes = set()
for chunk in RrdReader(sys.argv[3]).stream().to_chunks():
    if chunk.entity_path.endswith("/mesh"):
        meshes.add(chunk.entity_path)
assert len(meshes) == 12, meshes
t = pl.read_parquet(sys.argv[1])
assert t.height == 12, t
for c in ["case", "length_m", "height_m", "thickness_m", "youngs_modulus_Pa", "weight_N_per_m2",
          "support_displacement_m", "n", "q", "zmax_cm", "iterations", "converged"]:
    assert c in t.columns, c
assert t["converged"].all()
m = pl.read_parquet(sys.argv[2])
assert set(m["case"].unique()) == set(t["case"]), m
assert m.group_by("case").len()["len"].unique().to_list() == [41 * 81]
"#;
    crate::support::run_python(
        code,
        &[
            &tmp.path().join("wrinkles.parquet"),
            &tmp.path().join("mesh.parquet"),
            &tmp.path().join("wrinkles.rrd"),
        ],
    );
}

#[test]
fn invalid_wrinkle_inputs_exit_2_naming_the_key() {
    crate::support::assert_bad_edits(
        "wrinkles",
        "datasets/wrinkles/seed_tables.toml",
        &[
            (
                "length_m = 1.40\nheight_m = 0.90",
                "length_m = 0.0\nheight_m = 0.90",
                "cases[0].length_m",
            ),
            (
                "thickness_m = 0.25e-3",
                "thickness_m = -1e-3",
                "cases[0].thickness_m",
            ),
            (
                "poisson_ratio = 0.3",
                "poisson_ratio = 0.5",
                "cases[0].poisson_ratio",
            ),
            (
                "support_displacement_m = 0.10",
                "support_displacement_m = 0.80",
                "cases[0].support_displacement_m",
            ),
            (
                "tolerance_rel = 0.05",
                "tolerance_rel = 0.05\ncolour = 1",
                "defaults.colour",
            ),
        ],
    );
}

#[test]
fn a_sweep_adds_one_case_per_value_and_n_grows_with_height() {
    let tmp = tempfile::tempdir().unwrap();
    let file = tmp.path().join("s.toml");
    let base = std::fs::read_to_string(root().join("datasets/wrinkles/seed_tables.toml")).unwrap();
    std::fs::write(
        &file,
        format!(
            "{base}\n[[sweeps]]\nbase = \"I-h140\"\nkey = \"height_m\"\nvalues = [0.6, 1.0, 1.6, 2.4, 3.2]\n"
        ),
    )
    .unwrap();
    let cfg = load_config(&file).unwrap();
    assert_eq!(cfg.cases.len(), 17);
    let swept: Vec<_> = cfg
        .cases
        .iter()
        .filter(|c| c.case.starts_with("I-h140/height_m="))
        .map(|c| solve(&c.inputs(&cfg.defaults)).n)
        .collect();
    assert_eq!(swept.len(), 5);
    assert!(
        swept.windows(2).all(|w| w[1] >= w[0]) && swept[4] > swept[0],
        "{swept:?}"
    );
}
