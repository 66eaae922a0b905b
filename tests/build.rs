//! Generates, for every spec in `../motors/`, the template-rendered module, the
//! proc-macro expansion of the same spec, and a listing of their constants, so the
//! tests cover a new motor file without any Rust or Cargo edit.

use std::fmt::Write;
use std::path::Path;

use codegen::constants::constants;
use codegen::render::{Output, render};

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let motors = root.join("motors");
    println!("cargo::rerun-if-changed={}", motors.display());
    println!("cargo::rerun-if-changed={}", root.join("templates").display());
    let out = std::env::var("OUT_DIR").expect("OUT_DIR");
    let mut specs: Vec<_> = std::fs::read_dir(&motors)
        .expect("motors/")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    specs.sort();
    if specs.is_empty() {
        // Every generated-module test would loop over no motor and pass.
        println!("cargo::error={} holds no *.toml: nothing to test", motors.display());
        return;
    }
    let mut all = String::new();
    let mut table = String::from(
        "/// Every motor: (stem, template listing, proc-macro listing).\npub const MOTORS: &[(&str, Listing, Listing)] = &[\n",
    );
    for path in &specs {
        println!("cargo::rerun-if-changed={}", path.display());
        let stem = path.file_stem().unwrap().to_string_lossy().into_owned();
        let ident = stem.replace('-', "_");
        let rel = format!("motors/{stem}.toml");
        let text = std::fs::read_to_string(path).expect("spec");
        let design = match codegen::design_source(&rel, &text) {
            Ok(d) => d,
            Err(e) => {
                for line in e.to_string().lines() {
                    println!("cargo::error={line}");
                }
                return;
            }
        };
        let code = render(&design, Output::Rust).expect("render");
        std::fs::write(Path::new(&out).join(format!("{ident}.rs")), code).expect("write");
        let mut list = String::new();
        for g in constants(&design) {
            for k in &g.constants {
                let item = format!("{}::{}", g.name, k.name);
                let expr = match k.value.rust_type.as_str() {
                    "::fixed::types::I1F31" => format!("vec![m::{item}.to_bits() as f64]"),
                    t if t.starts_with('[') => format!("m::{item}.iter().map(|&v| f64::from(v)).collect()"),
                    _ => format!("vec![m::{item} as f64]"),
                };
                writeln!(
                    list,
                    "        (\"{item}\", \"{}\", \"{}\", {expr}),",
                    k.json_path, k.value.rust_type
                )
                .unwrap();
            }
        }
        writeln!(
            all,
            "/// `{rel}`.\npub mod {ident} {{\n    /// Rendered through `templates/motor.rs.j2`.\n    pub mod template {{\n        include!(concat!(env!(\"OUT_DIR\"), \"/{ident}.rs\"));\n    }}\n    /// Expanded by `motor_constants!`.\n    pub mod expanded {{\n        motor_macros::motor_constants!(\"../{rel}\");\n    }}\n    /// Template constants: (item, JSON pointer, Rust type, value(s)).\n    pub fn template() -> Vec<super::Entry> {{\n        use template as m;\n        vec![\n{list}        ]\n    }}\n    /// Proc-macro constants, same order.\n    pub fn expanded() -> Vec<super::Entry> {{\n        use expanded as m;\n        vec![\n{list}        ]\n    }}\n}}"
        )
        .unwrap();
        writeln!(table, "    (\"{stem}\", {ident}::template, {ident}::expanded),").unwrap();
    }
    table.push_str("];\n");
    all.push_str(&table);
    std::fs::write(Path::new(&out).join("generated.rs"), all).expect("write");
}
