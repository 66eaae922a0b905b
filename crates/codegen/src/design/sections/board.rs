//! The board section (`design.board`), a motor on an inverter board: the ADC-to-SI
//! constants from the board's sensing (the 16-bit left-aligned codes of thesis A (4.16),
//! Table 4.1; the sequences' timing of RM0440 §21.4.12), the dead time, trips and bus
//! timing in the units the firmware needs, and the checks that can only be made with
//! both. It runs on the motor's finished design ([`crate::design::on_board`]).
//!
//! What the pair must satisfy is an error at the board key (the motor's numbers in the
//! message): the motor's peak current within what the board's current sensing measures
//! and within its power stage's rating (`protection.over_current`), its DC link within
//! what the divider measures and within `protection.over_voltage`, its maximum speed
//! within `protection.over_speed`. A board's `[protection]` values are ceilings: the
//! image trips at the lower of the motor's limit and the board's ceiling ([`Trips`]), the
//! motor's limits being the full scales of its design (the spec's `[scaling] margin` over
//! its peak current, DC link and maximum speed, thesis A Table 4.1). Conversions that
//! take more than a quarter of the control period are a warning. The duty limit of the
//! current sensing's sampling window (`design::duty_limit`) is carried here; a window
//! that leaves less than [`MIN_USABLE_VOLTAGE_FRACTION`] of U_dc/√3 is refused at the
//! board key that set it.

use serde::Serialize;

use crate::board::{
    ADC_CLOCK_HZ, Board, PinUse, Signal, break_active_high, break_pull, checks_option_bytes, current_sample_instant,
    gates, resolver_sample_instant, resolver_skew, samples_at_carrier_maximum, sequence_time, tim1_ccer_polarity,
    tim1_cr2_idle, warning_at,
};
use crate::design::Design;
use crate::design::duty_limit::{self, DutyBound, DutyLimit};
use crate::diagnostic::{Diagnostic, Source};
use crate::firmware::{self, CanBitTiming};

/// Left-aligned 16-bit ADC codes per volt at the pin, over V_REF+: the firmware shifts
/// the 12-bit conversions into Q1.15 offset binary (thesis A (4.16), Table 4.1).
const CODES_16: f64 = 65_536.0;
/// The DC link as a 15-bit unipolar code (0 … 2^15 over V_REF+).
const CODES_15: f64 = 32_768.0;

/// The board's values with one motor.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BoardOut {
    /// The board as resolved.
    pub board: Board,
    /// ADC code (16-bit left-aligned) at zero current: V_off/V_REF+·2^16.
    pub current_offset_code: i32,
    /// Amperes per 16-bit code: V_REF+/(G·2^16), with the sign of the sensing's gain G
    /// (negative for low-side shunts behind a non-inverting stage).
    pub amps_per_lsb: f64,
    /// Measurable current ± \[A\].
    pub current_full_scale_a: f64,
    /// Conversions per phase the image averages at start-up, gates off, for the measured
    /// zero-current level (`offset_samples` below).
    pub offset_samples: u32,
    /// Largest |measured − nominal| zero-current level the image accepts, in 16-bit
    /// left-aligned codes (`offset_bound_code` below).
    pub offset_bound_code: i32,
    /// Volts of DC link per 15-bit code: V_REF+/(ratio·2^15).
    pub dc_link_volts_per_lsb: f64,
    /// Measurable DC link \[V\].
    pub dc_link_full_scale_v: f64,
    /// Dead time the firmware programs \[ns\]: the longer of the board's and the spec's.
    pub dead_time_ns: u32,
    /// Duration of the longer injected sequence, trigger to last conversion \[s\].
    pub conversion_time_s: f64,
    /// Gate pins u/v/w high, u/v/w low as port·16 + pin (PA8 = 0x08, PB13 = 0x1D).
    pub gate_pins: [u8; 6],
    /// Their alternate functions.
    pub gate_afs: [u8; 6],
    /// Break input, excitation, CAN RX, CAN TX pins (port·16 + pin).
    pub io_pins: [u8; 4],
    /// Their alternate functions.
    pub io_afs: [u8; 4],
    /// Injected channels of ADC1 and ADC2, rank order.
    pub adc_channels: [Vec<u8>; 2],
    /// The signal of each rank ([`Signal::adc_code`]).
    pub adc_signals: [Vec<u8>; 2],
    /// ADC_SMPR code of each rank.
    pub adc_smp: [Vec<u8>; 2],
    /// Phase currents measured (2 or 3).
    pub current_phases: u8,
    /// 1: break input active high (TIM1_BDTR.BKP = 1).
    pub break_active_high: u8,
    /// GPIOx_PUPDR code of the break pin: 0 none, 1 pull-up, 2 pull-down.
    pub break_pull: u8,
    /// TIM1_CCER polarity bits CCxP/CCxNP (x = 1..3) for the gate driver's inputs.
    pub tim1_ccer_polarity: u32,
    /// TIM1_CR2 idle levels OISx/OISxN (x = 1..3): each input's off level.
    pub tim1_cr2_idle: u32,
    /// The level each gate pin (u/v/w high, u/v/w low) is driven to when the outputs are
    /// off (the fault path's GPIO levels).
    pub gate_off_levels: [u8; 6],
    /// HSE crystal frequency \[Hz\], 0 when the board has none.
    pub hse_hz: u32,
    /// 1: currents sampled at the carrier maximum (low-side centre), 0: at the minimum.
    pub sample_at_carrier_maximum: u8,
    /// 1: the image requires and checks the BOOT0 option bytes.
    pub boot0_option_bytes: u8,
    /// The trip levels the image uses: the lower of the motor's limit and the board's
    /// ceiling, each with which one set it.
    pub trips: Trips,
    /// Over-speed trip as electrical speed n_p·ω_m \[rad/s\] (of `trips.over_speed_rad_s`).
    pub over_speed_electrical_rad_s: f64,
    /// TIM1 ticks from the ADC trigger (TRGO2 = OC4REF at the board's sampling instant)
    /// to the update event that loads the compare values the control step computed from
    /// that trigger's conversions (`control_timing`).
    pub trigger_to_update_ticks: u32,
    /// From the ADC trigger to the mean end of the phase currents' sampling phases \[s\]
    /// (`board::current_sample_instant`).
    pub current_sample_instant_s: f64,
    /// From the ADC trigger to the mean end of the resolver SIN and COS sampling phases
    /// \[s\] (`board::resolver_sample_instant`).
    pub resolver_sample_instant_s: f64,
    /// TIM3's resolver-excitation edges this many timer ticks later than half a carrier
    /// period after the ADC trigger, so that the excitation's fundamental peaks at the
    /// resolver's mean hold instant (`excitation_shift_ticks`).
    pub excitation_shift_ticks: u16,
    /// How long after the resolver's SIN its COS is held \[s\] (`board::resolver_skew`):
    /// the design takes their mean instant, which leaves a ripple of the angle at twice
    /// the resolver angle.
    pub resolver_skew_s: f64,
    /// That ripple's amplitude in electrical angle at the over-speed trip \[rad\]:
    /// ω_e·|Δt|/2 (first order in ε = ω_r·Δt/2, times n_p/n_r), the most the drive can
    /// see of it.
    pub resolver_skew_ripple_rad: f64,
    /// The resolver signal at the observer's input as a fraction of full scale
    /// (`board::resolver_signal_gain`: the front end's amplitude over V_REF/2 times the
    /// excitation's envelope where SIN and COS are held): what the image measures at
    /// start-up against [`RESOLVER_SIGNAL_RATIO`].
    pub resolver_signal: f64,
    /// The least and largest measured/designed resolver signal the start-up check
    /// accepts ([`RESOLVER_SIGNAL_RATIO`]).
    pub resolver_signal_ratio_min: f64,
    /// See `resolver_signal_ratio_min`.
    pub resolver_signal_ratio_max: f64,
    /// The delay from the resolver's sample to the mean of the voltage computed from it
    /// [periods of T_s], the default angle lead k (thesis A (4.23)).
    pub angle_lead_periods: f64,
    /// The loop delay this timing makes, which the current loop is designed for \[s\]:
    /// from the currents' sample to the update, plus half a period, the mean delay of the
    /// voltage held over the period after the update (thesis A §4.6).
    pub loop_delay_s: f64,
    /// The largest duty the current sensing's sampling window leaves and the voltage it
    /// leaves the design (`design::duty_limit`).
    pub duty_limit: DutyLimit,
    /// CAN nominal bit rate \[bit/s\].
    pub can_bit_rate: u32,
    /// FDCAN1's nominal bit timing for that rate from the FDCAN kernel clock
    /// (`firmware::can_bit_timing`, RM0440 §44.4.7).
    pub can_timing: CanBitTiming,
    /// What does not fit between this board and this motor (also in the design's
    /// warnings), located at the board key.
    pub warnings: Vec<String>,
}

/// Which limit set a trip level.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum TripSource {
    /// The motor's limit (its design's full scale) is the lower.
    Motor,
    /// The board's `[protection]` ceiling is the lower (or equal).
    Board,
}

/// One trip level of the image.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Trip {
    /// The level the image trips at (SI: A, V, rad/s mechanical): min(motor, board).
    pub value: f64,
    /// Which of the two set it.
    pub set_by: TripSource,
    /// The motor's limit (SI).
    pub motor_limit: f64,
    /// How the motor's limit is computed, with its numbers and keys.
    pub motor_rule: String,
    /// The board's ceiling (SI), its `[protection]` value.
    pub board_ceiling: f64,
    /// The board key of the ceiling.
    pub board_key: &'static str,
}

impl Trip {
    fn new(motor_limit: f64, motor_rule: String, board_ceiling: f64, board_key: &'static str) -> Trip {
        let set_by = if motor_limit < board_ceiling {
            TripSource::Motor
        } else {
            TripSource::Board
        };
        Trip {
            value: motor_limit.min(board_ceiling),
            set_by,
            motor_limit,
            motor_rule,
            board_ceiling,
            board_key,
        }
    }

    /// Who set it, in words: `motor: 1.25·√2·10 A` or `board: protection.over_current`.
    pub fn describe(&self, unit: &str, scale: f64) -> String {
        let motor = format!("{:.2} {unit} ({})", self.motor_limit * scale, self.motor_rule);
        let board = format!("{:.2} {unit} ({})", self.board_ceiling * scale, self.board_key);
        match self.set_by {
            TripSource::Motor => format!("set by the motor: {motor}; board ceiling {board}"),
            TripSource::Board => format!("set by the board: {board}; motor's limit {motor}"),
        }
    }
}

/// The image's trip levels.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Trips {
    /// |i| of any phase \[A\].
    pub over_current_a: Trip,
    /// U_dc \[V\].
    pub over_voltage_v: Trip,
    /// Mechanical speed \[rad/s\].
    pub over_speed_rad_s: Trip,
}

/// The trip levels of the motor of `d` on `board`: the motor's limits are its design's
/// full scales, margin·√2·I_peak, margin·U_dc (thesis A Table 4.1) and margin·n_max; the
/// board's `[protection]` values are ceilings.
fn trips(board: &Board, d: &Design) -> Trips {
    let margin = d.scaling.margin;
    let speed = margin * d.motor.max_speed_rad_s;
    Trips {
        over_current_a: Trip::new(
            d.scaling.phase_current.full_scale,
            format!(
                "scaling.margin·√2·peak_current = {margin}·√2·{} A",
                d.motor.peak_current_a_rms
            ),
            board.over_current_a,
            "protection.over_current",
        ),
        over_voltage_v: Trip::new(
            d.scaling.dc_link_voltage.full_scale,
            format!(
                "scaling.margin·dc_link_voltage = {margin}·{} V",
                d.drive.dc_link_voltage_v
            ),
            board.over_voltage_v,
            "protection.over_voltage",
        ),
        over_speed_rad_s: Trip::new(
            speed,
            format!("scaling.margin·max_speed = {margin}·{:.0} rpm", d.motor.max_speed_rpm),
            board.over_speed_rad_s,
            "protection.over_speed",
        ),
    }
}

/// The board with the motor of `d`, and the warnings (each located at its board key); or
/// what does not fit between them, each an error at its board key.
pub(in crate::design) fn board(
    board: &Board,
    board_src: Source<'_>,
    d: &Design,
) -> Result<(BoardOut, Vec<String>), Vec<Diagnostic>> {
    let board_text = board_src.text;
    // The board's own warnings (stated facts its parts' datasheets contradict) travel with
    // every design on it.
    let mut warnings = board.warnings.clone();
    let mut errors = Vec::new();
    let mut refuse = |key: &str, problem: String, accepted: String| {
        errors.push(board_src.error(board.span(key), key, problem, accepted));
    };
    let i_fs = board.current_full_scale_a();
    let u_fs = board.dc_link_full_scale_v();
    let peak = d.motor.peak_current_a;
    let rms_max = |a: f64| a / std::f64::consts::SQRT_2;
    let spec = &d.spec_file;
    if i_fs < peak {
        // The largest |gain| [V/A] at the pin that keeps ±I_peak inside the ADC's range at
        // this offset, said in the key's own terms.
        let gain_max = board
            .current
            .offset_v
            .min(board.adc_reference_v - board.current.offset_v)
            / peak;
        let (gain_key, gain_accepted) = match (board.current.kind, board.current.shunt_ohm) {
            (crate::board::SensorKind::Shunt, Some(shunt)) => (
                "current_sensing.amplifier_gain",
                format!(
                    "an amplifier gain up to {:.2} with this {:.1} mΩ shunt and offset",
                    gain_max / shunt,
                    shunt * 1e3
                ),
            ),
            (crate::board::SensorKind::Shunt, None) => (
                "current_sensing.amplifier_gain",
                format!("a gain at the pin up to {:.2} mV/A at this offset", gain_max * 1e3),
            ),
            (crate::board::SensorKind::Hall, _) => (
                "current_sensing.sensitivity",
                format!("a sensitivity up to {:.2} mV/A at this offset", gain_max * 1e3),
            ),
        };
        refuse(
            gain_key,
            format!(
                "the board measures ±{i_fs:.1} A but {} ({spec}) drives its peak current {peak:.1} A (√2·{:.1} A rms, motor.peak_current): currents above {i_fs:.1} A read as the ADC rail",
                d.name, d.motor.peak_current_a_rms
            ),
            format!(
                "current sensing that measures ±{peak:.1} A ({gain_accepted}), or a motor peak_current up to {:.2} A rms",
                rms_max(i_fs)
            ),
        );
    } else if board.over_current_a < peak {
        refuse(
            "protection.over_current",
            format!(
                "the board's power stage is rated to {:.1} A (its over-current ceiling) but {} ({spec}) drives its peak current {peak:.1} A (√2·{:.1} A rms)",
                board.over_current_a, d.name, d.motor.peak_current_a_rms
            ),
            format!(
                "a board rated to at least {peak:.1} A, or a motor peak_current up to {:.2} A rms",
                rms_max(board.over_current_a)
            ),
        );
    }
    let udc = d.drive.dc_link_voltage_v;
    if u_fs < udc {
        refuse(
            "sensing.dc_link_divider",
            format!(
                "the divider measures up to {u_fs:.1} V but {} ({spec}) runs at U_dc = {udc} V (drive.dc_link_voltage): the DC-link reading would saturate and the 1/U_dc feed-forward (5.1) and the over-voltage trip go blind",
                d.name
            ),
            format!(
                "a divider that measures {udc} V (ratio up to {:.5}), or a motor DC link up to {u_fs:.1} V",
                board.adc_reference_v / udc
            ),
        );
    } else if board.over_voltage_v < udc {
        refuse(
            "protection.over_voltage",
            format!(
                "the board's power stage is rated to {:.1} V (its over-voltage ceiling) but {} ({spec}) runs at U_dc = {udc} V",
                board.over_voltage_v, d.name
            ),
            format!(
                "a board rated to at least {udc} V, or a motor DC link up to {:.1} V",
                board.over_voltage_v
            ),
        );
    }
    let n_max = d.motor.max_speed_rad_s;
    if board.over_speed_rad_s < n_max {
        refuse(
            "protection.over_speed",
            format!(
                "the board's over-speed ceiling is {:.0} rpm but {} ({spec}) runs to {:.0} rpm (motor.max_speed): the image would trip in normal operation",
                board.over_speed_rad_s * 30.0 / std::f64::consts::PI,
                d.name,
                d.motor.max_speed_rpm
            ),
            format!(
                "an over-speed ceiling of at least {:.0} rpm, or a motor max_speed up to {:.0} rpm",
                d.motor.max_speed_rpm,
                board.over_speed_rad_s * 30.0 / std::f64::consts::PI
            ),
        );
    }
    // The main loop refreshes the IWDG once the control interrupt has run again
    // (firmware/app/src/board/mod.rs), about once per T_s: a timeout shorter than two
    // control periods resets a healthy drive.
    let ts = d.drive.sample_period_s;
    if board.watchdog_timeout_s < 2.0 * ts {
        refuse(
            "watchdog.timeout",
            format!(
                "a watchdog timeout of {:.1} µs is shorter than two control periods of {} ({spec}), 2·T_s = {:.1} µs: the image refreshes the watchdog once per control period, so it would reset a healthy drive",
                board.watchdog_timeout_s * 1e6,
                d.name,
                2.0 * ts * 1e6
            ),
            format!(
                "a timeout of at least {:.1} µs (2·T_s), or a motor switching faster",
                2.0 * ts * 1e6
            ),
        );
    }
    if offset_bound_code(board) < OFFSET_BOUND_MIN_CODE {
        let headroom_a = i_fs - board.over_current_a;
        refuse(
            "protection.over_current",
            format!(
                "the over-current ceiling {:.1} A leaves {headroom_a:.2} A between the trip and the ±{i_fs:.1} A the sensing measures: the zero-current level measured at start-up could not deviate by even one 12-bit code before the trip left the ADC's range",
                board.over_current_a
            ),
            format!(
                "an over-current ceiling up to {:.1} A (one 12-bit code, {:.3} A, below full scale), or sensing that measures more",
                i_fs - f64::from(OFFSET_BOUND_MIN_CODE) / CODES_16 * board.adc_reference_v
                    / board.current.gain_v_per_a.abs(),
                f64::from(OFFSET_BOUND_MIN_CODE) / CODES_16 * board.adc_reference_v / board.current.gain_v_per_a.abs()
            ),
        );
    }
    let can_timing = match firmware::can_bit_rate(firmware::fdcan_kernel_clock_hz(board.hse_hz), board.can_bit_rate) {
        Ok(t) => Some(t),
        Err(r) => {
            refuse("can.bit_rate", r.problem, r.accepted);
            None
        }
    };
    let t_conv = sequence_time(board, ADC_CLOCK_HZ);
    let timing = timing_of(board, d.drive.switching_frequency_hz);
    if let Some(t) = &timing {
        let designed = d.current_loop.loop_delay_s;
        // The conversions must end (and the step run) before the update that is to
        // load its compare values; past it they would act a period later, a loop
        // delay the sampled model does not carry (`current_loop::discrete::plant`).
        if t_conv >= t.trigger_to_update_s {
            refuse(
                "sensing.source_resistance.current",
                format!(
                    "the conversions take {:.2} µs after the trigger, beyond the {:.2} µs to the update event that loads the step's compare values: the duties would act a period later, a loop delay of {:.2}·T_s the current loop of {} ({spec}) cannot be designed for",
                    t_conv * 1e6,
                    t.trigger_to_update_s * 1e6,
                    t.loop_delay_s / ts + 1.0,
                    d.name
                ),
                "source resistances whose sampling times fit well inside one control period".into(),
            );
        } else if (t.loop_delay_s - designed).abs() > 1e-9 * ts {
            // `crate::design_with_board` designs the current loop for this board's
            // delay; a design made for another board or none is not this pair's.
            refuse(
                "sensing.sample_instant",
                format!(
                    "the sampling instant and TIM1's update scheme make a loop delay of {:.4} µs ({:.4}·T_s), but the current loop of {} ({spec}) was designed for {:.4} µs",
                    t.loop_delay_s * 1e6,
                    t.loop_delay_s / ts,
                    d.name,
                    designed * 1e6
                ),
                "the motor designed on this board (`codegen::design_with_board`)".into(),
            );
        } else if d.angle_observer.lead_samples_source == crate::spec::Provenance::Default
            && (d.angle_observer.lead_samples - t.angle_lead_periods).abs() > 1e-9
        {
            refuse(
                "sensing.sample_instant",
                format!(
                    "the resolver's sampling instant and TIM1's update scheme make an angle lead of {:.4} periods, but the angle observer of {} ({spec}) was designed with {:.4}",
                    t.angle_lead_periods, d.name, d.angle_observer.lead_samples
                ),
                "the motor designed on this board (`codegen::design_with_board`)".into(),
            );
        }
    }
    let dead_s = d
        .drive
        .dead_time_s
        .map_or(board.dead_time_s, |spec| spec.max(board.dead_time_s));
    let limit = duty_limit::for_board(board, d.drive.switching_frequency_hz, dead_s);
    if let Some(l) = &limit
        && let Some(e) = refuse_duty_limit(board, board_src, l, d.drive.switching_frequency_hz)
    {
        errors.push(e);
    }
    let mut warn = |key: &str, problem: String| warnings.push(warning_at(board, board_text, key, &problem));
    if t_conv > 0.25 * ts {
        warn(
            "sensing.source_resistance.current",
            format!(
                "the conversions take {:.2} µs after the trigger, {:.0} % of the {:.1} µs control period: the control step starts late",
                t_conv * 1e6,
                t_conv / ts * 100.0,
                ts * 1e6
            ),
        );
    }
    let gates = [
        Signal::GateUHigh,
        Signal::GateVHigh,
        Signal::GateWHigh,
        Signal::GateULow,
        Signal::GateVLow,
        Signal::GateWLow,
    ];
    let io = [
        Signal::BreakInput,
        Signal::ResolverExcitation,
        Signal::CanRx,
        Signal::CanTx,
    ];
    let (Some(can_timing), Some(timing), Some(duty_limit), true) = (can_timing, timing, limit, errors.is_empty())
    else {
        return Err(errors);
    };
    let trips = trips(board, d);
    let over_speed_electrical_rad_s = trips.over_speed_rad_s.value * f64::from(d.motor.pole_pairs);
    let resolver_skew_s = resolver_skew(board, ADC_CLOCK_HZ);
    let out = BoardOut {
        board: board.clone(),
        current_offset_code: (board.current.offset_v / board.adc_reference_v * CODES_16).round() as i32,
        amps_per_lsb: board.adc_reference_v / (board.current.gain_v_per_a * CODES_16),
        current_full_scale_a: i_fs,
        offset_samples: offset_samples(),
        offset_bound_code: offset_bound_code(board),
        dc_link_volts_per_lsb: board.adc_reference_v / (board.dc_link_divider * CODES_15),
        dc_link_full_scale_v: u_fs,
        dead_time_ns: firmware::dead_time_ns(dead_s),
        conversion_time_s: t_conv,
        gate_pins: gates.map(|s| pin_code(board, s)),
        gate_afs: gates.map(|s| pin_af(board, s)),
        io_pins: io.map(|s| pin_code(board, s)),
        io_afs: io.map(|s| pin_af(board, s)),
        adc_channels: board.adc.clone().map(|q| q.iter().map(|x| x.channel).collect()),
        adc_signals: board.adc.clone().map(|q| {
            q.iter()
                .map(|x| if x.padding { u8::MAX } else { x.signal.adc_code() })
                .collect()
        }),
        adc_smp: board
            .adc
            .clone()
            .map(|q| q.iter().map(|x| x.sampling.smp_code).collect()),
        current_phases: if board.pin(Signal::CurrentW).is_some() { 3 } else { 2 },
        break_active_high: u8::from(break_active_high(board)),
        break_pull: break_pull(board),
        tim1_ccer_polarity: tim1_ccer_polarity(board),
        tim1_cr2_idle: tim1_cr2_idle(board),
        gate_off_levels: gates::off_levels(&board.gate_driver),
        hse_hz: board.hse_hz.map_or(0, |f| f.round() as u32),
        sample_at_carrier_maximum: u8::from(samples_at_carrier_maximum(board)),
        boot0_option_bytes: u8::from(checks_option_bytes(board)),
        over_speed_electrical_rad_s,
        trips,
        resolver_skew_s,
        excitation_shift_ticks: excitation_shift_ticks(timing.resolver_sample_instant_s),
        resolver_skew_ripple_rad: 0.5 * over_speed_electrical_rad_s * resolver_skew_s.abs(),
        resolver_signal: crate::board::resolver_signal_gain(board, d.drive.switching_frequency_hz),
        resolver_signal_ratio_min: RESOLVER_SIGNAL_RATIO.0,
        resolver_signal_ratio_max: RESOLVER_SIGNAL_RATIO.1,
        trigger_to_update_ticks: timing.trigger_to_update_ticks,
        current_sample_instant_s: timing.current_sample_instant_s,
        resolver_sample_instant_s: timing.resolver_sample_instant_s,
        angle_lead_periods: timing.angle_lead_periods,
        loop_delay_s: timing.loop_delay_s,
        duty_limit,
        can_bit_rate: can_timing.bit_rate,
        can_timing,
        warnings: Vec::new(),
    };
    let out = BoardOut {
        warnings: warnings.clone(),
        ..out
    };
    Ok((out, warnings))
}

/// Smallest usable fraction of U_dc/√3 a board's sampling window may leave
/// (`design::duty_limit`): below half of the modulator's linear range the sampling, not
/// the motor or the DC link, would set the drive's voltage and so its speed range —
/// a board file whose window needs that much of the carrier period has a wrong sampling
/// or settling time, or the motor switches too fast for it. (The spec's own
/// `field_weakening.voltage_fraction` stops at 0.5 of V_max for the same reason: below
/// it the field-weakening gain grows without bound, thesis B (2.60).)
pub const MIN_USABLE_VOLTAGE_FRACTION: f64 = 0.5;

/// The board key of the condition that set a duty limit: the settling time, or the
/// dead time where it is the larger part of the settling condition, or the current
/// inputs' sampling time.
pub fn duty_limit_key(l: &DutyLimit) -> &'static str {
    match l.bound {
        DutyBound::Settling if l.dead_time_s > l.settling_time_s => "pwm.dead_time",
        DutyBound::Settling => "current_sensing.settling_time",
        DutyBound::DeadTime => "pwm.dead_time",
        DutyBound::SamplingEnd => "sensing.source_resistance.current",
    }
}

/// The refusal of a duty limit that leaves less than [`MIN_USABLE_VOLTAGE_FRACTION`] of
/// U_dc/√3, at the board key of the condition that set it (the settling time, or the
/// dead time where it is the larger part, or the current inputs' sampling time), with
/// the switching frequency that would leave enough.
pub fn refuse_duty_limit(board: &Board, board_src: Source<'_>, l: &DutyLimit, fs_hz: f64) -> Option<Diagnostic> {
    if l.usable_voltage_fraction >= MIN_USABLE_VOLTAGE_FRACTION {
        return None;
    }
    // d_floor: the duty whose usable fraction is the floor.
    let d_floor = 0.5 + duty_limit::thpwm_phase_peak(MIN_USABLE_VOLTAGE_FRACTION);
    let key = duty_limit_key(l);
    let timer_hz = f64::from(crate::firmware::TIMER_CLOCK_HZ);
    if l.bound == DutyBound::DeadTime {
        let fs_max = highest_switching_frequency(u32::from(l.min_pulse), d_floor);
        return Some(board_src.error(
            board.span(key),
            key,
            format!(
                "a dead time of {:.0} ns (the longer of the board's and the motor's) is {} timer ticks as TIM1 makes it, and no compare value may come within that of either end of the carrier (its edge's dead interval would fall into the next period), so at f_s = {fs_hz} Hz the duty may reach only {:.3}, leaving {:.0} % of U_dc/√3 (at least {:.0} % is needed)",
                l.dead_time_s * 1e9,
                l.min_pulse,
                l.max_duty,
                l.usable_voltage_fraction * 100.0,
                MIN_USABLE_VOLTAGE_FRACTION * 100.0
            ),
            format!(
                "a shorter dead time (`pwm.dead_time` here, `drive.dead_time` in the motor file), or a motor switching at most {fs_max} Hz (d_max ≥ {d_floor:.3})"
            ),
        ));
    }
    let window_ticks = (l.half_window_s * timer_hz - 1e-9).ceil().max(0.0) as u32;
    let fs_max = highest_switching_frequency(window_ticks, d_floor);
    Some(board_src.error(
        board.span(key),
        key,
        format!(
            "the low-side shunts need the low side on for {:.2} µs either side of the carrier maximum (dead time {:.0} ns + settling {:.0} ns before the sampling, the current ranks' sampling to {:.0} ns after the trigger), so at f_s = {fs_hz} Hz the duty may reach only {:.3}, leaving {:.0} % of U_dc/√3 (at least {:.0} % is needed)",
            l.half_window_s * 1e6,
            l.dead_time_s * 1e9,
            l.settling_time_s * 1e9,
            l.ranks.iter().map(|r| r.end_s).fold(0.0, f64::max) * 1e9,
            l.max_duty,
            l.usable_voltage_fraction * 100.0,
            MIN_USABLE_VOLTAGE_FRACTION * 100.0
        ),
        format!(
            "a shorter settling, dead or sampling time, or a motor switching at most {fs_max} Hz (d_max ≥ {d_floor:.3})"
        ),
    ))
}

/// The highest whole switching frequency \[Hz\] whose duty limit `(ARR − gap)/ARR`, with
/// `gap` timer ticks kept from the carrier's end, reaches `d_floor`, ARR as the image
/// rounds it (`firmware::pwm_period`): the smallest ARR that does is
/// `⌈gap/(1 − d_floor)⌉`, and `ARR = ⌊f_TIM/(2·f_s) + ½⌋` holds it for
/// `f_s ≤ f_TIM/(2·(ARR − ½))`; checked down from there whole hertz by whole hertz
/// against the same rounding and the limit itself. 0 when no 16-bit ARR leaves enough.
pub fn highest_switching_frequency(gap: u32, d_floor: f64) -> u32 {
    let timer_hz = f64::from(crate::firmware::TIMER_CLOCK_HZ);
    let arr_min = (f64::from(gap) / (1.0 - d_floor)).ceil();
    let leaves_enough = |fs: u32| {
        crate::firmware::pwm_period(f64::from(fs))
            .is_ok_and(|arr| (f64::from(arr) - f64::from(gap)) / f64::from(arr) >= d_floor)
    };
    let mut fs = (timer_hz / (2.0 * (arr_min - 0.5))).floor().max(0.0) as u32;
    while fs > 0 && !leaves_enough(fs) {
        fs -= 1;
    }
    fs
}

/// The ADC's noise taken for the offset average \[12-bit LSB rms\]: the ideal 12-bit
/// quantisation noise is 1/√12 = 0.29 LSB; 1 LSB covers a real conversion's thermal and
/// reference noise besides (an assumption of this design, not a datasheet figure).
pub const OFFSET_NOISE_LSB: f64 = 1.0;
/// Resolution the averaged zero level must reach at 3σ \[12-bit LSB\]: a quarter LSB
/// (4 of the core's 16-bit codes).
pub const OFFSET_RESOLUTION_LSB: f64 = 0.25;
/// Smallest offset bound a board may leave \[16-bit codes\]: one 12-bit code.
pub const OFFSET_BOUND_MIN_CODE: i32 = 16;

/// Conversions averaged per phase at start-up: the smallest power of two N with
/// 3·σ/√N ≤ [`OFFSET_RESOLUTION_LSB`] for σ = [`OFFSET_NOISE_LSB`] (standard error of a
/// mean of N independent samples): N ≥ (3·1/0.25)² = 144 → 256 (moteus, an open STM32G474
/// drive, averages 256 as well).
pub fn offset_samples() -> u32 {
    let n_min = (3.0 * OFFSET_NOISE_LSB / OFFSET_RESOLUTION_LSB).powi(2);
    let mut n = 1u32;
    while f64::from(n) < n_min {
        n *= 2;
    }
    n
}

/// Largest deviation of the measured zero-current level from the board's nominal one
/// \[16-bit codes\]: the room the sensing leaves between the board's over-current
/// ceiling and the nearer ADC rail, `min(V_0, V_REF+ − V_0) − |G|·I_oc`, over V_REF+ ·
/// 2^16 (rounded down). A zero level off by more moves the over-current level out of
/// what the converter measures on one side (the trip would then see only the rail), and
/// says the board is not what its file describes (a wrong offset, a dead amplifier, a
/// sensor without supply).
pub fn offset_bound_code(board: &Board) -> i32 {
    let v0 = board.current.offset_v;
    let room_v = v0.min(board.adc_reference_v - v0) - board.current.gain_v_per_a.abs() * board.over_current_a;
    (room_v / board.adc_reference_v * CODES_16).floor().max(0.0) as i32
}

/// The control interrupt's timing, derived from the board's sampling instant and TIM1's
/// update scheme (firmware `registers::trigger_channel`, `registers::repetition`):
///
/// * the ADC trigger TRGO2 = OC4REF rises at the carrier minimum (CNT = 0, PWM mode 1
///   with CCR4 = 1), or for low-side shunts one tick before the maximum (PWM mode 2,
///   CCR4 = ARR − 1) so the conversions start inside the low-side pulse;
/// * the update event, which loads the preloaded compare values (TIMx_CCMRx.OCxPE, RM0440
///   §28.3.10), falls at the same carrier extreme, once per period (RCR = 1 with
///   REP_CNT set at the start, RM0440 §28.3.5);
/// * the control interrupt writes the compare values after the conversions, within the
///   period: the next update, one carrier period 2·ARR ticks after the one at the
///   trigger, loads them — for the low-side trigger one tick later, as the trigger
///   precedes its extreme by one tick.
///
/// The currents are held `held.currents_s` after the trigger (the end of their sampling
/// phases, `board::current_sample_instant`), so the loop delay is the time from there to
/// the update plus half a period: the voltage is held for the period after the update,
/// its mean half a period later (thesis A §4.6, which samples at the update: 1.5·T_s).
/// The current loop is designed for it (`current_loop::discrete`). In the same way the
/// resolver, held `held.resolver_s` after the trigger, sets the angle lead k (thesis A
/// (4.23)): from its sample to the voltage's mean, in periods.
fn control_timing(at_carrier_maximum: bool, arr: u16, ts: f64, held: HoldInstants) -> ControlTiming {
    let ticks = 2 * u32::from(arr) + u32::from(at_carrier_maximum);
    let s = f64::from(ticks) / f64::from(firmware::TIMER_CLOCK_HZ);
    ControlTiming {
        trigger_to_update_ticks: ticks,
        trigger_to_update_s: s,
        current_sample_instant_s: held.currents_s,
        resolver_sample_instant_s: held.resolver_s,
        loop_delay_s: s - held.currents_s + 0.5 * ts,
        angle_lead_periods: (s - held.resolver_s) / ts + 0.5,
    }
}

/// TIM3's shift of the resolver excitation \[timer ticks\]: the resolver's mean hold
/// instant `resolver_s` after the trigger, rounded. The excitation is a square wave at
/// f_s/2 that TIM3 toggles once per carrier period, `ARR + shift` ticks after each ADC
/// trigger resets it (firmware `board::resolver`); its fundamental, which the board's
/// excitation filter passes (thesis A §4.4), peaks midway between two edges, `shift`
/// ticks after the trigger — at the instant the ADCs hold SIN and COS. There the
/// envelope cos(π·f_s·(t − t_peak)) is at its extremum for both: an excitation peaking
/// at the trigger would read the two windings at the gains cos(π·f_s·t_SIN) and
/// cos(π·f_s·t_COS) — unequal where they are held apart (the NUCLEO's 1.52 and 7.64 µs
/// at 40 kHz: 0.982 and 0.574, an angle error up to 15° of the resolver), and less than
/// one everywhere (thesis A §4.4.1: a shift only lowers the apparent amplitude).
pub fn excitation_shift_ticks(resolver_s: f64) -> u16 {
    (resolver_s * f64::from(firmware::TIMER_CLOCK_HZ)).round() as u16
}

/// When the ADCs hold what the control step reads, after the trigger \[s\].
#[derive(Debug, Clone, Copy)]
struct HoldInstants {
    /// The phase currents' mean (`board::current_sample_instant`).
    currents_s: f64,
    /// The resolver SIN's and COS's mean (`board::resolver_sample_instant`).
    resolver_s: f64,
}

/// The start-up resolver check's bounds on the measured signal over the designed one
/// (`resolver_signal`): the trig-identity observer's ω_n and ζ scale with the square
/// root of that ratio (thesis A (4.10)), so (1 ∓ 20 %)² = 0.64 … 1.44 keeps them within
/// 20 % of the design; a dead excitation or an unplugged resolver (≈ 0) and a front end
/// unlike the board file's fall outside.
pub const RESOLVER_SIGNAL_RATIO: (f64, f64) = (0.64, 1.44);

/// `control_timing` of `board` at switching frequency `fs_hz` (T_s = 1/f_s, TIM1's
/// period for it, the board's sampling instant and ADC sequences); `None` where TIM1
/// cannot make f_s (`firmware::pwm_period`, refused at `drive.switching_frequency`).
pub fn timing_of(board: &Board, fs_hz: f64) -> Option<ControlTiming> {
    let arr = firmware::pwm_period(fs_hz).ok()?;
    Some(control_timing(
        samples_at_carrier_maximum(board),
        arr,
        1.0 / fs_hz,
        HoldInstants {
            currents_s: current_sample_instant(board, ADC_CLOCK_HZ),
            resolver_s: resolver_sample_instant(board, ADC_CLOCK_HZ),
        },
    ))
}

/// `control_timing`'s figures.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ControlTiming {
    /// TIM1 ticks from the ADC trigger to the update that loads the step's compare values.
    pub trigger_to_update_ticks: u32,
    /// The same in seconds.
    pub trigger_to_update_s: f64,
    /// Trigger → the currents' mean sample instant \[s\].
    pub current_sample_instant_s: f64,
    /// Trigger → the resolver's mean sample instant \[s\].
    pub resolver_sample_instant_s: f64,
    /// Sample → update plus T_s/2 \[s\].
    pub loop_delay_s: f64,
    /// Resolver sample → update plus T_s/2 [periods of T_s]: the angle lead k.
    pub angle_lead_periods: f64,
}

fn pin_code(board: &Board, s: Signal) -> u8 {
    board.pin(s).map_or(u8::MAX, PinUse::code)
}

fn pin_af(board: &Board, s: Signal) -> u8 {
    board.pin(s).and_then(|p| p.af).unwrap_or(u8::MAX)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn board_of(stem: &str) -> Board {
        let file = format!("boards/{stem}.toml");
        let text = std::fs::read_to_string(format!("{}/../../{file}", env!("CARGO_MANIFEST_DIR"))).unwrap();
        crate::board::parse(crate::Source {
            file: &file,
            text: &text,
        })
        .unwrap()
    }

    /// Hand calculation (RM0440 §21.4.12, DS12288 Table 66; ADC clock 170 MHz/4 =
    /// 42.5 MHz): both boards sense three phases, u and v first on ADC1 and ADC2, w second
    /// on ADC1, every current sampled 24.5 cycles (the board files' sequences). Held at
    /// 3.125 + 24.5 = 27.625 cycles (u, v) and 3.125 + 24.5 + 12.5 + 24.5 = 64.625 (w):
    /// mean 39.958 cycles = 0.940 196 µs.
    /// * motorgen-reference at 20 kHz (ARR 4250, trigger at the minimum): update 8500
    ///   ticks = 50 µs after the trigger; D = (50 − 0.940 196 + 25) µs = 74.059 804 µs =
    ///   1.481 196·T_s.
    /// * nucleo-g474re-ihm08m1 at 40 kHz (ARR 2125, low-side trigger one tick before the
    ///   maximum): 4251 ticks = 25.005 882 µs; D = (25.005 882 − 0.940 196 + 12.5) µs =
    ///   36.565 686 µs = 1.462 627·T_s.
    #[test]
    fn loop_delay_by_hand() {
        let reference = timing_of(&board_of("motorgen-reference"), 20e3).unwrap();
        assert_eq!(reference.trigger_to_update_ticks, 8500);
        assert!((reference.current_sample_instant_s - 0.940_196e-6).abs() < 1e-12);
        assert!(
            (reference.loop_delay_s - 74.059_804e-6).abs() < 1e-12,
            "{}",
            reference.loop_delay_s
        );
        let nucleo = timing_of(&board_of("nucleo-g474re-ihm08m1"), 40e3).unwrap();
        assert_eq!(nucleo.trigger_to_update_ticks, 4251);
        assert!(
            (nucleo.loop_delay_s - 36.565_686e-6).abs() < 1e-12,
            "{}",
            nucleo.loop_delay_s
        );
        // The resolver: on the reference board SIN and COS both rank 3, after two 24.5-cycle
        // ranks (the DC link moved ahead of SIN, `sequence::align_resolver`): 3.125 + 2·37
        // + 24.5 = 101.625 cycles = 2.391 176 µs, k = (50 − 2.391 176)/50 + ½ = 1.452 176.
        // On the NUCLEO SIN rank 2 (3.125 + 37 + 24.5 = 64.625 cycles), COS rank 3 with
        // 247.5 cycles (324.625), mean 194.625 = 4.579 412 µs: k = (25.005 882 −
        // 4.579 412)/25 + ½ = 1.317 059.
        assert!((reference.resolver_sample_instant_s - 2.391_176e-6).abs() < 1e-12);
        assert!(
            (reference.angle_lead_periods - 1.452_176).abs() < 1e-6,
            "{}",
            reference.angle_lead_periods
        );
        assert!((nucleo.resolver_sample_instant_s - 4.579_412e-6).abs() < 1e-12);
        // SIN and COS both at rank 3 on the reference board (101.625 cycles: no skew); SIN
        // rank 2, COS rank 3 on the NUCLEO (260 cycles = 6.117 647 µs apart: aligning them
        // would move its DC link's 247.5-cycle rank ahead of current v).
        let skew = |stem: &str| resolver_skew(&board_of(stem), ADC_CLOCK_HZ);
        assert_eq!(skew("motorgen-reference"), 0.0);
        assert!((skew("nucleo-g474re-ihm08m1") - 6.117_647e-6).abs() < 1e-12);
        // The excitation's peak at the mean hold instant, in 170 MHz ticks (4 per ADC
        // cycle): 101.625·4 = 406.5 → 407; 194.625·4 = 778.5 → 779.
        assert_eq!(excitation_shift_ticks(reference.resolver_sample_instant_s), 407);
        assert_eq!(excitation_shift_ticks(nucleo.resolver_sample_instant_s), 779);
        assert!(
            (nucleo.angle_lead_periods - 1.317_059).abs() < 1e-6,
            "{}",
            nucleo.angle_lead_periods
        );
        // The resolver signal at the observer: 0.66 V over the 1.65 V half range = 0.4 on
        // both boards; on the NUCLEO at 40 kHz each winding is held 3.058 824 µs from the
        // excitation's peak: 0.4·cos(π·40 000·3.058 824e-6) = 0.4·cos(0.384 383) = 0.4·0.927 030 = 0.370 812.
        let gain = |stem: &str, fs: f64| crate::board::resolver_signal_gain(&board_of(stem), fs);
        assert!((gain("motorgen-reference", 20e3) - 0.4).abs() < 1e-12);
        assert!((gain("nucleo-g474re-ihm08m1", 40e3) - 0.370_812).abs() < 1e-6);
    }

    /// N: (3·1 LSB/0.25 LSB)² = 144 → the next power of two, 256.
    #[test]
    fn offset_samples_by_hand() {
        assert_eq!(offset_samples(), 256);
    }

    /// Hand calculation per board, 16-bit codes = V/3.3 V·65 536 rounded down:
    /// * motorgen-reference: min(1.65, 1.65) − 15 mV/A·100 A = 0.150 V → 2978.9 → 2978
    ///   (186 12-bit codes, 10 A);
    /// * motorgen-reference-400a: 1.65 − 3.75 mV/A·400 A = 0.150 V → 2978 (40 A);
    /// * nucleo-g474re-ihm08m1: min(1.71, 1.59) − 51.8 mV/A·25 A = 1.59 − 1.295 = 0.295 V
    ///   → 5858.5 → 5858 (366 12-bit codes, 5.69 A).
    #[test]
    fn offset_bound_by_hand() {
        assert_eq!(offset_bound_code(&board_of("motorgen-reference")), 2978);
        assert_eq!(offset_bound_code(&board_of("motorgen-reference-400a")), 2978);
        assert_eq!(offset_bound_code(&board_of("nucleo-g474re-ihm08m1")), 5858);
    }
}
