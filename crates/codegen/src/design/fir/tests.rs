//! Tests of the whole design against published and hand-computed figures.

use super::quantise::quantise;
use super::response::{Grid, amplitude, q15_to_f64};
use super::search::design_weighted;
use super::validate::{Spec, validate};
use super::*;
use proptest::prelude::*;

/// The firmware's FMAC model on a window of input samples, newest last, 0 dB, CLIPEN.
fn fmac(taps: &[i16], window: &[i16]) -> i16 {
    motor_control::fir::output(taps, window.iter().rev(), 0, true)
}

/// Thesis A §6.2: f_s = 20 kHz, F_pass = 100 Hz, D_pass = 0.001, stop from 2 kHz, order 20.
fn thesis() -> FirRequest {
    FirRequest {
        sample_rate_hz: 20e3,
        pass_edge_hz: 100.0,
        stop_edge_hz: 2e3,
        pass_ripple: 0.001,
        length: FirLength::Order(20),
    }
}

fn sum_q15(q: &[i16]) -> i32 {
    q.iter().map(|&t| i32::from(t)).sum()
}

fn symmetric<T: PartialEq>(v: &[T]) -> bool {
    v.iter().eq(v.iter().rev())
}

#[test]
fn thesis_filter() {
    let d = design_fir(&thesis()).unwrap();
    // Order 20 ⇒ 21 taps, 2·21 + 1 = 43 FMAC words.
    assert_eq!(d.order, 20);
    assert_eq!(d.taps.len(), 21);
    assert_eq!(d.taps_q15.len(), 21);
    assert_eq!(d.fmac_memory_words, 43);
    assert!(symmetric(&d.taps_q15) && symmetric(&d.taps));
    assert_eq!(sum_q15(&d.taps_q15), 32768);
    assert!((d.taps.iter().sum::<f64>() - 1.0).abs() <= 4.0 * f64::EPSILON);
    // Thesis: "a delay of 0.5 ms, i.e. 10 sampling periods".
    assert_eq!(d.group_delay_samples, 10.0);
    assert!((d.group_delay_s - 0.5e-3).abs() < 1e-15);
    assert!(d.pass_ripple_quantised <= 0.001 && d.pass_ripple_design <= 0.001);
    // Something is attenuated at 2 kHz.
    assert!(magnitude(&q15_to_f64(&d.taps_q15), 2e3, 20e3) < 1.0);
    assert!(d.stop_attenuation_db_quantised > 0.0);
    // Independent reference: scipy.signal.remez(21, [0, 100, 2000, 10000], [1, 0], weight=[1, w],
    // fs=20000, grid_density=64), normalised to Σ = 1, with w bisected until max||H| − 1| over
    // [0, 100 Hz] = 0.001 (w = 0.01234), measured on a 200 000-point freqz grid: 27.84 dB.
    // Our DC-constrained design, after Q1.15 rounding, must land within 0.5 dB of it.
    assert!(
        (d.stop_attenuation_db_quantised - 27.84).abs() < 0.5,
        "{} dB vs 27.84 dB (scipy remez)",
        d.stop_attenuation_db_quantised
    );
    // Kaiser's fit, N = 20, Δf = (2000 − 100)/20000 = 0.095:
    //   −10·log10(δp·δs) = 14.6·0.095·20 + 13 = 40.74 dB ⇒ δs = 10^(−4.074)/0.001 = 0.0843 ⇒ 21.5 dB,
    // pessimistic for so narrow a pass band; the design must not be worse than it.
    assert!(d.stop_attenuation_db_quantised > 21.5);
}

#[test]
fn magnitude_by_hand() {
    // Two-tap average [½, ½]: |H(f)| = |cos(πf/f_s)|; at f_s/4: cos(π/4) = 0.7071.
    let h = [0.5, 0.5];
    assert!((magnitude(&h, 0.0, 1.0) - 1.0).abs() < 1e-15);
    assert!((magnitude(&h, 0.25, 1.0) - 0.5f64.sqrt()).abs() < 1e-15);
    assert!(magnitude(&h, 0.5, 1.0).abs() < 1e-15);
    // Delay does not change magnitude: [0, 0, 1] has |H| = 1 everywhere.
    assert!((magnitude(&[0.0, 0.0, 1.0], 0.123, 1.0) - 1.0).abs() < 1e-15);
    // amplitude() agrees with magnitude() on symmetric taps of both parities.
    let spec = Spec {
        fs: 1.0,
        pass_hz: 0.1,
        stop_hz: 0.2,
        fp: 0.1,
        fst: 0.2,
        ripple: 0.01,
    };
    for taps in [vec![0.1, 0.3, 0.3, 0.1, 0.2], vec![0.1, -0.2, 0.6, 0.6, -0.2, 0.1]] {
        let t: Vec<f64> = taps.iter().zip(taps.iter().rev()).map(|(a, b)| 0.5 * (a + b)).collect();
        let grid = Grid::new(&spec, t.len());
        for (i, &p) in grid.stop.iter().enumerate().step_by(37) {
            let f = 0.2 + 0.3 * i as f64 / (grid.stop.len() - 1) as f64;
            assert!((amplitude(&t, p).abs() - magnitude(&t, f, 1.0)).abs() < 1e-12);
        }
    }
}

#[test]
fn minimum_order_meets_attenuation_and_one_less_does_not() {
    let req = FirRequest {
        length: FirLength::StopAttenuationDb(40.0),
        ..thesis()
    };
    let d = design_fir(&req).unwrap();
    assert!(
        d.stop_attenuation_db_quantised >= 40.0,
        "{}",
        d.stop_attenuation_db_quantised
    );
    assert!(d.pass_ripple_quantised <= 0.001);
    assert_eq!(sum_q15(&d.taps_q15), 32768);
    assert!(symmetric(&d.taps_q15));
    // Weight by hand: δs = 10^(−40/20) = 0.01, w = 0.001/0.01 = 0.1.
    assert!((d.stop_weight - 0.1).abs() < 1e-12);
    // The same weight one order lower misses the ripple or the attenuation.
    let spec = validate(&req).unwrap();
    assert!(
        design_weighted(&spec, d.order - 1, d.stop_weight, 40.0).is_none(),
        "order {} also meets it",
        d.order - 1
    );
    // Kaiser: −10·log10(0.001·0.01) = 50 dB ⇒ N ≈ (50 − 13)/(14.6·0.095) = 37/1.387 = 26.7.
    assert!((20..=34).contains(&d.order), "order {}", d.order);
}

#[test]
fn fixed_order_beats_the_thesis_order_by_attenuation_mode() {
    // Designing at order 20 reaches some attenuation A20; asking for A20 − 0.5 dB needs at most order 20.
    let d20 = design_fir(&thesis()).unwrap();
    let req = FirRequest {
        length: FirLength::StopAttenuationDb(d20.stop_attenuation_db_quantised - 0.5),
        ..thesis()
    };
    let d = design_fir(&req).unwrap();
    assert!(d.order <= 20, "order {}", d.order);
}

#[test]
fn fmac_dc_gain_is_one() {
    let d = design_fir(&thesis()).unwrap();
    let n = d.taps_q15.len();
    // v a multiple of 2^8: every product b·v is a multiple of 2^8, so nothing is truncated and
    // acc = Σ b·v/2^8 = 32768·v/2^8 = 128·v ⇒ out = v exactly.
    for v in [-32768i16, -16384, -256, 0, 256, 1024, 16384, 32512] {
        assert_eq!(fmac(&d.taps_q15, &vec![v; n]), v, "v = {v}");
    }
    // Any v: out ∈ [v − 1, v] (truncation bound 1.16 LSB for N = 21, and out is an integer ≤ v).
    for v in [-32767i16, -12345, -1, 1, 1000, 12345, 32767] {
        let y = fmac(&d.taps_q15, &vec![v; n]);
        assert!(y == v || y == v - 1, "{v} → {y}");
    }
}

#[test]
fn fmac_impulse_returns_the_taps() {
    let d = design_fir(&thesis()).unwrap();
    let n = d.taps_q15.len();
    for k in 0..n {
        let mut w = vec![0i16; n];
        // Input k samples old is at index n − 1 − k (newest last).
        w[n - 1 - k] = i16::MIN; // −1.0: b·(−2^15) >> 8 = −b·2^7 exactly, >> 7 = −b.
        assert_eq!(i32::from(fmac(&d.taps_q15, &w)), -i32::from(d.taps_q15[k]));
        w[n - 1 - k] = 16384; // 0.5: b·2^14 >> 8 = b·2^6, >> 7 = ⌊b/2⌋.
        assert_eq!(i32::from(fmac(&d.taps_q15, &w)), i32::from(d.taps_q15[k]).div_euclid(2));
    }
}

#[test]
fn quantiser_keeps_symmetry_and_sum() {
    // 5 equal taps of 0.2: 6553.6 rounds to 6554, Σ = 32770, deficit −2 ⇒ one pair −1 each
    // (residual −0.4 everywhere; ties resolved deterministically).
    let q = quantise(&[0.2; 5]).unwrap();
    assert_eq!(sum_q15(&q), 32768);
    assert!(symmetric(&q));
    // Odd deficit goes to the centre: [0.25, 0.5, 0.25] + rounding noise.
    let q = quantise(&[0.25 + 1e-6, 0.5 - 2e-6, 0.25 + 1e-6]).unwrap();
    assert_eq!(q, vec![8192, 16384, 8192]);
    // A centre tap of 1.0 does not fit i16.
    assert!(quantise(&[0.0, 1.0, 0.0]).is_err());
}

#[test]
fn errors_name_their_key() {
    let key = |r: FirRequest| design_fir(&r).unwrap_err().key();
    // Edges out of order.
    assert_eq!(
        key(FirRequest {
            stop_edge_hz: 50.0,
            ..thesis()
        }),
        "stop_edge"
    );
    assert_eq!(
        key(FirRequest {
            stop_edge_hz: 100.0,
            ..thesis()
        }),
        "stop_edge"
    );
    // Beyond Nyquist.
    assert_eq!(
        key(FirRequest {
            stop_edge_hz: 12e3,
            ..thesis()
        }),
        "stop_edge"
    );
    assert_eq!(
        key(FirRequest {
            stop_edge_hz: 10e3,
            ..thesis()
        }),
        "stop_edge"
    );
    assert_eq!(
        key(FirRequest {
            pass_edge_hz: 11e3,
            stop_edge_hz: 12e3,
            ..thesis()
        }),
        "pass_edge"
    );
    // 128+ taps, and too low an order.
    assert_eq!(
        key(FirRequest {
            length: FirLength::Order(127),
            ..thesis()
        }),
        "order"
    );
    assert_eq!(
        key(FirRequest {
            length: FirLength::Order(usize::MAX),
            ..thesis()
        }),
        "order"
    );
    assert_eq!(
        key(FirRequest {
            length: FirLength::Order(1),
            ..thesis()
        }),
        "order"
    );
    // Infeasible attenuation.
    assert_eq!(
        key(FirRequest {
            length: FirLength::StopAttenuationDb(200.0),
            ..thesis()
        }),
        "stop_attenuation"
    );
    // NaN and non-positive inputs.
    assert_eq!(
        key(FirRequest {
            sample_rate_hz: f64::NAN,
            ..thesis()
        }),
        "sample_rate"
    );
    assert_eq!(
        key(FirRequest {
            sample_rate_hz: -20e3,
            ..thesis()
        }),
        "sample_rate"
    );
    assert_eq!(
        key(FirRequest {
            pass_edge_hz: f64::NAN,
            ..thesis()
        }),
        "pass_edge"
    );
    assert_eq!(
        key(FirRequest {
            pass_edge_hz: 0.0,
            ..thesis()
        }),
        "pass_edge"
    );
    assert_eq!(
        key(FirRequest {
            stop_edge_hz: f64::INFINITY,
            ..thesis()
        }),
        "stop_edge"
    );
    assert_eq!(
        key(FirRequest {
            pass_ripple: f64::NAN,
            ..thesis()
        }),
        "pass_ripple"
    );
    assert_eq!(
        key(FirRequest {
            pass_ripple: 0.5,
            ..thesis()
        }),
        "pass_ripple"
    );
    assert_eq!(
        key(FirRequest {
            pass_ripple: 0.0,
            ..thesis()
        }),
        "pass_ripple"
    );
    assert_eq!(
        key(FirRequest {
            length: FirLength::StopAttenuationDb(f64::NAN),
            ..thesis()
        }),
        "stop_attenuation"
    );
    assert_eq!(
        key(FirRequest {
            length: FirLength::StopAttenuationDb(0.0),
            ..thesis()
        }),
        "stop_attenuation"
    );
}

#[test]
fn error_messages_say_what_is_accepted() {
    let msg = |r: FirRequest| design_fir(&r).unwrap_err().to_string();
    assert_eq!(
        msg(FirRequest {
            stop_edge_hz: 12e3,
            ..thesis()
        }),
        "stop_edge 12 kHz is at or beyond the Nyquist frequency 10 kHz; accepted: pass_edge < stop_edge < f_s/2"
    );
    let m = msg(FirRequest {
        length: FirLength::Order(127),
        ..thesis()
    });
    assert!(
        m.contains("128 taps") && m.contains("127") && m.contains("2N + 1 ≤ 256"),
        "{m}"
    );
    // Transition 100 → 150 Hz: Kaiser at 126 taps gives 14.6·0.0025·126 + 13 = 17.6 dB for
    // −10·log10(δp·δs), nowhere near the 30 + 80 = 110 dB that 0.001 ripple and 80 dB need.
    let m = msg(FirRequest {
        stop_edge_hz: 150.0,
        length: FirLength::StopAttenuationDb(80.0),
        ..thesis()
    });
    assert!(m.contains("best at 127 taps"), "{m}");
    let m = msg(FirRequest {
        length: FirLength::StopAttenuationDb(200.0),
        ..thesis()
    });
    assert!(m.contains("≤ 100 dB"), "{m}");
    // Thesis edges at order 126: Kaiser 14.6·0.095·126 + 13 = 187.8 dB > 120 dB; the highest
    // order allowed is ⌊(120 − 13)/(14.6·0.095)⌋ = ⌊77.15⌋ = 77.
    let m = msg(FirRequest {
        length: FirLength::Order(126),
        ..thesis()
    });
    assert!(m.contains("order ≤ 77"), "{m}");
    // Every message splits into problem and accepted values.
    for r in [
        FirRequest {
            stop_edge_hz: 50.0,
            ..thesis()
        },
        FirRequest {
            pass_ripple: 2.0,
            ..thesis()
        },
        FirRequest {
            length: FirLength::Order(0),
            ..thesis()
        },
        FirRequest {
            pass_edge_hz: -1.0,
            ..thesis()
        },
    ] {
        assert!(msg(r).contains("; accepted: "));
    }
}

#[test]
fn infeasible_ripple_reports_the_smallest_reached() {
    // 1e−9 is far below one Q1.15 LSB (3e−5) of quantisation error at 100 Hz.
    let e = design_fir(&FirRequest {
        pass_ripple: 1e-9,
        ..thesis()
    })
    .unwrap_err();
    assert_eq!(e.key(), "pass_ripple");
    match e {
        FirError::RippleInfeasible {
            best: Some(b),
            order: 20,
            ..
        } => assert!(b > 1e-9 && b < 1e-3, "{b}"),
        other => panic!("{other:?}"),
    }
}

#[test]
fn odd_orders_and_the_smallest_orders_work() {
    for order in [2, 3, 4, 5, 21] {
        let d = design_fir(&FirRequest {
            pass_ripple: 0.01,
            stop_edge_hz: 4e3,
            length: FirLength::Order(order),
            ..thesis()
        })
        .unwrap_or_else(|e| panic!("order {order}: {e}"));
        assert_eq!(d.taps_q15.len(), order + 1);
        assert_eq!(sum_q15(&d.taps_q15), 32768);
        assert!(symmetric(&d.taps_q15));
        assert!(d.pass_ripple_quantised <= 0.01);
        assert_eq!(d.group_delay_samples, order as f64 / 2.0);
    }
}

#[test]
fn largest_fmac_filter() {
    // Transition 100 → 400 Hz (Δf = 0.015): Kaiser at order 126 gives 14.6·0.015·126 + 13 = 40.6 dB.
    let d = design_fir(&FirRequest {
        stop_edge_hz: 400.0,
        length: FirLength::Order(126),
        ..thesis()
    })
    .unwrap();
    assert_eq!(d.taps_q15.len(), 127);
    assert_eq!(d.fmac_memory_words, 255);
    assert_eq!(sum_q15(&d.taps_q15), 32768);
    assert!(d.pass_ripple_quantised <= 0.001);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(40))]

    /// Random plausible requests: a clean error, or symmetric Q1.15 taps with Σ = 32768 within the ripple.
    #[test]
    fn designs_are_symmetric_unity_gain_and_within_ripple(
        fs in 1e3f64..100e3,
        pass_frac in 0.001f64..0.3,
        gap_frac in 0.005f64..0.5,
        ripple in 1e-5f64..0.3,
        order in 0usize..140,
    ) {
        let pass = pass_frac * fs;
        let stop = pass + gap_frac * (0.5 * fs - pass);
        let req = FirRequest { sample_rate_hz: fs, pass_edge_hz: pass, stop_edge_hz: stop, pass_ripple: ripple, length: FirLength::Order(order) };
        match design_fir(&req) {
            Ok(d) => {
                prop_assert_eq!(d.order, order);
                prop_assert_eq!(d.taps_q15.len(), order + 1);
                prop_assert_eq!(sum_q15(&d.taps_q15), 32768);
                prop_assert!(symmetric(&d.taps_q15));
                prop_assert!(d.pass_ripple_quantised <= ripple);
                prop_assert!(d.stop_attenuation_db_quantised > 0.0);
            }
            Err(e) => {
                let text = e.to_string();
                prop_assert!(text.contains("; accepted: "), "{}", text);
                if !(2..=126).contains(&order) {
                    prop_assert_eq!(e.key(), "order");
                }
            }
        }
    }

    /// Minimum-order mode: the result meets the spec and one order less (same weight) does not.
    #[test]
    fn minimum_order_is_minimal(
        pass_frac in 0.002f64..0.1,
        gap_frac in 0.05f64..0.4,
        ripple in 1e-3f64..0.05,
        att in 20.0f64..60.0,
    ) {
        let fs = 20e3;
        let pass = pass_frac * fs;
        let stop = pass + gap_frac * (0.5 * fs - pass);
        let req = FirRequest { sample_rate_hz: fs, pass_edge_hz: pass, stop_edge_hz: stop, pass_ripple: ripple, length: FirLength::StopAttenuationDb(att) };
        if let Ok(d) = design_fir(&req) {
            prop_assert!(d.stop_attenuation_db_quantised >= att && d.pass_ripple_quantised <= ripple);
            prop_assert_eq!(sum_q15(&d.taps_q15), 32768);
            if d.order > MIN_ORDER {
                let spec = validate(&req).unwrap();
                prop_assert!(design_weighted(&spec, d.order - 1, d.stop_weight, att).is_none());
            }
        }
    }

    /// The FMAC model stays within the derived truncation bound of the exact convolution.
    #[test]
    fn fmac_matches_exact_convolution(
        taps in proptest::collection::vec(-4096i16..4096, 1..=127),
        seed in proptest::collection::vec(any::<i16>(), 127),
    ) {
        let n = taps.len();
        let window = &seed[..n];
        // Exact Σ b·x in units of 2^−30 (integers, exact in f64 below 2^53).
        let exact: f64 = taps.iter().zip(window.iter().rev()).map(|(&b, &x)| f64::from(b) * f64::from(x)).sum();
        let exact_lsb = exact / 32768.0; // units of 2^−15
        // |Σ b·x| ≤ 127·4096·32768·2^−30 < 16: may exceed q4.22; only compare when partial sums
        // cannot wrap and the output does not clip (|Σ|b||·1 < 8 and |y| < 1 − 2 LSB).
        let abs_sum: f64 = taps.iter().map(|&b| f64::from(b).abs()).sum::<f64>() / 32768.0;
        prop_assume!(abs_sum < 8.0 && exact_lsb.abs() < 32766.0);
        let y = f64::from(fmac(&taps, window));
        let bound = n as f64 * 255.0 / 32768.0 + 127.0 / 128.0;
        prop_assert!(exact_lsb - y >= 0.0 && exact_lsb - y <= bound, "exact {} out {} bound {}", exact_lsb, y, bound);
    }
}

/// Issue 18: `[fir] pass_edge = "0.001 Hz"` stalled the exchange for minutes; it is
/// refused at pass_edge with the range that works, and the lowest accepted edge designs.
#[test]
fn pass_edge_too_low_for_the_exchange_is_refused_and_its_minimum_designs() {
    let low = FirRequest {
        pass_edge_hz: 0.001,
        ..thesis()
    };
    let e = design_fir(&low).unwrap_err();
    assert_eq!(e.key(), "pass_edge");
    // 1e-6 · 20 kHz = 0.02 Hz.
    assert_eq!(
        e.to_string(),
        "pass_edge 0.001 Hz is below 1e-6·f_s = 0.02 Hz: the Parks–McClellan exchange does not converge on so narrow a pass band; accepted: 0.02 Hz ≤ pass_edge < stop_edge < f_s/2"
    );
    let d = design_fir(&FirRequest {
        pass_edge_hz: 0.02,
        ..thesis()
    })
    .unwrap();
    assert_eq!(d.order, 20);
    assert_eq!(d.taps_q15.iter().map(|&t| i32::from(t)).sum::<i32>(), Q15_ONE);
}

/// Issue 18: `stop_attenuation = "99 dB"` on the thesis-A band edges lies below the Q1.15
/// rounding floor. It is refused with the attenuation that works (the same bound a request
/// just below it is designed with), and the order walk stops at the floor instead of
/// running every order to the FMAC limit: the work is bounded in Parks–McClellan runs
/// (a count, not a time). Kaiser starts the walk at order 45; the floor (≈ 72 dB) is
/// reached near order 50, so the walk ends by order 50 + STALL_ORDERS and the final
/// stop-weight search adds at most MAX_WEIGHT_EVALUATIONS runs.
#[test]
fn attenuation_beyond_the_q15_floor_is_refused_after_a_bounded_walk() {
    use super::remez::RUNS;
    use super::search::STALL_ORDERS;
    RUNS.with(|r| r.set(0));
    let err = design_fir(&FirRequest {
        length: FirLength::StopAttenuationDb(99.0),
        ..thesis()
    })
    .unwrap_err();
    let runs = RUNS.with(|r| r.get());
    assert_eq!(err.key(), "stop_attenuation");
    let FirError::AttenuationFloor {
        order,
        last_order,
        best_db: Some(best),
        ..
    } = err
    else {
        panic!("expected the Q1.15 floor refusal, got {err:?}")
    };
    assert_eq!(last_order, order + STALL_ORDERS);
    assert!(last_order < FMAC_MAX_TAPS - 1, "walked to order {last_order}");
    assert!(best > 60.0 && best < 90.0, "best {best} dB");
    // Walk from the Kaiser start plus the weight search at the best order: far below the
    // ~80 orders + 24 runs at 127 taps of an unbounded walk.
    assert!(
        runs <= (last_order - 45 + 1) + MAX_WEIGHT_EVALUATIONS + 1,
        "{runs} Parks–McClellan runs"
    );
    let msg = err_text(99.0);
    assert!(
        msg.contains(&format!(
            "accepted: stop_attenuation ≤ {:.1} dB",
            (best * 10.0).floor() / 10.0
        )),
        "{msg}"
    );
    // The bound it names is designable: 3 dB below it, the minimum-order search succeeds.
    let d = design_fir(&FirRequest {
        length: FirLength::StopAttenuationDb(best - 3.0),
        ..thesis()
    })
    .unwrap();
    assert!(d.stop_attenuation_db_quantised >= best - 3.0);
}

fn err_text(db: f64) -> String {
    design_fir(&FirRequest {
        length: FirLength::StopAttenuationDb(db),
        ..thesis()
    })
    .unwrap_err()
    .to_string()
}

/// Issue 31: a narrow pass band, a stop edge near f_s/2 and a 99 dB target ran for more
/// than a minute in a release build before any answer; so did fixed orders on wide
/// transition bands (pass 100 Hz, stop 9 900 Hz, order 14), inside a single exchange:
/// nalgebra's Schur decomposition of the extrema search iterated without a bound
/// (vendor/pm-remez now bounds it). Every one answers — a design or a refusal naming the
/// key — and each exchange is bounded in work (at most 100 iterations, each with bounded
/// QR sweeps), so the whole search is bounded by its run count: the walk from Kaiser's
/// start, at most [`FMAC_MAX_TAPS`] orders, plus [`MAX_WEIGHT_EVALUATIONS`].
#[test]
fn near_nyquist_stop_edges_answer_in_bounded_work() {
    use super::remez::RUNS;
    let cases = [
        (0.02, 9_999.0, FirLength::StopAttenuationDb(99.0)),
        (100.0, 9_900.0, FirLength::Order(14)),
        (0.02, 9_980.0, FirLength::Order(8)),
        (2.0, 9_900.0, FirLength::Order(12)),
        (0.02, 9_999.0, FirLength::StopAttenuationDb(60.0)),
    ];
    for (pass, stop, length) in cases {
        RUNS.with(|r| r.set(0));
        let t = std::time::Instant::now();
        let r = design_fir(&FirRequest {
            sample_rate_hz: 20e3,
            pass_edge_hz: pass,
            stop_edge_hz: stop,
            pass_ripple: 0.001,
            length,
        });
        let runs = RUNS.with(|r| r.get());
        eprintln!(
            "pass {pass} Hz, stop {stop} Hz, {length:?}: {:?} in {:?}, {runs} Parks–McClellan runs",
            r.as_ref().map(|d| d.order).map_err(ToString::to_string),
            t.elapsed()
        );
        match &r {
            Ok(d) => {
                assert_eq!(d.taps_q15.iter().map(|&t| i32::from(t)).sum::<i32>(), Q15_ONE);
                if let FirLength::StopAttenuationDb(a) = length {
                    assert!(d.stop_attenuation_db_quantised >= a, "{d:?}");
                }
            }
            Err(e) => assert!(
                ["order", "stop_attenuation", "stop_edge", "pass_edge", "pass_ripple"].contains(&e.key()),
                "{e}"
            ),
        }
        assert!(runs <= FMAC_MAX_TAPS + MAX_WEIGHT_EVALUATIONS + 1, "{runs} runs");
    }
}
