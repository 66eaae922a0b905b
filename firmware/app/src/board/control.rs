//! The control interrupt (ADC1_2, end of the injected sequence): one
//! [`motor_control::ControllerConfig::process`] step per carrier period with the
//! CORDIC as [`motor_control::Trig`].
//!
//! The first `board::OFFSET_SAMPLES` periods measure the current sensing's zero level
//! with the outputs off (MOE = 0: no switch conducts, no phase current flows;
//! [`crate::offset`]); a level beyond `board::OFFSET_BOUND_CODE` from the nominal one is
//! a fault ([`FaultCause::CurrentOffset`]) and the drive never switches on, otherwise
//! every later period's currents are taken about the measured levels (trips included).
//! Meanwhile the step runs with [`Demand::Off`] and a commissioning routine sees a
//! fault, and the angle observer is acquired on each period's sample
//! ([`motor_control::ato::Acquisition`]: θ̂ = atan2 of SIN and COS, ω̂ = the mean
//! per-period increment of that angle over the calibration's second half, once the
//! excitation has settled): it starts on the rotor's angle and speed — at rest or
//! turning — instead of pulling in from θ̂ = 0, ω̂ = 0, whose speed kick (K_p·sin Δ at
//! rest, the whole speed on a turning rotor) the over-speed trip would take for a
//! runaway. The excitation has run for the whole calibration by its end.
//!
//! The pre-flight check (CAN routine 6) runs through the commissioning mode like the
//! chapter-6 routines; a refusal trips the drive here with its own cause (11–18,
//! `FaultCause::from(PreflightFault)`): outputs off until reset, the record sealed with
//! what it measured (`motor_control::preflight::Refusal`), as are the zero level's
//! refusal (the phase and its deviation in 16-bit codes) and the resolver signal's
//! (measured/designed).
//!
//! Order: read and acknowledge the conversions; trip on the board's levels
//! ([`crate::config::TRIPS`]: a phase current beyond the over-current level or at the
//! converter's rail, the DC link beyond the over-voltage level, the last period's
//! electrical speed beyond the over-speed level); advance the setpoint supervision with
//! the value the main loop received over CAN ([`crate::config::SETPOINT`]: timeout, ramp
//! to zero); run the step with the torque as [`Demand::Torque`] — the control core's torque
//! stage (MTPA, field weakening at the measured DC link, MTPV, current circle;
//! `motor_control::torque`, the function `motorgen verify` runs) turns it into current
//! references inside the step; write `StepOutput::compare` to CCR1..3; then set MOE only if
//! nothing tripped, the setpoint is alive or still ramping down, and the break flag —
//! read again now, not at the start of the interrupt (defect 6) — is clear
//! (`motor_config::bringup::finish_period`). A tripped drive stays off until reset.
//! Every period's state (currents, angle, speed, DC link, outputs on, tripped) is kept
//! for the fault record ([`super::fault::keep_state`]); the first trip seals the record
//! with its cause (trip, lost conversion, break) at the end of its period.

use core::cell::Cell;
use core::sync::atomic::{AtomicBool, AtomicU32, Ordering};

use cortex_m::interrupt::Mutex;
use motor_control::ato::Acquisition;
use motor_control::can_protocol::FaultMeasurement;
use motor_control::commissioning_mode::{Guards, Measured};
use motor_control::setpoint::SetpointState;
use motor_control::{ControllerState, Demand};
use stm32g4::stm32g474 as pac;
use stm32g4::stm32g474::interrupt;

use super::cordic::Cordic;
use super::{adc, commissioning, fault, pins, pwm};
use crate::adc_frame::Trips;
use crate::adc_frame::{self, Excitation};
use crate::bringup::{self, BreakControl};
use crate::config::{CONTROLLER, OFFSETS, RESOLVER_SIGNAL, SETPOINT, TRIPS};
use crate::fault_record::{ControlState, FaultCause};
use crate::motor::board;
use crate::offset::{self, OffsetCalibration, OffsetStatus};
use crate::resolver_check::{SignalCheck, SignalStatus};

/// Control periods run (wrapping); the main loop refreshes the watchdog only when
/// this advances.
pub static TICKS: AtomicU32 = AtomicU32::new(0);
/// Latest received torque setpoint \[N·m\] as `f32` bits.
static SETPOINT_BITS: AtomicU32 = AtomicU32::new(0);
/// A setpoint arrived since the interrupt last looked.
static SETPOINT_FRESH: AtomicBool = AtomicBool::new(false);

/// CAN bus-off events recovered from since start-up (saturating); the main loop counts,
/// the control interrupt copies it into the state it keeps for the fault record.
static BUS_OFF: AtomicU32 = AtomicU32::new(0);

/// Counts one bus-off (main loop only: one writer, so load and store do not race).
pub fn count_bus_off() {
    let n = BUS_OFF.load(Ordering::Relaxed);
    BUS_OFF.store(n.saturating_add(1), Ordering::Relaxed);
}

/// Hands a received torque setpoint \[N·m\] to the control interrupt.
pub fn publish_setpoint(torque: f32) {
    SETPOINT_BITS.store(torque.to_bits(), Ordering::Relaxed);
    SETPOINT_FRESH.store(true, Ordering::Release);
}

/// The setpoint received since the last call, if any.
fn take_setpoint() -> Option<f32> {
    SETPOINT_FRESH
        .swap(false, Ordering::Acquire)
        .then(|| f32::from_bits(SETPOINT_BITS.load(Ordering::Relaxed)))
}

/// Everything the control interrupt owns.
pub struct Control {
    tim1: pac::TIM1,
    adc1: pac::ADC1,
    adc2: pac::ADC2,
    cordic: Cordic,
    state: ControllerState,
    setpoint: SetpointState,
    tripped: bool,
    /// Electrical speed of the last step \[rad/s\], for the over-speed trip.
    omega_e: f32,
    /// Why this period tripped, recorded at its end with its state.
    trip_cause: Option<Trip>,
    /// What the last step measured, for a commissioning routine.
    measured: Measured,
    /// The start-up measurement of the current sensing's zero level.
    calibration: OffsetCalibration,
    /// The measured zero levels \[16-bit codes\], once measured and within the bound.
    zero: Option<[i32; 3]>,
    /// The start-up measurement of the resolver signal (over the same periods).
    signal: SignalCheck,
    /// That measurement still running.
    signal_pending: bool,
    /// The angle observer's start: the resolver's angle and speed over the calibration.
    acquisition: Acquisition,
    /// The trips, about the measured zero levels once known.
    trips: Trips,
}

/// A trip waiting for the period's end to be recorded: its cause and what the start-up
/// check that refused the drive measured.
#[derive(Clone, Copy)]
struct Trip {
    cause: FaultCause,
    measured: Option<FaultMeasurement>,
}

/// Passes the [`Control`] from `run` to the interrupt once.
pub static HANDOFF: Mutex<Cell<Option<Control>>> = Mutex::new(Cell::new(None));

impl Control {
    /// Takes the peripherals of the control path (configured by the caller).
    pub fn new(tim1: pac::TIM1, adc1: pac::ADC1, adc2: pac::ADC2, cordic: Cordic) -> Self {
        Self {
            tim1,
            adc1,
            adc2,
            cordic,
            state: ControllerState::new(),
            setpoint: SetpointState::new(),
            tripped: false,
            omega_e: 0.0,
            trip_cause: None,
            measured: Measured {
                i_dq: motor_control::transforms::Dq { d: 0.0, q: 0.0 },
                theta_r: 0,
                omega_e: 0.0,
                u_q: 0.0,
                u_d: 0.0,
                theta_e: 0,
                i_uvw: motor_control::transforms::Uvw { u: 0.0, v: 0.0, w: 0.0 },
            },
            calibration: OffsetCalibration::new(),
            zero: None,
            signal: SignalCheck::new(),
            signal_pending: true,
            acquisition: Acquisition::new(),
            trips: TRIPS,
        }
    }

    /// Latches a trip and switches the gates off at once; the first trip's cause goes
    /// into the fault record.
    fn trip(&mut self, cause: FaultCause) {
        self.refuse(cause, None);
    }

    /// [`Self::trip`] by a start-up check, with the figure it judged (the fault
    /// record's measurement).
    fn refuse(&mut self, cause: FaultCause, measured: Option<FaultMeasurement>) {
        if !self.tripped && self.trip_cause.is_none() {
            self.trip_cause = Some(Trip { cause, measured });
        }
        self.tripped = true;
        pwm::outputs_off(&self.tim1);
    }

    /// One control period.
    pub fn step(&mut self) {
        let Some(raw) = adc::read(&self.adc1, &self.adc2) else {
            // A lost conversion: no valid currents this period (the record keeps the
            // last period's state).
            self.trip(FaultCause::LostConversion);
            return self.record_trip();
        };
        let was_tripped = self.tripped;
        let phases = usize::from(board::CURRENT_PHASES);
        if self.zero.is_none() {
            match self.calibration.add(&OFFSETS, &raw, phases) {
                OffsetStatus::Measuring => {}
                OffsetStatus::Measured(levels) => {
                    self.zero = Some(levels);
                    self.trips.current_offset = levels;
                }
                OffsetStatus::OutOfBound { phase, deviation } => self.refuse(
                    FaultCause::CurrentOffset,
                    Some(FaultMeasurement::at(deviation as f32, phase)),
                ),
            }
        }
        if self.trips.tripped(&raw, phases, self.omega_e) {
            self.trip(FaultCause::Trip);
        }
        // Measuring the zero level (or refused it): the outputs stay off.
        let calibrating = self.zero.is_none();
        let excitation = if pins::excitation_high() {
            Excitation::Positive
        } else {
            Excitation::Negative
        };
        let mut sample = adc_frame::to_sample(&raw, excitation);
        if let Some(levels) = self.zero {
            sample.phase_currents = offset::to_nominal(sample.phase_currents, levels, OFFSETS.nominal);
        }
        let torque = SETPOINT.process(&mut self.setpoint, take_setpoint());
        let alive = !(self.setpoint.timed_out(&SETPOINT) && torque == 0.0);
        let run = alive && !self.tripped && !calibrating;
        let normal = if run { Demand::Torque(torque) } else { Demand::Off };
        // A commissioning routine replaces the torque demand (or switches off). The break
        // as TIM1 latched it: TIM1_SR.BIF (bit 7) is set by hardware as soon as the break
        // input goes active, and software can clear it only once the input is inactive
        // again (RM0440 §28.6.5, TIMx_SR (x = 1, 8, 20)) — so a break since the last
        // period's MOE decision aborts a routine here, before its demand is run;
        // `finish_period` reads BIF again before MOE.
        let guards = Guards {
            torque_setpoint: torque,
            fault: self.tripped || calibrating,
            break_active: pwm::Break(&self.tim1).break_flag(),
            setpoint_timeout: self.setpoint.timed_out(&SETPOINT),
        };
        let (demand, run, refused) =
            commissioning::control_step(&mut self.cordic, &self.measured, &guards, self.omega_e, normal, run);
        // The pre-flight check refused the drive: outputs off until reset, its cause
        // (11–18) in the fault record.
        if let Some(r) = refused {
            self.refuse(FaultCause::from(r.fault), Some(r.measured));
        }
        let (demand, run) = if calibrating {
            (Demand::Off, false)
        } else {
            (demand, run)
        };
        let out = CONTROLLER.process(&mut self.state, &mut self.cordic, &sample, demand);
        self.measured = Measured {
            i_dq: out.i_dq,
            theta_r: out.theta_r,
            omega_e: out.omega_e,
            u_q: out.u_dq.q,
            u_d: out.u_dq.d,
            theta_e: out.theta_e,
            i_uvw: out.i_uvw,
        };
        self.omega_e = out.omega_e;
        if self.signal_pending {
            match self.signal.add(&RESOLVER_SIGNAL, sample.resolver) {
                SignalStatus::Measuring => {}
                SignalStatus::Within(_) => self.signal_pending = false,
                SignalStatus::Outside(square) => {
                    self.signal_pending = false;
                    let ratio = RESOLVER_SIGNAL.ratio_of(square);
                    self.refuse(FaultCause::ResolverSignal, Some(FaultMeasurement::of(ratio)));
                }
            }
        }
        if calibrating {
            // The rotor's angle and its speed over the settled half of the calibration
            // (the resolver signal check's averaged periods): the observer starts locked
            // on a turning rotor too. The over-speed trip judges the observer's speed
            // only once it runs.
            let counted = self.signal.averaging(&RESOLVER_SIGNAL);
            self.state.observer = self.acquisition.add(&mut self.cordic, sample.resolver, counted);
            self.omega_e = 0.0;
        }
        pwm::set_compare(&self.tim1, out.compare);
        let on = bringup::finish_period(&mut pwm::Break(&self.tim1), &mut self.tripped, run);
        if self.tripped && !was_tripped && self.trip_cause.is_none() {
            self.trip_cause = Some(Trip {
                cause: FaultCause::Break,
                measured: None,
            });
        }
        let periods = TICKS.fetch_add(1, Ordering::Relaxed).wrapping_add(1);
        fault::keep_state(&ControlState {
            i_d: out.i_dq.d,
            i_q: out.i_dq.q,
            theta_e: out.theta_e,
            omega_e: out.omega_e,
            u_dc: out.u_dc,
            periods,
            bus_off: BUS_OFF.load(Ordering::Relaxed),
            running: on,
            tripped: self.tripped,
        });
        self.record_trip();
    }

    /// Seals the fault record once, for the first trip (the drive stays off until
    /// reset, and the record waits for it).
    fn record_trip(&mut self) {
        if let Some(t) = self.trip_cause.take() {
            fault::record(t.cause, t.measured);
        }
    }
}

/// The control interrupt.
#[interrupt]
fn ADC1_2() {
    static mut CONTROL: Option<Control> = None;
    if CONTROL.is_none() {
        *CONTROL = cortex_m::interrupt::free(|cs| HANDOFF.borrow(cs).take());
    }
    if let Some(control) = CONTROL {
        control.step();
    }
}
