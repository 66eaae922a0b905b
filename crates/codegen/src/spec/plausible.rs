//! Physically sensible ranges: every quantity a spec or board file gives must lie in the
//! range of its kind (and, for the keys the whole design scales with, in the narrower range
//! of that key). The ranges are wide — decades beyond any real motor drive on either side —
//! so that they refuse only typos in the exponent or the prefix and values such as
//! `peak_current = "6.1e201 A"`, whose products overflow f64 or lose every digit in the
//! design (issue 18), never a real machine.

use crate::units::Kind;

/// The accepted interval of one quantity (SI, inclusive bounds) and why.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Plausible {
    /// Smallest accepted value of a key that must be positive.
    pub lo: f64,
    /// Largest accepted value; a key that may be zero or negative accepts [−hi, hi].
    pub hi: f64,
    /// `lo` as shown to the user, e.g. `1 V`.
    pub lo_text: &'static str,
    /// `hi` as shown to the user, e.g. `2000 V`.
    pub hi_text: &'static str,
    /// Why this interval.
    pub reason: &'static str,
}

const fn range(lo: f64, hi: f64, lo_text: &'static str, hi_text: &'static str, reason: &'static str) -> Plausible {
    Plausible {
        lo,
        hi,
        lo_text,
        hi_text,
        reason,
    }
}

/// The range of `key` (a dotted key) of `kind`: the key's own, else its kind's.
pub(crate) fn plausible(key: &str, kind: Kind) -> Option<Plausible> {
    key_range(key).or_else(|| kind_range(kind))
}

/// Keys every per-unit base, gain and scaling depends on get ranges narrower than their kind.
fn key_range(key: &str) -> Option<Plausible> {
    match key {
        "drive.switching_frequency" => Some(switching_frequency()),
        "drive.dc_link_voltage" | "drive.dc_link_voltage_min" => Some(dc_link_voltage()),
        "current_loop.bandwidth" => Some(current_loop_bandwidth()),
        _ => None,
    }
}

/// f_s = sampling frequency: from a 1 kHz high-power drive to the 200 kHz of a GaN stage;
/// the controller runs once per period (thesis A (1.1)).
fn switching_frequency() -> Plausible {
    range(
        1e3,
        200e3,
        "1 kHz",
        "200 kHz",
        "the current loop runs once per PWM period, from 1 kHz (MW drives) to 200 kHz (GaN stages)",
    )
}

/// U_dc: from a 1 V bench supply to the 2 kV above every 1.7 kV-class IGBT/SiC inverter.
fn dc_link_voltage() -> Plausible {
    range(
        1.0,
        2000.0,
        "1 V",
        "2000 V",
        "a DC link from a bench supply to the 1.7 kV class of IGBT and SiC inverters",
    )
}

/// α of the current loop: slower than 1 rad/s is slower than any mechanical motion it
/// serves; faster than 10^6 rad/s is beyond any sampled loop at f_s ≤ 200 kHz.
fn current_loop_bandwidth() -> Plausible {
    range(
        1.0,
        1e6,
        "1 rad/s",
        "1e6 rad/s",
        "a current loop faster than the mechanics (≥ 1 rad/s) and slower than any sampling (f_s ≤ 200 kHz)",
    )
}

/// Every quantity of a kind: five or more decades around the motor drives of the theses.
fn kind_range(kind: Kind) -> Option<Plausible> {
    Some(match kind {
        Kind::Resistance => range(1e-6, 1e6, "1 µΩ", "1 MΩ", "from a bus bar to a sensing divider"),
        Kind::Inductance => range(
            1e-9,
            10.0,
            "1 nH",
            "10 H",
            "from a stray inductance to a large line reactor",
        ),
        Kind::FluxLinkage => range(
            1e-6,
            100.0,
            "1 µWb",
            "100 Wb",
            "from a micromotor to a multi-megawatt machine (ψ_M ≈ 1 Wb at 100 kW)",
        ),
        Kind::Current => range(1e-3, 1e5, "1 mA", "100 kA", "from a micromotor to a traction converter"),
        Kind::Voltage => range(
            1e-3,
            2000.0,
            "1 mV",
            "2000 V",
            "up to the 1.7 kV class of IGBT and SiC inverters",
        ),
        Kind::Frequency => range(
            1e-3,
            1e9,
            "1 mHz",
            "1 GHz",
            "from a thermal time scale to the fastest peripheral clock",
        ),
        Kind::Speed => range(
            1e-3,
            1e5,
            "0.001 rad/s",
            "1e5 rad/s (955 000 rpm)",
            "the fastest electrical machines turn below a million rpm",
        ),
        Kind::AngularFrequency => range(
            1e-3,
            1e8,
            "0.001 rad/s",
            "1e8 rad/s",
            "from a drift filter to beyond any sampled loop",
        ),
        Kind::Torque => range(
            1e-6,
            1e6,
            "1 µN·m",
            "1 MN·m",
            "from a micromotor to a ship propulsion motor",
        ),
        Kind::TemperatureCelsius => range(
            -273.15,
            1000.0,
            "−273.15 °C",
            "1000 °C",
            "above absolute zero and below where any winding insulation or magnet survives",
        ),
        Kind::Capacitance => range(
            1e-15,
            10.0,
            "1 fF",
            "10 F",
            "from an ADC sample capacitor to a DC-link bank",
        ),
        Kind::Energy => range(1e-12, 1e3, "1 pJ", "1 kJ", "switching and recovery energies per event"),
        Kind::Power => range(
            1e-3,
            1e8,
            "1 mW",
            "100 MW",
            "from a micromotor to a ship propulsion motor",
        ),
        Kind::Time => range(
            1e-12,
            1e6,
            "1 ps",
            "1e6 s",
            "from a switching edge to a thermal time constant",
        ),
        Kind::Decibel => range(1e-6, 200.0, "1e-6 dB", "200 dB", "beyond 200 dB no f64 filter resolves"),
        Kind::TorqueConstant => range(1e-6, 1e3, "1 µN·m/A", "1000 N·m/A", "ψ_M's range times 3/2·n_p"),
        Kind::BackEmfConstant => range(1e-6, 1e3, "1 µV·s/rad", "1000 V·s/rad", "ψ_M's range times n_p"),
        Kind::SpeedConstant => range(
            1e-3,
            1e6,
            "0.001 rad/s/V",
            "1e6 rad/s/V",
            "the reciprocal of a back-EMF constant",
        ),
        Kind::Inertia => range(
            1e-12,
            1e4,
            "1e-12 kg·m²",
            "1e4 kg·m²",
            "from a micromotor to a ship shaft",
        ),
        Kind::ViscousFriction => range(
            1e-15,
            1e4,
            "1e-15 N·m·s/rad",
            "1e4 N·m·s/rad",
            "from a micromotor's bearing to a ship shaft",
        ),
        Kind::AngularAcceleration => range(
            1e-3,
            1e9,
            "0.001 rad/s²",
            "1e9 rad/s²",
            "beyond any shaft's acceleration",
        ),
        Kind::Angle => range(0.0, 1e3, "0 rad", "1000 rad", "angles are taken modulo a turn"),
        Kind::Transresistance => range(1e-6, 1e3, "1 µV/A", "1 kV/A", "from a shunt to a Hall sensor"),
        Kind::BitRate => return None,
    })
}

/// The interval accepted for a key that must be positive (`positive`) or may take either
/// sign: [lo, hi], or [−hi, hi] (a range with a negative `lo`, temperatures, stays).
pub(crate) fn interval(p: &Plausible, positive: bool) -> (f64, String) {
    if positive || p.lo < 0.0 {
        (p.lo, format!("[{}, {}]", p.lo_text, p.hi_text))
    } else {
        (-p.hi, format!("[−{}, {}]", p.hi_text, p.hi_text))
    }
}

/// Whether `value` of a key (that must be positive if `positive`) lies in `p`.
pub(crate) fn contains(p: &Plausible, value: f64, positive: bool) -> bool {
    let (lo, _) = interval(p, positive);
    value.is_finite() && value >= lo && value <= p.hi
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 18's examples are outside; the theses' values inside.
    #[test]
    fn issue_examples_are_refused_and_thesis_values_accepted() {
        let p = plausible("motor.datasheet.peak_current", Kind::Current).unwrap();
        assert!(!contains(&p, 6.1e201, true));
        assert!(contains(&p, 61.0, true)); // Fischer TI085, thesis A Table 1.1
        let u = plausible("drive.dc_link_voltage", Kind::Voltage).unwrap();
        assert!(!contains(&u, f64::MAX, true));
        assert!(contains(&u, 600.0, true)); // thesis A §5.1
        let a = plausible("current_loop.bandwidth", Kind::AngularFrequency).unwrap();
        assert!(!contains(&a, 1e-308, true));
        assert!(contains(&a, 100.0, true)); // thesis A §5.4.1
        let fs = plausible("drive.switching_frequency", Kind::Frequency).unwrap();
        assert!(contains(&fs, 20e3, true) && !contains(&fs, 1e300, true) && !contains(&fs, 10.0, true));
    }

    /// A key that may be zero or negative accepts [−hi, hi]; temperatures stop at absolute zero.
    #[test]
    fn signed_keys_and_temperatures() {
        let psi = plausible("motor.harmonics.d_flux_6", Kind::FluxLinkage).unwrap();
        assert!(contains(&psi, 0.0, false) && contains(&psi, -0.01, false) && !contains(&psi, -1e3, false));
        assert!(!contains(&psi, 0.0, true));
        let t = plausible("thermal.ambient", Kind::TemperatureCelsius).unwrap();
        assert!(contains(&t, -40.0, false) && !contains(&t, -300.0, false));
    }
}
