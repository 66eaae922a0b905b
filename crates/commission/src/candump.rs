//! Captures carried over CAN, read from a log of the standard SocketCAN tools
//! (`candump -l`: `(1700000000.123456) can0 123#DEADBEEF`, one frame a line) or from a
//! live socket: the frames are reassembled and checked (header, sequence numbers 0 …
//! count − 1 without gaps or repeats, the routine of every frame, the end frame's
//! CRC-32) and each capture becomes the CSV recording ([`super::recording`]) the
//! firmware routine would have produced, which `identify` then reads exactly as a CSV
//! file. Problems are located at the log line of the offending frame; a problem found
//! later in the CSV (a saturated current, a step too short) is moved back to the log
//! line of the frame that carried the row ([`Capture::relocate`]).
//!
//! The frame layouts are `motor_control::can_protocol`'s, with the identifiers and
//! scalings of the design's `can` constants group ([`layout`]).

use std::fmt::Write as _;

use motor_control::can_protocol::{self as p, Crc32, End, Header, Layout, Quantity, Routine};
use motor_control::commissioning::{Axis, Capture as StepCapture, CommissioningError, FluxLinkage};
use motor_control::commissioning_mode::ModeConfig;
use motor_control::preflight::Preflight;

use super::recording::{RecordingKind, StepRun, write_step_csv};
use codegen::constants::{Group, constants, group_named};
use codegen::design::Design;
use codegen::diagnostic::{Diagnostic, Diagnostics, Source};

/// The interface of a design on a board, from its `can` constants group (`None` without
/// a board).
pub fn layout(d: &Design) -> Option<Layout> {
    layout_of(&constants(d))
}

/// The [`Layout`] described by the `can` group of `groups`.
pub fn layout_of(groups: &[Group]) -> Option<Layout> {
    let g = group_named(groups, "can")?;
    let id = |name: &str| g.number(name).map(|x| x as u16);
    let f = |name: &str| g.number(name).map(|x| x as f32);
    Some(Layout {
        status_id: id("STATUS_ID")?,
        command_id: id("COMMAND_ID")?,
        header_id: id("CAPTURE_HEADER_ID")?,
        data_id: id("CAPTURE_DATA_ID")?,
        end_id: id("CAPTURE_END_ID")?,
        current_per_lsb: f("CURRENT_PER_LSB")?,
        voltage_per_lsb: f("VOLTAGE_PER_LSB")?,
        speed_per_lsb: f("SPEED_PER_LSB")?,
    })
}

/// The firmware's commissioning configuration of a design on a board, from its `can`
/// and `commissioning` constants groups (what `firmware/config` builds from the same
/// generated constants), and the image's capture capacity.
pub fn mode_config(d: &Design) -> Option<(ModeConfig, usize)> {
    let groups = constants(d);
    let layout = layout_of(&groups)?;
    let g = group_named(&groups, "commissioning")?;
    let can = group_named(&groups, "can")?;
    let u = |name: &str| g.number(name).map(|x| x as u32);
    let f = |name: &str| g.number(name).map(|x| x as f32);
    Some((
        ModeConfig {
            layout,
            sample_period_units: can.number("SAMPLE_PERIOD_UNITS")? as u16,
            standstill_speed: g.number("STANDSTILL_SPEED")? as f32,
            zero_torque: 0.5 * d.board.as_ref()?.board.torque_resolution_nm as f32,
            step_samples: (u("STEP_PRE_SAMPLES")?, u("STEP_SAMPLES")?),
            align_samples: (
                u("ALIGN_RAMP_SAMPLES")?,
                u("ALIGN_SETTLE_SAMPLES")?,
                u("ALIGN_AVERAGE_SAMPLES")?,
            ),
            rotation: (
                g.number("ROTATION_STEP")? as i32,
                u("ROTATION_TURNS")?,
                u("ROTATION_SETTLE_SAMPLES")?,
            ),
            flux: FluxLinkage {
                settle_samples: u("FLUX_SETTLE_SAMPLES")?,
                average_samples: u("FLUX_AVERAGE_SAMPLES")?,
                min_speed: g.number("FLUX_MIN_SPEED")? as f32,
            },
            injection_limit: g.number("INJECTION_LIMIT")? as f32,
            preflight: Preflight {
                voltage: f("PREFLIGHT_VOLTAGE")?,
                level_samples: u("PREFLIGHT_LEVEL_SAMPLES")?,
                rest_samples: u("PREFLIGHT_REST_SAMPLES")?,
                average_samples: u("PREFLIGHT_AVERAGE_SAMPLES")?,
                resistance: f("PREFLIGHT_RESISTANCE")?,
                inductance: f("PREFLIGHT_INDUCTANCE")?,
                resistance_ratio: f("PREFLIGHT_RESISTANCE_RATIO")?,
                inductance_ratio: f("PREFLIGHT_INDUCTANCE_RATIO")?,
                current_trip: f("PREFLIGHT_CURRENT_TRIP")?,
                sum_bound: f("PREFLIGHT_SUM_BOUND")?,
                open_fraction: f("PREFLIGHT_OPEN_FRACTION")?,
                sample_period: d.drive.sample_period_s as f32,
                tau_offset: f("PREFLIGHT_TAU_OFFSET")?,
                rotation_voltage: f("PREFLIGHT_VOLTAGE")?,
                rotation_step: g.number("PREFLIGHT_ROTATION_STEP")? as i32,
                settle_samples: u("ROTATION_SETTLE_SAMPLES")?,
                ratio: f("PREFLIGHT_RATIO")?,
                ratio_bound: f("PREFLIGHT_RATIO_BOUND")?,
                angle_bound: g.number("PREFLIGHT_ANGLE_BOUND")? as i32,
            },
        },
        u("CAPTURE_CAPACITY")? as usize,
    ))
}

/// The recording kind a routine's capture becomes.
pub fn kind_of(r: Routine) -> RecordingKind {
    match r {
        Routine::Step => RecordingKind::Step,
        Routine::ResolverOffset => RecordingKind::ResolverOffset,
        Routine::PolePairRatio => RecordingKind::PolePairRatio,
        Routine::Flux => RecordingKind::Flux,
        Routine::FrequencyResponse => RecordingKind::FrequencyResponse,
        // Captures nothing: `decode_header` refuses a header of it, so no capture of
        // this routine reaches here; the arm only completes the match.
        Routine::Preflight => RecordingKind::Step,
    }
}

/// One frame of a log, with where it was.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LoggedFrame {
    /// Byte offset of the line in the log.
    pub offset: usize,
    /// Identifier (standard frames; extended frames are kept with their 29-bit id).
    pub id: u32,
    /// Extended (29-bit) identifier.
    pub extended: bool,
    /// Data bytes.
    pub data: Vec<u8>,
}

/// One line of a `candump -l` log: `(seconds.micros) interface ID#HEX`. `None` for a
/// line that is not a classic data frame this reader keeps (remote and CAN FD frames
/// are skipped: the drive sends neither); `Err` with the problem for a malformed line.
fn parse_line(line: &str) -> Result<Option<(u32, bool, Vec<u8>)>, String> {
    let mut parts = line.split_whitespace();
    let (Some(stamp), Some(_iface), Some(frame), None) = (parts.next(), parts.next(), parts.next(), parts.next())
    else {
        return Err("not a `(timestamp) interface ID#DATA` line".into());
    };
    let well_stamped = stamp
        .strip_prefix('(')
        .and_then(|s| s.strip_suffix(')'))
        .is_some_and(|s| !s.is_empty() && s.chars().all(|c| c.is_ascii_digit() || c == '.'));
    if !well_stamped {
        return Err(format!("`{stamp}` is not a timestamp `(seconds.micros)`"));
    }
    let Some((id, data)) = frame.split_once('#') else {
        return Err(format!("`{frame}` has no `#` between identifier and data"));
    };
    if data.starts_with('#') || data.starts_with('R') {
        return Ok(None);
    }
    let extended = match id.len() {
        3 => false,
        8 => true,
        _ => {
            return Err(format!(
                "identifier `{id}` is neither 3 (standard) nor 8 (extended) hex digits"
            ));
        }
    };
    let id = u32::from_str_radix(id, 16).map_err(|_| format!("identifier `{id}` is not hexadecimal"))?;
    if data.len() % 2 != 0 || data.len() > 16 {
        return Err(format!("data `{data}` is not 0 to 8 bytes as pairs of hex digits"));
    }
    let bytes = (0..data.len() / 2)
        .map(|k| u8::from_str_radix(&data[2 * k..2 * k + 2], 16))
        .collect::<Result<Vec<u8>, _>>()
        .map_err(|_| format!("data `{data}` is not hexadecimal"))?;
    Ok(Some((id, extended, bytes)))
}

const LOG_ACCEPTED: &str = "a `candump -l` log: one frame a line, `(1700000000.123456) can0 123#DEADBEEF`";

/// Every data frame of a `candump -l` log, located.
pub fn parse_log(file: &str, text: &str) -> Result<Vec<LoggedFrame>, Diagnostics> {
    let src = Source { file, text };
    let mut out = Vec::new();
    let mut offset = 0usize;
    for raw in text.split_inclusive('\n') {
        let at = offset;
        offset += raw.len();
        let line = raw.trim_end_matches(['\n', '\r']);
        if line.trim().is_empty() {
            continue;
        }
        match parse_line(line) {
            Ok(Some((id, extended, data))) => out.push(LoggedFrame {
                offset: at,
                id,
                extended,
                data,
            }),
            Ok(None) => {}
            Err(problem) => return Err(src.error(at..at, "", problem, LOG_ACCEPTED).into()),
        }
    }
    Ok(out)
}

/// One reassembled, checked capture.
#[derive(Debug, Clone, PartialEq)]
pub struct Capture {
    /// The header.
    pub header: Header,
    /// The end frame.
    pub end: End,
    /// Raw channels A, B of every data frame, in sequence order.
    pub rows: Vec<(i16, i16)>,
    /// Log offset of the header frame's line.
    pub header_offset: usize,
    /// Log offset of each data frame's line.
    pub row_offsets: Vec<usize>,
}

const SEQUENCE_ACCEPTED: &str =
    "a header frame, then data frames with sequence numbers 0, 1, … count − 1 in order, then the end frame";

/// Reassembles every capture of `frames` (other frames on the bus are ignored).
pub fn captures(file: &str, text: &str, frames: &[LoggedFrame], layout: &Layout) -> Result<Vec<Capture>, Diagnostics> {
    let src = Source { file, text };
    let err = |at: usize, key: &str, problem: String, accepted: &str| -> Diagnostics {
        src.error(at..at, key, problem, accepted).into()
    };
    let sequence_accepted = SEQUENCE_ACCEPTED;
    // A capture cut short at `at` (a new header or the end of the log).
    let truncated = |at: usize, key: &str, what: &str, c: &Capture| -> Diagnostics {
        err(
            at,
            key,
            format!(
                "{what} the capture started at line {} is truncated: {} of {} data frames and no end frame",
                line_of(text, c.header_offset),
                c.rows.len(),
                c.header.count
            ),
            SEQUENCE_ACCEPTED,
        )
    };
    let mut out = Vec::new();
    // The capture being received and the CRC over its bytes.
    let mut open: Option<(Capture, Crc32)> = None;
    let ours = |f: &LoggedFrame| {
        !f.extended && [layout.header_id, layout.data_id, layout.end_id].contains(&(f.id as u16)) && f.id <= 0x7FF
    };
    for f in frames.iter().filter(|f| ours(f)) {
        let id = f.id as u16;
        let name = |len: u8| format!("{len} data bytes");
        if id == layout.header_id {
            let header = p::decode_header(layout, &f.data).ok_or_else(|| {
                err(
                    f.offset,
                    "CAPTURE_HEADER",
                    format!(
                        "a capture header with {} bytes or an unknown routine code",
                        f.data.len()
                    ),
                    &format!("{} with routine 1–4 in bits 0–3 of byte 0", name(p::HEADER_LEN)),
                )
            })?;
            if let Some((c, _)) = &open {
                return Err(truncated(
                    f.offset,
                    "CAPTURE_HEADER",
                    "a new capture starts here, but",
                    c,
                ));
            }
            let mut crc = Crc32::new();
            crc.update(&f.data);
            open = Some((
                Capture {
                    header,
                    end: End {
                        crc: 0,
                        trip_sample: 0,
                        trip_current: 0.0,
                    },
                    rows: Vec::new(),
                    header_offset: f.offset,
                    row_offsets: Vec::new(),
                },
                crc,
            ));
        } else if id == layout.data_id {
            let Some((c, crc)) = &mut open else {
                return Err(err(
                    f.offset,
                    "CAPTURE_DATA",
                    "a capture data frame without a capture header before it".into(),
                    sequence_accepted,
                ));
            };
            let (routine, seq, a, b) = p::decode_data(&f.data).ok_or_else(|| {
                err(
                    f.offset,
                    "CAPTURE_DATA",
                    format!("a capture data frame with {} bytes", f.data.len()),
                    &name(p::DATA_LEN),
                )
            })?;
            if routine != c.header.routine.code() {
                return Err(err(
                    f.offset,
                    "ROUTINE",
                    format!(
                        "this data frame is of routine {routine}, its capture (line {}) of routine {} ({})",
                        line_of(text, c.header_offset),
                        c.header.routine.code(),
                        kind_of(c.header.routine).name()
                    ),
                    "data frames of the routine their header names",
                ));
            }
            let expected = c.rows.len();
            let seq = usize::from(seq);
            if seq != expected {
                let problem = if seq < expected {
                    format!("sequence number {seq} is repeated (expected {expected} next)")
                } else {
                    format!(
                        "sequence numbers {expected}{} are missing (this frame is {seq})",
                        if seq > expected + 1 {
                            format!("–{}", seq - 1)
                        } else {
                            String::new()
                        }
                    )
                };
                return Err(err(f.offset, "SEQUENCE", problem, sequence_accepted));
            }
            if seq >= usize::from(c.header.count) {
                return Err(err(
                    f.offset,
                    "SEQUENCE",
                    format!("data frame {seq} is beyond the header's count of {}", c.header.count),
                    sequence_accepted,
                ));
            }
            crc.update(&f.data);
            c.rows.push((a, b));
            c.row_offsets.push(f.offset);
        } else {
            let Some((mut c, crc)) = open.take() else {
                return Err(err(
                    f.offset,
                    "CAPTURE_END",
                    "a capture end frame without a capture header before it".into(),
                    sequence_accepted,
                ));
            };
            let end = p::decode_end(layout, &f.data).ok_or_else(|| {
                err(
                    f.offset,
                    "CAPTURE_END",
                    format!("a capture end frame with {} bytes", f.data.len()),
                    &name(p::END_LEN),
                )
            })?;
            if c.rows.len() != usize::from(c.header.count) {
                return Err(err(
                    f.offset,
                    "SEQUENCE",
                    format!(
                        "the capture ends after {} of the header's {} data frames: sequence numbers {}–{} are missing",
                        c.rows.len(),
                        c.header.count,
                        c.rows.len(),
                        c.header.count.saturating_sub(1)
                    ),
                    sequence_accepted,
                ));
            }
            if end.crc != crc.value() {
                return Err(err(
                    f.offset,
                    "CRC32",
                    format!(
                        "checksum mismatch: the end frame says {:#010x}, the header and data frames received give {:#010x} (a corrupted frame)",
                        end.crc,
                        crc.value()
                    ),
                    "a capture whose CRC-32 over the header and data bytes matches its end frame",
                ));
            }
            c.end = end;
            out.push(c);
        }
    }
    if let Some((c, _)) = open {
        return Err(truncated(text.len(), "CAPTURE_END", "the log ends here:", &c));
    }
    if out.is_empty() {
        return Err(err(
            0,
            "",
            format!(
                "no capture in the log (no frame with the capture header identifier {:#05x})",
                layout.header_id
            ),
            "a log of the bus while the drive sent a capture (`candump -l can0`)",
        ));
    }
    Ok(out)
}

fn line_of(text: &str, offset: usize) -> usize {
    text[..offset.min(text.len())].matches('\n').count() + 1
}

impl Capture {
    /// T_s \[s\] from the header.
    pub fn sample_period_s(&self) -> f64 {
        f64::from(self.header.sample_period_units) / p::SAMPLE_PERIOD_UNITS_PER_S
    }

    /// The CSV recording of this capture ([`super::recording`]'s format; a step through
    /// [`write_step_csv`], exactly as a capture buffer is written).
    pub fn to_csv(&self, layout: &Layout) -> String {
        let h = &self.header;
        let [qa, qb] = h.routine.channels();
        let decimation = u32::from(h.decimation.max(1));
        let value = |q: Quantity, raw: i16| layout.from_lsb(q, raw);
        let ts = self.sample_period_s();
        if h.routine == Routine::Step {
            let caps: Vec<StepCapture> = (0u32..)
                .zip(&self.rows)
                .map(|(k, &(a, b))| StepCapture {
                    sample: k * decimation,
                    voltage: value(qa, a),
                    current: value(qb, b),
                })
                .collect();
            let run = StepRun {
                axis: if h.axis_q { Axis::Q } else { Axis::D },
                current_trip: h.current_trip,
                outcome: if h.tripped {
                    Err(CommissioningError::Tripped {
                        sample: u32::from(self.end.trip_sample),
                        current: self.end.trip_current,
                    })
                } else {
                    Ok(())
                },
            };
            return write_step_csv(&caps, ts, &run);
        }
        let kind = kind_of(h.routine);
        let mut s = String::new();
        let _ = writeln!(s, "# motorgen recording: {}", kind.name());
        let _ = writeln!(s, "# sample_period = {} µs", ts * 1e6);
        let _ = writeln!(s, "sample,{}", kind.columns().join(","));
        for (k, &(a, b)) in (0u32..).zip(&self.rows) {
            let _ = writeln!(s, "{},{},{}", k * decimation, value(qa, a), value(qb, b));
        }
        s
    }

    /// `e`, found in the CSV of [`Capture::to_csv`] (`csv`), moved to the log: a data
    /// row's problem to its data frame's line, a header problem to the header frame's.
    pub fn relocate(&self, e: Diagnostics, csv: &str, file: &str, log: &str) -> Diagnostics {
        let lines = csv.lines().count();
        let header_lines = lines.saturating_sub(self.rows.len());
        let src = Source { file, text: log };
        Diagnostics(
            e.0.into_iter()
                .map(|d: Diagnostic| {
                    let row = d.line.checked_sub(header_lines + 1);
                    let at = match row.and_then(|r| self.row_offsets.get(r)) {
                        Some(&o) => o,
                        None if d.line > lines => log.len(),
                        None => self.header_offset,
                    };
                    src.error(
                        at..at,
                        d.key,
                        format!(
                            "{} (in the capture at line {})",
                            d.problem,
                            line_of(log, self.header_offset)
                        ),
                        d.accepted,
                    )
                })
                .collect(),
        )
    }
}

/// The frames of one capture as `motor_control::can_protocol` encodes them: header, data
/// frames of `rows` (channel values in SI units), end frame with the CRC.
pub fn encode_capture(layout: &Layout, header: &Header, rows: &[(f32, f32)], end: &End) -> Vec<p::Frame> {
    let h = p::encode_header(layout, header);
    let mut crc = Crc32::new();
    crc.update(h.bytes());
    let mut out = vec![h];
    for (k, &(a, b)) in rows.iter().enumerate() {
        let f = p::encode_data(layout, header.routine, k as u16, a, b);
        crc.update(f.bytes());
        out.push(f);
    }
    out.push(p::encode_end(
        layout,
        &End {
            crc: crc.value(),
            ..*end
        },
    ));
    out
}

/// A frame as a `candump -l` line at time `t` \[s\] on `iface`.
pub fn candump_line(t: f64, iface: &str, f: &p::Frame) -> String {
    frame_line(t, iface, u32::from(f.id), false, f.bytes())
}

/// A received frame as a `candump -l` line at time `t` \[s\] on `iface`: identifier
/// in 3 (standard) or 8 (extended) hex digits, `#`, the data bytes in hex.
pub fn frame_line(t: f64, iface: &str, id: u32, extended: bool, data: &[u8]) -> String {
    let hex: String = data.iter().map(|b| format!("{b:02X}")).collect();
    if extended {
        format!("({t:.6}) {iface} {id:08X}#{hex}")
    } else {
        format!("({t:.6}) {iface} {id:03X}#{hex}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn layout() -> Layout {
        p::EXAMPLE_LAYOUT
    }

    fn log(frames: &[p::Frame]) -> String {
        let mut s = String::from("(1700000000.000000) can0 100#0000\n");
        for (k, f) in frames.iter().enumerate() {
            s.push_str(&candump_line(1.7e9 + k as f64 * 1e-4, "can0", f));
            s.push('\n');
        }
        s
    }

    fn sample() -> Vec<p::Frame> {
        let h = Header {
            routine: Routine::Flux,
            axis_q: false,
            tripped: false,
            decimation: 1,
            sample_period_units: 500,
            count: 3,
            current_trip: 0.0,
        };
        let end = End {
            crc: 0,
            trip_sample: 0,
            trip_current: 0.0,
        };
        encode_capture(&layout(), &h, &[(600.0, 60.0), (601.0, 60.1), (602.0, 60.2)], &end)
    }

    #[test]
    fn reassembles_and_writes_the_csv() {
        let text = log(&sample());
        let frames = parse_log("x.log", &text).unwrap();
        assert_eq!(frames.len(), 6);
        let caps = captures("x.log", &text, &frames, &layout()).unwrap();
        assert_eq!(caps.len(), 1);
        let csv = caps[0].to_csv(&layout());
        // 500 × 100 ns = 50 µs; values within half an LSB (0.5 rad/s, 5 mV).
        let rec = super::super::recording::parse("x.log", &csv, RecordingKind::Flux, 0.0).unwrap();
        assert!((rec.sample_period_s - 50e-6).abs() < 1e-15);
        assert_eq!(rec.samples, [0.0, 1.0, 2.0]);
        for (row, want) in rec.values.iter().zip([[600.0, 60.0], [601.0, 60.1], [602.0, 60.2]]) {
            assert!(
                (row[0] - want[0]).abs() <= 0.5 && (row[1] - want[1]).abs() <= 0.005,
                "{row:?}"
            );
        }
    }

    /// Each corruption is located at the line of the frame (line 1 is the setpoint).
    #[test]
    fn corruptions_are_located() {
        let l = layout();
        let check = |frames: Vec<p::Frame>, line: usize, words: &str| {
            let text = log(&frames);
            let fr = parse_log("x.log", &text).unwrap();
            let e = captures("x.log", &text, &fr, &l).unwrap_err();
            assert_eq!(e.0[0].line, line, "{e}");
            assert!(e.0[0].problem.contains(words), "{e}");
        };
        let good = sample();
        // Dropped data frame 1 (line 4): frame 2 at line 4 reports 1 missing.
        let mut v = good.clone();
        v.remove(2);
        check(v, 4, "sequence numbers 1 are missing");
        // Repeated frame.
        let mut v = good.clone();
        v.insert(2, good[1]);
        check(v, 4, "sequence number 0 is repeated");
        // A flipped byte in channel A of frame 1: the CRC at the end frame (line 6).
        let mut v = good.clone();
        v[2].data[3] ^= 0x10;
        check(v, 6, "checksum mismatch");
        // Truncated: the end frame missing; located at the end of the log (line 6).
        let mut v = good.clone();
        v.pop();
        check(v, 6, "truncated");
        // Malformed line.
        let e = parse_log("x.log", "(1.0) can0 103#ABC\n").unwrap_err();
        assert_eq!((e.0[0].line, e.0[0].column), (1, 1));
        assert!(e.0[0].problem.contains("pairs of hex digits"), "{e}");
    }
}
