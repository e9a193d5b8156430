//! No two modules of a crate import each other at any depth: the graph of every module (each `.rs`
//! file) and the modules its code names (`use` trees and paths from `crate::`, `super::`, `self::`,
//! a path through a parent's `pub use` followed to the module that defines the item), read by
//! parsing the files as Rust (syn), has no cycle. `#[cfg(test)]` items are left out.

use crate::layering::rust_files;
use crate::support::root;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use syn::visit::Visit;

/// A module's absolute path in its crate (`["solve", "newton"]`; empty for the crate root).
type ModPath = Vec<String>;

/// One crate's modules: each module's parsed file, and each directory module's re-exports (item
/// name → the absolute path it names).
struct Crate {
    files: BTreeMap<ModPath, syn::File>,
    reexports: BTreeMap<ModPath, BTreeMap<String, ModPath>>,
}

/// The module path of `file` under a crate's `src`, and whether it is a directory module (a crate
/// root or a `mod.rs`, whose `super` is its parent directory's module).
fn module_path(src: &Path, file: &Path) -> (ModPath, bool) {
    let rel = file.strip_prefix(src).unwrap();
    let mut parts: Vec<String> = rel
        .components()
        .map(|c| {
            c.as_os_str()
                .to_string_lossy()
                .trim_end_matches(".rs")
                .to_string()
        })
        .collect();
    let last = parts.pop().unwrap();
    let dir = matches!(last.as_str(), "mod" | "lib" | "main");
    if !dir {
        parts.push(last);
    }
    (parts, dir)
}

fn is_test(attrs: &[syn::Attribute]) -> bool {
    attrs.iter().any(|a| {
        a.path().is_ident("cfg")
            && matches!(&a.meta, syn::Meta::List(l) if l.tokens.to_string().contains("test"))
    })
}

/// Every path a use tree names, as segments (a glob ends in `*`, a rename keeps its source name).
fn use_paths(tree: &syn::UseTree, prefix: &mut Vec<String>, out: &mut Vec<(Vec<String>, String)>) {
    match tree {
        syn::UseTree::Path(p) => {
            prefix.push(p.ident.to_string());
            use_paths(&p.tree, prefix, out);
            prefix.pop();
        }
        syn::UseTree::Name(n) => out.push((prefix.clone(), n.ident.to_string())),
        syn::UseTree::Rename(r) => out.push((prefix.clone(), r.ident.to_string())),
        syn::UseTree::Glob(_) => out.push((prefix.clone(), "*".into())),
        syn::UseTree::Group(g) => g.items.iter().for_each(|t| use_paths(t, prefix, out)),
    }
}

/// The absolute form of `path` named in module `here` (a directory module when `dir`): from
/// `crate::`, `super::` or `self::`; none for another crate's path or a bare name.
fn absolute(here: &[String], dir: bool, path: &[String]) -> Option<ModPath> {
    let (first, rest) = path.split_first()?;
    let mut base: ModPath = here.to_vec();
    match first.as_str() {
        "crate" => base.clear(),
        "self" => {}
        "super" => {
            base.pop()?;
            let mut rest = rest;
            while rest.first().is_some_and(|s| s == "super") {
                base.pop()?;
                rest = &rest[1..];
            }
            base.extend(rest.iter().cloned());
            return Some(base);
        }
        _ => return None,
    }
    let _ = dir;
    base.extend(rest.iter().cloned());
    Some(base)
}

/// The paths module `here` names outside its tests.
fn named_paths(file: &syn::File, here: &[String], dir: bool) -> Vec<ModPath> {
    struct Paths<'a> {
        here: &'a [String],
        dir: bool,
        out: Vec<ModPath>,
    }
    impl<'ast> Visit<'ast> for Paths<'_> {
        fn visit_item_mod(&mut self, m: &'ast syn::ItemMod) {
            if !is_test(&m.attrs) {
                syn::visit::visit_item_mod(self, m);
            }
        }
        fn visit_item_fn(&mut self, f: &'ast syn::ItemFn) {
            if !is_test(&f.attrs) {
                syn::visit::visit_item_fn(self, f);
            }
        }
        fn visit_item_use(&mut self, u: &'ast syn::ItemUse) {
            let mut found = Vec::new();
            use_paths(&u.tree, &mut Vec::new(), &mut found);
            for (mut p, last) in found {
                p.push(last);
                self.out.extend(absolute(self.here, self.dir, &p));
            }
        }
        fn visit_path(&mut self, p: &'ast syn::Path) {
            let segs: Vec<String> = p.segments.iter().map(|s| s.ident.to_string()).collect();
            self.out.extend(absolute(self.here, self.dir, &segs));
            syn::visit::visit_path(self, p);
        }
    }
    let mut v = Paths {
        here,
        dir,
        out: Vec::new(),
    };
    v.visit_file(file);
    v.out
}

impl Crate {
    fn load(src: &Path) -> Crate {
        let mut paths = Vec::new();
        rust_files(src, &mut paths);
        let mut files = BTreeMap::new();
        let mut reexports = BTreeMap::new();
        for f in paths {
            let (m, dir) = module_path(src, &f);
            let text = std::fs::read_to_string(&f).unwrap();
            let file = syn::parse_file(&text).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
            if dir {
                reexports.insert(m.clone(), pub_uses(&file, &m));
            }
            files.insert(m, file);
        }
        Crate { files, reexports }
    }

    /// The module that defines what `path` names: its longest prefix that is a module, followed
    /// through that module's re-exports where the next segment is one (at most 8 hops).
    fn resolve(&self, path: &[String]) -> Option<ModPath> {
        let mut path = path.to_vec();
        for _ in 0..8 {
            let k = (0..=path.len())
                .rev()
                .find(|&k| self.files.contains_key(&path[..k]))?;
            let module = path[..k].to_vec();
            let next = path.get(k);
            match next.and_then(|n| self.reexports.get(&module)?.get(n)) {
                Some(target) if target[..] != path[..k + 1] => {
                    let mut p = target.clone();
                    p.extend(path[k + 1..].iter().cloned());
                    path = p;
                }
                _ => return Some(module),
            }
        }
        None
    }

    /// The graph: each module and the other modules its code names.
    fn graph(&self) -> BTreeMap<ModPath, BTreeSet<ModPath>> {
        let mut g: BTreeMap<ModPath, BTreeSet<ModPath>> = BTreeMap::new();
        for (m, file) in &self.files {
            let dir = self.reexports.contains_key(m);
            let deps = g.entry(m.clone()).or_default();
            for p in named_paths(file, m, dir) {
                if let Some(d) = self.resolve(&p).filter(|d| d != m && !m.starts_with(d)) {
                    deps.insert(d);
                }
            }
        }
        g
    }
}

/// A directory module's `pub use` re-exports: item name → the absolute path it names.
fn pub_uses(file: &syn::File, here: &[String]) -> BTreeMap<String, ModPath> {
    let mut out = BTreeMap::new();
    for item in &file.items {
        let syn::Item::Use(u) = item else { continue };
        if !matches!(u.vis, syn::Visibility::Public(_)) {
            continue;
        }
        let mut found = Vec::new();
        use_paths(&u.tree, &mut Vec::new(), &mut found);
        for (mut p, last) in found {
            p.push(last.clone());
            // `pub use child::X` names a child of this module; `pub use crate::..` is absolute.
            let abs = absolute(here, true, &p).unwrap_or_else(|| {
                let mut a = here.to_vec();
                a.extend(p.iter().cloned());
                a
            });
            out.insert(last, abs);
        }
    }
    out
}

/// A cycle of the graph, if any (depth-first search).
fn find_cycle(g: &BTreeMap<ModPath, BTreeSet<ModPath>>) -> Option<Vec<ModPath>> {
    fn visit(
        g: &BTreeMap<ModPath, BTreeSet<ModPath>>,
        m: &ModPath,
        path: &mut Vec<ModPath>,
        done: &mut BTreeSet<ModPath>,
    ) -> Option<Vec<ModPath>> {
        if let Some(i) = path.iter().position(|p| p == m) {
            return Some(path[i..].to_vec());
        }
        if !done.insert(m.clone()) {
            return None;
        }
        path.push(m.clone());
        for d in g.get(m).into_iter().flatten() {
            if let Some(c) = visit(g, d, path, done) {
                return Some(c);
            }
        }
        path.pop();
        None
    }
    let mut done = BTreeSet::new();
    g.keys()
        .find_map(|m| visit(g, m, &mut Vec::new(), &mut done))
}

/// Cycles of the graph, each found after the first edge of those before is taken out (every
/// circle to mend shows at once; at most 50).
fn all_cycles(mut g: BTreeMap<ModPath, BTreeSet<ModPath>>) -> Vec<Vec<ModPath>> {
    let mut found = Vec::new();
    while let Some(c) = find_cycle(&g).filter(|_| found.len() < 50) {
        let (a, b) = (c[0].clone(), c[1 % c.len()].clone());
        g.get_mut(&a).unwrap().remove(&b);
        found.push(c);
    }
    found
}

fn crate_sources() -> Vec<PathBuf> {
    let mut srcs = vec![root().join("src")];
    for e in std::fs::read_dir(root().join("crates")).unwrap() {
        srcs.push(e.unwrap().path().join("src"));
    }
    srcs
}

fn show(c: &[ModPath]) -> String {
    c.iter()
        .map(|m| format!("crate::{}", m.join("::")))
        .collect::<Vec<_>>()
        .join(" → ")
}

#[test]
fn no_two_modules_import_each_other_at_any_depth() {
    for src in crate_sources() {
        let g = Crate::load(&src).graph();
        assert!(g.len() > 1, "{}: no modules", src.display());
        let cycles = all_cycles(g);
        assert!(
            cycles.is_empty(),
            "{}: modules import each other:\n{}",
            src.display(),
            cycles
                .iter()
                .map(|c| show(c))
                .collect::<Vec<_>>()
                .join("\n")
        );
    }
}

/// The check itself: a circle planted two modules deep (`a::b::c` ↔ `a::b::d`, one through the
/// parent's re-export) is found; the same tree without it passes.
#[test]
fn the_module_check_finds_a_circle_planted_two_modules_deep() {
    let tmp = tempfile::tempdir().unwrap();
    let src = tmp.path();
    let write = |rel: &str, text: &str| {
        let p = src.join(rel);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, text).unwrap();
    };
    write("lib.rs", "mod a;\n");
    write("a/mod.rs", "mod b;\n");
    write("a/b/mod.rs", "mod c;\nmod d;\npub use d::Y;\n");
    write("a/b/c.rs", "use super::Y;\npub struct X;\n");
    write(
        "a/b/d.rs",
        "pub struct Y;\nfn f() -> crate::a::b::c::X { \"{ crate::a::b::c }\"; todo!() }\n",
    );
    let found = find_cycle(&Crate::load(src).graph()).expect("the planted circle");
    assert_eq!(show(&found), "crate::a::b::c → crate::a::b::d");
    write("a/b/d.rs", "pub struct Y;\n");
    assert_eq!(find_cycle(&Crate::load(src).graph()), None);
}
