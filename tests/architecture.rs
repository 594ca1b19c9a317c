//! The crate graph of `docs/architecture.md` is true: every `flexstar-*` dependency of a crate's
//! manifest (normal dependencies, not dev ones) is a crate drawn above it in the picture, every
//! crate of `crates/` is in the picture, and the FEM never depends on the AMM (the independent
//! reference stays independent). The reference is the manifests themselves, read here.

use std::collections::BTreeMap;
use std::path::Path;

/// The crates of `crates/` (the Python package is drawn at the bottom).
fn crate_dirs(root: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(root.join("crates"))
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.path().join("Cargo.toml").exists())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// The row of each crate in the picture (crates on one row are side by side).
fn rows_of_picture(doc: &str, crates: &[String]) -> BTreeMap<String, usize> {
    let start = doc.find("## Crate graph").expect("a crate graph section");
    let block = &doc[start..];
    let open = block.find("```text").expect("a text block") + "```text".len();
    let close = open + block[open..].find("```").expect("the block's end");
    let mut rows = BTreeMap::new();
    for (k, line) in block[open..close].lines().enumerate() {
        // the crate names stand left of the descriptions (column 33)
        let left: String = line.chars().take(33).collect();
        for word in left.split(|c: char| !c.is_ascii_alphabetic()) {
            if crates.iter().any(|c| c == word) && !rows.contains_key(word) {
                rows.insert(word.to_string(), k);
            }
        }
    }
    rows
}

/// The `flexstar-*` normal dependencies of a crate's manifest.
fn flexstar_dependencies(manifest: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(manifest).unwrap();
    let doc: toml::Table = toml::from_str(&text).unwrap();
    let deps = doc
        .get("dependencies")
        .and_then(|d| d.as_table())
        .cloned()
        .unwrap_or_default();
    deps.keys()
        .filter_map(|k| k.strip_prefix("flexstar-").map(str::to_string))
        .collect()
}

#[test]
fn architecture_graph_is_true() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let doc = std::fs::read_to_string(root.join("docs/architecture.md")).unwrap();
    let crates = crate_dirs(&root);
    let rows = rows_of_picture(&doc, &crates);
    for c in &crates {
        let Some(&row) = rows.get(c) else {
            panic!("crate `{c}` is not in the picture of docs/architecture.md");
        };
        for d in flexstar_dependencies(&root.join("crates").join(c).join("Cargo.toml")) {
            let above = rows.get(&d).is_some_and(|&r| r < row);
            assert!(
                above,
                "`{c}` depends on `{d}`, which the picture does not draw above it"
            );
        }
    }
    let fem = flexstar_dependencies(&root.join("crates/fem/Cargo.toml"));
    assert!(!fem.iter().any(|d| d == "amm"), "the FEM must not depend on the AMM");
}
