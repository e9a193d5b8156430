//! Issue 20: smooth textured drape surfaces (seed 003 §10.8) — trimming, texture mapping, glTF.

use crate::support::{drapelab, root, run_python, scene};
use drapelab::scene::Scene;
use drapelab_core::surface::{DrapeSurface, Parametrization, SurfaceMesh};
use nalgebra::Vector3;

/// A scene solved statically: its grid, positions and which particles belong to the sheet.
fn solved(s: &Scene) -> (drapelab_core::cloth::Grid, Vec<Vector3<f64>>, Vec<bool>) {
    let v = s.clone().validated().expect("valid");
    let built = drapelab_core::build::build_scene(&v);
    let (grid, mut model, mut x) = (built.grid, built.model, built.x0);
    let present: Vec<bool> = model.masses[..grid.len()]
        .iter()
        .map(|m| *m > 0.0)
        .collect();
    let r = drapelab_core::simulate::solve_model(
        &v,
        &grid,
        &mut model,
        &mut x,
        &mut drapelab_core::solve::NoObserver,
    );
    assert!(r.is_converged(), "{}: {}", s.name, r.message);
    x.truncate(grid.len());
    (grid, x, present)
}

/// Area of the parameter-plane triangles of a mesh.
fn param_area(m: &SurfaceMesh) -> f64 {
    m.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|k| m.params[k as usize]);
            ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])).abs() / 2.0
        })
        .sum()
}

/// Chessboard distance, in pixels, from every pixel to the nearest covered pixel of `p` (BFS).
fn distance_to(p: &drapelab_core::measure::Projection) -> Vec<usize> {
    let mut d = vec![usize::MAX; p.covered.len()];
    let mut queue: std::collections::VecDeque<usize> =
        (0..p.covered.len()).filter(|&k| p.covered[k]).collect();
    queue.iter().for_each(|&k| d[k] = 0);
    while let Some(k) = queue.pop_front() {
        let (c, r) = ((k % p.nx) as i64, (k / p.nx) as i64);
        for (dc, dr) in [
            (-1, -1),
            (-1, 0),
            (-1, 1),
            (0, -1),
            (0, 1),
            (1, -1),
            (1, 0),
            (1, 1),
        ] {
            let (c2, r2) = (c + dc, r + dr);
            if c2 >= 0 && r2 >= 0 && (c2 as usize) < p.nx && (r2 as usize) < p.ny {
                let q = r2 as usize * p.nx + c2 as usize;
                if d[q] == usize::MAX {
                    d[q] = d[k] + 1;
                    queue.push_back(q);
                }
            }
        }
    }
    d
}

/// The largest distance from a point of `params` outside the region of `triangles` (over `pts`) to
/// that region's outline.
fn beyond_region(params: &[[f64; 2]], pts: &[[f64; 2]], triangles: &[[u32; 3]]) -> f64 {
    let inside = |q: [f64; 2]| {
        triangles.iter().any(|t| {
            let [a, b, c] = t.map(|k| pts[k as usize]);
            let cross = |p: [f64; 2], r: [f64; 2]| {
                (r[0] - p[0]) * (q[1] - p[1]) - (r[1] - p[1]) * (q[0] - p[0])
            };
            let (d0, d1, d2) = (cross(a, b), cross(b, c), cross(c, a));
            let e = 1e-12;
            (d0 >= -e && d1 >= -e && d2 >= -e) || (d0 <= e && d1 <= e && d2 <= e)
        })
    };
    let loops = drapelab_core::surface::outline(pts, triangles);
    let seg_dist = |q: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let t = (((q[0] - a[0]) * dx + (q[1] - a[1]) * dy) / (dx * dx + dy * dy)).clamp(0.0, 1.0);
        ((q[0] - a[0] - t * dx).powi(2) + (q[1] - a[1] - t * dy).powi(2)).sqrt()
    };
    params
        .iter()
        .filter(|q| !inside(**q))
        .map(|q| {
            loops
                .iter()
                .flat_map(|l| (0..l.len()).map(move |k| (l[k], l[(k + 1) % l.len()])))
                .map(|(a, b)| seg_dist(*q, pts[a as usize], pts[b as usize]))
                .fold(f64::INFINITY, f64::min)
        })
        .fold(0.0, f64::max)
}

/// Seed 003 §10.8 on the skirt: extended to the rectangle, interpolated, trimmed. The surface passes
/// through every particle; in the pattern (parameter) plane the trimmed region has the area of the
/// solver's mesh; seen from above (the shadow a drape tester measures) it covers the mesh's shadow to
/// 1 %, reaching beyond it only by the bulge of a cubic between nodes.
#[test]
fn the_trimmed_skirt_covers_its_own_mesh_and_nothing_outside_it() {
    let s = scene("skirt_wool.toml", &[]);
    let (grid, x, present) = solved(&s);
    let surf = DrapeSurface::new(&grid, &x, &present, Parametrization::Uniform).expect("surface");
    let (u, v) = surf.shape.params.clone();
    let worst_node = (0..grid.len())
        .filter(|&p| present[p])
        .map(|p| (surf.shape.point(u[p % grid.nx], v[p / grid.nx]) - x[p]).norm())
        .fold(0.0, f64::max);
    assert!(
        worst_node < 1e-10,
        "a node {worst_node:.2e} m off the surface"
    );
    let mesh = surf.tessellate(240);
    let kept: Vec<[u32; 3]> = drapelab_core::cloth::grid_triangles(&grid)
        .into_iter()
        .filter(|t| t.iter().all(|&k| present[k as usize]))
        .collect();
    let pts: Vec<[f64; 2]> = (0..grid.len())
        .map(|p| [u[p % grid.nx], v[p / grid.nx]])
        .collect();
    let kept_param: f64 = kept
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|k| pts[k as usize]);
            ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])).abs() / 2.0
        })
        .sum();
    let rel = (param_area(&mesh) - kept_param).abs() / kept_param;
    assert!(
        rel < 0.01,
        "pattern-plane area {:.5} against the mesh's {kept_param:.5}",
        param_area(&mesh)
    );
    let shadow_mesh = drapelab_core::measure::vertical_projection(&x, &kept, 1000);
    let mut shadow = drapelab_core::measure::Projection::empty(
        shadow_mesh.nx,
        shadow_mesh.ny,
        shadow_mesh.pixel_m,
        shadow_mesh.origin_m,
    );
    shadow.fill_triangles(
        &mesh.positions,
        mesh.triangles.iter().map(|t| t.map(|k| k as usize)),
    );
    let (a, b) = (shadow.area_m2(), shadow_mesh.area_m2());
    println!(
        "shadow: surface {a:.5} m², mesh {b:.5} m² ({:+.2} %)",
        100.0 * (a - b) / b
    );
    assert!(
        (a - b).abs() < 0.01 * b,
        "shadow {a:.5} m² against the mesh's {b:.5} m²"
    );
    let dist = distance_to(&shadow_mesh);
    let farthest = shadow
        .covered
        .iter()
        .zip(&dist)
        .filter(|(c, _)| **c)
        .map(|(_, d)| *d)
        .max()
        .unwrap_or(0) as f64
        * shadow.pixel_m;
    let h = grid.min_spacing_m();
    println!(
        "farthest beyond the mesh's shadow: {:.2} mm (grid spacing {:.1} mm)",
        farthest * 1e3,
        h * 1e3
    );
    // Between nodes a cubic bulges beyond the chords of the solver's mesh where the drape bends
    // sharply (at the hem), by h²/(8r) for a bend of radius r, and the smooth hem runs beyond the
    // staircase's notches: 8.4 mm here at h = 22.5 mm.
    assert!(
        farthest < 0.5 * h,
        "the surface reaches {farthest:.4} m beyond the mesh's shadow"
    );
    // In the pattern plane the trimmed domain stays on the mesh's region: where the smooth outline
    // crosses the staircase (a smooth hem runs through its middle) it leaves it by less than half a
    // cell (0.33 here: the notches of the staircase it smooths over).
    let beyond = beyond_region(&mesh.params, &pts, &kept);
    let cell = 1.0 / (grid.nx - 1) as f64;
    println!(
        "pattern plane: farthest beyond the mesh's region {:.3} of a cell",
        beyond / cell
    );
    assert!(
        beyond < 0.5 * cell,
        "the trimmed domain leaves the mesh's region by {:.3} cells",
        beyond / cell
    );
}

/// Installs the Khronos glTF validator (tests/gltf, `npm ci`) once per test process and validates
/// `glb`: the report's JSON (issues and info).
pub(crate) fn gltf_validate(glb: &std::path::Path) -> serde_json::Value {
    static READY: std::sync::OnceLock<()> = std::sync::OnceLock::new();
    let dir = root().join("tests/gltf");
    READY.get_or_init(|| {
        if !dir.join("node_modules/gltf-validator").exists() {
            let ok = std::process::Command::new("npm")
                .args(["ci", "--no-audit", "--no-fund", "--silent"])
                .current_dir(&dir)
                .status()
                .is_ok_and(|s| s.success());
            assert!(
                ok,
                "npm ci in tests/gltf failed: the tests need Node.js with npm"
            );
        }
    });
    let out = std::process::Command::new("node")
        .arg(dir.join("validate.js"))
        .arg(glb)
        .output()
        .expect("node runs");
    assert!(
        out.status.code().is_some_and(|c| c <= 1),
        "the validator did not run: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("the validator's report")
}

/// `drapelab surface` on a run folder: drape.glb passes the Khronos validator with no errors,
/// pygltflib reads as many vertices and triangles as surface.json says with the texture embedded
/// and +Y up (its height range is the drape's z range), and rerun-sdk reads the textured mesh.
#[test]
fn the_glb_passes_the_khronos_validator_and_loads_in_python() {
    let tmp = tempfile::tempdir().unwrap();
    let run = tmp.path().join("run");
    let o = drapelab()
        .args(["simulate", "datasets/scenes/hang4.toml", "--out"])
        .arg(&run)
        .args(["--set", "cloth.nx=15", "--set", "cloth.ny=15"])
        .current_dir(root())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = tmp.path().join("surf");
    let o = drapelab()
        .arg("surface")
        .arg(&run)
        .args(["--out"])
        .arg(&out)
        .args([
            "--resolution",
            "57",
            "--repeats",
            "3,2",
            "--rotation-deg",
            "15",
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("surface.json")).unwrap()).unwrap();
    // A full rectangle: the 57 × 57 lattice (through every node of the 15 × 15 grid), two
    // triangles a cell, no trimming.
    assert_eq!(summary["vertices"], 57 * 57);
    assert_eq!(summary["triangles"], 2 * 56 * 56);
    assert_eq!(summary["trimmed"], false);
    assert!(summary["max_node_distance_m"].as_f64().unwrap() < 1e-10);
    let report = gltf_validate(&out.join("drape.glb"));
    let issues = &report["issues"];
    assert_eq!(issues["numErrors"], 0, "{issues}");
    assert_eq!(issues["numWarnings"], 0, "{issues}");
    assert_eq!(report["info"]["totalVertexCount"], 57 * 57);
    assert_eq!(report["info"]["hasTextures"], true);
    let printed = run_python(
        r#"
import sys, pygltflib, pyarrow.parquet as pq
from rerun.experimental import RrdReader
g = pygltflib.GLTF2().load(sys.argv[1])
prim = g.meshes[0].primitives[0]
pos = g.accessors[prim.attributes.POSITION]
idx = g.accessors[prim.indices]
assert g.accessors[prim.attributes.TEXCOORD_0].count == pos.count
assert g.images[0].mimeType == "image/png" and g.textures[0].source == 0
z = pq.read_table(sys.argv[2]).column("z_m").to_pylist()
# +Z up became +Y up: the heights are the drape's z range (the lattice passes through the nodes).
assert abs(pos.min[1] - min(z)) < 1e-6 and abs(pos.max[1] - max(z)) < 1e-6, (pos.min, pos.max, min(z), max(z))
mesh = None
for c in RrdReader(sys.argv[3]).stream().to_chunks():
    if c.entity_path.startswith("/surface/"):
        mesh = c.to_record_batch()
assert mesh is not None
names = set(mesh.schema.names)
assert {"Mesh3D:vertex_texcoords", "Mesh3D:albedo_texture_buffer", "Mesh3D:vertex_normals"} <= names, names
print(pos.count, idx.count // 3, len(mesh.column("Mesh3D:vertex_texcoords")[0]))
"#,
        &[
            &out.join("drape.glb"),
            &run.join("particles.parquet"),
            &out.join("surface.rrd"),
        ],
    );
    assert_eq!(printed.trim(), format!("3249 {} 3249", 2 * 56 * 56));
}

/// Bad inputs to `drapelab surface` exit 2 naming the flag, before any work, and write nothing.
#[test]
fn bad_surface_inputs_exit_2_naming_the_argument() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("o");
    let scene = root().join("datasets/scenes/hang4.toml");
    let not_image = root().join("README.md");
    let missing = tmp.path().join("no_such.png");
    let cases: Vec<(Vec<std::ffi::OsString>, Vec<&str>)> = vec![
        (
            vec!["--texture".into(), missing.clone().into()],
            vec!["--texture", "no_such.png"],
        ),
        (
            vec!["--texture".into(), not_image.clone().into()],
            vec!["--texture", "README.md", "not a PNG or JPEG"],
        ),
        (
            vec!["--repeats".into(), "0,3".into()],
            vec!["--repeats", "> 0"],
        ),
        (vec!["--repeats".into(), "-2".into()], vec!["--repeats"]),
        (vec!["--repeats".into(), "six".into()], vec!["--repeats"]),
        (
            vec!["--resolution".into(), "1".into()],
            vec!["--resolution"],
        ),
    ];
    for (extra, names) in cases {
        let mut args: Vec<std::ffi::OsString> = vec![
            "surface".into(),
            scene.clone().into(),
            "--out".into(),
            out.clone().into(),
        ];
        args.extend(extra);
        crate::support::assert_bad_input(&args, &names);
        assert!(!out.exists(), "{names:?}: the output folder was made");
    }
}

/// A flat square sheet dressed with a checkerboard at 4 × 4 repeats, rendered from straight above:
/// the squares come out square (aspect within 1 %); on a 0.9 × 0.6 m sheet with 3 × 2 repeats too
/// (the repeats set per direction keep tiles square when they match the sides).
#[test]
fn a_flat_sheet_maps_a_checkerboard_without_distortion() {
    for (lx, ly, reps) in [(0.6, 0.6, [4.0, 4.0]), (0.9, 0.6, [3.0, 2.0])] {
        let grid = drapelab_core::cloth::Grid::uniform(13, 9, lx, ly);
        let x = grid.flat_positions();
        let surf = DrapeSurface::new(
            &grid,
            &x,
            &vec![true; grid.len()],
            Parametrization::ChordLength,
        )
        .unwrap();
        let mesh = surf.tessellate(40);
        assert!(
            mesh.positions.iter().all(|p| p.z.abs() < 1e-12)
                && mesh.normals.iter().all(|n| (n.z - 1.0).abs() < 1e-12)
        );
        let map = drapelab_core::surface::TextureMapping {
            repeats: reps,
            rotation_deg: 0.0,
        };
        let st: Vec<[f64; 2]> = mesh
            .material_m
            .iter()
            .map(|m| map.texcoord(*m, surf.extent_m))
            .collect();
        let tex = drapelab_core::surface::checkerboard(64, 2);
        let view = drapelab_core::surface::View {
            azimuth_deg: 0.0,
            elevation_deg: 90.0,
        };
        let img = drapelab_core::surface::render_surface(
            &mesh,
            &drapelab_core::surface::Paint::Texture(&tex, &st),
            view,
            (900, 900),
            10,
        );
        // Transitions between dark and light along the middle row and column, px.
        let dark = |x: u32, y: u32| img.get_pixel(x, y).0[0] < 120;
        let edges = |n: u32, at: &dyn Fn(u32) -> bool| {
            let mut e = Vec::new();
            let mut prev = None;
            for k in 0..n {
                let d = at(k);
                if prev.is_some_and(|p| p != d) {
                    e.push(k as f64);
                }
                prev = Some(d);
            }
            e
        };
        let (w, h) = (img.width(), img.height());
        let across = edges(w, &|k| dark(k, h / 2 + 7));
        let down = edges(h, &|k| dark(w / 2 + 7, k));
        let size = |e: &[f64]| (e[e.len() - 2] - e[1]) / (e.len() - 3) as f64;
        let (sx, sy) = (size(&across), size(&down));
        println!("{lx}×{ly} m, repeats {reps:?}: squares {sx:.2} × {sy:.2} px");
        assert!(across.len() >= 6 && down.len() >= 6, "{across:?} {down:?}");
        assert!((sx / sy - 1.0).abs() < 0.01, "squares {sx:.2} × {sy:.2} px");
    }
}

/// The bundled textures (datasets/textures) are exactly what drapelab's generators draw, so their
/// provenance line holds; `DRAPELAB_BLESS=1` rewrites them.
#[test]
fn the_bundled_textures_are_drapelabs_own_drawings() {
    let dir = root().join("datasets/textures");
    for (file, img) in [
        ("woven_check.png", drapelab_core::surface::woven_check(256)),
        (
            "warp_stripes.png",
            drapelab_core::surface::warp_stripes(128),
        ),
    ] {
        let path = dir.join(file);
        if std::env::var("DRAPELAB_BLESS").is_ok_and(|v| v == "1") {
            img.save(&path).unwrap();
        }
        let bundled = image::open(&path).unwrap().to_rgb8();
        assert!(bundled == img, "{file} differs from its generator");
    }
}

/// The `surface` stage kind in a pipeline: a scene solved in the stage and dressed with a bundled
/// texture (its glb passes the validator, the picture is the size asked for); repeats ≤ 0 in its
/// params are refused when the plan loads (exit 2, naming the file and key), before anything runs.
#[test]
fn the_surface_stage_dresses_a_scene_and_refuses_bad_repeats() {
    let pipeline = r#"
name = "t"
[stages.dress]
kind = "surface"
inputs.drape = "datasets/scenes/hang4.toml"
inputs.texture = "datasets/textures/warp_stripes.png"
outputs.glb = "{run}/dress/drape.glb"
outputs.picture = "{run}/dress/drape.png"
outputs.summary = "{run}/dress/surface.json"
params = { repeats = [2.0, 2.0], resolution = 41, picture_px = [320, 240] }
"#;
    let (tmp, file) = crate::support::temp_project(
        &["datasets/scenes/hang4.toml", "datasets/textures/*.png"],
        "t.toml",
        pipeline,
    );
    crate::support::run_plan(&file);
    let dir = tmp.path().join("runs/t/dress");
    let pic = image::open(dir.join("drape.png")).unwrap();
    assert_eq!((pic.width(), pic.height()), (320, 240));
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("surface.json")).unwrap()).unwrap();
    assert_eq!(s["vertices"], 41 * 41);
    assert!(
        s["texture"].as_str().unwrap().ends_with("warp_stripes.png"),
        "{s}"
    );
    assert_eq!(
        gltf_validate(&dir.join("drape.glb"))["issues"]["numErrors"],
        0
    );
    let bad = file.with_file_name("bad.toml");
    std::fs::write(
        &bad,
        pipeline.replace("repeats = [2.0, 2.0]", "repeats = [2.0, 0.0]"),
    )
    .unwrap();
    let err = crate::support::assert_bad_input(
        ["run".as_ref(), bad.as_os_str()],
        &["bad.toml", "stages.dress.params.repeats"],
    );
    assert!(err.contains("> 0"), "{err}");
    assert!(!tmp.path().join("runs/bad").exists(), "{err}");
}
