//! The scaling section: the full scale and Q format of every quantity the firmware
//! represents (margin over the ratings; angle, speed and observer error per (4.20)).

use std::f64::consts::{PI, SQRT_2};

use serde::Serialize;

use crate::design::scaling::{QFormat, Scaling, scaling};
use crate::spec::Spec;

/// Fixed-point scalings of every quantity the firmware represents.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ScalingsOut {
    /// Headroom factor applied to the ratings.
    pub margin: f64,
    /// Phase current.
    pub phase_current: Scaling,
    /// Phase voltage.
    pub phase_voltage: Scaling,
    /// DC-link voltage.
    pub dc_link_voltage: Scaling,
    /// Angle (fixed by the CORDIC interface, A = π).
    pub angle: Scaling,
    /// Observer speed, A = f_s·π (4.20).
    pub speed: Scaling,
    /// Observer error, A = 1 (4.20).
    pub observer_error: Scaling,
}

/// Every scaling of one motor.
pub(in crate::design) fn scalings(spec: &Spec) -> ScalingsOut {
    let m = &spec.motor;
    let margin = spec.scaling_margin.value;
    let udc = spec.drive.dc_link_voltage.value;
    let fs = spec.drive.switching_frequency.value;
    let i_peak = SQRT_2 * m.peak_current.value;
    ScalingsOut {
        margin,
        phase_current: scaling(
            margin * i_peak,
            "A",
            QFormat::Q15,
            format!("margin·√2·I_peak,rms = {margin}·√2·{} A", m.peak_current.value),
        ),
        phase_voltage: scaling(
            margin * udc / 3f64.sqrt(),
            "V",
            QFormat::Q15,
            format!("margin·U_dc/√3 = {margin}·{udc} V/√3 (THPWM phase amplitude limit)"),
        ),
        dc_link_voltage: scaling(
            margin * udc,
            "V",
            QFormat::Q15,
            format!("margin·U_dc = {margin}·{udc} V"),
        ),
        angle: scaling(
            PI,
            "rad",
            QFormat::Q31,
            "A = π, dictated by the CORDIC interface (4.20)",
        ),
        speed: scaling(
            fs * PI,
            "rad/s",
            QFormat::Q31,
            "A = f_s·π so that θ^i(n) = θ^i(n−1) + ω^i(n−1) (4.19), (4.20)",
        ),
        observer_error: scaling(1.0, "1", QFormat::Q31, "A = 1 (4.20); atan2 error normalised by π"),
    }
}
