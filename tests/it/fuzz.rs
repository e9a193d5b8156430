//! Issue 78: a property test over mutated inputs. Bundled scenes (a grid net, a continuum sheet
//! over a sphere, a sheet on a mesh body) with one value replaced by an extreme one (0, a negative,
//! 1e300, NaN, a huge or wrong-typed value), a key deleted or an unknown key added, each run
//! through `drapelab simulate` with a small iteration budget: no run panics, a refused input exits
//! 2 with one line and leaves nothing, and a run that exits 0 or 1 writes a run.json whose status
//! is one of the statuses.

use crate::support::{drapelab, root};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::Path;

/// The values a mutation puts in place of a number, as TOML.
const EXTREMES: [&str; 9] = [
    "0", "0.0", "-1.0", "1e300", "nan", "inf", "-0.0", "\"text\"", "[1, 2]",
];

/// Every `key = value` line of a scene's text whose value starts like a number or a list.
fn numeric_lines(text: &str) -> Vec<usize> {
    text.lines()
        .enumerate()
        .filter(|(_, l)| {
            let v = l.split_once(" = ").map(|(_, v)| v.trim_start());
            v.is_some_and(|v| v.starts_with(|c: char| c.is_ascii_digit() || c == '-' || c == '['))
        })
        .map(|(k, _)| k)
        .collect()
}

/// `text` with one mutation drawn by `rng`.
fn mutated(text: &str, rng: &mut ChaCha8Rng) -> String {
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let numeric = numeric_lines(text);
    let k = numeric[rng.random_range(0..numeric.len())];
    match rng.random_range(0..4) {
        0 => lines[k].clear(),
        1 => lines.insert(k + 1, "unknown_key_m = 1.0".into()),
        _ => {
            let key = lines[k]
                .split_once(" = ")
                .map(|(k, _)| k.to_string())
                .unwrap_or_default();
            lines[k] = format!("{key} = {}", EXTREMES[rng.random_range(0..EXTREMES.len())]);
        }
    }
    lines.join("\n") + "\n"
}

/// Runs `drapelab -q simulate SCENE --out OUT` with `sets` and checks the property: exit 0, 1 or
/// 2; a refusal (2) is one line on stderr naming one of `names` and leaves nothing; a run (0 or 1)
/// writes a run.json whose status is a status, with a message, and exits 0 exactly when it
/// converged. Returns the exit code.
fn checked_run(scene: &Path, out: &Path, sets: &[&str], names: &[&str], what: &str) -> usize {
    let mut cmd = drapelab();
    cmd.args(["-q", "simulate"])
        .arg(scene)
        .arg("--out")
        .arg(out);
    for s in sets {
        cmd.args(["--set", s]);
    }
    let o = cmd.output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    let code = o.status.code();
    assert!(matches!(code, Some(0..=2)), "{what}: exit {code:?}: {err}");
    if code == Some(2) {
        assert_eq!(err.trim().lines().count(), 1, "{what}: {err}");
        assert!(names.iter().any(|n| err.contains(n)), "{what}: {err}");
        assert!(!out.exists(), "{what}: a refusal left {}", out.display());
        return 2;
    }
    let run: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).unwrap()).unwrap();
    let status = run["status"].as_str().unwrap_or_default();
    let statuses = ["converged", "max-iterations", "diverged", "invalid"];
    assert!(statuses.contains(&status), "{what}: status {status:?}");
    assert_eq!(
        code == Some(0),
        status == "converged",
        "{what}: exit {code:?}, {status}"
    );
    let message = run["report"]["message"].as_str().unwrap_or_default();
    assert!(!message.is_empty(), "{what}: {status} without a message");
    code.unwrap() as usize
}

#[test]
fn mutated_scenes_never_panic_and_every_exit_is_a_result_or_a_refusal() {
    let scenes = [
        root().join("datasets/scenes/hang4.toml"),
        root().join("datasets/scenes/sphere_wool.toml"),
        root().join("datasets/bodies/table_wool_mesh.toml"),
    ];
    let mut rng = ChaCha8Rng::seed_from_u64(78);
    let dir = tempfile::tempdir().unwrap();
    let mut outcomes = [0usize; 3];
    for case in 0..60 {
        let source = &scenes[case % scenes.len()];
        // Relative mesh and fabric paths made absolute: the scene is written elsewhere.
        let folder = source.parent().unwrap().display().to_string();
        let original = std::fs::read_to_string(source)
            .unwrap()
            .replace("mesh = \"", &format!("mesh = \"{folder}/"))
            .replace("fabric = \"", &format!("fabric = \"{folder}/"));
        let text = mutated(&original, &mut rng);
        let scene = dir.path().join(format!("case{case}.toml"));
        std::fs::write(&scene, &text).unwrap();
        let out = dir.path().join(format!("out{case}"));
        let sets = [
            "solver.static.max_iterations=40",
            "cloth.nx=11",
            "cloth.ny=11",
        ];
        let what = format!("case {case}\n{text}");
        outcomes[checked_run(&scene, &out, &sets, &["case", ".toml"], &what)] += 1;
    }
    eprintln!("exits 0 / 1 / 2: {outcomes:?}");
    assert!(outcomes[2] > 10 && outcomes[0] > 5, "{outcomes:?}");
}

/// `obj` with one line mutated by `rng`: a vertex's coordinate made extreme, a face's index moved
/// out of range or onto its neighbour's, a line deleted or doubled.
fn mutated_obj(obj: &str, rng: &mut ChaCha8Rng) -> String {
    let mut lines: Vec<String> = obj.lines().map(String::from).collect();
    let k = rng.random_range(2..lines.len());
    let words: Vec<String> = lines[k].split_whitespace().map(String::from).collect();
    match (words.first().map(String::as_str), rng.random_range(0..4)) {
        (Some("v"), 0) => lines[k] = format!("v {} {} nan", words[1], words[2]),
        (Some("v"), 1) => lines[k] = format!("v 1e300 {} {}", words[2], words[3]),
        (Some("f"), 0) => lines[k] = format!("f {} {} 99999", words[1], words[2]),
        (Some("f"), 1) => lines[k] = format!("f {} {} {}", words[1], words[1], words[2]),
        (_, 2) => lines[k].clear(),
        _ => {
            let copy = lines[k].clone();
            lines.insert(k, copy);
        }
    }
    lines.join("\n") + "\n"
}

/// The same property over mutated pattern meshes (the L-shaped panel on the sphere): a file that
/// is no valid pattern is refused naming it (exit 2, one line, nothing written); one that still is
/// drapes with a status.
#[test]
fn mutated_pattern_meshes_never_panic_and_every_exit_is_a_result_or_a_refusal() {
    let folder = root().join("datasets/patterns");
    let scene_text = std::fs::read_to_string(folder.join("l_panel_sphere.toml")).unwrap();
    let obj = std::fs::read_to_string(folder.join("l_panel.obj")).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(49);
    let dir = tempfile::tempdir().unwrap();
    let mut outcomes = [0usize; 3];
    for case in 0..30 {
        std::fs::write(dir.path().join("l_panel.obj"), mutated_obj(&obj, &mut rng)).unwrap();
        let scene = dir.path().join("scene.toml");
        std::fs::write(&scene, &scene_text).unwrap();
        let out = dir.path().join(format!("out{case}"));
        let sets = ["solver.static.max_iterations=30"];
        let names = ["l_panel.obj", "scene.toml"];
        outcomes[checked_run(&scene, &out, &sets, &names, &format!("case {case}"))] += 1;
    }
    eprintln!("exits 0 / 1 / 2: {outcomes:?}");
    assert!(
        outcomes[2] > 5 && outcomes[1] + outcomes[0] > 2,
        "{outcomes:?}"
    );
}

/// `text` (a body OBJ, a pattern OBJ or a fabric file) with one byte-level or line-level mutation
/// drawn by `rng` (issue 92): truncated at a random byte, a number made NaN, huge or negative, an
/// index out of range, a line deleted, doubled or reversed, a byte-order mark or a Latin-1 byte
/// added, an unknown key.
fn mutated_bytes(text: &str, rng: &mut ChaCha8Rng) -> Vec<u8> {
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let numbered: Vec<usize> = (0..lines.len())
        .filter(|&k| {
            lines[k]
                .split_whitespace()
                .any(|w| w.parse::<f64>().is_ok())
        })
        .collect();
    let k = numbered[rng.random_range(0..numbered.len())];
    let swap_number = |line: &str, to: &str, rng: &mut ChaCha8Rng| {
        let mut words: Vec<String> = line.split_whitespace().map(String::from).collect();
        let at: Vec<usize> = (0..words.len())
            .filter(|&i| words[i].parse::<f64>().is_ok())
            .collect();
        words[at[rng.random_range(0..at.len())]] = to.to_string();
        words.join(" ")
    };
    match rng.random_range(0..10) {
        0 => {
            let cut = rng.random_range(0..text.len());
            let cut = (0..=cut)
                .rev()
                .find(|&c| text.is_char_boundary(c))
                .unwrap_or(0);
            return text.as_bytes()[..cut].to_vec();
        }
        1 => lines[k] = swap_number(&lines[k], "nan", rng),
        2 => lines[k] = swap_number(&lines[k], "1e300", rng),
        3 => lines[k] = swap_number(&lines[k], "-0.5", rng),
        4 => lines[k] = swap_number(&lines[k], "99999", rng),
        5 => lines[k].clear(),
        6 => {
            let copy = lines[k].clone();
            lines.insert(k, copy);
        }
        7 => {
            // A face (or any line) read backwards: a face turned over.
            let mut words: Vec<&str> = lines[k].split_whitespace().collect();
            words[1..].reverse();
            lines[k] = words.join(" ");
        }
        8 => lines.insert(k, "unknown_key_m = 1.0".into()),
        _ => {
            let mut b = b"\xEF\xBB\xBF# caf\xE9\n".to_vec();
            b.extend((lines.join("\n") + "\n").bytes());
            return b;
        }
    }
    (lines.join("\n") + "\n").into_bytes()
}

/// Issue 92's fuzz test: the bundled mesh body, fabric file and pattern mutated (truncation, NaN,
/// huge and negative numbers, out-of-range indices, missing and unknown keys, turned faces, a BOM
/// and a Latin-1 byte), each run through `drapelab simulate` unchanged otherwise: a mutated file
/// is refused naming it (exit 2, one line, nothing left) or the drape converges (exit 0). Nothing
/// is passed off: no converged drape through a body, no solve that cannot end.
#[test]
fn mutated_bodies_fabrics_and_patterns_are_refused_naming_them_or_drape() {
    let bodies = root().join("datasets/bodies");
    let body = std::fs::read_to_string(bodies.join("table_10cm.obj")).unwrap();
    let body_scene = std::fs::read_to_string(bodies.join("table_wool_mesh.toml")).unwrap();
    let fabric =
        std::fs::read_to_string(root().join("datasets/fabrics/wool_seed003.toml")).unwrap();
    let sphere = root().join("datasets/scenes/sphere_wool.toml");
    let panel_dir = root().join("datasets/patterns");
    let panel = std::fs::read_to_string(panel_dir.join("l_panel.obj")).unwrap();
    let panel_scene = std::fs::read_to_string(panel_dir.join("l_panel_table.toml")).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(92);
    let dir = tempfile::tempdir().unwrap();
    let mut outcomes = [0usize; 3];
    for case in 0..45 {
        let out = dir.path().join(format!("out{case}"));
        let what = format!("case {case}");
        let code = match case % 3 {
            0 => {
                std::fs::write(
                    dir.path().join("table_10cm.obj"),
                    mutated_bytes(&body, &mut rng),
                )
                .unwrap();
                let scene = dir.path().join("table_wool_mesh.toml");
                std::fs::write(&scene, &body_scene).unwrap();
                let sets = [
                    "cloth.nx=11",
                    "cloth.ny=11",
                    "cloth.refine_x_m=[]",
                    "cloth.refine_y_m=[]",
                    "cloth.spacing=\"uniform\"",
                ];
                checked_run(&scene, &out, &sets, &["table_10cm.obj"], &what)
            }
            1 => {
                let f = dir.path().join("wool.toml");
                std::fs::write(&f, mutated_bytes(&fabric, &mut rng)).unwrap();
                let scene = dir.path().join("sphere.toml");
                let text = std::fs::read_to_string(&sphere).unwrap();
                let (head, rest) = text.split_once("[material.continuum]").unwrap();
                let tail = &rest[rest.find("\n[").unwrap()..];
                std::fs::write(
                    &scene,
                    format!("{head}[material]\nfabric = \"wool.toml\"\n{tail}"),
                )
                .unwrap();
                let sets = [
                    "cloth.nx=11",
                    "cloth.ny=11",
                    "boundary.pin_particles=[[5,5]]",
                ];
                checked_run(&scene, &out, &sets, &["wool.toml"], &what)
            }
            _ => {
                std::fs::write(
                    dir.path().join("l_panel.obj"),
                    mutated_bytes(&panel, &mut rng),
                )
                .unwrap();
                let scene = dir.path().join("l_panel_table.toml");
                std::fs::write(&scene, &panel_scene).unwrap();
                checked_run(&scene, &out, &[], &["l_panel.obj"], &what)
            }
        };
        if code == 1 {
            let run = std::fs::read_to_string(out.join("run.json")).unwrap_or_default();
            let v: serde_json::Value = serde_json::from_str(&run).unwrap_or_default();
            eprintln!("case {case}: {} {}", v["status"], v["report"]["message"]);
        }
        outcomes[code] += 1;
    }
    eprintln!("exits 0 / 1 / 2: {outcomes:?}");
    assert_eq!(
        outcomes[1], 0,
        "a mutated input neither refused nor draped: {outcomes:?}"
    );
    assert!(outcomes[2] > 10 && outcomes[0] > 5, "{outcomes:?}");
}
