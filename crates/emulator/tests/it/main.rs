//! The real image on the emulated G474, one test binary: boot, protection, CAN and the
//! closed loop, on every motor in `motors/` (README, "Scenarios").

mod at_speed;
mod boards;
mod boot;
mod can;
mod closed_loop;
mod defects;
mod duty_limit;
mod first_power_up;
mod frequency_response;
mod preflight;
mod protection;

/// Upper bound for the bring-up \[s\]: the ADC regulator's 2 × 20 µs, a calibration each,
/// the CORDIC/FMAC self-tests and polling, at 170 MHz, are well under 10 ms; the first
/// setpoint frame after the CAN join comes within one 10 ms period.
const BOOT_LIMIT_S: f64 = 0.05;
