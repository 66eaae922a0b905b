//! The board section (`design.board`), a motor on an inverter board: the ADC-to-SI
//! constants from the board's sensing (the 16-bit left-aligned codes of thesis A (4.16),
//! Table 4.1; the sequences' timing of RM0440 §21.4.12), the dead time, trips and bus
//! timing in the units the firmware needs, and the checks that can only be made with
//! both — a board whose current range is below the motor's peak current, a DC link above
//! what the divider measures, trips below the motor's ratings, conversions that take too
//! much of the control period. It runs on the motor's finished design
//! ([`crate::design::on_board`]).
//!
//! Those are warnings at the board key, not errors: an engineer may well run a large
//! motor on a small board at reduced current (the firmware trips at the board's levels
//! and the ADC scaling is the board's, so the image measures correctly); the image for
//! every motor stays buildable on every board, and `motorgen firmware`/`check` print
//! what does not fit.

use serde::Serialize;

use crate::board::{
    ADC_CLOCK_HZ, Board, PinUse, Signal, break_active_high, break_pull, checks_option_bytes, gates,
    samples_at_carrier_maximum, sequence_time, tim1_ccer_polarity, tim1_cr2_idle, warning_at,
};
use crate::design::Design;

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
    /// Over-speed trip as electrical speed n_p·ω_m \[rad/s\].
    pub over_speed_electrical_rad_s: f64,
    /// CAN nominal bit rate \[bit/s\].
    pub can_bit_rate: u32,
    /// What does not fit between this board and this motor (also in the design's
    /// warnings), located at the board key.
    pub warnings: Vec<String>,
}

/// The board with the motor of `d`, and the warnings (each located at its board key).
pub(in crate::design) fn board(board: &Board, board_text: &str, d: &Design) -> (BoardOut, Vec<String>) {
    let mut warnings = board.warnings.clone();
    let mut warn = |key: &str, problem: String| warnings.push(warning_at(board, board_text, key, &problem));
    let i_fs = board.current_full_scale_a();
    let u_fs = board.dc_link_full_scale_v();
    let peak = d.motor.peak_current_a;
    let gain_key = match board.current.kind {
        crate::board::SensorKind::Shunt => "current_sensing.amplifier_gain",
        crate::board::SensorKind::Hall => "current_sensing.sensitivity",
    };
    if i_fs < peak {
        warn(
            gain_key,
            format!(
                "the board measures ±{i_fs:.1} A but {} needs its peak current {peak:.1} A (√2·{:.1} A rms): currents above {i_fs:.1} A read as the ADC rail and trip the drive; size the sensing to the motor or lower its peak current",
                d.name, d.motor.peak_current_a_rms
            ),
        );
    }
    if board.over_current_a < peak && i_fs >= peak {
        warn(
            "protection.over_current",
            format!(
                "the drive trips at {:.1} A, below {}'s peak current {peak:.1} A",
                board.over_current_a, d.name
            ),
        );
    }
    let udc = d.drive.dc_link_voltage_v;
    if u_fs < udc {
        warn(
            "sensing.dc_link_divider",
            format!(
                "the divider measures up to {u_fs:.1} V but {} runs at U_dc = {udc:.0} V: the DC-link reading saturates (the 1/U_dc feed-forward (5.1) and the over-voltage trip go blind)",
                d.name
            ),
        );
    } else if board.over_voltage_v < udc {
        warn(
            "protection.over_voltage",
            format!(
                "the drive trips at {:.0} V, below {}'s DC link {udc:.0} V",
                board.over_voltage_v, d.name
            ),
        );
    }
    let n_max = d.motor.max_speed_rad_s;
    if board.over_speed_rad_s < n_max {
        warn(
            "protection.over_speed",
            format!(
                "the drive trips at {:.0} rpm, below {}'s maximum speed {:.0} rpm",
                board.over_speed_rad_s * 30.0 / std::f64::consts::PI,
                d.name,
                d.motor.max_speed_rpm
            ),
        );
    }
    let t_conv = sequence_time(board, ADC_CLOCK_HZ);
    let ts = d.drive.sample_period_s;
    if t_conv > 0.25 * ts {
        warn(
            "sensing.source_resistance",
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
    let board_dead = board.dead_time_s;
    let dead_s = d.drive.dead_time_s.map_or(board_dead, |spec| spec.max(board_dead));
    let out = BoardOut {
        board: board.clone(),
        current_offset_code: (board.current.offset_v / board.adc_reference_v * CODES_16).round() as i32,
        amps_per_lsb: board.adc_reference_v / (board.current.gain_v_per_a * CODES_16),
        current_full_scale_a: i_fs,
        dc_link_volts_per_lsb: board.adc_reference_v / (board.dc_link_divider * CODES_15),
        dc_link_full_scale_v: u_fs,
        // Whole nanoseconds, never shorter than asked (the −1e-6 absorbs 500e-9·1e9 = 500.0000000000001).
        dead_time_ns: (dead_s * 1e9 - 1e-6).ceil() as u32,
        conversion_time_s: t_conv,
        gate_pins: gates.map(|s| pin_code(board, s)),
        gate_afs: gates.map(|s| pin_af(board, s)),
        io_pins: io.map(|s| pin_code(board, s)),
        io_afs: io.map(|s| pin_af(board, s)),
        adc_channels: board.adc.clone().map(|q| q.iter().map(|x| x.channel).collect()),
        adc_signals: board
            .adc
            .clone()
            .map(|q| q.iter().map(|x| x.signal.adc_code()).collect()),
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
        over_speed_electrical_rad_s: board.over_speed_rad_s * f64::from(d.motor.pole_pairs),
        can_bit_rate: board.can_bit_rate.round() as u32,
        warnings: Vec::new(),
    };
    let out = BoardOut {
        warnings: warnings.clone(),
        ..out
    };
    (out, warnings)
}

fn pin_code(board: &Board, s: Signal) -> u8 {
    board.pin(s).map_or(u8::MAX, PinUse::code)
}

fn pin_af(board: &Board, s: Signal) -> u8 {
    board.pin(s).and_then(|p| p.af).unwrap_or(u8::MAX)
}
