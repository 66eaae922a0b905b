//! Time and peak memory of `motorgen identify --dry-run`'s write-back path on long specs:
//! the Fischer spec after 0, 20,000 and 40,000 comment lines, with q-axis values written
//! (`writeback::apply`), the updated spec designed (`design_source`, as identify checks
//! it) and the change printed (`writeback::line_diff`).
//!
//! `cargo bench -p motor-benches --bench writeback`. Each size runs in a child process of this
//! binary so that its peak resident memory (VmHWM, /proc/self/status) is its own.

use std::path::Path;
use std::process::Command;
use std::time::Instant;

use motor_commission::writeback::{Entry, Origin, apply, line_diff};

const SIZES: [usize; 3] = [0, 20_000, 40_000];
const CHILD: &str = "MOTORGEN_WRITEBACK_BENCH_LINES";

/// Peak resident set of this process [kB] (Linux).
fn peak_rss_kb() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// One run of the dry-run path on a spec with `lines` comment lines; prints
/// `lines seconds peak_kB diff_lines`.
fn child(lines: usize) {
    let spec = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../../motors/fischer-ti085.toml"))
        .expect("the Fischer spec");
    let comments: String = (0..lines).map(|k| format!("# bench note {k}\n")).collect();
    let text = format!("{comments}{spec}");
    let files = vec!["q1.csv".to_string()];
    let entries = [
        Entry {
            key: "phase_resistance",
            value: "0.1322 Ω".into(),
            note: "bench".into(),
        },
        Entry {
            key: "q_inductance",
            value: "0.4130 mH".into(),
            note: "bench".into(),
        },
    ];
    let origin = Origin {
        date: "2025-03-14",
        label: "step q",
        files: &files,
    };
    let start = Instant::now();
    let new = apply(&text, &entries, &origin).expect("the spec takes the values");
    codegen::design_source("fischer.toml", &new).expect("the updated spec designs");
    let diff = line_diff(&text, &new);
    let secs = start.elapsed().as_secs_f64();
    println!(
        "{lines} {secs:.4} {} {}",
        peak_rss_kb().unwrap_or(0),
        diff.lines().count()
    );
}

fn main() {
    if let Ok(n) = std::env::var(CHILD) {
        child(n.parse().expect("a line count"));
        return;
    }
    let me = std::env::current_exe().expect("this bench's path");
    println!("writeback --dry-run path (apply + design + line diff), one child process per size");
    println!(
        "{:>14} {:>10} {:>14} {:>11}",
        "comment lines", "time [s]", "peak RSS [MB]", "diff lines"
    );
    for lines in SIZES {
        let out = Command::new(&me)
            .env(CHILD, lines.to_string())
            .output()
            .expect("run the child");
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let text = String::from_utf8_lossy(&out.stdout);
        let f: Vec<&str> = text.split_whitespace().collect();
        let kb: f64 = f[2].parse().unwrap_or(0.0);
        println!("{:>14} {:>10} {:>14.1} {:>11}", f[0], f[1], kb / 1024.0, f[3]);
    }
}
