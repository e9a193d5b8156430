//! Issue 49: a flat pattern read from OBJ as the sheet — bundled pattern scenes draped over
//! obstacles, grid scenes re-run as triangulated meshes of the same sheets, malformed files refused.

use crate::support::{drapelab, root, scene, simulate_recorded};
use drapelab::measure::drape_measures;
use drapelab::scene::Scene;
use drapelab::simulate::solve_scene;
use std::path::Path;

/// The grid keys a mesh scene leaves out.
const GRID_KEYS: [&str; 9] = [
    "size_x_m",
    "size_y_m",
    "nx",
    "ny",
    "spacing",
    "grading",
    "refine_x_m",
    "refine_y_m",
    "shape",
];

/// The bundled grid scene `name` as the same sheet from a mesh: its flat grid written as OBJ
/// (two triangles per cell, the grid's own split) into `dir`, its pinned particles as group `pins`,
/// and the scene file with `cloth.mesh` in place of the grid's keys.
fn mesh_twin(name: &str, dir: &Path) -> Scene {
    let grid_scene = scene(name, &[]);
    let grid = grid_scene.grid();
    let mut obj = String::new();
    for p in grid.flat_positions() {
        obj += &format!("v {} {} 0\n", p.x, p.y);
    }
    for t in drapelab::cloth::grid_triangles(&grid) {
        obj += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    let pins = &grid_scene.boundary.pin_particles;
    if !pins.is_empty() {
        obj += "g pins\nl";
        for p in pins {
            obj += &format!(" {}", grid.index(p[0], p[1]) + 1);
        }
        obj += "\n";
    }
    let stem = name.trim_end_matches(".toml");
    std::fs::write(dir.join(format!("{stem}.obj")), obj).unwrap();
    let text = std::fs::read_to_string(root().join("datasets/scenes").join(name)).unwrap();
    let mut out = String::new();
    for line in text.lines() {
        let key = line.split('=').next().unwrap_or("").trim();
        if GRID_KEYS.contains(&key) {
            continue;
        }
        if key == "pin_particles" {
            out += "pin_groups = [\"pins\"]\n";
            continue;
        }
        out += line;
        out += "\n";
        if line.trim() == "[cloth]" {
            out += &format!("mesh = \"{stem}.obj\"\n");
        }
    }
    let file = dir.join(name);
    std::fs::write(&file, out).unwrap();
    Scene::load(&file, &[])
        .expect("mesh twin")
        .scene
        .into_inner()
}

/// table_wool and sphere_wool re-run as triangulated meshes of the same sheets (the membrane and
/// the patch bending on triangles instead of the grid's finite-volume cells) agree with their grid
/// versions: the same folds, the table's DC and the sphere's projected area (% of the flat
/// sheet's) within 1 point.
#[test]
fn a_grid_sheet_and_its_triangulated_mesh_drape_alike() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["table_wool.toml", "sphere_wool.toml"] {
        let on_grid = scene(name, &[]);
        let on_mesh = mesh_twin(name, dir.path());
        let (a, b) = (
            solve_scene(&on_grid, &mut drapelab::solve::NoObserver),
            solve_scene(&on_mesh, &mut drapelab::solve::NoObserver),
        );
        assert!(a.report.is_converged(), "{name} grid: {}", a.report.message);
        assert!(b.report.is_converged(), "{name} mesh: {}", b.report.message);
        let (ma, mb) = (
            drape_measures(&on_grid, &a.x),
            drape_measures(&on_mesh, &b.x),
        );
        let pct = |m: &drapelab::measure::DrapeMeasures| {
            m.drape_coefficient_pct
                .unwrap_or(100.0 * m.projected_area_m2 / m.flat_area_m2)
        };
        eprintln!(
            "{name}: grid {:.2} % ({} it), mesh {:.2} % ({} it)",
            pct(&ma),
            a.report.iterations,
            pct(&mb),
            b.report.iterations
        );
        // Measured 0.06 (table) and 0.81 points (sphere) with the patch bending the grid's
        // own split gets (3.6 and 1.7 with hinges).
        assert!(
            (pct(&ma) - pct(&mb)).abs() < 1.0,
            "{name}: {ma:?} against {mb:?}"
        );
        assert_eq!(ma.folds, mb.folds, "{name}");
    }
}

/// `drapelab simulate` of a bundled pattern scene into a fresh folder, recording asked: the run
/// record as JSON.
fn simulate_pattern(name: &str, out: &Path) -> serde_json::Value {
    let o = simulate_recorded(
        &root().join("datasets/patterns").join(name),
        out,
        &["--obj"],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).unwrap()).unwrap()
}

/// The L-shaped panel, the Cusick template and the two-panel skirt, each read from OBJ, draped over
/// bundled obstacles (a sphere, a table, the tester's pedestal, the body form) with self-contact: converged, nowhere through themselves, no
/// vertex inside the obstacle, and written as every run is — particles (one per vertex), the
/// file's triangles, drape.obj, the MCAP timeline and the rerun recording. The Cusick drape folds
/// and hangs below the flat specimen (0 < DC < 100 %).
#[test]
fn patterns_from_obj_drape_over_obstacles_and_are_recorded() {
    let dir = tempfile::tempdir().unwrap();
    for (name, obj) in [
        ("l_panel_sphere.toml", "l_panel.obj"),
        ("l_panel_table.toml", "l_panel.obj"),
        ("cusick_disc_pedestal.toml", "cusick_disc.obj"),
        ("skirt_form.toml", "skirt.obj"),
    ] {
        let out = dir.path().join(name);
        let run = simulate_pattern(name, &out);
        assert_eq!(run["status"], "converged", "{name}");
        let sc = &run["self_contact"];
        assert_eq!(sc["modelled"], true, "{name}");
        assert_eq!(sc["crossing_edges"], 0, "{name}");
        assert_eq!(run["drape"]["max_penetration_m"], 0.0, "{name}");
        let text = std::fs::read_to_string(root().join("datasets/patterns").join(obj)).unwrap();
        let count = |tag: &str| text.lines().filter(|l| l.starts_with(tag)).count();
        assert_eq!(run["particles"], count("v ") as u64, "{name}");
        let tris = drapelab::io::read_triangles(&out.join("triangles.parquet")).unwrap();
        assert_eq!(
            tris.len(),
            count("f "),
            "{name}: the file's faces are triangles"
        );
        for f in [
            "particles.parquet",
            "drape.obj",
            "timeline.mcap",
            "drape.rrd",
        ] {
            assert!(out.join(f).metadata().unwrap().len() > 0, "{name}: {f}");
        }
    }
    let cusick = simulate_pattern("cusick_disc_pedestal.toml", &dir.path().join("again"));
    let dc = cusick["drape"]["drape_coefficient_pct"].as_f64().unwrap();
    assert!(dc > 20.0 && dc < 90.0, "DC {dc}");
    assert!(cusick["drape"]["folds"].as_u64().unwrap() >= 3);
}

/// A mesh scene's bad input is one line naming the file and key, exit 2, nothing written: the
/// mesh file missing, a malformed mesh (the defect named in the mesh file), a grid key beside the
/// mesh, a group the file lacks, the grid's pins on a mesh, a mesh sheet without the continuum.
#[test]
fn a_bad_mesh_scene_is_refused_in_one_line_naming_file_and_key() {
    let dir = tempfile::tempdir().unwrap();
    let base = std::fs::read_to_string(root().join("datasets/patterns/l_panel_table.toml"))
        .unwrap()
        .replace(
            "mesh = \"l_panel.obj\"",
            &format!(
                "mesh = \"{}\"",
                root().join("datasets/patterns/l_panel.obj").display()
            ),
        );
    let bowtie = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 2 1 0\nv 2 2 0\nf 1 2 3\nf 3 4 5\n";
    std::fs::write(dir.path().join("bowtie.obj"), bowtie).unwrap();
    let huge = "v 0 0 0\nv 1e300 0 0\nv 0 1 0\nf 1 2 3\n";
    std::fs::write(dir.path().join("huge.obj"), huge).unwrap();
    let panel = root()
        .join("datasets/patterns/l_panel.obj")
        .display()
        .to_string();
    let cases: Vec<(String, &str, &str)> = vec![
        (
            base.replace("l_panel.obj", "missing.obj"),
            "cloth.mesh",
            "scene.toml",
        ),
        (
            base.replace(
                &root()
                    .join("datasets/patterns/l_panel.obj")
                    .display()
                    .to_string(),
                "bowtie.obj",
            ),
            "vertex",
            "bowtie.obj",
        ),
        // A coordinate that would overflow the areas: its line, not "a face without area".
        (base.replace(&panel, "huge.obj"), "line 2", "huge.obj"),
        (
            base.replace("[cloth]", "[cloth]\nnx = 11"),
            "cloth.nx",
            "scene.toml",
        ),
        (
            base.replace(
                "[[obstacles]]",
                "[boundary]\npin_groups = [\"waist\"]\n[[obstacles]]",
            ),
            "boundary.pin_groups.0",
            "scene.toml",
        ),
        (
            base.replace(
                "[[obstacles]]",
                "[boundary]\npin_particles = [[0, 0]]\n[[obstacles]]",
            ),
            "boundary.pin_particles",
            "scene.toml",
        ),
        (
            base.replace(
                "[material.continuum]",
                "[material.mass_spring]\nstiffness_N_per_m = 100.0\n[unused]",
            )
            .lines()
            .filter(|l| {
                !l.contains("_gf_") && !l.starts_with("thickness_m") && !l.starts_with("[unused]")
            })
            .collect::<Vec<_>>()
            .join("\n"),
            "material",
            "scene.toml",
        ),
    ];
    // A mesh scene's run folder is dressed with the pattern beside the scene file it names; where
    // that file is gone, `surface RUN` says so in one line, naming it.
    let copied = dir.path().join("copied");
    std::fs::create_dir_all(&copied).unwrap();
    for f in ["l_panel_table.toml", "l_panel.obj"] {
        std::fs::copy(root().join("datasets/patterns").join(f), copied.join(f)).unwrap();
    }
    let run = dir.path().join("run");
    let scene = copied.join("l_panel_table.toml");
    assert!(simulate_recorded(&scene, &run, &[]).status.success());
    let surface = |out: &Path| {
        drapelab()
            .arg("surface")
            .arg(&run)
            .arg("--out")
            .arg(out)
            .output()
    };
    let dressed = dir.path().join("dressed");
    let o = surface(&dressed).unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(dressed.join("drape.glb").is_file());
    std::fs::remove_file(&scene).unwrap();
    let out = dir.path().join("surface");
    let o = surface(&out).unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert_eq!(
        err.lines().filter(|l| !l.trim().is_empty()).count(),
        1,
        "{err}"
    );
    assert!(err.contains("scene_file") && !out.exists(), "{err}");
    for (text, key, file) in cases {
        let scene = dir.path().join("scene.toml");
        std::fs::write(&scene, &text).unwrap();
        let out = dir.path().join("out");
        let o = drapelab()
            .arg("simulate")
            .arg(&scene)
            .arg("--out")
            .arg(&out)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        let lines: Vec<&str> = err.lines().filter(|l| !l.trim().is_empty()).collect();
        assert_eq!(o.status.code(), Some(2), "{key}: {err}");
        assert_eq!(lines.len(), 1, "{key}: {err}");
        assert!(
            lines[0].contains(key) && lines[0].contains(file),
            "{key}: {err}"
        );
        assert!(!out.exists(), "{key}: {} left behind", out.display());
    }
}

/// The sensitivities of a mesh sheet's drape (the membrane's and the hinges' coefficients, the
/// areal density, the file's unit, which scales the pattern, the warp's angle, which turns the
/// membrane's and the hinges' rigidities) agree with central differences of
/// two solves: the L panel on the table (hinge bending) and table_wool's mesh twin (patch
/// bending), each key moved by 10⁻⁴ of its value (at 10⁻³ the unit
/// moves a particle across the table's edge: a kink), the solves started from the equilibrium.
/// Relative to the largest displacement, within 2 % (measured: 0.00 %; the unit's was 12 % off
/// before the membrane's rest shape joined its coefficients).
#[test]
fn a_mesh_sheets_sensitivities_are_the_differences_of_its_drapes() {
    let file = root().join("datasets/patterns/l_panel_table.toml");
    let sets = [drapelab::config::parse_override("cloth.mesh_unit_m=1.0").unwrap()];
    let dir = tempfile::tempdir().unwrap();
    let keys = [
        "material.continuum.bending_warp_gf_cm2_per_cm",
        "material.continuum.tensile_weft_gf_per_cm",
        "cloth.areal_density_kg_per_m2",
        "cloth.mesh_unit_m",
        "cloth.warp_angle_deg",
    ];
    let panel = Scene::load(&file, &sets).unwrap().scene.into_inner();
    mesh_sensitivities_match_differences(panel, &keys);
    // The twin's unit is refused as structural (moving it changes the model's terms there).
    let twin = mesh_twin("table_wool.toml", dir.path());
    let keys: Vec<&str> = keys
        .into_iter()
        .filter(|k| *k != "cloth.mesh_unit_m")
        .collect();
    mesh_sensitivities_match_differences(twin, &keys);
}

/// [`a_mesh_sheets_sensitivities_are_the_differences_of_its_drapes`] for one mesh scene.
fn mesh_sensitivities_match_differences(mut base: Scene, keys: &[&str]) {
    use drapelab::params::with_value;
    use drapelab::sensitivity::Equilibrium;
    use drapelab::simulate::solve_scene_from;
    base.cloth.mesh_unit_m = 1.0 + 1e-9; // serialized, so a key
    base.cloth.warp_angle_deg = 10.0; // likewise
    // Differences of drapes need drapes converged far below their difference.
    base.solver.static_.residual_tol_rel = 1e-11;
    let name = base.name.clone();
    let scene = base.validated().unwrap();
    let sol = solve_scene(&scene, &mut drapelab::solve::NoObserver);
    assert!(sol.report.is_converged(), "{}", sol.report.message);
    let mut eq = Equilibrium::new(&scene, &sol.model, &sol.x, &sol.report, "test").unwrap();
    for &key in keys {
        let s = eq.sensitivity(key).unwrap();
        let h = 1e-4 * s.value;
        let solve_at = |v: f64| {
            let moved = with_value(&scene, key, v, "test").unwrap();
            // From the drape, the fixed particles where the changed scene puts them (the unit
            // scales the whole pattern).
            let built = drapelab::build::build_scene(&moved);
            let start: Vec<_> = (0..sol.x.len())
                .map(|p| {
                    if built.model.fixed[p] {
                        built.x0[p]
                    } else {
                        sol.x[p]
                    }
                })
                .collect();
            let r = solve_scene_from(&moved, &start, &mut drapelab::solve::NoObserver);
            assert!(r.report.is_converged(), "{key} = {v}: {}", r.report.message);
            r.x
        };
        let (xp, xm) = (solve_at(s.value + h), solve_at(s.value - h));
        let scale = s.dx.iter().map(|d| d.norm()).fold(0.0, f64::max);
        let worst = (0..xp.len())
            .map(|p| ((xp[p] - xm[p]) / (2.0 * h) - s.dx[p]).norm())
            .fold(0.0, f64::max);
        eprintln!(
            "{}: {key}: |dx| {scale:.3e}, worst difference {:.2} %",
            name,
            100.0 * worst / scale
        );
        assert!(
            scale > 0.0 && worst < 0.02 * scale,
            "{key}: {worst:e} against {scale:e}"
        );
    }
}

/// A mesh scene dressed on its own triangles (`drapelab surface SCENE`): drape.glb passes the
/// Khronos validator with no errors and holds the pattern's vertices and triangles; the texture
/// lies on the flat pattern.
#[test]
fn a_mesh_drape_is_dressed_on_its_own_triangles_as_valid_gltf() {
    let summary = dressed(&root().join("datasets/patterns/cusick_disc_pedestal.toml"));
    let obj = std::fs::read_to_string(root().join("datasets/patterns/cusick_disc.obj")).unwrap();
    let count = |tag: &str| obj.lines().filter(|l| l.starts_with(tag)).count() as u64;
    assert_eq!(summary["vertices"], count("v "));
    assert_eq!(summary["triangles"], count("f "));
}

/// `drapelab surface` of a pattern scene (solved there) into a fresh folder: its drape.glb valid
/// (Khronos validator, 0 errors) and its surface.json returned.
fn dressed(scene: &Path) -> serde_json::Value {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("surface");
    let o = drapelab()
        .arg("surface")
        .arg(scene)
        .args(["--repeats", "6,6", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let report = crate::surface::gltf_validate(&out.join("drape.glb"));
    assert_eq!(report["issues"]["numErrors"], 0, "{report}");
    serde_json::from_str(&std::fs::read_to_string(out.join("surface.json")).unwrap()).unwrap()
}

/// Issue 49's garment: the two-panel skirt (`skirt.obj`: front and back panels placed on a cone
/// round the form, their flat shapes as texture coordinates, the side seams' vertices shared) on the
/// body form. Converged with no crossing; sewn: the seams' vertices belong to both panels' faces,
/// the seam's edges keep their rest length (the membrane holds them: within 3 %; measured 1.0 %
/// at most, near the waist where the panels fall onto the hips), and both panels'
/// rest shapes agree along the seam; the hem falls below where the cone put it; dressed with each
/// panel's print on its own triangles, as valid glTF (Khronos validator, 0 errors).
#[test]
fn a_two_panel_skirt_sewn_at_its_side_seams_drapes_on_the_form_and_is_dressed() {
    let path = root().join("datasets/patterns/skirt_form.toml");
    let scene = Scene::load(&path, &[]).unwrap().scene;
    let sol = solve_scene(&scene, &mut drapelab::solve::NoObserver);
    assert!(sol.report.is_converged(), "{}", sol.report.message);
    let p = scene.pattern().unwrap();
    assert!(!p.is_flat());
    // The seam: vertices of both panels' faces, two seams of 21 rows.
    let (front, back) = (&p.groups["front"], &p.groups["back"]);
    let seam: Vec<usize> = front.iter().filter(|v| back.contains(v)).copied().collect();
    assert_eq!(seam.len(), 42);
    // Each seam edge (both ends on the seam, in one triangle of each panel) against its rest
    // length in each panel.
    let mut checked = 0;
    for (t, r) in p.triangles.iter().zip(&p.rest_triangles) {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if !(seam.contains(&a) && seam.contains(&b)) {
                continue;
            }
            let (ra, rb) = (p.rest_m[r[k]], p.rest_m[r[(k + 1) % 3]]);
            let rest = ((ra[0] - rb[0]).powi(2) + (ra[1] - rb[1]).powi(2)).sqrt();
            let now = (sol.x[a] - sol.x[b]).norm();
            assert!(
                (now / rest - 1.0).abs() < 0.03,
                "seam edge {a}-{b}: {now} m against {rest} m"
            );
            let start = scene.initial_positions();
            // Placed unstretched, to the file's rounding (1 µm).
            assert!(
                ((start[a] - start[b]).norm() - rest).abs() < 5e-6,
                "placed unstretched"
            );
            checked += 1;
        }
    }
    // 20 edges per seam, each seen from the front's and the back's triangle.
    assert_eq!(checked, 80);
    let lowest = |x: &[nalgebra::Vector3<f64>]| x.iter().map(|v| v.z).fold(f64::INFINITY, f64::min);
    assert!(lowest(&sol.x) < lowest(&scene.initial_positions()) - 0.005);
    // The surface's vertices are the rest vertices: a seam's vertex once per panel.
    let summary = dressed(&path);
    assert_eq!(summary["vertices"], p.rest_m.len() as u64);
    assert_eq!(p.rest_m.len(), p.vertex_count() + seam.len());
}

/// A flat pattern lies in its own plane: a file at a constant z = 0.3 is placed by `origin_m`
/// alone, as one at z = 0; a garment starts where its file places it.
#[test]
fn a_flat_pattern_is_placed_by_its_origin_whatever_its_files_constant_z() {
    let dir = tempfile::tempdir().unwrap();
    let base =
        std::fs::read_to_string(root().join("datasets/patterns/l_panel_table.toml")).unwrap();
    let obj = std::fs::read_to_string(root().join("datasets/patterns/l_panel.obj")).unwrap();
    let lifted: String = obj
        .lines()
        .map(|l| match l.strip_suffix(" 0") {
            Some(v) if l.starts_with("v ") => format!("{v} 0.3\n"),
            _ => format!("{l}\n"),
        })
        .collect();
    assert_ne!(lifted, obj);
    std::fs::write(dir.path().join("l_panel.obj"), lifted).unwrap();
    std::fs::write(dir.path().join("scene.toml"), &base).unwrap();
    let scene = Scene::load(&dir.path().join("scene.toml"), &[])
        .unwrap()
        .scene;
    let z: Vec<f64> = scene.initial_positions().iter().map(|p| p.z).collect();
    assert!(z.iter().all(|&v| v == 0.0), "{:?}", &z[..3]);
    let skirt = Scene::load(&root().join("datasets/patterns/skirt_form.toml"), &[])
        .unwrap()
        .scene;
    let start = skirt.initial_positions();
    let p = skirt.pattern().unwrap();
    assert!(
        start
            .iter()
            .zip(&p.start_m)
            .all(|(a, b)| (a.z - b[2]).abs() < 1e-12)
    );
}

/// The cantilever's strip as a mesh: its grid (one more column at x = −h, where the grid's clamp
/// puts its ghost particle) split along one diagonal, or along alternating ones, the two columns
/// at x ≤ 0 pinned (group `pins`); the scene with `cloth.mesh` for the grid's keys and the clamp.
fn cantilever_twin(alternate: bool, dir: &Path) -> Scene {
    let base = scene("cantilever_wool_warp.toml", &[]);
    let (nx, ny) = (base.cloth.nx, base.cloth.ny);
    let h = base.cloth.size_x_m / (nx - 1) as f64;
    let hy = base.cloth.size_y_m / (ny - 1) as f64;
    let cols = nx + 1;
    let mut obj = String::new();
    for j in 0..ny {
        for i in 0..cols {
            obj += &format!("v {} {} 0\n", (i as f64 - 1.0) * h, j as f64 * hy);
        }
    }
    for j in 0..ny - 1 {
        for i in 0..cols - 1 {
            let a = j * cols + i + 1;
            let (b, c, d) = (a + 1, a + cols + 1, a + cols);
            obj += &match alternate && (i + j) % 2 == 1 {
                true => format!("f {a} {b} {d}\nf {b} {c} {d}\n"),
                false => format!("f {a} {b} {c}\nf {a} {c} {d}\n"),
            };
        }
    }
    obj += "g pins\nl";
    for j in 0..ny {
        obj += &format!(" {} {}", j * cols + 1, j * cols + 2);
    }
    std::fs::write(dir.join("strip.obj"), obj + "\n").unwrap();
    let text =
        std::fs::read_to_string(root().join("datasets/scenes/cantilever_wool_warp.toml")).unwrap();
    let mut out = String::new();
    for line in text.lines() {
        let key = line.split('=').next().unwrap_or("").trim();
        if GRID_KEYS.contains(&key) || key == "clamp_edges" {
            continue;
        }
        out += &format!("{line}\n");
        match line.trim() {
            "[cloth]" => out += "mesh = \"strip.obj\"\n",
            "[boundary]" => out += "pin_groups = [\"pins\"]\n",
            _ => {}
        }
    }
    std::fs::write(dir.join("strip.toml"), out).unwrap();
    Scene::load(&dir.join("strip.toml"), &[])
        .expect("cantilever twin")
        .scene
        .into_inner()
}

/// The wool cantilever re-run as a mesh of the same strip lands its tip within 1 % of the exact
/// heavy elastica (of the displacement) when split along one diagonal, where the patch bending
/// bends it; on alternating diagonals its patches misread creases and hinges bend it, stiffer
/// across the diagonals (measured 0.87 % and 11.8 %).
#[test]
fn a_cantilever_from_a_mesh_lands_its_tip_within_one_percent_of_the_elastica() {
    let base = scene("cantilever_wool_warp.toml", &[]);
    let (xe, ze) = drapelab::elastica::HeavyElastica::of_cantilever(&base)
        .unwrap()
        .tip();
    let (l, nx, ny) = (base.cloth.size_x_m, base.cloth.nx, base.cloth.ny);
    let dir = tempfile::tempdir().unwrap();
    let mut errors = Vec::new();
    for alternate in [false, true] {
        let twin = cantilever_twin(alternate, dir.path());
        let model = drapelab::build::build_scene(&twin.clone().validated().unwrap()).model;
        let bending = if alternate {
            "bending/hinge"
        } else {
            "bending/patch"
        };
        assert!(model.term_names().iter().any(|n| n == bending), "{bending}");
        let sol = solve_scene(&twin, &mut drapelab::solve::NoObserver);
        assert!(sol.report.is_converged(), "{}", sol.report.message);
        let tip = sol.x[(ny / 2) * (nx + 1) + nx];
        let err = (tip.x - xe).hypot(tip.z - ze) / (xe - l).hypot(ze);
        errors.push(err);
    }
    eprintln!("mesh cantilever tip error, one diagonal and alternating: {errors:?}");
    // The bundled L panel alternates its diagonals: hinges.
    let panel = Scene::load(&root().join("datasets/patterns/l_panel_table.toml"), &[]).unwrap();
    let names = drapelab::build::build_scene(&panel.scene)
        .model
        .term_names();
    assert!(names.iter().any(|n| n == "bending/hinge"), "{names:?}");
    assert!(errors[0] < 0.01, "{errors:?}");
}

/// A pattern one or two triangles wide (one triangle, two, a strip one cell wide) has no quadratic
/// patches: it is bent by hinges and drapes on the table like any pattern, where it panicked
/// (a fuzzer's find). The strip, over the table, ends with a status (exit 0, or 1 with its status
/// written), never a panic; the lone triangle or two, beside the table, are held by nothing
/// (`contact.fix_supported` fixes none of them) and are refused before the solve (exit 2 naming
/// the key), where they slid on for the whole iteration budget (issue 92).
#[test]
fn patterns_one_or_two_triangles_wide_drape_without_a_panic() {
    let dir = tempfile::tempdir().unwrap();
    let base = std::fs::read_to_string(root().join("datasets/patterns/l_panel_table.toml"))
        .unwrap()
        .replace(
            "origin_m = [-0.15, -0.15, 0.0]",
            "origin_m = [-0.09, -0.0075, 0.0]",
        );
    let strip: String = (0..=12)
        .flat_map(|i| [(i, 0.0), (i, 0.015)])
        .map(|(i, y)| format!("v {} {y} 0\n", i as f64 * 0.015))
        .chain((0..12).map(|i| {
            let (a, b) = (2 * i + 1, 2 * i + 3);
            format!("f {a} {b} {}\nf {a} {} {}\n", b + 1, b + 1, a + 1)
        }))
        .collect();
    let meshes = [
        (
            "one.obj",
            "v 0 0 0\nv 0.03 0 0\nv 0 0.03 0\nf 1 2 3\n".to_string(),
        ),
        (
            "two.obj",
            "v 0 0 0\nv 0.03 0 0\nv 0.03 0.03 0\nv 0 0.03 0\nf 1 2 3\nf 1 3 4\n".to_string(),
        ),
        ("strip.obj", strip),
    ];
    for (name, obj) in meshes {
        std::fs::write(dir.path().join(name), obj).unwrap();
        let scene = dir.path().join(format!("{name}.toml"));
        std::fs::write(&scene, base.replace("l_panel.obj", name)).unwrap();
        let out = dir.path().join(format!("{name}.out"));
        // A lone triangle or two slide on the frictionless table without converging: the run
        // is bounded, its status is what is checked.
        let o = simulate_recorded(&scene, &out, &["--set", "solver.static.max_iterations=100"]);
        let err = String::from_utf8_lossy(&o.stderr);
        let code = o.status.code();
        if name != "strip.obj" {
            assert_eq!(code, Some(2), "{name}: {err}");
            assert!(
                err.contains("contact.fix_supported") && err.contains(name),
                "{err}"
            );
            assert!(!out.exists(), "{name}: a refusal left {}", out.display());
            continue;
        }
        assert!(matches!(code, Some(0) | Some(1)), "{name}: {code:?} {err}");
        assert!(!err.contains("panicked"), "{name}: {err}");
        assert!(
            out.join("run.json").exists(),
            "{name}: no status written; {err}"
        );
    }
}
