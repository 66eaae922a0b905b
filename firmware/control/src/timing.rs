//! Register codes computed from times (pure, `const`): TIM1's dead-time generator and the
//! independent watchdog's prescaler and reload.
//!
//! Two callers use these same functions: the firmware (`motor-config` computes its
//! TIM1_BDTR.DTG and IWDG_PR/RLR with them at compile time, a build error where they return
//! `None`) and the code generator (`motorgen check` refuses, at the board or spec key, a
//! dead time or a watchdog timeout they cannot encode). So a value `check` accepts is a
//! value the image's build encodes, and the limit is written once.

/// Nanoseconds per second.
const NS_PER_S: u64 = 1_000_000_000;

/// Longest dead time TIMx_BDTR.DTG encodes, in t_DTS ticks: `111` + DTG\[4:0\] = 31 gives
/// (32 + 31)·16 = 1008 (RM0440 §28.6.20, TIMx_BDTR DTG\[7:0\]).
pub const DTG_MAX_TICKS: u32 = 1008;

/// Dead-time length in `t_DTS` ticks of a TIMx_BDTR.DTG code (RM0440 §28.6.20):
/// `0xx`: DTG; `10x`: (64 + DTG\[5:0\])·2; `110`: (32 + DTG\[4:0\])·8;
/// `111`: (32 + DTG\[4:0\])·16.
pub const fn dtg_ticks(dtg: u8) -> u32 {
    let d = dtg as u32;
    if d & 0x80 == 0 {
        d
    } else if d & 0xC0 == 0x80 {
        (d & 0x3F).saturating_add(64).saturating_mul(2)
    } else if d & 0xE0 == 0xC0 {
        (d & 0x1F).saturating_add(32).saturating_mul(8)
    } else {
        (d & 0x1F).saturating_add(32).saturating_mul(16)
    }
}

/// The DTG code of the shortest dead time that is at least `dead_ns` with
/// `t_DTS = 1/timer_hz` (CKD = 0): never shorter than requested, so shoot-through
/// protection is kept. `None` beyond the longest encodable [`DTG_MAX_TICKS`] ticks
/// (5929 ns at 170 MHz).
pub const fn dead_time_dtg(dead_ns: u32, timer_hz: u32) -> Option<u8> {
    // Ticks, rounded up (a product of two u32 always fits a u64).
    let ticks = (dead_ns as u64).saturating_mul(timer_hz as u64).div_ceil(NS_PER_S);
    if ticks <= 127 {
        Some(ticks as u8)
    } else if ticks <= 254 {
        Some(0x80 | (ticks.div_ceil(2).saturating_sub(64)) as u8)
    } else if ticks <= 504 {
        Some(0xC0 | (ticks.div_ceil(8).saturating_sub(32)) as u8)
    } else if ticks <= DTG_MAX_TICKS as u64 {
        Some(0xE0 | (ticks.div_ceil(16).saturating_sub(32)) as u8)
    } else {
        None
    }
}

/// Largest IWDG_RLR reload (12 bits, RM0440 §42.4.3).
pub const IWDG_MAX_RELOAD: u32 = 0x0FFF;
/// Largest IWDG_PR prescaler code this firmware uses: 6, divider 4·2⁶ = 256 (RM0440
/// §42.4.2; code 7 divides by 256 as well).
pub const IWDG_MAX_PRESCALER: u32 = 6;

/// IWDG prescaler code PR (divider 4·2^PR, PR ≤ [`IWDG_MAX_PRESCALER`]) and reload RLR
/// (≤ [`IWDG_MAX_RELOAD`]) for a timeout of at least `lsi_ticks` LSI periods (RM0440
/// §42.3): the smallest divider that fits, reload rounded up. `None` if the timeout
/// exceeds 256·4095 ticks.
pub const fn iwdg_setting(lsi_ticks: u32) -> Option<(u8, u16)> {
    let mut pr = 0;
    while pr <= IWDG_MAX_PRESCALER {
        let div = 4u32 << pr;
        let reload = lsi_ticks.div_ceil(div);
        if reload <= IWDG_MAX_RELOAD {
            let reload = if reload == 0 { 1 } else { reload };
            return Some((pr as u8, reload as u16));
        }
        pr = pr.saturating_add(1);
    }
    None
}

/// [`iwdg_setting`] for a timeout of `timeout_s` seconds of an `lsi_hz` LSI clock: the
/// tick count `timeout_s·f_LSI` in `f32`, truncated (as the firmware's generated
/// `f32` timeout gives it), then the setting.
pub const fn iwdg_for_timeout(timeout_s: f32, lsi_hz: u32) -> Option<(u8, u16)> {
    iwdg_setting((timeout_s * lsi_hz as f32) as u32)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Hand calculations at 170 MHz (5.88 ns per tick):
    /// 500 ns = 85 ticks → DTG 85; 1 µs = 170 ticks → (64 + 21)·2 = 170 → 0x95;
    /// 2 µs = 340 ticks → ⌈340/8⌉ = 43 = 32 + 11 → 0xCB (344 ticks);
    /// 3 µs = 510 ticks → ⌈510/16⌉ = 32 → 0xE0 (512 ticks); 6 µs = 1020 > 1008 → None;
    /// 5929 ns = 1007.93 → 1008 ticks → 0xFF; 5930 ns = 1008.1 → 1009 → None.
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
        assert_eq!(dead_time_dtg(5_929, 170_000_000), Some(0xFF));
        assert_eq!(dead_time_dtg(5_930, 170_000_000), None);
    }

    /// Property over every tick count: the chosen code is never shorter than asked,
    /// and no code gives a shorter dead time that is still long enough.
    #[test]
    fn dead_time_is_minimal_and_safe() {
        let all: Vec<u32> = (0..=255u8).map(dtg_ticks).collect();
        assert_eq!(all.iter().max(), Some(&DTG_MAX_TICKS));
        for ticks in 0..=DTG_MAX_TICKS {
            // 1 GHz: one tick per ns.
            let code = dead_time_dtg(ticks, 1_000_000_000).expect("encodable");
            let got = dtg_ticks(code);
            assert!(got >= ticks);
            assert!(!all.iter().any(|&t| t >= ticks && t < got), "{ticks}: {got}");
        }
        assert_eq!(dead_time_dtg(DTG_MAX_TICKS + 1, 1_000_000_000), None);
    }

    /// Hand calculations: 160 LSI ticks (5 ms at 32 kHz) → /4, reload 40;
    /// 100 000 ticks → /32 (PR 3), reload 3125; 2 000 000 ticks > 256·4095 → None;
    /// 32.76 s at 32 kHz = 1 048 320 ticks = 256·4095 → (6, 4095); 32.77 s = 1 048 640
    /// ticks → ⌈1 048 640/256⌉ = 4097 > 4095 → None.
    #[test]
    fn watchdog_setting() {
        assert_eq!(iwdg_setting(160), Some((0, 40)));
        assert_eq!(iwdg_setting(100_000), Some((3, 3125)));
        assert_eq!(iwdg_setting(2_000_000), None);
        assert_eq!(iwdg_setting(0), Some((0, 1)));
        assert_eq!(iwdg_for_timeout(0.005, 32_000), Some((0, 40)));
        assert_eq!(iwdg_for_timeout(32.76, 32_000), Some((6, 4095)));
        assert_eq!(iwdg_for_timeout(32.77, 32_000), None);
    }
}
