//! The emulated board's CAN bus as a bench host sees it: the commissioning session of
//! `motorgen commission --can` (`motor_commission::commission::FrameBus`) runs over the
//! emulated FDCAN1, so the same request, capture and stream code that talks to a board
//! (or to `--sim`'s simulated drive) talks to the image.
//!
//! A frame the host sends is put on the bus at once (the image's RX FIFO 0 takes it,
//! [`Rig::send`]); the host receives the frames the image transmits, each when its
//! transmission ended ([`crate::periph::fdcan::Fdcan::take_sent`]: the Tx FIFO drained
//! one frame after the other at the joined bit rate). While the host waits the image
//! runs, and the vehicle unit goes on sending the zero-torque setpoint every setpoint
//! period ([`Rig::run`]), as on a bench where the drive's setpoint must not time out.

use std::time::Duration;

use motor_commission::commission::{BusFrame, FrameBus};
use motor_control::can_protocol as p;

use crate::periph::fdcan::Frame;
use crate::rig::Rig;

/// The time stamp of emulated time 0 \[s since the epoch\] (2023-11-14, as the simulated
/// drive's).
const EPOCH: f64 = 1.7e9;

/// A host on the emulated bus of `rig`.
pub struct CanBus<'a> {
    rig: &'a mut Rig,
    /// Emulated time the bus was opened \[s\].
    opened_s: f64,
    /// End of the last received frame's transmission \[s\].
    received_s: f64,
}

impl<'a> CanBus<'a> {
    /// Opens the bus of `rig` now.
    pub fn new(rig: &'a mut Rig) -> Self {
        let now = rig.machine.soc().time_s();
        Self {
            rig,
            opened_s: now,
            received_s: now,
        }
    }

    fn take(&mut self) -> Option<BusFrame> {
        let now = self.rig.machine.soc().time_s();
        let (t, f) = self.rig.machine.soc_mut().fdcan.take_sent(now)?;
        self.received_s = t;
        Some(BusFrame {
            id: f.id,
            extended: f.extended,
            data: f.data,
        })
    }
}

impl FrameBus for CanBus<'_> {
    fn send(&mut self, frame: &p::Frame) -> Result<(), String> {
        self.rig.send(&Frame {
            id: u32::from(frame.id),
            extended: false,
            remote: false,
            data: frame.bytes().to_vec(),
        });
        Ok(())
    }

    fn receive(&mut self, timeout: Duration) -> Result<Option<BusFrame>, String> {
        if let Some(f) = self.take() {
            return Ok(Some(f));
        }
        let until = self.rig.machine.soc().time_s() + timeout.as_secs_f64();
        self.rig
            .run(until, |_| Some(0.0), |m| m.soc().fdcan.has_sent_by(m.soc().time_s()))
            .map_err(|e| format!("{e}; {}", self.rig.machine.summary()))?;
        Ok(self.take())
    }

    fn elapsed(&self) -> Duration {
        Duration::from_secs_f64((self.rig.machine.soc().time_s() - self.opened_s).max(0.0))
    }

    fn timestamp(&self) -> f64 {
        EPOCH + self.received_s
    }
}
