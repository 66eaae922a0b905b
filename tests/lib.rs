//! Shared helpers for the end-to-end tests: the repository's `motors/` folder.

use std::path::{Path, PathBuf};

/// The repository root.
pub fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Every `*.toml` in `motors/`, sorted, as (stem, path relative to the repo, text).
pub fn motors() -> Vec<(String, String, String)> {
    let dir = repo().join("motors");
    let mut out: Vec<_> = std::fs::read_dir(&dir)
        .expect("motors/ exists")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .map(|p| {
            let stem = p.file_stem().unwrap().to_string_lossy().into_owned();
            let rel = format!("motors/{stem}.toml");
            let text = std::fs::read_to_string(&p).unwrap();
            (stem, rel, text)
        })
        .collect();
    out.sort();
    out
}

/// The design of `motors/<stem>.toml` as JSON.
pub fn design_json(stem: &str) -> serde_json::Value {
    let rel = format!("motors/{stem}.toml");
    let text = std::fs::read_to_string(repo().join(&rel)).unwrap();
    let d = codegen::design_source(&rel, &text).unwrap_or_else(|e| panic!("{e}"));
    serde_json::to_value(&d).unwrap()
}
