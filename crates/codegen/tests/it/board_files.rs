//! Board files: every file in `boards/` resolves and passes the chip checks; every file
//! of the corpus `tests/bad-boards/` is refused with a located error (file,
//! line:column of the offending value, key, what is wrong, what is accepted).

use std::path::Path;

use codegen::Source;
use codegen::board::{self, Board};

use motor_test_support::repo;

fn parse(path: &Path) -> (String, Result<Board, codegen::Diagnostics>) {
    let text = std::fs::read_to_string(path).expect("readable");
    let shown = path.file_name().unwrap().to_string_lossy().into_owned();
    let r = board::parse(Source {
        file: &shown,
        text: &text,
    });
    (text, r)
}

#[test]
fn every_board_in_boards_resolves() {
    let mut n = 0;
    for stem in motor_test_support::board_stems() {
        let path = repo().join(format!("boards/{stem}.toml"));
        let (_, r) = parse(&path);
        if let Err(d) = r {
            panic!("{}: {d}", path.display());
        }
        n += 1;
    }
    assert!(n >= 2, "the reference board and the NUCLEO-G474RE + X-NUCLEO-IHM08M1");
}

/// 1-based line and column of the first occurrence of `needle` in `text` (the
/// value the error must point at, located independently of the code under test).
fn position(text: &str, needle: &str) -> (usize, usize) {
    let at = text
        .find(needle)
        .unwrap_or_else(|| panic!("{needle:?} in the corpus file"));
    let line = text[..at].matches('\n').count() + 1;
    let col = text[..at].rsplit('\n').next().unwrap().chars().count() + 1;
    (line, col)
}

/// One corpus entry: (file, text the error points at, key, words of the problem, words
/// of the accepted line).
type Case = (
    &'static str,
    &'static str,
    &'static str,
    &'static [&'static str],
    &'static [&'static str],
);

const CORPUS: &[Case] = &[
    (
        "wrong-af.toml",
        "\"PA5\"",
        "pins.gate_u_low",
        &[
            "PA5 has no TIM1_CH1N function on the STM32G474RE",
            "alternate functions: AF1 TIM2_CH1",
        ],
        &["PA7 (AF6)", "PB13 (AF6)"],
    ),
    (
        "slow-channel-too-fast.toml",
        "2.5             # every input",
        "sensing.sampling_cycles",
        &[
            "PA4 is ADC2_IN17, a slow channel",
            "1100 Ω needs ≥ 24.5 cycles",
            "DS12288 Table 67",
        ],
        &["sampling_cycles = 24.5"],
    ),
    (
        "pin-used-twice.toml",
        "\"PB13\"             # TIM1_CH2N",
        "pins.gate_v_low",
        &["two signals on PB13: `pins.gate_u_low` and `pins.gate_v_low`"],
        &["one pin per signal"],
    ),
    (
        "boot0-unstated.toml",
        "\"PB8\"",
        "pins.can_rx",
        &["PB8 is BOOT0", "DS12288 §3.7", "nSWBOOT0 = 1"],
        &["[boot0]", "\"option_bytes\"", "\"held_low\""],
    ),
    (
        "boot0-held-low-with-can.toml",
        "\"held_low\"",
        "boot0.handling",
        &["CAN transceiver drives RXD high"],
        &["\"option_bytes\""],
    ),
    (
        "unknown-pin.toml",
        "\"PC16\"",
        "pins.resolver_excitation",
        &["\"PC16\" is not a pin of the STM32G474RE (LQFP64)"],
        &["PA0", "PC15", "PG10"],
    ),
    (
        "missing-signal.toml",
        "[pins]",
        "pins.gate_w_low",
        &["missing required key `pins.gate_w_low`"],
        &["TIM1_CH3N", "PB1 (AF6)", "PB15 (AF4)"],
    ),
    (
        "not-an-adc12-input.toml",
        "\"PB13\"",
        "pins.current_v",
        &["PB13 is not an input of ADC1 or ADC2", "ADC3_IN5"],
        &["an ADC1/ADC2 input", "PA0"],
    ),
    (
        "trip-beyond-range.toml",
        "\"150 A\"",
        "protection.over_current",
        &["beyond what the board measures, ±110.00 A"],
        &["up to 110.00 A"],
    ),
    (
        "gate-pull-turns-on.toml",
        "\"down\"   # wrong",
        "gate_driver.low_side_pull",
        &["the low_side input is inverted and held down", "it turns its switch on"],
        &["low_side_pull = \"up\""],
    ),
    (
        "unknown-gate-driver.toml",
        "\"L6399\"",
        "gate_driver.part",
        &["\"L6399\" is not in the parts table"],
        &["L6398", "DRV8323", "IR2110", "1EDI20N12AF", "high_side_input"],
    ),
    (
        "dc-link-shunt.toml",
        "\"dc_link\"",
        "current_sensing.placement",
        &["single DC-link shunt", "does not reconstruct"],
        &["\"low_side\" or \"inline\""],
    ),
    (
        "low-side-shunt-sampled-high.toml",
        "\"high_side_centre\"",
        "sensing.sample_instant",
        &["low-side shunts carry the phase current only while the low-side switch conducts"],
        &["\"low_side_centre\""],
    ),
    (
        "current-gain-moved.toml",
        "\"15 mV/A\"   # the old",
        "sensing.current_gain",
        &["no longer a board fact", "low-side shunt inverts it"],
        &["[current_sensing]", "amplifier_gain"],
    ),
    (
        "open-drain-active-high.toml",
        "\"open_drain\"",
        "break_input.output",
        &["open-drain output can only pull the line low"],
        &["output = \"push_pull\""],
    ),
    (
        "hse-out-of-range.toml",
        "\"50 MHz\"",
        "clock.hse",
        &["50 MHz is outside the HSE oscillator's range"],
        &["4 MHz and 48 MHz", "DS12288"],
    ),
    (
        "resolver-amplitude-clips.toml",
        "\"2 V\"",
        "sensing.resolver_amplitude",
        &["2 V is outside 0.165 V … 1.650 V", "half the 3.3 V reference"],
        &["from its schematic", "transformation ratio", "e.g. \"1.3 V\""],
    ),
    (
        "bare-number.toml",
        "500 ",
        "pwm.dead_time",
        &["bare number 500 where a time belongs"],
        &["\"1.5 ms\""],
    ),
];

#[test]
fn bad_boards_are_refused_at_the_key() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/bad-boards");
    let files = std::fs::read_dir(&dir).unwrap().count();
    assert_eq!(files, CORPUS.len(), "every corpus file has an expectation");
    for (file, at, key, problem, accepted) in CORPUS {
        let (text, r) = parse(&dir.join(file));
        let errors = match r {
            Ok(_) => panic!("{file} was accepted"),
            Err(d) => d.0,
        };
        let (line, column) = position(&text, at);
        let d = errors
            .iter()
            .find(|d| d.key == *key)
            .unwrap_or_else(|| panic!("{file}: no error at `{key}`: {errors:#?}"));
        assert_eq!(
            (d.file.as_str(), d.line, d.column),
            (*file, line, column),
            "{file}: {d}"
        );
        for p in *problem {
            assert!(d.problem.contains(p), "{file}: problem lacks {p:?}:\n{d}");
        }
        for a in *accepted {
            assert!(d.accepted.contains(a), "{file}: accepted lacks {a:?}:\n{d}");
        }
        // The rendered message names file:line:column and the key, like a motor spec's.
        assert!(
            d.to_string()
                .starts_with(&format!("error: {file}:{line}:{column}: `{key}`: ")),
            "{d}"
        );
    }
}

/// A board that names its driver and states facts contradicting it: the stated facts are
/// used (an inverter on the board would explain them) and `check` warns at each key,
/// citing the datasheet passage. Built from the NUCLEO file with LIN declared in phase
/// (and pulled down, which an in-phase input needs: an in-phase input with the L6398's
/// pull-up would turn its switch on at reset, which is refused).
#[test]
fn a_stated_fact_contradicting_its_part_is_warned_at_the_key() {
    let text = std::fs::read_to_string(repo().join("boards/nucleo-g474re-ihm08m1.toml")).unwrap();
    let stated = text.replace(
        "part = \"L6398\"",
        "part = \"L6398\"\nlow_side_input = \"in_phase\"   # contradicts the L6398\nlow_side_pull = \"down\"",
    );
    assert_ne!(stated, text);
    let b = board::parse(Source {
        file: "nucleo-stated.toml",
        text: &stated,
    })
    .unwrap_or_else(|d| panic!("{d}"));
    let (line, column) = position(&stated, "\"in_phase\"   # contradicts");
    assert_eq!(b.warnings.len(), 2, "{:#?}", b.warnings);
    let w = &b.warnings[0];
    assert!(
        w.starts_with(&format!(
            "nucleo-stated.toml:{line}:{column}: `gate_driver.low_side_input`: "
        )),
        "{w}"
    );
    for needle in ["in_phase", "L6398 has inverted", "truth table", "LIN is active low"] {
        assert!(w.contains(needle), "{needle:?} not in {w}");
    }
    assert!(
        b.warnings[1].contains("`gate_driver.low_side_pull`") && b.warnings[1].contains("Table 8"),
        "{}",
        b.warnings[1]
    );
    // The stated fact wins: no CCxNP, no OISxN.
    assert_eq!(board::tim1_ccer_polarity(&b), 0);
    assert_eq!(board::tim1_cr2_idle(&b), 0);
    // The file as shipped: no warning, the L6398's inverted LIN.
    let shipped = board::parse(Source {
        file: "nucleo-g474re-ihm08m1.toml",
        text: &text,
    })
    .unwrap();
    assert!(shipped.warnings.is_empty(), "{:?}", shipped.warnings);
    assert_eq!(board::tim1_ccer_polarity(&shipped), 0x0888);
}

/// A board value that only overflows with a motor (issue 31): a DC-link divider of
/// 1e-300 passes its own range check (a plain ratio) but gives ∞ volts per LSB. The
/// error is at `sensing.dc_link_divider` (not line 1, column 1), names the keys that
/// decide the value, and every board file the message points at exists.
#[test]
fn a_board_value_overflowing_with_the_motor_is_located_at_its_key() {
    let board = motor_test_support::read("boards/motorgen-reference.toml");
    let bad = board.replacen("dc_link_divider = 0.0044", "dc_link_divider = 1e-300", 1);
    assert_ne!(bad, board, "the reference board's divider line");
    let spec = motor_test_support::read("motors/fischer-ti085.toml");
    let e = codegen::design_with_board("motors/fischer-ti085.toml", &spec, "b.toml", &bad)
        .expect_err("an overflowing board value is refused");
    let d = &e.0[0];
    let (line, column) = position(&bad, "1e-300");
    assert_eq!((d.file.as_str(), d.line, d.column), ("b.toml", line, column), "{d}");
    assert_eq!(d.key, "sensing.dc_link_divider", "{d}");
    assert!(d.problem.contains("sensing.adc_reference"), "{d}");
    let message = d.to_string();
    let named: Vec<&str> = message
        .split(|c: char| c.is_whitespace() || c == '(' || c == ')' || c == ',')
        .filter(|w| w.starts_with("boards/") && w.ends_with(".toml"))
        .collect();
    assert!(!named.is_empty(), "{message}");
    for file in named {
        assert!(
            repo().join(file).is_file(),
            "the message names {file}, which does not exist:\n{message}"
        );
    }
}

/// ES0430 (STM32G47x errata), ADC: two ADCs converting concurrently disturb each other's
/// conversions unless they run in lock-step — same clock, same hardware trigger (as the
/// image's ADC1/ADC2 on HCLK/4 and TIM1_TRGO2 are) and, with sequences, the same number
/// of ranks with the same sampling time rank by rank, so that every sampling phase of
/// one starts and ends with the other's (moteus, `fw/bldc_servo.cc`, cites ES0430
/// §2.7.11 for the simultaneous trigger and converts one rank on every ADC). Property of
/// every board's plan: equal lengths, equal cycles per rank.
#[test]
fn both_converters_run_in_lock_step() {
    for stem in motor_test_support::board_stems() {
        let path = repo().join(format!("boards/{stem}.toml"));
        let (_, r) = parse(&path);
        let b = r.unwrap_or_else(|d| panic!("{}: {d}", path.display()));
        let [a1, a2] = &b.adc;
        assert_eq!(a1.len(), a2.len(), "{stem}: ranks of ADC1 {a1:?} and ADC2 {a2:?}");
        for (k, (x, y)) in a1.iter().zip(a2).enumerate() {
            assert_eq!(x.sampling.cycles, y.sampling.cycles, "{stem}: rank {} sampling", k + 1);
        }
    }
}
