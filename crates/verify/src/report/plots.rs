//! SVG charts with `plotters` (SVG backend only: text is written as `<text>` elements,
//! so no font or bitmap system libraries are needed).

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::Trace;
use crate::frequency::Response;

/// Chart width and height \[px\].
pub const SIZE: (u32, u32) = (760, 380);
/// Height of a two-panel (magnitude/phase) chart \[px\].
pub const BODE_HEIGHT: u32 = 560;

const COLORS: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
    RGBColor(140, 86, 75),
    RGBColor(0, 0, 0),
];

fn color(k: usize) -> RGBColor {
    COLORS[k % COLORS.len()]
}

/// A line on a chart: label and (x, y) points.
pub type Line = (String, Vec<(f64, f64)>);

/// Range of the finite values with 5 % padding (a unit range around a constant).
fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
    if !lo.is_finite() {
        return (-1.0, 1.0);
    }
    if hi - lo < 1e-12 * (1.0 + lo.abs()) {
        return (lo - 1.0, hi + 1.0);
    }
    let pad = 0.05 * (hi - lo);
    (lo - pad, hi + pad)
}

/// Tick label: plain decimals for 0.01 ≤ |x| < 10⁵, else an exponent.
fn tick(x: f64) -> String {
    let a = x.abs();
    if x == 0.0 {
        "0".into()
    } else if !(0.01..1e5).contains(&a) {
        format!("{x:.0e}")
    } else if a >= 100.0 || (x - x.round()).abs() < 1e-9 * a {
        format!("{x:.0}")
    } else {
        let s = format!("{x:.2}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

fn err(e: impl std::fmt::Display) -> String {
    format!("plot: {e}")
}

/// Draws `lines` on `area` with linear or logarithmic x.
fn panel(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    caption: Option<&str>,
    x_desc: &str,
    y_desc: &str,
    lines: &[Line],
    log_x: bool,
    fixed: Option<((f64, f64), (f64, f64))>,
) -> Result<(), String> {
    let ((x0, x1), (y0, y1)) = fixed.unwrap_or_else(|| {
        (
            range(lines.iter().flat_map(|l| l.1.iter().map(|p| p.0))),
            range(lines.iter().flat_map(|l| l.1.iter().map(|p| p.1))),
        )
    });
    let mut b = ChartBuilder::on(area);
    b.margin(12).x_label_area_size(40).y_label_area_size(64);
    if let Some(c) = caption {
        b.caption(c, ("sans-serif", 17));
    }
    macro_rules! draw {
        ($chart:expr) => {{
            let mut chart = $chart;
            chart
                .configure_mesh()
                .x_label_formatter(&|x| tick(*x))
                .y_label_formatter(&|y| tick(*y))
                .x_desc(x_desc)
                .y_desc(y_desc)
                .light_line_style(RGBColor(235, 235, 235))
                .draw()
                .map_err(err)?;
            for (k, (label, pts)) in lines.iter().enumerate() {
                let c = color(k);
                // Points outside the axes split the line (no drawing beyond the frame).
                let mut segments: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
                for &(x, y) in pts {
                    let inside = x.is_finite() && y.is_finite() && x >= x0 && x <= x1 && y >= y0 && y <= y1;
                    if inside {
                        if let Some(s) = segments.last_mut() {
                            s.push((x, y));
                        }
                    } else if segments.last().is_some_and(|s| !s.is_empty()) {
                        segments.push(Vec::new());
                    }
                }
                for (j, seg) in segments.into_iter().filter(|s| !s.is_empty()).enumerate() {
                    let series = chart
                        .draw_series(LineSeries::new(seg, c.stroke_width(2)))
                        .map_err(err)?;
                    if j == 0 {
                        series
                            .label(label.as_str())
                            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], c.stroke_width(2)));
                    }
                }
            }
            chart
                .configure_series_labels()
                .position(SeriesLabelPosition::UpperRight)
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK.mix(0.4))
                .label_font(("sans-serif", 13))
                .draw()
                .map_err(err)?;
        }};
    }
    if log_x {
        draw!(
            b.build_cartesian_2d((x0.max(1e-9)..x1).log_scale(), y0..y1)
                .map_err(err)?
        );
    } else {
        draw!(b.build_cartesian_2d(x0..x1, y0..y1).map_err(err)?);
    }
    Ok(())
}

/// One chart of `lines` over linear x.
pub fn line_chart(title: &str, x_desc: &str, y_desc: &str, lines: &[Line]) -> Result<String, String> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        panel(&root, Some(title), x_desc, y_desc, lines, false, None)?;
        root.present().map_err(err)?;
    }
    Ok(svg)
}

/// A scenario trace over time \[ms\].
pub fn trace_chart(t: &Trace) -> Result<String, String> {
    let lines: Vec<Line> = t
        .series
        .iter()
        .map(|s| {
            (
                s.label.clone(),
                t.t_ms.iter().copied().zip(s.values.iter().copied()).collect(),
            )
        })
        .collect();
    line_chart(&t.title, "t [ms]", &t.y_label, &lines)
}

/// Magnitude \[dB\] and phase [°] of labelled responses, stacked; `log_x` for Bode plots
/// over rad/s, else linear (e.g. Hz for the FIR).
pub fn bode_chart(title: &str, x_desc: &str, responses: &[(String, &Response)], log_x: bool) -> Result<String, String> {
    let mag: Vec<Line> = responses
        .iter()
        .map(|(l, r)| (l.clone(), r.omega.iter().copied().zip(r.magnitude_db()).collect()))
        .collect();
    let phase: Vec<Line> = responses
        .iter()
        .map(|(l, r)| (l.clone(), r.omega.iter().copied().zip(r.phase_deg()).collect()))
        .collect();
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (SIZE.0, BODE_HEIGHT)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let root = root.titled(title, ("sans-serif", 17)).map_err(err)?;
        let (top, bottom) = root.split_vertically(BODE_HEIGHT / 2 - 10);
        // Magnitudes far below the pass band only squash the interesting range.
        let (lo, hi) = range(mag.iter().flat_map(|l| l.1.iter().map(|p| p.1)));
        let xr = range(mag.iter().flat_map(|l| l.1.iter().map(|p| p.0)));
        let xr = if log_x {
            let (a, b) = mag
                .iter()
                .flat_map(|l| l.1.iter().map(|p| p.0))
                .fold((f64::INFINITY, 0.0f64), |(a, b), x| (a.min(x), b.max(x)));
            (a, b)
        } else {
            (0.0f64.max(xr.0), xr.1)
        };
        panel(
            &top,
            None,
            x_desc,
            "magnitude [dB]",
            &mag,
            log_x,
            Some((xr, (lo.max(-120.0), hi))),
        )?;
        let pr = range(phase.iter().flat_map(|l| l.1.iter().map(|p| p.1)));
        panel(&bottom, None, x_desc, "phase [°]", &phase, log_x, Some((xr, pr)))?;
        root.present().map_err(err)?;
    }
    Ok(svg)
}

/// A chart with equal axis scales (for the dq plane): `lines` within ±`half` on both axes.
pub fn plane_chart(title: &str, x_desc: &str, y_desc: &str, lines: &[Line], half: f64) -> Result<String, String> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (640, 640)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        panel(
            &root,
            Some(title),
            x_desc,
            y_desc,
            lines,
            false,
            Some(((-half, half), (-half, half))),
        )?;
        root.present().map_err(err)?;
    }
    Ok(svg)
}
