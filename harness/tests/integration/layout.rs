//! The layout rules a newcomer relies on: no source file over 600 lines (shaders, scripts and
//! the review page's JS and CSS included), so each concern stays in a file that can be read in
//! one sitting, and no relative link in the Markdown (README.md, docs/, ...) leads nowhere.
//! Function length is clippy's `too_many_lines` (see clippy.toml). And the README's two commands
//! share one build.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The longest a source file may be.
const MAX_LINES: usize = 600;

/// Extensions of the files the rule covers.
const SOURCE_EXTENSIONS: &[&str] = &["rs", "wgsl", "geom", "js", "css", "py", "sh"];

/// Folders the rule does not walk: build outputs and version control.
const SKIPPED: &[&str] = &["target", ".git"];

/// The files under `dir` whose extension is one of `extensions`, build outputs and version
/// control left out.
fn files_with_extensions(dir: &Path, extensions: &[&str], out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let entry = entry.unwrap();
        let path = entry.path();
        let name = entry.file_name().to_string_lossy().into_owned();
        if entry.file_type().unwrap().is_dir() {
            if !SKIPPED.contains(&name.as_str()) {
                files_with_extensions(&path, extensions, out);
            }
        } else if path
            .extension()
            .is_some_and(|e| extensions.contains(&e.to_string_lossy().as_ref()))
        {
            out.push(path);
        }
    }
}

#[test]
fn no_source_file_is_over_600_lines() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut files = Vec::new();
    for dir in ["engine", "harness", "benches", "scripts", "fuzz", ".ci"] {
        files_with_extensions(&root.join(dir), SOURCE_EXTENSIONS, &mut files);
    }
    assert!(files.len() > 100, "found only {} source files", files.len());
    let long: Vec<String> = files
        .iter()
        .filter_map(|path| {
            let lines = std::fs::read_to_string(path).ok()?.lines().count();
            (lines > MAX_LINES).then(|| format!("{} ({lines} lines)", path.display()))
        })
        .collect();
    assert!(long.is_empty(), "over {MAX_LINES} lines: {long:?}");
}

/// Every relative link in the project's Markdown (README.md, docs/, golden/, scenes/, ...)
/// points at a file or folder that exists: a moved doc must not leave a dead link behind.
#[test]
fn every_relative_markdown_link_points_at_a_file() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut docs = Vec::new();
    files_with_extensions(&root, &["md"], &mut docs);
    assert!(docs.iter().any(|d| d.ends_with("README.md")), "{docs:?}");
    let mut dead = Vec::new();
    for doc in &docs {
        let text = std::fs::read_to_string(doc).unwrap();
        for target in relative_links(&text) {
            let path = target.split('#').next().unwrap_or_default();
            if !path.is_empty() && !doc.parent().unwrap().join(path).exists() {
                dead.push(format!("{}: {target}", doc.display()));
            }
        }
    }
    assert!(dead.is_empty(), "dead links: {dead:#?}");
}

/// The targets of `[text](target)` links that are neither absolute URLs nor anchors.
fn relative_links(text: &str) -> Vec<&str> {
    text.match_indices("](")
        .filter_map(|(at, _)| {
            let rest = &text[at + 2..];
            let target = &rest[..rest.find(')')?];
            let external = target.contains("://") || target.starts_with("mailto:");
            (!external && !target.starts_with('#') && !target.is_empty()).then_some(target)
        })
        .collect()
}

/// The test targets of the harness library and of the `harness` and `make_hard_assets` binaries
/// are off (`test = false`: `cargo test` would compile the library a second time in test mode,
/// and build, link and run two empty test binaries), so none of their files holds tests, which
/// would never run there: the library's are in `tests/integration/units/`, the binaries are
/// tested through their command lines. `make_scene_assets` keeps its unit tests. (The engine
/// keeps its unit tests too: most test private modules, which the engine's public API should not
/// grow for; its second compile is 13 CPU-s on the EPYC host, 27-29 on host-c.)
#[test]
fn no_unit_tests_where_cargo_test_would_not_run() {
    let harness = Path::new(env!("CARGO_MANIFEST_DIR"));
    let manifest = std::fs::read_to_string(harness.join("Cargo.toml")).unwrap();
    for (target, off) in [
        ("the library", "[lib]\ntest = false"),
        (
            "the harness binary",
            "name = \"harness\"\npath = \"src/main.rs\"\ntest = false",
        ),
        (
            "make_hard_assets",
            "name = \"make_hard_assets\"\npath = \"src/bin/make_hard_assets.rs\"\ntest = false",
        ),
    ] {
        assert!(
            manifest.contains(off),
            "harness/Cargo.toml no longer turns off the tests of {target}: update this rule"
        );
    }
    let mut files = Vec::new();
    files_with_extensions(&harness.join("src"), &["rs"], &mut files);
    let keeps_its_tests = |path: &&PathBuf| {
        path.components()
            .any(|c| c.as_os_str() == "make_scene_assets")
    };
    let with_tests: Vec<String> = files
        .iter()
        .filter(|path| !keeps_its_tests(path))
        .filter(|path| {
            let text = std::fs::read_to_string(path).unwrap();
            text.contains("#[test]") || text.contains("#[cfg(test)]")
        })
        .map(|path| path.display().to_string())
        .collect();
    assert!(
        with_tests.is_empty(),
        "tests where `cargo test` does not run them (the library's belong in \
         harness/tests/integration/units/; a binary's in a test of its command line): {with_tests:?}"
    );
}

/// The README's two commands share one build: every crate that `cargo run -p harness` builds is
/// built by `cargo test --workspace` with the same features (the dev-dependencies turn some on;
/// harness/Cargo.toml names those, or the tests would build engine and harness a second time).
#[test]
fn the_main_command_and_the_tests_build_the_same_crates() {
    let workspace = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let tree = |args: &[&str]| -> BTreeMap<String, String> {
        let output = std::process::Command::new(std::env::var("CARGO").unwrap_or("cargo".into()))
            .args([
                "tree",
                "--offline",
                "--prefix",
                "none",
                "--format",
                "{p}|{f}",
            ])
            .args(args)
            .current_dir(&workspace)
            .output()
            .unwrap();
        assert!(
            output.status.success(),
            "cargo tree: {}",
            String::from_utf8_lossy(&output.stderr)
        );
        String::from_utf8_lossy(&output.stdout)
            .lines()
            .filter_map(|line| {
                let (package, features) = line.trim_end_matches(" (*)").split_once('|')?;
                Some((package.to_owned(), features.to_owned()))
            })
            .collect()
    };
    let main = tree(&["-p", "harness", "-e", "normal,build"]);
    let tests = tree(&["--workspace", "-e", "normal,build,dev"]);
    assert!(main.len() > 100, "{} crates", main.len());
    let differ: Vec<String> = main
        .iter()
        .filter_map(|(package, features)| {
            let in_tests = tests.get(package)?;
            (in_tests != features).then(|| format!("{package}: [{features}] vs [{in_tests}]"))
        })
        .collect();
    assert!(
        differ.is_empty(),
        "`cargo test` would build these again with other features (name them in \
         harness/Cargo.toml): {differ:#?}"
    );
}
