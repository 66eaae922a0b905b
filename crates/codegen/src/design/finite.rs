//! The last gate before anything is written or printed: every number of the [`Design`] is
//! finite, in f64 and in the firmware's f32. `serde_json` writes NaN and ±∞ as `null` without a word, and a template prints
//! them as `NaN`/`inf` in generated code (issue 18), so the whole design is walked in its
//! serialised form — the same form the JSON and the templates see — and the first
//! non-finite number is an error naming its JSON path (e.g. `current_loop.d.kp`) and the
//! spec keys that decide that section, located at the first of them. `null` stays allowed:
//! it is an absent optional value (an `Option` that is `None`), never a number.

use std::ops::Range;

use minijinja::value::{Value, ValueKind};

use super::Design;
use crate::diagnostic::{Diagnostic, Source};
use crate::spec::Spec;

/// Finite in f64 and in f32: the firmware's constants are f32, where |x| > f32::MAX is ∞
/// (a field-weakening gain of 1e300 was written as `f32 = inf`, issue 18).
pub fn representable(x: f64) -> bool {
    x.is_finite() && x.abs() <= f32::MAX as f64
}

/// The first number in `value` that is not [`representable`], as (JSON path, value).
pub fn first_non_finite(value: &Value) -> Option<(String, f64)> {
    let mut path = String::new();
    walk(value, &mut path)
}

fn walk(value: &Value, path: &mut String) -> Option<(String, f64)> {
    match value.kind() {
        ValueKind::Number => {
            let x = f64::try_from(value.clone()).ok()?;
            (!representable(x)).then(|| (path.clone(), x))
        }
        ValueKind::Seq | ValueKind::Iterable => {
            for (i, item) in value.try_iter().ok()?.enumerate() {
                let len = path.len();
                path.push_str(&format!("[{i}]"));
                let found = walk(&item, path);
                path.truncate(len);
                if found.is_some() {
                    return found;
                }
            }
            None
        }
        ValueKind::Map => {
            for key in value.try_iter().ok()? {
                let item = value.get_item(&key).ok()?;
                let len = path.len();
                if !path.is_empty() {
                    path.push('.');
                }
                path.push_str(&key.to_string());
                let found = walk(&item, path);
                path.truncate(len);
                if found.is_some() {
                    return found;
                }
            }
            None
        }
        _ => None,
    }
}

/// The board keys that decide the board section's value at `path` (a JSON path below
/// `board`), the first the one an error is located at; the sensing keys when the path
/// is not one of the listed results.
pub fn deciding_board_keys(path: &str) -> Vec<&'static str> {
    let leaf = path.rsplit('.').next().unwrap_or(path);
    match leaf {
        "dc_link_volts_per_lsb" | "dc_link_full_scale_v" | "dc_link_divider" => {
            vec!["sensing.dc_link_divider", "sensing.adc_reference"]
        }
        "can_bit_rate" | "bit_rate" => vec!["can.bit_rate"],
        "dead_time_ns" | "dead_time" => vec!["pwm.dead_time"],
        "over_speed_electrical_rad_s" | "over_speed" => vec!["protection.over_speed"],
        "conversion_time_s" => vec!["sensing.sampling_cycles", "sensing.adc_reference"],
        _ => vec![
            "sensing.current_gain",
            "sensing.current_offset",
            "sensing.adc_reference",
        ],
    }
}

/// The spec keys that decide the design section `section` (the first segment of a JSON
/// path), and the span to report at.
fn deciding(spec: &Spec, section: &str) -> (&'static str, Range<usize>) {
    let m = &spec.motor;
    let d = &spec.drive;
    match section {
        "current_loop" => (
            "current_loop.bandwidth, motor.*.phase_resistance, motor.*.inductance, drive.switching_frequency",
            spec.current_loop.bandwidth.span.clone(),
        ),
        "angle_observer" => (
            "angle_observer.natural_frequency, angle_observer.damping, drive.switching_frequency",
            spec.angle_observer.natural_frequency.span.clone(),
        ),
        "drive" | "modulation" => (
            "drive.switching_frequency, drive.dc_link_voltage, drive.dc_link_voltage_min, motor.*.max_speed",
            d.dc_link_voltage.span.clone(),
        ),
        "scaling" => (
            "motor.*.peak_current, motor.*.max_speed, scaling.margin, drive.dc_link_voltage",
            m.peak_current.span.clone(),
        ),
        "fir" => (
            "fir.pass_edge, fir.stop_edge, fir.pass_ripple, fir.order / fir.stop_attenuation, drive.switching_frequency",
            spec.fir.span.clone(),
        ),
        "adc" => (
            "[adc], drive.switching_frequency, motor.*.phase_resistance, motor.*.inductance",
            spec.adc
                .as_ref()
                .map_or(d.switching_frequency.span.clone(), |a| a.clock.span.clone()),
        ),
        "per_unit" | "field_weakening" | "sensorless" => (
            "motor.*.peak_current, motor.*.nominal_current, motor.*.flux_linkage (or K_t, K_e), motor.*.inductance, motor.*.max_speed, drive.dc_link_voltage_min",
            m.peak_current.span.clone(),
        ),
        _ => (
            "[motor] (phase_resistance, inductance, flux linkage, currents, speeds)",
            m.span.clone(),
        ),
    }
}

/// `Err` with the first non-finite number of `design`, located at the spec key that decides it.
pub fn check(design: &Design, spec: &Spec, src: Source<'_>) -> Result<(), Box<Diagnostic>> {
    let Some((path, x)) = first_non_finite(&Value::from(minijinja::value::Serde(design))) else {
        return Ok(());
    };
    let section = path.split(['.', '[']).next().unwrap_or("");
    let (keys, span) = deciding(spec, section);
    Err(Box::new(src.error(
        span,
        keys.split(", ").next().unwrap_or(""),
        format!("the design's `{path}` comes out as {x:e}, not a finite number in f64 and in the firmware's f32 (|x| ≤ 3.4e38): these inputs overflow or underflow its formula (decided by {keys})"),
        "values in their physically sensible ranges (`motorgen new` writes a commented example); the design never writes a non-finite number",
    )))
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde::Serialize;

    #[derive(Serialize)]
    struct Inner {
        kp: f64,
        gains: Vec<f64>,
        optional: Option<f64>,
    }

    #[derive(Serialize)]
    struct Outer {
        name: String,
        d: Inner,
    }

    /// NaN and ±∞ are found by path wherever they sit; `None` (JSON null) is not a number.
    #[test]
    fn finds_non_finite_numbers_by_path() {
        let ok = Outer {
            name: "x".into(),
            d: Inner {
                kp: 1.0,
                gains: vec![1.0, 2.0],
                optional: None,
            },
        };
        assert_eq!(first_non_finite(&Value::from(minijinja::value::Serde(&ok))), None);
        let nan = Outer {
            d: Inner { kp: f64::NAN, ..ok.d },
            ..ok
        };
        let (path, x) = first_non_finite(&Value::from(minijinja::value::Serde(&nan))).unwrap();
        assert_eq!(path, "d.kp");
        assert!(x.is_nan());
        let inf = Outer {
            name: "y".into(),
            d: Inner {
                kp: 1.0,
                gains: vec![1.0, f64::NEG_INFINITY],
                optional: Some(f64::INFINITY),
            },
        };
        assert_eq!(
            first_non_finite(&Value::from(minijinja::value::Serde(&inf))),
            Some(("d.gains[1]".to_string(), f64::NEG_INFINITY))
        );
        // Finite in f64 but ∞ as the firmware's f32 (3.4028235e38 is f32::MAX).
        let big = Outer {
            name: "z".into(),
            d: Inner {
                kp: 3.5e38,
                gains: vec![3.4e38],
                optional: None,
            },
        };
        assert_eq!(
            first_non_finite(&Value::from(minijinja::value::Serde(&big))),
            Some(("d.kp".to_string(), 3.5e38))
        );
    }
}
