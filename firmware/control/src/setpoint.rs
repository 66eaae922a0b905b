//! Setpoint supervision: a periodically received setpoint (the vehicle unit's torque
//! demand over CAN) that ramps to zero when it stops arriving.
//!
//! Called once per control period with the value received since the previous call
//! (if any). While frames arrive, the output follows them (limited to ±`limit`).
//! After more than `timeout_ticks` calls without one, the output moves towards zero
//! by `ramp_step` per call and stays there; the next valid frame is followed again
//! at once (the sender is back in control). A non-finite value counts as missing.

/// Timeout and ramp, in control periods.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SetpointConfig {
    /// Calls without a new value after which the ramp to zero starts.
    pub timeout_ticks: u32,
    /// Magnitude the output falls per call once timed out (> 0).
    pub ramp_step: f32,
    /// Largest magnitude accepted; received values are clamped to ±limit.
    pub limit: f32,
}

/// Supervision state.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SetpointState {
    /// Current output.
    pub value: f32,
    /// Calls since the last valid value (saturating).
    pub since_last: u32,
}

impl SetpointState {
    /// Output zero, as if the timeout had already passed.
    pub const fn new() -> Self {
        Self {
            value: 0.0,
            since_last: u32::MAX,
        }
    }

    /// The setpoint has not arrived for longer than the timeout.
    pub fn timed_out(&self, config: &SetpointConfig) -> bool {
        self.since_last > config.timeout_ticks
    }
}

impl SetpointConfig {
    /// One control period; `received` is the value that arrived since the last call.
    pub fn process(&self, state: &mut SetpointState, received: Option<f32>) -> f32 {
        match received.filter(|v| v.is_finite()) {
            Some(v) => {
                state.value = v.clamp(-self.limit.abs(), self.limit.abs());
                state.since_last = 0;
            }
            None => {
                state.since_last = state.since_last.saturating_add(1);
                if state.timed_out(self) {
                    let step = self.ramp_step.abs();
                    state.value = if state.value > step {
                        state.value - step
                    } else if state.value < -step {
                        state.value + step
                    } else {
                        0.0
                    };
                }
            }
        }
        state.value
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 10 ms frames, 3 missed frames at 20 kHz = 600 ticks; ramp 0.25 per tick
    /// (exact in binary, so the ramp is exact).
    const C: SetpointConfig = SetpointConfig {
        timeout_ticks: 600,
        ramp_step: 0.25,
        limit: 80.0,
    };

    #[test]
    fn starts_at_zero_and_follows_frames() {
        let mut s = SetpointState::new();
        assert_eq!(C.process(&mut s, None), 0.0);
        assert!(s.timed_out(&C));
        assert_eq!(C.process(&mut s, Some(10.0)), 10.0);
        assert!(!s.timed_out(&C));
        // Between frames the value is held.
        for _ in 0..199 {
            assert_eq!(C.process(&mut s, None), 10.0);
        }
        assert_eq!(C.process(&mut s, Some(-5.0)), -5.0);
    }

    /// Held for exactly `timeout_ticks` missed calls, then 0.25 per call down to
    /// zero: 10/0.25 = 40 calls, and it stays at zero.
    #[test]
    fn timeout_then_ramp_to_zero() {
        let mut s = SetpointState::new();
        C.process(&mut s, Some(10.0));
        for _ in 0..600 {
            assert_eq!(C.process(&mut s, None), 10.0);
        }
        for k in 1..=40 {
            assert_eq!(C.process(&mut s, None), 10.0 - 0.25 * k as f32);
        }
        for _ in 0..10 {
            assert_eq!(C.process(&mut s, None), 0.0);
        }
    }

    /// Negative values ramp up to zero; a remainder smaller than a step ends at 0
    /// (−0.625 → −0.375 → −0.125 → 0, all exact in binary).
    #[test]
    fn negative_ramp_and_remainder() {
        let mut s = SetpointState::new();
        C.process(&mut s, Some(-0.625));
        for _ in 0..600 {
            C.process(&mut s, None);
        }
        assert_eq!(C.process(&mut s, None), -0.375);
        assert_eq!(C.process(&mut s, None), -0.125);
        assert_eq!(C.process(&mut s, None), 0.0);
    }

    /// A frame during the ramp is followed at once; the timeout restarts.
    #[test]
    fn recovery() {
        let mut s = SetpointState::new();
        C.process(&mut s, Some(10.0));
        for _ in 0..610 {
            C.process(&mut s, None);
        }
        assert_eq!(s.value, 7.5);
        assert_eq!(C.process(&mut s, Some(4.0)), 4.0);
        assert_eq!(s.since_last, 0);
        for _ in 0..600 {
            assert_eq!(C.process(&mut s, None), 4.0);
        }
        assert_eq!(C.process(&mut s, None), 3.75);
    }

    /// Values beyond the limit are clamped; NaN and ∞ count as missing frames.
    #[test]
    fn limit_and_invalid_values() {
        let mut s = SetpointState::new();
        assert_eq!(C.process(&mut s, Some(500.0)), 80.0);
        assert_eq!(C.process(&mut s, Some(-500.0)), -80.0);
        assert_eq!(C.process(&mut s, Some(f32::NAN)), -80.0);
        assert_eq!(s.since_last, 1);
        assert_eq!(C.process(&mut s, Some(f32::INFINITY)), -80.0);
        assert_eq!(s.since_last, 2);
    }
}
