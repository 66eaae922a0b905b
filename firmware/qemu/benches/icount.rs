//! Instructions per control step on the emulated Cortex-M4F, per motor in `motors/`.
//!
//! For every `motors/<stem>.toml` (or `$MOTORS_DIR`): builds the `icount` binary with
//! `MOTOR=<stem>` (release, thumbv7em-none-eabihf; only `motor-config` and
//! `motor-qemu` rebuild per motor), runs it twice under
//! `qemu-system-arm -machine netduinoplus2 -icount shift=5` (deterministic: both runs
//! must print the same bytes), checks the tick/instruction factor against the
//! 1024-`nop` calibration and prints one table row per motor.
//!
//! ```text
//! cd firmware && cargo bench -p motor-qemu --bench icount
//! ```
//!
//! Instructions = SysTick ticks / 5.376 (2^5 ns per instruction, 168 MHz SYSCLK). The
//! CORDIC column is the step with every trig result replayed from memory (the
//! software trigonometry removed, same output) plus the CORDIC's computation time,
//! [`CORDIC_CYCLES`] per call, during which the core stalls on the result read.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use motor_qemu::host::{build, emulate, on_path};
use motor_qemu::icount::{Measurement, deci_instructions};

/// Seconds one emulator run may take.
const TIMEOUT_S: u32 = 120;
/// STM32G474 CORDIC cycles for one sine/cosine or phase (atan2) in q1.31 at 20-bit
/// precision: PRECISION = 6, i.e. 24 iterations at 4 iterations per clock cycle
/// (RM0440, CORDIC precision table). The register accesses around it (one or two
/// writes of WDATA, reads of RDATA) cost about what [`motor_qemu::icount::Replay`]'s
/// loads cost, so they are already in the replayed step.
const CORDIC_CYCLES: u64 = 6;
/// Cycle budget of one step: 170 MHz core clock / 20 kHz control rate.
const BUDGET_CYCLES: u64 = 8_500;

/// Motor stems in `dir`, sorted; an unreadable or empty `dir` fails
/// (`motor_test_support::stems_in`), never a table of no motors.
fn motors(dir: &Path) -> Vec<String> {
    motor_test_support::stems_in(dir)
}

/// `x` (× 10) as `<int>.<digit>`.
fn deci(x: u64) -> String {
    format!("{}.{}", x / 10, x % 10)
}

/// One motor's row: parses the output and derives the figures.
fn row(stem: &str, output: &str) -> Result<String, String> {
    let mut m = BTreeMap::new();
    let mut calls = BTreeMap::new();
    for line in output.lines() {
        if let Some(meas) = Measurement::parse(line) {
            m.insert(meas.name.to_string(), meas.stats);
        } else if let Some((name, n)) = line.split_once(' ')
            && let Ok(n) = n.trim().parse::<u64>()
        {
            calls.insert(name.to_string(), n);
        }
    }
    let get = |name: &str| {
        m.get(name)
            .copied()
            .ok_or_else(|| format!("{stem}: no `{name}` line in\n{output}"))
    };
    let calls_of = |name: &str| {
        calls
            .get(name)
            .copied()
            .ok_or_else(|| format!("{stem}: no `{name}` line in\n{output}"))
    };
    let nops = get("nop-1024")?;
    // 1024 instructions × 5.376 = 5505.0 ticks; the two SysTick reads quantise to ±1.
    if nops.min < 5_504 || nops.max > 5_506 {
        return Err(format!(
            "{stem}: 1024 nops took {}..{} ticks, expected 5505 ± 1 (5.376 ticks per instruction): \
             the -icount conversion does not hold",
            nops.min, nops.max
        ));
    }
    let step = get("step")?;
    let replayed = get("step-trig-replayed")?;
    let sin_cos = get("sin-cos")?;
    let atan2 = get("atan2")?;
    let fast = get("step-fast-trig")?;
    let fast_sin_cos = get("fast-sin-cos")?;
    let fast_atan2 = get("fast-atan2")?;
    let n_sc = calls_of("sin-cos-calls-per-step")?;
    let n_at = calls_of("atan2-calls-per-step")?;
    let mean = |s: motor_qemu::icount::Stats| deci_instructions(s.sum, u64::from(s.count));
    let step_mean = mean(step);
    let replayed_mean = mean(replayed);
    let cordic = replayed_mean + 10 * CORDIC_CYCLES * (n_sc + n_at);
    let trig = n_sc * mean(sin_cos) + n_at * mean(atan2);
    let fast_mean = mean(fast);
    Ok(format!(
        "| {stem} | {} / {} / {} ({:.1} %) | {}, {} | {} / {} / {} | {:.1} % | {} × {} + {} × {} = {} | {} | {} ({:.1} %) |",
        deci(deci_instructions(u64::from(fast.min), 1)),
        deci(deci_instructions(u64::from(fast.max), 1)),
        deci(fast_mean),
        fast_mean as f64 / 10.0 / BUDGET_CYCLES as f64 * 100.0,
        deci(mean(fast_sin_cos)),
        deci(mean(fast_atan2)),
        deci(deci_instructions(u64::from(step.min), 1)),
        deci(deci_instructions(u64::from(step.max), 1)),
        deci(step_mean),
        step_mean as f64 / 10.0 / BUDGET_CYCLES as f64 * 100.0,
        n_sc,
        deci(mean(sin_cos)),
        n_at,
        deci(mean(atan2)),
        deci(trig),
        deci(replayed_mean),
        deci(cordic),
        cordic as f64 / 10.0 / BUDGET_CYCLES as f64 * 100.0,
    ))
}

fn run() -> Result<(), String> {
    for program in ["qemu-system-arm", "timeout"] {
        if !on_path(program) {
            return Err(format!(
                "{program} is not on PATH: install it (Debian: `apt-get install qemu-system-arm coreutils`)"
            ));
        }
    }
    let workspace = Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .ok_or("the crate lies inside the firmware workspace")?
        .to_path_buf();
    let dir = std::env::var_os("MOTORS_DIR").map_or_else(|| workspace.join("..").join("motors"), PathBuf::from);
    let stems = motors(&dir);
    let mut rows = Vec::new();
    for stem in &stems {
        let elf = build(&workspace, "icount", Some(stem))?;
        let first = emulate(&elf, &["-icount", "shift=5"], TIMEOUT_S)?;
        let second = emulate(&elf, &["-icount", "shift=5"], TIMEOUT_S)?;
        if first != second {
            return Err(format!(
                "{stem}: two runs differ (not deterministic)\nfirst:\n{first}\nsecond:\n{second}"
            ));
        }
        println!("{stem} (two identical runs):\n{first}");
        rows.push(row(stem, &first)?);
    }
    println!(
        "instructions per current-control step on the emulated Cortex-M4F (-icount shift=5; \
         min / max / mean over the measured steps)"
    );
    println!(
        "| motor | step, FastTrig min / max / mean (of {BUDGET_CYCLES} cycles) | FastTrig sin/cos, atan2 | \
         step, SoftTrig min / max / mean | of {BUDGET_CYCLES} cycles | SoftTrig (calls × mean) | \
         step, trig replayed | with CORDIC (+{CORDIC_CYCLES} cycles per call) |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for r in rows {
        println!("{r}");
    }
    Ok(())
}

fn main() -> ExitCode {
    // `cargo bench` passes `--bench`; nothing else is accepted.
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
