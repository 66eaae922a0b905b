//! The emulator's former blind spots: single defects of the board layer that the image
//! once got past the emulator with, each reintroduced at the bus ([`Patches`]) and
//! caught by the rule that names it — gate outputs judged at the pins through their GPIO
//! mode and alternate function, complementary outputs with dead time into the board's
//! gate driver, break pulses of any length, a core lockup actually triggered, OSSI/OSSR,
//! the ADC's sampling against each input's source resistance, NVIC priorities with
//! BASEPRI, the factory option bytes. Each runs on every board (with the first motor
//! that fits it); where a board's hardware makes a defect harmless, the test says so and
//! checks it stays harmless there.

use crate::BOOT_LIMIT_S;
use motor_emulator::rig::{Bench, OPTR_FACTORY, Rig, benches, first_enabled_period};
use motor_emulator::{HARD_FAULT, Patches, Pulse, Stop, UNITS_PER_S, Violation};

/// One bench per board: the first motor that fits it.
fn one_per_board() -> Vec<Bench> {
    let mut out: Vec<Bench> = Vec::new();
    for (motor, board) in benches() {
        if !out.iter().any(|b| b.board.stem == board) {
            out.push(Bench::new(&motor, &board).unwrap());
        }
    }
    out
}

/// Boots with `patches` and runs until `periods` carrier periods after the first enabled
/// one (zero torque; at most [`BOOT_LIMIT_S`] without one); the violation that stopped
/// it, if any.
fn run_patched(bench: Bench, patches: Patches, periods: f64) -> (Rig, Option<Violation>) {
    let name = bench.name();
    let mut rig = Rig::new(bench.patched(patches)).unwrap_or_else(|e| panic!("{name}: {e}"));
    let p = rig.pwm_period_s();
    let r = rig.run(
        BOOT_LIMIT_S,
        |_| Some(0.0),
        |m| first_enabled_period(m).is_some_and(|t| m.soc().time_s() >= t + periods * p),
    );
    let v = match r {
        Ok(_) => None,
        Err(Stop::Violation(v)) => Some(v),
        Err(e) => panic!("{name}: {e}"),
    };
    (rig, v)
}

/// Asserts the run stopped on a rule whose text contains every one of `words`.
fn assert_rule(name: &str, v: Option<Violation>, words: &[&str]) {
    let v = v.unwrap_or_else(|| panic!("{name}: the defect passed the emulator"));
    println!("{name}: {v}");
    for w in words {
        assert!(v.rule.contains(w) || v.register.contains(w), "{name}: {w:?} not in {v}");
    }
}

/// Dead time written as 0. On the reference board each switch has its own isolated
/// driver, nothing else separates a leg's switches: shoot-through. The NUCLEO's L6398s
/// insert their own 320 ns and interlock the inputs, which covers their switches'
/// turn-off: harmless there, and the emulated board shows it harmless.
#[test]
fn dead_time_zero_shoots_through() {
    let patches = Patches {
        dead_time_zero: true,
        ..Patches::default()
    };
    for bench in one_per_board() {
        let name = format!("{} (dead time 0)", bench.name());
        let own = bench.hardware.driver.dead_time_s;
        let (_, v) = run_patched(bench, patches.clone(), 20.0);
        if own > 0.0 {
            assert!(v.is_none(), "{name}: the driver's own dead time should cover it: {v:?}");
            println!("{name}: harmless, the driver inserts {:.0} ns itself", own * 1e9);
        } else {
            assert_rule(&name, v, &["shoot-through"]);
        }
    }
}

/// The u low-side gate pin given AF0 instead of TIM1_CH1N: the pin is not driven, the
/// driver input is held only by its own bias once the bridge runs.
#[test]
fn wrong_alternate_function_leaves_a_gate_floating() {
    for bench in one_per_board() {
        let name = format!("{} (wrong AF)", bench.name());
        let patches = Patches {
            low_side_wrong_af: true,
            ..Patches::default()
        };
        let (_, v) = run_patched(bench, patches, 5.0);
        assert_rule(&name, v, &["gate pin left floating into a driver input", "AF0"]);
    }
}

/// OSSI/OSSR dropped from the BDTR write: with MOE = 0 TIM1 leaves its outputs in Hi-Z
/// instead of driving the idle levels (RM0440 output control table).
#[test]
fn ossi_dropped_leaves_the_gates_floating() {
    for bench in one_per_board() {
        let name = format!("{} (OSSI/OSSR = 0)", bench.name());
        let patches = Patches {
            drop_ossi_ossr: true,
            ..Patches::default()
        };
        let (_, v) = run_patched(bench, patches, 5.0);
        assert_rule(&name, v, &["gate pin left floating into a driver input", "OSSI = 0"]);
    }
}

/// Every slow channel sampled for 2.5 cycles: its source does not settle (DS12288
/// Table 67).
#[test]
fn slow_channels_at_2_5_cycles_do_not_settle() {
    for bench in one_per_board() {
        let name = format!("{} (slow channels 2.5 cycles)", bench.name());
        let patches = Patches {
            slow_channels_2_5_cycles: true,
            ..Patches::default()
        };
        let (_, v) = run_patched(bench, patches, 5.0);
        assert_rule(&name, v, &["ADC sampling does not settle", "slow channel", "Table 67"]);
    }
}

/// Issue 26 item 5: the injected conversions started by a read-modify-write of ADC_CR
/// that writes the ADEN reading 1 again next to JADSTART (the image's former
/// `modify(|_, w| w.jadstart().set_bit())`): named as a set-only bit re-written. The
/// image itself writes JADSTART alone (every other test boots it).
#[test]
fn aden_rewritten_with_jadstart_is_named() {
    for bench in one_per_board() {
        let name = format!("{} (ADEN with JADSTART)", bench.name());
        let patches = Patches {
            jadstart_rewrites_aden: true,
            ..Patches::default()
        };
        let (_, v) = run_patched(bench, patches, 5.0);
        assert_rule(&name, v, &["set-only bits that already read 1", "ADC1_CR", "§21.7.3"]);
    }
}

/// The control interrupt's priority raised to 0x80 (a byte write to NVIC_IPR) and
/// BASEPRI left at 0x80: the interrupt never runs.
#[test]
fn basepri_masking_the_control_interrupt_is_named() {
    for bench in one_per_board() {
        let name = format!("{} (BASEPRI)", bench.name());
        let patches = Patches {
            basepri_masks_control: true,
            ..Patches::default()
        };
        let (_, v) = run_patched(bench, patches, 5.0);
        assert_rule(&name, v, &["masked by BASEPRI = 0x80", "priority 0x80"]);
    }
}

/// The factory option bytes (nSWBOOT0 = 1): the image must halt with the outputs off —
/// it does (fault record: bring-up) — and with its check removed (FLASH_OPTR read as
/// programmed) it enables the outputs, which the emulated board refuses: PB8 carries an
/// idle-high CAN RXD.
#[test]
fn factory_option_bytes_keep_the_outputs_off() {
    for bench in one_per_board() {
        let name = bench.name();
        let factory = Bench {
            optr: OPTR_FACTORY,
            ..bench.clone()
        };
        let (rig, v) = run_patched(factory.clone(), Patches::default(), 5.0);
        assert!(v.is_none(), "{name}: {v:?}");
        assert!(
            !rig.machine
                .soc()
                .notes
                .iter()
                .any(|n| matches!(n, motor_emulator::Note::MainOutput(_, true))),
            "{name}: outputs enabled with the factory option bytes"
        );
        let cause = rig.fault_cause().unwrap_or_default();
        assert!(cause.contains("bring-up"), "{name}: fault record {cause:?}");
        println!("{name}: factory option bytes → halted, fault record {cause}");
        let patches = Patches {
            optr_reads_programmed: true,
            ..Patches::default()
        };
        let (_, v) = run_patched(factory, patches, 5.0);
        assert_rule(
            &format!("{name} (option-byte check removed)"),
            v,
            &["nSWBOOT0 = 1", "bootloader"],
        );
    }
}

/// A core lockup while the bridge switches: a second fault at the HardFault handler's
/// first instruction, before it clears MOE. With SYSCFG_CFGR2.CLL the lockup breaks
/// TIM1 (outputs off); without it the bridge switches on, named.
#[test]
fn lockup_breaks_tim1_only_with_cll() {
    for bench in one_per_board() {
        for cll in [true, false] {
            let name = format!("{} (CLL {})", bench.name(), if cll { "set" } else { "dropped" });
            let patches = Patches {
                drop_cll: !cll,
                ..Patches::default()
            };
            let mut rig = Rig::new(bench.clone().patched(patches)).unwrap();
            rig.boot(BOOT_LIMIT_S).unwrap_or_else(|e| panic!("{name}: {e}"));
            let t = rig.machine.soc().time_s() + 5.0 * rig.pwm_period_s();
            rig.run(t, |_| Some(0.0), |_| false).unwrap();
            rig.machine.inject(HARD_FAULT);
            rig.machine.inject(HARD_FAULT);
            let r = rig.machine.run_until(t + rig.pwm_period_s());
            match (cll, r) {
                (true, Err(Stop::Lockup(_))) => {
                    assert!(
                        !rig.machine.soc().gates_can_switch(),
                        "{name}: a switch on after the lockup"
                    );
                    println!("{name}: lockup → break → outputs off");
                }
                (false, Err(Stop::Violation(v))) => assert_rule(&name, Some(v), &["locked up", "CLL clear"]),
                (_, r) => panic!("{name}: {r:?}"),
            }
        }
    }
}

/// A break pulse of 200 ns right after the control interrupt's first TIM1_SR read: the
/// image reads BIF again before deciding MOE and stays off; with MOE decided from the
/// first read (the defect) it re-enables the bridge the break switched off.
#[test]
fn a_break_pulse_inside_the_interrupt_is_not_missed() {
    for bench in one_per_board() {
        for stale in [false, true] {
            let name = format!("{} ({})", bench.name(), if stale { "stale BIF" } else { "BIF re-read" });
            let patches = Patches {
                stale_bif: stale,
                ..Patches::default()
            };
            let mut rig = Rig::new(bench.clone().patched(patches)).unwrap();
            rig.boot(BOOT_LIMIT_S).unwrap_or_else(|e| panic!("{name}: {e}"));
            let t = rig.machine.soc().time_s() + 3.0 * rig.pwm_period_s();
            rig.run(t, |_| Some(0.0), |_| false).unwrap();
            let soc = rig.machine.soc_mut();
            let now = soc.now;
            soc.pulses.push(Pulse::AfterSrReadInIrq {
                after: now,
                len: (200e-9 * UNITS_PER_S) as u64,
            });
            let r = rig.run(t + 10.0 * rig.pwm_period_s(), |_| Some(0.0), |_| false);
            if stale {
                let Err(Stop::Violation(v)) = r else {
                    panic!("{name}: the short break pulse was missed: {r:?}")
                };
                assert_rule(&name, Some(v), &["MOE set while SR.BIF is latched"]);
            } else {
                r.unwrap_or_else(|e| panic!("{name}: {e}"));
                assert!(
                    !rig.machine.soc().gates_can_switch(),
                    "{name}: outputs on after the break"
                );
                println!("{name}: 200 ns break inside the interrupt → off for good");
            }
        }
    }
}

/// The resolver excitation's peak at the ADC trigger (the image before stop 40: TIM3_CCR1
/// at half its period, `Patches::excitation_peak_at_trigger`) on the NUCLEO +
/// X-NUCLEO-IHM08M1, where SIN and COS are held at different ranks: the emulated
/// excitation (the square wave's fundamental, `Tim3::excitation`) reads them at different
/// envelope gains — by hand cos(π·f_s·t) for a winding held t after the peak, 0.982 and
/// 0.574 at the 1.52 µs and 7.64 µs the emulator measures at 40 kHz — which the boot test
/// (`control_interrupt_instructions_fit_the_period_and_the_budget`) refuses on every pair.
/// The image's own start-up check sees it too, depending on the rotor's angle: here the
/// resolver rests at 0 (COS only), so it measures 0.4·0.5736 = 0.2294 of full scale,
/// below 0.64 of the designed 0.3708 (0.2373): fault 19, the outputs never on. (At 90°,
/// SIN only, it would measure 0.4·0.9818 = 0.3927, 1.06 of the design, and pass.)
#[test]
fn excitation_peak_at_the_trigger_reads_sin_and_cos_at_different_gains() {
    let bench = Bench::new("maxon-ec45-flat-70w", "nucleo-g474re-ihm08m1").unwrap();
    let name = bench.name();
    let patches = Patches {
        excitation_peak_at_trigger: true,
        ..Patches::default()
    };
    let (rig, v) = run_patched(bench, patches, 5.0);
    assert!(v.is_none(), "{name}: {v:?}");
    let soc = rig.machine.soc();
    let [Some((t_sin, e_sin)), Some((t_cos, e_cos))] = soc.resolver_excitation else {
        panic!("{name}: SIN or COS never converted");
    };
    // The windings' hold instants after the trigger: their mean (measured per trigger)
    // ∓ half their distance.
    let (mean, _, _) = soc.resolver_sample_instant.expect("resolver conversions");
    let fs = rig.design.drive.switching_frequency_hz;
    let gain = |t: f64| (std::f64::consts::PI * fs * t).cos();
    let (g_sin, g_cos) = (gain(mean - (t_cos - t_sin) / 2.0), gain(mean + (t_cos - t_sin) / 2.0));
    println!(
        "{name}: excitation peak at the trigger: SIN held {:.3} µs after it at gain {e_sin:.4} (by hand {g_sin:.4}), COS {:.3} µs at {e_cos:.4} (by hand {g_cos:.4})",
        (mean - (t_cos - t_sin) / 2.0) * 1e6,
        (mean + (t_cos - t_sin) / 2.0) * 1e6
    );
    assert!(
        (e_sin.abs() - g_sin).abs() < 0.01 && (e_cos.abs() - g_cos).abs() < 0.01,
        "{name}: envelope gains {e_sin:.4} / {e_cos:.4}, by hand {g_sin:.4} / {g_cos:.4}"
    );
    assert!(
        (e_sin - e_cos).abs() > 0.3,
        "{name}: SIN and COS read at gains {e_sin:.4} and {e_cos:.4}"
    );
    assert_eq!(rig.fault_cause().as_deref(), Some("19 (resolver signal)"), "{name}");
    assert!(!rig.machine.soc().tim1.moe(), "{name}: outputs on");
}
