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
}
