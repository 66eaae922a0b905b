//! A test rig: one motor's image, built from a board file, on the emulated hardware of a
//! board (its own description, [`crate::hardware`]), at standstill unless the test gives
//! another analog source, with the vehicle unit's setpoint frames on the CAN bus.

use std::sync::OnceLock;

use codegen::design::Design;

use crate::hardware::{self, Hardware};
use crate::image::{self, BoardFile};
use crate::periph::fdcan::Frame;
use crate::soc::{Analog, OPTR_NSWBOOT0, Patches, Soc, Wiring};
use crate::wiring::{self, Standstill};
use crate::{Machine, Stop};

/// FLASH_OPTR as delivered (RM0440 §3.7.8, FLASH_OPTR reset value from the factory
/// option bytes: 0xFFEF_F8AA, nSWBOOT0 = nBOOT0 = 1).
pub const OPTR_FACTORY: u32 = 0xFFEF_F8AA;

/// FLASH_OPTR as the image requires it on a board with a signal on PB8 (firmware
/// README, "Option bytes"): the delivered value with nSWBOOT0 (bit 26) programmed to 0 and
/// nBOOT0 (bit 27) left at 1.
pub const OPTR_BOOT_FROM_FLASH: u32 = OPTR_FACTORY & !OPTR_NSWBOOT0;
/// First word of a valid fault record of layout version 3, "MFR3" (firmware README
/// "Fault record"; version 2 added the CAN bus-off count, version 3 the start-up checks'
/// measurement in word 6).
pub const FAULT_RECORD_MAGIC: u32 = 0x4D46_5233;
/// The record's flags word (2): bit 3 a measurement is present, bits 4–5 its index
/// (firmware README "Fault record").
const RECORD_HAS_MEASURED: u32 = 1 << 3;

/// What a rig runs: a motor's image built from a board file, on a board's hardware.
#[derive(Clone, Debug)]
pub struct Bench {
    /// The motor (`motors/<motor>.toml`).
    pub motor: String,
    /// The board file the image is built from.
    pub board: BoardFile,
    /// The hardware it runs on.
    pub hardware: Hardware,
    /// Injected defects.
    pub patches: Patches,
    /// FLASH_OPTR of the chip.
    pub optr: u32,
}

impl Bench {
    /// `motor` on `boards/<board>.toml` and that board's hardware, option bytes
    /// programmed, no defect.
    pub fn new(motor: &str, board: &str) -> Result<Self, String> {
        let hardware = hardware::for_board(board).ok_or_else(|| format!("no hardware description of {board}"))?;
        Ok(Self {
            motor: motor.to_string(),
            board: BoardFile::shipped(board)?,
            hardware,
            patches: Patches::default(),
            optr: OPTR_BOOT_FROM_FLASH,
        })
    }

    /// With `patches`.
    pub fn patched(self, patches: Patches) -> Self {
        Self { patches, ..self }
    }

    /// The image built from `text` (a variant of the board's file) on the same hardware.
    pub fn board_text(self, text: String) -> Self {
        let board = BoardFile::variant(&self.board.stem, text);
        Self { board, ..self }
    }

    /// `motor/board`, for messages.
    pub fn name(&self) -> String {
        if self.board.variant {
            format!("{} on a variant of {}", self.motor, self.board.stem)
        } else {
            format!("{} on {}", self.motor, self.board.stem)
        }
    }
}

/// The rig.
pub struct Rig {
    /// The emulated chip running the image.
    pub machine: Machine,
    /// The motor's design on the board file the image was built from.
    pub design: Design,
    /// The board's hardware.
    pub hardware: Hardware,
    /// What runs.
    pub bench: Bench,
    /// The next setpoint frame is due at this time \[s\].
    next_frame_s: f64,
    /// When [`Rig::run`] sent its last setpoint frame \[s\].
    last_frame_s: Option<f64>,
}

impl Rig {
    /// Builds (once per process) and loads the bench's image, at reset, at standstill.
    pub fn new(bench: Bench) -> Result<Self, String> {
        Self::with_analog(bench, |d, hw| Ok(Box::new(Standstill::new(d, hw))))
    }

    /// [`Rig::new`] with the analog inputs from `analog` (given the design and the
    /// hardware), e.g. the closed loop's [`crate::drive::Drive`].
    pub fn with_analog(
        bench: Bench,
        analog: impl FnOnce(&Design, &Hardware) -> Result<Box<dyn Analog>, String>,
    ) -> Result<Self, String> {
        let design = wiring::design(&bench.motor, &bench.board.file_name(), &bench.board.text)?;
        let image = image::image(&bench.motor, &bench.board)?;
        let soc = Soc::new(
            Wiring::new(bench.hardware.clone()),
            analog(&design, &bench.hardware)?,
            bench.optr,
            bench.patches.clone(),
        );
        let machine = Machine::new(&image, soc).map_err(|e| e.to_string())?;
        Ok(Self {
            machine,
            design,
            hardware: bench.hardware.clone(),
            bench,
            next_frame_s: 0.0,
            last_frame_s: None,
        })
    }

    fn board(&self) -> &codegen::board::Board {
        &self.design.board.as_ref().expect("board design").board
    }

    /// The torque setpoint frame for `torque_nm` (the board's `[can]`: standard id,
    /// bytes 0–1 a little-endian i16 in units of the torque resolution).
    pub fn setpoint(&self, torque_nm: f64) -> Frame {
        let b = self.board();
        let raw = (torque_nm / b.torque_resolution_nm).round().clamp(-32768.0, 32767.0) as i16;
        Frame {
            id: u32::from(b.setpoint_id),
            extended: false,
            remote: false,
            data: raw.to_le_bytes().to_vec(),
        }
    }

    /// When [`Rig::run`] (or [`Rig::boot`]) sent its last setpoint frame \[s\], if it sent one.
    pub fn last_frame_s(&self) -> Option<f64> {
        self.last_frame_s
    }

    /// The setpoint period \[s\] (board `[can].setpoint_period`).
    pub fn setpoint_period_s(&self) -> f64 {
        self.board().setpoint_period_s
    }

    /// Runs from reset with zero-torque setpoints until the first enabled PWM period
    /// (within `limit_s`); returns its time \[s\].
    pub fn boot(&mut self, limit_s: f64) -> Result<f64, String> {
        let reached = self
            .run(limit_s, |_| Some(0.0), |m| first_enabled_period(m).is_some())
            .map_err(|e| format!("{e}; {}", self.machine.summary()))?;
        if !reached {
            return Err(format!(
                "no enabled PWM period within {limit_s} s{}; {}",
                self.fault_cause()
                    .map_or(String::new(), |c| format!(" (fault record: {c})")),
                self.machine.summary()
            ));
        }
        first_enabled_period(&self.machine).ok_or_else(|| "no enabled period".into())
    }

    /// The address of the image's fault record (`MOTOR_FAULT_RECORD`) if it holds one of
    /// this layout (word 0 the magic).
    fn sealed_record(&self) -> Option<u32> {
        let at = self.machine.symbol("MOTOR_FAULT_RECORD")?;
        (self.machine.peek(at).ok()? == FAULT_RECORD_MAGIC).then_some(at)
    }

    /// The cause the image sealed in its fault record (`MOTOR_FAULT_RECORD` word 1,
    /// firmware README "Fault record"), if the record is valid.
    pub fn fault_cause(&self) -> Option<String> {
        let at = self.sealed_record()?;
        let cause = self.machine.peek(at + 4).ok()?;
        let name = match cause {
            1 => "HardFault",
            2 => "stack overflow",
            3 => "break",
            4 => "trip",
            5 => "lost conversion",
            6 => "bring-up",
            7 => "unhandled interrupt",
            8 => "panic",
            9 => "watchdog",
            10 => "current offset",
            11 => "inverted current sensing",
            12 => "resistance out of bound",
            13 => "inductance out of bound",
            14 => "phase currents do not sum to zero",
            15 => "open phase",
            16 => "wrong direction",
            17 => "pole-pair ratio",
            18 => "resolver offset",
            19 => "resolver signal",
            _ => "unknown",
        };
        Some(format!("{cause} ({name})"))
    }

    /// What the start-up check that refused the drive measured, from the sealed fault
    /// record (word 6, an f32, and the index in bits 4–5 of word 2; firmware README
    /// "Fault record", read as a probe would): `None` without a record or a measurement.
    pub fn fault_measurement(&self) -> Option<(f32, u8)> {
        let at = self.sealed_record()?;
        let flags = self.machine.peek(at + 8).ok()?;
        if flags & RECORD_HAS_MEASURED == 0 {
            return None;
        }
        let value = f32::from_bits(self.machine.peek(at + 24).ok()?);
        Some((value, ((flags >> 4) & 0b11) as u8))
    }

    /// The CAN bus-off count the control interrupt last wrote into its state
    /// (`MOTOR_CONTROL_STATE` word 6, firmware README "Fault record"), if written.
    pub fn bus_off_count(&self) -> Option<u32> {
        let flags = self.live_state(7)?;
        (flags >> 31 == 1).then(|| self.live_state(6)).flatten()
    }

    /// Word `k` of the control state the control interrupt last wrote
    /// (`MOTOR_CONTROL_STATE`, firmware README "Fault record": 0 i_d, 1 i_q, 2 θ_e,
    /// 3 ω_e, 4 U_dc, 5 periods, 6 bus-offs, 7 flags).
    pub fn live_state(&self, k: u32) -> Option<u32> {
        let at = self.machine.symbol("MOTOR_CONTROL_STATE")?;
        self.machine.peek(at + 4 * k).ok()
    }

    /// The standstill analog source, to change currents or the DC link.
    pub fn analog(&mut self) -> &mut Standstill {
        self.analog_as().expect("the rig's analog source is Standstill")
    }

    /// The analog source as a `T`, if it is one.
    pub fn analog_as<T: Analog>(&mut self) -> Option<&mut T> {
        let a: &mut dyn std::any::Any = self.machine.soc_mut().analog.as_mut();
        a.downcast_mut()
    }

    /// One carrier period \[s\] (the design's switching frequency).
    pub fn pwm_period_s(&self) -> f64 {
        1.0 / self.design.drive.switching_frequency_hz
    }

    /// Puts a frame on the bus now.
    pub fn send(&mut self, f: &Frame) {
        let now = self.machine.soc().time_s();
        self.machine.soc_mut().fdcan.receive(f, now);
    }

    /// Runs to `until_s`, sending `torque(t)` every setpoint period (none while it
    /// returns `None`), stopping early when `stop` says so.
    pub fn run(
        &mut self,
        until_s: f64,
        mut torque: impl FnMut(f64) -> Option<f64>,
        mut stop: impl FnMut(&Machine) -> bool,
    ) -> Result<bool, Stop> {
        // Times compared in bus units, rounded up as `run_while` rounds its end.
        let reached = |m: &Machine, x: f64| m.soc().now >= (x * crate::UNITS_PER_S).ceil() as u64;
        loop {
            if reached(&self.machine, until_s) {
                return Ok(false);
            }
            if reached(&self.machine, self.next_frame_s) {
                if let Some(nm) = torque(self.next_frame_s) {
                    let f = self.setpoint(nm);
                    self.send(&f);
                    self.last_frame_s = Some(self.machine.soc().time_s());
                }
                self.next_frame_s += self.setpoint_period_s();
            }
            let step = self.next_frame_s.min(until_s);
            if self.machine.run_while(step, |m| !stop(m))? {
                return Ok(true);
            }
        }
    }
}

/// The time of the first update event with MOE = 1 \[s\], if any.
pub fn first_enabled_period(m: &Machine) -> Option<f64> {
    m.soc().notes.iter().find_map(|n| match n {
        crate::Note::FirstEnabledPeriod(t) => Some(*t),
        _ => None,
    })
}

/// Whether `motor` fits the board `board` (its file's ranges): `motorgen check --board`
/// accepts the pair (its peak current and DC link inside what the board measures and is
/// rated for, its top speed below the board's ceiling), its DC link below the board's
/// over-voltage trip, and `motorgen verify`'s current step below the over-current trip.
/// A motor that does not fit trips the image at once; the scenarios run every motor on
/// every board it fits.
pub fn fits(motor: &str, board: &str) -> Result<bool, String> {
    let b = BoardFile::shipped(board)?;
    // A refusal of the pair (errors at the board's keys) is a misfit, if the spec alone
    // designs (else the motor file is broken, not a misfit).
    let Ok(d) = wiring::design(motor, &b.file_name(), &b.text) else {
        let (spec_file, spec_text) = wiring::read(&format!("motors/{motor}.toml"))?;
        codegen::design_source(&spec_file, &spec_text).map_err(|e| e.to_string())?;
        return Ok(false);
    };
    let spec = wiring::spec(motor)?;
    let out = d.board.as_ref().ok_or("no board")?;
    let udc = d.drive.dc_link_voltage_v;
    let step = motor_verify::scenarios::step_amplitude(&motor_verify::Setup::new(&spec, &d));
    Ok(udc < out.board.over_voltage_v && udc < out.dc_link_full_scale_v && step < out.board.over_current_a)
}

/// Every (motor, board) the scenarios run: each board in `boards/` (each has a hardware
/// description, or this fails) with each motor of [`image::motors`] that [`fits`] it —
/// on a board that is a variant of another (the same hardware, another sensing gain:
/// `Hardware::variant_of`) only the motors that other board does not take, so that
/// the same hardware is not run twice with the same motor; a board no motor fits fails
/// too (its scenarios would run zero times).
pub fn benches() -> Vec<(String, String)> {
    static BENCHES: OnceLock<Vec<(String, String)>> = OnceLock::new();
    // Once per process: deciding every pair designs every motor on every board.
    BENCHES.get_or_init(find_benches).clone()
}

/// [`benches`], computed.
fn find_benches() -> Vec<(String, String)> {
    let mut out = Vec::new();
    for board in motor_test_support::board_stems() {
        let hw = hardware::for_board(&board).unwrap_or_else(|| {
            panic!("boards/{board}.toml has no hardware description in crates/emulator/src/hardware")
        });
        let mut n = 0;
        for motor in image::motors() {
            let fits_it = |b: &str| fits(&motor, b).unwrap_or_else(|e| panic!("{motor} on {b}: {e}"));
            if fits_it(&board) && !hw.variant_of.is_some_and(fits_it) {
                out.push((motor.clone(), board.clone()));
                n += 1;
            }
        }
        assert!(
            n > 0 || std::env::var_os("EMULATOR_MOTORS").is_some(),
            "no motor fits {board}"
        );
    }
    // A motor no board fits would run no scenario at all.
    for motor in image::motors() {
        assert!(
            out.iter().any(|(m, _)| *m == motor),
            "{motor} fits no board in boards/ (`motorgen check motors/{motor}.toml --board …` says why)"
        );
    }
    out
}
