//! The design report: one self-contained HTML page (inline CSS and SVG, no scripts, no
//! external resources) with the verification table, the plots and every constant with
//! its formula and provenance.
//!
//! Plots ([`plots_of`], in page order; a new design rule adds its plot as a further entry):
//! current-loop step responses (simulated vs designed) and Bode plots (discrete
//! open/closed loop vs the continuous design), decoupling and DC-link responses, ATO lock
//! and ramp responses and Bode plot, FIR magnitude and phase, and the dq plane with the
//! current circle and voltage ellipses (thesis B (2.50)–(2.53)), the MTPA curve (3.10)
//! and the field-weakening run's (i_d, i_q) trajectory; the field-weakening run's
//! currents, voltage and speed; the sensorless estimator's recovery.

pub mod plots;

use std::f64::consts::PI;
use std::fmt::Write as _;

use crate::{Verification, format_value, frequency};
use codegen::constants::constants;
use codegen::design::Design;
use codegen::design::current_loop::{Axis, discrete};
use nalgebra::Complex;
use plots::Line;

/// One plot of the page.
#[derive(Clone, Debug, PartialEq)]
pub struct Plot {
    /// HTML id (unique in the page), e.g. `current-step-q`.
    pub id: String,
    /// Section it belongs to.
    pub section: &'static str,
    /// Caption under the plot.
    pub caption: String,
    /// The `<svg>` element.
    pub svg: String,
}

/// Escapes text for HTML element content and attribute values.
pub fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// Section titles in page order.
pub const SECTIONS: &[(&str, &str)] = &[
    ("current-loop", "Current loop"),
    ("feed-forward", "Feed-forward: decoupling and DC link"),
    ("observer", "Angle tracking observer"),
    ("fir", "Identification FIR"),
    ("dq-plane", "Operating limits in the dq plane"),
    ("field-weakening", "Field weakening"),
    ("sensorless", "Sensorless estimator"),
];

/// Current circle and voltage ellipses (thesis B (2.50)–(2.53)): |i| = i_max and
/// (L_d·i_d + ψ_M)² + (L_q·i_q)² = (V_max/ω_e)², V_max = U_dc/√3, at a quarter, half,
/// three quarters and all of ω_e,max, and at the speed where the ellipse passes through
/// (0, i_max) when that is below ω_e,max. Returns the lines and the half-width of the
/// square view \[A\].
pub fn dq_plane_lines(d: &Design) -> (Vec<Line>, f64) {
    let m = &d.motor;
    let i_max = m.peak_current_a;
    let v_max = d.current_loop.voltage_limit_v;
    let psi = m.flux_linkage_wb.unwrap_or(0.0);
    let (ld, lq) = (m.d_inductance_h, m.q_inductance_h);
    let n = 361;
    let circle: Vec<(f64, f64)> = (0..n)
        .map(|k| {
            let a = 2.0 * PI * k as f64 / (n - 1) as f64;
            (i_max * a.cos(), i_max * a.sin())
        })
        .collect();
    let mut lines = vec![(format!("current circle |i| = {}", format_value(i_max, "A")), circle)];
    let w_max = m.max_electrical_speed_rad_s;
    let w_corner = corner_speed(d);
    let mut speeds: Vec<f64> = [0.25, 0.5, 0.75, 1.0].iter().map(|f| f * w_max).collect();
    if w_corner < w_max {
        speeds.push(w_corner);
    }
    speeds.sort_by(f64::total_cmp);
    for w in speeds {
        let rho = v_max / w;
        let pts = (0..n)
            .map(|k| {
                let a = 2.0 * PI * k as f64 / (n - 1) as f64;
                ((rho * a.cos() - psi) / ld, rho * a.sin() / lq)
            })
            .collect();
        let rpm = w / f64::from(m.pole_pairs) * 30.0 / PI;
        lines.push((
            format!(
                "voltage ellipse ω_e = {} ({})",
                format_value(w, "rad/s"),
                format_value(rpm, "rpm")
            ),
            pts,
        ));
    }
    // Room for the current circle and for the top-speed ellipse's part nearest the
    // origin (its rightmost point and its i_q semi-axis), which a slow motor may place
    // outside the circle.
    let rho = v_max / w_max;
    let half = (1.6 * i_max).max(1.1 * (rho - psi).abs() / ld).max(1.1 * rho / lq);
    (lines, half)
}

/// The MTPA curve i_d(i_q) (thesis B (3.10): the design's table, both signs of i_q, up to
/// the MTPA point on the current circle) and the (i_d, i_q) samples of the
/// field-weakening run, if the motor has one.
pub fn field_weakening_lines(d: &Design, v: &Verification) -> Vec<Line> {
    let mut lines = Vec::new();
    let Some(fw) = &d.field_weakening else {
        return lines;
    };
    let t = &fw.mtpa;
    let mtpa = t
        .iq_a
        .iter()
        .zip(&t.id_a)
        .rev()
        .map(|(&iq, &id)| (id, -iq))
        .chain(t.iq_a.iter().zip(&t.id_a).map(|(&iq, &id)| (id, iq)))
        .collect();
    lines.push(("MTPA i_d(i_q) (3.10)".to_string(), mtpa));
    let run = v
        .scenarios
        .iter()
        .filter(|s| s.id == "field_weakening")
        .flat_map(|s| s.traces.first());
    for t in run {
        let col = |label: &str| t.series.iter().find(|s| s.label == label).map(|s| &s.values);
        if let (Some(id), Some(iq)) = (col("i_d simulated"), col("i_q simulated")) {
            let pts = id.iter().zip(iq).map(|(a, b)| (*a, *b)).collect();
            lines.push(("field-weakening run (simulated i_d, i_q)".to_string(), pts));
        }
    }
    lines
}

/// The run's torque over speed and the envelope, one line per region (each starting at the
/// last point of the region before it, so the envelope is drawn unbroken).
pub fn torque_speed_lines(ts: &crate::field_weakening::TorqueSpeed) -> Vec<Line> {
    use crate::field_weakening::Region;
    let e = &ts.envelope;
    let mut lines = vec![(
        "simulated run".to_string(),
        ts.speed_rpm.iter().copied().zip(ts.torque_nm.iter().copied()).collect(),
    )];
    for (region, label) in [
        (Region::Mtpa, "envelope: MTPA (current limit)"),
        (
            Region::VoltageLimited,
            "envelope: voltage-limited, current circle (Mode B)",
        ),
        (Region::Mtpv, "envelope: maximum torque per volt"),
    ] {
        let pts: Vec<(f64, f64)> = (0..e.region.len())
            .filter(|&k| e.region[k] == region || (k + 1 < e.region.len() && e.region[k + 1] == region))
            .map(|k| (e.speed_rpm[k], e.torque_nm[k]))
            .collect();
        if pts.len() > 1 {
            lines.push((label.to_string(), pts));
        }
    }
    lines
}

/// Electrical speed [rad/s] at which the voltage ellipse passes through (0, i_max):
/// ω = V_max/√(ψ_M² + (L_q·i_max)²) (thesis B (2.53) with i_d = 0, |i_q| = i_max).
pub fn corner_speed(d: &Design) -> f64 {
    let m = &d.motor;
    let psi = m.flux_linkage_wb.unwrap_or(0.0);
    d.current_loop.voltage_limit_v / (psi * psi + (m.q_inductance_h * m.peak_current_a).powi(2)).sqrt()
}

/// A current loop's open-loop response measured on the drive (`motorgen commission …
/// frequency-response`), to overlay on the designed Bode plot of its axis.
#[derive(Clone, Debug, PartialEq)]
pub struct MeasuredLoop {
    /// `d` or `q`.
    pub axis: String,
    /// The lines' ω [rad/s].
    pub omega: Vec<f64>,
    /// |L| at each line \[dB\].
    pub magnitude_db: Vec<f64>,
    /// arg L at each line [°].
    pub phase_deg: Vec<f64>,
    /// The measured margins and the fitted plant beside the spec's, for the caption.
    pub summary: String,
}

/// Every plot of the report for `d` and its verification `v`, in page order.
pub fn plots_of(d: &Design, v: &Verification) -> Result<Vec<Plot>, String> {
    plots_with_measured(d, v, &[])
}

/// [`plots_of`] with measured current-loop responses overlaid on the Bode plots of their
/// axes (the open loop L measured on the drive next to the discrete design's).
pub fn plots_with_measured(d: &Design, v: &Verification, measured: &[MeasuredLoop]) -> Result<Vec<Plot>, String> {
    let mut out = Vec::new();
    let traces = |id: &'static str| {
        v.scenarios
            .iter()
            .filter(move |s| s.id == id)
            .flat_map(|s| s.traces.iter())
    };
    for (k, t) in traces("current_step").enumerate() {
        out.push(Plot {
            id: format!("current-step-{k}"),
            section: "current-loop",
            caption: format!(
                "{} — firmware control step on the simulated motor vs the designed response",
                t.title
            ),
            svg: plots::trace_chart(t)?,
        });
    }
    let ts = d.drive.sample_period_s;
    let alpha = d.current_loop.bandwidth_rad_s;
    let grid = frequency::log_grid(alpha / 100.0, PI / ts, 400);
    let designed = frequency::current_loop_designed(d, &grid);
    for (axis, g, which) in [("d", &d.current_loop.d, Axis::D), ("q", &d.current_loop.q, Axis::Q)] {
        let plant = discrete::plant(&d.current_loop_request(which));
        let (open, closed) = frequency::current_loop(g, &plant, &grid);
        let mut responses = vec![
            ("open loop L (discrete)".to_string(), open),
            ("closed loop T (discrete)".to_string(), closed),
            ("closed loop (continuous design)".to_string(), designed.clone()),
        ];
        let mut caption = format!(
            "{axis}-axis current loop: discrete open loop L = C·P and closed loop T (forward-difference PI, ZOH plant, the design's {:.4}·T_s loop delay) against the continuous design, up to the Nyquist frequency π·f_s",
            plant.lag + 0.5
        );
        for meas in measured.iter().filter(|x| x.axis == axis) {
            let values = meas
                .magnitude_db
                .iter()
                .zip(&meas.phase_deg)
                .map(|(db, deg)| Complex::from_polar(10f64.powf(db / 20.0), deg.to_radians()))
                .collect();
            responses.push((
                "open loop L (measured on the drive)".to_string(),
                frequency::Response {
                    omega: meas.omega.clone(),
                    values,
                },
            ));
            caption.push_str(&format!("; measured on the drive: {}", meas.summary));
        }
        let refs: Vec<(String, &frequency::Response)> = responses.iter().map(|(l, r)| (l.clone(), r)).collect();
        out.push(Plot {
            id: format!("current-bode-{axis}"),
            section: "current-loop",
            caption,
            svg: plots::bode_chart(&format!("{axis}-axis current loop"), "ω [rad/s]", &refs, true)?,
        });
    }
    for (k, t) in traces("decoupling").chain(traces("dc_link_step")).enumerate() {
        out.push(Plot {
            id: format!("feed-forward-{k}"),
            section: "feed-forward",
            caption: t.title.clone(),
            svg: plots::trace_chart(t)?,
        });
    }
    for (k, t) in traces("ato_lock").chain(traces("ato_ramp")).enumerate() {
        out.push(Plot {
            id: format!("observer-{k}"),
            section: "observer",
            caption: t.title.clone(),
            svg: plots::trace_chart(t)?,
        });
    }
    let o = &d.angle_observer;
    let grid = frequency::log_grid(o.natural_frequency_rad_s / 100.0, PI / ts, 400);
    let (open, closed) = frequency::observer(d, &grid);
    let designed = frequency::observer_designed(d, &grid);
    out.push(Plot {
        id: "observer-bode".into(),
        section: "observer",
        caption: "Angle tracking observer with the Q1.31 gains (4.19), (4.22), linearised, against the continuous design (4.14)".into(),
        svg: plots::bode_chart(
            "Angle tracking observer",
            "ω [rad/s]",
            &[
                ("open loop (discrete, Q1.31)".into(), &open),
                ("closed loop θ̂/θ (discrete, Q1.31)".into(), &closed),
                ("closed loop (continuous design)".into(), &designed),
            ],
            true,
        )?,
    });
    let h = frequency::fir(d, 800);
    out.push(Plot {
        id: "fir-response".into(),
        section: "fir",
        caption: format!(
            "Q1.15 FIR of order {}: pass band to {} (ripple {:.2e}), stop band from {} ({:.1} dB), linear phase (delay {} samples)",
            d.fir.order,
            format_value(d.fir.pass_edge_hz, "Hz"),
            d.fir.pass_ripple_quantised,
            format_value(d.fir.stop_edge_hz, "Hz"),
            d.fir.stop_attenuation_db_quantised,
            d.fir.group_delay_samples
        ),
        svg: plots::bode_chart(
            "Identification FIR (Q1.15 taps)",
            "f [Hz]",
            &[("H(e^jωT)".into(), &h)],
            false,
        )?,
    });
    let (mut lines, half) = dq_plane_lines(d);
    let mut caption = String::from(
        "Current circle and voltage ellipses (thesis B (2.50)–(2.53), V_max = U_dc/√3): at a speed, the reachable currents lie inside both",
    );
    let fw = field_weakening_lines(d, v);
    if !fw.is_empty() {
        caption.push_str("; MTPA curve (3.10) and the simulated field-weakening run (Fig. 2.15): along MTPA below base speed, then toward the ellipse centre −ψ_M/L_d on the current circle (Mode B, (2.57))");
    }
    lines.extend(fw);
    out.push(Plot {
        id: "dq-plane".into(),
        section: "dq-plane",
        caption,
        svg: plots::plane_chart("dq plane", "i_d [A]", "i_q [A]", &lines, half)?,
    });
    if let Some(ts) = v.scenarios.iter().find_map(|x| x.torque_speed.as_ref()) {
        out.push(Plot {
            id: "torque-speed".into(),
            section: "field-weakening",
            caption: format!(
                "Torque versus speed: the field-weakening run under {} (the image's torque stage on the simulated machine) against the designed envelope, the most torque within |i| ≤ I_max and |v| ≤ V'_max at each speed — current-limited on the MTPA point (3.10), voltage-limited on the current circle (Mode B, (2.57)), maximum torque per volt inside it",
                format_value(ts.commanded_nm, "N·m")
            ),
            svg: plots::line_chart("Torque–speed", "n [rpm]", "T [N·m]", &torque_speed_lines(ts))?,
        });
    }
    for (section, id) in [
        ("field-weakening", "field_weakening"),
        ("sensorless", "estimator_recovery"),
    ] {
        for (k, t) in traces(id).enumerate() {
            out.push(Plot {
                id: format!("{section}-{k}"),
                section,
                caption: t.title.clone(),
                svg: plots::trace_chart(t)?,
            });
        }
    }
    Ok(out)
}

const STYLE: &str = "body{font-family:sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;color:#222}\
h1{font-size:1.6em}h2{margin-top:2em;border-bottom:1px solid #ccc}\
table{border-collapse:collapse;margin:1em 0;font-size:0.9em}\
th,td{border:1px solid #ccc;padding:0.25em 0.5em;text-align:left;vertical-align:top}\
th{background:#f2f2f2}td.num{text-align:right;white-space:nowrap}\
tr.pass td.result{color:#1a7f37;font-weight:bold}tr.fail td.result{color:#c62828;font-weight:bold}\
figure.plot{margin:1.5em 0}figure.plot svg{max-width:100%;height:auto}\
figcaption{font-size:0.9em;color:#555}code{font-size:0.95em}";

/// The whole HTML page for `d`, its verification `v` and its plots.
pub fn html(d: &Design, v: &Verification, plots: &[Plot]) -> String {
    let mut s = String::new();
    let _ = write!(
        s,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>{}</title>\n<style>{STYLE}</style>\n</head>\n<body>\n",
        escape(&format!("{} — motor-controller design report", d.name))
    );
    let _ = writeln!(
        s,
        "<h1>{}</h1>\n<p>Spec <code>{}</code>; generated by motorgen {}. Plant: {}.</p>",
        escape(&d.name),
        escape(&d.spec_file),
        env!("CARGO_PKG_VERSION"),
        escape(&v.plant_model)
    );
    let passed = v.scenarios.iter().filter(|x| x.passed()).count();
    let _ = writeln!(
        s,
        "<h2 id=\"verification\">Verification</h2>\n<p>{passed} of {} scenarios passed. The firmware's control step (<code>motor-control</code>) runs with this design's constants against the simulated motor (the design's {:.4}·T_s loop delay).</p>",
        v.scenarios.len(),
        d.current_loop.loop_delay_s / d.drive.sample_period_s
    );
    s.push_str("<table id=\"verification-table\">\n<tr><th>scenario</th><th>check</th><th>measured</th><th>designed</th><th>criterion</th><th>result</th></tr>\n");
    for sc in &v.scenarios {
        for c in &sc.checks {
            let _ = writeln!(
                s,
                "<tr class=\"{}\"><td title=\"{}\">{}</td><td>{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td>{}</td><td class=\"result\">{}</td></tr>",
                if c.pass { "pass" } else { "fail" },
                escape(sc.reference),
                escape(&sc.title),
                escape(&c.quantity),
                escape(&format_value(c.measured, c.unit)),
                escape(&c.designed.map_or("—".into(), |x| format_value(x, c.unit))),
                escape(&c.criterion),
                if c.pass { "pass" } else { "FAIL" }
            );
        }
    }
    s.push_str("</table>\n");
    for (id, title) in SECTIONS {
        let here: Vec<&Plot> = plots.iter().filter(|p| p.section == *id).collect();
        if here.is_empty() {
            continue;
        }
        let _ = writeln!(s, "<h2 id=\"{id}\">{}</h2>", escape(title));
        if *id == "current-loop" {
            let c = &d.current_loop;
            let _ = writeln!(
                s,
                "<p>Sampled loop (T_s, {:.4}·T_s delay; floors: phase margin ≥ {}°, gain margin ≥ {} dB, overshoot ≤ {:.1} %; delay compensation {}):</p>\n<ul>\n<li>d axis: {}</li>\n<li>q axis: {}</li>\n</ul>",
                c.loop_delay_s / d.drive.sample_period_s,
                c.floors.min_phase_margin_deg,
                c.floors.min_gain_margin_db,
                c.floors.max_overshoot_pct,
                if c.compensate_delay { "on" } else { "off" },
                escape(&c.d.sampled.describe()),
                escape(&c.q.sampled.describe())
            );
        }
        for p in here {
            let _ = writeln!(
                s,
                "<figure class=\"plot\" id=\"{}\">\n{}\n<figcaption>{}</figcaption>\n</figure>",
                escape(&p.id),
                p.svg.trim(),
                escape(&p.caption)
            );
        }
    }
    s.push_str("<h2 id=\"constants\">Constants</h2>\n<p>Every generated constant with its physical value, formula, source equation and the provenance of its inputs (the same list the Rust, C and Markdown outputs render).</p>\n");
    for g in constants(d) {
        let _ = writeln!(
            s,
            "<h3><code>{}</code> — {}</h3>\n<table class=\"constants\">\n<tr><th>constant</th><th>value</th><th>formula</th><th>equation</th><th>inputs (provenance)</th></tr>",
            escape(g.name),
            escape(g.title)
        );
        for c in &g.constants {
            let _ = writeln!(
                s,
                "<tr><td><code>{}</code></td><td class=\"num\">{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
                escape(&c.name),
                escape(&c.physical),
                escape(&c.formula),
                escape(&c.equation),
                escape(&c.inputs)
            );
        }
        s.push_str("</table>\n");
    }
    s.push_str("<h2 id=\"provenance\">Motor values</h2>\n<table>\n<tr><th>value</th><th>source</th><th>key</th><th>note</th></tr>\n");
    for (name, o) in &d.motor.provenance {
        let source = serde_json::to_value(o.source)
            .ok()
            .and_then(|v| v.as_str().map(str::to_string))
            .unwrap_or_default();
        let _ = writeln!(
            s,
            "<tr><td>{}</td><td>{}</td><td><code>{}</code></td><td>{}</td></tr>",
            escape(name),
            escape(&source),
            escape(&o.key),
            escape(o.note.as_deref().unwrap_or(""))
        );
    }
    s.push_str("</table>\n</body>\n</html>\n");
    s
}

/// The report page for `d` and `v`.
pub fn report(d: &Design, v: &Verification) -> Result<String, String> {
    report_with_measured(d, v, &[])
}

/// [`report`] with measured current-loop responses overlaid ([`plots_with_measured`]).
pub fn report_with_measured(d: &Design, v: &Verification, measured: &[MeasuredLoop]) -> Result<String, String> {
    let plots = plots_with_measured(d, v, measured)?;
    Ok(html(d, v, &plots))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escapes_markup() {
        assert_eq!(escape("a<b & \"c\"'"), "a&lt;b &amp; &quot;c&quot;&#39;");
    }

    /// Fischer by hand: ψ_M from K_e = 0.296 V·s/rad (rms, line to line, mechanical):
    /// 0.296·√2/(√3·4) = 0.060421 Wb; i_max = √2·61 A = 86.267 A; V_max = 600/√3 =
    /// 346.41 V; ω_e,max = 4·20000·2π/60 = 8377.6 rad/s.
    /// Corner speed 346.41/√(0.060421² + (0.393e-3·86.267)²) = 346.41/0.069283 = 5000 rad/s.
    /// At ω_e,max, ρ = 346.41/8377.6 = 0.041350 Wb and the ellipse's rightmost point is
    /// i_d = (ρ − ψ_M)/L_d = (0.041350 − 0.060421)/0.393e-3 = −48.53 A, at i_q = 0.
    #[test]
    fn fischer_limits_by_hand() {
        let text =
            std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../motors/fischer-ti085.toml")).unwrap();
        let d = codegen::design_source("f.toml", &text).unwrap();
        assert!((corner_speed(&d) - 5000.0).abs() < 1.0, "{}", corner_speed(&d));
        let (lines, half) = dq_plane_lines(&d);
        assert!((half - 1.6 * 86.267).abs() < 0.01);
        let (_, circle) = &lines[0];
        assert!(circle.iter().all(|(x, y)| (x.hypot(*y) - 86.267).abs() < 1e-3));
        let (label, top) = lines.last().unwrap();
        assert!(label.contains("8378 rad/s"), "{label}");
        let right = top.iter().map(|p| p.0).fold(f64::NEG_INFINITY, f64::max);
        assert!((right + 48.53).abs() < 0.01, "{right}");
        // ¼, ½, ¾, 1 of ω_e,max and the corner speed.
        assert_eq!(lines.len(), 6);
    }
}
