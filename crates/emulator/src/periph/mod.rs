//! Register models of the STM32G474 peripherals the image touches, one module per
//! block; the bus ([`crate::soc`]) routes accesses, clock gates and the signals between
//! them (TIM1 → ADC trigger, TIM1 → TIM3 reset, pins → break, ADC → NVIC).

/// Bus time unit: 1/8 of a 170 MHz cycle, so 16, 85 and 170 MHz cycles are whole
/// numbers of units (85, 16 and 8). The peripherals count in it; the bus
/// ([`crate::soc`]) advances it.
pub const UNITS_PER_S: f64 = 1.36e9;

/// A measurement's (min, max, count) with `x` added.
pub fn spread<T: PartialOrd + Copy>(stat: Option<(T, T, u64)>, x: T) -> Option<(T, T, u64)> {
    Some(match stat {
        None => (x, x, 1),
        Some((lo, hi, n)) => (if x < lo { x } else { lo }, if x > hi { x } else { hi }, n + 1),
    })
}

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
