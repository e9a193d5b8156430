//! Tension-field wrinkles (seed 002): the trends the seed states on its own Tables I–IV, Simpson's rule
//! against closed forms, convergence of the iteration, the mesh's folds, real readers of the outputs,
//! and bad inputs. A failure means the wrinkle model no longer behaves as the theory says.

use crate::support::{drapelab, root};
use drapelab::solve::Status;
use drapelab::wrinkles::{
    WrinkleConfig, WrinkleInputs, WrinkleResult, boundary_length_m, count_folds, load_config,
    simpson, solve, wrinkle_mesh,
};
use std::path::Path;

fn seed_tables() -> WrinkleConfig {
    load_config(&root().join("datasets/wrinkles/seed_tables.toml")).unwrap()
}

/// The seed's tables with the reading of Eq. 7 fitted to the seed (c = 135, Table I's middle row):
/// the tension field then wrinkles every case but one, and its trends can be tested. The bundled
/// config reads Eq. 7 for a fabric (issue 50), whose count depends on h and l alone.
fn seed_tables_seed_reading() -> WrinkleConfig {
    let mut cfg = seed_tables();
    cfg.defaults.buckling_constant = 135.0;
    cfg.defaults.bending_length_m = None;
    cfg
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
    let cfg = seed_tables_seed_reading();
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

/// Eq. 7 read for a fabric (issue 50): a fabric whose bending term 12 w c_b³ equals the plate's
/// E t³/(1 − ν²) gives the plate's count exactly; and the fabric's count depends on h and l alone
/// (s = 12 c c_b³/(h l²)), not on the weight, thickness or modulus the plate's reading feels.
#[test]
fn eq7_read_for_a_fabric_is_the_plates_at_the_same_bending_term_and_blind_to_weight() {
    let plate = WrinkleInputs {
        bending_length_m: None,
        buckling_constant: 135.0,
        ..i_h140()
    };
    let term =
        plate.youngs_modulus_Pa * plate.thickness_m.powi(3) / (1.0 - plate.poisson_ratio.powi(2));
    let same = WrinkleInputs {
        bending_length_m: Some((term / (12.0 * plate.weight_N_per_m2)).cbrt()),
        ..plate.clone()
    };
    let (a, b) = (solve(&plate), solve(&same));
    assert!(a.n >= 2, "{a:?}");
    assert_eq!(a.n, b.n);
    assert!((a.q_critical - b.q_critical).abs() < 1e-12, "{a:?} {b:?}");
    assert!((a.zmax_m - b.zmax_m).abs() < 1e-9, "{a:?} {b:?}");
    // The fabric's count: the same whatever w, t and E; the plate's moves with each.
    let fabric = WrinkleInputs {
        bending_length_m: Some(0.0143),
        buckling_constant: 7197.0,
        ..plate.clone()
    };
    let heavier = |inp: &WrinkleInputs| WrinkleInputs {
        weight_N_per_m2: 3.0 * inp.weight_N_per_m2,
        thickness_m: 2.0 * inp.thickness_m,
        youngs_modulus_Pa: 0.5 * inp.youngs_modulus_Pa,
        ..inp.clone()
    };
    let f = solve(&fabric);
    assert!(f.n >= 1, "{f:?}");
    assert!((solve(&heavier(&fabric)).q_critical - f.q_critical).abs() < 1e-12);
    assert!((solve(&heavier(&plate)).q_critical - a.q_critical).abs() > 1e-3);
    // A taller fabric sheet wrinkles more: s falls as 1/h.
    let taller = WrinkleInputs {
        height_m: 2.0 * fabric.height_m,
        ..fabric.clone()
    };
    assert!(solve(&taller).q_critical < f.q_critical);
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
    let mut cfg = seed_tables_seed_reading();
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
    let cfg = seed_tables_seed_reading();
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
                "cases.0.length_m",
            ),
            (
                "thickness_m = 0.25e-3",
                "thickness_m = -1e-3",
                "cases.0.thickness_m",
            ),
            (
                "poisson_ratio = 0.3",
                "poisson_ratio = 0.5",
                "cases.0.poisson_ratio",
            ),
            (
                "support_displacement_m = 0.10",
                "support_displacement_m = 0.80",
                "cases.0.support_displacement_m",
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
    let base = std::fs::read_to_string(root().join("datasets/wrinkles/seed_tables.toml"))
        .unwrap()
        .replacen("buckling_constant = 7197.0", "buckling_constant = 135.0", 1)
        .replacen("bending_length_m = 0.0143\n", "", 1);
    assert!(base.contains("buckling_constant = 135.0"));
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

/// Case I-h140 of the seed's Table I.
fn i_h140() -> drapelab::wrinkles::WrinkleInputs {
    let cfg = seed_tables();
    let c = cfg.cases.iter().find(|c| c.case == "I-h140").unwrap();
    c.inputs(&cfg.defaults)
}

#[test]
fn a_synthetic_cosine_sheet_of_known_n_is_counted_exactly_on_the_grid() {
    // Seed 002 Eq. 4 on the simulation's own grid: lines y_i down the sheet alternating ±z_max,
    // out of plane z = z_max cos(π n η) cos(π x / l) (η the fraction of the way down).
    use drapelab::wrinkles::full::{hung_sheet_scene, sheet_wrinkles};
    let inp = i_h140();
    let plate = drapelab::wrinkles::full::SheetReading::Plate { shear_ratio: 1.0 };
    let grid = hung_sheet_scene(&inp, 29, 121, &plate)
        .unwrap()
        .scene
        .grid();
    let l = drapelab::wrinkles::support_span_m(&inp);
    for n in 1..=12usize {
        let x: Vec<nalgebra::Vector3<f64>> = grid
            .flat_positions()
            .iter()
            .map(|p| {
                let (u, eta) = ((p.x / inp.length_m - 0.5) * l, 1.0 - p.y / inp.height_m);
                let out = 0.04
                    * (std::f64::consts::PI * n as f64 * eta).cos()
                    * (std::f64::consts::PI * u / l).cos();
                nalgebra::Vector3::new(u, out, -eta * inp.height_m)
            })
            .collect();
        let w = sheet_wrinkles(&grid, &x, 0.005);
        assert_eq!(w.n, n, "n = {n}: {w:?}");
        assert!((w.zmax_m - 0.04).abs() < 1e-12, "{w:?}");
        let spacing = inp.height_m / 120.0;
        for (i, d) in w.line_depths_m.iter().enumerate() {
            let exact = inp.height_m * i as f64 / n as f64;
            assert!(
                (d - exact).abs() <= spacing + 1e-12,
                "line {i} of n = {n} at {d} m"
            );
        }
    }
}

#[test]
fn a_simulated_hung_sheet_holds_its_weight_and_its_wrinkle_count_does_not_depend_on_the_seed() {
    // I-h140 on a 29 × 29 grid from the strain-free arc start with three seeded ripples: each
    // equilibrium carries the sheet's weight w L h at its two supports, and all give one count.
    use drapelab::wrinkles::full::{HungSetup, HungStart, sheet_wrinkles, solve_hung};
    let inp = i_h140();
    let mut counts = Vec::new();
    for seed in [1, 2, 3] {
        let setup = HungSetup {
            start: HungStart::Arc,
            ripple_amplitude_m: 0.005,
            seed,
            reading: drapelab::wrinkles::full::SheetReading::Plate { shear_ratio: 1.0 },
        };
        let sol = solve_hung(&inp, (29, 29), &setup).unwrap();
        assert_eq!(sol.report.status, Status::Converged, "{:?}", sol.report);
        let mut g = Vec::new();
        sol.model.gradient(&sol.x, 1.0, &mut g);
        let reaction: nalgebra::Vector3<f64> = (0..sol.grid.len())
            .filter(|&p| sol.model.fixed[p])
            .map(|p| -g[p])
            .sum();
        let weight = inp.weight_N_per_m2 * inp.length_m * inp.height_m;
        assert!(
            (reaction - nalgebra::Vector3::new(0.0, 0.0, -weight)).norm() < 1e-6 * weight,
            "seed {seed}: the supports carry {reaction:?}, the weight is {weight} N"
        );
        let w = sheet_wrinkles(&sol.grid, &sol.x, 0.005);
        counts.push(w.n);
    }
    assert!(
        counts[0] >= 1 && counts.iter().all(|&n| n == counts[0]),
        "n by seed: {counts:?}"
    );
}

/// A small `wrinkles-simulate` pipeline over two cases of the seed's tables.
const FULL_PIPELINE: &str = r#"
name = "wrinkles_small"
[stages.full]
kind = "wrinkles-simulate"
inputs.config = "datasets/wrinkles/seed_tables.toml"
outputs.table = "{run}/full/wrinkles_full.parquet"
outputs.fibres = "{run}/full/fibres.parquet"
outputs.starts = "{run}/full/starts.parquet"
outputs.recording = "{run}/full/sheets.rrd"
outputs.sheets = "{run}/full/sheets.png"
outputs.fibres_plot = "{run}/full/fibres.svg"
outputs.markdown = "{run}/full/wrinkles.md"
params = { coarse_nx = 15, fine_nx = 29, cases = ["I-h90", "II-w33"], other_starts = ["compressed"], shear_ratios = [1e-4], fabric_coarse_nx = 15, fabric_fine_nx = 29, map_cases = ["I-h90"], map_bending_lengths_m = [0.029], map_shear_N_per_m = [170.0], points_coarse_nx = 9, points_fine_nx = 15 }
"#;

#[test]
fn the_wrinkles_simulate_stage_writes_the_contract_table_read_by_pyarrow_and_rerun() {
    let (tmp, file) = crate::support::temp_project(
        &["datasets/wrinkles/seed_tables.toml"],
        "wrinkles_small.toml",
        FULL_PIPELINE,
    );
    crate::support::run_plan(&file);
    let dir = tmp.path().join("runs/wrinkles_small/full");
    let code = r#"
import sys, pyarrow as pa, pyarrow.parquet as pq
from rerun.experimental import RrdReader
t = pq.read_table(sys.argv[1])
want = {"case": pa.string(), "n_seed": pa.int32(), "n_tension_field": pa.int32(),
        "n_full_simulation": pa.int32(), "n_full_simulation_coarse": pa.int32(),
        "z_max_full_simulation_m": pa.float64(), "wall_time_s": pa.float64(), "status": pa.string(),
        "reading": pa.string(), "bending_length_m": pa.float64(), "shear_rigidity_N_per_m": pa.float64()}
for name, ty in want.items():
    assert t.schema.field(name).type == ty, (name, t.schema.field(name).type)
assert t.schema.field("role").type == pa.string()
rows = t.to_pylist()
assert [(r["case"], r["reading"], r["role"]) for r in rows] == [
    ("I-h90", "plate", "table"), ("II-w33", "plate", "table"), ("I-h90", "fabric", "table"),
    ("II-w33", "fabric", "table"), ("I-h90", "fabric", "map"), ("Fig4-d5", "fabric", "photograph"),
    ("Fig4-d10", "fabric", "photograph"), ("Fig4-d15", "fabric", "photograph")], rows
# The map's point and the photographs are solved on the points' meshes.
assert all(r["grid"].startswith("15x") and r["grid_coarse"].startswith("9x") for r in rows[4:]), rows
m = rows[4]
assert abs(m["bending_length_m"] - 0.029) < 1e-12 and m["shear_rigidity_N_per_m"] == 170.0, m
for r in rows:
    assert r["status"] in ("converged", "converged in n only", "not converged in the mesh"), r
    # Eq. 7 read for a fabric of 14.3 mm (c = 7197) wrinkles every one of these sheets.
    assert r["n_tension_field"] >= 1, r
    assert r["n_seed"] in ((5, 6) if r["role"] != "photograph" else (4,)), r
    assert 0.0 < r["z_max_full_simulation_m"] < 1.0 and r["wall_time_s"] > 0.0, r
    assert len(r["line_depths_full_simulation_m"]) == r["n_full_simulation"] + 1, r
    assert r["self_crossing_edges"] == 0, r
# The plate's bending lengths are centimetres and its shear kN/m; the fabric's the stage's defaults.
for r in rows[:2]:
    assert r["bending_length_m"] > 0.03 and r["shear_rigidity_N_per_m"] > 1e4, r
for r in rows[2:4] + rows[5:]:
    assert abs(r["bending_length_m"] - 0.0143) < 1e-12 and r["shear_rigidity_N_per_m"] == 53.3, r
f = pq.read_table(sys.argv[2]).to_pylist()
assert {(r["case"], r["reading"], r["mesh"]) for r in f} == {
    (c, g, m) for c in ("I-h90", "II-w33") for g in ("plate", "fabric") for m in ("fine", "coarse")}
s = pq.read_table(sys.argv[3]).to_pylist()
assert sorted((r["case"], r["start"], r["shear_ratio"]) for r in s) == [
    (c, st, g) for c in ("I-h90", "II-w33") for st, g in (("arc", 1e-4), ("arc", 1.0), ("compressed", 1.0))], s
assert all(r["self_crossing_edges"] == 0 and r["status"] == "converged" for r in s), s
meshes = {c.entity_path for c in RrdReader(sys.argv[4]).stream().to_chunks() if c.entity_path.endswith("/mesh")}
assert len(meshes) == 16, meshes
assert "/cases/I-h90_fabric-c29_0mm-G170Npm_fine/mesh" in meshes, meshes
"#;
    crate::support::run_python(
        code,
        &[
            &dir.join("wrinkles_full.parquet"),
            &dir.join("fibres.parquet"),
            &dir.join("starts.parquet"),
            &dir.join("sheets.rrd"),
        ],
    );
    let md = std::fs::read_to_string(dir.join("wrinkles.md")).unwrap();
    for part in [
        "## Three columns side by side",
        "## Does the count depend on the start?",
        "## Which reading of Eq. 7 the simulations support",
        "## The sheets read as fabric",
        "**Eq. 7 refitted to fabric.**",
        "### The map: bending length × shear rigidity",
        "### The photographed cloth (Fig. 4)",
        "![the simulated sheets, finer mesh](sheets.png)",
    ] {
        assert!(md.contains(part), "{part} missing from the report");
    }
    let png = image::open(dir.join("sheets.png")).unwrap();
    assert!(png.width() > 0 && png.height() > 0);
}

#[test]
fn a_bad_wrinkles_simulate_parameter_exits_2_naming_the_pipeline_and_key() {
    // Checked when the plan loads: one line, nothing run.
    for (from, to, key) in [
        (
            "other_starts = [\"compressed\"]",
            "start = \"sideways\"",
            "start",
        ),
        ("coarse_nx = 15", "coarse_nx = 31", "fine_nx"),
        (
            "shear_ratios = [1e-4]",
            "shear_ratios = [0.0]",
            "shear_ratios",
        ),
        (
            "shear_ratios = [1e-4]",
            "shear_ratios = [1e-4], fabric_bending_length_m = -0.01",
            "fabric_bending_length_m",
        ),
        (
            "points_fine_nx = 15",
            "points_fine_nx = 9",
            "points_fine_nx",
        ),
        (
            "map_shear_N_per_m = [170.0]",
            "map_shear_N_per_m = [-1.0]",
            "map_shear_N_per_m",
        ),
    ] {
        let (_tmp, file) = crate::support::temp_project(
            &["datasets/wrinkles/seed_tables.toml"],
            "wrinkles_small.toml",
            &FULL_PIPELINE.replacen(from, to, 1),
        );
        crate::support::assert_bad_input([Path::new("run"), &file], &["wrinkles_small.toml", key]);
    }
    // A case the config does not have: found when the stage reads the config, before any solve.
    for (from, to, key) in [
        ("\"II-w33\"", "\"II-w99\"", "stages.full.params.cases"),
        (
            "map_cases = [\"I-h90\"]",
            "map_cases = [\"II-w99\"]",
            "stages.full.params.map_cases",
        ),
    ] {
        let (tmp, file) = crate::support::temp_project(
            &["datasets/wrinkles/seed_tables.toml"],
            "wrinkles_small.toml",
            &FULL_PIPELINE.replacen(from, to, 1),
        );
        let o = drapelab().arg("run").arg(&file).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert!(
            err.lines().any(|l| l.contains(key) && l.contains("II-w99")),
            "{err}"
        );
        assert!(
            !tmp.path()
                .join("runs/wrinkles_small/full/wrinkles_full.parquet")
                .exists()
        );
    }
}

/// Issue 50: I-h140 read as a fabric (bending length 14.3 mm, shear 17 N/m — the soft end of KES
/// apparel shear) on the 29 × 29 grid folds into more wrinkles than the same sheet read as seed
/// 002's plate, with one count for three seeds of the start's ripple (measured n = 3 against 1).
#[test]
fn a_hung_sheet_read_as_fabric_folds_into_more_wrinkles_than_as_a_plate_whatever_the_seed() {
    use drapelab::wrinkles::full::{
        HungSetup, HungStart, SheetReading, sheet_wrinkles, solve_hung,
    };
    let inp = i_h140();
    let count = |reading: SheetReading, seed: u64| {
        let setup = HungSetup {
            start: HungStart::Arc,
            ripple_amplitude_m: 0.005,
            seed,
            reading,
        };
        let sol = solve_hung(&inp, (29, 29), &setup).unwrap();
        assert_eq!(sol.report.status, Status::Converged, "{:?}", sol.report);
        sheet_wrinkles(&sol.grid, &sol.x, 0.005).n
    };
    let fabric = SheetReading::Fabric {
        bending_length_m: 0.0143,
        shear_N_per_m: 17.0,
    };
    let plate = SheetReading::Plate { shear_ratio: 1.0 };
    assert!(fabric.bending_length_m(&inp) < 0.3 * plate.bending_length_m(&inp));
    let fabrics: Vec<usize> = [1, 2, 3].map(|seed| count(fabric, seed)).to_vec();
    let plates: Vec<usize> = [1, 2, 3].map(|seed| count(plate, seed)).to_vec();
    assert!(
        fabrics.iter().all(|&n| n == fabrics[0])
            && fabrics[0] > plates.iter().copied().max().unwrap(),
        "n by seed: fabric {fabrics:?}, plate {plates:?}"
    );
}
