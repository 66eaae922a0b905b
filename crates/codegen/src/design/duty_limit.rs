//! The largest duty cycle the current sensing leaves, and the voltage it leaves the
//! current loop and the field weakening.
//!
//! **Low-side shunts** carry a phase current only while their leg's low-side switch
//! conducts. With TIM1's centre-aligned carrier (PWM mode 1, RM0440 §28.3.10) a leg's
//! OCxREF is low for `(1 − d)·T_s` centred on the carrier maximum; the complementary
//! output, which turns the low side on, rises one dead time `t_d` after OCxREF falls
//! (RM0440 §28.3.15) and falls with OCxREF. The ADC trigger TRGO2 rises one timer tick
//! before the maximum (`sections::board::control_timing`); rank k of a converter samples
//! from `t_k = t_lat + Σ_{j<k} (t_s,j + 12.5)` ADC cycles to `t_k + t_s,k` after it (RM0440
//! §21.4.12: sampling, then 12.5 cycles of conversion at 12 bits; the held charge no
//! longer depends on the pin once sampling has ended), with the trigger latency t_lat
//! between 0 and 3.125 cycles (DS12288 Table 66, t_LATRINJ): the earliest start
//! (t_lat = 0) is taken for the settling condition, the latest end for the other. A rank that samples a phase
//! current must sample inside that phase's low-side pulse, and no earlier than the
//! stage's settling time `t_set` (`current_sensing.settling_time`) after the low side
//! switched on — as ST's motor-control SDK waits `TW_AFTER = t_d + max(T_noise,
//! T_rise)` after an edge and ends the sampling `TW_BEFORE` before the next one.
//! Measured from the carrier maximum the pulse is `[−(1 − d)·T_s/2 + t_d, (1 − d)·T_s/2]`,
//! so every current rank needs
//!
//! ```text
//! (1 − d)·T_s/2 ≥ t_d + t_set − (t_k − t_tick)       (settled before sampling starts)
//! (1 − d)·T_s/2 ≥ t_k + t_s,k − t_tick                (sampling ends before the edge)
//! ```
//!
//! and `d_max = 1 − 2·h/T_s` with `h` the largest right-hand side, rounded up to whole
//! timer ticks and `d_max` down to a whole compare value (`d_max·ARR` an integer, so the
//! firmware's `round(d·ARR)` never exceeds it). The factor 2 is the centre-aligned
//! carrier's: the low-side pulse is split evenly about the maximum.
//!
//! **In-line sensing** (Hall sensors, in-line shunts) measures the phase current whatever
//! the switches do: no limit from the sampling. The reference boards' isolated drivers
//! (1EDI20N12AF) state no bootstrap supply that a 100 % duty would starve, so only the
//! dead time (below) limits it.
//!
//! **Dead intervals that leave their period.** TIM1 turns a switch on `t_d` after its
//! OCxREF edge (RM0440 §28.3.15, dead-time insertion; `t_d` in timer ticks as the image
//! programs TIM1_BDTR.DTG, §28.6.20). A leg's OCxREF is high while CNT < CCR: high for
//! `2·CCR` ticks about the carrier minimum, low for `2·(ARR − CCR)` about the maximum,
//! so one period, update to update, holds two edges, each followed by a dead interval of
//! `t_d` in which both switches are off and the phase follows its current's sign through
//! a diode (`design::dead_time`). With the update at the underflow (the in-line boards,
//! `sections::board::control_timing`) the high pulse spans the update: the falling
//! edge's interval ends inside the low pulse if `2·(ARR − CCR) ≥ t_d`, and the rising
//! edge's ends before the update if `CCR ≥ t_d`. With the update at the maximum (the
//! low-side boards) the roles swap: the low pulse spans the update, so `ARR − CCR ≥ t_d`
//! and `2·CCR ≥ t_d`. Where both hold, every period holds exactly its own two dead
//! intervals: its volt-seconds are its compare value's less a dead-time error set by
//! the current's sign alone — the same in every period at a given current, a slow
//! disturbance the current loop's integrator takes out (the emulated bridge splits each
//! dead interval evenly, so there such a period gives exactly its compare value's
//! volt-seconds). A compare value within `t_d` of the rail at the update moves its
//! edge's dead interval across the update: part of this period's error lands in the
//! next one, by how much depends on the neighbouring compare values, and within
//! `t_d/2` of either rail the dead time swallows the pulse altogether ("if the delay is
//! greater than the width of the active output … the corresponding pulse is not
//! generated", §28.3.15). Keeping every compare value in `[t_d, ARR − t_d]` satisfies
//! all four conditions whichever extreme the update is at, so
//!
//! ```text
//! p = t_d   compare units,      d_max ≤ (ARR − p)/ARR
//! ```
//!
//! and with the modulator's symmetry about 1/2 (`d ≥ 1 − d_max`) every compare value
//! lies in `[p, ARR − p]`, both conditions hold. In-line sensing has no other limit, so
//! there `d_max = 1 − p/ARR` (0.98000 for 500 ns, 85 ticks, at 20 kHz).
//!
//! Measured with a torque step at 20 000 rpm on fischer-ti085 (15 carrier periods per
//! electrical turn, so a leg leaves a rail within a few periods):
//! - stop 42, d_max = 1: the emulated bridge (which swallows such pulses, as the
//!   hardware does) put the image's i_q 4–6 A below `verify`'s ideal inverter;
//! - stop 43, p = ⌈t_d/2⌉ = 43 (no pulse swallowed, but compare values down to 43 < 85):
//!   torque 0.73–1.68 of the at-speed tolerance off `verify`'s at four carrier phases,
//!   bisected to the rising edge's interval crossing the update (a bottom leg went
//!   45 → 115 → 538 ticks in three periods);
//! - stop 44, p = t_d = 85: 0.41–0.76 at the same four phases (`motor-emulator`'s
//!   `duty_limit` tests).
//!
//! A low-side shunt's window usually needs more: its settling condition alone asks
//! `h ≥ t_d + t_set − (t_k − t_tick)` (the NUCLEO: h = 1 515 ns against t_d = 500 ns);
//! the code takes the smaller limit all the same. The dead time is TIM1's; a gate
//! driver inserting a longer one of its own would need the longer (the NUCLEO's L6398
//! inserts 320 ns under TIM1's 500 ns; no in-line board in `boards/` has one).
//!
//! **Usable voltage.** The modulator (thesis A (3.7), (3.8), `motor_control::modulation`)
//! keeps the duties symmetric about 1/2, so `d ≤ d_max` also bounds the low duties at
//! `1 − d_max`: the phase peak `max_φ (a·cos φ − b·cos 3φ)` (b = U_dc/(6√3), the fixed
//! third-harmonic amplitude of (3.7)) may reach `(d_max − 1/2)·U_dc`. The largest
//! voltage amplitude `a` that keeps it there, over the linear range's `U_dc/√3`, is the
//! usable fraction ([`usable_voltage_fraction`]); the current loop's voltage limit and
//! the field weakening's V_max (thesis B (2.50), (2.55)) are that fraction of U_dc/√3.

use serde::Serialize;

/// One rank that samples a phase current, its sampling phase after the trigger.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CurrentRank {
    /// Converter (1 or 2).
    pub adc: u8,
    /// Rank, 1-based.
    pub rank: u8,
    /// Phase 0 = u, 1 = v, 2 = w.
    pub phase: u8,
    /// Earliest sampling start after the trigger \[s\] (no trigger latency).
    pub start_s: f64,
    /// Latest sampling end after the trigger \[s\] (the longest trigger latency).
    pub end_s: f64,
}

/// Which condition sets the maximum duty.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum DutyBound {
    /// No limit from the sampling (in-line sensing): the dead time, p = t_d (module
    /// documentation, "Dead intervals that leave their period").
    DeadTime,
    /// The dead time and settling before the first current rank's sampling starts.
    Settling,
    /// The last current rank's sampling end before the low side turns off.
    SamplingEnd,
}

/// The duty limit and the voltage it leaves.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DutyLimit {
    /// Largest duty cycle of a leg, d_max (a whole compare value over ARR).
    pub max_duty: f64,
    /// Its compare value, d_max·ARR \[ticks\].
    pub max_compare: u16,
    /// Half the low-side pulse the sampling needs, h \[s\] (0 for in-line sensing).
    pub half_window_s: f64,
    /// Which condition set `max_compare`: the sampling window's h, or the dead time's
    /// gap p.
    pub bound: DutyBound,
    /// Dead time t_d \[s\].
    pub dead_time_s: f64,
    /// Settling time after the low side's turn-on, t_set \[s\] (0 for in-line sensing).
    pub settling_time_s: f64,
    /// The ranks that sample a phase current.
    pub ranks: Vec<CurrentRank>,
    /// The usable fraction of the THPWM linear range U_dc/√3 ([`usable_voltage_fraction`]).
    pub usable_voltage_fraction: f64,
    /// The shortest gap a compare value keeps from either end of the carrier, p = t_d
    /// \[compare units\] ([`min_pulse`]; module documentation, "Dead intervals that leave
    /// their period").
    pub min_pulse: u16,
}

/// The duty limit of `board` at switching frequency `fs_hz` with dead time
/// `dead_time_s` (the longer of the board's and the spec's): low-side shunts as the
/// module documentation derives it, and on every board no dead interval that leaves its
/// period (d_max ≤ 1 − p/ARR). `None` when f_s needs an
/// auto-reload TIM1 cannot hold (refused elsewhere, `firmware::pwm_period`).
pub fn for_board(board: &crate::board::Board, fs_hz: f64, dead_time_s: f64) -> Option<DutyLimit> {
    use crate::board::Placement;
    let arr = crate::firmware::pwm_period(fs_hz).ok()?;
    let timer_hz = f64::from(crate::firmware::TIMER_CLOCK_HZ);
    let low_side = board.current.placement == Some(Placement::LowSide);
    let (ranks, settling) = if low_side {
        (
            current_ranks(board, crate::board::ADC_CLOCK_HZ),
            board.current.settling_time_s.unwrap_or(0.0),
        )
    } else {
        (Vec::new(), 0.0)
    };
    let (h, bound) = half_window(&ranks, dead_time_s, settling, 1.0 / timer_hz);
    let p = min_pulse(dead_time_s);
    let window = if low_side { max_compare(h, arr, timer_hz) } else { arr };
    // The sampling window or the dead time's gap, whichever leaves the smaller duty.
    let (max_compare, bound) = if window <= arr.saturating_sub(p) {
        (window, bound)
    } else {
        (arr.saturating_sub(p), DutyBound::DeadTime)
    };
    let max_duty = f64::from(max_compare) / f64::from(arr);
    Some(DutyLimit {
        max_duty,
        max_compare,
        half_window_s: h,
        bound,
        dead_time_s,
        settling_time_s: settling,
        ranks,
        usable_voltage_fraction: usable_voltage_fraction(max_duty),
        min_pulse: p,
    })
}

/// p = t_d \[compare units\] of a dead time of `dead_time_s` as TIM1 makes it: the
/// image's DTG code (`firmware::dead_time`, never shorter than asked) decoded to ticks
/// of the timer clock (RM0440 §28.6.20); 0 where TIM1 cannot make it (refused at the
/// key, `firmware::dead_time`).
pub fn min_pulse(dead_time_s: f64) -> u16 {
    crate::firmware::dead_time(dead_time_s).map_or(0, |dtg| motor_control::timing::dtg_ticks(dtg) as u16)
}

/// The ranks of `board`'s sequences that sample a phase current (padding repeats
/// excluded), with their sampling phases after the trigger at `adc_hz` (module
/// documentation: earliest start without, latest end with the 3.125-cycle latency).
pub fn current_ranks(board: &crate::board::Board, adc_hz: f64) -> Vec<CurrentRank> {
    use crate::board::Signal;
    let mut out = Vec::new();
    for (k, seq) in board.adc.iter().enumerate() {
        let mut before = 0.0;
        for (r, slot) in seq.iter().enumerate() {
            let phase = match slot.signal {
                Signal::CurrentU => Some(0),
                Signal::CurrentV => Some(1),
                Signal::CurrentW => Some(2),
                _ => None,
            };
            if let (Some(phase), false) = (phase, slot.padding) {
                out.push(CurrentRank {
                    adc: k as u8 + 1,
                    rank: r as u8 + 1,
                    phase,
                    start_s: before / adc_hz,
                    end_s: (TRIGGER_LATENCY_CYCLES + before + slot.sampling.cycles) / adc_hz,
                });
            }
            before += slot.sampling.cycles + CONVERSION_CYCLES;
        }
    }
    out
}

pub use crate::board::{CONVERSION_CYCLES, TRIGGER_LATENCY_CYCLES};

/// h of the module documentation \[s\]: the larger of the two conditions over `ranks`,
/// with `tick_s` the trigger's lead before the carrier maximum; and which one set it.
pub fn half_window(ranks: &[CurrentRank], dead_time_s: f64, settling_s: f64, tick_s: f64) -> (f64, DutyBound) {
    let mut h = 0.0;
    let mut bound = DutyBound::DeadTime;
    for r in ranks {
        let settle = dead_time_s + settling_s - (r.start_s - tick_s);
        let end = r.end_s - tick_s;
        if settle > h {
            h = settle;
            bound = DutyBound::Settling;
        }
        if end > h {
            h = end;
            bound = DutyBound::SamplingEnd;
        }
    }
    (h, bound)
}

/// The duty limit for a low-side half window `h` \[s\] on a centre-aligned carrier of
/// auto-reload `arr` at `timer_hz`: `ARR − ⌈h·f_TIM⌉` ticks as the largest compare value
/// (the low-side pulse 2·(ARR − CCR) ticks about the maximum), clamped at 0; d_max is it
/// over ARR.
pub fn max_compare(h_s: f64, arr: u16, timer_hz: f64) -> u16 {
    let ticks = (h_s * timer_hz - 1e-9).ceil().max(0.0);
    (f64::from(arr) - ticks).max(0.0) as u16
}

/// The phase peak of (3.8) over U_dc for a voltage amplitude `m` in units of U_dc/√3:
/// `max_φ (m/√3·cos φ − cos 3φ/(6√3))`. Where the maximum lies: the derivative
/// `−m·sin φ + sin 3φ/2 = sin φ·(3/2 − m − 2·sin²φ)` (sin 3φ = 3 sin φ − 4 sin³φ) is
/// zero at φ = 0 and, for m < 3/2, at sin²φ = (3/2 − m)/2 — both are candidates.
pub fn thpwm_phase_peak(m: f64) -> f64 {
    let s3 = 3f64.sqrt();
    let f = |phi: f64| m / s3 * phi.cos() - (3.0 * phi).cos() / (6.0 * s3);
    let mut peak = f(0.0);
    let s2 = (1.5 - m) / 2.0;
    if (0.0..=1.0).contains(&s2) {
        peak = peak.max(f(s2.sqrt().asin()));
    }
    peak
}

/// The largest amplitude, as a fraction of U_dc/√3, whose phase peak with the fixed
/// third harmonic of (3.7) stays within `(d_max − 1/2)·U_dc` ([`thpwm_phase_peak`] is
/// increasing in m on \[0, 1\]: bisection to 1e-12). 1 for d_max = 1 (the whole linear
/// range, the peak there is exactly U_dc/2); 0 when d_max leaves no more than the third
/// harmonic's own U_dc/(6√3).
pub fn usable_voltage_fraction(max_duty: f64) -> f64 {
    let room = max_duty - 0.5;
    if thpwm_phase_peak(1.0) <= room + 1e-15 {
        return 1.0;
    }
    if thpwm_phase_peak(0.0) >= room {
        return 0.0;
    }
    let (mut lo, mut hi) = (0.0, 1.0);
    while hi - lo > 1e-12 {
        let mid = 0.5 * (lo + hi);
        if thpwm_phase_peak(mid) <= room {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

#[cfg(test)]
mod tests {
    use super::*;

    /// By hand: 500 ns at 170 MHz is 85 ticks (DTG = 85, RM0440 §28.6.20: `0xx` codes
    /// count single ticks), p = 85; 320 ns → 54.4 → 55 ticks (never shorter), p = 55;
    /// 1 µs → 170 ticks, above 127 so DTG = 0x80 | (85 − 64) = 0x95, which is
    /// (64 + 21)·2 = 170 ticks, p = 170; no dead time, p = 0.
    #[test]
    fn min_pulse_by_hand() {
        assert_eq!(min_pulse(500e-9), 85);
        assert_eq!(min_pulse(320e-9), 55);
        assert_eq!(min_pulse(1e-6), 170);
        assert_eq!(min_pulse(0.0), 0);
    }

    /// (3.8) at the edge of the linear range: the peak is exactly U_dc/2 (m = 1), and
    /// at m = 0 the third harmonic alone, 1/(6√3) = 0.096225.
    #[test]
    fn phase_peak_by_hand() {
        assert!((thpwm_phase_peak(1.0) - 0.5).abs() < 1e-12);
        assert!((thpwm_phase_peak(0.0) - 0.096_225_044_864_937_6).abs() < 1e-12);
        // Against a dense scan of φ (an independent evaluation of the same formula).
        for m in [0.3, 0.7, 0.9, 0.95] {
            let s3 = 3f64.sqrt();
            let scan = (0..200_000)
                .map(|k| {
                    let phi = k as f64 * std::f64::consts::TAU / 200_000.0;
                    m / s3 * phi.cos() - (3.0 * phi).cos() / (6.0 * s3)
                })
                .fold(f64::MIN, f64::max);
            assert!((thpwm_phase_peak(m) - scan).abs() < 1e-9, "{m}");
        }
    }

    /// d_max = 1 leaves the whole linear range; d_max = 0.9 leaves the amplitude m whose
    /// peak is 0.4·U_dc: near m = 1 the peak is at φ = π/2·… — checked by the peak itself.
    #[test]
    fn usable_fraction() {
        assert_eq!(usable_voltage_fraction(1.0), 1.0);
        let k = usable_voltage_fraction(0.9);
        assert!((thpwm_phase_peak(k) - 0.4).abs() < 1e-9, "{k}");
        assert!(k > 0.75 && k < 0.85, "{k}");
        assert_eq!(usable_voltage_fraction(0.55), 0.0);
    }

    /// Hand calculation, two ranks of 24.5-cycle sampling at 42.5 MHz (23.53 ns a
    /// cycle): rank 1 from 0 to (3.125 + 24.5) cycles = 650.0 ns, rank 2 from 37 cycles =
    /// 870.6 ns to (3.125 + 61.5) cycles = 1520.6 ns; t_d = 500 ns, t_set = 1 µs, tick
    /// 5.88 ns: settle 1500 + 5.88 = 1505.9 ns; end of rank 2 1520.6 − 5.9 = 1514.7 ns →
    /// h = 1514.7 ns (sampling end); at 20 kHz (ARR 4250) ⌈1514.7·0.17⌉ = ⌈257.5⌉ = 258
    /// ticks → CCR_max = 3992, d_max = 0.93929. Without dead time and settling only the
    /// sampling end counts; with a 2 µs settling time the settling condition:
    /// 2500 + 5.88 = 2505.9 ns.
    #[test]
    fn window_by_hand() {
        let c = 1.0 / 42.5e6;
        let tick = 1.0 / 170e6;
        let ranks = [
            CurrentRank {
                adc: 1,
                rank: 1,
                phase: 0,
                start_s: 0.0,
                end_s: 27.625 * c,
            },
            CurrentRank {
                adc: 1,
                rank: 2,
                phase: 1,
                start_s: 37.0 * c,
                end_s: 64.625 * c,
            },
        ];
        let (h, bound) = half_window(&ranks, 500e-9, 1e-6, tick);
        assert!((h - 1514.71e-9).abs() < 0.01e-9, "{h}");
        assert_eq!(bound, DutyBound::SamplingEnd);
        assert_eq!(max_compare(h, 4250, 170e6), 3992);
        let (h, bound) = half_window(&ranks, 500e-9, 2e-6, tick);
        assert!((h - 2505.88e-9).abs() < 0.01e-9, "{h}");
        assert_eq!(bound, DutyBound::Settling);
        assert_eq!(half_window(&[], 500e-9, 1e-6, tick), (0.0, DutyBound::DeadTime));
    }
}
