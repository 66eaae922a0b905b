//! No code: the feature pins of `Cargo.toml` (see the comment there). Only `motorgen`
//! depends on this crate.

#[cfg(test)]
mod tests {
    use std::collections::{BTreeMap, BTreeSet};
    use std::process::Command;

    /// `cargo tree` over `args`, as package → the feature sets it is built with (one per
    /// distinct set: the host and the target side can differ).
    fn features(args: &[&str]) -> BTreeMap<String, BTreeSet<String>> {
        let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");
        let out = Command::new(env!("CARGO"))
            .args(["tree", "--locked", "--prefix", "none", "--format", "{p}|{f}"])
            .args(args)
            .current_dir(root)
            .output()
            .expect("cargo tree runs");
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let mut map: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
        for line in String::from_utf8_lossy(&out.stdout).lines() {
            let Some((package, features)) = line.split_once('|') else {
                continue;
            };
            // "name vX.Y.Z (path) (*)": the name and version say which package.
            let package = package.split(" (").next().unwrap_or(package).trim().to_string();
            let features = features.trim_end_matches(" (*)").trim().to_string();
            map.entry(package).or_default().insert(features);
        }
        map
    }

    /// Every package `cargo run -p motorgen` builds has the features `cargo test
    /// --workspace` builds it with: otherwise the README's main job, run after the
    /// tests, compiles it and everything above it again. A dependency change that turns
    /// on a feature through a dev-dependency fails here with the package and the two
    /// feature sets; the fix is a pin in this crate's `Cargo.toml`.
    #[test]
    fn motorgen_is_built_with_the_workspace_features() {
        let workspace = features(&["--workspace", "--edges", "normal,build,dev"]);
        let motorgen = features(&["--package", "motorgen", "--edges", "normal,build"]);
        assert!(motorgen.len() > 50, "motorgen's tree: {} packages", motorgen.len());
        let differing: Vec<String> = motorgen
            .iter()
            .filter(|(package, sets)| workspace.get(*package) != Some(*sets))
            .map(|(package, sets)| {
                format!(
                    "{package}: motorgen {sets:?}, the workspace {:?}",
                    workspace.get(package)
                )
            })
            .collect();
        assert!(differing.is_empty(), "pin these features:\n{}", differing.join("\n"));
    }

    /// `cargo test --workspace` compiles the design core once: the host side (the build
    /// scripts' and motor-macros' codegen) and the target side (the tests' codegen) are
    /// one unit. When one crate under it gets more features on one side, cargo compiles
    /// that crate twice and everything above it up to codegen (60 s of one core); the fix
    /// is a host-side pin (`[build-dependencies]` in `Cargo.toml`). `cargo tree` merges
    /// the two sides, so this reads cargo's unit graph (`--unit-graph`, unstable, on the
    /// toolchain `rust-toolchain.toml` pins).
    #[test]
    fn the_design_core_is_compiled_once_for_build_scripts_and_tests() {
        let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");
        let out = Command::new(env!("CARGO"))
            .args([
                "test",
                "--workspace",
                "--locked",
                "--no-run",
                "--unit-graph",
                "-Z",
                "unstable-options",
            ])
            .env("RUSTC_BOOTSTRAP", "1")
            .current_dir(root)
            .output()
            .expect("cargo runs");
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let graph: serde_json::Value = serde_json::from_slice(&out.stdout).expect("a unit graph");
        let mut libraries: BTreeMap<String, Vec<String>> = BTreeMap::new();
        for unit in graph["units"].as_array().expect("units") {
            let library = unit["target"]["kind"]
                .as_array()
                .is_some_and(|k| k.iter().any(|k| k == "lib"));
            if unit["mode"] == "build" && library {
                // "…#name@version" or, for a path package, "…/dir#version".
                let package = unit["pkg_id"].as_str().unwrap_or_default();
                let version = package.rsplit(['@', '#']).next().unwrap_or(package);
                let name = format!("{} {version}", unit["target"]["name"].as_str().unwrap_or_default());
                libraries.entry(name).or_default().push(unit["features"].to_string());
            }
        }
        let codegen: Vec<&String> = libraries.keys().filter(|k| k.starts_with("codegen ")).collect();
        assert!(!codegen.is_empty(), "no codegen unit in {:?}", libraries.keys());
        let twice: Vec<String> = libraries
            .iter()
            .filter(|(_, units)| units.len() > 1)
            .map(|(package, units)| format!("{package}: {units:?}"))
            .collect();
        assert!(
            twice.is_empty(),
            "libraries compiled more than once:\n{}",
            twice.join("\n")
        );
    }
}
