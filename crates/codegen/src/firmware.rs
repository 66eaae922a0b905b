//! The firmware image's fixed facts (its clock tree) and the limits its build enforces.
//!
//! The image is compiled against one spec and one board; where a value cannot be encoded
//! in the STM32G474's registers, the build fails with a const-evaluation error (the
//! firmware's `match … { None => panic!(…) }` and `const _: () = assert!(…)` items). Every
//! such limit is a row of [`FIRMWARE_LIMITS`], and `motorgen check` enforces each one first,
//! at the key whose value reaches it, with the accepted range and the nearest values that
//! work; the build's assertions stay as a second line. Where the firmware computes the
//! register with a function of the control core (`motor_control::timing`,
//! `motor_control::modulation::centre_aligned_period`), the rule here calls that same
//! function with the same clock, so a value `check` accepts is one the build encodes.
//!
//! The rows are data a test reads (`tests/it/firmware_limits.rs`): it collects every
//! const-evaluated panic and assertion in the firmware's sources and fails on one that no
//! row names (a new firmware limit without a `check` rule), and it runs each row's boundary
//! cases (hand calculations) through `check`.

use motor_control::modulation::centre_aligned_period;
use motor_control::timing::{DTG_MAX_TICKS, IWDG_MAX_RELOAD, dead_time_dtg, iwdg_for_timeout};
use serde::Serialize;

/// TIM1's kernel clock \[Hz\]: SYSCLK = 170 MHz (HSI16/4·85/2, DS12288 §3.9: the
/// STM32G474's maximum in range-1 boost mode) through APB2 with prescaler 1 (RM0440
/// §7.2.17: ×1). The firmware's `hw::TIMER_CLOCK_HZ`; its build checks that the generated
/// `board::TIMER_CLOCK_HZ` equals it.
pub const TIMER_CLOCK_HZ: u32 = 170_000_000;

/// FDCAN kernel clock \[Hz\] of a board without an HSE crystal: PCLK1 = 170 MHz
/// (RCC_CCIPR.FDCANSEL = 0b10, RM0440 §7.4.26). An input of the bit-timing computation
/// ([`can_bit_timing`]), not a literal inside it: see [`fdcan_kernel_clock_hz`].
pub const FDCAN_CLOCK_HZ: u32 = 170_000_000;

/// FDCAN1's kernel clock \[Hz\] on a board with the HSE crystal `hse_hz` (`None`: none):
/// the crystal where there is one (RCC_CCIPR.FDCANSEL = 0b00, RM0440 §7.4.26) — an RC
/// oscillator's tolerance (HSI16, behind the PLL in PCLK1) takes most of what CAN's bit
/// timing tolerates at the 87.5 % sample point (ISO 11898-1), a crystal's tens of ppm
/// almost none — else PCLK1 ([`FDCAN_CLOCK_HZ`]). The image makes the same choice
/// (`firmware/config/src/hw.rs`, `FDCAN_FROM_HSE`).
pub fn fdcan_kernel_clock_hz(hse_hz: Option<f64>) -> u32 {
    hse_hz.map_or(FDCAN_CLOCK_HZ, |f| f.round() as u32)
}

/// LSI clock of the independent watchdog \[Hz\] (DS12288 Table 56, typical 32 kHz); the
/// firmware's `hw::LSI_HZ`.
pub const LSI_HZ: u32 = 32_000;

/// Standard identifier of the fault report, a choice of the firmware: low (high priority
/// on the bus). The generated `can::FAULT_REPORT_ID`; a board's `can.setpoint_id` must keep
/// the drive's own frames off it ([`setpoint_id`]).
pub const FAULT_REPORT_ID: u16 = 0x0E0;

/// CAN sample point the bit timing aims at: 87.5 % of the bit (CiA 601-3 and CiA 301's
/// recommendation for the nominal bit rate; ST's and Bosch's calculators default to it).
pub const CAN_SAMPLE_POINT: f64 = 0.875;

/// Fewest time quanta per nominal bit: 8 (Bosch CAN 2.0 §8, ISO 11898-1: a CAN
/// controller's bit time is programmable from at least 8 quanta).
pub const CAN_MIN_TQ_PER_BIT: u32 = 8;
/// Most time quanta per nominal bit the FDCAN allows: 1 + 256 + 128 = 385 (RM0440
/// §44.4.7, FDCAN_NBTP: NTSEG1 up to 256 quanta, NTSEG2 up to 128).
pub const CAN_MAX_TQ_PER_BIT: u32 = 385;
/// Largest nominal prescaler (NBRP + 1, RM0440 §44.4.7: NBRP 0 … 511).
pub const CAN_MAX_PRESCALER: u32 = 512;

/// Classic CAN's largest nominal bit rate \[bit/s\] (ISO 11898-1).
pub const CLASSIC_CAN_MAX_BIT_RATE: u32 = 1_000_000;

/// The CiA 301 bit rates \[bit/s\] (named in the message when a rate cannot be made).
pub const CIA_BIT_RATES: [u32; 9] = [
    10_000, 20_000, 50_000, 100_000, 125_000, 250_000, 500_000, 800_000, 1_000_000,
];

/// Why a value cannot go into the image, and what would.
#[derive(Debug, Clone, PartialEq)]
pub struct Refusal {
    /// What is wrong, with the numbers.
    pub problem: String,
    /// What is accepted, with the nearest values that work.
    pub accepted: String,
}

/// TIM1's auto-reload for f_s \[Hz\] (centre-aligned: ARR = f_TIM/(2·f_s), in the `f32` the
/// firmware's generated `limits::SWITCHING_FREQUENCY_HZ` carries), or why it does not fit
/// the 16-bit register.
pub fn pwm_period(fs_hz: f64) -> Result<u16, Refusal> {
    if let Some(arr) = centre_aligned_period(TIMER_CLOCK_HZ, fs_hz as f32) {
        return Ok(arr);
    }
    // The lowest f_s that fits, found with the same function (0.01 Hz steps from the
    // bound ARR + ½ = 65535.5).
    let mut lowest = f64::from(TIMER_CLOCK_HZ) / (2.0 * 65_534.5);
    lowest = (lowest * 100.0).floor() / 100.0;
    while centre_aligned_period(TIMER_CLOCK_HZ, lowest as f32).is_none() {
        lowest += 0.01;
    }
    Err(Refusal {
        problem: format!(
            "f_s = {fs_hz} Hz needs a TIM1 auto-reload of {:.0} (f_TIM/(2·f_s), centre-aligned, f_TIM = {} MHz), beyond the 16-bit ARR's 65535 (RM0440 §28.3.3)",
            f64::from(TIMER_CLOCK_HZ) / (2.0 * fs_hz),
            TIMER_CLOCK_HZ / 1_000_000
        ),
        accepted: format!("a switching frequency of at least {lowest:.2} Hz (ARR = 65535)"),
    })
}

/// Whole nanoseconds of a dead time of `seconds`, never shorter than asked (the −1e-6
/// absorbs 500e-9·1e9 = 500.0000000000001): the generated `board::DEAD_TIME_NS`.
pub fn dead_time_ns(seconds: f64) -> u32 {
    (seconds * 1e9 - 1e-6).ceil().clamp(0.0, f64::from(u32::MAX)) as u32
}

/// The longest dead time TIM1 encodes \[s\]: [`DTG_MAX_TICKS`] ticks of [`TIMER_CLOCK_HZ`].
pub fn max_dead_time_s() -> f64 {
    f64::from(DTG_MAX_TICKS) / f64::from(TIMER_CLOCK_HZ)
}

/// TIM1_BDTR.DTG of a dead time of `seconds` (the firmware's computation on the generated
/// nanoseconds), or why TIM1 cannot make it.
pub fn dead_time(seconds: f64) -> Result<u8, Refusal> {
    let ns = dead_time_ns(seconds);
    if let Some(dtg) = dead_time_dtg(ns, TIMER_CLOCK_HZ) {
        return Ok(dtg);
    }
    // The longest whole-nanosecond dead time that encodes.
    let mut longest = (max_dead_time_s() * 1e9).floor() as u32;
    while dead_time_dtg(longest, TIMER_CLOCK_HZ).is_none() {
        longest -= 1;
    }
    Err(Refusal {
        problem: format!(
            "a dead time of {ns} ns is {:.0} ticks of TIM1's {} MHz clock; TIM1_BDTR.DTG encodes at most {DTG_MAX_TICKS} ticks ({longest} ns; RM0440 §28.6.20, CKD = 0)",
            (f64::from(ns) * f64::from(TIMER_CLOCK_HZ) / 1e9).ceil(),
            TIMER_CLOCK_HZ / 1_000_000
        ),
        accepted: format!("a dead time up to {longest} ns ({:.3} µs)", f64::from(longest) / 1e3),
    })
}

/// The longest watchdog timeout the IWDG makes \[s\]: 256·4095 LSI ticks.
pub fn max_watchdog_timeout_s() -> f64 {
    256.0 * f64::from(IWDG_MAX_RELOAD) / f64::from(LSI_HZ)
}

/// The shortest watchdog timeout the IWDG makes \[s\]: prescaler /4 with reload 1, 4 LSI
/// ticks (125 µs at 32 kHz; RM0440 §42.3). The firmware's computation rounds a shorter
/// request up to it, so `check` refuses one instead of building a longer timeout than
/// asked.
pub fn min_watchdog_timeout_s() -> f64 {
    4.0 / f64::from(LSI_HZ)
}

/// IWDG prescaler code and reload for a timeout of `seconds` (the firmware's computation
/// on the generated `f32` timeout), or why the IWDG cannot make it.
pub fn watchdog(seconds: f64) -> Result<(u8, u16), Refusal> {
    let shortest = min_watchdog_timeout_s();
    if seconds < shortest * (1.0 - 1e-9) {
        return Err(Refusal {
            problem: format!(
                "{seconds} s is {:.2} ticks of the {} kHz LSI; the IWDG's shortest timeout is 4 ticks ({:.0} µs: prescaler /4, reload 1, RM0440 §42.3), so the image would wait longer than asked",
                seconds * f64::from(LSI_HZ),
                LSI_HZ / 1000,
                shortest * 1e6
            ),
            accepted: format!(
                "a timeout from {:.0} µs up to {:.2} s",
                shortest * 1e6,
                max_watchdog_timeout_s()
            ),
        });
    }
    if let Some(s) = iwdg_for_timeout(seconds as f32, LSI_HZ) {
        return Ok(s);
    }
    Err(Refusal {
        problem: format!(
            "{seconds} s is {:.0} ticks of the {} kHz LSI; the IWDG counts at most 256·{IWDG_MAX_RELOAD} = {} ticks ({:.2} s; prescaler /256, 12-bit reload, RM0440 §42.3)",
            seconds * f64::from(LSI_HZ),
            LSI_HZ / 1000,
            256 * IWDG_MAX_RELOAD,
            max_watchdog_timeout_s()
        ),
        accepted: format!(
            "a timeout from {:.0} µs up to {:.2} s",
            min_watchdog_timeout_s() * 1e6,
            max_watchdog_timeout_s()
        ),
    })
}

/// The nominal bit timing of FDCAN1 (RM0440 §44.4.7): prescaler, time quanta and the
/// FDCAN_NBTP value that holds them.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CanBitTiming {
    /// The kernel clock it was computed for \[Hz\].
    pub kernel_clock_hz: u32,
    /// The bit rate \[bit/s\]: kernel clock/(prescaler·quanta).
    pub bit_rate: u32,
    /// Kernel clocks per time quantum (NBRP + 1).
    pub prescaler: u32,
    /// Time quanta per bit: 1 (sync) + TSEG1 + TSEG2.
    pub tq_per_bit: u32,
    /// Quanta before the sample point after the sync segment (NTSEG1 + 1).
    pub tseg1: u32,
    /// Quanta after the sample point (NTSEG2 + 1).
    pub tseg2: u32,
    /// Resynchronisation jump width (NSJW + 1) = TSEG2: the largest the FDCAN allows,
    /// which tolerates the largest oscillator error.
    pub sjw: u32,
    /// (1 + TSEG1)/quanta.
    pub sample_point: f64,
    /// FDCAN_NBTP: NSJW\[31:25\], NBRP\[24:16\], NTSEG1\[15:8\], NTSEG2\[6:0\], each the value − 1.
    pub nbtp: u32,
}

/// The bit timing that makes `bit_rate` \[bit/s\] exactly from `kernel_hz`: of every
/// prescaler 1 … 512 and bit of 8 … 385 quanta with kernel_hz = rate·prescaler·quanta, the
/// one whose sample point is nearest [`CAN_SAMPLE_POINT`] (TSEG1 rounded to it, TSEG1 ≤ 256,
/// TSEG2 ≤ 128 quanta), on a tie the smaller prescaler (more quanta per bit: CiA 601-3
/// recommends the smallest prescaler). SJW = TSEG2. `None` if no combination makes the
/// rate exactly.
pub fn can_bit_timing(kernel_hz: u32, bit_rate: f64) -> Option<CanBitTiming> {
    if !(bit_rate >= 1.0 && bit_rate.fract() == 0.0 && bit_rate <= f64::from(kernel_hz)) {
        return None;
    }
    let rate = bit_rate as u64;
    let clk = u64::from(kernel_hz);
    if !clk.is_multiple_of(rate) {
        return None;
    }
    let per_bit = clk / rate;
    let mut best: Option<(f64, CanBitTiming)> = None;
    for prescaler in 1..=CAN_MAX_PRESCALER {
        if !per_bit.is_multiple_of(u64::from(prescaler)) {
            continue;
        }
        let n = per_bit / u64::from(prescaler);
        if n < u64::from(CAN_MIN_TQ_PER_BIT) || n > u64::from(CAN_MAX_TQ_PER_BIT) {
            continue;
        }
        let n = n as u32;
        // 1 + TSEG1 quanta to the sample point, rounded to the aim.
        let to_sample = (CAN_SAMPLE_POINT * f64::from(n)).round() as u32;
        let tseg1 = to_sample.saturating_sub(1);
        if !(1..=256).contains(&tseg1) {
            continue;
        }
        let Some(tseg2) = n.checked_sub(1 + tseg1).filter(|t| (1..=128).contains(t)) else {
            continue;
        };
        let sample_point = f64::from(1 + tseg1) / f64::from(n);
        let error = (sample_point - CAN_SAMPLE_POINT).abs();
        let sjw = tseg2;
        let timing = CanBitTiming {
            kernel_clock_hz: kernel_hz,
            bit_rate: rate as u32,
            prescaler,
            tq_per_bit: n,
            tseg1,
            tseg2,
            sjw,
            sample_point,
            nbtp: ((sjw - 1) << 25) | ((prescaler - 1) << 16) | ((tseg1 - 1) << 8) | (tseg2 - 1),
        };
        // Strictly better only: on a tie the smaller prescaler, found first, stays.
        if best.as_ref().is_none_or(|(e, _)| error < *e - 1e-12) {
            best = Some((error, timing));
        }
    }
    best.map(|(_, t)| t)
}

/// `rate` \[bit/s\] as text: `500 kbit/s`, `1 Mbit/s`.
fn bit_rate_text(rate: f64) -> String {
    if rate >= 1e6 && (rate / 1e6).fract() == 0.0 {
        format!("{} Mbit/s", rate / 1e6)
    } else if rate >= 1e3 {
        format!("{} kbit/s", rate / 1e3)
    } else {
        format!("{rate} bit/s")
    }
}

/// The bit timing of `bit_rate` from `kernel_hz`, or why that clock cannot make the rate
/// exactly, naming the CiA 301 rates it can make and the nearest rates around the request.
pub fn can_bit_rate(kernel_hz: u32, bit_rate: f64) -> Result<CanBitTiming, Refusal> {
    let made: Vec<String> = CIA_BIT_RATES
        .iter()
        .filter(|&&r| can_bit_timing(kernel_hz, f64::from(r)).is_some())
        .map(|&r| bit_rate_text(f64::from(r)))
        .collect();
    // The image runs FDCAN1 as classic CAN (CCCR.FDOE left at its reset 0, RM0440 §44.4.6;
    // firmware/app/src/board/can.rs), whose nominal bit rate ends at 1 Mbit/s (ISO
    // 11898-1; CiA 301's table ends there): a faster rate would build, and no classic
    // node on the bus could follow it.
    if bit_rate > f64::from(CLASSIC_CAN_MAX_BIT_RATE) {
        return Err(Refusal {
            problem: format!(
                "{} is beyond classic CAN's nominal bit rate of at most 1 Mbit/s (ISO 11898-1): the image runs FDCAN1 in classic mode (FDCAN_CCCR.FDOE = 0, RM0440 §44.4.6), where a bit rate switch does not exist",
                bit_rate_text(bit_rate)
            ),
            accepted: format!(
                "a rate up to 1 Mbit/s this clock makes exactly: {} (CiA 301)",
                made.join(", ")
            ),
        });
    }
    if let Some(t) = can_bit_timing(kernel_hz, bit_rate) {
        return Ok(t);
    }
    // Exact rates near the request: kernel/(prescaler·quanta) that are whole bit/s.
    let mut near: Vec<u32> = Vec::new();
    for divisor in 1..=(CAN_MAX_PRESCALER * CAN_MAX_TQ_PER_BIT) {
        if !kernel_hz.is_multiple_of(divisor) {
            continue;
        }
        let r = kernel_hz / divisor;
        if can_bit_timing(kernel_hz, f64::from(r)).is_some() {
            near.push(r);
        }
    }
    let below = near.iter().copied().filter(|&r| f64::from(r) < bit_rate).max();
    let above = near.iter().copied().filter(|&r| f64::from(r) > bit_rate).min();
    let around: Vec<String> = [below, above]
        .into_iter()
        .flatten()
        .map(|r| bit_rate_text(f64::from(r)))
        .collect();
    let clocks = f64::from(kernel_hz) / bit_rate;
    Err(Refusal {
        problem: format!(
            "the FDCAN kernel clock ({} MHz, PCLK1) cannot make {} exactly: a bit is {clocks:.4} clock periods, not a whole prescaler (1 … {CAN_MAX_PRESCALER}) × quanta ({CAN_MIN_TQ_PER_BIT} … {CAN_MAX_TQ_PER_BIT}) (RM0440 §44.4.7); every node of a bus must run the same nominal rate",
            f64::from(kernel_hz) / 1e6,
            bit_rate_text(bit_rate)
        ),
        accepted: format!(
            "a rate this clock makes exactly: {} (CiA 301){}",
            made.join(", "),
            if around.is_empty() {
                String::new()
            } else {
                format!("; nearest to the request: {}", around.join(", "))
            }
        ),
    })
}

/// A board's setpoint identifier: the drive's frames take it and the `frames_after`
/// identifiers after it, none of which may be the fault report's [`FAULT_REPORT_ID`] (the
/// firmware's `fault_frame` asserts it), all within the 11-bit range.
pub fn setpoint_id(id: u16, frames_after: u16) -> Result<(), Refusal> {
    let last = id.saturating_add(frames_after);
    if (id..=last).contains(&FAULT_REPORT_ID) {
        let lo = FAULT_REPORT_ID.saturating_sub(frames_after);
        return Err(Refusal {
            problem: format!(
                "the drive's frames take {id:#05x} … {last:#05x} (setpoint, then status, command and capture frames), which includes the fault report's fixed identifier {FAULT_REPORT_ID:#05x} (sent once after a boot that found a fault record)"
            ),
            accepted: format!(
                "a setpoint identifier 0 … {:#05x} outside {lo:#05x} … {FAULT_REPORT_ID:#05x}, e.g. {:#05x} or {:#05x}",
                0x7FF - frames_after,
                lo - 1,
                FAULT_REPORT_ID + 1
            ),
        });
    }
    Ok(())
}

/// GPIO ports the firmware configures for the routed (alternate-function) pins: A, B, C
/// (`motor_config::registers::PORTS`; on the LQFP64 only PD2, PF0, PF1 and PG10 lie
/// beyond, and the firmware's clock enables, mode and fault-path writes cover A–C).
pub const ROUTED_PORTS: u8 = 3;

/// Where a firmware limit's value comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Home {
    /// A motor spec (`motors/*.toml`).
    Spec,
    /// A board file (`boards/*.toml`).
    Board,
}

/// One boundary case of a limit: a value at `key` that `check` accepts and one it refuses
/// (at that key), with the other edits the base file needs for this limit to be the one
/// that binds; the numbers are hand calculations, written in `why`.
#[derive(Debug, Clone, Copy)]
pub struct Case {
    /// The file the key is in.
    pub home: Home,
    /// The file's stem in `motors/` or `boards/` the case edits.
    pub base: &'static str,
    /// The dotted key.
    pub key: &'static str,
    /// A value (TOML) `check` accepts and the image builds with.
    pub accepted: &'static str,
    /// A value (TOML) `check` refuses at `key`.
    pub refused: &'static str,
    /// Further (key, value) edits of the same file, applied to both.
    pub also: &'static [(&'static str, &'static str)],
    /// (key, value) edits of the file `check` pairs it with (`Home::partner`, in `board`), where
    /// another limit would bind first there.
    pub partner: &'static [(&'static str, &'static str)],
    /// The hand calculation.
    pub why: &'static str,
}

/// One limit the firmware's build enforces, and the `check` rule that enforces it first.
#[derive(Debug, Clone, Copy)]
pub struct FirmwareLimit {
    /// The firmware's const-evaluation messages for it: the text of each `panic!` or
    /// `assert!`, or the asserted expression of an assertion without one.
    pub firmware_messages: &'static [&'static str],
    /// Where the firmware checks it.
    pub firmware_item: &'static str,
    /// What the limit is, with its source.
    pub limit: &'static str,
    /// The `check` rule: the function or module that enforces it and the keys it reports
    /// at; empty for an assertion no spec or board value reaches (two firmware facts that
    /// must agree).
    pub rule: &'static str,
    /// Boundary cases (see [`Case`]).
    pub cases: &'static [Case],
}

/// Every limit of the firmware's build, one row each.
pub const FIRMWARE_LIMITS: &[FirmwareLimit] = &[
    FirmwareLimit {
        firmware_messages: &["f_s cannot be generated by TIM1 from the timer clock"],
        firmware_item: "firmware/config/src/config.rs: PWM_PERIOD",
        limit: "centre-aligned TIM1 auto-reload f_TIM/(2·f_s) ≤ 65535 (16-bit ARR, RM0440 §28.3.3)",
        rule: "firmware::pwm_period, at drive.switching_frequency (the drive section)",
        cases: &[Case {
            home: Home::Spec,
            base: "unimotor-142umd300",
            key: "drive.switching_frequency",
            accepted: "\"1298 Hz\"",
            refused: "\"1297 Hz\"",
            also: &[
                ("motor.datasheet.max_speed", "\"1000 rpm\""),
                ("fir.pass_edge", "\"20 Hz\""),
                ("fir.stop_edge", "\"400 Hz\""),
            ],
            partner: &[],
            why: "ARR = 170e6/(2·f_s) + ½ truncated: 1298 Hz → 65485.9 → 65485 ≤ 65535; 1297 Hz → 65536.4 > 65535 (the limit is f_s = 170e6/(2·65534.5) = 1297.03 Hz); the Unimotor (5 pole pairs) at 1000 rpm has 12·f_e,max = 1000 Hz, so (1.1) does not bind, and its identification FIR's edges move below the Nyquist frequency (649 Hz)",
        }],
    },
    FirmwareLimit {
        firmware_messages: &["dead time longer than TIM1 can encode"],
        firmware_item: "firmware/config/src/config.rs: DEAD_TIME_DTG",
        limit: "TIM1_BDTR.DTG at most 1008 ticks of 170 MHz (RM0440 §28.6.20, CKD = 0)",
        rule: "firmware::dead_time, at pwm.dead_time (board) and drive.dead_time (spec); the image programs the longer",
        cases: &[
            Case {
                home: Home::Board,
                base: "motorgen-reference",
                key: "pwm.dead_time",
                accepted: "\"5929 ns\"",
                refused: "\"5930 ns\"",
                also: &[],
                partner: &[
                    ("drive.switching_frequency", "\"19 kHz\""),
                    ("motor.datasheet.max_speed", "\"10000 rpm\""),
                ],
                why: "⌈5929·0.17⌉ = ⌈1007.93⌉ = 1008 ticks ≤ 1008; ⌈5930·0.17⌉ = ⌈1008.1⌉ = 1009 > 1008; fischer-ti085 at 19 kHz (ARR 4474, d_max = 3466/4474 = 0.775) and 10 000 rpm, as at 20 kHz the duty limit (4250 − 1008)/4250 = 0.763 would leave less than half of U_dc/√3 first, and at 19 kHz 0.506 of it is too little for 20 000 rpm (design::duty_limit)",
            },
            Case {
                home: Home::Spec,
                base: "fischer-ti085",
                key: "drive.dead_time",
                accepted: "\"5.929 µs\"",
                refused: "\"6 µs\"",
                also: &[
                    ("drive.switching_frequency", "\"19 kHz\""),
                    ("motor.datasheet.max_speed", "\"10000 rpm\""),
                ],
                partner: &[],
                why: "5929 ns → 1008 ticks; 6000 ns → 1020 ticks > 1008; at 19 kHz (ARR 4474, d_max = 3466/4474 = 0.775) and 10 000 rpm, as at 20 kHz the duty limit 0.763 would leave less than half of U_dc/√3 first, and at 19 kHz 0.506 of it is too little for 20 000 rpm (design::duty_limit)",
            },
        ],
    },
    FirmwareLimit {
        firmware_messages: &["watchdog timeout out of range"],
        firmware_item: "firmware/config/src/config.rs: WATCHDOG",
        limit: "IWDG: prescaler /4 … /256, 12-bit reload 1 … 4095: 4 … 256·4095 LSI ticks (125 µs … 32.76 s at 32 kHz, RM0440 §42.3)",
        rule: "firmware::watchdog, at watchdog.timeout",
        cases: &[
            Case {
                home: Home::Board,
                base: "motorgen-reference",
                key: "watchdog.timeout",
                accepted: "\"32.76 s\"",
                refused: "\"32.77 s\"",
                also: &[],
                partner: &[],
                why: "32.76 s·32 kHz = 1 048 319.9 ticks (f32) → ⌈1 048 319/256⌉ = 4095 ≤ 4095; 32.77 s → 1 048 640 ticks → 4097 > 4095",
            },
            Case {
                home: Home::Board,
                base: "motorgen-reference",
                key: "watchdog.timeout",
                accepted: "\"125 µs\"",
                refused: "\"120 µs\"",
                also: &[],
                partner: &[],
                why: "125 µs·32 kHz = 4 ticks: prescaler /4, reload 1, the IWDG's shortest; 120 µs = 3.84 ticks, which the firmware's rounding would make 125 µs (longer than asked). The reference board's motors run T_s ≤ 50 µs, so 125 µs ≥ 2·T_s",
            },
        ],
    },
    FirmwareLimit {
        firmware_messages: &["the generated CAN bit timing does not make the board's bit rate from the FDCAN clock"],
        firmware_item: "firmware/app/src/board/can.rs: NBTP",
        limit: "FDCAN_NBTP: kernel clock = rate·prescaler (1 … 512)·quanta (8 … 385), TSEG1 ≤ 256, TSEG2 ≤ 128 (RM0440 §44.4.7)",
        rule: "firmware::can_bit_rate, at can.bit_rate (the board's NBTP is generated from it)",
        cases: &[
            Case {
                home: Home::Board,
                base: "motorgen-reference",
                key: "can.bit_rate",
                accepted: "\"1 Mbit/s\"",
                refused: "\"800 kbit/s\"",
                also: &[],
                partner: &[],
                why: "170 MHz/1 Mbit/s = 170 = 1·170 (prescaler 1, 170 quanta); 170 MHz/800 kbit/s = 212.5 clock periods: no whole prescaler·quanta",
            },
            Case {
                home: Home::Board,
                base: "motorgen-reference",
                key: "can.bit_rate",
                accepted: "\"125 kbit/s\"",
                refused: "\"83.333 kbit/s\"",
                also: &[],
                partner: &[],
                why: "170 MHz/125 kbit/s = 1360 = 5·272 (prescaler 5, 272 quanta); 170 MHz/83 333 bit/s = 2040.0082 periods",
            },
        ],
    },
    FirmwareLimit {
        firmware_messages: &["the fault report's identifier (can::FAULT_REPORT_ID) collides with a drive frame's"],
        firmware_item: "firmware/config/src/fault_frame.rs: const assertion",
        limit: "the setpoint identifier and the 5 after it must not include the fault report's 0x0E0",
        rule: "firmware::setpoint_id, at can.setpoint_id (board parsing)",
        cases: &[
            Case {
                home: Home::Board,
                base: "motorgen-reference",
                key: "can.setpoint_id",
                accepted: "0x0DA",
                refused: "0x0DB",
                also: &[],
                partner: &[],
                why: "0x0DA … 0x0DF leaves 0x0E0 free; 0x0DB + 5 = 0x0E0",
            },
            Case {
                home: Home::Board,
                base: "motorgen-reference",
                key: "can.setpoint_id",
                accepted: "0x0E1",
                refused: "0x0E0",
                also: &[],
                partner: &[],
                why: "0x0E1 is above the fault report; 0x0E0 is the fault report",
            },
        ],
    },
    FirmwareLimit {
        firmware_messages: &["a board pin outside GPIOA..C or an AF above 15"],
        firmware_item: "firmware/config/src/config.rs: PORTS_CONFIG",
        limit: "routed pins (gates, break, excitation, CAN) on GPIOA … GPIOC, AF 0 … 15 (RM0440 §9.4.9, GPIOx_AFRL/AFRH)",
        rule: "board parsing: every digital signal on port A, B or C (firmware::ROUTED_PORTS); the AF comes from the chip's pin table (0 … 15)",
        cases: &[Case {
            home: Home::Board,
            base: "motorgen-reference",
            key: "pins.gate_w_low",
            accepted: "\"PB1\"",
            refused: "\"PF0\"",
            also: &[],
            partner: &[],
            why: "TIM1_CH3N is PB1 (AF6), PB15 (AF4) or PF0 (AF6) on the STM32G474RE (DS12288 Table 13); PF0 is on port F",
        }],
    },
    FirmwareLimit {
        firmware_messages: &["an ADC sequence the JSQR cannot hold"],
        firmware_item: "firmware/config/src/config.rs: JSQR",
        limit: "1 … 4 injected ranks per converter, channels 0 … 18 (RM0440 §21.7.16, ADC_JSQR)",
        rule: "board parsing (board::sequence::plan): at most four inputs per converter, at the first analog pin (`pins.resolver_sin`)",
        cases: &[Case {
            home: Home::Board,
            base: "motorgen-reference",
            key: "pins.resolver_sin",
            accepted: "\"PA1\"",
            refused: "\"PB12\"",
            also: &[
                ("pins.current_u", "\"PA2\""),
                ("pins.current_v", "\"PA3\""),
                ("pins.current_w", "\"PB14\""),
                ("pins.dc_link", "\"PB1\""),
                ("pins.gate_v_low", "\"PA12\""),
                ("pins.break_input", "\"PA6\""),
            ],
            partner: &[],
            why: "PA2 (ADC1_IN3), PA3 (ADC1_IN4), PB14 (ADC1_IN5), PB1 (ADC1_IN12) and PB12 (ADC1_IN11) are inputs of ADC1 only (DS12288 Table 13): SIN on PB12 makes five ranks on ADC1 > 4; on PA1 (ADC12_IN2) it goes to ADC2 with COS (PA7, ADC2_IN4); TIM1_CH2N and BKIN move to PA12 (AF6) and PA6 (AF6) to free PB14 and PB12",
        }],
    },
    FirmwareLimit {
        firmware_messages: &["FIR too long for the FMAC memory", "the FMAC supports 1 to 127 taps"],
        firmware_item: "firmware/app/src/board/fmac.rs: the FMAC's load; firmware/control/src/fir.rs: FmacFir::new, process",
        limit: "FMAC: an N-tap FIR needs 2N + 1 of the 256 words, so at most 127 taps (RM0440 §18.3.8); the image's layout takes 2N + 2d words, d = 2 or, at 127 taps, 1",
        rule: "design::fir (the FIR's validation), at fir.order / fir.stop_attenuation",
        cases: &[Case {
            home: Home::Spec,
            base: "fischer-ti085",
            key: "fir.order",
            accepted: "126",
            refused: "127",
            also: &[("fir.stop_edge", "\"300 Hz\"")],
            partner: &[],
            why: "order 126 = 127 taps ≤ 127; order 127 = 128 taps (a 100–300 Hz transition at 20 kHz, where Kaiser's estimate for order 126 is 14.6·0.01·126 + 13 = 31 dB, far inside what the design resolves)",
        }],
    },
    FirmwareLimit {
        firmware_messages: &["board::ADC_CLOCK_HZ == hw::ADC_CLOCK_HZ"],
        firmware_item: "firmware/config/src/config.rs: const assertion",
        limit: "the ADC clock the board's sampling codes were chosen for is the firmware's",
        rule: "",
        cases: &[],
    },
    FirmwareLimit {
        firmware_messages: &["HSI_HZ / PLL_M * PLL_N / PLL_R == SYSCLK_HZ"],
        firmware_item: "firmware/config/src/hw.rs: const assertion",
        limit: "the PLL settings make the SYSCLK the firmware states",
        rule: "",
        cases: &[],
    },
    FirmwareLimit {
        firmware_messages: &["the generated clocks are the firmware's (board::TIMER_CLOCK_HZ, FDCAN_CLOCK_HZ, LSI_HZ)"],
        firmware_item: "firmware/config/src/config.rs: const assertion",
        limit: "the clocks `check`'s rules computed with are the ones the image runs",
        rule: "",
        cases: &[],
    },
];

#[cfg(test)]
mod tests {
    use super::*;

    /// 170 MHz/(2·20 kHz) = 4250 (thesis A's f_s); 1297 Hz → 65 536.4 > 65 535.
    #[test]
    fn pwm_period_by_hand() {
        assert_eq!(pwm_period(20e3), Ok(4250));
        let e = pwm_period(1297.0).unwrap_err();
        assert!(e.accepted.contains("1297.03 Hz"), "{e:?}");
        assert!(pwm_period(1297.03).is_ok());
    }

    /// The dead time of the reference board, 500 ns = 85 ticks; 5930 ns → 1009 ticks.
    #[test]
    fn dead_time_by_hand() {
        assert_eq!(dead_time(500e-9), Ok(85));
        assert_eq!(dead_time_ns(500e-9), 500);
        let e = dead_time(5.93e-6).unwrap_err();
        assert!(e.accepted.contains("5929 ns"), "{e:?}");
    }

    /// 5 ms at 32 kHz = 160 ticks → /4, 40; 40 s is beyond 32.76 s; 125 µs = 4 ticks → /4,
    /// 1, the shortest; 100 µs = 3.2 ticks is shorter than the IWDG makes.
    #[test]
    fn watchdog_by_hand() {
        assert_eq!(watchdog(5e-3), Ok((0, 40)));
        assert!((max_watchdog_timeout_s() - 32.76).abs() < 1e-9);
        assert!(watchdog(40.0).unwrap_err().accepted.contains("32.76 s"));
        assert_eq!(watchdog(125e-6), Ok((0, 1)));
        let e = watchdog(100e-6).unwrap_err();
        assert!(
            e.problem.contains("3.20 ticks") && e.accepted.contains("from 125 µs"),
            "{e:?}"
        );
    }

    /// Hand calculations at 170 MHz, aiming at 87.5 %:
    /// * 500 kbit/s: 340 clocks per bit; prescaler 1 (340 quanta) needs TSEG1 = 297 > 256;
    ///   prescaler 2, 170 quanta: 1 + TSEG1 = round(148.75) = 149 → 87.647 % (error
    ///   0.147 %, the best: 85 quanta 87.06 %, 34 quanta 88.24 %), TSEG1 = 148, TSEG2 = 21,
    ///   SJW = 21 → NBTP = (20 << 25) | (1 << 16) | (147 << 8) | 20 = 0x2801_9314;
    /// * 1 Mbit/s: 170 clocks; prescaler 1, 170 quanta, the same segments → 0x2800_9314;
    /// * 125 kbit/s: 1360 clocks; prescaler 4 (340 quanta) needs TSEG1 = 297 > 256;
    ///   prescaler 5, 272 quanta: 1 + TSEG1 = 0.875·272 = 238 exactly, TSEG1 = 237,
    ///   TSEG2 = SJW = 34 → (33 << 25) | (4 << 16) | (236 << 8) | 33 = 0x4204_EC21;
    /// * 800 kbit/s: 212.5 clocks: none.
    #[test]
    fn can_bit_timing_by_hand() {
        let t = can_bit_timing(170_000_000, 500e3).unwrap();
        assert_eq!(
            (t.prescaler, t.tq_per_bit, t.tseg1, t.tseg2, t.sjw),
            (2, 170, 148, 21, 21)
        );
        assert!((t.sample_point - 149.0 / 170.0).abs() < 1e-12);
        assert_eq!(t.nbtp, 0x2801_9314);
        assert_eq!(can_bit_timing(170_000_000, 1e6).map(|t| t.nbtp), Some(0x2800_9314));
        assert_eq!(can_bit_timing(170_000_000, 125e3).map(|t| t.nbtp), Some(0x4204_EC21));
        assert_eq!(can_bit_timing(170_000_000, 800e3), None);
        assert_eq!(can_bit_timing(170_000_000, 83_333.0), None);
        assert_eq!(can_bit_timing(170_000_000, 500.5e3), None);
        // A kernel clock is an input: an 8 MHz HSE makes 500 kbit/s with 16 quanta
        // (prescaler 1): 1 + TSEG1 = 14 → 87.5 % exactly.
        // A board with a crystal times FDCAN from it, one without from PCLK1; the
        // NUCLEO-G474RE's 24 MHz at 500 kbit/s: 48 quanta, 1 + 41 + 6 → 87.5 %, NBTP
        // 0x0A00_2805 (NSJW 5, NBRP 0, NTSEG1 40, NTSEG2 5).
        assert_eq!(fdcan_kernel_clock_hz(None), 170_000_000);
        assert_eq!(fdcan_kernel_clock_hz(Some(24e6)), 24_000_000);
        let nucleo = can_bit_timing(24_000_000, 500e3).unwrap();
        assert_eq!(
            (nucleo.prescaler, nucleo.tq_per_bit, nucleo.tseg1, nucleo.tseg2),
            (1, 48, 41, 6)
        );
        assert_eq!(nucleo.nbtp, 0x0A00_2805);
        let hse = can_bit_timing(8_000_000, 500e3).unwrap();
        assert_eq!((hse.prescaler, hse.tq_per_bit, hse.tseg1, hse.tseg2), (1, 16, 13, 2));
        assert!((hse.sample_point - 0.875).abs() < 1e-12);
    }

    /// Every CiA 301 rate but 800 kbit/s divides 170 MHz; the refusal names them.
    #[test]
    fn can_refusal_names_the_rates_the_clock_makes() {
        let e = can_bit_rate(170_000_000, 800e3).unwrap_err();
        assert!(
            e.accepted
                .starts_with("a rate this clock makes exactly: 10 kbit/s, 20 kbit/s, 50 kbit/s, 100 kbit/s, 125 kbit/s, 250 kbit/s, 500 kbit/s, 1 Mbit/s (CiA 301)"),
            "{e:?}"
        );
        assert!(e.problem.contains("212.5000 clock periods"), "{e:?}");
    }

    /// 0x0DB + 5 = 0x0E0 collides; 0x0DA and 0x0E1 do not.
    #[test]
    fn setpoint_identifier_keeps_off_the_fault_report() {
        assert!(setpoint_id(0x0DA, 5).is_ok());
        assert!(setpoint_id(0x0DB, 5).is_err());
        assert!(setpoint_id(0x0E0, 5).is_err());
        assert!(setpoint_id(0x0E1, 5).is_ok());
        assert!(setpoint_id(0x100, 5).is_ok());
    }
}
