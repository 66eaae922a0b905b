//! The CLI's output under faults: stdout on a full disk (`/dev/full`) or a closed pipe,
//! and `generate` killed mid-write, failing on one output, or given a file as `--out`.

#![cfg(unix)]

use crate::common::{EXIT_IO, SIGXFSZ, repo, temporaries, text_of};

use std::fs::OpenOptions;
use std::os::unix::process::ExitStatusExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

fn spec() -> String {
    repo().join("motors/fischer-ti085.toml").display().to_string()
}

fn motorgen() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_motorgen"));
    c.current_dir(repo());
    c
}

/// The commands that print to stdout, with arguments, and a directory for `report`.
fn printing_commands(dir: &Path) -> Vec<Vec<String>> {
    let s = spec();
    let out = dir.display().to_string();
    let ident = dir.join("fischer.toml");
    std::fs::copy(&s, &ident).unwrap();
    let csv = dir.join("flux.csv");
    let mut rec = String::from("# motorgen recording: flux\nsample,omega_e_rad_s,u_q_v\n");
    for n in 0..100 {
        rec.push_str(&format!("{n},1000,60\n"));
    }
    std::fs::write(&csv, rec).unwrap();
    [
        vec!["design", &s],
        vec!["design", &s, "--format", "rust"],
        vec!["design", &s, "--format", "json"],
        vec!["check", &s],
        vec!["list"],
        vec!["verify", &s],
        vec!["report", &s, "--out", &out],
        vec![
            "identify",
            "flux",
            &ident.display().to_string(),
            "--csv",
            &csv.display().to_string(),
            "--dry-run",
        ],
    ]
    .iter()
    .map(|v| v.iter().map(|x| x.to_string()).collect())
    .collect()
}

/// Every command that prints, with stdout on `/dev/full` (every write fails with
/// ENOSPC): exit 74, one clear message on stderr, no panic.
#[test]
fn full_disk_on_stdout_is_an_error_not_a_panic() {
    let dir = crate::common::tmp("output", "dev_full");
    for args in printing_commands(&dir) {
        let full = OpenOptions::new().write(true).open("/dev/full").unwrap();
        let o = motorgen().args(&args).stdout(full).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(EXIT_IO), "{args:?}: {}", text_of(&o));
        assert!(
            err.contains("error: cannot write to standard output: No space left on device"),
            "{args:?}: {err}"
        );
        assert!(!err.contains("panicked"), "{args:?}: {err}");
    }
}

/// Every command that prints, with its stdout a pipe whose reading end is closed before
/// it writes: it ends quietly (no message about the pipe: stderr holds at most the
/// design's warnings, which go there whatever becomes of stdout) with exit 0, as
/// `… | head -1` expects.
#[test]
fn closed_pipe_exits_quietly() {
    let dir = crate::common::tmp("output", "closed_pipe");
    for args in printing_commands(&dir) {
        let mut child = motorgen()
            .args(&args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        drop(child.stdout.take());
        let o = child.wait_with_output().unwrap();
        assert_eq!(o.status.code(), Some(0), "{args:?}: {}", text_of(&o));
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(
            stderr.lines().all(|l| l.starts_with("warning: ")),
            "{args:?}: {}",
            text_of(&o)
        );
    }
    // The shell pipeline of the issue, with pipefail: head's exit and motorgen's.
    let o = Command::new("bash")
        .arg("-c")
        .arg("set -o pipefail; \"$0\" design \"$1\" --format rust | head -1")
        .arg(env!("CARGO_BIN_EXE_motorgen"))
        .arg(spec())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text_of(&o));
    assert_eq!(String::from_utf8_lossy(&o.stdout).lines().count(), 1);
    assert!(
        String::from_utf8_lossy(&o.stderr)
            .lines()
            .all(|l| l.starts_with("warning: ")),
        "{}",
        text_of(&o)
    );
}

/// An output directory holding the previous set ("old" in each file).
fn old_set(name: &str) -> (PathBuf, Vec<PathBuf>) {
    let dir = crate::common::tmp("output", name);
    let files: Vec<PathBuf> = ["fischer_ti085.rs", "fischer_ti085.h", "fischer-ti085.md"]
        .iter()
        .map(|f| dir.join(f))
        .collect();
    for f in &files {
        std::fs::write(f, "old\n").unwrap();
    }
    (dir, files)
}

fn all_old(files: &[PathBuf]) -> bool {
    files.iter().all(|f| std::fs::read_to_string(f).unwrap() == "old\n")
}

/// `generate` under a 4 KiB file-size limit (`ulimit -f 4`; the Rust module is larger):
/// killed, it leaves the previous set untouched (its temporary file is removed by the
/// next run, which says so); with SIGXFSZ ignored it fails with an I/O error naming the
/// file and "no file was replaced", and leaves nothing behind.
#[test]
fn generate_writes_the_set_all_or_nothing() {
    let (dir, files) = old_set("generate_killed");
    let out = dir.display().to_string();
    let limited = |trap: &str, out: &str| {
        Command::new("bash")
            .arg("-c")
            .arg(format!("{trap} ulimit -f 4; exec \"$0\" generate \"$1\" --out \"$2\""))
            .arg(env!("CARGO_BIN_EXE_motorgen"))
            .arg(spec())
            .arg(out)
            .output()
            .unwrap()
    };
    let o = limited("", &out);
    assert_eq!(o.status.signal(), Some(SIGXFSZ), "{}", text_of(&o));
    assert!(all_old(&files));
    let left = temporaries(&dir);
    assert_eq!(left.len(), 1, "{left:?}");
    let o = motorgen().args(["generate", &spec(), "--out", &out]).output().unwrap();
    assert!(o.status.success(), "{}", text_of(&o));
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("removed"),
        "{}",
        text_of(&o)
    );
    assert_eq!(String::from_utf8_lossy(&o.stdout).matches("wrote ").count(), 3);
    assert!(temporaries(&dir).is_empty());
    assert!(std::fs::read_to_string(&files[0]).unwrap().contains("pub const"));

    let (dir, files) = old_set("generate_efbig");
    let out = dir.display().to_string();
    let o = limited("trap '' XFSZ;", &out);
    assert_eq!(o.status.code(), Some(EXIT_IO), "{}", text_of(&o));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("File too large") && err.contains("no file was replaced"),
        "{err}"
    );
    assert!(all_old(&files));
    assert!(temporaries(&dir).is_empty());
}

/// One output that cannot be replaced (a directory where the header goes) fails the
/// whole set before any file is touched.
#[test]
fn generate_refuses_before_replacing_any_file() {
    let (dir, mut files) = old_set("generate_blocked");
    std::fs::remove_file(&files[1]).unwrap();
    std::fs::create_dir(&files[1]).unwrap();
    files.remove(1);
    let o = motorgen()
        .args(["generate", &spec(), "--out", &dir.display().to_string()])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(EXIT_IO), "{}", text_of(&o));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("fischer_ti085.h") && err.contains("no file was replaced"),
        "{err}"
    );
    assert!(all_old(&files));
    assert!(temporaries(&dir).is_empty());
}

/// `--out` naming a file: `generate` and `report` say they need a directory, exit 1,
/// and leave the file alone.
#[test]
fn out_naming_a_file_needs_a_directory() {
    let dir = crate::common::tmp("output", "out_file");
    let file = dir.join("not-a-dir");
    std::fs::write(&file, "mine\n").unwrap();
    for cmd in ["generate", "report"] {
        let o = motorgen()
            .args([cmd, &spec(), "--out", &file.display().to_string()])
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(1), "{cmd}: {}", text_of(&o));
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains("--out needs a directory"), "{cmd}: {err}");
        assert_eq!(std::fs::read_to_string(&file).unwrap(), "mine\n");
    }
}
