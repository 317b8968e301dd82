//! The crate's modules import one way: each imports only modules listed before it in
//! ARCHITECTURE.md's tree (data flows down the list, never back up). This test reads every
//! `crate::…` path in `src/` and fails on an import against that order, or on a module the list
//! does not place.

use std::collections::BTreeSet;
use std::path::Path;

/// ARCHITECTURE.md's order, top to bottom.
const ORDER: [&str; 20] = [
    "error",
    "parameter",
    "ode",
    "motor",
    "forward",
    "density",
    "bayes",
    "optimize",
    "evidence",
    "diagnostics",
    "sampler",
    "io",
    "synthetic",
    "pipeline",
    "plot",
    "study",
    "discover",
    "design",
    "paper",
    "app",
];

/// The top-level modules a source text names after `crate::` (comments left out), with
/// `use crate::{a, b::c}` groups opened.
fn imported_modules(text: &str) -> BTreeSet<String> {
    let mut found = BTreeSet::new();
    for line in text.lines() {
        let code = line.split("//").next().unwrap_or("");
        let mut rest = code;
        while let Some(at) = rest.find("crate::") {
            rest = &rest[at + "crate::".len()..];
            let names: Vec<&str> = if let Some(group) = rest.strip_prefix('{') {
                // A group: the first path segment of each member.
                let end = group.find('}').unwrap_or(group.len());
                group[..end]
                    .split(',')
                    .map(|m| m.trim().split("::").next().unwrap_or("").trim())
                    .collect()
            } else {
                vec![
                    rest.split(|c: char| !(c.is_alphanumeric() || c == '_'))
                        .next()
                        .unwrap_or(""),
                ]
            };
            found.extend(
                names
                    .into_iter()
                    .filter(|n| !n.is_empty())
                    .map(String::from),
            );
        }
    }
    found
}

fn rust_files(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// Every import of module `a` by module `b` where `a` stands below `b` in the list.
fn violations(src: &Path) -> Vec<String> {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    let mut found = Vec::new();
    for file in files {
        let relative = file.strip_prefix(src).unwrap();
        let top = relative
            .components()
            .next()
            .unwrap()
            .as_os_str()
            .to_string_lossy()
            .trim_end_matches(".rs")
            .to_string();
        if top == "lib" || top == "main" {
            continue;
        }
        let Some(rank) = ORDER.iter().position(|m| *m == top) else {
            found.push(format!(
                "{}: module '{top}' is not in the order",
                relative.display()
            ));
            continue;
        };
        let text = std::fs::read_to_string(&file).unwrap();
        for module in imported_modules(&text) {
            match ORDER.iter().position(|m| *m == module) {
                Some(r) if r > rank => found.push(format!(
                    "{}: {top} imports {module}, which stands below it",
                    relative.display()
                )),
                Some(_) => {}
                None => found.push(format!(
                    "{}: imports crate::{module}, which the order does not place",
                    relative.display()
                )),
            }
        }
    }
    found
}

#[test]
fn no_module_imports_one_below_it() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let found = violations(&src);
    assert!(
        found.is_empty(),
        "imports against the order:\n{}",
        found.join("\n")
    );
}

#[test]
fn every_module_of_lib_rs_is_placed_and_in_the_documented_order() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let lib = std::fs::read_to_string(root.join("src/lib.rs")).unwrap();
    let declared: BTreeSet<&str> = lib
        .lines()
        .filter_map(|l| l.trim().strip_prefix("pub mod "))
        .map(|m| m.trim_end_matches(';'))
        .collect();
    let placed: BTreeSet<&str> = ORDER.into_iter().collect();
    assert_eq!(declared, placed, "lib.rs's modules against the order");
    // ARCHITECTURE.md draws the same list in the same order.
    let doc = std::fs::read_to_string(root.join("ARCHITECTURE.md")).unwrap();
    let mut at = 0;
    for module in ORDER {
        let needle = format!("\n  {module}");
        let found = doc[at..].find(&needle).unwrap_or_else(|| {
            panic!("ARCHITECTURE.md does not list {module} after the modules before it")
        });
        at += found + needle.len();
    }
}

#[test]
fn the_check_catches_an_import_back_up() {
    // A sampler that imported the discovery would run against the flow.
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("motorcal-arch-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("sampler")).unwrap();
    std::fs::write(
        dir.join("sampler/bad.rs"),
        "use crate::{density::LogDensity, discover::Candidate};\n// crate::app in a comment\n",
    )
    .unwrap();
    let found = violations(&dir);
    std::fs::remove_dir_all(&dir).unwrap();
    assert_eq!(found.len(), 1, "{found:?}");
    assert!(found[0].contains("sampler imports discover"), "{found:?}");
}
