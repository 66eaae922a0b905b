//! SVG charts with `plotters` (SVG backend only: text is written as `<text>` elements,
//! so no font or bitmap system libraries are needed).

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::Trace;
use crate::frequency::Response;

/// Chart width and height \[px\].
pub const SIZE: (u32, u32) = (800, 420);
/// Height of a two-panel (magnitude/phase) chart \[px\].
pub const BODE_HEIGHT: u32 = 600;
/// Height of the (square) plotting side of a dq-plane chart \[px\].
pub const PLANE: u32 = 640;

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

/// Tick label of `x` on an axis spanning `span` (for a logarithmic axis, pass `x`
/// itself): zero for values within 10⁻⁹ of the span of zero (the rounding residue of a
/// tick step, e.g. −6·10⁻¹⁷), else the value to a thousandth of the span with trailing
/// zeros dropped (at most four significant digits on a tick grid), in exponent form with
/// at most three significant digits only for |x| ≥ 10⁵ or |x| < 10⁻³.
pub fn tick(x: f64, span: f64) -> String {
    let a = x.abs();
    let span = span.abs();
    if !x.is_finite() {
        return format!("{x}");
    }
    if a == 0.0 || a <= 1e-9 * span {
        return "0".into();
    }
    if !(1e-3..1e5).contains(&a) {
        let s = format!("{x:.2e}");
        let (m, e) = s.split_once('e').unwrap_or((&s, "0"));
        let m = if m.contains('.') {
            m.trim_end_matches('0').trim_end_matches('.')
        } else {
            m
        };
        return format!("{m}e{e}");
    }
    let resolution = if span > 0.0 { 1e-3 * span.min(1e3 * a) } else { 1e-3 * a };
    let decimals = (-resolution.log10()).ceil().clamp(0.0, 9.0) as usize;
    let s = format!("{x:.decimals$}");
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        &s
    };
    if s == "-0" { "0".into() } else { s.to_string() }
}

fn err(e: impl std::fmt::Display) -> String {
    format!("plot: {e}")
}

/// Font size given to `plotters` for tick labels, axis labels and legends: its SVG backend
/// writes `font-size` as the size ÷ 1.24, so 17 is 13.7 px in the SVG's own units, and the
/// page shows every chart at its own width (none is wider than the page's 1100 px column),
/// so also 13.7 px on screen.
pub const FONT: u32 = 17;
/// Font size of chart titles (see [`FONT`]).
const TITLE_FONT: u32 = 22;
/// Legend row height and inner padding \[px\].
const ROW: i32 = 22;
const PAD: i32 = 8;
/// Width of a legend's colour swatch and its gap to the label \[px\].
const SWATCH: i32 = 22;

/// Size \[px\] of the legend of `lines`: text width estimated at 0.62 em a character
/// (wider than DejaVu Sans' and Liberation Sans' average), so the box holds the text.
fn legend_size(lines: &[Line]) -> (i32, i32) {
    let em = f64::from(FONT) / 1.24;
    let chars = lines.iter().map(|l| l.0.chars().count()).max().unwrap_or(0);
    let text = (chars as f64 * 0.62 * em).ceil() as i32;
    (
        PAD + SWATCH + PAD + text + PAD,
        PAD + ROW * lines.len() as i32 + PAD / 2,
    )
}

/// Whether the segment p–q meets the rectangle `r` = (x0, y0, x1, y1) (Liang–Barsky).
fn segment_hits(r: (f64, f64, f64, f64), p: (f64, f64), q: (f64, f64)) -> bool {
    let (dx, dy) = (q.0 - p.0, q.1 - p.1);
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (den, num) in [(-dx, p.0 - r.0), (dx, r.2 - p.0), (-dy, p.1 - r.1), (dy, r.3 - p.1)] {
        if den == 0.0 {
            if num < 0.0 {
                return false;
            }
        } else {
            let t = num / den;
            if den < 0.0 {
                t0 = t0.max(t);
            } else {
                t1 = t1.min(t);
            }
            if t0 > t1 {
                return false;
            }
        }
    }
    true
}

/// Where the legend goes, from the drawn data: the first corner (then the middles of the
/// top, bottom, right and left sides) of the plotting area `plot` (pixels: x0, y0, x1, y1) whose legend box of
/// `size`, 6 px clear all round, meets none of the `polylines` (pixels); `None` if every
/// such place covers data.
fn free_corner(plot: (i32, i32, i32, i32), size: (i32, i32), polylines: &[Vec<(i32, i32)>]) -> Option<(i32, i32)> {
    let (x0, y0, x1, y1) = plot;
    let (w, h) = size;
    let inset = 6;
    if w + 2 * inset > x1 - x0 || h + 2 * inset > y1 - y0 {
        return None;
    }
    let (l, r) = (x0 + inset, x1 - inset - w);
    let (t, b) = (y0 + inset, y1 - inset - h);
    let (mid, middle) = ((x0 + x1 - w) / 2, (y0 + y1 - h) / 2);
    [
        (r, t),
        (l, t),
        (r, b),
        (l, b),
        (mid, t),
        (mid, b),
        (r, middle),
        (l, middle),
    ]
    .into_iter()
    .find(|&(x, y)| {
        let rect = (
            f64::from(x - inset),
            f64::from(y - inset),
            f64::from(x + w + inset),
            f64::from(y + h + inset),
        );
        !polylines.iter().any(|pl| {
            let f = |p: &(i32, i32)| (f64::from(p.0), f64::from(p.1));
            match pl.len() {
                0 => false,
                1 => segment_hits(rect, f(&pl[0]), f(&pl[0])),
                _ => pl.windows(2).any(|s| segment_hits(rect, f(&s[0]), f(&s[1]))),
            }
        })
    })
}

/// Draws the legend of `lines` with its top left corner at `at` (pixels within `area`):
/// a white box with a grey border, a colour swatch (a filled rectangle, so the only
/// polylines of a chart are its data) and the label per line.
fn draw_legend(area: &DrawingArea<SVGBackend<'_>, Shift>, at: (i32, i32), lines: &[Line]) -> Result<(), String> {
    let (w, h) = legend_size(lines);
    let (x, y) = at;
    area.draw(&Rectangle::new([(x, y), (x + w, y + h)], WHITE.mix(0.9).filled()))
        .map_err(err)?;
    area.draw(&Rectangle::new(
        [(x, y), (x + w, y + h)],
        BLACK.mix(0.4).stroke_width(1),
    ))
    .map_err(err)?;
    for (k, (label, _)) in lines.iter().enumerate() {
        let top = y + PAD + ROW * k as i32;
        let mid = top + ROW / 2 - 2;
        area.draw(&Rectangle::new(
            [(x + PAD, mid - 2), (x + PAD + SWATCH, mid + 2)],
            color(k).filled(),
        ))
        .map_err(err)?;
        area.draw(&Text::new(
            label.clone(),
            (x + PAD + SWATCH + PAD, top + 2),
            ("sans-serif", FONT).into_font(),
        ))
        .map_err(err)?;
    }
    Ok(())
}

/// The visible pieces of each line: points outside the axes (or not finite) split it, so
/// nothing is drawn beyond the frame.
fn pieces(lines: &[Line], (x0, x1): (f64, f64), (y0, y1): (f64, f64)) -> Vec<Vec<Vec<(f64, f64)>>> {
    lines
        .iter()
        .map(|(_, pts)| {
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
            segments.retain(|s| !s.is_empty());
            segments
        })
        .collect()
}

/// Where a panel's legend goes.
#[derive(Clone, Copy, PartialEq)]
enum LegendAt {
    /// In a free corner of the plotting area if there is one, else in a column to the right.
    Auto,
    /// In a column to the right of the plotting area.
    Outside,
    /// Nowhere, the chart on the whole area (another panel of the figure has the legend).
    Hidden,
    /// Nowhere, the chart leaving the column [`LegendAt::Outside`] would take empty (so
    /// stacked panels keep one x scale).
    Reserved,
    /// Draw nothing: only find the free corner [`LegendAt::Auto`] would take.
    Probe,
}

#[allow(clippy::too_many_arguments)]
fn panel(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    caption: Option<&str>,
    x_desc: &str,
    y_desc: &str,
    lines: &[Line],
    log_x: bool,
    fixed: Option<((f64, f64), (f64, f64))>,
    legend: LegendAt,
) -> Result<Option<(i32, i32)>, String> {
    let ((x0, x1), (y0, y1)) = fixed.unwrap_or_else(|| {
        (
            range(lines.iter().flat_map(|l| l.1.iter().map(|p| p.0))),
            range(lines.iter().flat_map(|l| l.1.iter().map(|p| p.1))),
        )
    });
    let area = match caption {
        Some(c) => area.titled(c, ("sans-serif", TITLE_FONT)).map_err(err)?,
        None => area.clone(),
    };
    let parts = pieces(lines, (x0, x1), (y0, y1));
    let size = legend_size(lines);
    let (xspan, yspan) = (x1 - x0, y1 - y0);
    // Builds the chart on `$area` (drawing nothing), then runs `$body` with it.
    macro_rules! with_chart {
        ($area:expr, |$chart:ident| $body:expr) => {{
            let mut b = ChartBuilder::on($area);
            b.margin(12).x_label_area_size(52).y_label_area_size(84);
            if log_x {
                let $chart = b
                    .build_cartesian_2d((x0.max(1e-9)..x1).log_scale(), y0..y1)
                    .map_err(err)?;
                $body
            } else {
                let $chart = b.build_cartesian_2d(x0..x1, y0..y1).map_err(err)?;
                $body
            }
        }};
    }
    macro_rules! draw {
        ($chart:ident, $legend:expr) => {{
            let mut chart = $chart;
            chart
                .configure_mesh()
                .x_label_formatter(&|x| if log_x { tick(*x, *x) } else { tick(*x, xspan) })
                .y_label_formatter(&|y| tick(*y, yspan))
                .label_style(("sans-serif", FONT))
                .axis_desc_style(("sans-serif", FONT))
                .x_desc(x_desc)
                .y_desc(y_desc)
                .light_line_style(RGBColor(235, 235, 235))
                .draw()
                .map_err(err)?;
            for (k, segs) in parts.iter().enumerate() {
                for seg in segs {
                    chart
                        .draw_series(LineSeries::new(seg.iter().copied(), color(k).stroke_width(2)))
                        .map_err(err)?;
                }
            }
            let at: Option<(i32, i32)> = $legend;
            if let Some(at) = at {
                draw_legend(&area, at, lines)?;
            }
            Ok::<(i32, i32), String>({
                let (xr, yr) = chart.plotting_area().get_pixel_range();
                let base = area.get_base_pixel();
                (xr.end - base.0, yr.start - base.1)
            })
        }};
    }
    // The corner, within `area`, the data leave free for the legend.
    let corner = if matches!(legend, LegendAt::Auto | LegendAt::Probe) {
        with_chart!(&area, |chart| {
            let base = area.get_base_pixel();
            let (xr, yr) = chart.plotting_area().get_pixel_range();
            let px: Vec<Vec<(i32, i32)>> = parts
                .iter()
                .flatten()
                .map(|seg| {
                    seg.iter()
                        .map(|p| {
                            let (x, y) = chart.backend_coord(p);
                            (x - base.0, y - base.1)
                        })
                        .collect()
                })
                .collect();
            free_corner(
                (xr.start - base.0, yr.start - base.1, xr.end - base.0, yr.end - base.1),
                size,
                &px,
            )
        })
    } else {
        None
    };
    match (legend, corner) {
        (LegendAt::Probe, _) => {}
        (_, Some(at)) => {
            with_chart!(&area, |chart| draw!(chart, Some(at)))?;
        }
        (LegendAt::Hidden, None) => {
            with_chart!(&area, |chart| draw!(chart, None))?;
        }
        (_, None) => {
            let (w, _) = area.dim_in_pixel();
            let (left, _) = area.split_horizontally(w as i32 - size.0 - 12);
            let (right, top) = with_chart!(&left, |chart| draw!(chart, None))?;
            if legend != LegendAt::Reserved {
                draw_legend(&area, (right + 12, top), lines)?;
            }
        }
    }
    Ok(corner)
}

/// One chart of `lines` over linear x.
pub fn line_chart(title: &str, x_desc: &str, y_desc: &str, lines: &[Line]) -> Result<String, String> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        panel(&root, Some(title), x_desc, y_desc, lines, false, None, LegendAt::Auto)?;
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
        let root = root.titled(title, ("sans-serif", TITLE_FONT)).map_err(err)?;
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
        let pr = range(phase.iter().flat_map(|l| l.1.iter().map(|p| p.1)));
        let mag_range = Some((xr, (lo.max(-120.0), hi)));
        let phase_range = Some((xr, pr));
        // One legend for both panels (same lines, same colours): in a free corner of the
        // magnitude panel, else of the phase panel, else in a column right of both.
        let probe =
            |area, desc, lines: &[Line], fixed| panel(area, None, x_desc, desc, lines, log_x, fixed, LegendAt::Probe);
        let (top_legend, bottom_legend) = if probe(&top, "magnitude [dB]", &mag, mag_range)?.is_some() {
            (LegendAt::Auto, LegendAt::Hidden)
        } else if probe(&bottom, "phase [°]", &phase, phase_range)?.is_some() {
            (LegendAt::Hidden, LegendAt::Auto)
        } else {
            (LegendAt::Outside, LegendAt::Reserved)
        };
        panel(&top, None, x_desc, "magnitude [dB]", &mag, log_x, mag_range, top_legend)?;
        panel(
            &bottom,
            None,
            x_desc,
            "phase [°]",
            &phase,
            log_x,
            phase_range,
            bottom_legend,
        )?;
        root.present().map_err(err)?;
    }
    Ok(svg)
}

/// A chart with equal axis scales (for the dq plane): `lines` within ±`half` on both axes.
pub fn plane_chart(title: &str, x_desc: &str, y_desc: &str, lines: &[Line], half: f64) -> Result<String, String> {
    let mut svg = String::new();
    {
        // The plane square, the legend in a column to its right (it would cover the curves).
        let root =
            SVGBackend::with_string(&mut svg, (PLANE + legend_size(lines).0 as u32 + 12, PLANE)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        panel(
            &root,
            Some(title),
            x_desc,
            y_desc,
            lines,
            false,
            Some(((-half, half), (-half, half))),
            LegendAt::Outside,
        )?;
        root.present().map_err(err)?;
    }
    Ok(svg)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The text of every `<text>` element of `svg`.
    fn texts(svg: &str) -> Vec<String> {
        svg.split("<text")
            .skip(1)
            .map(|t| {
                let body = &t[t.find('>').unwrap() + 1..];
                body[..body.find("</text>").unwrap()].trim().to_string()
            })
            .collect()
    }

    /// Issue 28: a tick at zero reached by adding steps (−0.3 + 3 × 0.1 is 5.6·10⁻¹⁷ in
    /// binary) prints as 0; no tick of these charts is in exponent form at all, and none is
    /// a non-zero value smaller than a millionth of the axis span.
    #[test]
    fn near_zero_ticks_print_as_zero() {
        assert_eq!(tick(-6e-17, 2.0), "0");
        assert_eq!(tick(5.551115123125783e-17, 1.0), "0");
        assert_eq!(tick(-0.30000000000000004, 1.0), "-0.3");
        assert_eq!(tick(0.1 + 0.2, 1.0), "0.3");
        assert_eq!(tick(2500.0000000001, 10000.0), "2500");
        assert_eq!(tick(1.5e6, 1e7), "1.5e6");
        let mut zeros = 0;
        for (lo, hi) in [
            (-0.3, 0.7),
            (-0.25, 0.65),
            (-0.7, 0.3),
            (-1.3, 0.9),
            (-0.035, 0.045),
            (-3.1, 2.9),
        ] {
            let line = ("y".to_string(), vec![(lo, lo), (hi, hi)]);
            let svg = line_chart("t", "x", "y", &[line]).unwrap();
            for t in texts(&svg) {
                if let Ok(v) = t.parse::<f64>() {
                    assert!(!t.contains('e'), "{lo}..{hi}: tick {t}");
                    assert!(v == 0.0 || v.abs() > 1e-6 * (hi - lo), "{lo}..{hi}: tick {t}");
                    zeros += usize::from(t == "0");
                }
            }
        }
        // Zero is a tick of both axes of every chart.
        assert_eq!(zeros, 12);
    }

    /// The legend goes to a corner free of data, and nowhere when the data fill the plot.
    #[test]
    fn legend_avoids_the_data() {
        let plot = (0, 0, 400, 200);
        // A line across the top: the legend goes to the bottom right.
        let top = vec![vec![(0, 10), (400, 10)]];
        assert_eq!(free_corner(plot, (100, 50), &top), Some((294, 144)));
        // A diagonal from bottom left to top right: the top left corner is free.
        let diagonal = vec![vec![(0, 200), (400, 0)]];
        assert_eq!(free_corner(plot, (100, 50), &diagonal), Some((6, 6)));
        // Horizontal lines every 20 px: no place.
        let full: Vec<Vec<(i32, i32)>> = (0..=10).map(|k| vec![(0, 20 * k), (400, 20 * k)]).collect();
        assert_eq!(free_corner(plot, (100, 50), &full), None);
    }
}
