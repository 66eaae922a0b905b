//! The bounded in-process fuzz harness of the crates' `fuzz` tests: a seeded generator,
//! case counts from the environment, and a runner that catches each case's panic
//! without touching the process's panic hook for anyone else.
//!
//! A case's panic is a finding, not noise: it is caught and reported with its seed and
//! input. Its message is silenced only on the thread running the case (a thread-local
//! flag consulted by a hook installed once that forwards every other panic to the hook
//! it replaced), so a failing test elsewhere in the same binary still prints its
//! message — the earlier harness swapped the global hook and silenced them all.

use std::cell::Cell;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::Once;
use std::time::Instant;

/// Cases per target from `MOTORGEN_FUZZ_CASES`, else `default` (CI's bounded slice).
pub fn cases(default: usize) -> usize {
    std::env::var("MOTORGEN_FUZZ_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

/// The first seed, from `MOTORGEN_FUZZ_SEED` (default 0).
pub fn seed_base() -> u64 {
    std::env::var("MOTORGEN_FUZZ_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(0)
}

/// A seeded, reproducible generator (SplitMix64).
pub struct Rng(u64);

impl Rng {
    /// The generator of case `seed`.
    pub fn new(seed: u64) -> Rng {
        Rng(seed.wrapping_mul(0x2545_F491_4F6C_DD1D) ^ 0x1234_5678)
    }

    /// A uniform sample in (0, 1).
    pub fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        ((z >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }

    /// A uniform index below `n` (0 for `n` = 0).
    pub fn below(&mut self, n: usize) -> usize {
        ((self.uniform() * n as f64) as usize).min(n.saturating_sub(1))
    }

    /// A uniformly chosen element of a non-empty slice.
    pub fn pick<'a, T>(&mut self, xs: &'a [T]) -> &'a T {
        &xs[self.below(xs.len())]
    }

    /// `true` with probability `p`.
    pub fn chance(&mut self, p: f64) -> bool {
        self.uniform() < p
    }
}

/// `lines` joined with `\n`, line `i` replaced by `new`.
pub fn replace_line(lines: &[&str], i: usize, new: &str) -> String {
    let mut out: Vec<&str> = lines.to_vec();
    out[i] = new;
    out.join("\n")
}

thread_local! {
    static QUIET: Cell<bool> = const { Cell::new(false) };
}

static HOOK: Once = Once::new();

/// Runs `f`, turning a panic into `Err(message)`; the panic's message is not printed
/// (only on this thread, only while `f` runs).
pub fn caught<R>(f: impl FnOnce() -> R) -> Result<R, String> {
    HOOK.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !QUIET.with(Cell::get) {
                previous(info);
            }
        }));
    });
    QUIET.with(|q| q.set(true));
    let r = catch_unwind(AssertUnwindSafe(f));
    QUIET.with(|q| q.set(false));
    r.map_err(|p| {
        p.downcast_ref::<&str>()
            .map(|s| (*s).to_string())
            .or_else(|| p.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "non-string panic".into())
    })
}

/// Runs `n` cases of `one` (seed → (input, verdict)) from [`seed_base`], each inside
/// [`caught`] (a panic is a failure with its seed), printing counts and the slowest case;
/// fails the test with the first five failures, each with its seed and input.
/// `Ok(true)` is an accepted input, `Ok(false)` one refused as it should be.
pub fn run(name: &str, n: usize, mut one: impl FnMut(u64) -> (String, Result<bool, String>)) {
    assert!(n > 0, "{name}: zero cases would pass without testing anything");
    let started = Instant::now();
    let mut failures = Vec::new();
    let mut accepted = 0usize;
    let mut slowest = (0.0f64, 0u64);
    for k in 0..n as u64 {
        let seed = seed_base() + k;
        let t = Instant::now();
        let (input, verdict) = match caught(|| one(seed)) {
            Ok(r) => r,
            Err(p) => (
                String::from("(the panic happened while building the input)"),
                Err(format!("panic: {p}")),
            ),
        };
        let dt = t.elapsed().as_secs_f64();
        if dt > slowest.0 {
            slowest = (dt, seed);
        }
        if verdict == Ok(true) {
            accepted += 1;
        }
        if n >= 10_000 && (k + 1) % (n as u64 / 10) == 0 {
            eprintln!("{name}: {} cases, {:.0} s", k + 1, started.elapsed().as_secs_f64());
        }
        if n == 1 {
            eprintln!("seed {seed} ({dt:.2} s): {verdict:?}\n--- input ---\n{input}\n---");
        }
        if let Err(why) = verdict {
            // Printed at once: a long run shows its findings while it goes on.
            eprintln!("FAILURE seed {seed}: {why}\n--- input ---\n{input}\n---");
            failures.push(format!("seed {seed}: {why}\n--- input ---\n{input}\n---"));
            if failures.len() >= 5 {
                break;
            }
        }
    }
    eprintln!(
        "{name}: {n} cases ({accepted} accepted, the rest refused with a located error) in {:.1} s, slowest {:.2} s (seed {}), {} failures",
        started.elapsed().as_secs_f64(),
        slowest.0,
        slowest.1,
        failures.len()
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Every diagnostic `(file, line, column, problem, accepted)` names one of `files`, a
/// line and column ≥ 1, what is wrong and what is accepted; and there is at least one.
pub fn located<'a>(
    diagnostics: impl IntoIterator<Item = (&'a str, usize, usize, &'a str, &'a str)>,
    files: &[&str],
) -> Result<(), String> {
    let mut n = 0;
    for (file, line, column, problem, accepted) in diagnostics {
        n += 1;
        if !files.contains(&file) || line == 0 || column == 0 || problem.is_empty() || accepted.is_empty() {
            return Err(format!(
                "unlocated diagnostic: {file}:{line}:{column}: {problem:?} (accepted: {accepted:?})"
            ));
        }
    }
    if n == 0 {
        return Err("an error without any diagnostic".into());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_caught_panic_is_its_message_and_the_hook_stays_for_others() {
        assert_eq!(caught(|| panic!("boom")), Err::<(), _>("boom".to_string()));
        assert_eq!(caught(|| 3), Ok(3));
        // Another thread's panic still reaches the previous hook: the flag is per thread.
        assert!(!QUIET.with(Cell::get));
    }

    #[test]
    fn the_generator_is_reproducible() {
        let (mut a, mut b) = (Rng::new(7), Rng::new(7));
        for _ in 0..100 {
            assert_eq!(a.uniform().to_bits(), b.uniform().to_bits());
        }
        let u = Rng::new(1).uniform();
        assert!(u > 0.0 && u < 1.0);
    }
}
