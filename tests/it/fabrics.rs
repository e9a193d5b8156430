//! Fabric files (issue 77): a scene takes its material from a fabric file (`[material] fabric =
//! "FILE"` or `--fabric FILE`) and drapes exactly as with the same material written inline; bad
//! fabric inputs are refused naming the file and the key.

use crate::support::{assert_bad_input, drapelab, root};
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
    let o = drapelab()
        .arg("-q")
        .arg("simulate")
        .arg(scene)
        .arg("--out")
        .arg(out)
        .args(extra)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
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
