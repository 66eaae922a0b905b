//! What `check` accepts builds: the firmware image (release, LTO: its link also proves
//! that no panic path survives) is built for spec × board pairs `check` accepts.
//!
//! * The boundary: every accepted value of `codegen::firmware::FIRMWARE_LIMITS`' cases
//!   (hand calculations at each limit the build enforces), grouped into as few files as
//!   `check` accepts together, each built on the default motor or board.
//! * A fuzz slice: pairs of a seed motor and board with values drawn near the firmware's
//!   limits (bit rates, dead times, watchdog timeouts, setpoint identifiers, two or three
//!   current phases, sampling instant, break polarity, f_s and the spec's dead time); the
//!   pairs `check` refuses are skipped, every pair it accepts must build.
//!   `MOTORGEN_FIRMWARE_FUZZ=N` builds N accepted pairs (CI: 2; each image build costs
//!   seconds after the first), `MOTORGEN_FUZZ_SEED` moves the seeds.

use codegen::firmware::{FIRMWARE_LIMITS, Home};
use motor_test_support::fuzz::{Rng, seed_base};
use motor_test_support::{read, set_toml_key};

/// Builds the release image of `motor` on `board` (texts) in `firmware/target`, from a
/// temporary motors and boards folder; `Err` with cargo's messages.
fn build(tag: &str, motor: &str, board: &str) -> Result<(), String> {
    let dir = motor_test_support::tmp("firmware-limits", tag);
    std::fs::create_dir_all(dir.join("motors")).unwrap();
    std::fs::create_dir_all(dir.join("boards")).unwrap();
    std::fs::write(dir.join("motors/fuzz-motor.toml"), motor).unwrap();
    std::fs::write(dir.join("boards/fuzz-board.toml"), board).unwrap();
    let out = motor_test_support::firmware_image_build("fuzz-motor", "fuzz-board", &dir.join("boards"))
        .env("MOTORS_DIR", dir.join("motors"))
        .output()
        .map_err(|e| format!("cargo: {e}"))?;
    if out.status.success() {
        Ok(())
    } else {
        Err(String::from_utf8_lossy(&out.stderr).into_owned())
    }
}

/// Whether `check` accepts `motor` on `board`.
fn accepted(motor: &str, board: &str) -> Result<(), String> {
    codegen::design_with_board("motors/fuzz-motor.toml", motor, "boards/fuzz-board.toml", board)
        .map(|_| ())
        .map_err(|e| e.to_string())
}

/// The texts of a file with `edits`.
fn edit(text: &str, edits: &[(&str, &str)]) -> String {
    edits.iter().fold(text.to_string(), |t, (k, v)| set_toml_key(&t, k, v))
}

/// (key, value) edits of one file.
type Edits = Vec<(&'static str, &'static str)>;

/// One group of boundary cases: the file (home and base), its edits, and the edits of
/// the partner file `check` pairs it with.
type Group = (Home, &'static str, Edits, &'static [(&'static str, &'static str)]);

/// The boundary cases' accepted values, grouped per file: each case joins the first group
/// of its file (home, base and partner edits) whose keys it does not set otherwise and
/// with which `check` still accepts the pair.
fn boundary_groups() -> Vec<Group> {
    let mut groups: Vec<Group> = Vec::new();
    for l in FIRMWARE_LIMITS {
        for c in l.cases {
            let mut mine: Vec<(&str, &str)> = c.also.to_vec();
            mine.push((c.key, c.accepted));
            let joined = groups.iter_mut().find(|(home, base, edits, partner)| {
                if *home != c.home || *base != c.base || *partner != c.partner {
                    return false;
                }
                let clash = mine
                    .iter()
                    .any(|(k, v)| edits.iter().any(|(k2, v2)| k == k2 && v != v2));
                if clash {
                    return false;
                }
                let mut all = edits.clone();
                all.extend(mine.iter().copied());
                pair(*home, base, &all, partner).is_ok_and(|(m, b)| accepted(&m, &b).is_ok())
            });
            match joined {
                Some((_, _, edits, _)) => edits.extend(mine),
                None => groups.push((c.home, c.base, mine, c.partner)),
            }
        }
    }
    groups
}

/// The motor and board texts of a group: the edited file and the default partner with
/// `partner`'s edits.
fn pair(home: Home, base: &str, edits: &[(&str, &str)], partner: &[(&str, &str)]) -> Result<(String, String), String> {
    let other = edit(&read(&home.partner()), partner);
    Ok(match home {
        Home::Spec => (edit(&read(&format!("motors/{base}.toml")), edits), other),
        Home::Board => (other, edit(&read(&format!("boards/{base}.toml")), edits)),
    })
}

#[test]
fn the_image_builds_at_every_limit_check_accepts() {
    let groups = boundary_groups();
    let cases: usize = FIRMWARE_LIMITS.iter().map(|l| l.cases.len()).sum();
    println!("{cases} boundary cases in {} builds", groups.len());
    assert!(groups.len() < cases, "the cases should share builds");
    for (k, (home, base, edits, partner)) in groups.iter().enumerate() {
        let (motor, board) = pair(*home, base, edits, partner).unwrap();
        if let Err(e) = accepted(&motor, &board) {
            panic!("{base} with {edits:?} (partner {partner:?}): check refuses the accepted values together:\n{e}");
        }
        let t = std::time::Instant::now();
        if let Err(e) = build(&format!("boundary-{k}"), &motor, &board) {
            panic!("{base} with {edits:?}: check accepts, the build fails:\n{e}");
        }
        println!("{base} {edits:?}: built in {:.1} s", t.elapsed().as_secs_f64());
    }
}

/// `text` without the line of `key` in `[table]` (an optional key left out).
fn without(text: &str, table: &str, key: &str) -> String {
    let mut in_table = false;
    text.lines()
        .filter(|l| {
            let t = l.trim_start();
            if t.starts_with('[') {
                in_table = t.starts_with(&format!("[{table}]"));
            }
            !(in_table && t.starts_with(key) && t[key.len()..].trim_start().starts_with('='))
        })
        .collect::<Vec<_>>()
        .join("\n")
        + "\n"
}

/// A motor and board near the firmware's limits, from `seed`.
fn near_limits(seed: u64) -> (String, String, String) {
    let mut rng = Rng::new(seed ^ 0x4649_524D);
    let motors = motor_test_support::motor_stems();
    let boards = motor_test_support::board_stems();
    let m = rng.pick(&motors).clone();
    let b = rng.pick(&boards).clone();
    let mut motor = read(&format!("motors/{m}.toml"));
    let mut board = read(&format!("boards/{b}.toml"));
    let mut what = vec![format!("{m} on {b}")];
    let set = |text: &mut String, key: &str, value: String, what: &mut Vec<String>| {
        *text = set_toml_key(text, key, &value);
        what.push(format!("{key} = {value}"));
    };
    let rates = [
        "10 kbit/s",
        "20 kbit/s",
        "50 kbit/s",
        "100 kbit/s",
        "125 kbit/s",
        "250 kbit/s",
        "1 Mbit/s",
    ];
    if rng.chance(0.5) {
        set(
            &mut board,
            "can.bit_rate",
            format!("\"{}\"", rng.pick(&rates)),
            &mut what,
        );
    }
    if rng.chance(0.5) {
        let ns = (rng.uniform() * 5929.0).round();
        set(&mut board, "pwm.dead_time", format!("\"{ns} ns\""), &mut what);
    }
    if rng.chance(0.5) {
        // Log-uniform from 125 µs to 32.76 s.
        let s = 125e-6 * (32.76f64 / 125e-6).powf(rng.uniform());
        set(&mut board, "watchdog.timeout", format!("\"{s:.6} s\""), &mut what);
    }
    if rng.chance(0.5) {
        let id = rng.below(0x7FB);
        set(&mut board, "can.setpoint_id", format!("{id:#05x}"), &mut what);
    }
    if rng.chance(0.3) {
        board = without(&board, "pins", "current_w");
        what.push("no current_w".into());
    }
    if rng.chance(0.3) {
        let i = rng.pick(&["\"low_side_centre\"", "\"high_side_centre\""]).to_string();
        set(&mut board, "sensing.sample_instant", i, &mut what);
    }
    if rng.chance(0.3) {
        let p = rng.pick(&["\"active_low\"", "\"active_high\""]).to_string();
        set(&mut board, "break_input.polarity", p, &mut what);
    }
    if rng.chance(0.3) {
        let ns = (rng.uniform() * 5929.0).round();
        set(&mut motor, "drive.dead_time", format!("\"{ns} ns\""), &mut what);
    }
    if rng.chance(0.3) {
        // Log-uniform from 1.3 kHz to 80 kHz (check refuses what the motor cannot use).
        let f = 1.3e3 * (80e3f64 / 1.3e3).powf(rng.uniform());
        set(
            &mut motor,
            "drive.switching_frequency",
            format!("\"{f:.0} Hz\""),
            &mut what,
        );
    }
    (what.join(", "), motor, board)
}

#[test]
fn accepted_pairs_near_the_limits_build() {
    let n: usize = std::env::var("MOTORGEN_FIRMWARE_FUZZ")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(2);
    let (mut built, mut refused) = (0, 0);
    let mut seed = seed_base();
    while built < n {
        assert!(refused < 50 * n + 50, "{refused} pairs refused for {built} built");
        let (what, motor, board) = near_limits(seed);
        seed += 1;
        if accepted(&motor, &board).is_err() {
            refused += 1;
            continue;
        }
        let t = std::time::Instant::now();
        if let Err(e) = build(&format!("fuzz-{}", seed - 1), &motor, &board) {
            panic!("seed {}: {what}: check accepts, the build fails:\n{e}", seed - 1);
        }
        println!("seed {}: {what}: built in {:.1} s", seed - 1, t.elapsed().as_secs_f64());
        built += 1;
    }
    println!("{built} accepted pairs built, {refused} refused by check");
}
