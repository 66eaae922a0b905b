//! From the six gate pins to the six switches, through the board's gate driver
//! ([`crate::hardware`]): two-level waveforms over one carrier period, the driver's input
//! logic, interlock and dead time, the switches' turn-off, and what the power stage does
//! with them — the strict rules a bridge can break (shoot-through; a switch on while the
//! image means the outputs off) and each leg's average output for the plant.

use crate::hardware::{Driver, DriverInput};

/// A two-level signal over `[0, len)` seconds: its high intervals, sorted and disjoint.
#[derive(Clone, Debug, PartialEq)]
pub struct Wave {
    /// Length of the window \[s\].
    pub len: f64,
    /// High intervals `[a, b)`.
    pub high: Vec<(f64, f64)>,
}

/// Intervals shorter than this are dropped \[s\] (well below a 170 MHz timer tick).
const EPS: f64 = 1e-12;

impl Wave {
    /// A constant level.
    pub fn constant(level: bool, len: f64) -> Self {
        Self {
            len,
            high: if level { vec![(0.0, len)] } else { Vec::new() },
        }
    }

    /// From high intervals (clipped to the window, merged).
    pub fn from_intervals(len: f64, mut iv: Vec<(f64, f64)>) -> Self {
        iv.retain(|(a, b)| b - a > EPS);
        iv.sort_by(|x, y| x.0.total_cmp(&y.0));
        let mut high: Vec<(f64, f64)> = Vec::new();
        for (a, b) in iv {
            let (a, b) = (a.max(0.0), b.min(len));
            if b - a <= EPS {
                continue;
            }
            match high.last_mut() {
                Some(last) if a <= last.1 + EPS => last.1 = last.1.max(b),
                _ => high.push((a, b)),
            }
        }
        Self { len, high }
    }

    /// The level at `t`.
    pub fn at(&self, t: f64) -> bool {
        self.high.iter().any(|&(a, b)| t >= a && t < b)
    }

    /// The complement.
    pub fn not(&self) -> Self {
        let mut iv = Vec::new();
        let mut t = 0.0;
        for &(a, b) in &self.high {
            iv.push((t, a));
            t = b;
        }
        iv.push((t, self.len));
        Self::from_intervals(self.len, iv)
    }

    /// Both high.
    pub fn and(&self, o: &Self) -> Self {
        let mut iv = Vec::new();
        for &(a, b) in &self.high {
            for &(c, d) in &o.high {
                iv.push((a.max(c), b.min(d)));
            }
        }
        Self::from_intervals(self.len, iv.into_iter().filter(|(a, b)| b > a).collect())
    }

    /// Each rising edge inside the window delayed by `d` (an interval that starts at 0
    /// continues from before the window and has no edge here).
    pub fn delay_rise(&self, d: f64) -> Self {
        let iv = self
            .high
            .iter()
            .map(|&(a, b)| if a > EPS { (a + d, b) } else { (a, b) })
            .collect();
        Self::from_intervals(self.len, iv)
    }

    /// Each high interval extended by `d` past its end.
    pub fn extend_fall(&self, d: f64) -> Self {
        let iv = self.high.iter().map(|&(a, b)| (a, b + d)).collect();
        Self::from_intervals(self.len, iv)
    }

    /// Total high time \[s\].
    pub fn high_time(&self) -> f64 {
        self.high.iter().map(|(a, b)| b - a).sum()
    }

    /// Whether it is high anywhere.
    pub fn any(&self) -> bool {
        !self.high.is_empty()
    }
}

/// What a gate pin does over the window.
#[derive(Clone, Debug, PartialEq)]
pub enum PinWave {
    /// Driven by the MCU with this waveform.
    Driven(Wave),
    /// Not driven (Hi-Z): the GPIO's pull if it has one, else the board's.
    Undriven {
        /// The GPIO pull (PUPDR) level, if any.
        gpio_pull: Option<bool>,
        /// Why the MCU does not drive it, for messages.
        why: String,
    },
}

/// One leg's switches over the window.
#[derive(Clone, Debug, PartialEq)]
pub struct LegSwitches {
    /// High-side switch commanded on (the driver output).
    pub high: Wave,
    /// Low-side switch commanded on.
    pub low: Wave,
}

/// The level a driver input sees: the pin's, or what pulls it; `None` if it floats.
pub fn input_level(pin: &PinWave, input: &DriverInput, len: f64) -> Option<Wave> {
    match pin {
        PinWave::Driven(w) => Some(w.clone()),
        PinWave::Undriven { gpio_pull, .. } => gpio_pull.or(input.undriven()).map(|l| Wave::constant(l, len)),
    }
}

/// The driver's outputs for one leg from its inputs' levels: each input's logic, the
/// interlock (both requests cancel), and its dead time (an output turns on only once
/// the other has been off for `dead_time_s`).
pub fn leg(driver: &Driver, inputs: [&DriverInput; 2], levels: [&Wave; 2]) -> LegSwitches {
    let ask = |k: usize| {
        let w = levels[k];
        match inputs[k].logic {
            crate::hardware::Logic::ActiveHigh => w.clone(),
            crate::hardware::Logic::ActiveLow => w.not(),
        }
    };
    let (mut hi, mut lo) = (ask(0), ask(1));
    if driver.interlock {
        let both = hi.and(&lo);
        hi = hi.and(&both.not());
        lo = lo.and(&both.not());
    }
    if driver.dead_time_s > 0.0 {
        let (h, l) = (hi.clone(), lo.clone());
        hi = h.and(&l.extend_fall(driver.dead_time_s).not());
        lo = l.and(&h.extend_fall(driver.dead_time_s).not());
    }
    LegSwitches { high: hi, low: lo }
}

/// The time both switches of a leg conduct together \[s\]: each keeps conducting
/// `turn_off_s` after its command ends.
pub fn overlap(driver: &Driver, s: &LegSwitches) -> f64 {
    let h = s.high.extend_fall(driver.turn_off_s);
    let l = s.low.extend_fall(driver.turn_off_s);
    h.and(&l).high_time()
}

/// A leg's average output over the window as a duty (high-side share), the dead
/// intervals split evenly (the ideal volt-second average of thesis A (3.3), as `motorgen
/// verify`'s inverter: no dead-time voltage error); `None` when neither switch conducts
/// at all (the phase floats).
pub fn duty(s: &LegSwitches) -> Option<f64> {
    let len = s.high.len;
    let (h, l) = (s.high.high_time(), s.low.high_time());
    if h + l <= EPS {
        return None;
    }
    Some((h + (len - h - l) / 2.0) / len)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hardware::{Logic, Pull};

    const P: f64 = 50e-6;

    fn input(logic: Logic) -> DriverInput {
        DriverInput {
            pin: "PA0",
            logic,
            pull: Pull::None,
        }
    }

    fn driver(interlock: bool, dead: f64) -> Driver {
        Driver {
            part: "test",
            interlock,
            dead_time_s: dead,
            turn_off_s: 100e-9,
        }
    }

    /// A centre-aligned PWM leg at 30 % duty with complementary signals and TIM1 dead
    /// time `td` on each rising edge, as RM0440's dead-time generator makes them.
    fn complementary(td: f64) -> (Wave, Wave) {
        let on = 0.3 * P;
        let r = Wave::from_intervals(P, vec![(0.0, on / 2.0), (P - on / 2.0, P)]);
        (r.delay_rise(td), r.not().delay_rise(td))
    }

    /// In-phase inputs without interlock (the reference board's isolated drivers): 500 ns
    /// of dead time separate the switches by more than their 100 ns turn-off; none gives
    /// 100 ns of conduction together at each of the two edges (shoot-through).
    #[test]
    fn dead_time_keeps_a_leg_from_shooting_through() {
        let d = driver(false, 0.0);
        let inputs = [&input(Logic::ActiveHigh), &input(Logic::ActiveHigh)];
        let (h, l) = complementary(500e-9);
        let s = leg(&d, inputs, [&h, &l]);
        assert_eq!(overlap(&d, &s), 0.0);
        // Duty stays 30 % with the dead intervals split evenly.
        assert!((duty(&s).unwrap() - 0.3).abs() < 1e-9);
        let (h, l) = complementary(0.0);
        let s = leg(&d, inputs, [&h, &l]);
        assert!((overlap(&d, &s) - 200e-9).abs() < 1e-12, "{}", overlap(&d, &s));
    }

    /// An L6398 (LIN active low, interlock, 320 ns of its own) fed the complementary pair
    /// without inverting CHxN: the low-side request coincides with the high side's, the
    /// interlock cancels both, the leg never conducts. Fed correctly (CHxN inverted) it
    /// switches with its own 320 ns even from a TIM1 dead time of 0.
    #[test]
    fn l6398_blanks_a_leg_driven_with_the_wrong_polarity() {
        let d = driver(true, 320e-9);
        let inputs = [&input(Logic::ActiveHigh), &input(Logic::ActiveLow)];
        let (h, l) = complementary(0.0);
        let s = leg(&d, inputs, [&h, &l]);
        assert!(!s.high.any() && !s.low.any());
        assert_eq!(duty(&s), None);
        let s = leg(&d, inputs, [&h, &l.not()]);
        assert!(s.high.any() && s.low.any());
        assert_eq!(overlap(&d, &s), 0.0);
        // 320 ns before each rise: on time 0.3·P − 320 ns.
        assert!((s.high.high_time() - (0.3 * P - 320e-9)).abs() < 1e-12);
    }

    #[test]
    fn wave_algebra() {
        let w = Wave::from_intervals(10.0, vec![(2.0, 4.0), (3.0, 5.0), (8.0, 12.0)]);
        assert_eq!(w.high, vec![(2.0, 5.0), (8.0, 10.0)]);
        assert_eq!(w.not().high, vec![(0.0, 2.0), (5.0, 8.0)]);
        assert_eq!(w.delay_rise(1.0).high, vec![(3.0, 5.0), (9.0, 10.0)]);
        assert_eq!(w.extend_fall(1.0).high, vec![(2.0, 6.0), (8.0, 10.0)]);
        assert!(w.at(2.0) && !w.at(5.0) && (w.high_time() - 5.0).abs() < 1e-12);
        let z = Wave::from_intervals(10.0, vec![(0.0, 1.0)]);
        assert_eq!(z.delay_rise(5.0).high, vec![(0.0, 1.0)]);
    }
}
