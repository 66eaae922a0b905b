//! Physical quantities written as `"<value> <unit>"` strings, parsed with `uom`.
//!
//! Typed quantities end here: every parser returns the value in SI base units
//! as `f64`, and callers name their fields with the unit (`_ohm`, `_h`, …).
//! A bare number is never accepted where a quantity belongs, so `0.0012`
//! cannot silently mean henries.

use std::str::FromStr;
use uom::si::f64 as q;

/// What kind of quantity a key holds; decides the accepted units.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// Ω.
    Resistance,
    /// H.
    Inductance,
    /// Wb (flux linkage).
    FluxLinkage,
    /// A.
    Current,
    /// V.
    Voltage,
    /// Hz.
    Frequency,
    /// rad/s or rpm (speed).
    Speed,
    /// rad/s, or Hz taken as 2π·f (bandwidths, natural frequencies).
    AngularFrequency,
    /// N·m.
    Torque,
    /// °C or K, returned in °C.
    TemperatureCelsius,
    /// F.
    Capacitance,
    /// J.
    Energy,
    /// W.
    Power,
    /// s.
    Time,
    /// dB, returned in dB (positive = attenuation).
    Decibel,
    /// Any torque per any current (N·m/A, mN·m/A, …), returned in N·m/A.
    TorqueConstant,
    /// V·s/rad (per rad/s), or any voltage per any speed (V/krpm, mV/rpm, …), returned in V·s/rad.
    BackEmfConstant,
    /// Any speed per any voltage (rpm/V, rad/s/V, …), returned in rad/s per V.
    SpeedConstant,
    /// kg·m², or any mass times any area (g·cm², kg·cm², …), returned in kg·m².
    Inertia,
    /// N·m·s/rad (viscous friction b).
    ViscousFriction,
    /// °, deg or rad, returned in rad.
    Angle,
    /// rad/s² or rpm/s, returned in rad/s².
    AngularAcceleration,
    /// V/A (a current sensor's output voltage per ampere), returned in V/A.
    Transresistance,
    /// bit/s (a bus bit rate), returned in bit/s.
    BitRate,
}

impl Kind {
    /// Human name of the dimension.
    pub fn name(self) -> &'static str {
        match self {
            Kind::Resistance => "a resistance",
            Kind::Inductance => "an inductance",
            Kind::FluxLinkage => "a flux linkage",
            Kind::Current => "a current",
            Kind::Voltage => "a voltage",
            Kind::Frequency => "a frequency",
            Kind::Speed => "a speed",
            Kind::AngularFrequency => "an angular frequency",
            Kind::Torque => "a torque",
            Kind::TemperatureCelsius => "a temperature",
            Kind::Capacitance => "a capacitance",
            Kind::Energy => "an energy",
            Kind::Power => "a power",
            Kind::Time => "a time",
            Kind::Decibel => "a level in decibels",
            Kind::TorqueConstant => "a torque constant",
            Kind::BackEmfConstant => "a back-EMF constant",
            Kind::SpeedConstant => "a speed constant",
            Kind::Inertia => "a moment of inertia",
            Kind::ViscousFriction => "a viscous friction coefficient",
            Kind::Angle => "an angle",
            Kind::AngularAcceleration => "an angular acceleration",
            Kind::Transresistance => "a current-sensor gain",
            Kind::BitRate => "a bit rate",
        }
    }

    /// What a user may write, with an example.
    pub fn accepted(self) -> &'static str {
        match self {
            Kind::Resistance => "a resistance such as \"0.126 Ω\" (units: Ω, mΩ, µΩ, kΩ, ohm, mohm)",
            Kind::Inductance => "an inductance such as \"0.393 mH\" (units: H, mH, µH, uH, nH, henry)",
            Kind::FluxLinkage => "a flux linkage such as \"60 mWb\" (units: Wb, mWb, µWb, V·s)",
            Kind::Current => "a current such as \"22.6 A\" (units: A, mA, kA)",
            Kind::Voltage => "a voltage such as \"600 V\" (units: V, mV, kV)",
            Kind::Frequency => "a frequency such as \"20 kHz\" (units: Hz, kHz, MHz)",
            Kind::Speed => "a speed such as \"20000 rpm\" or \"2094 rad/s\" (units: rpm, krpm, rad/s)",
            Kind::AngularFrequency => {
                "an angular frequency such as \"100 rad/s\" (units: rad/s; Hz, kHz are taken as 2π·f)"
            }
            Kind::Torque => "a torque such as \"11.1 N·m\" (units: N·m, Nm, N m, mN·m, mNm, N·cm)",
            Kind::TemperatureCelsius => "a temperature such as \"20 °C\" (units: °C, degC, K)",
            Kind::Capacitance => "a capacitance such as \"5 pF\" (units: F, µF, nF, pF)",
            Kind::Energy => "an energy such as \"306 mJ\" (units: J, mJ, µJ)",
            Kind::Power => "a power such as \"50 kW\" (units: W, kW)",
            Kind::Time => "a time such as \"1.5 ms\" (units: s, ms, µs, ns)",
            Kind::Decibel => "a level in decibels such as \"40 dB\"",
            Kind::TorqueConstant => {
                "a torque constant such as \"0.492 N·m/A\" or \"36.9 mN·m/A\" (a torque unit per a current unit: N·m/A, Nm/A, mN·m/A, mNm/A, N·cm/A)"
            }
            Kind::BackEmfConstant => {
                "a back-EMF constant such as \"0.296 V·s/rad\" or \"31 V/krpm\" (V·s/rad, or a voltage unit per a speed unit: V/(rad/s), V/krpm, V/rpm, mV/rpm, V/1000 rpm)"
            }
            Kind::SpeedConstant => {
                "a speed constant such as \"259 rpm/V\" (a speed unit per a voltage unit: rpm/V, krpm/V, rad/s/V, (rad/s)/V)"
            }
            Kind::Inertia => {
                "a moment of inertia such as \"181 g·cm²\" or \"0.01 kg·m²\" (kg·m², or a mass unit times an area unit: g·cm², kg·cm², g·mm², kg m^2)"
            }
            Kind::ViscousFriction => "a viscous friction coefficient such as \"0.001 N·m·s/rad\"",
            Kind::Angle => "an angle such as \"10 °\" (units: °, deg, rad, mrad)",
            Kind::AngularAcceleration => {
                "an angular acceleration such as \"5000 rpm/s\" (units: rad/s², rad/s^2, rpm/s, krpm/s)"
            }
            Kind::Transresistance => "a current-sensor gain such as \"51.8 mV/A\" (units: V/A, mV/A)",
            Kind::BitRate => "a bit rate such as \"500 kbit/s\" (units: bit/s, kbit/s, Mbit/s)",
        }
    }
}

/// Why a quantity string was refused.
#[derive(Debug, Clone, PartialEq)]
pub struct UnitError {
    /// What is wrong.
    pub problem: String,
}

/// Splits `"0.126 Ω"` (or `"0.126Ω"`) into the number and the trimmed unit.
fn split(text: &str) -> Result<(f64, String), UnitError> {
    let t = text.trim();
    let end = t
        .char_indices()
        .find(|&(i, c)| {
            !(c.is_ascii_digit()
                || c == '.'
                || ((c == '-' || c == '+') && (i == 0 || t[..i].ends_with(['e', 'E'])))
                || ((c == 'e' || c == 'E')
                    && i > 0
                    && t[i + 1..].starts_with(|n: char| n.is_ascii_digit() || n == '-' || n == '+')))
        })
        .map_or(t.len(), |(i, _)| i);
    let (number, unit) = t.split_at(end);
    let unit = unit.trim();
    if number.is_empty() {
        let word = unit.split_whitespace().next().unwrap_or("");
        let lower = word.to_ascii_lowercase();
        if matches!(lower.as_str(), "nan" | "inf" | "+inf" | "-inf" | "infinity") {
            return Err(UnitError {
                problem: format!("\"{text}\" is not a finite number"),
            });
        }
        return Err(UnitError {
            problem: format!("\"{text}\" does not start with a number"),
        });
    }
    let value: f64 = number.parse().map_err(|_| UnitError {
        problem: format!("\"{number}\" in \"{text}\" is not a number"),
    })?;
    if unit.is_empty() {
        return Err(UnitError {
            problem: format!("\"{text}\" has no unit; write the unit after the number"),
        });
    }
    Ok((value, normalise(unit)))
}

/// Canonical spellings: the micro sign, `u` for micro, `ohm`, `N·m`.
fn normalise(unit: &str) -> String {
    let mut u = unit.replace('\u{03BC}', "\u{00B5}"); // Greek mu → micro sign
    for (from, to) in [
        ("Ohm", "Ω"),
        ("ohms", "Ω"),
        ("ohm", "Ω"),
        ("N·cm", "N · cm"),
        ("Ncm", "N · cm"),
        ("N·m", "N · m"),
        ("N*m", "N · m"),
        ("N.m", "N · m"),
        ("Nm", "N · m"),
        ("degC", "°C"),
        ("deg C", "°C"),
        ("kg·m²", "kg · m²"),
        ("kg m^2", "kg · m²"),
        ("kg·m^2", "kg · m²"),
        ("^2", "²"),
        ("r/min", "rpm"),
        ("RPM", "rpm"),
    ] {
        u = u.replace(from, to);
    }
    if u == "N m" {
        u = "N · m".to_string();
    }
    // `uH`, `uWb`, `us`, … : a leading ASCII `u` before a unit letter means micro.
    if let Some(rest) = u.strip_prefix('u')
        && rest.starts_with(|c: char| c.is_ascii_uppercase() || c == 's' || c == 'Ω')
    {
        u = format!("µ{rest}");
    }
    u
}

/// Where a compound unit `a/b` is split: at its first `/` (`V/rad/s` is V per rad/s)
/// or its last (`rad/s/V` is rad/s per V).
#[derive(Clone, Copy)]
enum Split {
    First,
    Last,
}

/// The SI value of one `num/den` unit, each side parsed as its own kind (so every unit uom
/// knows for that dimension is accepted): `mN · m/A` → 1 mN·m / 1 A = 1e-3. A side may
/// carry its own number (`V/1000 rpm`) and parentheses (`V/(rad/s)`).
fn ratio(unit: &str, num: Kind, den: Kind, at: Split) -> Option<f64> {
    let (n, d) = match at {
        Split::First => unit.split_once('/')?,
        Split::Last => unit.rsplit_once('/')?,
    };
    let side = |kind: Kind, text: &str| {
        let t = text.trim().trim_start_matches('(').trim_end_matches(')').trim();
        let with_number = if t.starts_with(|c: char| c.is_ascii_digit()) {
            t.to_string()
        } else {
            format!("1 {t}")
        };
        parse(kind, &with_number).ok().filter(|x| *x != 0.0)
    };
    Some(side(num, n)? / side(den, d)?)
}

/// kg·m² per unit of `unit` written as a mass unit times an area unit (`g · cm²`, `kgcm²`),
/// both parsed by uom: the first split of the unit (separators removed) into a mass and an
/// area that both parse.
fn mass_times_area(unit: &str) -> Option<f64> {
    use uom::si::{area::square_meter, mass::kilogram};
    let compact: String = unit.chars().filter(|c| !matches!(c, ' ' | '·' | '*' | '.')).collect();
    compact.char_indices().skip(1).find_map(|(i, _)| {
        let (m, a) = compact.split_at(i);
        let mass = via_uom::<q::Mass>(1.0, m)?.get::<kilogram>();
        let area = via_uom::<q::Area>(1.0, a)?.get::<square_meter>();
        Some(mass * area)
    })
}

fn via_uom<Q: FromStr>(value: f64, unit: &str) -> Option<Q> {
    format!("{value:e} {unit}").parse::<Q>().ok()
}

/// Parses `text` as a quantity of `kind`, returning its value in SI units
/// (°C for temperatures, dB for decibels, N·m/A and V·s/rad for the motor constants).
pub fn parse(kind: Kind, text: &str) -> Result<f64, UnitError> {
    use uom::si::{
        angular_velocity::radian_per_second, capacitance::farad, electric_current::ampere, electric_potential::volt,
        electrical_resistance::ohm, energy::joule, frequency::hertz, inductance::henry, magnetic_flux::weber,
        moment_of_inertia::kilogram_square_meter, power::watt, thermodynamic_temperature::degree_celsius, time::second,
        torque::newton_meter,
    };
    let (value, unit) = split(text)?;
    if !value.is_finite() {
        return Err(UnitError {
            problem: format!("\"{text}\" is not a finite number"),
        });
    }
    let si = match kind {
        Kind::Resistance => via_uom::<q::ElectricalResistance>(value, &unit).map(|v| v.get::<ohm>()),
        Kind::Inductance => via_uom::<q::Inductance>(value, &unit).map(|v| v.get::<henry>()),
        Kind::FluxLinkage => match unit.as_str() {
            "V·s" | "Vs" | "V s" => Some(value),
            _ => via_uom::<q::MagneticFlux>(value, &unit).map(|v| v.get::<weber>()),
        },
        Kind::Current => via_uom::<q::ElectricCurrent>(value, &unit).map(|v| v.get::<ampere>()),
        Kind::Voltage => via_uom::<q::ElectricPotential>(value, &unit).map(|v| v.get::<volt>()),
        Kind::Frequency => via_uom::<q::Frequency>(value, &unit).map(|v| v.get::<hertz>()),
        Kind::Speed => match unit.as_str() {
            "krpm" | "kRPM" | "krpm " => via_uom::<q::AngularVelocity>(value * 1e3, "rpm"),
            _ => via_uom::<q::AngularVelocity>(value, &unit),
        }
        .map(|v| v.get::<radian_per_second>()),
        Kind::AngularFrequency => via_uom::<q::AngularVelocity>(value, &unit)
            .filter(|_| unit == "rad/s" || unit.starts_with("radian"))
            .map(|v| v.get::<radian_per_second>())
            .or_else(|| via_uom::<q::Frequency>(value, &unit).map(|f| 2.0 * std::f64::consts::PI * f.get::<hertz>())),
        Kind::Torque => via_uom::<q::Torque>(value, &unit).map(|v| v.get::<newton_meter>()),
        Kind::TemperatureCelsius => {
            via_uom::<q::ThermodynamicTemperature>(value, &unit).map(|v| v.get::<degree_celsius>())
        }
        Kind::Capacitance => via_uom::<q::Capacitance>(value, &unit).map(|v| v.get::<farad>()),
        Kind::Energy => via_uom::<q::Energy>(value, &unit).map(|v| v.get::<joule>()),
        Kind::Power => via_uom::<q::Power>(value, &unit).map(|v| v.get::<watt>()),
        Kind::Time => via_uom::<q::Time>(value, &unit).map(|v| v.get::<second>()),
        Kind::Inertia => via_uom::<q::MomentOfInertia>(value, &unit)
            .map(|v| v.get::<kilogram_square_meter>())
            .or_else(|| mass_times_area(&unit).map(|k| value * k)),
        Kind::Decibel => (unit == "dB").then_some(value),
        Kind::ViscousFriction => {
            matches!(unit.as_str(), "N · m·s/rad" | "N · m s/rad" | "N · ms/rad" | "N · m·s").then_some(value)
        }
        Kind::Angle => match unit.as_str() {
            "°" | "deg" | "degree" | "degrees" => Some(value.to_radians()),
            "rad" => Some(value),
            "mrad" => Some(value * 1e-3),
            _ => None,
        },
        Kind::AngularAcceleration => match unit.as_str() {
            "rad/s²" | "rad/s^2" | "rad/s2" => Some(value),
            "rpm/s" => Some(value * std::f64::consts::PI / 30.0),
            "krpm/s" => Some(value * 1e3 * std::f64::consts::PI / 30.0),
            _ => None,
        },
        Kind::Transresistance => match unit.as_str() {
            "V/A" => Some(value),
            "mV/A" => Some(value * 1e-3),
            _ => None,
        },
        Kind::BitRate => match unit.as_str() {
            "bit/s" | "bps" => Some(value),
            "kbit/s" | "kbps" => Some(value * 1e3),
            "Mbit/s" | "Mbps" => Some(value * 1e6),
            _ => None,
        },
        Kind::TorqueConstant => ratio(&unit, Kind::Torque, Kind::Current, Split::Last).map(|k| value * k),
        Kind::SpeedConstant => ratio(&unit, Kind::Speed, Kind::Voltage, Split::Last).map(|k| value * k),
        Kind::BackEmfConstant => {
            let rpm = std::f64::consts::PI / 30.0; // rad/s per rpm
            match unit.as_str() {
                "V·s/rad" | "Vs/rad" | "V s/rad" | "V/(rad/s)" | "V/rad/s" => Some(value),
                "mV·s/rad" | "mV/(rad/s)" => Some(value * 1e-3),
                "V/krpm" | "V/kRPM" => Some(value / (1e3 * rpm)),
                "V/rpm" => Some(value / rpm),
                "mV/rpm" => Some(value * 1e-3 / rpm),
                _ => ratio(&unit, Kind::Voltage, Kind::Speed, Split::First).map(|k| value * k),
            }
        }
    };
    si.ok_or_else(|| UnitError {
        problem: format!(
            "\"{text}\" is not {}: unit \"{unit}\" is not accepted here",
            kind.name()
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-12 * b.abs().max(1e-300)
    }

    #[test]
    fn angles_and_accelerations() {
        // 10° = π/18 rad; 1 rpm/s = π/30 rad/s² (hand conversions).
        assert!(close(parse(Kind::Angle, "10 °").unwrap(), std::f64::consts::PI / 18.0));
        assert!(close(
            parse(Kind::Angle, "10 deg").unwrap(),
            std::f64::consts::PI / 18.0
        ));
        assert!(close(parse(Kind::Angle, "0.1 rad").unwrap(), 0.1));
        assert!(close(
            parse(Kind::AngularAcceleration, "300 rpm/s").unwrap(),
            10.0 * std::f64::consts::PI
        ));
        assert!(close(parse(Kind::AngularAcceleration, "50 rad/s²").unwrap(), 50.0));
        assert!(parse(Kind::Angle, "10 rad/s").is_err());
    }

    #[test]
    fn accepts_the_spellings_users_write() {
        assert!(close(parse(Kind::Resistance, "0.126 Ω").unwrap(), 0.126));
        assert!(close(parse(Kind::Resistance, "0.126 ohm").unwrap(), 0.126));
        assert!(close(parse(Kind::Resistance, "7.9 mΩ").unwrap(), 7.9e-3));
        assert!(close(parse(Kind::Resistance, "7.9 mOhm").unwrap(), 7.9e-3));
        assert!(close(parse(Kind::Inductance, "0.393 mH").unwrap(), 0.393e-3));
        assert!(close(parse(Kind::Inductance, "393 µH").unwrap(), 393e-6)); // U+00B5
        assert!(close(parse(Kind::Inductance, "393 μH").unwrap(), 393e-6)); // U+03BC
        assert!(close(parse(Kind::Inductance, "393 uH").unwrap(), 393e-6));
        assert!(close(parse(Kind::Inductance, "393µH").unwrap(), 393e-6));
        assert!(close(parse(Kind::FluxLinkage, "60 mWb").unwrap(), 0.060));
        assert!(close(parse(Kind::Frequency, "20 kHz").unwrap(), 20e3));
        assert!(close(parse(Kind::Capacitance, "5 pF").unwrap(), 5e-12));
        assert!(close(parse(Kind::Energy, "306 mJ").unwrap(), 0.306));
        assert!(close(parse(Kind::Time, "1.5 ms").unwrap(), 1.5e-3));
        assert!(close(parse(Kind::Decibel, "40 dB").unwrap(), 40.0));
        assert!(close(parse(Kind::Torque, "11.1 N·m").unwrap(), 11.1));
        assert!(close(parse(Kind::Torque, "11.1 Nm").unwrap(), 11.1));
        assert!(close(parse(Kind::TemperatureCelsius, "130 °C").unwrap(), 130.0));
        assert!((parse(Kind::TemperatureCelsius, "293.15 K").unwrap() - 20.0).abs() < 1e-9);
        assert!(close(parse(Kind::Voltage, "1.2e2 V").unwrap(), 120.0));
    }

    /// Board quantities: 10 mΩ shunt × gain 5.18 = 51.8 mV/A; 500 kbit/s.
    #[test]
    fn sensor_gains_and_bit_rates() {
        assert!(close(parse(Kind::Transresistance, "51.8 mV/A").unwrap(), 0.0518));
        assert!(close(parse(Kind::Transresistance, "0.02 V/A").unwrap(), 0.02));
        assert!(close(parse(Kind::BitRate, "500 kbit/s").unwrap(), 500e3));
        assert!(close(parse(Kind::BitRate, "1 Mbit/s").unwrap(), 1e6));
        assert!(parse(Kind::Transresistance, "5 mV").is_err());
    }

    #[test]
    fn speeds_convert_rpm_to_rad_per_second() {
        // 20000 rpm = 20000·2π/60 = 2094.3951 rad/s (hand calculation).
        let w = parse(Kind::Speed, "20000 rpm").unwrap();
        assert!((w - 2_094.395_102_393_195).abs() < 1e-9, "{w}");
        assert!((parse(Kind::Speed, "20 krpm").unwrap() - w).abs() < 1e-9);
        assert!(close(parse(Kind::Speed, "100 rad/s").unwrap(), 100.0));
    }

    #[test]
    fn bandwidth_in_hertz_is_taken_as_two_pi_f() {
        assert!(close(parse(Kind::AngularFrequency, "100 rad/s").unwrap(), 100.0));
        let w = parse(Kind::AngularFrequency, "1 kHz").unwrap();
        assert!((w - 6_283.185_307_179_586).abs() < 1e-9);
    }

    #[test]
    fn motor_constants_in_datasheet_units() {
        assert!(close(parse(Kind::TorqueConstant, "0.492 N·m/A").unwrap(), 0.492));
        assert!(close(parse(Kind::TorqueConstant, "0.492 Nm/A").unwrap(), 0.492));
        assert!(close(parse(Kind::BackEmfConstant, "0.296 V·s/rad").unwrap(), 0.296));
        // 31 V/krpm = 31 V / (1000·π/30 rad/s) = 0.296028 V·s/rad (hand calculation).
        let k = parse(Kind::BackEmfConstant, "31 V/krpm").unwrap();
        assert!((k - 0.296_028_194_6).abs() < 1e-9, "{k}");
    }

    /// The forms datasheets print, each converted by hand:
    /// 36.9 mN·m/A = 0.0369 N·m/A; 259 rpm/V = 259·π/30 = 27.1224 rad/s per V;
    /// 181 g·cm² = 181·1e-3 kg·1e-4 m² = 1.81e-5 kg·m²; 2.56 kg·cm² = 2.56e-4 kg·m²;
    /// 50 N·cm/A = 0.5 N·m/A; 31 V/1000 rpm = 31 V/krpm = 0.296028 V·s/rad;
    /// 1 rad/s/V = 1 rad/s per V; 84.3 mNm = 0.0843 N·m.
    #[test]
    fn datasheet_compound_units() {
        assert!(close(parse(Kind::TorqueConstant, "36.9 mN·m/A").unwrap(), 0.0369));
        assert!(close(parse(Kind::TorqueConstant, "36.9 mNm/A").unwrap(), 0.0369));
        assert!(close(parse(Kind::TorqueConstant, "50 N·cm/A").unwrap(), 0.5));
        assert!(close(parse(Kind::TorqueConstant, "0.5 N·m/mA").unwrap(), 500.0));
        let kn = parse(Kind::SpeedConstant, "259 rpm/V").unwrap();
        assert!((kn - 27.122_417_1).abs() < 1e-6, "{kn}");
        assert!(close(parse(Kind::SpeedConstant, "0.259 krpm/V").unwrap(), kn));
        assert!(close(parse(Kind::SpeedConstant, "27 rad/s/V").unwrap(), 27.0));
        assert!(close(parse(Kind::SpeedConstant, "27 (rad/s)/V").unwrap(), 27.0));
        assert!(close(parse(Kind::Inertia, "181 g·cm²").unwrap(), 1.81e-5));
        assert!(close(parse(Kind::Inertia, "181 gcm²").unwrap(), 1.81e-5));
        assert!(close(parse(Kind::Inertia, "181 g cm^2").unwrap(), 1.81e-5));
        assert!(close(parse(Kind::Inertia, "2.56 kg·cm²").unwrap(), 2.56e-4));
        assert!(close(parse(Kind::Inertia, "0.01 kg·m²").unwrap(), 0.01));
        let ke = parse(Kind::BackEmfConstant, "31 V/1000 rpm").unwrap();
        assert!((ke - 0.296_028_194_6).abs() < 1e-9, "{ke}");
        assert!(close(parse(Kind::BackEmfConstant, "31 V/krpm").unwrap(), ke));
        assert!(close(parse(Kind::Torque, "84.3 mNm").unwrap(), 0.0843));
        assert!(close(parse(Kind::Torque, "84.3 mN·m").unwrap(), 0.0843));
        // Wrong dimension on either side is refused.
        assert!(parse(Kind::TorqueConstant, "36.9 mN·m/V").is_err());
        assert!(parse(Kind::SpeedConstant, "259 rpm/A").is_err());
        assert!(parse(Kind::Inertia, "181 g·cm").is_err());
        assert!(parse(Kind::TorqueConstant, "36.9 mN·m/0 A").is_err());
    }

    #[test]
    fn refuses_wrong_dimension_missing_unit_and_non_finite() {
        assert!(
            parse(Kind::Inductance, "0.393 mA")
                .unwrap_err()
                .problem
                .contains("not an inductance")
        );
        assert!(
            parse(Kind::Inductance, "0.393")
                .unwrap_err()
                .problem
                .contains("no unit")
        );
        assert!(
            parse(Kind::Inductance, "NaN mH")
                .unwrap_err()
                .problem
                .contains("finite")
        );
        assert!(
            parse(Kind::Inductance, "inf mH")
                .unwrap_err()
                .problem
                .contains("finite")
        );
        assert!(
            parse(Kind::Inductance, "1e999 mH")
                .unwrap_err()
                .problem
                .contains("finite")
        );
        assert!(parse(Kind::Inductance, "mH").is_err());
        assert!(parse(Kind::AngularFrequency, "100 rpm").is_err());
        assert!(parse(Kind::Decibel, "40").is_err());
    }
}
