//! Register models of the STM32G474 peripherals the image touches, one module per
//! block; the bus ([`crate::soc`]) routes accesses, clock gates and the signals between
//! them (TIM1 → ADC trigger, TIM1 → TIM3 reset, pins → break, ADC → NVIC).

pub mod adc;
pub mod clock;
pub mod fdcan;
pub mod gpio;
pub mod math;
pub mod system;
pub mod tim1;
pub mod tim3;

/// Dead time in timer ticks of a BDTR.DTG code (RM0440 §28.6.20, DTG\[7:5\]: `0xx` DTG,
/// `10x` (64 + DTG\[5:0\])·2, `110` (32 + DTG\[4:0\])·8, `111` (32 + DTG\[4:0\])·16), with
/// t_DTS = t_CK_INT (CKD = 0).
pub fn dead_time_ticks(dtg: u8) -> u32 {
    let d = u32::from(dtg);
    match d >> 5 {
        0..=3 => d,
        4 | 5 => (64 + (d & 0x3F)) * 2,
        6 => (32 + (d & 0x1F)) * 8,
        _ => (32 + (d & 0x1F)) * 16,
    }
}
