//! Time of `motorgen verify` (spec text → design → every scenario) and of `motorgen report`
//! (the same plus the plots and the HTML page) per motor.
//! Target (issue): under 2 s each, release build.

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
    let mut g = c.benchmark_group("verify");
    g.sample_size(20);
    for (file, text) in &specs() {
        let stem = Path::new(file).file_stem().unwrap().to_string_lossy().into_owned();
        g.bench_function(format!("verify/{stem}"), |b| {
            b.iter(|| motor_verify::verify_source(black_box(file), black_box(text)).unwrap())
        });
        g.bench_function(format!("report/{stem}"), |b| {
            b.iter(|| {
                let (d, v) = motor_verify::verify_source(black_box(file), black_box(text)).unwrap();
                motor_verify::report::report(&d, &v).unwrap()
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
