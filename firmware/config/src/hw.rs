//! Facts of the STM32G474 and choices of this firmware (clock tree, filter
//! codes): the only place in the firmware where numbers that are not generated from the
//! motor spec or the board file live (`tests/literals.rs` enforces this). None of them is
//! a motor, tuning or board parameter — those are in `motor::board`, generated from
//! `boards/<BOARD>.toml`.
//!
//! Sources: RM0440 (STM32G4 reference manual), DS12288 (STM32G474 datasheet).

/// SYSCLK = HCLK = PCLK1 = PCLK2 \[Hz\]: HSI16 → PLL ×85/8 (M = 4, N = 85, R = 2),
/// the STM32G474's maximum in range-1 boost mode (DS12288 §3.9).
pub const SYSCLK_HZ: u32 = 170_000_000;
/// TIM1 kernel clock \[Hz\]: PCLK2 with APB2 prescaler 1 (RM0440 §7.2.17: ×1).
pub const TIMER_CLOCK_HZ: u32 = SYSCLK_HZ;
/// ADC clock \[Hz\]: synchronous HCLK/4 (ADC12_CCR.CKMODE = 0b11), within the 52 MHz
/// of DS12288 Table 66 for several ADCs at V_DDA ≥ 2.7 V. The board's sampling codes are
/// chosen for it (`motor::board::ADC_CLOCK_HZ`, checked equal at compile time).
pub const ADC_CLOCK_HZ: u32 = SYSCLK_HZ / 4;
/// ADC resolution \[bit\] (ADC_CFGR.RES = 0).
pub const ADC_BITS: u32 = 12;
/// LSI clock of the independent watchdog \[Hz\] (DS12288 Table 56, typical).
pub const LSI_HZ: u32 = 32_000;
/// FDCAN kernel clock \[Hz\]: the board's HSE crystal where it has one (RCC_CCIPR.FDCANSEL
/// = 0b00, RM0440 §7.4.26) — a crystal's tens of ppm against HSI16's percent-level
/// accuracy over temperature (DS12288, HSI16 oscillator characteristics), which takes
/// most of what CAN's bit timing tolerates at the 87.5 % sample point (ISO 11898-1's
/// oscillator tolerance: min(SJW/(20·NBT), min(TSEG1, TSEG2)/(2·(13·NBT − TSEG2))) ≈
/// 0.5 % for 500 kbit/s from 24 MHz, 48 quanta, TSEG2 = SJW = 6) — else PCLK1 (0b10; the
/// PLL from HSI16). The generated `board::CAN_NBTP`
/// is computed from the same choice (`board::FDCAN_CLOCK_HZ`, checked equal at compile
/// time).
pub const FDCAN_CLOCK_HZ: u32 = if FDCAN_FROM_HSE {
    crate::motor::board::HSE_HZ
} else {
    SYSCLK_HZ
};
/// FDCAN timed from the board's HSE crystal (`motor::board::HSE_HZ` ≠ 0).
pub const FDCAN_FROM_HSE: bool = crate::motor::board::HSE_HZ != 0;
/// RCC_CCIPR.FDCANSEL: 0b00 HSE, 0b10 PCLK1 (RM0440 §7.4.26).
pub const FDCANSEL: u8 = if FDCAN_FROM_HSE { 0b00 } else { 0b10 };

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

/// FDCAN1 message RAM (SRAMCAN) base address (RM0440 §44.3.3).
pub const FDCAN1_RAM: usize = 0x4000_A400;
/// Offset of RX FIFO 0 in the message RAM \[bytes\] (fixed layout, RM0440 §44.3.3).
pub const FDCAN_RXF0_OFFSET: usize = 0xB0;
/// Size of one RX FIFO element \[bytes\]: 18 words (header + 64 data bytes).
pub const FDCAN_RX_ELEMENT_BYTES: usize = 72;
/// Offset of the Tx buffers in the message RAM \[bytes\]: after the 28 standard and 8
/// extended filter elements, RX FIFO 0 and 1 (3 × 18 words each) and the 3 Tx event
/// FIFO elements (2 words each): 0xB0 + 2·216 + 24 = 0x278 (RM0440 §44.3.3, Figure 589).
pub const FDCAN_TXBUF_OFFSET: usize = 0x278;
/// Size of one Tx buffer element \[bytes\]: 18 words, as the Rx elements.
pub const FDCAN_TX_ELEMENT_BYTES: usize = 72;
/// Standard identifier of the fault-report frame sent once after a boot that found a
/// fault record (`fault_frame`): the generated `can::FAULT_REPORT_ID` (described in the
/// DBC file with the other frames), checked at compile time to differ from the drive's
/// other identifiers.
pub const FAULT_REPORT_ID: u16 = crate::motor::can::FAULT_REPORT_ID;

/// TIM1 break-input digital filter BKF: f_DTS, N = 8 samples (RM0440 §28.6.20,
/// code 0b0011 = f_CK_INT, N = 8): ignores glitches shorter than 47 ns.
pub const BREAK_FILTER: u8 = 0b0011;
/// Polls of ADC2's end-of-sequence flag after ADC1's (they finish together; a few
/// polls cover bus timing).
pub const ADC_SLAVE_POLLS: u32 = 16;
/// CORDIC start-up check tolerance against the software reference \[LSB of Q1.31\]:
/// 2^13 ≈ 3.8·10⁻⁶, above the 24-iteration residual error (order 2^-19 = 2^12 LSB).
pub const CORDIC_TOLERANCE_LSB: u32 = 1 << 13;

/// Control periods from the carrier phase of a step to the current the sensorless
/// estimator demodulates with it: the voltage acts 1.5 periods after the sample it was
/// computed from (thesis A §4.6) and the estimator reads the previous period's current,
/// one more. A property of this firmware's timing, not of the motor.
pub const CARRIER_DELAY_PERIODS: f32 = 2.5;
