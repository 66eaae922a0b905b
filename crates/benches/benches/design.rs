//! Time to design one motor (spec text → complete design, FIR included) and all of `motors/`.
//! Target (issue): under 10 ms per motor, release build.

use std::hint::black_box;
use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};

/// `(motors/<stem>.toml, text)` of every motor; an empty or unreadable `motors/` fails
/// (`motor_test_support::motors`) instead of benchmarking nothing.
fn specs() -> Vec<(String, String)> {
    motor_test_support::motors()
        .into_iter()
        .map(|(_, rel, text)| (rel, text))
        .collect()
}

fn bench(c: &mut Criterion) {
    let specs = specs();
    for (file, text) in &specs {
        let stem = Path::new(file).file_stem().unwrap().to_string_lossy().into_owned();
        c.bench_function(&format!("design/{stem}"), |b| {
            b.iter(|| codegen::design_source(black_box(file), black_box(text)).unwrap())
        });
    }
    c.bench_function("design/all-motors", |b| {
        b.iter(|| {
            for (file, text) in &specs {
                black_box(codegen::design_source(file, text).unwrap());
            }
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
