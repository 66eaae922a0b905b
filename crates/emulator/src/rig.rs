//! A test rig: one motor's image on its board (`image::board_for`) at standstill, with the vehicle
//! unit's setpoint frames on the CAN bus.

use codegen::design::Design;

use crate::image;
use crate::periph::fdcan::Frame;
use crate::soc::{Analog, Patches, Soc};
use crate::wiring::{self, Standstill};
use crate::{Machine, Stop};

/// FLASH_OPTR as the image requires it on a board with a signal on PB8 (firmware
/// README, "Option bytes"): the delivered value 0xFFEF_F8AA (RM0440 §5.4.1, FLASH_OPTR
/// reset value from the option bytes) with nSWBOOT0 (bit 26) programmed to 0 and nBOOT0
/// (bit 27) left at 1.
pub const OPTR_BOOT_FROM_FLASH: u32 = 0xFFEF_F8AA & !(1 << 26);

/// The rig.
pub struct Rig {
    /// The emulated chip running the image.
    pub machine: Machine,
    /// The motor's design on its board.
    pub design: Design,
    /// The next setpoint frame is due at this time \[s\].
    next_frame_s: f64,
}

impl Rig {
    /// Builds (once per process) and loads `motor`'s image, at reset.
    pub fn new(motor: &str, patches: Patches) -> Result<Self, String> {
        Self::with_analog(motor, patches, |d| Ok(Box::new(Standstill::new(d)?)))
    }

    /// [`Rig::new`] with the analog inputs from `analog` (given the design), e.g. the
    /// closed loop's [`crate::drive::Drive`].
    pub fn with_analog(
        motor: &str,
        patches: Patches,
        analog: impl FnOnce(&Design) -> Result<Box<dyn Analog>, String>,
    ) -> Result<Self, String> {
        let design = wiring::design(motor)?;
        let image = image::image(motor)?;
        let soc = Soc::new(
            wiring::wiring(&design)?,
            analog(&design)?,
            OPTR_BOOT_FROM_FLASH,
            patches,
        );
        let machine = Machine::new(&image, soc).map_err(|e| e.to_string())?;
        Ok(Self {
            machine,
            design,
            next_frame_s: 0.0,
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
                "no enabled PWM period within {limit_s} s; {}",
                self.machine.summary()
            ));
        }
        first_enabled_period(&self.machine).ok_or_else(|| "no enabled period".into())
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
        self.machine.soc_mut().fdcan.receive(f);
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
