//! Register encodings computed from times and frequencies (pure, host-tested):
//! TIM1 dead time, watchdog prescaler and reload (the TIM1 period is the control core's
//! `motor_control::modulation::centre_aligned_period`).
#![forbid(unsafe_code)]

/// Nanoseconds per second.
const NS_PER_S: u64 = 1_000_000_000;

/// Dead-time length in `t_DTS` ticks of a TIMx_BDTR.DTG code (RM0440 §28.6.20):
/// `0xx`: DTG; `10x`: (64 + DTG\[5:0\])·2; `110`: (32 + DTG\[4:0\])·8;
/// `111`: (32 + DTG\[4:0\])·16.
pub const fn dtg_ticks(dtg: u8) -> u32 {
    let d = dtg as u32;
    if d & 0x80 == 0 {
        d
    } else if d & 0xC0 == 0x80 {
        (64 + (d & 0x3F)) * 2
    } else if d & 0xE0 == 0xC0 {
        (32 + (d & 0x1F)) * 8
    } else {
        (32 + (d & 0x1F)) * 16
    }
}

/// The DTG code of the shortest dead time that is at least `dead_ns` with
/// `t_DTS = 1/timer_hz` (CKD = 0): never shorter than requested, so shoot-through
/// protection is kept. `None` beyond the longest encodable 1008 ticks.
pub const fn dead_time_dtg(dead_ns: u32, timer_hz: u32) -> Option<u8> {
    // Ticks, rounded up.
    let ticks = (dead_ns as u64 * timer_hz as u64).div_ceil(NS_PER_S);
    if ticks <= 127 {
        Some(ticks as u8)
    } else if ticks <= 254 {
        Some(0x80 | (ticks.div_ceil(2) - 64) as u8)
    } else if ticks <= 504 {
        Some(0xC0 | (ticks.div_ceil(8) - 32) as u8)
    } else if ticks <= 1008 {
        Some(0xE0 | (ticks.div_ceil(16) - 32) as u8)
    } else {
        None
    }
}

/// IWDG prescaler code PR (divider 4·2^PR, PR ≤ 6) and reload RLR (≤ 4095) for a
/// timeout of at least `lsi_ticks` LSI periods (RM0440 §41.3): the smallest divider
/// that fits, reload rounded up. `None` if the timeout exceeds 256·4096 ticks.
pub const fn iwdg_setting(lsi_ticks: u32) -> Option<(u8, u16)> {
    let mut pr = 0;
    while pr <= 6 {
        let div = 4u32 << pr;
        let reload = lsi_ticks.div_ceil(div);
        if reload <= 0x0FFF {
            let reload = if reload == 0 { 1 } else { reload };
            return Some((pr as u8, reload as u16));
        }
        pr += 1;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Hand calculations at 170 MHz (5.88 ns per tick):
    /// 500 ns = 85 ticks → DTG 85; 1 µs = 170 ticks → (64 + 21)·2 = 170 → 0x95;
    /// 2 µs = 340 ticks → ⌈340/8⌉ = 43 = 32 + 11 → 0xCB (344 ticks);
    /// 3 µs = 510 ticks → ⌈510/16⌉ = 32 → 0xE0 (512 ticks); 6 µs = 1020 > 1008 → None.
    #[test]
    fn dead_time_encoding() {
        assert_eq!(dead_time_dtg(500, 170_000_000), Some(85));
        assert_eq!(dead_time_dtg(1_000, 170_000_000), Some(0x95));
        assert_eq!(dtg_ticks(0x95), 170);
        assert_eq!(dead_time_dtg(2_000, 170_000_000), Some(0xCB));
        assert_eq!(dtg_ticks(0xCB), 344);
        assert_eq!(dead_time_dtg(3_000, 170_000_000), Some(0xE0));
        assert_eq!(dtg_ticks(0xE0), 512);
        assert_eq!(dead_time_dtg(6_000, 170_000_000), None);
        assert_eq!(dtg_ticks(0xFF), 1008);
    }

    /// Property over every tick count: the chosen code is never shorter than asked,
    /// and no code gives a shorter dead time that is still long enough.
    #[test]
    fn dead_time_is_minimal_and_safe() {
        let all: Vec<u32> = (0..=255u8).map(dtg_ticks).collect();
        for ticks in 0..=1008u32 {
            // 1 GHz: one tick per ns.
            let code = dead_time_dtg(ticks, 1_000_000_000).expect("encodable");
            let got = dtg_ticks(code);
            assert!(got >= ticks);
            assert!(!all.iter().any(|&t| t >= ticks && t < got), "{ticks}: {got}");
        }
    }

    /// Hand calculations: 160 LSI ticks (5 ms at 32 kHz) → /4, reload 40;
    /// 100 000 ticks → /32 (PR 3), reload 3125; 2 000 000 ticks > 256·4095 → None.
    #[test]
    fn watchdog_setting() {
        assert_eq!(iwdg_setting(160), Some((0, 40)));
        assert_eq!(iwdg_setting(100_000), Some((3, 3125)));
        assert_eq!(iwdg_setting(2_000_000), None);
        assert_eq!(iwdg_setting(0), Some((0, 1)));
    }
}
