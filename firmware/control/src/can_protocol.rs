//! The drive's CAN frames as bytes (pure): status, commissioning command and the
//! capture stream (header, sequence-numbered data frames, end frame with a CRC-32),
//! encoded by the firmware and decoded by `motorgen` on the host from the same code.
//!
//! Nothing here is a constant of a motor or a board: identifiers and scalings come in a
//! [`Layout`], built from the generated `can` constants group (firmware) or from the same
//! group of the design (host). The generated DBC file (`templates/motor.dbc.j2`) describes
//! exactly these layouts; `crates/commission/tests/it/can_dbc.rs` parses it and checks every signal
//! against the encoders here.
//!
//! All multi-byte fields are little-endian (DBC byte order `1`, "Intel"). Scaled values
//! are Q1.15 stored integers of the design's per-unit scalings (thesis A (4.16)):
//! x = A·p/2^15 with A the full scale of the quantity, so one signal's factor is
//! A/2^15; angles are the top 16 bits of the π-scaled Q1.31 angle (π/2^15 rad per LSB).
//!
//! | frame | DLC | bytes |
//! |---|---|---|
//! | command | 8 | 0 routine, 1 axis, 2–3 voltage (i16), 4–5 current trip (i16), 6–7 decimation (u16) |
//! | status | 4 | 0 state, 1 reason, 2 routine, 3 fault flags |
//! | capture header | 8 | 0 routine (bits 0–3), axis (bit 4), tripped (bit 5); 1 decimation; 2–3 T_s in 100 ns (u16); 4–5 sample count (u16); 6–7 trip level (i16) |
//! | capture data | 7 | 0 routine (multiplexor), 1–2 sequence (u16), 3–4 channel A (i16), 5–6 channel B (i16) |
//! | capture end | 8 | 0–3 CRC-32 of every header and data byte sent, 4–5 trip sample (u16), 6–7 trip current (i16) |
//! | fault report | 8 | 0 cause, 1 flags (PC valid, state valid, outputs on, tripped, measurement valid, measurement index), 2–5 PC (u32) or the start-up check's measurement (f32), 6–7 i_q (i16) |

/// A classic CAN data frame (standard identifier, up to 8 bytes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Frame {
    /// Standard (11-bit) identifier.
    pub id: u16,
    /// Data length code 0–8.
    pub len: u8,
    /// Data bytes; the first `len` are sent.
    pub data: [u8; 8],
}

impl Frame {
    /// The bytes sent.
    pub fn bytes(&self) -> &[u8] {
        self.data.get(..usize::from(self.len)).unwrap_or(&[])
    }
}

/// Data length of the command frame.
pub const COMMAND_LEN: u8 = 8;
/// Data length of the status frame.
pub const STATUS_LEN: u8 = 4;
/// Data length of the capture header frame.
pub const HEADER_LEN: u8 = 8;
/// Data length of a capture data frame.
pub const DATA_LEN: u8 = 7;
/// Data length of the capture end frame.
pub const END_LEN: u8 = 8;
/// Header sample-period units per second: the unit is 100 ns, so a u16 holds up to
/// 6.5535 ms.
pub const SAMPLE_PERIOD_UNITS_PER_S: f64 = 1e7;

/// Identifiers and scalings of the interface (the generated `can` group).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Layout {
    /// Status frame identifier.
    pub status_id: u16,
    /// Commissioning command identifier.
    pub command_id: u16,
    /// Capture header identifier.
    pub header_id: u16,
    /// Capture data identifier.
    pub data_id: u16,
    /// Capture end identifier.
    pub end_id: u16,
    /// Current per LSB \[A\] (phase-current full scale/2^15).
    pub current_per_lsb: f32,
    /// Voltage per LSB \[V\] (phase-voltage full scale/2^15).
    pub voltage_per_lsb: f32,
    /// Electrical speed per LSB \[rad/s\] (speed full scale/2^15).
    pub speed_per_lsb: f32,
}

/// An example interface for tests (here, in the commissioning mode's and in the host's
/// CAN tests): identifiers 0x101 (status) to 0x105 (capture end); 10 mA, 10 mV and
/// 1 rad/s per LSB, so a value in LSB reads off its SI value by hand. (Always compiled:
/// a feature that only the host's tests turned on gave the control core two builds in
/// one test run; an unused constant costs the image nothing.)
pub const EXAMPLE_LAYOUT: Layout = Layout {
    status_id: 0x101,
    command_id: 0x102,
    header_id: 0x103,
    data_id: 0x104,
    end_id: 0x105,
    current_per_lsb: 0.01,
    voltage_per_lsb: 0.01,
    speed_per_lsb: 1.0,
};

/// Angle per LSB of a 16-bit angle signal \[rad\]: π/2^15.
pub const ANGLE_PER_LSB: f32 = core::f32::consts::PI / 32768.0;

/// The commissioning routines of thesis A chapter 6, as numbered on the bus.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Routine {
    /// Blocked-rotor voltage step (§6.2): channels voltage \[V\], current \[A\].
    Step = 1,
    /// Resolver offset by α alignment (§6.3): channels u_α \[V\], θ_r \[rad\].
    ResolverOffset = 2,
    /// Pole-pair ratio and direction (§6.4): channels θ_e \[rad\], θ_r \[rad\].
    PolePairRatio = 3,
    /// ψ_M at zero current (§6.5): channels ω_e \[rad/s\], u_q \[V\].
    Flux = 4,
    /// The current loop's frequency response (loop-breaking multisine,
    /// [`crate::commissioning::FrequencyResponse`]): channels u_PI \[V\], v = u_PI + d \[V\]
    /// of the injected axis. The command's decimation bytes carry the line set: byte 6 the
    /// first harmonic, byte 7 the lines per octave (the capture is never decimated).
    FrequencyResponse = 5,
    /// The pre-flight check before the loop closes ([`crate::preflight`]): d pulses and one
    /// electrical turn with generated parameters (the command's voltage, trip and
    /// decimation are not used); nothing is captured — the verdict is the status frame
    /// (idle, reason none: passed; fault, reason `PreflightFailed`: the fault record's
    /// cause says which check).
    Preflight = 6,
}

impl Routine {
    /// All routines, in code order.
    pub const ALL: [Routine; 6] = [
        Routine::Step,
        Routine::ResolverOffset,
        Routine::PolePairRatio,
        Routine::Flux,
        Routine::FrequencyResponse,
        Routine::Preflight,
    ];

    /// The routine with bus code `code`.
    pub fn from_code(code: u8) -> Option<Routine> {
        match code {
            1 => Some(Routine::Step),
            2 => Some(Routine::ResolverOffset),
            3 => Some(Routine::PolePairRatio),
            4 => Some(Routine::Flux),
            5 => Some(Routine::FrequencyResponse),
            6 => Some(Routine::Preflight),
            _ => None,
        }
    }

    /// Bus code.
    pub fn code(self) -> u8 {
        self as u8
    }

    /// Which quantity each data channel (A, B) carries.
    pub fn channels(self) -> [Quantity; 2] {
        match self {
            Routine::Step => [Quantity::Voltage, Quantity::Current],
            Routine::ResolverOffset => [Quantity::Voltage, Quantity::Angle],
            Routine::PolePairRatio => [Quantity::Angle, Quantity::Angle],
            Routine::Flux => [Quantity::Speed, Quantity::Voltage],
            Routine::FrequencyResponse => [Quantity::Voltage, Quantity::Voltage],
            // Nothing is captured; the d pulses' voltage and current if it ever were.
            Routine::Preflight => [Quantity::Voltage, Quantity::Current],
        }
    }
}

/// A scaled quantity on the bus.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quantity {
    /// Current \[A\].
    Current,
    /// Voltage \[V\].
    Voltage,
    /// Electrical speed \[rad/s\].
    Speed,
    /// Angle \[rad\], wrapping at ±π.
    Angle,
}

impl Layout {
    /// SI value of one LSB of `q`.
    pub fn per_lsb(&self, q: Quantity) -> f32 {
        match q {
            Quantity::Current => self.current_per_lsb,
            Quantity::Voltage => self.voltage_per_lsb,
            Quantity::Speed => self.speed_per_lsb,
            Quantity::Angle => ANGLE_PER_LSB,
        }
    }

    /// `x` in LSB of `q`, rounded and saturated to i16 (NaN → 0). An angle is taken
    /// modulo 2π (the wrap of the π-scaled format).
    pub fn to_lsb(&self, q: Quantity, x: f32) -> i16 {
        let lsb = x / self.per_lsb(q);
        match q {
            // Wraps: the angle modulo 2^16 LSB = 2π (float → i32 saturates, far beyond
            // any recorded angle).
            Quantity::Angle => (libm::roundf(lsb) as i32) as i16,
            _ => libm::roundf(lsb) as i16,
        }
    }

    /// The SI value of `raw` LSB of `q`.
    pub fn from_lsb(&self, q: Quantity, raw: i16) -> f32 {
        f32::from(raw) * self.per_lsb(q)
    }
}

/// The drive's state in the status frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum State {
    /// PWM off, waiting for a setpoint or a command.
    Idle = 0,
    /// Torque control from the setpoint frame.
    Torque = 1,
    /// A commissioning routine is running.
    Commissioning = 2,
    /// A capture is being sent.
    Streaming = 3,
    /// A fault, break or timeout switched the outputs off.
    Fault = 4,
}

/// Why the last command was refused or aborted (status byte 1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reason {
    /// Nothing refused.
    None = 0,
    /// The rotor was turning (|ω_e| above the standstill threshold).
    NotAtStandstill = 1,
    /// The torque setpoint was not zero.
    TorqueNotZero = 2,
    /// A fault is latched.
    FaultActive = 3,
    /// Unknown routine code or parameters out of range.
    BadCommand = 4,
    /// A routine or capture is already in progress.
    Busy = 5,
    /// Aborted: a fault, break or setpoint/command timeout switched the outputs off.
    Aborted = 6,
    /// The routine's current trip fired (capture still sent, with its trip data).
    Tripped = 7,
    /// The pre-flight check refused the drive: outputs off until reset, the fault
    /// record's cause (11–18) says which check.
    PreflightFailed = 8,
    /// A frequency response's amplitude is above the drive's generated injection limit
    /// (`INJECTION_LIMIT`): refused, nothing runs.
    AmplitudeAboveLimit = 9,
}

impl State {
    /// The state with status code `code`.
    pub fn from_code(code: u8) -> Option<State> {
        [
            State::Idle,
            State::Torque,
            State::Commissioning,
            State::Streaming,
            State::Fault,
        ]
        .into_iter()
        .find(|s| *s as u8 == code)
    }
}

impl Reason {
    /// The reason with status code `code`.
    pub fn from_code(code: u8) -> Option<Reason> {
        [
            Reason::None,
            Reason::NotAtStandstill,
            Reason::TorqueNotZero,
            Reason::FaultActive,
            Reason::BadCommand,
            Reason::Busy,
            Reason::Aborted,
            Reason::Tripped,
            Reason::PreflightFailed,
            Reason::AmplitudeAboveLimit,
        ]
        .into_iter()
        .find(|r| *r as u8 == code)
    }
}

/// A status frame's state, reason, routine code and fault flags; `None` for another
/// identifier, another length or an unknown state or reason code.
pub fn decode_status(layout: &Layout, id: u16, data: &[u8]) -> Option<(State, Reason, u8, u8)> {
    if id != layout.status_id {
        return None;
    }
    let [state, reason, routine, faults] = *data else {
        return None;
    };
    Some((State::from_code(state)?, Reason::from_code(reason)?, routine, faults))
}

/// Status frame.
pub fn encode_status(layout: &Layout, state: State, reason: Reason, routine: u8, faults: u8) -> Frame {
    Frame {
        id: layout.status_id,
        len: STATUS_LEN,
        data: [state as u8, reason as u8, routine, faults, 0, 0, 0, 0],
    }
}

/// A commissioning command as received.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Command {
    /// Requested routine (`None`: abort / unknown code).
    pub routine: Option<Routine>,
    /// Axis of a step or a frequency response: 0 d, 1 q.
    pub axis_q: bool,
    /// Voltage of the step or alignment \[V\].
    pub voltage: f32,
    /// Current trip \[A\].
    pub current_trip: f32,
    /// Capture decimation (periods per captured sample, ≥ 1).
    pub decimation: u16,
}

/// Command frame.
pub fn encode_command(layout: &Layout, c: &Command) -> Frame {
    let [v0, v1] = layout.to_lsb(Quantity::Voltage, c.voltage).to_le_bytes();
    let [t0, t1] = layout.to_lsb(Quantity::Current, c.current_trip).to_le_bytes();
    let [d0, d1] = c.decimation.to_le_bytes();
    Frame {
        id: layout.command_id,
        len: COMMAND_LEN,
        data: [
            c.routine.map_or(0, Routine::code),
            u8::from(c.axis_q),
            v0,
            v1,
            t0,
            t1,
            d0,
            d1,
        ],
    }
}

/// The command in a received frame, `None` if it is not a command frame (identifier or
/// length).
pub fn decode_command(layout: &Layout, id: u16, data: &[u8]) -> Option<Command> {
    if id != layout.command_id {
        return None;
    }
    let [r, axis, v0, v1, t0, t1, d0, d1] = *data else {
        return None;
    };
    Some(Command {
        routine: Routine::from_code(r),
        axis_q: axis != 0,
        voltage: layout.from_lsb(Quantity::Voltage, i16::from_le_bytes([v0, v1])),
        current_trip: layout.from_lsb(Quantity::Current, i16::from_le_bytes([t0, t1])),
        decimation: u16::from_le_bytes([d0, d1]),
    })
}

/// What the capture header carries.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Header {
    /// Routine captured.
    pub routine: Routine,
    /// Step axis is q (false: d; 0 for the other routines).
    pub axis_q: bool,
    /// The routine tripped (the end frame says where).
    pub tripped: bool,
    /// Periods per captured sample (1–255).
    pub decimation: u8,
    /// T_s in units of 100 ns ([`SAMPLE_PERIOD_UNITS_PER_S`]).
    pub sample_period_units: u16,
    /// Number of data frames that follow.
    pub count: u16,
    /// The routine's trip level \[A\] (0 if it has none).
    pub current_trip: f32,
}

/// Capture header frame.
pub fn encode_header(layout: &Layout, h: &Header) -> Frame {
    let flags = (h.routine.code() & 0x0F) | (u8::from(h.axis_q) << 4) | (u8::from(h.tripped) << 5);
    let [p0, p1] = h.sample_period_units.to_le_bytes();
    let [c0, c1] = h.count.to_le_bytes();
    let [t0, t1] = layout.to_lsb(Quantity::Current, h.current_trip).to_le_bytes();
    Frame {
        id: layout.header_id,
        len: HEADER_LEN,
        data: [flags, h.decimation, p0, p1, c0, c1, t0, t1],
    }
}

/// The header in a header frame's bytes; `None` if the length or routine is wrong (the
/// pre-flight check captures nothing, so a header of it is wrong too).
pub fn decode_header(layout: &Layout, data: &[u8]) -> Option<Header> {
    let [flags, decimation, p0, p1, c0, c1, t0, t1] = *data else {
        return None;
    };
    Some(Header {
        routine: Routine::from_code(flags & 0x0F).filter(|r| *r != Routine::Preflight)?,
        axis_q: flags & 0x10 != 0,
        tripped: flags & 0x20 != 0,
        decimation,
        sample_period_units: u16::from_le_bytes([p0, p1]),
        count: u16::from_le_bytes([c0, c1]),
        current_trip: layout.from_lsb(Quantity::Current, i16::from_le_bytes([t0, t1])),
    })
}

/// Capture data frame `sequence` of `routine` with the two channel values (SI units).
pub fn encode_data(layout: &Layout, routine: Routine, sequence: u16, a: f32, b: f32) -> Frame {
    let [qa, qb] = routine.channels();
    let [s0, s1] = sequence.to_le_bytes();
    let [a0, a1] = layout.to_lsb(qa, a).to_le_bytes();
    let [b0, b1] = layout.to_lsb(qb, b).to_le_bytes();
    Frame {
        id: layout.data_id,
        len: DATA_LEN,
        data: [routine.code(), s0, s1, a0, a1, b0, b1, 0],
    }
}

/// A data frame's routine code, sequence number and raw channels; `None` if the length
/// is wrong.
pub fn decode_data(data: &[u8]) -> Option<(u8, u16, i16, i16)> {
    let [r, s0, s1, a0, a1, b0, b1] = *data else {
        return None;
    };
    Some((
        r,
        u16::from_le_bytes([s0, s1]),
        i16::from_le_bytes([a0, a1]),
        i16::from_le_bytes([b0, b1]),
    ))
}

/// What the end frame carries.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct End {
    /// CRC-32 of the header's and every data frame's bytes ([`Crc32`]).
    pub crc: u32,
    /// Period index at which the routine tripped (0 if it did not).
    pub trip_sample: u16,
    /// |i_dq| that tripped \[A\] (0 if it did not).
    pub trip_current: f32,
}

/// Capture end frame.
pub fn encode_end(layout: &Layout, e: &End) -> Frame {
    let [c0, c1, c2, c3] = e.crc.to_le_bytes();
    let [s0, s1] = e.trip_sample.to_le_bytes();
    let [i0, i1] = layout.to_lsb(Quantity::Current, e.trip_current).to_le_bytes();
    Frame {
        id: layout.end_id,
        len: END_LEN,
        data: [c0, c1, c2, c3, s0, s1, i0, i1],
    }
}

/// The end frame's fields; `None` if the length is wrong.
pub fn decode_end(layout: &Layout, data: &[u8]) -> Option<End> {
    let [c0, c1, c2, c3, s0, s1, i0, i1] = *data else {
        return None;
    };
    Some(End {
        crc: u32::from_le_bytes([c0, c1, c2, c3]),
        trip_sample: u16::from_le_bytes([s0, s1]),
        trip_current: layout.from_lsb(Quantity::Current, i16::from_le_bytes([i0, i1])),
    })
}

/// Data length of the fault-report frame.
pub const FAULT_REPORT_LEN: u8 = 8;

/// What a start-up check measured when it refused the drive (causes 10–19 of
/// `motor_config::fault_record::FaultCause`): the figure it judged, in the unit its
/// cause documents, and which phase or instance it was (0 … 3). The fault record keeps
/// it and the fault report sends it, so a user sees by how much the bench missed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FaultMeasurement {
    /// The judged figure (its unit by cause: README, "What a refusal reports").
    pub value: f32,
    /// The phase (0 u, 1 v, 2 w) or the instance the figure belongs to, 0 … 3.
    pub index: u8,
}

impl FaultMeasurement {
    /// `value` of instance 0.
    pub const fn of(value: f32) -> Self {
        Self { value, index: 0 }
    }

    /// `value` of phase or instance `index` (kept to its two bits).
    pub const fn at(value: f32, index: u8) -> Self {
        Self {
            value,
            index: index & MEASUREMENT_INDEX_MASK,
        }
    }
}

/// The two bits a [`FaultMeasurement`]'s index takes in the report's flags byte.
pub const MEASUREMENT_INDEX_MASK: u8 = 0b11;

/// What the fault-report frame carries: the record the image found at boot
/// (`motor_config::fault_record`), reduced to what a logger on the bus needs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FaultReport {
    /// The cause code (1 HardFault, 2 stack overflow, 3 break, 4 trip, 5 lost
    /// conversion, 6 bring-up, 7 unhandled interrupt, 8 panic, 9 watchdog, 10 current
    /// offset, 11–18 pre-flight, 19 resolver signal).
    pub cause: u8,
    /// The stacked PC of a CPU fault.
    pub pc: Option<u32>,
    /// The control state of the last period.
    pub state: Option<FaultState>,
    /// What the start-up check that refused the drive measured.
    pub measured: Option<FaultMeasurement>,
}

/// The last period's control state in a fault report.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FaultState {
    /// The outputs were on.
    pub running: bool,
    /// The drive had tripped.
    pub tripped: bool,
    /// i_q \[A\].
    pub i_q: f32,
}

/// The fault-report frame's bytes: 0 cause; 1 flags (bit 0 PC valid, bit 1 state valid,
/// bit 2 outputs were on, bit 3 tripped, bit 4 measurement valid, bits 5–6 the
/// measurement's index); 2–5 the PC, little-endian, when valid — else the measurement as
/// an IEEE 754 single, little-endian, when valid — else 0 (a CPU fault has a PC and a
/// start-up check a measurement, never both: the PC wins, the measurement's flag is then
/// clear); 6–7 i_q in units of `amps_per_lsb` (the generated `FAULT_CURRENT_PER_LSB`),
/// rounded and saturated to i16, `i16::MIN` for not a number, 0 when the state is not
/// valid.
pub fn encode_fault_report(amps_per_lsb: f32, r: &FaultReport) -> [u8; 8] {
    let state = r.state;
    let measured = if r.pc.is_some() { None } else { r.measured };
    let flags = u8::from(r.pc.is_some())
        | u8::from(state.is_some()) << 1
        | u8::from(state.is_some_and(|s| s.running)) << 2
        | u8::from(state.is_some_and(|s| s.tripped)) << 3
        | u8::from(measured.is_some()) << 4
        | measured.map_or(0, |m| m.index & MEASUREMENT_INDEX_MASK) << 5;
    let word = match (r.pc, measured) {
        (Some(pc), _) => pc,
        (None, Some(m)) => m.value.to_bits(),
        (None, None) => 0,
    };
    let [p0, p1, p2, p3] = word.to_le_bytes();
    let iq = state.map_or(0, |s| {
        if s.i_q.is_nan() {
            i16::MIN
        } else {
            // Float → integer `as` saturates at the i16 range.
            libm::roundf(s.i_q / amps_per_lsb) as i16
        }
    });
    let [q0, q1] = iq.to_le_bytes();
    [r.cause, flags, p0, p1, p2, p3, q0, q1]
}

/// CRC-32 (IEEE 802.3: reflected polynomial 0xEDB88320, initial value and final XOR
/// 0xFFFFFFFF), bitwise: 8 shifts per byte, no table in flash. The capture's check runs
/// over the header frame's data bytes and then every data frame's, in order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Crc32 {
    state: u32,
}

impl Default for Crc32 {
    fn default() -> Self {
        Self::new()
    }
}

impl Crc32 {
    /// Before the first byte.
    pub const fn new() -> Self {
        Self { state: 0xFFFF_FFFF }
    }

    /// Feeds `bytes`.
    pub fn update(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.state ^= u32::from(b);
            for _ in 0..8 {
                let mask = (self.state & 1).wrapping_neg();
                self.state = (self.state >> 1) ^ (0xEDB8_8320 & mask);
            }
        }
    }

    /// The checksum of the bytes fed so far.
    pub fn value(&self) -> u32 {
        !self.state
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn layout() -> Layout {
        EXAMPLE_LAYOUT
    }

    /// The CRC catalogue's check value of CRC-32/ISO-HDLC: "123456789" → 0xCBF43926.
    #[test]
    fn crc32_check_value() {
        let mut c = Crc32::new();
        c.update(b"1234");
        c.update(b"56789");
        assert_eq!(c.value(), 0xCBF4_3926);
        assert_eq!(Crc32::new().value(), 0);
    }

    /// Hand-encoded frames: 4 V at 10 mV/LSB = 400 = 0x0190; 10 A at 10 mA/LSB = 1000 =
    /// 0x03E8; 50 µs = 500 units = 0x01F4; 3040 samples = 0x0BE0.
    #[test]
    fn frames_by_hand() {
        let l = layout();
        let c = Command {
            routine: Some(Routine::Step),
            axis_q: true,
            voltage: 4.0,
            current_trip: 10.0,
            decimation: 1,
        };
        let f = encode_command(&l, &c);
        assert_eq!((f.id, f.bytes()), (0x102, &[1, 1, 0x90, 0x01, 0xE8, 0x03, 1, 0][..]));
        assert_eq!(decode_command(&l, 0x102, f.bytes()), Some(c));
        assert_eq!(decode_command(&l, 0x102, &f.bytes()[..7]), None);
        let h = Header {
            routine: Routine::Step,
            axis_q: true,
            tripped: true,
            decimation: 2,
            sample_period_units: 500,
            count: 3040,
            current_trip: 10.0,
        };
        let f = encode_header(&l, &h);
        assert_eq!(f.bytes(), &[0x31, 2, 0xF4, 0x01, 0xE0, 0x0B, 0xE8, 0x03]);
        assert_eq!(decode_header(&l, f.bytes()), Some(h));
        // −1.5 A = −150 = 0xFF6A; 4 V = 0x0190; sequence 0x1234.
        let f = encode_data(&l, Routine::Step, 0x1234, 4.0, -1.5);
        assert_eq!(f.bytes(), &[1, 0x34, 0x12, 0x90, 0x01, 0x6A, 0xFF]);
        assert_eq!(decode_data(f.bytes()), Some((1, 0x1234, 400, -150)));
        let e = End {
            crc: 0xCBF4_3926,
            trip_sample: 812,
            trip_current: 10.2,
        };
        let f = encode_end(&l, &e);
        assert_eq!(f.bytes(), &[0x26, 0x39, 0xF4, 0xCB, 0x2C, 0x03, 0xFC, 0x03]);
        let f = encode_status(&l, State::Idle, Reason::TorqueNotZero, 1, 0);
        assert_eq!(f.bytes(), &[0, 2, 1, 0]);
        assert_eq!(
            decode_status(&l, 0x101, f.bytes()),
            Some((State::Idle, Reason::TorqueNotZero, 1, 0))
        );
        assert_eq!(decode_status(&l, 0x101, &[4, 10, 0, 0]), None);
        assert_eq!(decode_status(&l, 0x102, f.bytes()), None);
        // Every state and reason survives the trip through its code.
        for code in 0..=9u8 {
            assert_eq!(Reason::from_code(code).map(|r| r as u8), Some(code));
        }
        for code in 0..=4u8 {
            assert_eq!(State::from_code(code).map(|s| s as u8), Some(code));
        }
        assert_eq!((State::from_code(5), Reason::from_code(10)), (None, None));
    }

    /// Saturation and wrap: currents beyond ±327.67 A saturate, NaN is 0; an angle of
    /// π − 1 LSB stays, +π wraps to −π (−32768), 3π/2 to −π/2.
    #[test]
    fn scaling_saturates_and_angles_wrap() {
        let l = layout();
        assert_eq!(l.to_lsb(Quantity::Current, 1e6), i16::MAX);
        assert_eq!(l.to_lsb(Quantity::Current, -1e6), i16::MIN);
        assert_eq!(l.to_lsb(Quantity::Current, f32::NAN), 0);
        let pi = core::f32::consts::PI;
        assert_eq!(l.to_lsb(Quantity::Angle, pi - ANGLE_PER_LSB), 32767);
        assert_eq!(l.to_lsb(Quantity::Angle, pi), -32768);
        assert_eq!(l.to_lsb(Quantity::Angle, 1.5 * pi), -16384);
    }
}
