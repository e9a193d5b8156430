//! `simulate --sensitivity KEY` and `simulate --start FILE` at the command line: the table's rows and
//! values, run.json's word on them, bad keys and bad start files refused as bad input.

use crate::support::{assert_bad_input, drapelab, root, run_json, run_python};
use drapelab::io::{read_particles, read_sensitivities};
use std::path::Path;

const K: &str = "material.mass_spring.stiffness_N_per_m";
const RHO: &str = "cloth.areal_density_kg_per_m2";

fn hang4() -> std::path::PathBuf {
    root().join("datasets/scenes/hang4.toml")
}

#[test]
fn sensitivity_parquet_holds_one_row_per_particle_and_key_in_particles_order() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("o");
    let o = drapelab()
        .arg("simulate")
        .arg(hang4())
        .args([
            "--out",
            out.to_str().unwrap(),
            "--sensitivity",
            K,
            "--sensitivity",
            RHO,
            // Asked twice: computed and written once.
            "--sensitivity",
            K,
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let particles = read_particles(&out.join("particles.parquet")).unwrap();
    let rows = read_sensitivities(&out.join("sensitivity.parquet")).unwrap();
    let n = particles.len();
    assert_eq!(rows.len(), 2 * n);
    assert_eq!(
        run_json(&out)["sensitivity"]["keys"],
        serde_json::json!([K, RHO])
    );
    for (k, key) in [K, RHO].iter().enumerate() {
        for (p, (i, j, _)) in particles.iter().enumerate() {
            let r = &rows[k * n + p];
            assert_eq!((r.i, r.j, r.key.as_str()), (*i, *j, *key));
        }
    }
    // Against the library at the converged state: the same numbers within the run's accuracy
    // estimate (the CLI writes them after one more Newton step of the equilibrium).
    let accuracy: Vec<f64> = run_json(&out)["sensitivity"]["accuracy_rel"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| a.as_f64().unwrap())
        .collect();
    assert!(
        accuracy.len() == 2 && accuracy.iter().all(|a| *a < 1e-6),
        "{accuracy:?}"
    );
    let scene = drapelab::scene::Scene::load(&hang4(), &[]).unwrap().scene;
    let sol = drapelab::simulate::solve_scene(&scene, &mut drapelab::solve::NoObserver);
    let mut eq =
        drapelab::sensitivity::Equilibrium::new(&scene, &sol.model, &sol.x, &sol.report, "t")
            .unwrap();
    let s = eq.sensitivity(RHO).unwrap();
    for p in 0..n {
        let r = &rows[n + p];
        let d = nalgebra::Vector3::new(r.dx_m_per_unit, r.dy_m_per_unit, r.dz_m_per_unit);
        assert!(
            (d - s.dx[p]).norm()
                <= 1e-12 + 10.0 * accuracy[1] * s.dx.iter().map(|v| v.norm()).fold(0.0, f64::max),
            "{p}"
        );
    }
    // Physics: the pinned corners do not move; a heavier net sags lower at its centre, a stiffer
    // one less.
    let centre = 5 * 11 + 5;
    assert_eq!(rows[n].dz_m_per_unit, 0.0);
    assert!(rows[n + centre].dz_m_per_unit < 0.0);
    assert!(rows[centre].dz_m_per_unit > 0.0);
    let run = run_json(&out);
    assert_eq!(run["sensitivity"]["written"], true);
    // dE*/dθ per key, as the library gives it; a heavier net stores less energy (it hangs lower:
    // gravity's energy falls faster than the springs' rises).
    let de = run["sensitivity"]["d_energy_J_per_unit"]
        .as_array()
        .unwrap();
    assert_eq!(de.len(), 2);
    assert!((de[1].as_f64().unwrap() - s.d_energy).abs() <= 1e-12 * s.d_energy.abs());
    assert!(s.d_energy < 0.0, "{}", s.d_energy);
    assert!(
        run["outputs"]
            .as_array()
            .unwrap()
            .iter()
            .any(|o| o == "sensitivity.parquet")
    );
}

/// `simulate SCENE --out DIR [extra] --sensitivity KEY` is refused as bad input in one line naming
/// `names`, and leaves no DIR behind.
fn assert_sensitivity_refused(scene: &Path, extra: &[&str], key: &str, names: &[&str]) {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("o");
    let mut args = vec![
        "simulate",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend(extra);
    args.extend(["--sensitivity", key]);
    assert_bad_input(args, names);
    assert!(!out.exists(), "{key}: {} left behind", out.display());
}

#[test]
fn a_key_that_is_not_a_continuous_parameter_is_bad_input_and_leaves_nothing() {
    for key in [
        "cloth.nx",
        "material.mass_spring.nope",
        "solver.static.residual_tol_rel",
    ] {
        assert_sensitivity_refused(&hang4(), &[], key, &["--sensitivity", key]);
    }
}

/// Friction's lagged equilibrium is not differentiated: a drape with friction asked for a
/// sensitivity (of μ itself or of any other key) is refused before the solve, naming the flag, the
/// key and friction, where it wrote a table of zeros (for μ) or left friction's dependence out.
#[test]
fn a_drape_with_friction_refuses_sensitivities_naming_the_reason() {
    let rod = root().join("datasets/scenes/rod_polyester.toml");
    for key in [
        "contact.friction_coefficient",
        "material.continuum.bending_warp_gf_cm2_per_cm",
    ] {
        let friction = ["--set", "contact.friction_coefficient=0.3"];
        assert_sensitivity_refused(&rod, &friction, key, &["--sensitivity", key, "friction"]);
    }
}

#[test]
fn a_solve_that_does_not_converge_gets_no_sensitivities_and_says_why() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("o");
    let o = drapelab()
        .arg("simulate")
        .arg(hang4())
        .args(["--out", out.to_str().unwrap(), "--sensitivity", K])
        .args(["--set", "solver.static.max_iterations=1"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert!(!out.join("sensitivity.parquet").exists());
    let run = run_json(&out);
    assert_eq!(run["sensitivity"]["written"], false);
    let reason = run["sensitivity"]["reason"].as_str().unwrap();
    assert!(reason.contains("did not converge"), "{reason}");
}

/// A particles table rewritten by pyarrow with its default compression (snappy) is read as a
/// start like drapelab's own (zstd), where it was refused as corrupt.
#[test]
fn a_start_written_by_pyarrow_with_snappy_is_read() {
    let tmp = tempfile::tempdir().unwrap();
    let (first, second) = (tmp.path().join("a"), tmp.path().join("b"));
    let sim = |out: &Path, extra: &[&str]| {
        drapelab()
            .arg("simulate")
            .arg(hang4())
            .args(["--out", out.to_str().unwrap()])
            .args(extra)
            .output()
            .unwrap()
    };
    assert!(sim(&first, &[]).status.success());
    let snappy = tmp.path().join("snappy.parquet");
    run_python(
        "import sys, pyarrow.parquet as pq\n\
         t = pq.read_table(sys.argv[1])\n\
         pq.write_table(t, sys.argv[2], compression='snappy')\n\
         assert pq.ParquetFile(sys.argv[2]).metadata.row_group(0).column(0).compression == 'SNAPPY'\n",
        &[&first.join("particles.parquet"), &snappy],
    );
    let o = sim(&second, &["--start", snappy.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(run_json(&second)["start_file"], snappy.to_str().unwrap());
}

/// A start whose particle has a non-finite or far-off coordinate is refused naming the column that
/// holds it (it named x_m for a NaN in z_m), and nothing is written.
#[test]
fn a_start_with_a_bad_coordinate_names_its_column() {
    let tmp = tempfile::tempdir().unwrap();
    let first = tmp.path().join("a");
    let o = drapelab()
        .arg("simulate")
        .arg(hang4())
        .args(["--out", first.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(o.status.success());
    for (column, value) in [("z_m", "float('nan')"), ("y_m", "1e300")] {
        let bad = tmp.path().join(format!("{column}.parquet"));
        run_python(
            &format!(
                "import sys, pyarrow as pa, pyarrow.parquet as pq\n\
                 t = pq.read_table(sys.argv[1])\n\
                 c = t.column('{column}').to_pylist()\n\
                 c[3] = {value}\n\
                 t = t.set_column(t.schema.get_field_index('{column}'), '{column}', pa.array(c))\n\
                 pq.write_table(t, sys.argv[2])\n"
            ),
            &[&first.join("particles.parquet"), &bad],
        );
        let out = tmp.path().join(format!("{column}-out"));
        assert_bad_input(
            [
                "simulate",
                hang4().to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
                "--start",
                bad.to_str().unwrap(),
            ],
            &["--start", column, "row 3"],
        );
        assert!(!out.exists(), "{column}: {} left behind", out.display());
    }
}

#[test]
fn a_restart_from_a_saved_drape_lands_on_it_at_once() {
    let tmp = tempfile::tempdir().unwrap();
    let (first, second) = (tmp.path().join("a"), tmp.path().join("b"));
    let sim = |out: &Path, extra: &[&str]| {
        let o = drapelab()
            .arg("simulate")
            .arg(hang4())
            .args(["--out", out.to_str().unwrap()])
            .args(extra)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    };
    sim(&first, &[]);
    let saved = first.join("particles.parquet");
    sim(&second, &["--start", saved.to_str().unwrap()]);
    let (a, b) = (
        read_particles(&saved).unwrap(),
        read_particles(&second.join("particles.parquet")).unwrap(),
    );
    let moved = a
        .iter()
        .zip(&b)
        .map(|(p, q)| (p.2 - q.2).norm())
        .fold(0.0, f64::max);
    assert!(moved < 1e-9, "the restart moved the drape by {moved} m");
    let (r1, r2) = (run_json(&first), run_json(&second));
    assert!(
        r2["report"]["iterations"].as_u64().unwrap() < r1["report"]["iterations"].as_u64().unwrap(),
        "{} vs {}",
        r2["report"]["iterations"],
        r1["report"]["iterations"]
    );
    assert_eq!(r2["start_file"], saved.to_str().unwrap());
    // A drape of another grid is refused, naming the flag and the file, and nothing is written.
    let out = tmp.path().join("c");
    assert_bad_input(
        [
            "simulate",
            hang4().to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--set",
            "cloth.nx=13",
            "--start",
            saved.to_str().unwrap(),
        ],
        &["--start", "particles.parquet", "121 particles"],
    );
    assert!(!out.exists());
}

/// Issue 78: a start that moves the scene's fixed particles, puts a particle inside an obstacle or
/// two neighbours at one point is refused naming `--start`, the particle and what is wrong, and
/// nothing is written (they ran before: "diverged" with an empty message, or "converged in 0
/// iterations" with the pins moved).
#[test]
fn a_start_that_the_scene_cannot_have_is_refused_naming_the_particle() {
    let tmp = tempfile::tempdir().unwrap();
    let sphere = root().join("datasets/scenes/sphere_wool.toml");
    let edit = |scene: &Path, name: &str, code: &str| {
        let saved = tmp.path().join(format!("{name}-saved"));
        let o = drapelab()
            .arg("simulate")
            .arg(scene)
            .args(["--out", saved.to_str().unwrap()])
            .output()
            .unwrap();
        assert!(o.status.success());
        let bad = tmp.path().join(format!("{name}.parquet"));
        run_python(
            &format!(
                "import sys, pyarrow as pa, pyarrow.parquet as pq\n\
                 t = pq.read_table(sys.argv[1])\n\
                 x, y, z = (t.column(c).to_pylist() for c in ('x_m', 'y_m', 'z_m'))\n\
                 {code}\n\
                 for c, v in (('x_m', x), ('y_m', y), ('z_m', z)):\n\
                 \x20   t = t.set_column(t.schema.get_field_index(c), c, pa.array(v))\n\
                 pq.write_table(t, sys.argv[2])\n"
            ),
            &[&saved.join("particles.parquet"), &bad],
        );
        bad
    };
    let cases = [
        (
            hang4(),
            "moved",
            "z = [v + 0.1 for v in z]",
            &["--start", "fixed", "x_m"][..],
        ),
        (
            sphere.clone(),
            "inside",
            "k = 15 * 31 + 16\nz[k] = -0.03",
            &["--start", "obstacles.0", "z_m", "[16, 15]"][..],
        ),
        (
            hang4(),
            "coincident",
            "x[5], y[5], z[5] = x[6], y[6], z[6]",
            &["--start", "one point"][..],
        ),
        (
            // A corner laid 10 µm above a particle of the drape's far side: two layers closer
            // than the sheet's thickness, which self-contact's barrier cannot start from.
            sphere.clone(),
            "layers",
            "a, b = 3, 20 * 31 + 20\nx[a], y[a], z[a] = x[b], y[b], z[b] + 1e-5",
            &["--start", "contact/self", "thickness"][..],
        ),
    ];
    for (scene, name, code, names) in cases {
        let bad = edit(&scene, name, code);
        let out = tmp.path().join(format!("{name}-out"));
        assert_bad_input(
            [
                "simulate",
                scene.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
                "--start",
                bad.to_str().unwrap(),
            ],
            names,
        );
        assert!(!out.exists(), "{name}: {} left behind", out.display());
    }
}

/// Issue 78: run.json says which rigid motions a converged equilibrium is free to make. The wool
/// sheet held at its centre on a frictionless sphere may turn about the vertical through the pin
/// (its sensitivities are the ones orthogonal to that turn); the hanging net held at four corners
/// has none.
#[test]
fn run_json_lists_the_neutral_modes_of_the_equilibrium() {
    let tmp = tempfile::tempdir().unwrap();
    let modes = |scene: &Path, name: &str| {
        let out = tmp.path().join(name);
        let o = drapelab()
            .arg("simulate")
            .arg(scene)
            .args(["--out", out.to_str().unwrap()])
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        run_json(&out)["neutral_modes"].clone()
    };
    let sphere = modes(&root().join("datasets/scenes/sphere_wool.toml"), "sphere");
    let list = sphere.as_array().expect("a list");
    assert_eq!(list.len(), 1, "{sphere}");
    assert_eq!(list[0]["kind"], "turn");
    let axis: Vec<f64> = serde_json::from_value(list[0]["axis"].clone()).unwrap();
    assert_eq!(axis, vec![0.0, 0.0, 1.0]);
    let through: Vec<f64> = serde_json::from_value(list[0]["through_m"].clone()).unwrap();
    assert!(
        through[0].abs() < 1e-12 && through[1].abs() < 1e-12,
        "{through:?}"
    );
    let hang = modes(&hang4(), "hang4");
    assert_eq!(hang.as_array().map(Vec::len), Some(0), "{hang}");
}

/// `--sensitivity` at the scene's own tolerance (table_wool_quarter at 15 × 15, residual 10⁻⁶ of a
/// particle's weight) is as good as the issue asks: within 10⁻⁴ (2-norm over particles) of the
/// central difference of drapes solved to 10⁻¹⁰ at θ(1 ± 10⁻⁴), and run.json's estimate says so.
#[test]
fn a_sensitivity_at_the_scenes_own_tolerance_matches_differences_of_drapes_solved_tightly() {
    use drapelab::params::{value, with_value};
    use drapelab::simulate::{solve_scene, solve_scene_from};
    use drapelab::solve::NoObserver;
    const BEND: &str = "material.continuum.bending_warp_gf_cm2_per_cm";
    let scene_file = root().join("datasets/scenes/table_wool_quarter.toml");
    let grid = ["--set", "cloth.nx=15", "--set", "cloth.ny=15"];
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("o");
    let o = drapelab()
        .arg("simulate")
        .arg(&scene_file)
        .args(grid)
        .args(["--out", out.to_str().unwrap(), "--sensitivity", BEND, "-q"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let accuracy = run_json(&out)["sensitivity"]["accuracy_rel"][0]
        .as_f64()
        .unwrap();
    assert!(accuracy < 1e-4, "{accuracy}");
    let rows = read_sensitivities(&out.join("sensitivity.parquet")).unwrap();
    let set = |tol: f64| {
        vec![
            ("cloth.nx".to_string(), toml::Value::Integer(15)),
            ("cloth.ny".to_string(), toml::Value::Integer(15)),
            (
                "solver.static.residual_tol_rel".to_string(),
                toml::Value::Float(tol),
            ),
        ]
    };
    let tight = drapelab::scene::Scene::load(&scene_file, &set(1e-10))
        .unwrap()
        .scene;
    let sol = solve_scene(&tight, &mut NoObserver);
    assert!(sol.report.is_converged(), "{}", sol.report.message);
    let theta = value(&tight, BEND, "t").unwrap();
    // 10⁻⁴: a bending key barely moves the forces, and at 10⁻⁵ the neighbours' own tolerance
    // (10⁻¹⁰ of a weight) is 10⁻³ of the difference (measured: 9·10⁻⁴ at 10⁻⁵ and 10⁻⁶, 8·10⁻⁶ at
    // 10⁻⁴ and 10⁻³).
    let h = 1e-4 * theta;
    let side = |t: f64| {
        let s = with_value(&tight, BEND, t, "t").unwrap();
        let r = solve_scene_from(&s, &sol.x, &mut NoObserver);
        assert!(r.report.is_converged(), "{}", r.report.message);
        r.x
    };
    let (hi, lo) = (side(theta + h), side(theta - h));
    let (mut diff, mut scale) = (0.0, 0.0);
    for (p, r) in rows.iter().enumerate() {
        let fd = (hi[p] - lo[p]) / (2.0 * h);
        let d = nalgebra::Vector3::new(r.dx_m_per_unit, r.dy_m_per_unit, r.dz_m_per_unit);
        diff += (d - fd).norm_squared();
        scale += fd.norm_squared();
    }
    let rel = (diff / scale).sqrt();
    assert!(rel <= 1e-4, "{rel:e} (run.json's estimate {accuracy:e})");
    eprintln!(
        "sensitivity at the scene's tolerance: {rel:.2e} from tight differences; estimate {accuracy:.2e}"
    );
}
