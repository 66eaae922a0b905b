//! The commissioning mode (pure): which chapter-6 routine runs, when a CAN command may
//! start one, what it captures and how the capture leaves the board as frames.
//!
//! * A command ([`crate::can_protocol::Command`]) starts a routine only with a zero
//!   torque setpoint, no fault and — except the ψ_M run — at standstill
//!   (|ω_e| ≤ [`ModeConfig::standstill_speed`]); otherwise it is refused and the status
//!   frame gives the [`Reason`]. The ψ_M run (§6.5) needs the rotor turned by the
//!   dynamometer, so it is the one routine accepted at speed (and refused below the
//!   routine's minimum speed at the end, as [`FluxLinkage`] does).
//! * Every period [`CommissioningMode::step`] answers what the current-control step gets:
//!   the normal torque path ([`Control::Normal`]), the routine's demand, or
//!   [`Control::Off`]. A fault, a break or a setpoint timeout while a routine runs
//!   aborts it to outputs off (latched until an abort command clears it).
//! * The routine's view each period is captured (two channels, every `decimation`-th
//!   period) as [`crate::can_protocol::Routine::channels`] names; when it finishes the
//!   capture is sent raw (unfiltered): header, one data frame per sample, end frame
//!   with the CRC-32 ([`CommissioningMode::next_frame`], one frame per call).
//!
//! * The pre-flight check (routine 6, [`crate::preflight`]) runs the same way but captures
//!   nothing: it ends idle (passed) or in the fault state with reason
//!   [`Reason::PreflightFailed`], its refusal handed once to the board
//!   ([`CommissioningMode::take_refusal`]), which trips with the refusal's fault cause.
//!
//! Raw capture instead of the FMAC: the host filters with the bit-exact FMAC model
//! (`motor_control::fir::FmacFir`, the same taps), so the result is the same number
//! for number, and the log keeps the unfiltered current for inspection; the FMAC stays
//! free for the control interrupt and the capture needs no second buffer.

use crate::angle::to_radians;
use crate::can_protocol::{self as p, Command, End, Frame, Header, Layout, Reason, Routine, State};
use crate::commissioning::{
    Axis, CommissioningError, FluxLinkage, FluxLinkageState, FrequencyResponse, FrequencyResponseState, PolePairRatio,
    PolePairRatioState, Progress, ResolverOffset, ResolverOffsetState, VoltageStep, VoltageStepState, multisine_lines,
};
use crate::preflight::{Preflight, PreflightInput, PreflightState, Refusal};
use crate::step::Demand;
use crate::transforms::{Dq, Uvw};
use crate::trig::Trig;

/// Fixed parameters of the routines (the command gives voltage, trip and decimation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModeConfig {
    /// Frame identifiers and scalings.
    pub layout: Layout,
    /// T_s in units of 100 ns (the generated `SAMPLE_PERIOD_UNITS`).
    pub sample_period_units: u16,
    /// Largest |ω_e| counted as standstill \[rad/s\].
    pub standstill_speed: f32,
    /// Largest |torque setpoint| counted as zero \[N·m\].
    pub zero_torque: f32,
    /// Blocked-rotor step: periods at 0 V before the step, periods at the step.
    pub step_samples: (u32, u32),
    /// Resolver offset: ramp, settle and averaging periods (§6.3).
    pub align_samples: (u32, u32, u32),
    /// Pole-pair ratio: angle step per period (π-scaled), whole turns, settle periods.
    pub rotation: (i32, u32, u32),
    /// ψ_M run (§6.5).
    pub flux: FluxLinkage,
    /// Largest injection peak of the frequency response \[V\] (the generated
    /// `INJECTION_LIMIT`: the injected current within half the routine's trip and the
    /// applied voltage within the linear modulation range); a command above it is
    /// refused with [`Reason::AmplitudeAboveLimit`].
    pub injection_limit: f32,
    /// The pre-flight check ([`crate::preflight`]).
    pub preflight: Preflight,
}

/// Safety inputs, every period.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Guards {
    /// The torque setpoint now \[N·m\].
    pub torque_setpoint: f32,
    /// A latched drive fault (over-current, over-voltage, over-speed).
    pub fault: bool,
    /// The break input is active (the timer has disabled the outputs).
    pub break_active: bool,
    /// No setpoint frame within the board's timeout.
    pub setpoint_timeout: bool,
}

impl Guards {
    fn any(&self) -> bool {
        self.fault || self.break_active || self.setpoint_timeout
    }
}

/// What the routine sees each period (from the previous control step).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Measured {
    /// Measured currents \[A\].
    pub i_dq: Dq,
    /// Observed resolver angle (π-scaled Q1.31).
    pub theta_r: i32,
    /// Electrical speed \[rad/s\].
    pub omega_e: f32,
    /// Applied q voltage \[V\] (the controller's output, without a frequency
    /// response's injection).
    pub u_q: f32,
    /// Applied d voltage \[V\] (the same).
    pub u_d: f32,
    /// The resolver's electrical angle θ_e (π-scaled Q1.31).
    pub theta_e: i32,
    /// Measured phase currents \[A\].
    pub i_uvw: Uvw,
}

/// Multisine periods the frequency response runs before the captured one: the loop's
/// slowest mode (the plant pole R/L a first-order design cancels, at most some 20 ms
/// for the motors here) has decayed to e⁻¹⁰ after one period of 4096 samples at 20 kHz.
pub const FREQUENCY_RESPONSE_SETTLE_PERIODS: u32 = 1;

/// The frequency response's multisine period N \[samples\] for a capture buffer of
/// `capacity` samples: the largest power of two that fits (at most 2¹⁵, the u16
/// sample count), so the lines are exact harmonics and the FFT-free DFT on the host
/// sees whole periods; 0 for an empty buffer.
pub fn frequency_response_period(capacity: usize) -> u32 {
    let c = capacity.min(1 << 15) as u32;
    if c == 0 {
        0
    } else {
        1u32.checked_shl(31u32.saturating_sub(c.leading_zeros())).unwrap_or(0)
    }
}

/// What a command needs computed before the supervisor takes it: a frequency
/// response's oscillators ([`FrequencyResponse::start`]: libm's sine and cosine of every
/// line's rotation and phase, and the lines' weights). The board runs the supervisor's
/// [`CommissioningMode::command_prepared`] inside a critical section that masks the
/// control interrupt; computed there, the oscillators held the interrupt off for longer
/// than a carrier period at 40 kHz (the emulated G474 names it: 25.1 µs masked, one
/// instruction per cycle, a lower bound). [`prepare`] runs before, interrupts enabled.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Prepared {
    command: Command,
    /// The routine and its oscillators, or the reason the command is refused.
    run: Result<(FrequencyResponse, FrequencyResponseState), Reason>,
}

/// Prepares `c` for [`CommissioningMode::command_prepared`]: for a valid frequency
/// response (lines valid for the period a buffer of `capacity` holds, amplitude and trip
/// positive and finite) the routine and its oscillators' initial state; nothing for
/// any other command.
pub fn prepare(cfg: &ModeConfig, c: &Command, capacity: usize) -> Prepared {
    Prepared {
        command: *c,
        run: prepare_frequency_response(cfg, c, capacity),
    }
}

/// The frequency response of `c`: its line set valid for the period a buffer of
/// `capacity` holds, amplitude and trip positive and finite ([`Reason::BadCommand`]
/// otherwise), the amplitude at most the configuration's `injection_limit` (refused, not
/// clamped: [`Reason::AmplitudeAboveLimit`], so a capture never carries another
/// amplitude than the host asked for).
fn prepare_frequency_response(
    cfg: &ModeConfig,
    c: &Command,
    capacity: usize,
) -> Result<(FrequencyResponse, FrequencyResponseState), Reason> {
    if c.routine != Some(Routine::FrequencyResponse) {
        return Err(Reason::BadCommand);
    }
    let [first, per_octave] = c.decimation.to_le_bytes();
    let period = frequency_response_period(capacity);
    let lines = multisine_lines(u16::from(first), per_octave, period).ok_or(Reason::BadCommand)?;
    if !(c.voltage > 0.0 && c.voltage.is_finite() && c.current_trip > 0.0 && c.current_trip.is_finite()) {
        return Err(Reason::BadCommand);
    }
    // The voltage is finite here; a NaN limit (never generated) refuses every amplitude.
    if c.voltage > cfg.injection_limit || cfg.injection_limit.is_nan() {
        return Err(Reason::AmplitudeAboveLimit);
    }
    let r = FrequencyResponse {
        axis: if c.axis_q { Axis::Q } else { Axis::D },
        amplitude: c.voltage,
        current_trip: c.current_trip,
        period,
        settle_periods: FREQUENCY_RESPONSE_SETTLE_PERIODS,
        lines,
    };
    Ok((r, r.start()))
}

/// What the current-control step gets this period.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Control {
    /// Torque control from the setpoint (no commissioning).
    Normal,
    /// The routine's demand.
    Demand(Demand),
    /// Outputs off.
    Off,
}

// The frequency response's oscillators (3·MAX_LINES phasors, 768 B) make its variant the
// largest; the mode lives in one static of the board and there is no heap to box it in.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Copy, Debug, PartialEq)]
enum Running {
    Step(VoltageStep, VoltageStepState<0>),
    Align(ResolverOffset, ResolverOffsetState),
    Rotate(PolePairRatio, PolePairRatioState),
    Flux(FluxLinkageState),
    Frequency(FrequencyResponse, FrequencyResponseState),
    Preflight(PreflightState),
}

// As `Running`: the running routine's state is the largest variant, by design.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Copy, Debug, PartialEq)]
enum Mode {
    Idle,
    Running {
        routine: Routine,
        run: Running,
        n: u32,
    },
    /// Sending: `next` 0 is the header, 1…count the data frames, count + 1 the end.
    Streaming {
        next: u32,
    },
    Fault,
}

/// The commissioning supervisor. The capture buffer is the caller's (a separate,
/// zero-initialised static on the board, so it costs RAM but no flash), passed to the
/// calls that use it; its length is the capture capacity.
#[derive(Clone, Debug, PartialEq)]
pub struct CommissioningMode {
    mode: Mode,
    reason: Reason,
    header: Header,
    end: End,
    crc: p::Crc32,
    len: usize,
    /// Why the last pre-flight check refused the drive, until taken.
    refused: Option<Refusal>,
}

impl Default for CommissioningMode {
    fn default() -> Self {
        Self::new()
    }
}

/// One captured sample: channels A and B (SI units).
pub type Sample = (f32, f32);

impl CommissioningMode {
    /// Idle, empty capture.
    pub const fn new() -> Self {
        Self {
            mode: Mode::Idle,
            reason: Reason::None,
            header: Header {
                routine: Routine::Step,
                axis_q: false,
                tripped: false,
                decimation: 1,
                sample_period_units: 0,
                count: 0,
                current_trip: 0.0,
            },
            end: End {
                crc: 0,
                trip_sample: 0,
                trip_current: 0.0,
            },
            crc: p::Crc32::new(),
            len: 0,
            refused: None,
        }
    }

    /// The pre-flight check's refusal, once (the board trips with its cause: outputs
    /// off until reset, the fault record).
    pub fn take_refusal(&mut self) -> Option<Refusal> {
        self.refused.take()
    }

    /// The state and reason for the status frame.
    pub fn state(&self) -> (State, Reason) {
        let s = match self.mode {
            Mode::Idle => State::Idle,
            Mode::Running { .. } => State::Commissioning,
            Mode::Streaming { .. } => State::Streaming,
            Mode::Fault => State::Fault,
        };
        (s, self.reason)
    }

    /// The status frame (`faults`: the image's fault flags).
    pub fn status(&self, cfg: &ModeConfig, faults: u8) -> Frame {
        let (s, r) = self.state();
        let routine = match self.mode {
            Mode::Running { routine, .. } => routine.code(),
            Mode::Streaming { .. } => self.header.routine.code(),
            _ => 0,
        };
        p::encode_status(&cfg.layout, s, r, routine, faults)
    }

    /// The samples captured so far in `buffer`.
    pub fn captured<'a>(&self, buffer: &'a [Sample]) -> &'a [Sample] {
        buffer.get(..self.len).unwrap_or(&[])
    }

    /// A received command; returns the reason it was refused ([`Reason::None`]:
    /// accepted). `capacity` is the capture buffer's length. [`prepare`] and
    /// [`CommissioningMode::command_prepared`] in one call.
    pub fn command(&mut self, cfg: &ModeConfig, c: &Command, guards: &Guards, omega_e: f32, capacity: usize) -> Reason {
        let prepared = prepare(cfg, c, capacity);
        self.command_prepared(cfg, c, &prepared, guards, omega_e, capacity)
    }

    /// [`CommissioningMode::command`] with what [`prepare`] computed for `c` beforehand
    /// (outside the board's critical section: see [`prepare`]); a `prepared` made from
    /// another command refuses a frequency response ([`Reason::BadCommand`]).
    pub fn command_prepared(
        &mut self,
        cfg: &ModeConfig,
        c: &Command,
        prepared: &Prepared,
        guards: &Guards,
        omega_e: f32,
        capacity: usize,
    ) -> Reason {
        let reason = self.accept(cfg, c, prepared, guards, omega_e, capacity);
        self.reason = reason;
        reason
    }

    fn accept(
        &mut self,
        cfg: &ModeConfig,
        c: &Command,
        prepared: &Prepared,
        guards: &Guards,
        omega_e: f32,
        capacity: usize,
    ) -> Reason {
        let Some(routine) = c.routine else {
            // Abort: outputs off, capture dropped; clears a latched abort once safe.
            return match self.mode {
                Mode::Fault if guards.any() => Reason::FaultActive,
                Mode::Running { .. } | Mode::Streaming { .. } => {
                    self.mode = Mode::Idle;
                    Reason::Aborted
                }
                _ => {
                    self.mode = Mode::Idle;
                    Reason::None
                }
            };
        };
        if !matches!(self.mode, Mode::Idle) {
            return if matches!(self.mode, Mode::Fault) {
                Reason::FaultActive
            } else {
                Reason::Busy
            };
        }
        if guards.any() {
            return Reason::FaultActive;
        }
        // NaN counts as not zero / not at standstill.
        let within = |x: f32, limit: f32| libm::fabsf(x) <= limit;
        if !within(guards.torque_setpoint, cfg.zero_torque) {
            return Reason::TorqueNotZero;
        }
        if routine != Routine::Flux && !within(omega_e, cfg.standstill_speed) {
            return Reason::NotAtStandstill;
        }
        if routine == Routine::FrequencyResponse {
            return self.accept_frequency_response(cfg, c, prepared);
        }
        if routine == Routine::Preflight {
            // Generated parameters only; nothing is captured.
            self.start(
                cfg,
                routine,
                Running::Preflight(PreflightState::default()),
                false,
                1,
                0.0,
            );
            return Reason::None;
        }
        let decimation = match u8::try_from(c.decimation) {
            Ok(d) if d >= 1 => d,
            _ => return Reason::BadCommand,
        };
        let needs_voltage = routine != Routine::Flux;
        if needs_voltage && !(c.voltage > 0.0 && c.voltage.is_finite()) {
            return Reason::BadCommand;
        }
        if routine == Routine::Step && !(c.current_trip > 0.0 && c.current_trip.is_finite()) {
            return Reason::BadCommand;
        }
        // The capture must fit: a routine whose samples overflow the buffer would be
        // identified from a cut record.
        let periods = capture_periods(cfg, routine);
        let samples = periods.div_ceil(u64::from(decimation));
        if samples > capacity as u64 || samples > u64::from(u16::MAX) {
            return Reason::BadCommand;
        }
        let run = match routine {
            Routine::Step => Running::Step(
                VoltageStep {
                    axis: if c.axis_q { Axis::Q } else { Axis::D },
                    voltage: c.voltage,
                    current_trip: c.current_trip,
                    pre_samples: cfg.step_samples.0,
                    step_samples: cfg.step_samples.1,
                    // The routine's own buffer is empty; this module captures.
                    decimation: 1,
                },
                VoltageStepState::new(),
            ),
            Routine::ResolverOffset => Running::Align(
                ResolverOffset {
                    voltage: c.voltage,
                    ramp_samples: cfg.align_samples.0,
                    settle_samples: cfg.align_samples.1,
                    average_samples: cfg.align_samples.2,
                },
                ResolverOffsetState::default(),
            ),
            Routine::PolePairRatio => Running::Rotate(
                PolePairRatio {
                    voltage: c.voltage,
                    step: cfg.rotation.0,
                    turns: cfg.rotation.1,
                    settle_samples: cfg.rotation.2,
                },
                PolePairRatioState::default(),
            ),
            Routine::Flux => Running::Flux(FluxLinkageState::default()),
            // Accepted above, never here.
            Routine::FrequencyResponse | Routine::Preflight => return Reason::BadCommand,
        };
        let trip = if routine == Routine::Step { c.current_trip } else { 0.0 };
        self.start(
            cfg,
            routine,
            run,
            routine == Routine::Step && c.axis_q,
            decimation,
            trip,
        );
        Reason::None
    }

    /// The frequency response [`prepare`]d from `c` (amplitude and trip positive, the
    /// line set valid for the period the buffer holds).
    fn accept_frequency_response(&mut self, cfg: &ModeConfig, c: &Command, prepared: &Prepared) -> Reason {
        if prepared.command != *c {
            return Reason::BadCommand;
        }
        let (r, st) = match prepared.run {
            Ok(run) => run,
            Err(reason) => return reason,
        };
        self.start(
            cfg,
            Routine::FrequencyResponse,
            Running::Frequency(r, st),
            c.axis_q,
            1,
            c.current_trip,
        );
        Reason::None
    }

    fn start(&mut self, cfg: &ModeConfig, routine: Routine, run: Running, axis_q: bool, decimation: u8, trip: f32) {
        self.header = Header {
            routine,
            axis_q,
            tripped: false,
            decimation,
            sample_period_units: cfg.sample_period_units,
            count: 0,
            current_trip: trip,
        };
        self.end = End {
            crc: 0,
            trip_sample: 0,
            trip_current: 0.0,
        };
        self.len = 0;
        self.mode = Mode::Running { routine, run, n: 0 };
    }

    /// One control period: what the current-control step gets; the routine's channels
    /// go to `buffer`.
    pub fn step<T: Trig>(
        &mut self,
        cfg: &ModeConfig,
        guards: &Guards,
        m: &Measured,
        trig: &mut T,
        buffer: &mut [Sample],
    ) -> Control {
        let Mode::Running { routine, mut run, n } = self.mode else {
            return match self.mode {
                Mode::Idle => Control::Normal,
                _ => Control::Off,
            };
        };
        if guards.any() {
            self.mode = Mode::Fault;
            self.reason = Reason::Aborted;
            return Control::Off;
        }
        // The pre-flight check: no capture; its verdict is the status (and, failed, the
        // refusal the board turns into a fault record).
        if let Running::Preflight(st) = &mut run {
            let input = PreflightInput {
                i_uvw: m.i_uvw,
                theta_e: m.theta_e,
                theta_r: m.theta_r,
            };
            return match cfg.preflight.process(st, trig, &input) {
                Progress::Running(demand) => {
                    self.mode = Mode::Running {
                        routine,
                        run,
                        n: n.saturating_add(1),
                    };
                    Control::Demand(demand)
                }
                Progress::Finished(Ok(_)) => {
                    self.mode = Mode::Idle;
                    self.reason = Reason::None;
                    Control::Off
                }
                Progress::Finished(Err(f)) => {
                    self.mode = Mode::Fault;
                    self.reason = Reason::PreflightFailed;
                    self.refused = Some(f);
                    Control::Off
                }
            };
        }
        // The frequency response captures its own window (the previous period's u_PI
        // and v), never decimated.
        if let Running::Frequency(r, st) = &mut run {
            let u_pi = match r.axis {
                Axis::D => m.u_d,
                Axis::Q => m.u_q,
            };
            let (pr, capture) = r.process(st, m.i_dq, u_pi);
            if let Some(sample) = capture
                && let Some(slot) = buffer.get_mut(self.len)
                && self.len < usize::from(u16::MAX)
            {
                *slot = sample;
                self.len = self.len.saturating_add(1);
            }
            return match pr {
                Progress::Running(demand) => {
                    self.mode = Mode::Running {
                        routine,
                        run,
                        n: n.saturating_add(1),
                    };
                    Control::Demand(demand)
                }
                Progress::Finished(Ok(())) => self.finish(None),
                Progress::Finished(Err(e)) => self.finish(Some(e)),
            };
        }
        // The demand and the two captured channels of this period, or the outcome.
        let (progress, channels) = match &mut run {
            Running::Step(r, st) => {
                let pr = r.process(st, m.i_dq);
                let ch = match pr {
                    Progress::Running(Demand::VoltageDq(v)) => match r.axis {
                        Axis::D => (v.d, m.i_dq.d),
                        Axis::Q => (v.q, m.i_dq.q),
                    },
                    _ => (0.0, 0.0),
                };
                let outcome = match pr {
                    Progress::Running(d) => Progress::Running(d),
                    Progress::Finished(Ok(_)) => Progress::Finished(None),
                    Progress::Finished(Err(e)) => Progress::Finished(Some(e)),
                };
                (outcome, ch)
            }
            Running::Align(r, st) => {
                let pr = r.process(st, m.theta_r);
                let u = match pr {
                    Progress::Running(Demand::VoltageAlphaBeta(v)) => v.alpha,
                    _ => 0.0,
                };
                (finish_ok(pr), (u, to_radians(m.theta_r)))
            }
            Running::Rotate(r, st) => {
                let pr = r.process(st, trig, m.theta_r);
                let generated = to_radians(st.generated_angle());
                let outcome = match pr {
                    Progress::Running(d) => Progress::Running(d),
                    Progress::Finished(Ok(_)) => Progress::Finished(None),
                    Progress::Finished(Err(e)) => Progress::Finished(Some(e)),
                };
                (outcome, (generated, to_radians(m.theta_r)))
            }
            Running::Flux(st) => {
                let pr = cfg.flux.process(st, m.u_q, m.omega_e);
                let outcome = match pr {
                    Progress::Running(d) => Progress::Running(d),
                    Progress::Finished(Ok(_)) => Progress::Finished(None),
                    Progress::Finished(Err(e)) => Progress::Finished(Some(e)),
                };
                (outcome, (m.omega_e, m.u_q))
            }
            Running::Frequency(..) | Running::Preflight(..) => (Progress::Finished(None), (0.0, 0.0)),
        };
        match progress {
            Progress::Running(demand) => {
                // ψ_M: only the averaged periods (the settling ones hold transients).
                let from = if routine == Routine::Flux {
                    cfg.flux.settle_samples
                } else {
                    0
                };
                if n >= from
                    && n.saturating_sub(from)
                        .is_multiple_of(u32::from(self.header.decimation.max(1)))
                    && let Some(slot) = buffer.get_mut(self.len)
                    && self.len < usize::from(u16::MAX)
                {
                    *slot = channels;
                    self.len = self.len.saturating_add(1);
                }
                self.mode = Mode::Running {
                    routine,
                    run,
                    n: n.saturating_add(1),
                };
                Control::Demand(demand)
            }
            Progress::Finished(error) => self.finish(error),
        }
    }

    /// The routine ended (tripped with `error`): outputs off, the capture to be sent.
    fn finish(&mut self, error: Option<CommissioningError>) -> Control {
        if let Some(CommissioningError::Tripped { sample, current }) = error {
            self.header.tripped = true;
            self.end.trip_sample = u16::try_from(sample).unwrap_or(u16::MAX);
            self.end.trip_current = current;
            self.reason = Reason::Tripped;
        }
        self.header.count = u16::try_from(self.len).unwrap_or(u16::MAX);
        self.crc = p::Crc32::new();
        self.mode = Mode::Streaming { next: 0 };
        Control::Off
    }

    /// The next capture frame (of `buffer`) to send while streaming (then idle again),
    /// `None` otherwise.
    pub fn next_frame(&mut self, cfg: &ModeConfig, buffer: &[Sample]) -> Option<Frame> {
        let Mode::Streaming { next } = self.mode else {
            return None;
        };
        let count = u32::from(self.header.count);
        let frame = if next == 0 {
            p::encode_header(&cfg.layout, &self.header)
        } else if next <= count {
            let k = next.saturating_sub(1);
            let (a, b) = buffer.get(k as usize).copied().unwrap_or((0.0, 0.0));
            p::encode_data(&cfg.layout, self.header.routine, k as u16, a, b)
        } else {
            self.mode = Mode::Idle;
            return Some(p::encode_end(
                &cfg.layout,
                &End {
                    crc: self.crc.value(),
                    ..self.end
                },
            ));
        };
        self.crc.update(frame.bytes());
        self.mode = Mode::Streaming {
            next: next.saturating_add(1),
        };
        Some(frame)
    }
}

/// Periods a routine captures (an upper bound for the rotation, whose last step may be
/// shorter): with decimation D it needs ⌈periods/D⌉ samples of the capture buffer.
pub fn capture_periods(cfg: &ModeConfig, routine: Routine) -> u64 {
    let sum = |a: u32, b: u32, c: u32| u64::from(a).saturating_add(u64::from(b)).saturating_add(u64::from(c));
    match routine {
        Routine::Step => sum(cfg.step_samples.0, cfg.step_samples.1, 0),
        Routine::ResolverOffset => sum(cfg.align_samples.0, cfg.align_samples.1, cfg.align_samples.2),
        Routine::PolePairRatio => {
            let (step, turns, settle) = cfg.rotation;
            let per_turn = (1u64 << 32)
                .checked_div(u64::from(step.unsigned_abs()))
                .unwrap_or(u64::MAX)
                .saturating_add(1);
            per_turn
                .saturating_mul(u64::from(turns))
                .saturating_add(sum(settle, settle, 2))
        }
        Routine::Flux => sum(cfg.flux.average_samples, 1, 0),
        // One multisine period of the buffer ([`frequency_response_period`]), checked
        // when the command is accepted.
        Routine::FrequencyResponse => 0,
        // Captures nothing.
        Routine::Preflight => 0,
    }
}

fn finish_ok<R>(pr: Progress<R>) -> Progress<Option<CommissioningError>> {
    match pr {
        Progress::Running(d) => Progress::Running(d),
        Progress::Finished(_) => Progress::Finished(None),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trig::SoftTrig;

    fn cfg() -> ModeConfig {
        ModeConfig {
            layout: p::EXAMPLE_LAYOUT,
            sample_period_units: 500,
            standstill_speed: 1.0,
            zero_torque: 0.005,
            step_samples: (2, 4),
            align_samples: (2, 2, 2),
            rotation: (1 << 30, 1, 1),
            flux: FluxLinkage {
                settle_samples: 1,
                average_samples: 2,
                min_speed: 10.0,
            },
            injection_limit: 3.0,
            preflight: crate::preflight::tests::EXAMPLE,
        }
    }

    /// A frequency response on the d axis with `voltage` as its amplitude: lines from
    /// harmonic 4, 3 per octave of the period an 8192-sample buffer holds.
    fn frequency_cmd(voltage: f32) -> Command {
        Command {
            routine: Some(Routine::FrequencyResponse),
            axis_q: false,
            voltage,
            current_trip: 10.0,
            decimation: u16::from_le_bytes([4, 3]),
        }
    }

    /// The injection limit (3 V in `cfg`): an amplitude at it runs, one above it is
    /// refused with its own reason and nothing starts; a command taken with what was
    /// prepared for another is refused.
    #[test]
    fn frequency_response_amplitude_is_bounded_by_the_injection_limit() {
        let c = cfg();
        let g = Guards::default();
        let mut m = CommissioningMode::new();
        assert_eq!(
            m.command(&c, &frequency_cmd(3.01), &g, 0.0, 8192),
            Reason::AmplitudeAboveLimit
        );
        assert_eq!(m.state(), (State::Idle, Reason::AmplitudeAboveLimit));
        let prepared = prepare(&c, &frequency_cmd(2.0), 8192);
        assert_eq!(
            m.command_prepared(&c, &frequency_cmd(2.5), &prepared, &g, 0.0, 8192),
            Reason::BadCommand
        );
        assert_eq!(m.command(&c, &frequency_cmd(3.0), &g, 0.0, 8192), Reason::None);
        assert_eq!(m.state().0, State::Commissioning);
    }

    fn step_cmd() -> Command {
        Command {
            routine: Some(Routine::Step),
            axis_q: true,
            voltage: 4.0,
            current_trip: 10.0,
            decimation: 1,
        }
    }

    /// Refusals, each with its reason; nothing starts.
    #[test]
    fn refuses_unless_at_standstill_with_zero_torque() {
        let c = cfg();
        let mut m = CommissioningMode::new();
        let mut buf = [(0.0f32, 0.0f32); 8];
        let g = Guards::default();
        let turning = m.command(&c, &step_cmd(), &g, 50.0, 8);
        assert_eq!(turning, Reason::NotAtStandstill);
        let torque = Guards {
            torque_setpoint: 1.0,
            ..g
        };
        assert_eq!(m.command(&c, &step_cmd(), &torque, 0.0, 8), Reason::TorqueNotZero);
        let fault = Guards { fault: true, ..g };
        assert_eq!(m.command(&c, &step_cmd(), &fault, 0.0, 8), Reason::FaultActive);
        let bad = Command {
            decimation: 0,
            ..step_cmd()
        };
        assert_eq!(m.command(&c, &bad, &g, 0.0, 8), Reason::BadCommand);
        assert_eq!(m.state(), (State::Idle, Reason::BadCommand));
        assert_eq!(m.status(&c, 0).bytes(), &[0, 4, 0, 0]);
        assert_eq!(
            m.step(&c, &g, &Measured::default(), &mut SoftTrig, &mut buf),
            Control::Normal
        );
        // Flux is accepted at speed.
        let flux = Command {
            routine: Some(Routine::Flux),
            ..step_cmd()
        };
        assert_eq!(m.command(&c, &flux, &g, 500.0, 8), Reason::None);
        assert_eq!(m.command(&c, &step_cmd(), &g, 0.0, 8), Reason::Busy);
    }

    /// A step of 2 + 4 periods: 6 demands (0, 0, 4, 4, 4, 4 V on q), then outputs off
    /// and the capture streamed as header, 6 data frames and the end frame, whose CRC
    /// is that of the header and data bytes.
    #[test]
    fn step_runs_captures_and_streams() {
        let c = cfg();
        let mut m = CommissioningMode::new();
        let mut buf = [(0.0f32, 0.0f32); 8];
        let g = Guards::default();
        assert_eq!(m.command(&c, &step_cmd(), &g, 0.0, 8), Reason::None);
        let mut volts = vec![];
        for k in 0..7 {
            let meas = Measured {
                i_dq: Dq {
                    d: 0.0,
                    q: 0.5 * k as f32,
                },
                ..Measured::default()
            };
            match m.step(&c, &g, &meas, &mut SoftTrig, &mut buf) {
                Control::Demand(Demand::VoltageDq(v)) => volts.push(v.q),
                Control::Off => break,
                other => panic!("{other:?}"),
            }
        }
        assert_eq!(volts, [0.0, 0.0, 4.0, 4.0, 4.0, 4.0]);
        assert_eq!(m.state().0, State::Streaming);
        let mut frames = vec![];
        while let Some(f) = m.next_frame(&c, &buf) {
            frames.push(f);
        }
        assert_eq!(frames.len(), 8);
        assert_eq!(m.state().0, State::Idle);
        let h = p::decode_header(&c.layout, frames[0].bytes()).unwrap();
        assert_eq!((h.count, h.axis_q, h.tripped), (6, true, false));
        // Data frame 3: 4 V = 400 LSB, 1.5 A = 150 LSB.
        assert_eq!(p::decode_data(frames[4].bytes()), Some((1, 3, 400, 150)));
        let mut crc = p::Crc32::new();
        for f in &frames[..7] {
            crc.update(f.bytes());
        }
        assert_eq!(p::decode_end(&c.layout, frames[7].bytes()).unwrap().crc, crc.value());
    }

    /// A setpoint timeout while running: outputs off at once, latched, no capture sent;
    /// an abort command clears it once the guards are clear.
    #[test]
    fn timeout_aborts_to_outputs_off() {
        let c = cfg();
        let mut m = CommissioningMode::new();
        let mut buf = [(0.0f32, 0.0f32); 8];
        let g = Guards::default();
        m.command(&c, &step_cmd(), &g, 0.0, 8);
        assert!(matches!(
            m.step(&c, &g, &Measured::default(), &mut SoftTrig, &mut buf),
            Control::Demand(_)
        ));
        let t = Guards {
            setpoint_timeout: true,
            ..g
        };
        assert_eq!(
            m.step(&c, &t, &Measured::default(), &mut SoftTrig, &mut buf),
            Control::Off
        );
        assert_eq!(m.state(), (State::Fault, Reason::Aborted));
        assert_eq!(m.next_frame(&c, &buf), None);
        assert_eq!(
            m.step(&c, &g, &Measured::default(), &mut SoftTrig, &mut buf),
            Control::Off
        );
        let abort = Command {
            routine: None,
            ..step_cmd()
        };
        assert_eq!(m.command(&c, &abort, &t, 0.0, 8), Reason::FaultActive);
        assert_eq!(m.command(&c, &abort, &g, 0.0, 8), Reason::None);
        assert_eq!(
            m.step(&c, &g, &Measured::default(), &mut SoftTrig, &mut buf),
            Control::Normal
        );
    }

    /// The break (TIM1_SR.BIF latched, as the board passes it): a running routine is
    /// aborted to outputs off in the period it is seen, no capture is sent, and while it
    /// stays active a new command is refused (fault active) and an abort does not clear
    /// the latch; once it is gone the abort clears it.
    #[test]
    fn break_aborts_and_refuses() {
        let c = cfg();
        let mut m = CommissioningMode::new();
        let mut buf = [(0.0f32, 0.0f32); 8];
        let g = Guards::default();
        let brk = Guards {
            break_active: true,
            ..g
        };
        assert_eq!(m.command(&c, &step_cmd(), &brk, 0.0, 8), Reason::FaultActive);
        assert_eq!(m.state(), (State::Idle, Reason::FaultActive));
        assert_eq!(m.command(&c, &step_cmd(), &g, 0.0, 8), Reason::None);
        for _ in 0..3 {
            assert!(matches!(
                m.step(&c, &g, &Measured::default(), &mut SoftTrig, &mut buf),
                Control::Demand(_)
            ));
        }
        assert_eq!(
            m.step(&c, &brk, &Measured::default(), &mut SoftTrig, &mut buf),
            Control::Off
        );
        assert_eq!(m.state(), (State::Fault, Reason::Aborted));
        assert_eq!(m.status(&c, 0).bytes(), &[4, 6, 0, 0]);
        assert_eq!(m.next_frame(&c, &buf), None);
        let abort = Command {
            routine: None,
            ..step_cmd()
        };
        assert_eq!(m.command(&c, &abort, &brk, 0.0, 8), Reason::FaultActive);
        assert_eq!(m.command(&c, &step_cmd(), &g, 0.0, 8), Reason::FaultActive);
        assert_eq!(m.command(&c, &abort, &g, 0.0, 8), Reason::None);
        assert_eq!(m.command(&c, &step_cmd(), &g, 0.0, 8), Reason::None);
    }

    /// A trip: the header says tripped, the end frame carries the sample and current.
    #[test]
    fn trip_is_reported_in_the_capture() {
        let c = cfg();
        let mut m = CommissioningMode::new();
        let mut buf = [(0.0f32, 0.0f32); 8];
        let g = Guards::default();
        m.command(&c, &step_cmd(), &g, 0.0, 8);
        let mut k = 0;
        while let Control::Demand(_) = m.step(
            &c,
            &g,
            &Measured {
                i_dq: Dq {
                    d: 0.0,
                    q: 6.0 * k as f32,
                },
                ..Measured::default()
            },
            &mut SoftTrig,
            &mut buf,
        ) {
            k += 1;
        }
        // 0, 6 A pass; 12 A > 10 A trips at period 2.
        assert_eq!(k, 2);
        assert_eq!(m.state(), (State::Streaming, Reason::Tripped));
        let h = m.next_frame(&c, &buf).unwrap();
        assert!(p::decode_header(&c.layout, h.bytes()).unwrap().tripped);
        let mut last = h;
        while let Some(f) = m.next_frame(&c, &buf) {
            last = f;
        }
        let e = p::decode_end(&c.layout, last.bytes()).unwrap();
        assert_eq!(e.trip_sample, 2);
        assert!((e.trip_current - 12.0).abs() < 0.01);
    }

    /// Routine 6, the pre-flight check: accepted with the generated parameters (the
    /// command's voltage and trip unused), runs with no capture; with no current flowing
    /// at all (every phase open) the turn refuses it as an open phase: outputs off, state
    /// fault with reason 8, the refusal taken once, nothing to stream; an abort clears it.
    #[test]
    fn preflight_refusal_is_reported_once() {
        let c = cfg();
        let mut m = CommissioningMode::new();
        let mut buf = [(0.0f32, 0.0f32); 8];
        let g = Guards::default();
        let pre = Command {
            routine: Some(Routine::Preflight),
            voltage: 0.0,
            current_trip: 0.0,
            ..step_cmd()
        };
        assert_eq!(m.command(&c, &pre, &g, 0.0, 8), Reason::None);
        assert_eq!(m.status(&c, 0).bytes(), &[2, 0, 6, 0]);
        let mut periods = 0u64;
        while let Control::Demand(d) = m.step(&c, &g, &Measured::default(), &mut SoftTrig, &mut buf) {
            assert!(matches!(d, Demand::VoltageAlphaBeta(_)), "{d:?}");
            periods += 1;
            assert!(periods <= c.preflight.periods());
        }
        // Hold 100 + turn 256 + hold 100 periods (EXAMPLE): the verdict at the end.
        assert!(periods > 400, "{periods}");
        assert_eq!(m.state(), (State::Fault, Reason::PreflightFailed));
        // Phase u first, at the 0 A every phase read (`Measured::default()`).
        let refusal = m.take_refusal().expect("refused");
        assert_eq!(refusal.fault, crate::preflight::PreflightFault::OpenPhase);
        assert_eq!(refusal.measured, p::FaultMeasurement::at(0.0, 0));
        assert_eq!(m.take_refusal(), None);
        assert_eq!(m.next_frame(&c, &buf), None);
        assert_eq!(
            m.step(&c, &g, &Measured::default(), &mut SoftTrig, &mut buf),
            Control::Off
        );
        let abort = Command {
            routine: None,
            ..step_cmd()
        };
        assert_eq!(m.command(&c, &abort, &g, 0.0, 8), Reason::None);
        assert_eq!(m.state(), (State::Idle, Reason::None));
    }
}
