//! Board files with one fact wrong, built into images and run on the emulated board
//! they claim to describe (its own hardware description, not the file): each fails with
//! the rule or the criterion that catches it. Built from the NUCLEO-G474RE +
//! X-NUCLEO-IHM08M1 file (the motor: the first that fits it).

use crate::BOOT_LIMIT_S;
use crate::closed_loop::current_step_on;
use motor_emulator::rig::{Bench, Rig, benches};
use motor_emulator::{Stop, Violation};

const BOARD: &str = "nucleo-g474re-ihm08m1";

/// The bench with the board file's `from` replaced by `to` (exactly once).
fn variant(from: &str, to: &str) -> Bench {
    let motor = benches()
        .into_iter()
        .find(|(_, b)| b == BOARD)
        .map(|(m, _)| m)
        .expect("a motor fits the NUCLEO");
    let bench = Bench::new(&motor, BOARD).unwrap();
    assert_eq!(
        bench.board.text.matches(from).count(),
        1,
        "{from:?} once in the board file"
    );
    let text = bench.board.text.replace(from, to);
    bench.board_text(text)
}

/// Boots the variant; the violation that stopped it.
fn boot_violation(bench: Bench) -> Violation {
    let name = bench.name();
    let mut rig = Rig::new(bench).unwrap_or_else(|e| panic!("{name}: {e}"));
    match rig.run(BOOT_LIMIT_S, |_| Some(0.0), |_| false) {
        Err(Stop::Violation(v)) => v,
        r => panic!("{name}: expected a strict-mode rule, got {r:?}"),
    }
}

/// The driver named wrongly (an IR2110, in-phase inputs, where the shield has L6398s
/// with an active-low LIN): the image idles CHxN low, which turns each low side on as
/// soon as its pin is routed. The bring-up routes port A first, so PA7 (u low) is the
/// first: one low side on with MOE = 0 stops the run before PB0/PB1 would short the
/// phases through the low sides.
#[test]
fn wrong_gate_driver_turns_a_low_side_on_at_bring_up() {
    let v = boot_violation(variant("part = \"L6398\"", "part = \"IR2110\""));
    println!("driver polarity wrong: {v}");
    assert!(v.rule.contains("while the image means the outputs off"), "{v}");
    assert!(
        v.rule
            .contains("u low side on (PA7 low, the L6398 input is active low)"),
        "{v}"
    );
}

/// The break input said to be active high: the comparator's idle-high line is a break
/// from the moment it is routed; the image halts at bring-up with the outputs off.
#[test]
fn wrong_break_polarity_halts_at_bring_up() {
    let bench = variant(
        "polarity = \"active_low\"         # the shield's",
        "polarity = \"active_high\"        # the shield's",
    );
    let name = bench.name();
    let mut rig = Rig::new(bench).unwrap();
    let e = rig.boot(BOOT_LIMIT_S).unwrap_err();
    println!("break polarity wrong: {e}");
    assert!(
        e.contains("no enabled PWM period") && e.contains("bring-up"),
        "{name}: {e}"
    );
    // The cause: TIM1 sees its break input active with the comparator idle (the pin
    // high, BKP = 1), so the image's check after arming the break halts it.
    let soc = rig.machine.soc();
    assert!(
        soc.tim1.break_active && !soc.tim1.moe(),
        "{name}: the break is not what stopped it"
    );
}

/// The shunts said to be in line: the sign of the current sensing flips and the current
/// loops feed back positively.
#[test]
fn wrong_current_sign_fails_the_closed_loop() {
    let bench = variant("placement = \"low_side\"", "placement = \"inline\"");
    let name = bench.name();
    let r = current_step_on(bench);
    let failed = match r {
        Err(e) => e,
        Ok(Some(out)) => format!("{:?}", out.failed()),
        Ok(None) => panic!("{name}: a motor without a torque constant"),
    };
    println!("current sign wrong: {failed}");
    assert!(failed != "[]", "{name}: the step passed");
}

/// The amplifier gain 10 % high and 10 % low: the image's currents are read 10 % off and
/// the step misses verify's criteria.
#[test]
fn current_gain_ten_percent_off_fails_the_step() {
    for gain in ["5.698", "4.662"] {
        let bench = variant("amplifier_gain = 5.18", &format!("amplifier_gain = {gain}"));
        let name = bench.name();
        let out = current_step_on(bench)
            .unwrap_or_else(|e| panic!("{name}: {e}"))
            .expect("a torque constant");
        for c in &out.checks {
            println!("gain {gain}: {}", c.2);
        }
        assert!(!out.failed().is_empty(), "{name}: a 10 % gain error passed");
    }
}

/// The resolver front end's amplitude stated as the full range (1.65 V) where the
/// hardware gives 0.66 V: the design divides the trig-identity gains by the envelope
/// alone (0.927), so the observer would run at 0.4 of its loop gain (ω_n and ζ at
/// √0.4 = 0.63 of the designed, thesis A (4.10)). The image measures the signal at
/// start-up and refuses: fault 19, the outputs never on. By hand the measured signal is
/// 0.66/1.65·cos(π·40 kHz·3.059 µs) = 0.4·0.9270 = 0.3708 against the designed 0.9270:
/// ratio 0.4, below 0.64.
#[test]
fn resolver_amplitude_stated_as_full_range_is_refused() {
    let bench = variant("resolver_amplitude = \"0.66 V\"", "resolver_amplitude = \"1.65 V\"");
    let name = bench.name();
    let mut rig = Rig::new(bench).unwrap_or_else(|e| panic!("{name}: {e}"));
    let r = rig.boot(BOOT_LIMIT_S);
    let (seen, designed) = crate::boot::resolver_signal(&rig);
    println!(
        "{name}, resolver_amplitude = \"1.65 V\": the observer sees {seen:.4} of full scale, its gains are designed for {designed:.4}; boot: {:?}",
        r.as_ref()
            .map_err(|e| e.lines().next().unwrap_or("").chars().take(120).collect::<String>())
    );
    assert!((seen - 0.3708).abs() < 1e-3, "{name}: {seen}");
    assert!((designed - 0.9270).abs() < 1e-3, "{name}: {designed}");
    assert!(r.is_err(), "{name}: it booted");
    assert_eq!(rig.fault_cause().as_deref(), Some("19 (resolver signal)"), "{name}");
    assert!(!rig.machine.soc().tim1.moe(), "{name}: outputs on");
}
