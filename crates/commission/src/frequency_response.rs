//! The current loop's frequency response measured where the loop runs, and compared
//! with the design.
//!
//! The drive's `frequency_response` routine (`motor_control::commissioning::
//! FrequencyResponse`) breaks one axis's loop at the controller's output: it regulates
//! both currents to zero and adds a multisine d to the controller's output u_PI (PI and
//! active damping), so the inverter gets v = u_PI + d. With the reference at zero the
//! loop answers u_PI = −L·v, L the loop transfer function broken at the plant input —
//! the L(z) of the design's sampled-loop analysis (`codegen::design::current_loop::
//! analysis`), delay included. One multisine period of N samples of (u_PI, v) is
//! captured after one period of settling, so at each line k (frequency k/(N·T_s)) the
//! DFT gives
//!
//! ```text
//! L(e^{jω_kT_s}) = −U_PI[k] / V[k],    X[k] = Σ_{n<N} x_n·e^{−j2πkn/N}
//! ```
//!
//! exactly for a linear loop in periodic steady state, whatever d's amplitude and the
//! clamp did to its shape (the ratio holds at every frequency v has energy at).
//!
//! # Margins from measured points
//!
//! Between two adjacent lines the magnitude in dB is interpolated linearly in ln ω
//! (a loop falling at 20 dB per decade is a straight line there) and the unwrapped
//! phase linearly in ω (the loop delay's −ω·T_d is a straight line there):
//!
//! * crossover ω_c: where the interpolated |L| passes 0 dB (the lowest such crossing);
//!   phase margin 180° + arg L(ω_c);
//! * phase crossover ω_p: where the unwrapped phase passes −180° (− k·360°); gain
//!   margin −|L(ω_p)| in dB; the smallest over the crossings, as the design's
//!   analysis takes it.
//!
//! None of them outside the measured lines: the crossing is then not measured (null).

use std::f64::consts::PI;
use std::path::Path;
use std::time::Duration;

use codegen::Design;
use codegen::units::{self, Kind};
use motor_control::can_protocol::{Command, Layout, Quantity, Routine};
use motor_control::commissioning_mode::FREQUENCY_RESPONSE_SETTLE_PERIODS;

use super::candump;
use super::commission::{self, FrameBus};
use super::error::{Error, Problem};
use super::identify::Input;
use super::writeback;
use codegen::design::current_loop::analysis::{self, AxisGains};
use codegen::design::current_loop::discrete;
use motor_control::commissioning::{Axis, multisine_lines};
use motor_control::commissioning_mode::frequency_response_period;

/// One measured (or modelled) point of L(jω).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Point {
    /// ω [rad/s].
    pub omega_rad_s: f64,
    /// Re L.
    pub re: f64,
    /// Im L.
    pub im: f64,
}

impl Point {
    /// |L| in dB.
    pub fn magnitude_db(&self) -> f64 {
        20.0 * self.re.hypot(self.im).log10()
    }

    /// arg L in (−π, π] \[rad\].
    pub fn phase(&self) -> f64 {
        self.im.atan2(self.re)
    }

    /// Frequency \[Hz\].
    pub fn frequency_hz(&self) -> f64 {
        self.omega_rad_s / (2.0 * PI)
    }
}

/// Margins and crossover of a loop, read from points or from the design.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Margins {
    /// Gain margin \[dB\] at the phase crossover (None: no phase crossover).
    pub gain_margin_db: Option<f64>,
    /// Phase margin [°] at the crossover (None: no crossover).
    pub phase_margin_deg: Option<f64>,
    /// Gain crossover ω_c [rad/s].
    pub crossover_rad_s: Option<f64>,
    /// Phase crossover ω_p [rad/s].
    pub phase_crossover_rad_s: Option<f64>,
}

/// The DFT bin `k` of the `n`-sample sequence `x` (one whole period).
fn bin(x: impl Iterator<Item = f64>, k: u16, n: usize) -> (f64, f64) {
    let w = 2.0 * PI * f64::from(k) / n as f64;
    let (mut re, mut im) = (0.0, 0.0);
    for (i, v) in x.enumerate() {
        let (s, c) = (w * i as f64).sin_cos();
        re += v * c;
        im -= v * s;
    }
    (re, im)
}

/// L at every line from one captured period of (u_PI, v) \[V\] (module documentation):
/// L = −U_PI/V. `ts` is T_s \[s\]. Lines whose V is zero (nothing injected) are left out.
pub fn response(rows: &[(f64, f64)], harmonics: &[u16], ts: f64) -> Vec<Point> {
    let n = rows.len();
    harmonics
        .iter()
        .filter_map(|&k| {
            let (ur, ui) = bin(rows.iter().map(|r| r.0), k, n);
            let (vr, vi) = bin(rows.iter().map(|r| r.1), k, n);
            let den = vr * vr + vi * vi;
            (den > 0.0).then(|| Point {
                omega_rad_s: 2.0 * PI * f64::from(k) / (n as f64 * ts),
                // −(U·conj V)/|V|².
                re: -(ur * vr + ui * vi) / den,
                im: -(ui * vr - ur * vi) / den,
            })
        })
        .collect()
}

/// Wraps an angle difference into (−π, π].
fn wrap(x: f64) -> f64 {
    let y = x.rem_euclid(2.0 * PI);
    if y > PI { y - 2.0 * PI } else { y }
}

/// The phases of `points` unwrapped along increasing ω, starting from the principal
/// value at the first \[rad\].
pub fn unwrapped_phase(points: &[Point]) -> Vec<f64> {
    let mut out: Vec<f64> = Vec::with_capacity(points.len());
    for (k, p) in points.iter().enumerate() {
        let ph = match (
            k.checked_sub(1).and_then(|j| out.get(j)),
            k.checked_sub(1).and_then(|j| points.get(j)),
        ) {
            (Some(prev), Some(q)) => prev + wrap(p.phase() - q.phase()),
            _ => p.phase(),
        };
        out.push(ph);
    }
    out
}

/// The margins of the module documentation from measured `points` (increasing ω).
pub fn margins(points: &[Point]) -> Margins {
    let phase = unwrapped_phase(points);
    let mut m = Margins::default();
    for k in 0..points.len().saturating_sub(1) {
        let (p0, p1) = (points[k], points[k + 1]);
        let (w0, w1) = (p0.omega_rad_s, p1.omega_rad_s);
        let (g0, g1) = (p0.magnitude_db(), p1.magnitude_db());
        let (f0, f1) = (phase[k], phase[k + 1]);
        // Gain crossover: the lowest.
        if m.crossover_rad_s.is_none() && (g0 >= 0.0) != (g1 >= 0.0) {
            let t = g0 / (g0 - g1);
            let wc = (w0.ln() + t * (w1.ln() - w0.ln())).exp();
            let ph = f0 + (wc - w0) / (w1 - w0) * (f1 - f0);
            m.crossover_rad_s = Some(wc);
            m.phase_margin_deg = Some(wrap(ph + PI).to_degrees());
        }
        // Phase crossovers: the unwrapped phase passes −π − 2πj.
        let (j0, j1) = (((f0 + PI) / (2.0 * PI)).floor(), ((f1 + PI) / (2.0 * PI)).floor());
        if j0 != j1 {
            let target = -PI + 2.0 * PI * j0.max(j1);
            let wp = w0 + (target - f0) / (f1 - f0) * (w1 - w0);
            let t = (wp.ln() - w0.ln()) / (w1.ln() - w0.ln());
            let gm = -(g0 + t * (g1 - g0));
            if m.gain_margin_db.is_none_or(|g| gm < g) {
                m.gain_margin_db = Some(gm);
                m.phase_crossover_rad_s = Some(wp);
            }
        }
    }
    m
}

/// The design's gains of `axis`.
pub fn axis_gains(d: &Design, axis: Axis) -> &AxisGains {
    match axis {
        Axis::D => &d.current_loop.d,
        Axis::Q => &d.current_loop.q,
    }
}

/// The designed margins of `axis` (the design's sampled-loop analysis).
pub fn designed_margins(d: &Design, axis: Axis) -> Margins {
    let s = &axis_gains(d, axis).sampled;
    Margins {
        gain_margin_db: s.gain_margin_db,
        phase_margin_deg: s.phase_margin_deg,
        crossover_rad_s: s.gain_crossover_rad_s,
        phase_crossover_rad_s: s.phase_crossover_rad_s,
    }
}

/// The designed L(e^{jωT_s}) of `axis` at `omega` [rad/s]: the design's gains on the
/// sampled plant of the design's request (R, L, T_s and the loop delay).
pub fn designed_point(d: &Design, axis: Axis, omega: f64) -> Point {
    let req = d.current_loop_request(axis);
    let l = analysis::open_loop(&axis_gains(d, axis).loop_gains(), &discrete::plant(&req), omega);
    Point {
        omega_rad_s: omega,
        re: l.re,
        im: l.im,
    }
}

/// The multisine's period N \[samples\] on a drive with a capture buffer of `capacity`.
pub fn period(capacity: usize) -> u32 {
    frequency_response_period(capacity)
}

/// The default line set for `axis` of design `d` with period `n` (the design core's,
/// which [`codegen::constants::can::injection_limit`] bounds).
pub use codegen::constants::can::{default_lines, lines_spanning};

// ---------------------------------------------------------------------------------
// The session
// ---------------------------------------------------------------------------------

/// A frequency-response session's options, as the user gave them (`motorgen commission
/// … frequency-response`).
#[derive(Debug, Clone, PartialEq)]
pub struct Options {
    /// The interface's name (in messages and the log).
    pub iface: String,
    /// How long to wait for the whole capture, e.g. `30 s` (at most an hour).
    pub timeout: String,
    /// The injected axis.
    pub axis: Axis,
    /// Peak of the injection, e.g. `5 V` (`None`: the drive's injection limit, the
    /// generated `INJECTION_LIMIT` (`codegen::constants::can::injection_limit`): the
    /// most signal the drive allows, so the 12-bit current sensing's steps matter least).
    pub amplitude: Option<String>,
    /// The lines: `FIRST_HARMONIC/PER_OCTAVE`, e.g. `4/3` (`None`: [`default_lines`]).
    pub frequencies: Option<String>,
}

/// A session checked before the bus is touched.
#[derive(Debug, Clone)]
pub struct Plan {
    /// The CAN interface of the design on the board.
    pub layout: Layout,
    /// The board's CAN bit rate \[bit/s\].
    pub bit_rate: u32,
    /// The command frame's content.
    pub command: Command,
    /// How long the whole session may take.
    pub timeout: Duration,
    /// The multisine's period N \[samples\].
    pub period: u32,
    /// The lines' harmonic numbers.
    pub harmonics: Vec<u16>,
    /// The design the margins are compared with.
    pub design: Design,
    options: Options,
    spec_stem: String,
}

/// A measured frequency response next to the design.
#[derive(Debug, Clone, PartialEq)]
pub struct Measurement {
    /// The injected axis.
    pub axis: Axis,
    /// Margins read from the measured points.
    pub measured: Margins,
    /// The design's margins (its sampled-loop analysis).
    pub designed: Margins,
    /// The measured points.
    pub points: Vec<Point>,
    /// The designed L at the same frequencies.
    pub designed_points: Vec<Point>,
    /// Injection peak \[V\] and trip \[A\] as sent.
    pub amplitude_v: f64,
    /// Trip level \[A\].
    pub trip_a: f64,
    /// Periods the routine ran and T_s \[s\].
    pub duration_s: f64,
    /// (file name, CSV recording) of the capture.
    pub csv: (String, String),
    /// The plant fitted to the measured points, from the design's.
    pub fit: Fit,
    /// The design's plant of the axis (R, L, loop delay).
    pub design_plant: PlantModel,
    /// The largest bandwidth whose loop, designed by the spec's method for the fitted
    /// plant, meets the margin floors on it ([`retune`]) [rad/s].
    pub retune_rad_s: Option<f64>,
}

fn bad_option(option: &str, problem: String, accepted: &str) -> Error {
    Error::Option(Problem::new(option, problem, accepted))
}

/// The trip level \[A\]: half the motor's peak current (the I_trip the generated
/// `INJECTION_LIMIT` keeps the injected current within half of).
pub fn trip_level(d: &Design) -> f64 {
    0.5 * d.motor.peak_current_a
}

/// Checks the options, the spec and the board (a design with a CAN interface).
pub fn plan(o: &Options, spec: &Input, board: &Input) -> Result<Plan, Error> {
    let d = codegen::design_with_board(&spec.name, spec.text()?, &board.name, board.text()?)?;
    plan_design(o, d, &spec.name)
}

/// [`plan`] for a design already made (`spec_name` names the CSV file).
pub fn plan_design(o: &Options, d: Design, spec_name: &str) -> Result<Plan, Error> {
    let Some((cfg, capacity)) = candump::mode_config(&d) else {
        return Err(bad_option(
            "--board",
            "the design has no CAN interface".into(),
            "a board file with a [can] section",
        ));
    };
    let timeout = units::parse(Kind::Time, &o.timeout)
        .ok()
        .filter(|t| *t > 0.0 && *t <= 3600.0)
        .ok_or_else(|| {
            bad_option(
                "--timeout",
                format!("`{}` is not a time up to an hour", o.timeout),
                "a time, e.g. \"30 s\"",
            )
        })?;
    let n = period(capacity);
    // One figure for the default, this refusal and the drive's own (it refuses a larger
    // amplitude with `Reason::AmplitudeAboveLimit`): the f32 the image holds, compared
    // with the amplitude as the drive decodes it from the command's voltage LSBs.
    let limit = cfg.injection_limit;
    let layout = cfg.layout;
    let on_bus = |v: f32| layout.from_lsb(Quantity::Voltage, layout.to_lsb(Quantity::Voltage, v));
    let amplitude = match &o.amplitude {
        // The largest whole number of LSBs within the limit.
        None => {
            let per = layout.per_lsb(Quantity::Voltage);
            let mut k = (limit / per).floor().min(f32::from(i16::MAX));
            while k > 0.0 && k * per > limit {
                k -= 1.0;
            }
            on_bus(k * per)
        }
        Some(t) => units::parse(Kind::Voltage, t)
            .ok()
            .map(|v| on_bus(v as f32))
            .filter(|v| v.is_finite() && *v > 0.0 && *v <= limit)
            .ok_or_else(|| {
                bad_option(
                    "--amplitude",
                    format!(
                        "`{t}` is not a voltage above 0 and up to the drive's injection limit INJECTION_LIMIT = {limit} V (the injected current within half the routine's trip, the voltage within U_dc/√3)"
                    ),
                    &format!("a voltage up to {limit} V, e.g. \"{:.2} V\"", 0.5 * limit),
                )
            })?,
    };
    let accepted = format!(
        "FIRST/PER_OCTAVE: a first harmonic 1–255 below {} and 1–8 lines per octave, e.g. \"4/3\"",
        n / 2
    );
    let (first, per_octave) = match &o.frequencies {
        None => default_lines(&d, o.axis, n).ok_or_else(|| {
            bad_option(
                "--frequencies",
                "no line set fits this drive's capture".into(),
                &accepted,
            )
        })?,
        Some(t) => t
            .split_once('/')
            .and_then(|(a, b)| Some((a.trim().parse::<u8>().ok()?, b.trim().parse::<u8>().ok()?)))
            .filter(|(a, b)| multisine_lines(u16::from(*a), *b, n).is_some())
            .map(|(a, b)| (u16::from(a), b))
            .ok_or_else(|| {
                bad_option(
                    "--frequencies",
                    format!("`{t}` is not a line set of this drive"),
                    &accepted,
                )
            })?,
    };
    let lines = multisine_lines(first, per_octave, n).ok_or_else(|| {
        bad_option(
            "--frequencies",
            "no line set fits this drive's capture".into(),
            &accepted,
        )
    })?;
    let trip = trip_level(&d);
    let current_full_scale = cfg.layout.current_per_lsb as f64 * 32767.0;
    let command = Command {
        routine: Some(Routine::FrequencyResponse),
        axis_q: o.axis == Axis::Q,
        voltage: amplitude,
        current_trip: trip.min(current_full_scale) as f32,
        decimation: u16::from_le_bytes([first as u8, per_octave]),
    };
    let bit_rate = d.board.as_ref().map_or(0, |b| b.board.can_bit_rate.round() as u32);
    let spec_stem = Path::new(spec_name)
        .file_stem()
        .map_or_else(|| "motor".into(), |s| s.to_string_lossy().into_owned());
    Ok(Plan {
        layout: cfg.layout,
        bit_rate,
        command,
        timeout: Duration::from_secs_f64(timeout),
        period: n,
        harmonics: lines.used().to_vec(),
        design: d,
        options: o.clone(),
        spec_stem,
    })
}

impl Plan {
    /// Runs the session on `bus`: the command, the capture (reassembled and checked as
    /// a `candump -l` log's), L at every line, the margins and the design's.
    pub fn run<B: FrameBus>(&self, bus: &mut B) -> Result<Measurement, Error> {
        let o = &self.options;
        let rec = commission::run_session(bus, &o.iface, &self.layout, &self.command, self.timeout)
            .map_err(|e| commission::session_error(e, &o.iface, &o.timeout))?;
        let name = format!("{} (live)", o.iface);
        let caps = candump::captures(&name, &rec.text, &rec.frames, &self.layout)?;
        let bad = |problem: String| {
            bad_option(
                &name,
                problem,
                "one complete frequency-response capture of one multisine period",
            )
        };
        let Some(c) = caps.iter().find(|c| c.header.routine == Routine::FrequencyResponse) else {
            return Err(bad("the session brought no frequency-response capture".into()));
        };
        if c.header.tripped {
            return Err(bad(format!(
                "the routine tripped at sample {} at {:.3} A; lower --amplitude",
                c.end.trip_sample, c.end.trip_current
            )));
        }
        if c.rows.len() != self.period as usize {
            return Err(bad(format!(
                "the capture has {} samples, not the multisine period {}",
                c.rows.len(),
                self.period
            )));
        }
        let per = f64::from(self.layout.voltage_per_lsb);
        let rows: Vec<(f64, f64)> = c
            .rows
            .iter()
            .map(|&(a, b)| (f64::from(a) * per, f64::from(b) * per))
            .collect();
        let ts = c.sample_period_s();
        let d = &self.design;
        let points = response(&rows, &self.harmonics, ts);
        let designed_points = points
            .iter()
            .map(|p| designed_point(d, o.axis, p.omega_rad_s))
            .collect();
        let axis = match o.axis {
            Axis::D => "d",
            Axis::Q => "q",
        };
        let t = rec
            .frames
            .iter()
            .position(|f| f.offset == c.header_offset)
            .map_or(0.0, |k| rec.times[k]);
        let file = format!(
            "{}-frequency_response-{axis}-{}.csv",
            self.spec_stem,
            commission::stamp(t)
        );
        let gains = axis_gains(d, o.axis).loop_gains();
        let design_plant = SimScale::default().plant_of(d, o.axis);
        let fit = fit_plant(&points, &gains, ts, &design_plant);
        Ok(Measurement {
            retune_rad_s: retune(d, o.axis, &fit.plant),
            fit,
            design_plant,
            axis: o.axis,
            measured: margins(&points),
            designed: designed_margins(d, o.axis),
            points,
            designed_points,
            amplitude_v: f64::from(self.command.voltage),
            trip_a: f64::from(self.command.current_trip),
            duration_s: (u64::from(FREQUENCY_RESPONSE_SETTLE_PERIODS) + 1) as f64 * f64::from(self.period) * ts,
            csv: (file, c.to_csv(&self.layout)),
        })
    }
}

fn json_number(x: Option<f64>) -> String {
    match x {
        Some(v) if v.is_finite() => format!("{v:.6}"),
        _ => "null".into(),
    }
}

fn json_margins(m: &Margins) -> String {
    format!(
        "{{\"gain_margin_db\": {}, \"phase_margin_deg\": {}, \"crossover_rad_s\": {}}}",
        json_number(m.gain_margin_db),
        json_number(m.phase_margin_deg),
        json_number(m.crossover_rad_s)
    )
}

fn json_plant(p: &PlantModel, determined: Option<bool>) -> String {
    let r = match determined {
        Some(false) => "null".to_string(),
        _ => json_number(Some(p.resistance_ohm)),
    };
    format!(
        "{{\"resistance_ohm\": {r}, \"inductance_h\": {}, \"delay_periods\": {}}}",
        json_number(Some(p.inductance_h)),
        json_number(Some(p.delay_periods))
    )
}

impl Measurement {
    /// `frequency-response-<axis>.json`: the axis, the measured and designed margins and
    /// every point with the designed response at its frequency (phases unwrapped along
    /// the points, in degrees).
    pub fn to_json(&self) -> String {
        let axis = match self.axis {
            Axis::D => "d",
            Axis::Q => "q",
        };
        let (pm, pd) = (unwrapped_phase(&self.points), unwrapped_phase(&self.designed_points));
        let points: Vec<String> = self
            .points
            .iter()
            .zip(&self.designed_points)
            .enumerate()
            .map(|(k, (m, d))| {
                format!(
                    "    {{\"frequency_hz\": {}, \"magnitude_db\": {}, \"phase_deg\": {}, \"designed_magnitude_db\": {}, \"designed_phase_deg\": {}}}",
                    json_number(Some(m.frequency_hz())),
                    json_number(Some(m.magnitude_db())),
                    json_number(pm.get(k).map(|p| p.to_degrees())),
                    json_number(Some(d.magnitude_db())),
                    json_number(pd.get(k).map(|p| p.to_degrees())),
                )
            })
            .collect();
        format!(
            "{{\n  \"axis\": \"{axis}\",\n  \"measured\": {},\n  \"designed\": {},\n  \"fitted_plant\": {},\n  \"designed_plant\": {},\n  \"retune_bandwidth_rad_s\": {},\n  \"amplitude_v\": {},\n  \"trip_a\": {},\n  \"duration_s\": {},\n  \"points\": [\n{}\n  ]\n}}\n",
            json_margins(&self.measured),
            json_margins(&self.designed),
            json_plant(&self.fit.plant, Some(self.fit.resistance_determined)),
            json_plant(&self.design_plant, None),
            json_number(self.retune_rad_s),
            json_number(Some(self.amplitude_v)),
            json_number(Some(self.trip_a)),
            json_number(Some(self.duration_s)),
            points.join(",\n")
        )
    }
}

// ---------------------------------------------------------------------------------
// The sampled loop with any delay, and the plant fitted to the measured points
// ---------------------------------------------------------------------------------

fn c_mul(a: (f64, f64), b: (f64, f64)) -> (f64, f64) {
    (a.0 * b.0 - a.1 * b.1, a.0 * b.1 + a.1 * b.0)
}

fn c_div(a: (f64, f64), b: (f64, f64)) -> (f64, f64) {
    let d = b.0 * b.0 + b.1 * b.1;
    ((a.0 * b.0 + a.1 * b.1) / d, (a.1 * b.0 - a.0 * b.1) / d)
}

/// A plant the loop is modelled with: R \[Ω\], L \[H\] and the loop delay in sample
/// periods (the design's through its request: the board's timing,
/// `codegen::design::timing_of`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlantModel {
    /// R \[Ω\].
    pub resistance_ohm: f64,
    /// L \[H\].
    pub inductance_h: f64,
    /// Loop delay D \[periods\] (≥ 0.5: the ZOH's half period).
    pub delay_periods: f64,
}

/// L(e^{jωT_s}) of gains `g` on `plant` at sample period `ts`: the ZOH-sampled
/// 1/(Ls + R) whose voltage acts τ = D − 1/2 periods after the sample (the ZOH's half
/// period makes the rest of D). With τ = q + x (q whole periods, 0 ≤ x < 1) the voltage
/// v_k acts on [t_k + τ, t_{k+1} + τ), so over one period the current sees v_{n−q−1}
/// for x·T_s, then v_{n−q} (the modified z-transform):
///
/// ```text
/// i_{n+1} = a·i_n + c₁·v_{n−q−1} + c₂·v_{n−q}
/// a  = e^(−R·T_s/L),   c₂ = (1 − e^(−R(1−x)T_s/L))/R,   c₁ = (e^(−R(1−x)T_s/L) − a)/R
/// P(z) = (c₂·z + c₁) / (z^(q+1)·(z − a)),     L(z) = P(z)·(k_p + R_a + k_i·T_s/(z − 1))
/// ```
///
/// At D = 1.5 (q = 1, x = 0) this is the design's b/(z·(z − a)) (`analysis::open_loop`).
pub fn model_point(g: &discrete::LoopGains, plant: &PlantModel, ts: f64, omega: f64) -> Point {
    let (r, l) = (plant.resistance_ohm, plant.inductance_h);
    let tau = (plant.delay_periods - 0.5).max(0.0);
    let q = tau.floor();
    let x = tau - q;
    // c₁, c₂ are the design's b, b₀ at the lag x (`SampledPlant::with_lag`).
    let p = discrete::SampledPlant::with_lag(r, l, ts, x);
    let (a, c1, c2) = (p.a, p.b, p.b0);
    let th = omega * ts;
    let z = (th.cos(), th.sin());
    let zq1 = ((q + 1.0) * th).cos();
    let zq1 = (zq1, ((q + 1.0) * th).sin());
    let num = (c2 * z.0 + c1, c2 * z.1);
    let p = c_div(num, c_mul(zq1, (z.0 - a, z.1)));
    let c = c_div((g.ki * ts, 0.0), (z.0 - 1.0, z.1));
    let c = (c.0 + g.kp + g.active_damping, c.1);
    let lz = c_mul(p, c);
    Point {
        omega_rad_s: omega,
        re: lz.0,
        im: lz.1,
    }
}

/// The margins of gains `g` on `plant` ([`model_point`] on 3000 logarithmic points from
/// 10⁻⁴/T_s to the Nyquist frequency, read as measured points are, [`margins`]).
pub fn model_margins(g: &discrete::LoopGains, plant: &PlantModel, ts: f64) -> Margins {
    let n = 3000;
    let (lo, hi) = ((1e-4 / ts).ln(), (PI / ts).ln());
    let points: Vec<Point> = (0..n)
        .map(|k| model_point(g, plant, ts, (lo + (hi - lo) * k as f64 / (n - 1) as f64).exp()))
        .collect();
    margins(&points)
}

/// The plant fitted to measured points.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fit {
    /// The fitted plant.
    pub plant: PlantModel,
    /// rms of the relative error |L_model − L|/|L| over the points after the fit.
    pub rms_relative_error: f64,
    /// R is determined by the points (its sensitivity is at least 1 % of L's): below the
    /// corner R/L the plant's magnitude is R's; far above it, R hardly shows.
    pub resistance_determined: bool,
}

/// Solves the 3×3 system `a·x = b` (Gaussian elimination with partial pivoting); `None`
/// when singular.
fn solve3(mut a: [[f64; 3]; 3], mut b: [f64; 3]) -> Option<[f64; 3]> {
    for col in 0..3 {
        let piv = (col..3).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[piv][col].abs() < 1e-300 {
            return None;
        }
        a.swap(col, piv);
        b.swap(col, piv);
        let (pivot, pb) = (a[col], b[col]);
        for (row, rb) in a.iter_mut().zip(b.iter_mut()).skip(col + 1) {
            let f = row[col] / pivot[col];
            for (x, p) in row.iter_mut().zip(pivot).skip(col) {
                *x -= f * p;
            }
            *rb -= f * pb;
        }
    }
    let mut x = [0.0; 3];
    for row in (0..3).rev() {
        let s: f64 = (row + 1..3).map(|k| a[row][k] * x[k]).sum();
        x[row] = (b[row] - s) / a[row][row];
    }
    Some(x)
}

/// R, L and the loop delay fitted to `points` with the loop's gains `g` at `ts`:
/// Levenberg–Marquardt on (ln R, ln L, D) (`fit_from`) from `start` and from its
/// delay half a period and one period longer, the fit with the least rms error kept. The
/// delay enters L(e^{jωT_s}) as a phase that grows with ω, so a start on the wrong side
/// of the true delay can settle where a longer inductance trades against a shorter delay
/// (a local minimum: Fischer with its delay × 1.5 from the design's 1.48 periods ended
/// at 1.07 periods and L + 38 %, rms 0.64, against 2.22 periods, rms 0.0055).
pub fn fit_plant(points: &[Point], g: &discrete::LoopGains, ts: f64, start: &PlantModel) -> Fit {
    [0.0, 0.5, 1.0]
        .map(|later| {
            fit_from(
                points,
                g,
                ts,
                &PlantModel {
                    delay_periods: start.delay_periods + later,
                    ..*start
                },
            )
        })
        .into_iter()
        .min_by(|a, b| a.rms_relative_error.total_cmp(&b.rms_relative_error))
        .expect("three starts")
}

/// Levenberg–Marquardt from one `start`, minimising the squared relative errors
/// (L_model − L)/L over the points (real and imaginary parts), numeric Jacobian.
fn fit_from(points: &[Point], g: &discrete::LoopGains, ts: f64, start: &PlantModel) -> Fit {
    let model = |p: [f64; 3]| PlantModel {
        resistance_ohm: p[0].exp(),
        inductance_h: p[1].exp(),
        delay_periods: p[2].max(0.5),
    };
    let residuals = |p: [f64; 3]| -> Vec<f64> {
        let m = model(p);
        points
            .iter()
            .flat_map(|pt| {
                let l = model_point(g, &m, ts, pt.omega_rad_s);
                let e = c_div((l.re - pt.re, l.im - pt.im), (pt.re, pt.im));
                [e.0, e.1]
            })
            .collect()
    };
    let cost = |r: &[f64]| r.iter().map(|x| x * x).sum::<f64>();
    let mut p = [start.resistance_ohm.ln(), start.inductance_h.ln(), start.delay_periods];
    let mut r = residuals(p);
    let mut c = cost(&r);
    let mut lambda = 1e-3;
    let mut jac_norm = [0.0; 3];
    for _ in 0..100 {
        let h = [1e-6, 1e-6, 1e-6];
        let cols: Vec<Vec<f64>> = (0..3)
            .map(|j| {
                let mut q = p;
                q[j] += h[j];
                residuals(q).iter().zip(&r).map(|(a, b)| (a - b) / h[j]).collect()
            })
            .collect();
        let mut jtj = [[0.0; 3]; 3];
        let mut jtr = [0.0; 3];
        for i in 0..3 {
            for k in 0..3 {
                jtj[i][k] = cols[i].iter().zip(&cols[k]).map(|(a, b)| a * b).sum();
            }
            jtr[i] = -cols[i].iter().zip(&r).map(|(a, b)| a * b).sum::<f64>();
            jac_norm[i] = jtj[i][i].sqrt();
        }
        let mut improved = false;
        for _ in 0..20 {
            let mut a = jtj;
            for (i, row) in a.iter_mut().enumerate() {
                row[i] += lambda * jtj[i][i].max(1e-12);
            }
            let Some(step) = solve3(a, jtr) else { break };
            let q = [p[0] + step[0], p[1] + step[1], (p[2] + step[2]).max(0.5)];
            let rq = residuals(q);
            let cq = cost(&rq);
            if cq.is_finite() && cq < c {
                let done = (c - cq) < 1e-14 * c.max(1e-30);
                p = q;
                r = rq;
                c = cq;
                lambda = (lambda / 10.0).max(1e-12);
                improved = !done;
                break;
            }
            lambda *= 10.0;
        }
        if !improved {
            break;
        }
    }
    Fit {
        plant: model(p),
        rms_relative_error: (c / points.len().max(1) as f64).sqrt(),
        resistance_determined: jac_norm[0] >= 0.01 * jac_norm[1],
    }
}

// ---------------------------------------------------------------------------------
// The simulated plant, perturbed (`--sim-scale KEY=FACTOR`)
// ---------------------------------------------------------------------------------

/// Factors on the simulated plant: R, L_d, L_q and the loop delay (1: as designed).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimScale {
    /// Factor on R.
    pub resistance: f64,
    /// Factor on L_d.
    pub ld: f64,
    /// Factor on L_q.
    pub lq: f64,
    /// Factor on the loop delay.
    pub delay: f64,
}

impl Default for SimScale {
    fn default() -> Self {
        SimScale {
            resistance: 1.0,
            ld: 1.0,
            lq: 1.0,
            delay: 1.0,
        }
    }
}

impl SimScale {
    /// `KEY=FACTOR` options (`R`, `Ld`, `Lq`, `delay`; a key given twice is refused).
    /// `design_delay` is the design's loop delay \[periods\]: the perturbed delay
    /// `delay`·design_delay must lie within what the simulated bench makes
    /// ([`motor_sim::plant::SIMULATED_LOOP_DELAY`]), which [`SimScale::apply`] sets.
    pub fn parse(options: &[String], design_delay: f64) -> Result<SimScale, Error> {
        let accepted = "KEY=FACTOR with KEY one of R, Ld, Lq, delay and a factor from 0.1 to 10, e.g. Lq=0.7";
        let mut s = SimScale::default();
        let mut seen: Vec<&str> = Vec::new();
        for o in options {
            let bad = |p: String| bad_option("--sim-scale", p, accepted);
            let (key, value) = o.split_once('=').ok_or_else(|| bad(format!("`{o}` has no `=`")))?;
            let f: f64 = value
                .trim()
                .parse()
                .ok()
                .filter(|f: &f64| f.is_finite() && (0.1..=10.0).contains(f))
                .ok_or_else(|| bad(format!("`{value}` is not a factor from 0.1 to 10")))?;
            let key = key.trim();
            if seen.contains(&key) {
                return Err(bad(format!("`{key}` is given twice")));
            }
            match key {
                "R" => s.resistance = f,
                "Ld" => s.ld = f,
                "Lq" => s.lq = f,
                "delay" => {
                    let d = f * design_delay;
                    let (lo, hi) = motor_sim::plant::SIMULATED_LOOP_DELAY;
                    if d <= lo || d >= hi {
                        return Err(bad_option(
                            "--sim-scale",
                            format!(
                                "delay={value} makes the loop delay {d:.3} periods; the simulated bench delays from above {lo} to below {hi} periods"
                            ),
                            &format!(
                                "a delay factor from above {:.3} to below {:.3}",
                                lo / design_delay,
                                hi / design_delay
                            ),
                        ));
                    }
                    s.delay = f;
                }
                _ => return Err(bad(format!("`{key}` is not a key"))),
            }
            seen.push(key);
        }
        Ok(s)
    }

    /// The plant of `axis` perturbed: the design's R, L and delay times the factors.
    pub fn plant_of(&self, d: &Design, axis: Axis) -> PlantModel {
        let req = d.current_loop_request(axis);
        let l = match axis {
            Axis::D => self.ld,
            Axis::Q => self.lq,
        };
        PlantModel {
            resistance_ohm: req.resistance_ohm * self.resistance,
            inductance_h: req.inductance_h * l,
            delay_periods: req.loop_delay_s / req.sample_period_s * self.delay,
        }
    }

    /// Perturbs the simulated `plant` (its motor's R, L_d, L_q; its loop delay,
    /// [`motor_sim::plant::Plant::loop_delay_periods`]) for a design whose loop delay is
    /// `design_delay` periods.
    pub fn apply(&self, plant: &mut motor_sim::plant::Plant, design_delay: f64) {
        plant.motor.resistance *= self.resistance;
        plant.motor.ld *= self.ld;
        plant.motor.lq *= self.lq;
        plant.motor.q_saturation.iter_mut().for_each(|(_, l)| *l *= self.lq);
        plant.loop_delay_periods = self.delay * design_delay;
    }
}

// ---------------------------------------------------------------------------------
// What to change: the retune and the values for the spec
// ---------------------------------------------------------------------------------

/// The phase and gain margins of `g` on `plant` meet the design's floors
/// (`analysis::MIN_PHASE_MARGIN_DEG`, `analysis::MIN_GAIN_MARGIN_DB`).
fn meets_floors(g: &discrete::LoopGains, plant: &PlantModel, ts: f64) -> bool {
    let m = model_margins(g, plant, ts);
    m.phase_margin_deg
        .is_some_and(|pm| pm >= analysis::MIN_PHASE_MARGIN_DEG)
        && m.gain_margin_db.is_none_or(|gm| gm >= analysis::MIN_GAIN_MARGIN_DB)
}

/// The retune: the largest bandwidth α whose gains, designed by the spec's method (and
/// delay compensation) for the fitted R and L, meet the margin floors on the fitted
/// plant with its delay. Scanned on 48 logarithmic steps from α/100 to a quarter of the
/// sampling frequency π/(2·T_s), then refined by bisection between the last step that
/// meets the floors and the next; `None` when none does (the top of the scan when all
/// do).
pub fn retune(d: &Design, axis: Axis, plant: &PlantModel) -> Option<f64> {
    let req = d.current_loop_request(axis);
    let ts = req.sample_period_s;
    let ok = |alpha: f64| {
        let r = codegen::design::current_loop::Request {
            resistance_ohm: plant.resistance_ohm,
            inductance_h: plant.inductance_h,
            ..req.at_bandwidth(alpha)
        };
        codegen::design::current_loop::design(&r).is_ok_and(|g| meets_floors(&g.loop_gains(), plant, ts))
    };
    let (lo, hi) = ((req.bandwidth_rad_s / 100.0).ln(), (0.5 * PI / ts).ln());
    let steps = 48;
    let at = |k: usize| (lo + (hi - lo) * k as f64 / steps as f64).exp();
    let last = (0..=steps).rev().find(|&k| ok(at(k)))?;
    if last == steps {
        return Some(at(steps));
    }
    let (mut a, mut b) = (at(last), at(last + 1));
    for _ in 0..20 {
        let m = (a * b).sqrt();
        if ok(m) { a = m } else { b = m }
    }
    Some(a)
}

impl Measurement {
    /// What the measurement says, one line each: measured against designed margins; the
    /// fitted plant against the design's, the values off by more than 5 % named; the
    /// retune.
    pub fn summary(&self) -> String {
        let f = |x: Option<f64>, unit: &str| x.map_or_else(|| "not measured".into(), |v| format!("{v:.2}{unit}"));
        let axis = match self.axis {
            Axis::D => "d",
            Axis::Q => "q",
        };
        let (m, d) = (&self.measured, &self.designed);
        let mut out = format!(
            "{axis} axis: gain margin {} (designed {}), phase margin {} (designed {}), crossover {} (designed {})\n",
            f(m.gain_margin_db, " dB"),
            f(d.gain_margin_db, " dB"),
            f(m.phase_margin_deg, "°"),
            f(d.phase_margin_deg, "°"),
            f(m.crossover_rad_s, " rad/s"),
            f(d.crossover_rad_s, " rad/s"),
        );
        let (p, q) = (&self.fit.plant, &self.design_plant);
        let pct = |a: f64, b: f64| 100.0 * (a / b - 1.0);
        let r = if self.fit.resistance_determined {
            format!(
                "R {:.4} Ω ({:+.1} %)",
                p.resistance_ohm,
                pct(p.resistance_ohm, q.resistance_ohm)
            )
        } else {
            "R not determined (the lines lie far above R/L)".into()
        };
        out.push_str(&format!(
            "fitted plant: {r}, L_{axis} {:.4} mH ({:+.1} %), loop delay {:.3} periods ({:+.1} %); rms fit error {:.2} %\n",
            p.inductance_h * 1e3,
            pct(p.inductance_h, q.inductance_h),
            p.delay_periods,
            pct(p.delay_periods, q.delay_periods),
            100.0 * self.fit.rms_relative_error
        ));
        let mut off = vec![];
        if self.fit.resistance_determined && pct(p.resistance_ohm, q.resistance_ohm).abs() > 5.0 {
            off.push(format!(
                "R is {:+.1} % off the spec",
                pct(p.resistance_ohm, q.resistance_ohm)
            ));
        }
        if pct(p.inductance_h, q.inductance_h).abs() > 5.0 {
            off.push(format!(
                "L_{axis} is {:+.1} % off the spec",
                pct(p.inductance_h, q.inductance_h)
            ));
        }
        if pct(p.delay_periods, q.delay_periods).abs() > 5.0 {
            off.push(format!(
                "the loop delay is {:+.1} % off the design's (the board's timing)",
                pct(p.delay_periods, q.delay_periods)
            ));
        }
        out.push_str(&if off.is_empty() {
            "the design's plant holds (R, L and delay within 5 %)\n".to_string()
        } else {
            format!("{}\n", off.join("; "))
        });
        out.push_str(&match self.retune_rad_s {
            Some(a) => format!(
                "retune: current_loop.bandwidth up to {a:.0} rad/s meets the margin floors on the measured plant\n"
            ),
            None => "retune: no bandwidth meets the margin floors on the measured plant\n".into(),
        });
        out
    }

    /// The values for `[motor.identified]` (`--write`): the axis's L, and R when the
    /// points determine it.
    pub fn entries(&self) -> Vec<writeback::Entry> {
        let p = &self.fit.plant;
        let (axis, key) = match self.axis {
            Axis::D => ("d", "d_inductance"),
            Axis::Q => ("q", "q_inductance"),
        };
        let note = format!(
            "fitted to the {axis}-axis frequency response (loop delay {:.3} periods, rms error {:.2} %)",
            p.delay_periods,
            100.0 * self.fit.rms_relative_error
        );
        let mut e = vec![];
        if self.fit.resistance_determined {
            e.push(writeback::Entry {
                key: "phase_resistance",
                value: writeback::ohms(p.resistance_ohm),
                note: note.clone(),
            });
        }
        e.push(writeback::Entry {
            key,
            value: writeback::henries(p.inductance_h),
            note,
        });
        e
    }
}
