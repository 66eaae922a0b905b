//! `[current_sensing]`: what turns a phase current into the voltage at its ADC pin, and
//! the signed gain that follows from it.
//!
//! Sign convention (the control core's, thesis A (2.7)): a phase current is positive
//! when it flows out of the inverter leg into the motor terminal.
//!
//! * **Low-side shunt** (between the low-side switch's source and ground): the phase
//!   current is measured while the low side conducts; a positive current then flows from
//!   ground up through the shunt into the leg, so the shunt's leg-side terminal sits at
//!   −R·i against ground. NuttX's `stm32_ihm08m1.c` gives the X-NUCLEO-IHM08M1's stage as
//!   "−5.18 (inverted current)" for this reason.
//! * **In-line shunt** (between the leg and the motor terminal): leg side minus motor
//!   side is +R·i.
//! * **DC-link shunt**: one shunt for all three phases; the firmware does not reconstruct
//!   the phase currents from it (refused).
//! * **Hall sensor**: its sensitivity times the sign of how its positive direction is
//!   mounted.
//!
//! The amplifier gain is from the shunt voltage so defined (leg-side terminal minus the
//! other) to the ADC pin: positive for a non-inverting stage, negative for an inverting
//! one. The signed gain at the pin is then gain·R·(−1 low side, +1 in-line), or
//! ±sensitivity.

use std::ops::Range;

use serde::Serialize;
use serde_spanned::Spanned;

use super::raw::{Direction, Placement, RawCurrentSensing, SampleInstant, SensorKind};
use crate::spec::{Param, Provenance, ResolveContext, Val};
use crate::units::Kind;

/// The resolved current sensing.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CurrentSensing {
    /// Shunt or Hall sensor.
    pub kind: SensorKind,
    /// Where the shunt sits (shunts only).
    pub placement: Option<Placement>,
    /// Shunt resistance \[Ω\] (shunts only).
    pub shunt_ohm: Option<f64>,
    /// Amplifier gain from the shunt voltage to the pin \[V/V\], signed (shunts only).
    pub amplifier_gain: Option<f64>,
    /// A Hall sensor's sensitivity \[V/A\] and mounting (Hall sensors only).
    pub sensitivity_v_per_a: Option<f64>,
    /// How a Hall sensor's positive direction is mounted.
    pub direction: Option<Direction>,
    /// Signed gain at the ADC pin \[V/A\]: d(V_pin)/d(i_phase), i positive out of the leg.
    pub gain_v_per_a: f64,
    /// ADC-pin voltage at zero current \[V\].
    pub offset_v: f64,
    /// Time the pin's signal needs after a switching edge of its leg before it reads the
    /// phase current (`current_sensing.settling_time`) \[s\]: the amplifier's settling and
    /// the edge's ringing. Required for low-side shunts, whose window it narrows
    /// (`design::duty_limit`); `None` where the board file does not state it.
    pub settling_time_s: Option<f64>,
}

/// What the sign of a low-side or in-line shunt's voltage is for a positive phase current.
pub fn shunt_sign(placement: Placement) -> f64 {
    match placement {
        Placement::LowSide => -1.0,
        Placement::Inline | Placement::DcLink => 1.0,
    }
}

/// A key that belongs to the other kind of sensor.
fn foreign(cx: &mut ResolveContext<'_>, v: Option<Range<usize>>, key: &str, kind: &str, instead: &str) {
    if let Some(span) = v {
        cx.err(
            span,
            key,
            format!("`{key}` describes a {kind}, but `current_sensing.kind` says otherwise"),
            instead.to_string(),
        );
    }
}

fn required<'v>(
    cx: &mut ResolveContext<'_>,
    v: Option<&'v Val>,
    section: Range<usize>,
    key: &str,
    what: &str,
) -> Option<&'v Val> {
    if v.is_none() {
        cx.err(section, key, format!("missing `{key}`: {what}"), what.to_string());
    }
    v
}

/// Resolves `[current_sensing]` against the ADC reference `vref` and the board's sampling
/// instant.
pub(super) fn resolve(
    cx: &mut ResolveContext<'_>,
    raw: &Spanned<RawCurrentSensing>,
    vref: Option<&Param>,
    sample_instant: &Spanned<SampleInstant>,
    spans: &mut Vec<(String, Range<usize>)>,
) -> Option<CurrentSensing> {
    let c = raw.get_ref();
    let section = raw.span();
    let kind = *c.kind.get_ref();
    spans.push(("current_sensing.kind".into(), c.kind.span()));
    spans.push(("current_sensing.offset".into(), c.offset.span()));
    let offset = cx.quantity(
        "current_sensing.offset",
        &c.offset,
        Kind::Voltage,
        Provenance::Datasheet,
        false,
    );
    if let (Some(o), Some(v)) = (&offset, vref)
        && !(o.value > 0.0 && o.value < v.value)
    {
        cx.err(o.span.clone(), "current_sensing.offset", format!("the zero-current level {} V is not inside the ADC range 0 … {} V: one current direction could not be measured", o.value, v.value), "the sensor output at 0 A, between 0 V and the ADC reference (bipolar phase currents), e.g. half the reference");
    }
    let settling = c.settling_time.as_ref().and_then(|v| {
        spans.push(("current_sensing.settling_time".into(), v.span()));
        cx.quantity(
            "current_sensing.settling_time",
            v,
            Kind::Time,
            Provenance::Datasheet,
            false,
        )
    });
    if let Some(t) = &settling
        && !(t.value >= 0.0 && t.value < 100e-6)
    {
        cx.err(
            t.span.clone(),
            "current_sensing.settling_time",
            format!(
                "a settling time of {} s is not one a current-sensing stage has",
                t.value
            ),
            "a time from 0 up to below 100 µs, e.g. settling_time = \"1 µs\"",
        );
    }
    let settling_time_s = settling.map(|t| t.value);
    let out = match kind {
        SensorKind::Shunt => {
            foreign(
                cx,
                c.sensitivity.as_ref().map(Spanned::span),
                "current_sensing.sensitivity",
                "Hall sensor",
                "a shunt is described by placement, shunt and amplifier_gain",
            );
            foreign(
                cx,
                c.direction.as_ref().map(Spanned::span),
                "current_sensing.direction",
                "Hall sensor",
                "a shunt's sign follows from its placement and the amplifier gain's sign",
            );
            let placement = match &c.placement {
                Some(p) => {
                    spans.push(("current_sensing.placement".into(), p.span()));
                    Some((*p.get_ref(), p.span()))
                }
                None => {
                    cx.err(
                        section.clone(),
                        "current_sensing.placement",
                        "missing `current_sensing.placement`: a shunt's sign depends on where it sits",
                        "placement = \"low_side\" (between each low-side switch and ground) or \"inline\" (between the leg and the motor)",
                    );
                    None
                }
            };
            if let Some((Placement::DcLink, span)) = &placement {
                cx.err(
                    span.clone(),
                    "current_sensing.placement",
                    "a single DC-link shunt measures one phase current at a time; the firmware does not reconstruct the three phase currents from it",
                    "placement = \"low_side\" or \"inline\" (one shunt per phase)",
                );
            }
            if let Some((Placement::LowSide, _)) = &placement
                && *sample_instant.get_ref() != SampleInstant::LowSideCentre
            {
                cx.err(
                    sample_instant.span(),
                    "sensing.sample_instant",
                    "low-side shunts carry the phase current only while the low-side switch conducts, i.e. around the carrier maximum; sampling at the high-side centre reads zero",
                    "sample_instant = \"low_side_centre\"",
                );
            }
            let shunt = required(
                cx,
                c.shunt.as_ref(),
                section.clone(),
                "current_sensing.shunt",
                "the shunt resistance, e.g. shunt = \"10 mΩ\"",
            )
            .and_then(|v| {
                spans.push(("current_sensing.shunt".into(), v.span()));
                cx.quantity(
                    "current_sensing.shunt",
                    v,
                    Kind::Resistance,
                    Provenance::Datasheet,
                    true,
                )
            });
            let gain = required(cx, c.amplifier_gain.as_ref(), section.clone(), "current_sensing.amplifier_gain", "the amplifier's gain from the shunt voltage (its leg-side terminal minus the other) to the ADC pin, e.g. amplifier_gain = 5.18; negative for an inverting stage").and_then(|v| {
                spans.push(("current_sensing.amplifier_gain".into(), v.span()));
                let accepted = "a plain number between −1000 and 1000, not 0: the gain from the shunt voltage (leg-side terminal minus the other) to the ADC pin, negative for an inverting stage, e.g. 5.18";
                let g = match v.get_ref() {
                    toml::Value::Float(f) => Some(*f),
                    toml::Value::Integer(i) => Some(*i as f64),
                    _ => None,
                };
                match g {
                    Some(g) if g.is_finite() && g != 0.0 && g.abs() < 1000.0 => Some(g),
                    _ => {
                        cx.err(v.span(), "current_sensing.amplifier_gain", format!("{} is not an amplifier gain", v.get_ref()), accepted);
                        None
                    }
                }
            });
            if let Some((Placement::LowSide, _)) = &placement
                && c.settling_time.is_none()
            {
                cx.err(
                    section.clone(),
                    "current_sensing.settling_time",
                    "missing `current_sensing.settling_time`: a low-side shunt reads the phase current only once its stage has settled after the low-side switch turned on, and the maximum duty follows from that window",
                    "settling_time = \"1 µs\": the amplifier's settling to 12 bits plus the switching edge's ringing, from the stage's datasheet or a measurement",
                );
            }
            let (Some((placement, _)), Some(shunt), Some(gain), Some(offset)) = (placement, shunt, gain, offset) else {
                return None;
            };
            CurrentSensing {
                kind,
                placement: Some(placement),
                shunt_ohm: Some(shunt.value),
                amplifier_gain: Some(gain),
                sensitivity_v_per_a: None,
                direction: None,
                gain_v_per_a: gain * shunt.value * shunt_sign(placement),
                offset_v: offset.value,
                settling_time_s,
            }
        }
        SensorKind::Hall => {
            for (v, key) in [
                (c.placement.as_ref().map(Spanned::span), "current_sensing.placement"),
                (c.shunt.as_ref().map(Spanned::span), "current_sensing.shunt"),
                (
                    c.amplifier_gain.as_ref().map(Spanned::span),
                    "current_sensing.amplifier_gain",
                ),
            ] {
                foreign(
                    cx,
                    v,
                    key,
                    "shunt",
                    "a Hall sensor is described by sensitivity and direction",
                );
            }
            let sens = required(
                cx,
                c.sensitivity.as_ref(),
                section.clone(),
                "current_sensing.sensitivity",
                "the sensor's output per ampere at the ADC pin, e.g. sensitivity = \"15 mV/A\"",
            )
            .and_then(|v| {
                spans.push(("current_sensing.sensitivity".into(), v.span()));
                cx.quantity(
                    "current_sensing.sensitivity",
                    v,
                    Kind::Transresistance,
                    Provenance::Datasheet,
                    true,
                )
            });
            let direction = match &c.direction {
                Some(d) => {
                    spans.push(("current_sensing.direction".into(), d.span()));
                    Some(*d.get_ref())
                }
                None => {
                    cx.err(
                        section.clone(),
                        "current_sensing.direction",
                        "missing `current_sensing.direction`: the sign of the measurement depends on how the sensor is mounted",
                        "direction = \"leg_to_motor\" (the sensor's positive current flows out of the leg into the motor) or \"motor_to_leg\"",
                    );
                    None
                }
            };
            let (Some(sens), Some(direction), Some(offset)) = (sens, direction, offset) else {
                return None;
            };
            let sign = match direction {
                Direction::LegToMotor => 1.0,
                Direction::MotorToLeg => -1.0,
            };
            CurrentSensing {
                kind,
                placement: None,
                shunt_ohm: None,
                amplifier_gain: None,
                sensitivity_v_per_a: Some(sens.value),
                direction: Some(direction),
                gain_v_per_a: sign * sens.value,
                offset_v: offset.value,
                settling_time_s,
            }
        }
    };
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// X-NUCLEO-IHM08M1 by hand: 10 mΩ low-side shunts, non-inverting stage 5.18 →
    /// −0.0518 V/A at the pin (NuttX's board notes: "−5.18 (inverted current)"); the same
    /// shunt in line gives +0.0518 V/A.
    #[test]
    fn low_side_shunts_invert_the_sign() {
        assert!((5.18 * 0.010 * shunt_sign(Placement::LowSide) + 0.0518).abs() < 1e-12);
        assert!((5.18 * 0.010 * shunt_sign(Placement::Inline) - 0.0518).abs() < 1e-12);
    }
}
