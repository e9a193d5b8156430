//! The layering written down in the module map (docs/src/reference/modules.md), checked: crates
//! depend only on crates below them, the core crate pulls in no I/O stack (not even transitively)
//! and the application layer no report stack, no module of the core imports a module above it (no circle
//! at any depth: `module_graph.rs`), a stage file is an adapter (at most 100 lines of
//! code), no function outside tests runs over 80 lines and no source file over 500 before its tests.

use crate::support::root;
use std::collections::BTreeMap;
use std::path::Path;

/// Each workspace crate and the workspace crates it may depend on.
const CRATES: [(&str, &[&str]); 8] = [
    ("drapelab-core", &[]),
    ("drapelab-record", &["drapelab-core"]),
    ("drapelab-pipeline", &["drapelab-core"]),
    ("drapelab-app", &["drapelab-core", "drapelab-record"]),
    (
        "drapelab-reports",
        &["drapelab-core", "drapelab-record", "drapelab-app"],
    ),
    (
        "drapelab-stages",
        &[
            "drapelab-core",
            "drapelab-record",
            "drapelab-pipeline",
            "drapelab-app",
            "drapelab-reports",
        ],
    ),
    (
        "drapelab-python",
        &[
            "drapelab-core",
            "drapelab-record",
            "drapelab-pipeline",
            "drapelab-app",
            "drapelab-stages",
        ],
    ),
    (
        "drapelab",
        &[
            "drapelab-core",
            "drapelab-record",
            "drapelab-pipeline",
            "drapelab-app",
            "drapelab-stages",
        ],
    ),
];

/// Crates the application layer must not depend on: the report stack and the engine's display.
const NOT_IN_APP: [&str; 5] = [
    "polars",
    "plotters",
    "clap",
    "indicatif",
    "drapelab-pipeline",
];

/// Crates the core must not reach, directly or through another crate.
const NOT_IN_CORE: [&str; 8] = [
    "rerun",
    "polars",
    "arrow",
    "parquet",
    "mcap",
    "clap",
    "plotters",
    "indicatif",
];

/// The modules of the core, lowest first: a module may import only modules of a lower rank. The
/// error types (`error`: a bad key, a bad input) are below everything that checks its input.
const CORE_RANKS: [(&str, u8); 31] = [
    ("error", 0),
    ("provenance", 0),
    ("atomic", 0),
    ("textfile", 0),
    ("memory", 0),
    ("table", 0),
    ("material", 1),
    ("obstacle", 1),
    ("proximity", 0),
    ("optim", 1),
    ("surface", 3),
    ("raster", 1),
    ("config", 2),
    ("cloth", 2),
    ("pattern", 1),
    ("physics", 2),
    ("solve", 3),
    ("sewing", 4),
    ("scene", 5),
    ("build", 6),
    ("params", 6),
    ("sensitivity", 7),
    ("simulate", 7),
    ("measure", 7),
    ("cusick", 8),
    ("elastica", 8),
    ("edges", 8),
    ("wrinkles", 8),
    ("calibrate", 9),
    ("benchmark", 10),
    ("lib", 11),
];

fn cargo() -> std::process::Command {
    let mut c =
        std::process::Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()));
    c.current_dir(root());
    c
}

#[test]
fn crates_depend_only_downwards() {
    let out = cargo()
        .args([
            "metadata",
            "--format-version",
            "1",
            "--no-deps",
            "--offline",
        ])
        .output()
        .expect("cargo metadata runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let meta: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let packages = meta["packages"].as_array().unwrap();
    assert_eq!(
        packages.len(),
        CRATES.len(),
        "every workspace crate is in the table"
    );
    for p in packages {
        let name = p["name"].as_str().unwrap();
        let allowed = CRATES
            .iter()
            .find(|(n, _)| *n == name)
            .unwrap_or_else(|| panic!("{name} is not in the layering table"))
            .1;
        for d in p["dependencies"].as_array().unwrap() {
            let dep = d["name"].as_str().unwrap();
            if dep.starts_with("drapelab") {
                assert!(allowed.contains(&dep), "{name} must not depend on {dep}");
            }
            if name == "drapelab-core" {
                assert!(
                    !NOT_IN_CORE.contains(&dep),
                    "drapelab-core depends on {dep}"
                );
            }
            if name == "drapelab-app" {
                assert!(!NOT_IN_APP.contains(&dep), "drapelab-app depends on {dep}");
            }
        }
    }
}

#[test]
fn the_core_crate_pulls_in_no_io_stack() {
    let out = cargo()
        .args([
            "tree",
            "-p",
            "drapelab-core",
            "-e",
            "normal",
            "--prefix",
            "none",
            "--offline",
        ])
        .output()
        .expect("cargo tree runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let tree = String::from_utf8_lossy(&out.stdout);
    let names: Vec<&str> = tree
        .lines()
        .filter_map(|l| l.split_whitespace().next())
        .collect();
    assert!(
        names.contains(&"faer") && names.contains(&"nalgebra"),
        "{tree}"
    );
    for bad in NOT_IN_CORE {
        assert!(
            !names
                .iter()
                .any(|n| *n == bad || n.starts_with(&format!("{bad}-"))),
            "drapelab-core reaches {bad}:\n{tree}"
        );
    }
}

/// The `crate::MODULE` paths a source file names (comments left out).
fn crate_refs(text: &str) -> Vec<String> {
    refs_after(text, "crate::")
}

/// The names that follow `prefix` in code (comments aside).
fn refs_after(text: &str, prefix: &str) -> Vec<String> {
    let mut refs = Vec::new();
    for line in text.lines() {
        let code = line.split("//").next().unwrap_or("");
        let mut rest = code;
        while let Some(i) = rest.find(prefix) {
            let tail = &rest[i + prefix.len()..];
            let name: String = tail
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                .collect();
            if !name.is_empty() {
                refs.push(name);
            }
            rest = &tail[1..];
        }
    }
    refs
}

/// The top module of a file under a crate's `src/`.
fn module_of(rel: &Path) -> String {
    let first = rel
        .components()
        .next()
        .unwrap()
        .as_os_str()
        .to_string_lossy();
    first.trim_end_matches(".rs").to_string()
}

/// Every `.rs` file under `dir`, into `out`.
pub(crate) fn rust_files(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let p = e.path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

#[test]
fn no_core_module_imports_one_above_it() {
    let rank: BTreeMap<&str, u8> = CORE_RANKS.into_iter().collect();
    let src = root().join("crates/core/src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let mut seen = std::collections::BTreeSet::new();
    for f in &files {
        let m = module_of(f.strip_prefix(&src).unwrap());
        seen.insert(m.clone());
        let r = *rank
            .get(m.as_str())
            .unwrap_or_else(|| panic!("core module `{m}` is not in the layering table"));
        let text = std::fs::read_to_string(f).unwrap();
        for dep in crate_refs(&text) {
            if dep == m || dep == "VERSION" || dep == "STANDARD_GRAVITY_M_PER_S2" {
                continue;
            }
            let d = *rank
                .get(dep.as_str())
                .unwrap_or_else(|| panic!("{}: unknown module crate::{dep}", f.display()));
            assert!(
                d < r,
                "{}: module `{m}` (rank {r}) imports `{dep}` (rank {d}), which is not below it",
                f.display()
            );
        }
    }
    assert_eq!(seen.len(), CORE_RANKS.len(), "modules: {seen:?}");
}

/// Lines of code of a Rust text outside `#[cfg(test)]`: not blank, not a comment.
fn code_lines(text: &str) -> usize {
    text.lines()
        .take_while(|l| !l.trim_start().starts_with("#[cfg(test)]"))
        .filter(|l| {
            let t = l.trim();
            !t.is_empty() && !t.starts_with("//")
        })
        .count()
}

#[test]
fn a_stage_file_is_an_adapter() {
    let src = root().join("crates/stages/src");
    for e in std::fs::read_dir(&src).unwrap() {
        let p = e.unwrap().path();
        if p.file_name().is_some_and(|n| n == "lib.rs") {
            continue;
        }
        let n = code_lines(&std::fs::read_to_string(&p).unwrap());
        assert!(
            n <= 100,
            "{}: {n} lines of code; a stage file is slots, parameters and a workflow call: move the work into drapelab-app or drapelab-reports",
            p.display()
        );
    }
}

/// Lengths of the functions of a Rust file (free, in impls, in traits with a body) outside
/// `#[cfg(test)]` items, from the line of `fn` to the line of the body's closing brace, found by
/// parsing the file as Rust (syn): braces in strings, chars and comments count for nothing.
fn long_functions(text: &str, limit: usize) -> Vec<(String, usize)> {
    use syn::visit::Visit;
    struct Lengths {
        limit: usize,
        out: Vec<(String, usize)>,
    }
    impl Lengths {
        fn check(&mut self, sig: &syn::Signature, body: &syn::Block) {
            let start = sig.fn_token.span.start().line;
            let end = body.brace_token.span.close().end().line;
            let len = end + 1 - start;
            if len > self.limit {
                self.out.push((format!("fn {}", sig.ident), len));
            }
        }
    }
    fn is_test(attrs: &[syn::Attribute]) -> bool {
        attrs.iter().any(|a| {
            a.path().is_ident("cfg")
                && matches!(&a.meta, syn::Meta::List(l) if l.tokens.to_string().contains("test"))
        })
    }
    impl<'ast> Visit<'ast> for Lengths {
        fn visit_item_mod(&mut self, m: &'ast syn::ItemMod) {
            if !is_test(&m.attrs) {
                syn::visit::visit_item_mod(self, m);
            }
        }
        fn visit_item_fn(&mut self, f: &'ast syn::ItemFn) {
            if !is_test(&f.attrs) {
                self.check(&f.sig, &f.block);
                syn::visit::visit_item_fn(self, f);
            }
        }
        fn visit_impl_item_fn(&mut self, f: &'ast syn::ImplItemFn) {
            self.check(&f.sig, &f.block);
            syn::visit::visit_impl_item_fn(self, f);
        }
        fn visit_trait_item_fn(&mut self, f: &'ast syn::TraitItemFn) {
            if let Some(body) = &f.default {
                self.check(&f.sig, body);
            }
            syn::visit::visit_trait_item_fn(self, f);
        }
    }
    let file = syn::parse_file(text).unwrap_or_else(|e| panic!("not Rust: {e}"));
    let mut v = Lengths {
        limit,
        out: Vec::new(),
    };
    v.visit_file(&file);
    v.out
}

/// The library and binary sources: every `.rs` under `crates/` and `src/` outside a `tests/` folder.
fn source_files() -> Vec<std::path::PathBuf> {
    let mut files = Vec::new();
    for dir in ["crates", "src"] {
        rust_files(&root().join(dir), &mut files);
    }
    files.retain(|f| !f.components().any(|c| c.as_os_str() == "tests"));
    files
}

#[test]
fn no_function_is_over_80_lines() {
    let mut long = Vec::new();
    for f in &source_files() {
        let text = std::fs::read_to_string(f).unwrap();
        for (name, len) in long_functions(&text, 80) {
            long.push(format!(
                "{}: {name} ({len} lines)",
                f.strip_prefix(root()).unwrap().display()
            ));
        }
    }
    assert!(
        long.is_empty(),
        "functions over 80 lines (split out a step with a name of its own):\n{}",
        long.join("\n")
    );
}

/// Lines of a Rust file before its `#[cfg(test)]` module (all of them without one).
fn lines_before_tests(text: &str) -> usize {
    text.lines()
        .position(|l| l.trim_start().starts_with("#[cfg(test)]"))
        .unwrap_or_else(|| text.lines().count())
}

#[test]
fn no_source_file_is_over_500_lines_before_its_tests() {
    let long: Vec<String> = source_files()
        .iter()
        .filter_map(|f| {
            let n = lines_before_tests(&std::fs::read_to_string(f).unwrap());
            (n > 500).then(|| format!("{}: {n} lines", f.strip_prefix(root()).unwrap().display()))
        })
        .collect();
    assert!(
        long.is_empty(),
        "source files over 500 lines before their tests (one concept per module: split one out):\n{}",
        long.join("\n")
    );
}

#[test]
fn the_file_length_check_counts_up_to_the_tests() {
    let text = format!(
        "{}#[cfg(test)]\nmod tests {{}}\n",
        "fn f() {}\n".repeat(501)
    );
    assert_eq!(lines_before_tests(&text), 501);
    assert_eq!(lines_before_tests("fn f() {}\n"), 1);
}

#[test]
fn the_function_length_check_sees_a_long_function() {
    let body = "    let x = 1;\n".repeat(160);
    let text = format!("fn long() {{\n{body}}}\nfn short() {{\n    1;\n}}\n");
    let found = long_functions(&text, 150);
    assert_eq!(found.len(), 1);
    assert_eq!(found[0].1, 162);
    // An 81-line method whose strings hold closing braces (a brace counter stops at the first), and
    // a short one whose strings hold opening braces (a brace counter runs on past its end).
    let braces = "        let s = \"}} }} {{\";\n".repeat(79);
    let text = format!(
        "impl A {{\n    fn planted(&self) {{\n{braces}    }}\n    fn short(&self) {{\n        let t = \"{{{{\";\n    }}\n}}\n"
    );
    assert_eq!(
        long_functions(&text, 80),
        vec![("fn planted".to_string(), 81)]
    );
    // Functions under #[cfg(test)] are not counted.
    let tested = format!("#[cfg(test)]\nmod tests {{\n    fn long() {{\n{body}    }}\n}}\n");
    assert!(long_functions(&tested, 80).is_empty());
}
