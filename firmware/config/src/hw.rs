//! Hardware facts of the STM32G474 and of the board's front end: the only place in
//! the firmware where numbers that are not generated from the motor spec live
//! (`tests/literals.rs` enforces this). None of them is a motor or tuning parameter.
//!
//! Sources: RM0440 (STM32G4 reference manual), DS12288 (STM32G474 datasheet) and
//! the board assumptions listed in `firmware/README.md` ("Board assumptions").

/// SYSCLK = HCLK = PCLK1 = PCLK2 \[Hz\]: HSI16 → PLL ×85/8 (M = 4, N = 85, R = 2),
/// the STM32G474's maximum in range-1 boost mode (DS12288 §3.9).
pub const SYSCLK_HZ: u32 = 170_000_000;
/// TIM1 kernel clock \[Hz\]: PCLK2 with APB2 prescaler 1 (RM0440 §7.2.17: ×1).
pub const TIMER_CLOCK_HZ: u32 = SYSCLK_HZ;
/// ADC clock \[Hz\]: synchronous HCLK/4 (ADC12_CCR.CKMODE = 0b11), within the
/// 60 MHz limit of DS12288 Table 66.
pub const ADC_CLOCK_HZ: u32 = SYSCLK_HZ / 4;
/// ADC resolution \[bit\] (ADC_CFGR.RES = 0).
pub const ADC_BITS: u32 = 12;
/// LSI clock of the independent watchdog \[Hz\] (DS12288 Table 56, typical).
pub const LSI_HZ: u32 = 32_000;
/// FDCAN kernel clock \[Hz\]: PCLK1 (RCC_CCIPR.FDCANSEL = 0b10).
pub const FDCAN_CLOCK_HZ: u32 = SYSCLK_HZ;

/// Board front end: sample-and-hold capacitance C_ADC \[pF\] (DS12288 Table 66).
pub const ADC_SAMPLE_CAPACITANCE_PF: u32 = 5;
/// Board front end: ADC switch resistance plus the driving op-amp's output and
/// anti-aliasing series resistance R_ADC + R_EXT (7.2) \[Ω\] (board assumption).
pub const ADC_SOURCE_RESISTANCE_OHM: u32 = 1_100;
/// Inverter dead time \[ns\] used when the spec gives no `[drive] dead_time`: the
/// gate driver's switching-time margin (board assumption, thesis A §3.2).
pub const INVERTER_DEAD_TIME_NS: u32 = 500;

/// FDCAN standard identifier of the torque-setpoint frame (vehicle unit → inverter).
pub const SETPOINT_CAN_ID: u16 = 0x100;
/// The vehicle unit sends a setpoint every 10 ms \[ms\].
pub const SETPOINT_PERIOD_MS: u32 = 10;
/// Missed setpoint periods after which the torque ramps to zero.
pub const SETPOINT_TIMEOUT_PERIODS: u32 = 3;
/// Time a missing setpoint takes to ramp the largest torque (peak current) to zero
/// \[ms\]: the ramp rate is PEAK_CURRENT_A/this (board policy, not a motor number).
pub const SETPOINT_RAMP_MS: u32 = 100;

/// Independent watchdog timeout in control periods: the main loop refreshes it only
/// while the control interrupt runs, so a stalled interrupt resets the MCU within
/// this many periods (plus one refresh period of the main loop).
pub const WATCHDOG_CONTROL_PERIODS: u32 = 100;
/// Torque resolution of the setpoint frame \[mN·m per LSB\]: bytes 0–1 hold a
/// little-endian `i16`, so ±327.67 N·m in 0.01 N·m steps.
pub const SETPOINT_TORQUE_MNM_PER_LSB: u32 = 10;

/// PLL input divider M (HSI16/4 = 4 MHz, within RM0440's 2.66–8 MHz).
pub const PLL_M: u32 = 4;
/// PLL multiplier N (VCO 4 MHz·85 = 340 MHz, within 96–344 MHz).
pub const PLL_N: u32 = 85;
/// PLL output divider R (340/2 = 170 MHz = SYSCLK).
pub const PLL_R: u32 = 2;
/// HSI16 oscillator \[Hz\].
pub const HSI_HZ: u32 = 16_000_000;
const _: () = assert!(HSI_HZ / PLL_M * PLL_N / PLL_R == SYSCLK_HZ);
/// Flash wait states at 170 MHz in range-1 boost mode (RM0440 Table 9).
pub const FLASH_WAIT_STATES: u8 = 4;
/// ADC voltage-regulator start-up time t_ADCVREG_STUP \[µs\] (DS12288 Table 66).
pub const ADC_VREG_STARTUP_US: u32 = 20;
/// Microseconds per second.
pub const US_PER_S: u32 = 1_000_000;

/// FDCAN nominal bit rate \[bit/s\] of the vehicle bus.
pub const CAN_BITRATE: u32 = 500_000;
/// Time quanta per CAN bit: 1 (sync) + 15 (TSEG1) + 4 (TSEG2), sample point 80 %.
pub const CAN_TQ_PER_BIT: u32 = 20;
/// TSEG2 and the resynchronisation jump width \[tq\].
pub const CAN_TSEG2: u32 = 4;
/// FDCAN1 message RAM (SRAMCAN) base address (RM0440 §44.3.3).
pub const FDCAN1_RAM: usize = 0x4000_A400;
/// Offset of RX FIFO 0 in the message RAM \[bytes\] (fixed layout, RM0440 §44.3.3).
pub const FDCAN_RXF0_OFFSET: usize = 0xB0;
/// Size of one RX FIFO element \[bytes\]: 18 words (header + 64 data bytes).
pub const FDCAN_RX_ELEMENT_BYTES: usize = 72;

/// TIM1 break-input digital filter BKF: f_DTS, N = 8 samples (RM0440 §28.6.20,
/// code 0b0011 = f_CK_INT, N = 8): ignores glitches shorter than 47 ns.
pub const BREAK_FILTER: u8 = 0b0011;
/// Polls of ADC2's end-of-sequence flag after ADC1's (they finish together; a few
/// polls cover bus timing).
pub const ADC_SLAVE_POLLS: u32 = 16;
/// CORDIC start-up check tolerance against the software reference \[LSB of Q1.31\]:
/// 2^13 ≈ 3.8·10⁻⁶, above the 24-iteration residual error (order 2^-19 = 2^12 LSB).
pub const CORDIC_TOLERANCE_LSB: u32 = 1 << 13;
