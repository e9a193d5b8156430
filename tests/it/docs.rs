//! The documentation (README.md and the mdBook under docs/) kept true: every generated reference
//! page equals what the code generates now (the tables' schemas, the scene keys, the stage kinds
//! with their slots and parameter defaults, the command line), every relative link resolves, every page is in the
//! book's summary, and the README stays short. `DRAPELAB_BLESS=1 cargo test --release --test it --
//! docs` rewrites the generated pages.

use crate::support::root;
use std::path::{Path, PathBuf};

/// Checks (or, blessed, rewrites) the part of `page` between `<!-- generated:begin -->` and
/// `<!-- generated:end -->` against `now`.
fn generated(page: &str, now: &str) {
    let path = root().join("docs/src/reference").join(page);
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{page}: {e}"));
    let (head, rest) = text
        .split_once("<!-- generated:begin -->\n")
        .unwrap_or_else(|| panic!("{page}: no generated:begin marker"));
    let (body, tail) = rest
        .split_once("<!-- generated:end -->")
        .unwrap_or_else(|| panic!("{page}: no generated:end marker"));
    if std::env::var_os("DRAPELAB_BLESS").is_some() {
        let new = format!(
            "{head}<!-- generated:begin -->\n{}\n<!-- generated:end -->{tail}",
            now.trim()
        );
        std::fs::write(&path, new).unwrap();
        return;
    }
    assert_eq!(
        body.trim(),
        now.trim(),
        "docs/src/reference/{page} differs from the code: rerun with DRAPELAB_BLESS=1"
    );
}

#[test]
fn the_reference_pages_match_the_code() {
    generated("tables.md", &drapelab::app::tables_markdown().unwrap());
    generated("kinds.md", &drapelab::cli::kinds_text());
    generated("cli.md", &drapelab::cli::cli_reference());
    let mut scenes: Vec<PathBuf> = ["scenes", "patterns", "bodies"]
        .iter()
        .flat_map(|d| {
            glob::glob(
                &root()
                    .join(format!("datasets/{d}/*.toml"))
                    .to_string_lossy(),
            )
            .unwrap()
            .map(Result::unwrap)
        })
        .collect();
    scenes.sort();
    generated(
        "scene-keys.md",
        &drapelab::app::scene_keys::scene_keys_markdown(&scenes).unwrap(),
    );
}

/// Every Markdown file of the README and the book.
fn pages() -> Vec<PathBuf> {
    let mut v = vec![root().join("README.md")];
    for e in glob::glob(&root().join("docs/src/**/*.md").to_string_lossy()).unwrap() {
        v.push(e.unwrap());
    }
    v
}

/// The relative link targets of a Markdown text (outside code blocks), without anchors.
fn links(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut in_code = false;
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            in_code = !in_code;
            continue;
        }
        if in_code {
            continue;
        }
        let mut rest = line;
        while let Some(i) = rest.find("](") {
            let tail = &rest[i + 2..];
            let Some(end) = tail.find(')') else { break };
            let target = &tail[..end];
            if !target.starts_with("http") && !target.starts_with('#') && !target.is_empty() {
                out.push(target.split('#').next().unwrap().to_string());
            }
            rest = &tail[end..];
        }
    }
    out
}

#[test]
fn every_relative_link_of_the_docs_resolves() {
    let mut broken = Vec::new();
    for page in pages() {
        let text = std::fs::read_to_string(&page).unwrap();
        let dir = page.parent().unwrap();
        // A page of the book links only within the book (a link out of docs/src breaks in the
        // rendered book: name a repository file as `code` instead).
        let in_book = page.starts_with(root().join("docs/src"));
        for l in links(&text) {
            let target = dir.join(&l);
            let outside =
                in_book && !normalize(&target).starts_with(normalize(&root().join("docs/src")));
            if !target.exists() || outside {
                broken.push(format!(
                    "{}: {l}{}",
                    page.strip_prefix(root()).unwrap().display(),
                    if outside { " (leaves the book)" } else { "" }
                ));
            }
        }
    }
    assert!(broken.is_empty(), "broken links:\n{}", broken.join("\n"));
}

/// `path` with its `..` and `.` resolved lexically.
fn normalize(path: &std::path::Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in path.components() {
        match c {
            std::path::Component::ParentDir => {
                out.pop();
            }
            std::path::Component::CurDir => {}
            c => out.push(c),
        }
    }
    out
}

#[test]
fn every_page_is_in_the_summary_and_the_readme_is_short() {
    let src = root().join("docs/src");
    let summary = std::fs::read_to_string(src.join("SUMMARY.md")).unwrap();
    let listed = links(&summary);
    for page in pages().iter().filter(|p| p.starts_with(&src)) {
        let rel = page
            .strip_prefix(&src)
            .unwrap()
            .to_string_lossy()
            .to_string();
        if rel != "SUMMARY.md" {
            assert!(listed.contains(&rel), "{rel} is not in docs/src/SUMMARY.md");
        }
    }
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let lines = readme.lines().count();
    assert!(
        lines <= 250,
        "README.md has {lines} lines: move detail into docs/"
    );
    assert!(Path::new(&root().join("docs/book.toml")).exists());
}

#[test]
fn the_link_reader_finds_links_and_skips_code() {
    let text = "see [a](b.md#x) and [c](https://e)\n```\n[d](e.md)\n```\n[f](../g.md)";
    assert_eq!(links(text), ["b.md", "../g.md"]);
}

/// The module map's "Where do I add…" table names only paths that exist: a newcomer who follows it
/// lands in a real file or folder.
#[test]
fn every_path_the_module_map_names_exists() {
    let text = std::fs::read_to_string(root().join("docs/src/reference/modules.md")).unwrap();
    let (_, rest) = text
        .split_once("## Where do I add")
        .expect("the module map has a Where do I add section");
    let section = rest.split("\n## ").next().unwrap();
    let paths: Vec<&str> = section
        .split('`')
        .skip(1)
        .step_by(2)
        .filter(|t| t.contains('/') && !t.contains(' '))
        .collect();
    assert!(paths.len() >= 20, "too few paths: {paths:?}");
    let missing: Vec<&&str> = paths.iter().filter(|p| !root().join(p).exists()).collect();
    assert!(
        missing.is_empty(),
        "the module map names paths that do not exist: {missing:?}"
    );
}

/// Whether `text` speaks of a development session ("session 39", "this session", "same
/// session"): the docs describe the build, and its history lives in git.
fn speaks_of_sessions(text: &str) -> bool {
    let lower = text.to_lowercase();
    lower.match_indices("session").any(|(i, _)| {
        let after = lower[i + "session".len()..].trim_start();
        let last_word = lower[..i].split_whitespace().last().unwrap_or("");
        after.starts_with(|c: char| c.is_ascii_digit())
            || after.starts_with("'s")
            || ["this", "same", "that", "last", "next", "earlier"].contains(&last_word)
    })
}

#[test]
fn no_page_or_report_speaks_of_development_sessions() {
    let mut files = pages();
    for e in glob::glob(&root().join("reports/**/*").to_string_lossy()).unwrap() {
        let p = e.unwrap();
        if p.extension().is_some_and(|x| x == "md" || x == "csv") {
            files.push(p);
        }
    }
    for f in files {
        let text = std::fs::read_to_string(&f).unwrap();
        assert!(
            !speaks_of_sessions(&text),
            "{} speaks of a development session",
            f.display()
        );
    }
    assert!(speaks_of_sessions("measured in session 31"));
    assert!(speaks_of_sessions("Also in this session, the"));
    assert!(!speaks_of_sessions("a Python session reads the .rrd"));
    assert!(!speaks_of_sessions("a camera session"));
}
