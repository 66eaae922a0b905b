//! `[motor]`: pole pairs, `[motor.datasheet]` merged with `[motor.identified]` key by key
//! (identified wins), harmonics (thesis B 2.14–2.16, 2.23) and the L_q saturation curve.
//! The inductances and ψ_M have their own modules ([`super::inductance`],
//! [`super::flux_linkage`]).

use std::ops::Range;

use super::flux_linkage::FluxSource;
use super::raw::{Connection, RawHarmonics, RawMotor, RawParams, RawSpec, Val};
use super::resolve::ResolveContext;
use super::{Param, Provenance};
use crate::units::Kind;

/// Optional harmonic data (thesis B 2.14–2.16, 2.23), SI.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Harmonics {
    /// ψ_d,6 \[Wb\].
    pub d_flux_6: Option<Param>,
    /// ψ_d,12 \[Wb\].
    pub d_flux_12: Option<Param>,
    /// ψ_q,6 \[Wb\].
    pub q_flux_6: Option<Param>,
    /// ψ_q,12 \[Wb\].
    pub q_flux_12: Option<Param>,
    /// L_6 \[H\].
    pub inductance_6: Option<Param>,
}

/// The resolved motor.
#[derive(Debug, Clone, PartialEq)]
pub struct Motor {
    /// n_p.
    pub pole_pairs: u32,
    /// R_s \[Ω\].
    pub phase_resistance: Param,
    /// L_d \[H\].
    pub d_inductance: Param,
    /// L_q \[H\].
    pub q_inductance: Param,
    /// ψ_M \[Wb\], if known or derivable.
    pub flux_linkage: Option<Param>,
    /// Every form in which the spec gives ψ_M (directly, K_t, K_e, k_n), for the cross-check.
    pub flux_sources: Vec<FluxSource>,
    /// Rated current, rms \[A\].
    pub nominal_current: Option<Param>,
    /// Peak current, rms \[A\].
    pub peak_current: Param,
    /// Maximum mechanical speed [rad/s].
    pub max_speed: Param,
    /// Rated torque [N·m].
    pub nominal_torque: Option<Param>,
    /// Peak torque [N·m].
    pub peak_torque: Option<Param>,
    /// Rated electrical frequency f_n \[Hz\] (given, or from the nominal speed).
    pub rated_frequency: Option<Param>,
    /// Nominal shaft speed [rad/s], if given (f_n comes from it when `rated_frequency` is not).
    pub nominal_speed: Option<Param>,
    /// Rated power \[W\].
    pub rated_power: Option<Param>,
    /// Rotor inertia J [kg·m²].
    pub inertia: Option<Param>,
    /// Viscous friction b [N·m·s/rad].
    pub viscous_friction: Option<Param>,
    /// Harmonic data.
    pub harmonics: Harmonics,
    /// L_q(|i_q|) curve points (\[A\], \[H\]), sorted by current.
    pub q_saturation: Vec<(f64, f64)>,
    /// Winding connection, if stated.
    pub connection: Option<Connection>,
    /// When and from what the identified values were obtained (`date`, `source`).
    pub identification: Option<String>,
    /// Byte span of the `[motor]` table: where a missing motor key is reported.
    pub span: Range<usize>,
}

/// "identified on <date> from <source>", from `[motor.identified]`'s `date` and `source`.
fn identification(m: &RawMotor) -> Option<String> {
    let p = m.identified.as_ref()?.get_ref();
    let text = |v: &toml::Value| match v {
        toml::Value::String(s) => s.clone(),
        other => other.to_string(),
    };
    match (p.date.as_ref().map(text), p.source.as_ref().map(text)) {
        (None, None) => None,
        (d, s) => Some(format!(
            "identified{}{}",
            d.map_or(String::new(), |d| format!(" on {d}")),
            s.map_or(String::new(), |s| format!(" from {s}"))
        )),
    }
}

impl ResolveContext<'_> {
    pub(super) fn motor(&mut self, raw: &RawSpec) -> Option<Motor> {
        let m = raw.motor.get_ref();
        let motor_span = raw.motor.span();
        let pole_pairs = self
            .integer(
                "motor.pole_pairs",
                &m.pole_pairs,
                1,
                64,
                "a whole number of pole pairs from 1 to 64, e.g. 4",
            )
            .map(|(i, _)| i as u32);
        if m.datasheet.is_none() && m.identified.is_none() {
            self.err(motor_span.clone(), "motor", "neither [motor.datasheet] nor [motor.identified] is given", "at least one of the two sections with phase_resistance, inductance (or d_/q_inductance), peak_current and max_speed");
            return None;
        }
        self.inductance_forms(m);
        let phase_resistance =
            self.phase_motor_key(m, "phase_resistance", |p| p.phase_resistance.as_ref(), Kind::Resistance);
        if phase_resistance.is_none() && !has(m, |p| p.phase_resistance.is_some()) {
            self.missing_motor_key(
                &motor_span,
                "phase_resistance",
                "the phase (star-equivalent) resistance, e.g. phase_resistance = \"0.126 Ω\", or a terminal value { value = \"0.252 Ω\", measured = \"line_to_line\" }",
            );
        }
        let d_inductance = self.inductance(m, true);
        let q_inductance = self.inductance(m, false);
        if d_inductance.is_none() && !has(m, |p| p.inductance.is_some() || p.d_inductance.is_some()) {
            self.missing_motor_key(
                &motor_span,
                "inductance",
                "inductance = \"0.393 mH\" (L_d = L_q) or d_inductance and q_inductance",
            );
        }
        let peak_current = self.required_motor_key(
            m,
            &motor_span,
            "peak_current",
            |p| p.peak_current.as_ref(),
            Kind::Current,
            "the peak phase current (rms), e.g. peak_current = \"61 A\"; it sets the current full scale",
        );
        let max_speed = self.required_motor_key(
            m,
            &motor_span,
            "max_speed",
            |p| p.max_speed.as_ref(),
            Kind::Speed,
            "the maximum shaft speed, e.g. max_speed = \"20000 rpm\"; it sets f_e,max (1.1)",
        );
        let nominal_current = self.motor_key(
            m,
            "nominal_current",
            |p| p.nominal_current.as_ref(),
            Kind::Current,
            true,
        );
        let nominal_torque = self.motor_key(m, "nominal_torque", |p| p.nominal_torque.as_ref(), Kind::Torque, true);
        let peak_torque = self.motor_key(m, "peak_torque", |p| p.peak_torque.as_ref(), Kind::Torque, true);
        let rated_power = self.motor_key(m, "rated_power", |p| p.rated_power.as_ref(), Kind::Power, true);
        let inertia = self.motor_key(m, "inertia", |p| p.inertia.as_ref(), Kind::Inertia, true);
        let viscous_friction = self.motor_key(
            m,
            "viscous_friction",
            |p| p.viscous_friction.as_ref(),
            Kind::ViscousFriction,
            true,
        );
        let nominal_speed = self.motor_key(m, "nominal_speed", |p| p.nominal_speed.as_ref(), Kind::Speed, true);
        let rated_frequency = self.rated_frequency(m, pole_pairs, nominal_speed.as_ref());
        let (flux_linkage, flux_sources) = match pole_pairs {
            Some(np) => self.flux(m, np),
            None => (None, Vec::new()),
        };
        let harmonics = m.harmonics.as_ref().map(|h| self.harmonics(h.get_ref()));
        let q_saturation = self.saturation(m);
        Some(Motor {
            span: motor_span,
            connection: m.connection.as_ref().map(|c| *c.get_ref()),
            identification: identification(m),
            pole_pairs: pole_pairs?,
            phase_resistance: phase_resistance?,
            d_inductance: d_inductance?,
            q_inductance: q_inductance?,
            flux_linkage,
            flux_sources,
            nominal_current,
            peak_current: peak_current?,
            max_speed: max_speed?,
            nominal_torque,
            peak_torque,
            rated_frequency,
            nominal_speed,
            rated_power,
            inertia,
            viscous_friction,
            harmonics: harmonics.unwrap_or_default(),
            q_saturation,
        })
    }

    /// The value of one motor key: identified over datasheet.
    pub(super) fn motor_key(
        &mut self,
        raw: &RawMotor,
        field: &str,
        pick: fn(&RawParams) -> Option<&Val>,
        kind: Kind,
        positive: bool,
    ) -> Option<Param> {
        for (section, prov) in [
            (&raw.identified, Provenance::Identified),
            (&raw.datasheet, Provenance::Datasheet),
        ] {
            if let Some(v) = section.as_ref().and_then(|s| pick(s.get_ref())) {
                let sect = if prov == Provenance::Identified {
                    "identified"
                } else {
                    "datasheet"
                };
                return self.quantity(&format!("motor.{sect}.{field}"), v, kind, prov, positive);
            }
        }
        None
    }

    /// A required positive motor key; reports it missing (at the `[motor]` table) when
    /// neither section has it.
    fn required_motor_key(
        &mut self,
        m: &RawMotor,
        motor_span: &Range<usize>,
        field: &str,
        pick: fn(&RawParams) -> Option<&Val>,
        kind: Kind,
        what: &str,
    ) -> Option<Param> {
        let value = self.motor_key(m, field, pick, kind, true);
        if value.is_none() && !has(m, |p| pick(p).is_some()) {
            self.missing_motor_key(motor_span, field, what);
        }
        value
    }

    fn missing_motor_key(&mut self, motor_span: &Range<usize>, key: &str, what: &str) {
        self.err(
            motor_span.clone(),
            &format!("motor.datasheet.{key}"),
            format!("missing required key `{key}` in [motor.datasheet] or [motor.identified]"),
            what.to_string(),
        );
    }

    /// f_n: given, or n_p·ω_m,n/(2π) (2.19) from the nominal speed.
    fn rated_frequency(
        &mut self,
        m: &RawMotor,
        pole_pairs: Option<u32>,
        nominal_speed: Option<&Param>,
    ) -> Option<Param> {
        let rated_frequency = self.motor_key(
            m,
            "rated_frequency",
            |p| p.rated_frequency.as_ref(),
            Kind::Frequency,
            true,
        );
        match (rated_frequency, nominal_speed, pole_pairs) {
            (Some(f), _, _) => Some(f),
            (None, Some(n), Some(np)) => Some(Param {
                value: n.value * np as f64 / (2.0 * std::f64::consts::PI),
                source: Provenance::Derived,
                key: "motor.rated_frequency".into(),
                span: n.span.clone(),
                note: Some(format!("f_n = n_p·ω_m,n/(2π) (2.19) from {}", n.key)),
            }),
            _ => None,
        }
    }

    fn harmonics(&mut self, h: &RawHarmonics) -> Harmonics {
        let flux = |r: &mut Self, key: &str, v: &Option<Val>| r.opt_quantity(key, v.as_ref(), Kind::FluxLinkage, false);
        Harmonics {
            d_flux_6: flux(self, "motor.harmonics.d_flux_6", &h.d_flux_6),
            d_flux_12: flux(self, "motor.harmonics.d_flux_12", &h.d_flux_12),
            q_flux_6: flux(self, "motor.harmonics.q_flux_6", &h.q_flux_6),
            q_flux_12: flux(self, "motor.harmonics.q_flux_12", &h.q_flux_12),
            inductance_6: self.opt_quantity(
                "motor.harmonics.inductance_6",
                h.inductance_6.as_ref(),
                Kind::Inductance,
                false,
            ),
        }
    }

    fn saturation(&mut self, m: &RawMotor) -> Vec<(f64, f64)> {
        let Some(s) = &m.saturation else { return Vec::new() };
        let mut points = Vec::new();
        let mut last = -1.0;
        for (i, p) in s.get_ref().q_inductance.iter().enumerate() {
            let key = format!("motor.saturation.q_inductance[{i}]");
            let c = self.quantity(
                &format!("{key}.current"),
                &p.get_ref().current,
                Kind::Current,
                Provenance::Datasheet,
                false,
            );
            let l = self.quantity(
                &format!("{key}.inductance"),
                &p.get_ref().inductance,
                Kind::Inductance,
                Provenance::Datasheet,
                true,
            );
            if let (Some(c), Some(l)) = (c, l) {
                if c.value < 0.0 || c.value <= last {
                    self.err(
                        p.span(),
                        &key,
                        "curve points must have increasing, non-negative currents",
                        "points ordered by |i_q| from 0 A upwards",
                    );
                }
                last = c.value;
                points.push((c.value, l.value));
            }
        }
        points
    }
}

/// Whether either motor section satisfies `f`.
fn has(m: &RawMotor, f: impl Fn(&RawParams) -> bool) -> bool {
    [&m.identified, &m.datasheet]
        .into_iter()
        .flatten()
        .any(|s| f(s.get_ref()))
}
