//! `[sensorless]`: inputs of the sensorless estimator design rules (thesis B chapter 4,
//! Table 4.1). The section is optional: the estimator is designed, emitted and verified
//! only for a spec that has it (a drive with a resolver or encoder has no estimator).
//! Every key is optional or has a documented default taken from the thesis.

use super::raw::{RawSpec, Val};
use super::{Param, Provenance, ResolveContext};
use crate::units::Kind;

/// Allowed transient angle error θ̃ when `sensorless.max_angle_error` is not given:
/// 10° (thesis B §4.4.2, "allowing for an angular error of 10°").
pub const DEFAULT_ANGLE_ERROR_DEG: f64 = 10.0;
/// R̃_s/R_s for ω_min2 (4.69) when `sensorless.resistance_error` is not given: thesis B
/// §4.4.2 assumes R̃_s = 2R_s.
pub const DEFAULT_RESISTANCE_ERROR: f64 = 2.0;

/// The resolved `[sensorless]` inputs (all SI; angles in rad, speeds electrical where
/// the design says so).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SensorlessSpec {
    /// Span of the `[sensorless]` section, for rules that no single key decides.
    pub span: std::ops::Range<usize>,
    /// ρ [rad/s], if given.
    pub bandwidth: Option<Param>,
    /// Largest shaft acceleration [rad/s², mechanical], if given.
    pub max_acceleration: Option<Param>,
    /// θ̃_max \[rad\] (default 10°).
    pub max_angle_error: Option<Param>,
    /// ω_e [rad/s], if given.
    pub injection_frequency: Option<Param>,
    /// V_e \[V\], if given.
    pub injection_voltage: Option<Param>,
    /// ω_hp [rad/s], if given.
    pub highpass: Option<Param>,
    /// ω_lp [rad/s], if given.
    pub lowpass: Option<Param>,
    /// R̃_s/R_s (default 2).
    pub resistance_error: Option<Param>,
    /// ω_ν [rad/s], if given.
    pub speed_noise: Option<Param>,
}

impl ResolveContext<'_> {
    /// `Some(None)` without the section, `None` when a key is bad.
    pub(super) fn sensorless(&mut self, raw: &RawSpec) -> Option<Option<SensorlessSpec>> {
        let Some(section) = raw.sensorless.as_ref() else {
            return Some(None);
        };
        let s = section.get_ref();
        let q = |r: &mut Self, key: &str, v: &Option<Val>, kind: Kind| r.opt_quantity(key, v.as_ref(), kind, true);
        let bandwidth = q(self, "sensorless.bandwidth", &s.bandwidth, Kind::AngularFrequency);
        let max_acceleration = q(
            self,
            "sensorless.max_acceleration",
            &s.max_acceleration,
            Kind::AngularAcceleration,
        );
        if let (Some(b), Some(_)) = (&s.bandwidth, &s.max_acceleration) {
            self.err(
                b.span(),
                "sensorless.bandwidth",
                "both bandwidth (ρ) and max_acceleration are given; ρ follows from max_acceleration by thesis B (4.74)",
                "one of them: bandwidth = \"120 rad/s\" (ρ directly) or max_acceleration = \"5000 rpm/s\" (ρ = √(|ω̇_r|max / sin θ̃max))",
            );
        }
        let max_angle_error = q(self, "sensorless.max_angle_error", &s.max_angle_error, Kind::Angle);
        if let (Some(p), Some(v)) = (&max_angle_error, &s.max_angle_error)
            && p.value >= std::f64::consts::FRAC_PI_2
        {
            self.err(
                v.span(),
                "sensorless.max_angle_error",
                "an angle error of 90° or more leaves no field orientation to speak of",
                "an angle above 0° and below 90°, e.g. \"10 °\" (thesis B §4.4.2)",
            );
        }
        let injection_frequency = q(
            self,
            "sensorless.injection_frequency",
            &s.injection_frequency,
            Kind::AngularFrequency,
        );
        let injection_voltage = q(
            self,
            "sensorless.injection_voltage",
            &s.injection_voltage,
            Kind::Voltage,
        );
        let highpass = q(self, "sensorless.highpass", &s.highpass, Kind::AngularFrequency);
        let lowpass = q(self, "sensorless.lowpass", &s.lowpass, Kind::AngularFrequency);
        let speed_noise = q(self, "sensorless.speed_noise", &s.speed_noise, Kind::AngularFrequency);
        let resistance_error = s.resistance_error.as_ref().and_then(|v| {
            self.number(
                "sensorless.resistance_error",
                v,
                0.0,
                100.0,
                "a ratio R̃_s/R_s above 0 and below 100, e.g. 2 (thesis B §4.4.2 assumes R̃_s = 2R_s)",
            )
        });
        Some(Some(SensorlessSpec {
            span: section.span(),
            bandwidth,
            max_acceleration,
            max_angle_error: max_angle_error.filter(|p| p.value < std::f64::consts::FRAC_PI_2),
            injection_frequency,
            injection_voltage,
            highpass,
            lowpass,
            resistance_error,
            speed_noise,
        }))
    }
}

/// θ̃_max \[rad\] of the spec, or the default 10°.
pub fn angle_error_rad(s: &SensorlessSpec) -> (f64, Provenance) {
    s.max_angle_error
        .as_ref()
        .map_or((DEFAULT_ANGLE_ERROR_DEG.to_radians(), Provenance::Default), |p| {
            (p.value, p.source)
        })
}
