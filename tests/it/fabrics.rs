//! Fabric files (issue 77): a scene takes its material from a fabric file (`[material] fabric =
//! "FILE"` or `--fabric FILE`) and drapes exactly as with the same material written inline; bad
//! fabric inputs are refused naming the file and the key.

use crate::support::{assert_bad_input, root};
use drapelab::io::read_particles;
use std::path::Path;

fn wool() -> std::path::PathBuf {
    root().join("datasets/fabrics/wool_seed003.toml")
}

/// sphere_wool.toml with its `[material.continuum]` table and its areal density replaced by
/// `material` (TOML text), written into `dir`.
fn sphere_with(dir: &Path, material: &str) -> std::path::PathBuf {
    let text = std::fs::read_to_string(root().join("datasets/scenes/sphere_wool.toml")).unwrap();
    let start = text.find("[material.continuum]").unwrap();
    let end = start + text[start..].find("\n\n").unwrap();
    let text = format!("{}{material}{}", &text[..start], &text[end..])
        .replace("areal_density_kg_per_m2 = 0.19\n", "");
    let path = dir.join("sphere.toml");
    std::fs::write(&path, text).unwrap();
    path
}

fn simulate(scene: &Path, out: &Path, extra: &[&str]) -> Vec<(u32, u32, nalgebra::Vector3<f64>)> {
    crate::support::simulate_ok(scene, out, extra);
    read_particles(&out.join("particles.parquet")).unwrap()
}

/// The bundled wool fabric file holds seed 003's Table 10.3, as sphere_wool.toml writes it inline:
/// the scene with `[material] fabric = …`, and sphere_wool with `--fabric`, drape bit for bit as
/// sphere_wool itself.
#[test]
fn a_scene_in_a_fabric_file_drapes_as_with_its_material_inline() {
    let dir = tempfile::tempdir().unwrap();
    let inline = simulate(
        &root().join("datasets/scenes/sphere_wool.toml"),
        &dir.path().join("inline"),
        &[],
    );
    let named = sphere_with(
        dir.path(),
        &format!("[material]\nfabric = {:?}", wool().display().to_string()),
    );
    let from_file = simulate(&named, &dir.path().join("file"), &[]);
    assert_eq!(inline, from_file);
    let flag = simulate(
        &root().join("datasets/scenes/sphere_wool.toml"),
        &dir.path().join("flag"),
        &["--fabric", wool().to_str().unwrap()],
    );
    assert_eq!(inline, flag);
}

/// Each bad fabric input: exit 2, one line naming the file (or flag) and the key, nothing written.
#[test]
fn bad_fabric_inputs_are_refused_naming_the_file_and_key() {
    let dir = tempfile::tempdir().unwrap();
    let no_density = dir.path().join("no_density.toml");
    std::fs::write(
        &no_density,
        std::fs::read_to_string(wool())
            .unwrap()
            .replace("areal_density_kg_per_m2 = 0.19\n", ""),
    )
    .unwrap();
    let unknown = dir.path().join("unknown.toml");
    std::fs::write(
        &unknown,
        std::fs::read_to_string(wool())
            .unwrap()
            .replace("[fabric.continuum]", "[fabric.continuum]\nstretch = 3"),
    )
    .unwrap();
    let file = |p: &Path| format!("[material]\nfabric = {:?}", p.display().to_string());
    let both = format!(
        "{}\n[material.continuum]\nbending_warp_N_m = 1e-6",
        file(&wool())
    );
    let cases: [(String, &[&str]); 4] = [
        (both, &["sphere.toml", "material"]),
        (
            file(&dir.path().join("missing.toml")),
            &["sphere.toml", "material.fabric", "not a file"],
        ),
        (
            file(&no_density),
            &[
                "sphere.toml",
                "cloth.areal_density_kg_per_m2",
                "no areal density",
            ],
        ),
        (
            file(&unknown),
            &["unknown.toml", "fabric.continuum.stretch"],
        ),
    ];
    for (k, (material, names)) in cases.into_iter().enumerate() {
        let scene = sphere_with(dir.path(), &material);
        let out = dir.path().join(format!("out{k}"));
        let args = [Path::new("simulate"), &scene, Path::new("--out"), &out];
        assert_bad_input(args, names);
        assert!(!out.exists(), "case {k}: nothing written");
    }
    let out = dir.path().join("flag-out");
    let scene = root().join("datasets/scenes/sphere_wool.toml");
    let missing = dir.path().join("nowhere.toml");
    let args = [
        Path::new("simulate"),
        &scene,
        Path::new("--out"),
        &out,
        Path::new("--fabric"),
        &missing,
    ];
    assert_bad_input(args, &["--fabric", "nowhere.toml", "not a file"]);
    assert!(!out.exists());
}

/// A strip 10 cm × 2 cm of 41 × 5 vertices (alternating diagonals), its first two columns in group
/// `root`, and a scene over it with `material` (TOML lines added to `[material.continuum]`) and
/// areal density `density`, written into `dir`.
fn strip_scene(dir: &Path, material: &str, density: f64) -> std::path::PathBuf {
    let (nx, ny, l, w) = (41, 5, 0.1, 0.02);
    let mut obj = String::new();
    for j in 0..ny {
        for i in 0..nx {
            obj += &format!("v {} {} 0\n", l * i as f64 / 40.0, w * j as f64 / 4.0);
        }
    }
    for j in 0..ny - 1 {
        for i in 0..nx - 1 {
            let a = j * nx + i + 1;
            let (b, c, d) = (a + 1, a + nx + 1, a + nx);
            obj += &match (i + j) % 2 {
                0 => format!("f {a} {b} {c}\nf {a} {c} {d}\n"),
                _ => format!("f {a} {b} {d}\nf {b} {c} {d}\n"),
            };
        }
    }
    let root: Vec<String> = (0..ny)
        .flat_map(|j| [j * nx + 1, j * nx + 2])
        .map(|v| v.to_string())
        .collect();
    obj += &format!("g root\nl {}\n", root.join(" "));
    std::fs::write(dir.join("strip.obj"), obj).unwrap();
    // A stiff strip with next to no weight rolls by its curl alone; a wool-like one droops.
    let b = if density < 0.01 { 1e-3 } else { 1e-4 };
    let scene = format!(
        "name = \"strip\"\n[cloth]\nmesh = \"strip.obj\"\nareal_density_kg_per_m2 = {density}\n\
         [material.continuum]\ntensile_warp_N_per_m = 1000.0\ntensile_weft_N_per_m = 1000.0\n\
         shear_N_per_m = 100.0\nbending_warp_N_m = {b:e}\nbending_weft_N_m = {b:e}\n{material}\n\
         [boundary]\npin_groups = [\"root\"]\n[solver]\nkind = \"static\"\n"
    );
    let path = dir.join("strip.toml");
    std::fs::write(&path, scene).unwrap();
    path
}

/// The tip of a strip's drape (its last column's middle vertex), m.
fn strip_tip(dir: &Path, material: &str, density: f64) -> nalgebra::Vector3<f64> {
    let out = dir.join(format!("out{}{density}", material.replace(' ', "")));
    let x = simulate(&strip_scene(dir, material, density), &out, &[]);
    x[2 * 41 + 40].2
}

/// The continuum keys the Cusick calibration fits, on a mesh sheet: a strip clamped at one end
/// with `curl_per_m` and next to no weight rolls up toward the side the curl's sign names, the
/// more the larger the curl, and mirrored for the opposite sign (its tip's height within 1 %); a
/// bending saturation far above every curvature the drape reaches bends as linear bending (the tip
/// within 10⁻⁵ of its droop, a little lower), one within them makes the cantilever droop further; a
/// grid sheet refuses both keys, naming them.
#[test]
fn a_mesh_strip_rolls_to_its_curl_and_droops_further_when_its_bending_saturates() {
    let dir = tempfile::tempdir().unwrap();
    let rolled = |kappa: f64| strip_tip(dir.path(), &format!("curl_per_m = {kappa:?}"), 1e-3);
    let (up, more, down) = (rolled(5.0), rolled(10.0), rolled(-5.0));
    assert!(up.z > 0.01 && more.z > up.z + 0.01, "{up} then {more}");
    assert!((up.z + down.z).abs() < 0.01 * up.z, "{up} against {down}");
    let linear = strip_tip(dir.path(), "", 0.2);
    let high = strip_tip(dir.path(), "bending_saturation_per_m = 10000.0", 0.2);
    let low = strip_tip(dir.path(), "bending_saturation_per_m = 5.0", 0.2);
    assert!(linear.z < -0.01, "the cantilever droops: {linear}");
    assert!(
        (linear - high).norm() < 1e-5 * linear.z.abs(),
        "{linear} against {high}"
    );
    assert!(high.z < linear.z, "{} against {}", high.z, linear.z);
    assert!(low.z < linear.z - 0.005, "{} against {}", low.z, linear.z);
    let sphere = root().join("datasets/scenes/sphere_wool.toml");
    for key in ["curl_per_m", "bending_saturation_per_m"] {
        let set = format!("material.continuum.{key}=3.0");
        let names = [format!("material.continuum.{key}"), "mesh".into()];
        crate::support::assert_bad_set(&sphere, &set, &names.each_ref().map(|n| n.as_str()));
    }
}
