//! The pre-flight check before the current loop closes (issue 26, item 2), as a pure
//! state machine stepped once per control period like the chapter-6 routines
//! ([`crate::commissioning`]): it answers the open-loop voltage to apply, or its
//! verdict. Nothing but the pulses and the rotation below is ever applied; the board
//! switches the outputs off at the verdict and a failure becomes a fault record with
//! the [`PreflightFault`]'s own cause.
//!
//! Why more than one pulse (the physics of a star-connected R-L-EMF load at standstill):
//! a d-axis voltage pulse at the resolver's angle shows inverted current sensing (the
//! measured i_d has the wrong sign), a wrong R (the steady current), a wrong L (the
//! rise), a sensor gain or offset fault (the three currents do not sum to zero) and an
//! open phase whose axis is within 60° of the pulse (its expected current ∝ cos of that
//! angle). It cannot show two swapped motor leads (a symmetric star load draws the same
//! leg currents whatever the lead order), an open phase near 90° to the pulse, a wrong
//! pole-pair count or a resolver offset on a non-salient machine (the current follows
//! the voltage in any frame). Those need the rotor to move: a slow open-loop rotation of
//! the voltage vector by one electrical turn with the rotor free (thesis A §6.4, its
//! direction check; ODrive's and moteus's encoder calibration do the same) — every
//! phase then carries its peak current at some angle, the resolver must turn in the
//! commanded direction at the ratio n_r/n_p, and the rotor must come to rest at the
//! commanded electrical angle.
//!
//! The sequence, all periods counted from the command — the rotation first, because a
//! pulse "on d" at a resolver angle that is wrong by 90° is a torque pulse that sets a
//! free rotor turning (its back EMF would then spoil every pulse figure); after the
//! rotation the rotor rests at the resolver's angle, checked, and the pulses are
//! torque-free:
//! 1. **Rotation**: the αβ voltage [`Preflight::rotation_voltage`] held at the
//!    resolver's θ_e for [`Preflight::settle_samples`] (the rotor aligns), turned by one
//!    electrical turn at [`Preflight::rotation_step`] per period, held again for
//!    `settle_samples`. Judged at the end of the first hold (the rotor at rest, the
//!    current settled): the current along the held voltage, averaged over the last
//!    [`Preflight::average_samples`], not below −[`Preflight::open_fraction`] of the
//!    least current the rotation draws, else [`PreflightFault::InvertedSensing`] — a
//!    passive load's current has a component along its voltage whatever the lead order,
//!    so inverted sensing is refused before the turn. Judged after the turn:
//!    * every phase's largest |i| during the turn ≥ [`Preflight::open_fraction`] of the
//!      least current the rotation draws (V_rot·ρ_R⁻¹/R), else
//!      [`PreflightFault::OpenPhase`];
//!    * the resolver travelled at least a quarter of the expected n_r/n_p turn, else
//!      [`PreflightFault::PolePairRatio`] (the rotor did not follow);
//!    * it travelled in the commanded direction, else [`PreflightFault::Direction`]
//!      (two motor leads swapped, or the resolver's windings);
//!    * the ratio turned/travelled is n_p/n_r within [`Preflight::ratio_bound`], else
//!      [`PreflightFault::PolePairRatio`];
//!    * the resolver's electrical angle at the end, averaged over the last
//!      [`Preflight::average_samples`], lies within [`Preflight::angle_bound`] of the
//!      commanded one, else [`PreflightFault::ResolverOffset`].
//! 2. **Pulses** `+` then `−` at the resolver's θ_e (now the rotor's d axis), each two
//!    levels `V/2` then `V` of [`Preflight::level_samples`] periods, then
//!    [`Preflight::rest_samples`] at 0 V (the current decays through the bridge's zero
//!    vectors). The current is read along the pulse (i_α cos θ + i_β sin θ of the phase
//!    currents, (2.7)); at the end of each level the last `average_samples` periods are
//!    averaged. Judged in this order:
//!    * sign: the current has the commanded sign, else
//!      [`PreflightFault::InvertedSensing`] (what the first hold's margin lets pass:
//!      one phase's sensing inverted, the current along the voltage then between −⅓
//!      and 1 of its true size with the angle, or a hold current below the margin);
//!    * sum: |i_u + i_v + i_w| ≤ [`Preflight::sum_bound`] (three measured phases only),
//!      else [`PreflightFault::CurrentSum`];
//!    * open phase: every phase whose axis lies within 60° of the pulse (|cos| ≥ 1/2)
//!      carries at least `open_fraction` of its share I·cos(θ − 2πk/3), else
//!      [`PreflightFault::OpenPhase`];
//!    * R = (V − V/2)/(I_2 − I_1): the difference of the two levels, so the bridge's
//!      dead-time voltage (the same for both levels of one sign) drops out, within
//!      [`Preflight::resistance_ratio`] of the spec's, else
//!      [`PreflightFault::Resistance`];
//!    * L = R·τ from the area between the second level's final value and its rise,
//!      τ = T_s·Σ(I_2 − i_k)/(I_2 − I_1) − [`Preflight::tau_offset`] (a first-order
//!      response's area is τ·ΔI), within [`Preflight::inductance_ratio`], else
//!      [`PreflightFault::Inductance`].
//!
//! Any |phase current| above [`Preflight::current_trip`] (more than the lowest accepted
//! R would draw) ends the check at once as [`PreflightFault::Resistance`].
//!
//! A refusal ([`Refusal`]) carries the figure it judged ([`FaultMeasurement`]: value and
//! index), which the fault record keeps and the CAN fault report sends:
//!
//! | fault | value | index |
//! |---|---|---|
//! | 11 inverted sensing | the current along the voltage \[A\] (≤ 0 or below the hold's margin) | 0 the first hold, 1 the + pulse, 2 the − pulse |
//! | 12 resistance | R \[Ω\] of the pulse (negative or infinite when the second level drew no more than the first) | 0 + pulse, 1 − pulse; 3: the largest \|phase current\| \[A\] beyond `current_trip` |
//! | 13 inductance | L \[H\] of the pulse | 0 + pulse, 1 − pulse |
//! | 14 current sum | \|i_u + i_v + i_w\| \[A\] | 0 + pulse, 1 − pulse |
//! | 15 open phase | the phase's \|current\| \[A\]: at the pulse's end, or its peak during the turn | the phase: 0 u, 1 v, 2 w |
//! | 16 direction | resolver travel / the expected n_r/n_p turn (negative) | 0 |
//! | 17 pole-pair ratio | the measured n_p/n_r (turned/travelled; infinite if the resolver did not move) | 0 |
//! | 18 resolver offset | θ_e(resolver) − θ_commanded at rest \[° electrical\] | 0 |

use crate::can_protocol::FaultMeasurement;
use crate::commissioning::Progress;
use crate::step::Demand;
use crate::transforms::{AlphaBeta, INV_SQRT_3, TWO_THIRDS, Uvw};
use crate::trig::Trig;

/// One electrical turn in π-scaled Q1.31 LSB.
const TURN: i64 = 1 << 32;
/// A third of a turn (2π/3) in π-scaled LSB (wrapping arithmetic).
const THIRD: i32 = 0x5555_5555;

/// Why the pre-flight check refused the drive. The numbers are the fault record's
/// causes (`motor_config::fault_record::FaultCause`, 11–18).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum PreflightFault {
    /// The measured current has the wrong sign: the current sensing is inverted.
    InvertedSensing = 11,
    /// R from the pulses (or a current above what the lowest accepted R would draw)
    /// outside the bound of the spec's R.
    Resistance = 12,
    /// L from the pulse's rise outside the bound of the spec's L_d.
    Inductance = 13,
    /// The three measured phase currents do not sum to zero.
    CurrentSum = 14,
    /// A phase carried less than its share of the current: an open phase (lead,
    /// connector, winding) or a dead sensor.
    OpenPhase = 15,
    /// The resolver turned against the rotating field: two motor leads swapped (or
    /// the resolver's SIN/COS).
    Direction = 16,
    /// The rotor did not follow, or the resolver turned by another ratio than
    /// n_r/n_p: a wrong pole-pair count.
    PolePairRatio = 17,
    /// The rotor came to rest away from the commanded electrical angle: the resolver
    /// offset is wrong.
    ResolverOffset = 18,
}

impl PreflightFault {
    /// The fault-record cause number.
    pub fn code(self) -> u8 {
        self as u8
    }

    /// A refusal for this fault with the figure it judged (module documentation).
    fn measured(self, measured: FaultMeasurement) -> Refusal {
        Refusal { fault: self, measured }
    }
}

/// The pre-flight check's refusal: which check failed and what it measured (the table
/// in the module documentation gives each fault's figure and unit).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Refusal {
    /// The check that failed.
    pub fault: PreflightFault,
    /// The figure it judged.
    pub measured: FaultMeasurement,
}

/// Degrees per π-scaled Q1.31 LSB (180°/2^31).
const DEGREES_PER_LSB: f32 = 180.0 / 2_147_483_648.0;

/// The check's fixed parameters (generated: codegen's `commissioning` group,
/// `PREFLIGHT_*`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Preflight {
    /// The pulses' second level V \[V\] (the first is V/2).
    pub voltage: f32,
    /// Periods of each level.
    pub level_samples: u32,
    /// Periods at 0 V after each pulse.
    pub rest_samples: u32,
    /// Periods averaged at the end of a level or hold (≥ 1, ≤ the level's).
    pub average_samples: u32,
    /// The spec's R \[Ω\].
    pub resistance: f32,
    /// The spec's L_d \[H\].
    pub inductance: f32,
    /// Accepted R between R/ρ and R·ρ (ρ > 1).
    pub resistance_ratio: f32,
    /// Accepted L between L/ρ and L·ρ.
    pub inductance_ratio: f32,
    /// Any |phase current| above this ends the check \[A\].
    pub current_trip: f32,
    /// Largest accepted |i_u + i_v + i_w| \[A\]; 0 disables the sum (two measured phases:
    /// the third is computed from them).
    pub sum_bound: f32,
    /// A phase must carry at least this fraction of its expected current.
    pub open_fraction: f32,
    /// T_s \[s\].
    pub sample_period: f32,
    /// Subtracted from the rise's area/ΔI to give τ \[s\]: the loop delay from a demand
    /// to its effect plus T_s/2 (the area is a left-rectangle sum from the sample of the
    /// period that computed the step).
    pub tau_offset: f32,
    /// The rotation's αβ voltage \[V\].
    pub rotation_voltage: f32,
    /// Electrical angle per period of the rotation (π-scaled Q1.31, > 0).
    pub rotation_step: i32,
    /// Periods held before and after the turn.
    pub settle_samples: u32,
    /// n_p/n_r expected.
    pub ratio: f32,
    /// Largest accepted |measured − expected| of n_p/n_r.
    pub ratio_bound: f32,
    /// Largest accepted |θ_e(resolver) − θ_commanded| at rest after the turn
    /// (π-scaled Q1.31).
    pub angle_bound: i32,
}

/// What the check reads each period (the previous control step's measurements).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PreflightInput {
    /// Phase currents \[A\].
    pub i_uvw: Uvw,
    /// The resolver's electrical angle θ_e (π-scaled Q1.31).
    pub theta_e: i32,
    /// The observed resolver angle θ_r (π-scaled Q1.31).
    pub theta_r: i32,
}

/// What the two pulses measured (for the report and the tests).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PulseFigures {
    /// R \[Ω\] of the + and − pulse.
    pub resistance: [f32; 2],
    /// L \[H\] of the + and − pulse.
    pub inductance: [f32; 2],
    /// Largest |i_u + i_v + i_w| at the levels' ends \[A\].
    pub sum: f32,
}

/// Where the sequence stands.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
enum Stage {
    /// Held at the rotation's start angle.
    #[default]
    Hold,
    /// Turning.
    Turn,
    /// Held at the end angle.
    EndHold,
    /// Pulse `pulse` (0 = +, 1 = −), level `level` (0, 1) or the rest (2).
    Pulse,
}

/// State of [`Preflight`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PreflightState {
    stage: Stage,
    started: bool,
    pulse: u8,
    level: u8,
    /// Periods into the current level/hold.
    n: u32,
    /// The pulses' angle (the resolver's θ_e when they started).
    angle: i32,
    /// Σ current along the pulse over the averaged periods.
    sum_i: f32,
    /// Σ i_u, i_v, i_w over the averaged periods.
    sum_uvw: [f32; 3],
    /// Σ current along the pulse over the whole second level (for τ).
    area: f32,
    /// I_1 of this pulse.
    first: f32,
    figures: PulseFigures,
    /// The rotation's start angle and the angle generated so far (unwrapped).
    start: i32,
    generated: i64,
    /// Resolver travel (unwrapped) and the last θ_r.
    travelled: i64,
    previous_r: i32,
    /// Largest |i| per phase during the turn.
    peak: [f32; 3],
    /// Σ (θ_e − θ_commanded) over the final averaged periods (π-scaled LSB).
    angle_error: i64,
}

impl PreflightState {
    /// The pulses' figures so far.
    pub fn figures(&self) -> PulseFigures {
        self.figures
    }
}

/// `x ≥ min`, false for NaN.
fn at_least(x: f32, min: f32) -> bool {
    x >= min
}

/// `x ≤ max`, false for NaN.
fn at_most(x: f32, max: f32) -> bool {
    x <= max
}

/// `x` with the pulse's sign (pulse 0 positive, 1 negative).
fn signed(pulse: u8, x: f32) -> f32 {
    if pulse == 0 { x } else { -x }
}

/// The current `i` along the angle `angle`: i_α cos θ + i_β sin θ of the phase
/// currents, (2.7).
fn along<T: Trig>(trig: &mut T, angle: i32, i: Uvw) -> f32 {
    let sc = trig.sin_cos(angle).to_f32();
    let alpha = TWO_THIRDS * (i.u - 0.5 * (i.v + i.w));
    let beta = INV_SQRT_3 * (i.v - i.w);
    alpha * sc.cos + beta * sc.sin
}

/// The open-loop αβ voltage of magnitude `v` at angle `angle`.
fn at_angle<T: Trig>(trig: &mut T, angle: i32, v: f32) -> Progress<Result<PulseFigures, Refusal>> {
    let sc = trig.sin_cos(angle).to_f32();
    Progress::Running(Demand::VoltageAlphaBeta(AlphaBeta {
        alpha: v * sc.cos,
        beta: v * sc.sin,
    }))
}

impl Preflight {
    /// Periods of the whole check (an upper bound: the turn rounded up).
    pub fn periods(&self) -> u64 {
        let pulse = u64::from(self.level_samples)
            .saturating_mul(2)
            .saturating_add(u64::from(self.rest_samples));
        let turn = TURN
            .checked_div(i64::from(self.rotation_step.max(1)))
            .unwrap_or(TURN)
            .unsigned_abs()
            .saturating_add(1);
        pulse
            .saturating_mul(2)
            .saturating_add(turn)
            .saturating_add(u64::from(self.settle_samples).saturating_add(1).saturating_mul(2))
            .saturating_add(1)
    }

    /// One period with what the previous control step measured: the voltage to apply,
    /// or the verdict (the pulses' figures when every check passed).
    pub fn process<T: Trig>(
        &self,
        st: &mut PreflightState,
        trig: &mut T,
        m: &PreflightInput,
    ) -> Progress<Result<PulseFigures, Refusal>> {
        // Beyond what the lowest accepted R would draw (NaN trips too).
        let trip = |i: f32| !at_most(libm::fabsf(i), self.current_trip);
        if trip(m.i_uvw.u) || trip(m.i_uvw.v) || trip(m.i_uvw.w) {
            let [u, v, w] = [m.i_uvw.u, m.i_uvw.v, m.i_uvw.w].map(libm::fabsf);
            // The largest (NaN when one is: `max` would drop it).
            let peak = if u.is_nan() || v.is_nan() || w.is_nan() {
                f32::NAN
            } else {
                u.max(v).max(w)
            };
            return Progress::Finished(Err(PreflightFault::Resistance.measured(FaultMeasurement::at(peak, 3))));
        }
        if !st.started {
            st.started = true;
            st.start = m.theta_e;
            st.previous_r = m.theta_r;
            return at_angle(trig, st.start, self.rotation_voltage);
        }
        match st.stage {
            Stage::Pulse => self.pulse(st, trig, m),
            Stage::Hold | Stage::Turn | Stage::EndHold => self.rotation(st, trig, m),
        }
    }

    /// Averaged periods at the end of a level or hold of `of` periods.
    fn averaged(&self, of: u32) -> u32 {
        self.average_samples.clamp(1, of.max(1))
    }

    /// The rotation: hold, turn, hold, its verdict; then the first pulse.
    fn rotation<T: Trig>(
        &self,
        st: &mut PreflightState,
        trig: &mut T,
        m: &PreflightInput,
    ) -> Progress<Result<PulseFigures, Refusal>> {
        let d = m.theta_r.wrapping_sub(st.previous_r);
        st.previous_r = m.theta_r;
        st.n = st.n.saturating_add(1);
        match st.stage {
            Stage::Hold => {
                let average = self.averaged(self.settle_samples);
                if st.n > self.settle_samples.saturating_sub(average) {
                    for (s, i) in st.sum_uvw.iter_mut().zip([m.i_uvw.u, m.i_uvw.v, m.i_uvw.w]) {
                        *s += i;
                    }
                }
                if st.n >= self.settle_samples {
                    if let Err(f) = self.hold_verdict(st, trig, average) {
                        return Progress::Finished(Err(f));
                    }
                    st.stage = Stage::Turn;
                    st.n = 0;
                }
            }
            Stage::Turn => {
                st.travelled = st.travelled.saturating_add(i64::from(d));
                for (p, i) in st.peak.iter_mut().zip([m.i_uvw.u, m.i_uvw.v, m.i_uvw.w]) {
                    *p = p.max(libm::fabsf(i));
                }
                if st.generated >= TURN {
                    st.stage = Stage::EndHold;
                    st.n = 0;
                } else {
                    let step = i64::from(self.rotation_step.max(1)).min(TURN.saturating_sub(st.generated));
                    st.generated = st.generated.saturating_add(step);
                }
            }
            Stage::EndHold | Stage::Pulse => {
                st.travelled = st.travelled.saturating_add(i64::from(d));
                let average = self.averaged(self.settle_samples);
                if st.n > self.settle_samples.saturating_sub(average) {
                    let commanded = st.start.wrapping_add(st.generated as i32);
                    st.angle_error = st
                        .angle_error
                        .saturating_add(i64::from(m.theta_e.wrapping_sub(commanded)));
                }
                if st.n >= self.settle_samples {
                    if let Err(f) = self.rotation_verdict(st, average) {
                        return Progress::Finished(Err(f));
                    }
                    st.stage = Stage::Pulse;
                    st.n = 0;
                    st.angle = m.theta_e;
                    return at_angle(trig, st.angle, 0.5 * self.voltage);
                }
            }
        }
        // The generated angle modulo one turn (truncation is the wrap).
        at_angle(trig, st.start.wrapping_add(st.generated as i32), self.rotation_voltage)
    }

    /// The least current the rotation's voltage draws: V_rot at the highest accepted R.
    fn least_rotation_current(&self) -> f32 {
        self.rotation_voltage / (self.resistance * self.resistance_ratio)
    }

    /// The first hold's end: the current along the held voltage, averaged over its last
    /// periods, must not be opposite to it. A star-connected R-L load at rest draws its
    /// current along the voltage (v·i = R·|i|² ≥ 0 once the rise is over, whatever the
    /// lead order), at least [`Self::least_rotation_current`] with every phase connected
    /// and down to 0 with one open at 90° to the voltage; measured at less than
    /// −`open_fraction` of that least current, the sensing is inverted. Judged here,
    /// before the turn, rather than only at the pulses 1–3 s later.
    fn hold_verdict<T: Trig>(&self, st: &mut PreflightState, trig: &mut T, average: u32) -> Result<(), Refusal> {
        let n = average.max(1) as f32;
        let [u, v, w] = st.sum_uvw.map(|s| s / n);
        st.sum_uvw = [0.0; 3];
        let i = along(trig, st.start, Uvw { u, v, w });
        if !at_least(i, -self.open_fraction * self.least_rotation_current()) {
            return Err(PreflightFault::InvertedSensing.measured(FaultMeasurement::of(i)));
        }
        Ok(())
    }

    fn rotation_verdict(&self, st: &PreflightState, average: u32) -> Result<(), Refusal> {
        let least = self.least_rotation_current();
        if let Some((k, &p)) = (0u8..)
            .zip(&st.peak)
            .find(|&(_, &p)| !at_least(p, self.open_fraction * least))
        {
            return Err(PreflightFault::OpenPhase.measured(FaultMeasurement::at(p, k)));
        }
        // Expected resolver travel: one electrical turn · n_r/n_p.
        let expected_travel = TURN as f32 / self.ratio;
        let travelled = st.travelled as f32;
        // Turned/travelled: the measured n_p/n_r (±∞ when the resolver did not move).
        let ratio = st.generated as f32 / travelled;
        if !at_least(libm::fabsf(travelled), 0.25 * expected_travel) {
            return Err(PreflightFault::PolePairRatio.measured(FaultMeasurement::of(ratio)));
        }
        if travelled < 0.0 {
            return Err(PreflightFault::Direction.measured(FaultMeasurement::of(travelled / expected_travel)));
        }
        if !at_most(libm::fabsf(ratio - self.ratio), self.ratio_bound) {
            return Err(PreflightFault::PolePairRatio.measured(FaultMeasurement::of(ratio)));
        }
        let error = st.angle_error.checked_div(i64::from(average.max(1))).unwrap_or(0);
        if error.unsigned_abs() > u64::from(self.angle_bound.unsigned_abs()) {
            return Err(PreflightFault::ResolverOffset.measured(FaultMeasurement::of(error as f32 * DEGREES_PER_LSB)));
        }
        Ok(())
    }

    /// The pulses: two levels and a rest per sign, each level judged at its end.
    fn pulse<T: Trig>(
        &self,
        st: &mut PreflightState,
        trig: &mut T,
        m: &PreflightInput,
    ) -> Progress<Result<PulseFigures, Refusal>> {
        let levels = self.level_samples.max(1);
        if st.level < 2 {
            // Sample n of this level: taken in the period that computed the level's
            // n-th demand (index 0: before the level's voltage acts). The current along
            // the pulse ([`along`]).
            let i = m.i_uvw;
            let on_pulse = along(trig, st.angle, i);
            let average = self.averaged(levels);
            if st.level == 1 {
                st.area += on_pulse;
            }
            if st.n >= levels.saturating_sub(average) {
                st.sum_i += on_pulse;
                for (s, i) in st.sum_uvw.iter_mut().zip([i.u, i.v, i.w]) {
                    *s += i;
                }
            }
            st.n = st.n.saturating_add(1);
            if st.n >= levels {
                let n = average as f32;
                let mean = st.sum_i / n;
                let uvw = st.sum_uvw.map(|s| s / n);
                st.sum_i = 0.0;
                st.sum_uvw = [0.0; 3];
                if let Err(f) = self.judge_level(st, trig, mean, uvw) {
                    return Progress::Finished(Err(f));
                }
                st.level = st.level.saturating_add(1);
                st.n = 0;
            }
        } else {
            st.n = st.n.saturating_add(1);
            if st.n >= self.rest_samples {
                if st.pulse != 0 {
                    return Progress::Finished(Ok(st.figures));
                }
                st.pulse = 1;
                st.level = 0;
                st.n = 0;
                st.area = 0.0;
            }
        }
        let v = match st.level {
            0 => 0.5 * self.voltage,
            1 => self.voltage,
            _ => 0.0,
        };
        at_angle(trig, st.angle, signed(st.pulse, v))
    }

    /// The end of a level: the sign at both, everything else at the second.
    fn judge_level<T: Trig>(
        &self,
        st: &mut PreflightState,
        trig: &mut T,
        mean: f32,
        uvw: [f32; 3],
    ) -> Result<(), Refusal> {
        let i = signed(st.pulse, mean);
        // The figures' index: the pulse (0 +, 1 −).
        let k = st.pulse.min(1);
        if !at_least(i, f32::MIN_POSITIVE) {
            return Err(PreflightFault::InvertedSensing.measured(FaultMeasurement::at(i, k.saturating_add(1))));
        }
        if st.level == 0 {
            st.first = i;
            return Ok(());
        }
        let sum = libm::fabsf(uvw.iter().sum::<f32>());
        st.figures.sum = st.figures.sum.max(sum);
        if self.sum_bound > 0.0 && !at_most(sum, self.sum_bound) {
            return Err(PreflightFault::CurrentSum.measured(FaultMeasurement::at(sum, k)));
        }
        // Open phase: the phases within 60° of the pulse carry their share.
        let mut axis = st.angle;
        for (phase, measured) in (0u8..).zip(uvw) {
            let c = trig.sin_cos(axis).to_f32().cos;
            axis = axis.wrapping_sub(THIRD);
            let expected = mean * c;
            if libm::fabsf(c) >= 0.5 && !at_least(libm::fabsf(measured), self.open_fraction * libm::fabsf(expected)) {
                return Err(PreflightFault::OpenPhase.measured(FaultMeasurement::at(libm::fabsf(measured), phase)));
            }
        }
        let rise = i - st.first;
        let r = 0.5 * self.voltage / rise;
        if let Some(slot) = st.figures.resistance.get_mut(usize::from(k)) {
            *slot = r;
        }
        let within = |x: f32, nominal: f32, ratio: f32| x >= nominal / ratio && x <= nominal * ratio;
        if !(rise > 0.0 && within(r, self.resistance, self.resistance_ratio)) {
            return Err(PreflightFault::Resistance.measured(FaultMeasurement::at(r, k)));
        }
        // τ = T_s·Σ(I_2 − i_k)/(I_2 − I_1) − offset over the level's samples.
        let area = self.level_samples.max(1) as f32 * i - signed(st.pulse, st.area);
        let tau = self.sample_period * area / rise - self.tau_offset;
        let l = r * tau;
        if let Some(slot) = st.figures.inductance.get_mut(usize::from(k)) {
            *slot = l;
        }
        if !within(l, self.inductance, self.inductance_ratio) {
            return Err(PreflightFault::Inductance.measured(FaultMeasurement::at(l, k)));
        }
        Ok(())
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A motor of R = 0.1 Ω, L = 1 mH at T_s = 50 µs; 1 V pulses (10 A), 4 ms levels.
    pub(crate) const EXAMPLE: Preflight = Preflight {
        voltage: 1.0,
        level_samples: 200,
        rest_samples: 200,
        average_samples: 20,
        resistance: 0.1,
        inductance: 1e-3,
        resistance_ratio: 2.0,
        inductance_ratio: 2.0,
        current_trip: 25.0,
        sum_bound: 1.0,
        open_fraction: 0.5,
        sample_period: 50e-6,
        tau_offset: 100e-6,
        rotation_voltage: 1.0,
        rotation_step: 1 << 24,
        settle_samples: 100,
        ratio: 4.0,
        ratio_bound: 0.5,
        angle_bound: 1 << 29,
    };
}
