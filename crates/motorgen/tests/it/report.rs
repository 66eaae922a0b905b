//! `motorgen verify` and `motorgen report` as a user runs them; the report page is
//! loaded in headless Chromium (Debian's `chromium`, installed by `.ci/run`): it must
//! load without console messages, every plot must be in the DOM after load as an
//! `<svg>` with lines and text, and a screenshot is taken (kept in the test temp dir).

use crate::common::{motor_stems, motorgen, repo};

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn tmp(name: &str) -> PathBuf {
    crate::common::tmp("report", name)
}

/// Headless Chromium: `$CHROMIUM` or `/usr/bin/chromium`. Missing is a failure, not a skip.
fn chromium() -> PathBuf {
    let path = std::env::var_os("CHROMIUM").map_or_else(|| PathBuf::from("/usr/bin/chromium"), PathBuf::from);
    assert!(
        path.exists(),
        "headless Chromium is needed to test the report page and was not found at {}: install it \
         (Debian: `apt-get install chromium`; .ci/run does) or set CHROMIUM to its path",
        path.display()
    );
    path
}

/// Runs Chromium headless on `page` with `extra` arguments; a fresh profile under `dir`.
fn run_chromium(dir: &Path, page: &Path, extra: &[&str]) -> Output {
    let profile = dir.join("chromium-profile");
    let url = format!("file://{}", page.canonicalize().unwrap().display());
    let out = Command::new(chromium())
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            &format!("--user-data-dir={}", profile.display()),
        ])
        .args(extra)
        .arg(url)
        .output()
        .expect("chromium runs");
    assert!(
        out.status.success(),
        "chromium failed on {}:\n{}",
        page.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// Console messages Chromium logged while loading `page` (`--enable-logging=stderr`
/// prints them as `…:CONSOLE(…)` / `INFO:CONSOLE:…` lines), and the screenshot taken.
fn console_and_screenshot(dir: &Path, page: &Path, png: &Path) -> Vec<String> {
    let out = run_chromium(
        dir,
        page,
        &[
            "--enable-logging=stderr",
            "--v=0",
            "--window-size=1200,3000",
            &format!("--screenshot={}", png.display()),
        ],
    );
    String::from_utf8_lossy(&out.stderr)
        .lines()
        .filter(|l| l.contains(":CONSOLE"))
        .map(str::to_string)
        .collect()
}

/// The console check can fail: a page that logs an error is caught.
#[test]
fn console_errors_are_detected() {
    let dir = tmp("console");
    let page = dir.join("bad.html");
    std::fs::write(
        &page,
        "<!DOCTYPE html><html><body><script>console.error('report-test-marker')</script></body></html>",
    )
    .unwrap();
    let lines = console_and_screenshot(&dir, &page, &dir.join("bad.png"));
    assert!(
        lines.iter().any(|l| l.contains("report-test-marker")),
        "console error not seen: {lines:?}"
    );
}

/// The plots every report has (page order), whatever the motor.
const PLOTS: &[&str] = &[
    "current-step-0",
    "current-step-1",
    "current-bode-d",
    "current-bode-q",
    "feed-forward-0",
    "feed-forward-1",
    "observer-0",
    "observer-1",
    "observer-2",
    "observer-bode",
    "fir-response",
    "dq-plane",
];

/// The plots of the field-weakening scenario (motors with ψ_M).
const FIELD_WEAKENING_PLOTS: &[&str] = &[
    "torque-speed",
    "field-weakening-0",
    "field-weakening-1",
    "field-weakening-2",
    "field-weakening-3",
];

/// The plots of the estimator scenario (motors with ψ_M and a `[sensorless]` section).
const SENSORLESS_PLOTS: &[&str] = &["sensorless-0", "sensorless-1", "sensorless-2"];

#[test]
fn report_loads_in_headless_chromium_with_every_plot() {
    for stem in motor_stems() {
        let dir = tmp(&stem);
        let spec = format!("motors/{stem}.toml");
        let out = motorgen(&["report", &spec, "--out", dir.to_str().unwrap()]);
        let page = dir.join(format!("{stem}.html"));
        let html = std::fs::read_to_string(&page)
            .unwrap_or_else(|e| panic!("{stem}: no page ({e}):\n{}", String::from_utf8_lossy(&out.stderr)));
        // Exit status follows the verification verdict shown in the page.
        let failed = html.contains("<td class=\"result\">FAIL</td>");
        assert_eq!(
            out.status.success(),
            !failed,
            "{stem}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        // Self-contained: nothing fetched from elsewhere.
        for needle in ["src=\"http", "href=\"http", "<link ", "<img "] {
            assert!(!html.contains(needle), "{stem}: external resource {needle}");
        }

        let dom = String::from_utf8(run_chromium(&dir, &page, &["--dump-dom"]).stdout).unwrap();
        let ids: Vec<&str> = dom
            .match_indices("<figure class=\"plot\" id=\"")
            .map(|(i, m)| {
                let rest = &dom[i + m.len()..];
                &rest[..rest.find('"').unwrap()]
            })
            .collect();
        // Motors with ψ_M also get the field-weakening plots, and those with a
        // `[sensorless]` section the estimator's.
        let mut want: Vec<&str> = PLOTS.to_vec();
        if html.contains("Field weakening, ramp") {
            want.extend(FIELD_WEAKENING_PLOTS);
        }
        if html.contains("Angle estimation error") {
            want.extend(SENSORLESS_PLOTS);
        }
        assert_eq!(ids, want, "{stem}: plots in the loaded page");
        for id in &want {
            let start = dom.find(&format!("<figure class=\"plot\" id=\"{id}\"")).unwrap();
            let fig = &dom[start..start + dom[start..].find("</figure>").unwrap()];
            for part in ["<svg", "</svg>", "<polyline", "<text", "<figcaption>"] {
                assert!(fig.contains(part), "{stem}: plot {id} lacks {part}");
            }
        }
        // The verification table and every constant group made it into the DOM.
        assert!(dom.contains("id=\"verification-table\""), "{stem}");
        for group in ["current_loop", "observer", "scaling", "filter", "limits"] {
            assert!(
                dom.contains(&format!("<code>{group}</code>")),
                "{stem}: constants {group}"
            );
        }

        let png = dir.join(format!("{stem}.png"));
        let console = console_and_screenshot(&dir, &page, &png);
        assert!(console.is_empty(), "{stem}: console messages:\n{}", console.join("\n"));
        let bytes = std::fs::read(&png).unwrap();
        assert!(
            bytes.starts_with(b"\x89PNG") && bytes.len() > 20_000,
            "{stem}: screenshot {} bytes",
            bytes.len()
        );
        println!("{stem}: screenshot {}", png.display());
    }
}

/// `motorgen verify`: the table on stdout, exit 0 when every scenario passes.
#[test]
fn verify_prints_the_table() {
    let out = motorgen(&["verify", "motors/fischer-ti085.toml"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for word in [
        "current_step: q-axis rise time 10–90 %",
        "decoupling:",
        "dc_link_step:",
        "ato_lock: cycle slips",
        "ato_ramp:",
        "ato_type2:",
        "field_weakening: peak |v| on the ramp",
        "field_weakening: peak |i_dq − i_dq^ref|",
        "7 of 7 scenarios passed",
    ] {
        assert!(stdout.contains(word), "{word} missing:\n{stdout}");
    }
}

/// A bad spec: located message, non-zero exit, nothing on stdout, no report written.
#[test]
fn bad_spec_is_reported_and_nothing_written() {
    let dir = tmp("bad-spec");
    let text = std::fs::read_to_string(repo().join("motors/fischer-ti085.toml"))
        .unwrap()
        .replacen("inductance = \"0.393 mH\"", "inductance = 0.000393", 1);
    let line = text[..text.find("inductance = 0.000393").unwrap()]
        .matches('\n')
        .count()
        + 1;
    let spec = dir.join("bad.toml");
    std::fs::write(&spec, text).unwrap();
    let out_dir = dir.join("out");
    for args in [
        vec!["verify", spec.to_str().unwrap()],
        vec!["report", spec.to_str().unwrap(), "--out", out_dir.to_str().unwrap()],
    ] {
        let out = motorgen(&args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?}");
        assert!(
            out.stdout.is_empty(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stdout)
        );
        assert!(stderr.contains(&format!("bad.toml:{line}:14")), "{args:?}: {stderr}");
        assert!(
            stderr.contains("`motor.datasheet.inductance`") && stderr.contains("accepted:"),
            "{stderr}"
        );
        assert!(!stderr.contains("panicked"), "{stderr}");
    }
    assert!(!out_dir.exists(), "report wrote into {}", out_dir.display());
}

/// `report --measured DIR` (issue 28): the Fischer d and q frequency responses measured
/// on the simulated drive (`commission --sim … frequency-response`, L_q × 0.7 on q) are
/// overlaid on the current-loop Bode plots — the loaded page's d and q figures carry the
/// measured series' legend entry and a caption with the measured margins and the fitted
/// plant beside the spec's; a directory without the files is bad input (exit 1).
#[test]
fn report_overlays_the_measured_frequency_response() {
    let dir = tmp("measured");
    let spec = "motors/fischer-ti085.toml";
    let meas = dir.join("meas");
    let meas_s = meas.to_str().unwrap();
    for (axis, scale) in [("d", &[][..]), ("q", &["--sim-scale", "Lq=0.7"][..])] {
        let args = [
            "commission",
            spec,
            "--board",
            "boards/motorgen-reference.toml",
            "--sim",
            "--out",
            meas_s,
            "frequency-response",
            "--axis",
            axis,
        ];
        let o = motorgen(&[&args[..], scale].concat());
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let out = dir.join("page");
    let o = motorgen(&["report", spec, "--out", out.to_str().unwrap(), "--measured", meas_s]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let page = out.join("fischer-ti085.html");
    let dom = String::from_utf8(run_chromium(&dir, &page, &["--dump-dom"]).stdout).unwrap();
    for axis in ["d", "q"] {
        let id = format!("<figure class=\"plot\" id=\"current-bode-{axis}\"");
        let start = dom.find(&id).unwrap_or_else(|| panic!("no {id}"));
        let fig = &dom[start..start + dom[start..].find("</figure>").unwrap()];
        assert!(
            fig.contains("open loop L (measured on the drive)"),
            "{axis}: no measured series"
        );
        assert!(fig.contains("measured on the drive: gain margin"), "{axis}: no caption");
        assert!(fig.contains("fitted plant R "), "{axis}: no fitted plant");
    }
    let o = motorgen(&[
        "report",
        spec,
        "--out",
        out.to_str().unwrap(),
        "--measured",
        dir.join("nothing").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", String::from_utf8_lossy(&o.stderr));
}

/// Measures every plot of `page` as Chromium lays it out at a 1400 px wide viewport: a
/// copy of the page with a script appended (the report itself has none) writes, per
/// figure, `id`, the smallest rendered font size of its SVG text [px] (computed
/// `font-size` × the SVG's on-screen scale) and the number of legend boxes (stroked
/// `<rect>`s) met by a data line (`<polyline>` segment, both in the SVG's units), into a
/// `<pre id="probe">` read back from `--dump-dom`.
fn probe_plots(dir: &Path, page: &Path) -> Vec<(String, f64, usize, usize)> {
    const SCRIPT: &str = r#"<script>
(function () {
  function hits(r, p, q) {
    var t0 = 0, t1 = 1, dx = q[0] - p[0], dy = q[1] - p[1];
    var c = [[-dx, p[0] - r.x0], [dx, r.x1 - p[0]], [-dy, p[1] - r.y0], [dy, r.y1 - p[1]]];
    for (var i = 0; i < 4; i++) {
      var den = c[i][0], num = c[i][1];
      if (den === 0) { if (num < 0) return false; }
      else { var t = num / den; if (den < 0) t0 = Math.max(t0, t); else t1 = Math.min(t1, t); if (t0 > t1) return false; }
    }
    return true;
  }
  var out = [];
  document.querySelectorAll('figure.plot').forEach(function (fig) {
    var svg = fig.querySelector('svg');
    var scale = svg.getBoundingClientRect().width / svg.viewBox.baseVal.width;
    var min = Infinity;
    svg.querySelectorAll('text').forEach(function (t) {
      if (t.textContent.trim() === '') return;
      min = Math.min(min, parseFloat(getComputedStyle(t).fontSize) * scale);
    });
    var boxes = [];
    svg.querySelectorAll('rect').forEach(function (r) {
      var s = r.getAttribute('stroke');
      if (s && s !== 'none') {
        var x = +r.getAttribute('x'), y = +r.getAttribute('y');
        boxes.push({x0: x, y0: y, x1: x + +r.getAttribute('width'), y1: y + +r.getAttribute('height')});
      }
    });
    var covered = 0;
    boxes.forEach(function (b) {
      var met = false;
      svg.querySelectorAll('polyline').forEach(function (pl) {
        var pts = pl.getAttribute('points').trim().split(/\s+/).map(function (s) { return s.split(',').map(Number); });
        for (var i = 0; i < pts.length; i++) {
          if (hits(b, pts[i], pts[Math.min(i + 1, pts.length - 1)])) { met = true; break; }
        }
      });
      if (met) covered++;
    });
    out.push(fig.id + ' ' + min + ' ' + boxes.length + ' ' + covered);
  });
  var pre = document.createElement('pre');
  pre.id = 'probe';
  pre.textContent = out.join('\n');
  document.body.appendChild(pre);
})();
</script>"#;
    let html = std::fs::read_to_string(page).unwrap();
    let probe = dir.join("probe.html");
    std::fs::write(&probe, html.replace("</body>", &format!("{SCRIPT}</body>"))).unwrap();
    let dom = String::from_utf8(run_chromium(dir, &probe, &["--window-size=1400,3000", "--dump-dom"]).stdout).unwrap();
    let start = dom.find("<pre id=\"probe\">").expect("the probe ran") + "<pre id=\"probe\">".len();
    let body = &dom[start..start + dom[start..].find("</pre>").unwrap()];
    body.lines()
        .map(|l| {
            let f: Vec<&str> = l.split(' ').collect();
            (
                f[0].to_string(),
                f[1].parse().unwrap(),
                f[2].parse().unwrap(),
                f[3].parse().unwrap(),
            )
        })
        .collect()
}

/// The probe's legend check can fail: a legend box drawn over a line is counted, one
/// beside it is not, and an 8 px font in an SVG shown at its own width measures 8 px.
#[test]
fn legend_and_font_probe_detects_problems() {
    let dir = tmp("probe-self-test");
    let page = dir.join("p.html");
    std::fs::write(
        &page,
        "<!DOCTYPE html><html><body>\
         <figure class=\"plot\" id=\"over\"><svg width=\"200\" height=\"100\" viewBox=\"0 0 200 100\">\
         <polyline points=\"0,50 200,50\" stroke=\"red\" fill=\"none\"/>\
         <rect x=\"80\" y=\"40\" width=\"40\" height=\"20\" fill=\"none\" stroke=\"#000000\"/>\
         <text x=\"10\" y=\"10\" font-size=\"8\">a</text></svg></figure>\
         <figure class=\"plot\" id=\"beside\"><svg width=\"200\" height=\"100\" viewBox=\"0 0 200 100\">\
         <polyline points=\"0,50 200,50\" stroke=\"red\" fill=\"none\"/>\
         <rect x=\"80\" y=\"60\" width=\"40\" height=\"20\" fill=\"none\" stroke=\"#000000\"/>\
         <text x=\"10\" y=\"10\" font-size=\"16\">a</text></svg></figure>\
         </body></html>",
    )
    .unwrap();
    let got = probe_plots(&dir, &page);
    assert_eq!(got.len(), 2, "{got:?}");
    assert_eq!((got[0].0.as_str(), got[0].2, got[0].3), ("over", 1, 1), "{got:?}");
    assert!((got[0].1 - 8.0).abs() < 0.01, "{got:?}");
    assert_eq!((got[1].0.as_str(), got[1].2, got[1].3), ("beside", 1, 0), "{got:?}");
    assert!((got[1].1 - 16.0).abs() < 0.01, "{got:?}");
}

/// Issue 28: the plots are legible as a user sees them, at a 1400 px wide window —
/// every tick label, axis label and legend text renders at 13 px or more, every plot has
/// a legend box, and no legend box meets a plotted line.
#[test]
fn report_plots_are_legible_at_1400_px() {
    for stem in motor_stems() {
        let dir = tmp(&format!("legible-{stem}"));
        let spec = format!("motors/{stem}.toml");
        let out = motorgen(&["report", &spec, "--out", dir.to_str().unwrap()]);
        let page = dir.join(format!("{stem}.html"));
        assert!(page.exists(), "{stem}: {}", String::from_utf8_lossy(&out.stderr));
        let got = probe_plots(&dir, &page);
        assert!(got.len() >= PLOTS.len(), "{stem}: {got:?}");
        for (id, font, boxes, covered) in &got {
            assert!(
                *font >= 13.0,
                "{stem}: plot {id}: smallest text {font:.2} px at 1400 px"
            );
            assert!(*boxes >= 1, "{stem}: plot {id}: no legend box");
            assert_eq!(
                *covered, 0,
                "{stem}: plot {id}: {covered} of {boxes} legend boxes on the data"
            );
        }
    }
}
