//! Verification by simulation: the firmware's control step (`motor-control`,
//! [`ControllerConfig::process`] with [`motor_control::SoftTrig`]) configured from the
//! design, in closed loop with a discrete-time PMSM (thesis A (2.26), optionally with
//! thesis B's harmonics (2.14)–(2.16) and L_q saturation (2.25)), same sample period,
//! the design's loop delay (1.5·T_s, or the board's: `motor_sim::plant::Plant::loop_delay_periods`).
//!
//! [`SCENARIOS`] is the standard scenario set; each runs on a [`Setup`] and returns
//! measured vs designed figures with a pass/fail criterion. A new design rule adds its
//! scenario by appending to the list.
//!
//! | module | what |
//! |---|---|
//! | [`motor_sim::plant`] | PMSM dq model, inverter, sensors (shared with the control core's tests) |
//! | [`controller`] | [`ControllerConfig`] from a [`Design`] |
//! | [`motor_sim::bench`] | controller + plant with the thesis-A §4.6 timing |
//! | [`motor_sim::figures`] | rise time, overshoot, settling of sampled responses |
//! | [`figures`] | the designed responses they are compared with |
//! | [`scenarios`] | the current-loop scenarios and their criteria |
//! | [`observer`] | the angle-observer scenarios: lock, run-up at the drive's acceleration, type-2 lag |
//! | [`frequency`] | frequency responses of the discrete designs (for the report) |
//! | [`field_weakening`] | the torque stage (MTPA, field weakening, MTPV) up to `max_speed`, the torque–speed envelope (thesis B §2.3, Fig. 2.15) |
//! | [`estimator`] | sensorless estimator recovery, cycle slips (thesis B Figs. 4.17, 4.18) |
//! | [`report`] | the self-contained HTML report with SVG plots (`motorgen report`) |
//!
//! May depend on `codegen` (the design core), `motor-control` and `motor-sim`; never on
//! `motor-commission` or `motorgen` (ARCHITECTURE.md).

pub mod controller;
pub mod estimator;
pub mod field_weakening;
pub mod figures;
pub mod frequency;
pub mod observer;
pub mod report;
pub mod scenarios;

use std::fmt::Write as _;

use motor_control::step::ControllerConfig;
use serde::Serialize;

use codegen::design::Design;
use codegen::diagnostic::{Diagnostics, Source};
use codegen::spec::Spec;
use motor_sim::bench::Bench;
use motor_sim::plant::{MotorModel, Plant, Shaft, SpeedProfile};

/// One measured figure and its criterion.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Check {
    /// What is measured, e.g. "q-axis rise time 10–90 %".
    pub quantity: String,
    /// Measured value, in `unit`.
    pub measured: f64,
    /// Designed (predicted) value, in `unit`, where the design predicts one.
    pub designed: Option<f64>,
    /// The criterion's bound, in `unit`: the largest passing value of a "≤" criterion, the
    /// smallest of a "≥" one, the upper end of a band around the designed value; `None`
    /// where the criterion is not a bound on the measured value (a count that must be 0 is
    /// the bound 0).
    pub limit: Option<f64>,
    /// Display unit of `measured` and `designed`.
    pub unit: &'static str,
    /// The pass criterion in words, e.g. "within 10 % of designed".
    pub criterion: String,
    /// Whether the criterion holds.
    pub pass: bool,
}

/// One named signal over time.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Series {
    /// Legend label.
    pub label: String,
    /// Values at the trace's time points.
    pub values: Vec<f64>,
}

/// A labelled series.
pub(crate) fn series(label: &str, values: Vec<f64>) -> Series {
    Series {
        label: label.into(),
        values,
    }
}

/// Recorded signals of a scenario, for plots.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Trace {
    /// Plot title.
    pub title: String,
    /// y-axis label with unit.
    pub y_label: String,
    /// Time points \[ms\].
    pub t_ms: Vec<f64>,
    /// The signals.
    pub series: Vec<Series>,
}

/// The outcome of one scenario.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ScenarioResult {
    /// Stable identifier, e.g. `current_step`.
    pub id: &'static str,
    /// Human title with the operating point.
    pub title: String,
    /// Where the criterion comes from (thesis figures/equations).
    pub reference: &'static str,
    /// The figures.
    pub checks: Vec<Check>,
    /// Signals for the report.
    pub traces: Vec<Trace>,
    /// The speed the field-weakening ramp reached \[rpm\] (that scenario only).
    pub reached_speed_rpm: Option<f64>,
    /// The torque–speed curve with the designed envelope (the field-weakening scenario).
    pub torque_speed: Option<field_weakening::TorqueSpeed>,
}

impl ScenarioResult {
    /// Whether every check passed.
    pub fn passed(&self) -> bool {
        self.checks.iter().all(|c| c.pass)
    }
}

/// Everything [`verify`] found for one motor.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Verification {
    /// Motor name.
    pub motor: String,
    /// Spec file.
    pub spec_file: String,
    /// Whether the plant carried harmonic or saturation terms.
    pub plant_model: String,
    /// Results in [`SCENARIOS`] order.
    pub scenarios: Vec<ScenarioResult>,
}

impl Verification {
    /// Whether every scenario passed.
    pub fn passed(&self) -> bool {
        self.scenarios.iter().all(ScenarioResult::passed)
    }

    /// The pass/fail table as plain text.
    pub fn table(&self) -> String {
        let mut s = format!(
            "verify {} ({})\nplant: {}\n",
            self.spec_file, self.motor, self.plant_model
        );
        let rows: Vec<[String; 5]> = self
            .scenarios
            .iter()
            .flat_map(|sc| {
                sc.checks.iter().map(move |c| {
                    [
                        format!("{}: {}", sc.id, c.quantity),
                        format_value(c.measured, c.unit),
                        c.designed.map_or("—".into(), |d| format_value(d, c.unit)),
                        c.criterion.clone(),
                        if c.pass { "pass".into() } else { "FAIL".into() },
                    ]
                })
            })
            .collect();
        let head = ["check", "measured", "designed", "criterion", "result"];
        let width = |k: usize| {
            rows.iter()
                .map(|r| r[k].chars().count())
                .chain([head[k].len()])
                .max()
                .unwrap_or(0)
        };
        let w: Vec<usize> = (0..5).map(width).collect();
        let mut line = |cells: [&str; 5]| {
            let mut l = String::new();
            for (k, c) in cells.iter().enumerate() {
                let pad = w[k].saturating_sub(c.chars().count());
                let _ = write!(l, "{c}{}  ", " ".repeat(pad));
            }
            s.push_str(l.trim_end());
            s.push('\n');
        };
        line(head);
        for r in &rows {
            line([&r[0], &r[1], &r[2], &r[3], &r[4]]);
        }
        let failed = self.scenarios.iter().filter(|s| !s.passed()).count();
        let _ = writeln!(
            s,
            "{} of {} scenarios passed{}",
            self.scenarios.len() - failed,
            self.scenarios.len(),
            if failed == 0 { "" } else { " — FAILED" }
        );
        s
    }
}

/// One criterion in [`Verification::json`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CriterionJson {
    /// What is measured ([`Check::quantity`]).
    pub name: String,
    /// The measured value, in `unit` (null if not finite).
    pub measured: f64,
    /// The designed value, in `unit`, if the design predicts one.
    pub designed: Option<f64>,
    /// The criterion's bound (`Check::limit`).
    pub limit: Option<f64>,
    /// Unit of `measured`, `designed`, `limit`.
    pub unit: &'static str,
    /// Whether it holds.
    pub pass: bool,
    /// The criterion in words.
    pub criterion: String,
}

/// One scenario in [`Verification::json`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ScenarioJson {
    /// Its identifier ([`ScenarioResult::id`]).
    pub name: &'static str,
    /// Whether every criterion holds.
    pub passed: bool,
    /// Title with the operating point.
    pub title: String,
    /// Where the criteria come from.
    pub reference: &'static str,
    /// The criteria.
    pub criteria: Vec<CriterionJson>,
    /// The field-weakening scenario: the speed its ramp reached \[rpm\].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reached_speed_rpm: Option<f64>,
}

/// The verdict in the form `motorgen verify --format json` prints.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct VerificationJson {
    /// 1; raised when a key is removed or renamed or changes meaning.
    pub schema_version: u32,
    /// Motor name.
    pub motor: String,
    /// Spec file.
    pub spec_file: String,
    /// The plant's terms.
    pub plant_model: String,
    /// Whether every scenario passed.
    pub passed: bool,
    /// The scenarios that applied, in order.
    pub scenarios: Vec<ScenarioJson>,
}

impl Verification {
    /// The verdict as data: every scenario with its criteria (name, measured, designed,
    /// limit, unit, pass) and its verdict; for the field-weakening scenario the speed its
    /// ramp reached.
    pub fn json(&self) -> VerificationJson {
        VerificationJson {
            schema_version: 1,
            motor: self.motor.clone(),
            spec_file: self.spec_file.clone(),
            plant_model: self.plant_model.clone(),
            passed: self.passed(),
            scenarios: self
                .scenarios
                .iter()
                .map(|sc| ScenarioJson {
                    name: sc.id,
                    passed: sc.passed(),
                    title: sc.title.clone(),
                    reference: sc.reference,
                    criteria: sc
                        .checks
                        .iter()
                        .map(|c| CriterionJson {
                            name: c.quantity.clone(),
                            measured: c.measured,
                            designed: c.designed,
                            limit: c.limit,
                            unit: c.unit,
                            pass: c.pass,
                            criterion: c.criterion.clone(),
                        })
                        .collect(),
                    reached_speed_rpm: sc.reached_speed_rpm,
                })
                .collect(),
        }
    }
}

/// `x` with 4 significant digits and its unit (in scientific notation from 10⁷ on, where
/// a simulation running away would otherwise print hundreds of digits); a value that is
/// not finite (a simulation that diverged) is "diverged", never NaN or inf.
pub fn format_value(x: f64, unit: &str) -> String {
    let s = if !x.is_finite() {
        return "diverged".into();
    } else if x.abs() >= 1e7 {
        format!("{x:.3e}")
    } else if x == 0.0 {
        "0".into()
    } else {
        let digits = (3 - x.abs().log10().floor() as i32).clamp(0, 8) as usize;
        format!("{x:.digits$}")
    };
    if unit.is_empty() { s } else { format!("{s} {unit}") }
}

/// What every scenario starts from: the design, the plant's machine model and the
/// firmware configuration.
#[derive(Clone, Debug)]
pub struct Setup<'a> {
    /// The design under test.
    pub design: &'a Design,
    /// The simulated machine.
    pub motor: MotorModel,
    /// The firmware configuration built from the design.
    pub cfg: ControllerConfig,
}

impl<'a> Setup<'a> {
    /// The setup for `design`, with the harmonic and saturation data of `spec`.
    pub fn new(spec: &Spec, design: &'a Design) -> Self {
        let m = &spec.motor;
        let h = &m.harmonics;
        let v = |p: &Option<codegen::spec::Param>| p.as_ref().map_or(0.0, |p| p.value);
        Self {
            design,
            motor: MotorModel {
                pole_pairs: design.motor.pole_pairs,
                resistance: design.motor.phase_resistance_ohm,
                ld: design.motor.d_inductance_h,
                lq: design.motor.q_inductance_h,
                psi: design.motor.flux_linkage_wb.unwrap_or(0.0),
                l6: v(&h.inductance_6),
                psi_d: [v(&h.d_flux_6), v(&h.d_flux_12)],
                psi_q: [v(&h.q_flux_6), v(&h.q_flux_12)],
                q_saturation: m.q_saturation.clone(),
            },
            cfg: controller::controller_config(design),
        }
    }

    /// A plant at rest at θ_m = 0 with the nominal DC link and the given speed profile.
    pub fn plant(&self, speed: SpeedProfile) -> Plant {
        let d = self.design;
        let mut p = Plant::new(
            self.motor.clone(),
            Shaft::Imposed(speed),
            d.drive.sample_period_s,
            d.drive.dc_link_voltage_v,
        );
        p.resolver_pole_pairs = d.angle_observer.resolver_pole_pairs;
        p.resolver_offset = controller::resolver_offset_rad(d);
        // The loop delay the current loop is designed for: the board's timing
        // (`codegen` `sections::board::control_timing`), 1.5·T_s without a board.
        p.loop_delay_periods = d.current_loop.loop_delay_s / d.drive.sample_period_s;
        // The resolver held later in the ADC sequences than the currents (the angle
        // lead is designed from its instant, `sections::board::control_timing`).
        p.resolver_lag_s = d
            .board
            .as_ref()
            .map_or(0.0, |b| b.resolver_sample_instant_s - b.current_sample_instant_s);
        p
    }

    /// Controller + plant at a constant mechanical speed [rad/s], observer locked.
    pub fn bench(&self, omega_m: f64) -> Bench {
        self.bench_on(SpeedProfile::constant(omega_m))
    }

    /// Controller + plant with the shaft on `profile`, observer locked, the resolver
    /// signals at the amplitude the design expects of its board ([`Self::signal_gain`]).
    pub fn bench_on(&self, profile: SpeedProfile) -> Bench {
        let mut b = Bench::new(self.cfg, self.plant(profile));
        b.resolver_amplitude = self.signal_gain();
        b
    }

    /// The resolver signals at the observer's input as a fraction of full scale that the
    /// design's trig-identity gains were divided by (`codegen::board::resolver_signal_gain`:
    /// the board's front end and the excitation's envelope at its hold instants; 1 without
    /// a board): the simulated drive reads them at that amplitude, so the observer is
    /// judged as the board runs it (thesis A (4.10)).
    pub fn signal_gain(&self) -> f64 {
        self.design.angle_observer.gains.signal_gain
    }

    /// Description of the plant's optional terms.
    pub fn plant_model(&self) -> String {
        let mut parts = vec!["dq model (thesis A 2.26)".to_string()];
        if self.motor.has_harmonics() {
            parts.push("flux/inductance harmonics (thesis B 2.14–2.16)".into());
        }
        if !self.motor.q_saturation.is_empty() {
            parts.push("L_q(|i_q|) saturation (thesis B 2.25)".into());
        }
        if self.motor.psi == 0.0 {
            parts.push("ψ_M unknown: simulated as 0".into());
        }
        parts.join(" + ")
    }
}

/// A scenario of the standard set.
#[derive(Clone, Copy, Debug)]
pub struct Scenario {
    /// Identifier (as in [`ScenarioResult::id`]).
    pub id: &'static str,
    /// Runs it.
    pub run: fn(&Setup<'_>) -> ScenarioResult,
    /// Whether it applies to the setup's motor (e.g. ψ_M known); if not, it is not run
    /// and not listed.
    pub applies: fn(&Setup<'_>) -> bool,
}

/// [`Scenario::applies`] of the scenarios every motor runs.
pub fn always(_: &Setup<'_>) -> bool {
    true
}

impl Scenario {
    /// The scenarios of [`SCENARIOS`] that apply to `setup`.
    pub fn applicable(setup: &Setup<'_>) -> Vec<&'static Scenario> {
        SCENARIOS.iter().filter(|s| (s.applies)(setup)).collect()
    }
}

/// The standard scenario set, in report order.
pub const SCENARIOS: &[Scenario] = &[
    Scenario {
        id: "current_step",
        run: scenarios::current_step,
        applies: always,
    },
    Scenario {
        id: "decoupling",
        run: scenarios::decoupling,
        applies: always,
    },
    Scenario {
        id: "dc_link_step",
        run: scenarios::dc_link_step,
        applies: always,
    },
    Scenario {
        id: "ato_lock",
        run: observer::ato_lock,
        applies: always,
    },
    Scenario {
        id: "ato_ramp",
        run: observer::ato_ramp,
        applies: always,
    },
    Scenario {
        id: "ato_type2",
        run: observer::ato_type2,
        applies: always,
    },
    Scenario {
        id: "field_weakening",
        run: field_weakening::field_weakening,
        applies: field_weakening::applies,
    },
    Scenario {
        id: "estimator_recovery",
        run: estimator::estimator_recovery,
        applies: estimator::applies,
    },
];

/// Runs every scenario of [`SCENARIOS`] that applies to `setup`.
pub fn verify(setup: &Setup<'_>) -> Verification {
    Verification {
        motor: setup.design.name.clone(),
        spec_file: setup.design.spec_file.clone(),
        plant_model: setup.plant_model(),
        scenarios: Scenario::applicable(setup)
            .iter()
            .map(|s| diverged_fails((s.run)(setup)))
            .collect(),
    }
}

/// What a simulation that diverged is: a failed scenario with its reason, never a NaN or
/// an infinity shown as a figure. Every check whose measured or designed value is not
/// finite fails, and a check "simulation stays finite" is added, counting the non-finite
/// figures and trace samples (which the table shows as "diverged", [`format_value`]).
pub fn diverged_fails(mut r: ScenarioResult) -> ScenarioResult {
    let mut bad = 0usize;
    for c in &mut r.checks {
        let finite = c.measured.is_finite() && c.designed.is_none_or(f64::is_finite);
        if !finite {
            c.pass = false;
            bad += 1;
        }
    }
    let samples = r
        .traces
        .iter()
        .flat_map(|t| t.series.iter().flat_map(|s| &s.values).chain(&t.t_ms))
        .filter(|x| !x.is_finite())
        .count();
    if bad + samples > 0 {
        r.checks.push(Check {
            quantity: "simulation stays finite".into(),
            measured: (bad + samples) as f64,
            designed: Some(0.0),
            limit: Some(0.0),
            unit: "values",
            criterion: format!(
                "every figure and signal finite: the simulation diverged ({bad} figures, {samples} samples not finite)"
            ),
            pass: false,
        });
    }
    r
}

/// Parses and designs `text` (named `file` in messages) on the board `board_text`
/// (`codegen::design_with_board`: refused where the motor does not fit the board), then
/// verifies the design with the board's current and DC-link sensing.
pub fn verify_source_on(
    file: &str,
    text: &str,
    board_file: &str,
    board_text: &str,
) -> Result<(Design, Verification), Diagnostics> {
    let source = Source { file, text };
    let spec = codegen::spec::parse(source)?;
    let design = codegen::design_with_board(file, text, board_file, board_text)?;
    let v = verify(&Setup::new(&spec, &design));
    Ok((design, v))
}

/// Parses and designs `text` (named `file` in messages), then verifies the design.
pub fn verify_source(file: &str, text: &str) -> Result<(Design, Verification), Diagnostics> {
    let source = Source { file, text };
    let spec = codegen::spec::parse(source)?;
    let design = codegen::design::design(&spec, source)?;
    let v = verify(&Setup::new(&spec, &design));
    Ok((design, v))
}
