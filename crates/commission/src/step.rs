//! R, L and transport delay of one axis from a blocked-rotor voltage step, thesis A §6.2.
//!
//! 1. The current is filtered with the spec's identification FIR exactly as the FMAC
//!    does it: the currents become Q1.15 of the current full scale (the firmware's
//!    scaling), pass through the bit-exact FMAC model of the firmware
//!    ([`motor_control::fir::FmacFir`]) with the design's Q1.15 taps, and are scaled back.
//!    The FIR's history is preloaded with the first sample (as the FMAC's X1 buffer can
//!    be), so a current offset does not start a transient.
//! 2. R = U/(i(∞) − i(0)) (6.3): i(0) is the mean before the step, i(∞) the mean of the
//!    last quarter of the step.
//! 3. τ = T_r/ln 9 from the 10 % and 90 % crossings (6.6), (6.7), linearly interpolated
//!    between rows; the FIR delays both by the same (N − 1)/2 rows (linear phase), so
//!    T_r is unaffected. L = R·τ (6.8).
//! 4. Delay: the thesis reads the 5 % crossing after the step. For a first-order
//!    response that crossing lies τ·ln(20/19) ≈ 0.051·τ after the response starts (6.5),
//!    which for the seed motors is 3 to 15 samples, so the transport delay reported is
//!    T_d = t_5% − t_step − (N − 1)/2·spacing − τ·ln(20/19) (the FIR's group delay and the
//!    first-order rise removed); the raw 5 % crossing is reported as well.

use motor_control::commissioning::Axis;
use motor_control::fir::{FirState, FmacFir, MAX_TAPS};

use super::recording::Recording;
use codegen::diagnostic::Diagnostics;
use codegen::units::{self, Kind};

/// What the design and the user fix for a step identification.
#[derive(Debug, Clone, PartialEq)]
pub struct StepSetup {
    /// Axis the recording must excite (`--axis`).
    pub axis: Axis,
    /// The FMAC's Q1.15 taps (the design's `fir.taps_q15`).
    pub taps_q15: Vec<i16>,
    /// Current full scale of the Q1.15 format \[A\] (the design's phase-current scaling).
    pub current_full_scale_a: f64,
    /// Current limit when the recording states no `current_trip` \[A\] (the motor's peak
    /// current amplitude).
    pub current_limit_a: f64,
    /// Largest voltage the inverter can apply in the linear range, U_dc/√3 \[V\].
    pub voltage_limit_v: f64,
}

/// R, L and delay from one recording.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepEstimate {
    /// Step height U \[V\].
    pub voltage_v: f64,
    /// i(∞) − i(0) of the filtered current \[A\].
    pub current_change_a: f64,
    /// R = U/Δi (6.3) \[Ω\].
    pub resistance_ohm: f64,
    /// T_r = t_90 − t_10 (6.6) \[s\].
    pub rise_time_s: f64,
    /// τ = T_r/ln 9 (6.7) \[s\].
    pub time_constant_s: f64,
    /// L = R·τ (6.8) \[H\].
    pub inductance_h: f64,
    /// 5 % crossing after the step, FIR group delay removed [periods T_s].
    pub crossing_5_samples: f64,
    /// Transport delay T_d = crossing − τ·ln(20/19) [periods T_s].
    pub delay_samples: f64,
    /// T_d \[s\].
    pub delay_s: f64,
}

/// The steady state must be reached: the step lasts at least this many τ
/// (e^−6 = 0.25 % left at the start of the averaged last quarter of 8τ).
pub const MIN_STEP_TIME_CONSTANTS: f64 = 8.0;

/// Filters `currents` \[A\] through the FMAC model: Q1.15 of `full_scale` \[A\], `taps`
/// (at most [`MAX_TAPS`], zero-padded to the FMAC's 127: zero taps add exactly zero to
/// the accumulator), history preloaded with the first sample.
pub fn fmac_filter(currents: &[f64], taps: &[i16], full_scale: f64) -> Vec<f64> {
    let mut padded = [0i16; MAX_TAPS];
    for (p, &t) in padded.iter_mut().zip(taps) {
        *p = t;
    }
    let fir = FmacFir::new(padded);
    let mut state = FirState::<MAX_TAPS>::new();
    let to_q15 = |i: f64| (i / full_scale * 32768.0).round().clamp(-32768.0, 32767.0) as i16;
    if let Some(&first) = currents.first() {
        for _ in 0..MAX_TAPS {
            fir.process(&mut state, to_q15(first));
        }
    }
    currents
        .iter()
        .map(|&i| f64::from(fir.process(&mut state, to_q15(i))) / 32768.0 * full_scale)
        .collect()
}

/// First time (in periods, interpolated) at which `y` reaches `target` from below
/// (`rising`) or above, searching rows from `from`.
fn crossing(samples: &[f64], y: &[f64], from: usize, target: f64, rising: bool) -> Option<f64> {
    let reached = |v: f64| if rising { v >= target } else { v <= target };
    let k = (from..y.len()).find(|&k| reached(y[k]))?;
    if k == 0 || k <= from {
        return Some(samples[k]);
    }
    let (y0, y1) = (y[k - 1], y[k]);
    let frac = if y1 != y0 { (target - y0) / (y1 - y0) } else { 0.0 };
    Some(samples[k - 1] + frac * (samples[k] - samples[k - 1]))
}

fn axis_name(a: Axis) -> &'static str {
    match a {
        Axis::D => "d",
        Axis::Q => "q",
    }
}

/// Identifies R, L and the delay from a `step` recording; every bad recording is a
/// located error, never a number.
pub fn identify_step(rec: &Recording, setup: &StepSetup) -> Result<StepEstimate, Diagnostics> {
    if let Some(h) = rec.header_key("axis") {
        let want = axis_name(setup.axis);
        if h.value != want {
            return Err(rec.error_at(
                h.offset,
                "axis",
                format!(
                    "the recording excites the {} axis, but --axis {want} was given",
                    h.value
                ),
                format!("a recording of the {want} axis, or --axis {}", h.value),
            ));
        }
    }
    if let Some(h) = rec.header_key("tripped") {
        return Err(rec.error_at(
            h.offset,
            "tripped",
            format!(
                "the current limit tripped during this run ({}); the step is incomplete",
                h.value
            ),
            "a run that finished without a trip: lower the step voltage so that U/R stays below the trip level",
        ));
    }
    let (vc, ic) = (rec.column("voltage_v"), rec.column("current_a"));
    let (Some(vc), Some(ic)) = (vc, ic) else {
        return Err(rec.error_at(0, "", "voltage_v or current_a missing", "sample,voltage_v,current_a"));
    };
    let voltage: Vec<f64> = rec.values.iter().map(|r| r[vc]).collect();
    let current: Vec<f64> = rec.values.iter().map(|r| r[ic]).collect();
    let (vcol, icol) = (vc + 1, ic + 1);
    let Some(k0) = voltage.iter().position(|&v| v != 0.0) else {
        return Err(rec.error_at_cell(
            rec.samples.len() - 1,
            vcol,
            "no step found: voltage_v is 0 in every row",
            "a recording of the whole routine: rows at 0 V, then rows at the step voltage",
        ));
    };
    if k0 == 0 {
        return Err(rec.error_at_cell(
            0,
            vcol,
            "no step found: the voltage is already on in the first row, so there is no baseline before the step",
            "rows at 0 V before the step (VoltageStep::pre_samples ≥ 1)",
        ));
    }
    let u = voltage[k0];
    if let Some(k) = (k0..voltage.len()).find(|&k| (voltage[k] - u).abs() > 1e-6 * u.abs()) {
        return Err(rec.error_at_cell(
            k,
            vcol,
            format!("the voltage changes again ({} V after the step to {u} V)", voltage[k]),
            "a single step: 0 V, then one constant voltage to the end of the recording",
        ));
    }
    if u.abs() > setup.voltage_limit_v {
        return Err(rec.error_at_cell(
            k0,
            vcol,
            format!(
                "the step of {u} V exceeds the inverter's linear range U_dc/√3 = {:.1} V: the applied voltage was saturated",
                setup.voltage_limit_v
            ),
            format!("a step below {:.1} V", setup.voltage_limit_v),
        ));
    }
    let full_scale = setup.current_full_scale_a;
    if let Some(k) = current
        .iter()
        .position(|i| i.abs() >= full_scale * (1.0 - 1.0 / 32768.0))
    {
        return Err(rec.error_at_cell(
            k,
            icol,
            format!(
                "the current {} A is at the measurement full scale ±{full_scale:.3} A: the recording is saturated",
                current[k]
            ),
            format!("currents within ±{full_scale:.3} A (a smaller step voltage)"),
        ));
    }
    let (limit, limit_what) = match rec.header_key("current_trip") {
        Some(h) => (
            units::parse(Kind::Current, &h.value)
                .ok()
                .filter(|x| *x > 0.0)
                .ok_or_else(|| {
                    rec.error_at(
                        h.offset,
                        "current_trip",
                        format!("`{}` is not a positive current", h.value),
                        Kind::Current.accepted(),
                    )
                })?,
            "the recording's current_trip",
        ),
        None => (setup.current_limit_a, "the motor's peak current amplitude"),
    };
    if let Some(k) = current.iter().position(|i| i.abs() >= limit) {
        return Err(rec.error_at_cell(
            k,
            icol,
            format!(
                "current limit tripped: |{}| A reaches {limit_what} ({limit:.3} A)",
                current[k]
            ),
            "a run whose current stays below the limit: lower the step voltage",
        ));
    }

    let y = fmac_filter(&current, &setup.taps_q15, full_scale);
    let n = y.len();
    let baseline = y[..k0].iter().sum::<f64>() / k0 as f64;
    let steps = n - k0;
    let tail = &y[n - (steps / 4).max(1)..];
    let final_value = tail.iter().sum::<f64>() / tail.len() as f64;
    let change = final_value - baseline;
    // Noise of the raw baseline, or one Q1.15 step if it is flat.
    let lsb = full_scale / 32768.0;
    let mean_raw = current[..k0].iter().sum::<f64>() / k0 as f64;
    let sigma = (current[..k0].iter().map(|i| (i - mean_raw).powi(2)).sum::<f64>() / k0 as f64).sqrt();
    if change.abs() < 10.0 * sigma.max(lsb) || change * u <= 0.0 {
        return Err(rec.error_at_cell(
            k0,
            icol,
            format!(
                "no step found in current_a: after the {u} V step the current changes by {change:.4} A{}",
                if change * u <= 0.0 && change.abs() >= 10.0 * sigma.max(lsb) {
                    ", against the voltage"
                } else {
                    ", which is within the noise"
                }
            ),
            "a step response rising in the direction of the voltage by much more than the noise (rotor blocked, PWM on)",
        ));
    }
    let rising = change > 0.0;
    let at = |level: f64| crossing(&rec.samples, &y, k0, baseline + level * change, rising);
    let (Some(t05), Some(t10), Some(t90)) = (at(0.05), at(0.1), at(0.9)) else {
        return Err(rec.error_at_cell(
            n - 1,
            icol,
            "the filtered current never reaches 90 % of its final value",
            "a recording that runs until the current has settled",
        ));
    };
    let spacing = rec.spacing;
    let ts = rec.sample_period_s;
    let rise = t90 - t10; // periods
    if rise < 4.0 * spacing {
        return Err(rec.error_at_cell(
            k0,
            icol,
            format!(
                "the current rises from 10 % to 90 % within {:.1} rows: too fast to measure at this rate",
                rise / spacing
            ),
            "a capture rate with at least 4 rows in the rise (less decimation)",
        ));
    }
    let tau = rise / 9f64.ln(); // periods, (6.7)
    let duration = rec.samples[n - 1] - rec.samples[k0];
    if duration < MIN_STEP_TIME_CONSTANTS * tau {
        return Err(rec.error_at_cell(
            n - 1,
            0,
            format!(
                "the recording is too short: the step lasts {:.0} periods = {:.1} τ (τ ≈ {:.0} periods), so the current has not settled for the final value (6.3)",
                duration,
                duration / tau,
                tau
            ),
            format!(
                "a step of at least {MIN_STEP_TIME_CONSTANTS} τ ≈ {:.0} periods ({:.1} ms)",
                (MIN_STEP_TIME_CONSTANTS * tau).ceil(),
                MIN_STEP_TIME_CONSTANTS * tau * ts * 1e3
            ),
        ));
    }
    let group_delay = (setup.taps_q15.len() as f64 - 1.0) / 2.0 * spacing;
    let crossing_5 = t05 - rec.samples[k0] - group_delay;
    let delay = crossing_5 - tau * (20.0f64 / 19.0).ln();
    let resistance = u / change;
    Ok(StepEstimate {
        voltage_v: u,
        current_change_a: change,
        resistance_ohm: resistance,
        rise_time_s: rise * ts,
        time_constant_s: tau * ts,
        inductance_h: resistance * tau * ts,
        crossing_5_samples: crossing_5,
        delay_samples: delay,
        delay_s: delay * ts,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::recording::{self, RecordingKind};

    /// The thesis-A 21-tap filter (Σ = 32768) as produced for the Fischer spec.
    const TAPS: [i16; 21] = [
        -852, -332, -177, 176, 730, 1447, 2256, 3054, 3730, 4182, 4340, 4182, 3730, 3054, 2256, 1447, 730, 176, -177,
        -332, -852,
    ];

    fn setup() -> StepSetup {
        StepSetup {
            axis: Axis::Q,
            taps_q15: TAPS.to_vec(),
            current_full_scale_a: 16.0,
            current_limit_a: 14.0,
            voltage_limit_v: 300.0,
        }
    }

    /// Ideal first-order response with a dead time (no noise): i = U/R·(1 − e^(−(t − t_d)/τ)).
    fn ideal(u: f64, r: f64, l: f64, delay: f64, pre: usize, len: usize) -> String {
        let tau = l / r / 50e-6;
        let mut s = String::from("# sample_period = 50 µs\nsample,voltage_v,current_a\n");
        for n in 0..len {
            let t = n as f64 - pre as f64 - delay;
            let i = if t > 0.0 { u / r * (1.0 - (-t / tau).exp()) } else { 0.0 };
            let v = if n >= pre { u } else { 0.0 };
            s.push_str(&format!("{n},{v},{i}\n"));
        }
        s
    }

    /// Unimotor q axis (thesis A Table 6.1: R = 0.65 Ω, L_q = 7.6 mH), 4 V step: without
    /// noise only the Q1.15 rounding and the FIR's smoothing of the first rows remain;
    /// R and L within 0.2 %, the 1.5-period dead time within 0.2 periods.
    #[test]
    fn recovers_an_ideal_first_order_step() {
        let text = ideal(4.0, 0.65, 7.6e-3, 1.5, 40, 40 + 12 * 234);
        let rec = recording::parse("q.csv", &text, RecordingKind::Step, 50e-6).unwrap();
        let e = identify_step(&rec, &setup()).unwrap();
        assert!((e.resistance_ohm / 0.65 - 1.0).abs() < 2e-3, "{e:?}");
        assert!((e.inductance_h / 7.6e-3 - 1.0).abs() < 2e-3, "{e:?}");
        assert!((e.delay_samples - 1.5).abs() < 0.2, "{e:?}");
        // Raw 5 % crossing: 1.5 + τ·ln(20/19) = 1.5 + 233.8·0.0513 = 13.5 periods.
        assert!((e.crossing_5_samples - 13.5).abs() < 0.3, "{e:?}");
    }

    /// A capture decimated by 2 (`VoltageStep::decimation = 2`: rows 0, 2, 4, …) is
    /// filtered at the capture rate; T_r and the delay are still counted in periods:
    /// R and L within 0.5 %, the 1.5-period delay within one period.
    #[test]
    fn decimated_capture() {
        let full = ideal(4.0, 0.65, 7.6e-3, 1.5, 40, 40 + 12 * 234);
        let mut lines = full.lines();
        let mut text = format!("{}\n{}\n", lines.next().unwrap(), lines.next().unwrap());
        for (k, l) in lines.enumerate() {
            if k % 2 == 0 {
                text.push_str(l);
                text.push('\n');
            }
        }
        let rec = recording::parse("q.csv", &text, RecordingKind::Step, 50e-6).unwrap();
        assert_eq!(rec.spacing, 2.0);
        let e = identify_step(&rec, &setup()).unwrap();
        assert!((e.resistance_ohm / 0.65 - 1.0).abs() < 5e-3, "{e:?}");
        assert!((e.inductance_h / 7.6e-3 - 1.0).abs() < 5e-3, "{e:?}");
        assert!((e.delay_samples - 1.5).abs() < 1.0, "{e:?}");
    }

    /// `# axis = d` in the file but `--axis q`: refused at the header value.
    #[test]
    fn axis_mismatch_is_rejected() {
        let text = format!("# axis = d\n{}", ideal(4.0, 0.65, 7.6e-3, 1.5, 40, 40 + 12 * 234));
        let rec = recording::parse("q.csv", &text, RecordingKind::Step, 50e-6).unwrap();
        let e = identify_step(&rec, &setup()).unwrap_err().0[0].clone();
        assert_eq!((e.line, e.column, e.key.as_str()), (1, 10, "axis"));
    }

    /// Zero-padding to the FMAC's 127 taps is exact: the output equals the firmware's
    /// `FmacFir<21>` with the same taps and preload, and the design's slice model
    /// (`motor_control::fir::output` on a window), sample for sample.
    #[test]
    fn padded_filter_is_bit_exact() {
        let xs: Vec<f64> = (0..300)
            .map(|n| 5.0 * ((n as f64) * 0.37).sin() + 0.01 * n as f64)
            .collect();
        let fs = 16.0;
        let y = fmac_filter(&xs, &TAPS, fs);
        let q = |i: f64| (i / fs * 32768.0).round().clamp(-32768.0, 32767.0) as i16;
        let fir = FmacFir::new(TAPS);
        let mut st = FirState::<21>::new();
        let mut window: Vec<i16> = vec![q(xs[0]); 21];
        for _ in 0..21 {
            fir.process(&mut st, q(xs[0]));
        }
        for (k, &x) in xs.iter().enumerate() {
            let direct = fir.process(&mut st, q(x));
            window.remove(0);
            window.push(q(x));
            let model = motor_control::fir::output(&TAPS, window.iter().rev(), 0, true);
            assert_eq!(y[k], f64::from(direct) / 32768.0 * fs, "sample {k}");
            assert_eq!(direct, model, "sample {k}");
        }
    }

    /// A constant input equal to the preload passes the unity-DC-gain filter
    /// unchanged up to the FMAC's truncation (< 1.2 LSB low, see `design::fir` tests).
    #[test]
    fn filter_has_unity_dc_gain() {
        let y = fmac_filter(&[3.0; 50], &TAPS, 16.0);
        let lsb = 16.0 / 32768.0;
        assert!(
            y.iter().all(|v| (3.0 - v) >= -lsb * 0.5 && (3.0 - v) < 1.7 * lsb),
            "{y:?}"
        );
    }

    #[test]
    fn short_recording_is_rejected() {
        // 3 τ of step only.
        let text = ideal(4.0, 0.65, 7.6e-3, 1.5, 40, 40 + 3 * 234);
        let rec = recording::parse("q.csv", &text, RecordingKind::Step, 50e-6).unwrap();
        let e = identify_step(&rec, &setup()).unwrap_err().0[0].clone();
        assert!(e.problem.contains("too short"), "{e}");
    }

    #[test]
    fn missing_step_and_flat_current_are_rejected() {
        let text = "sample,voltage_v,current_a\n0,0,0\n1,0,0.01\n2,0,0\n";
        let rec = recording::parse("q.csv", text, RecordingKind::Step, 50e-6).unwrap();
        let e = identify_step(&rec, &setup()).unwrap_err().0[0].clone();
        assert!(e.problem.contains("no step found"), "{e}");
        let mut text = String::from("sample,voltage_v,current_a\n");
        for n in 0..400 {
            text.push_str(&format!("{n},{},0\n", if n >= 10 { 4 } else { 0 }));
        }
        let rec = recording::parse("q.csv", &text, RecordingKind::Step, 50e-6).unwrap();
        let e = identify_step(&rec, &setup()).unwrap_err().0[0].clone();
        assert!(e.problem.contains("no step found in current_a"), "{e}");
        assert_eq!((e.line, e.key.as_str()), (12, "current_a"));
    }

    #[test]
    fn saturation_and_trip_are_rejected() {
        // 10 V/0.65 Ω = 15.4 A > the 14 A limit.
        let text = ideal(10.0, 0.65, 7.6e-3, 1.5, 40, 40 + 12 * 234);
        let rec = recording::parse("q.csv", &text, RecordingKind::Step, 50e-6).unwrap();
        let e = identify_step(&rec, &setup()).unwrap_err().0[0].clone();
        assert!(e.problem.contains("current limit tripped"), "{e}");
        // 11 V → 16.9 A ≥ the 16 A full scale.
        let text = ideal(11.0, 0.65, 7.6e-3, 1.5, 40, 40 + 12 * 234);
        let rec = recording::parse("q.csv", &text, RecordingKind::Step, 50e-6).unwrap();
        let e = identify_step(&rec, &setup()).unwrap_err().0[0].clone();
        assert!(e.problem.contains("saturated"), "{e}");
        // The routine's own trip note.
        let text = format!(
            "# tripped = sample 812, |i| = 10.2 A\n{}",
            ideal(4.0, 0.65, 7.6e-3, 1.5, 40, 4000)
        );
        let rec = recording::parse("q.csv", &text, RecordingKind::Step, 50e-6).unwrap();
        let e = identify_step(&rec, &setup()).unwrap_err().0[0].clone();
        assert!(e.problem.contains("tripped"), "{e}");
        assert_eq!((e.line, e.column), (1, 13));
    }
}
