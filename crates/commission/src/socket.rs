//! The live bus: a raw SocketCAN socket bound to one interface (Linux, through the
//! `socketcan` crate), the [`FrameBus`] of `motorgen commission` on a bench. Elsewhere
//! [`LiveBus`] has no values and [`open`] says that SocketCAN is Linux only.
//!
//! It is here rather than in the command line so that the session runs end to end on a
//! real (virtual) CAN interface in this crate's tests, exactly as `motorgen commission`
//! runs it.

#[cfg(target_os = "linux")]
use std::time::{Instant, SystemTime, UNIX_EPOCH};

use std::time::Duration;

use motor_control::can_protocol::Frame;
#[cfg(target_os = "linux")]
use socketcan::{CanFrame, CanSocket, EmbeddedFrame, Frame as _, Socket, StandardId};

use super::commission::{BusFrame, FrameBus};
use super::error::{Error, Problem};

/// A raw CAN socket on one interface.
#[cfg(target_os = "linux")]
pub struct LiveBus {
    socket: CanSocket,
    start: Instant,
}

/// A raw CAN socket on one interface: none outside Linux.
#[cfg(not(target_os = "linux"))]
pub enum LiveBus {}

/// Opens the SocketCAN interface `iface` for a drive at `bit_rate` \[bit/s\] (the
/// message says how to bring the interface up at that rate).
pub fn open(iface: &str, bit_rate: u32) -> Result<LiveBus, Error> {
    #[cfg(target_os = "linux")]
    {
        LiveBus::open(iface).map_err(|e| {
            Error::BusUnavailable(Problem::new(
                format!("CAN interface `{iface}`"),
                format!("cannot open it: {e}"),
                format!(
                    "a SocketCAN interface that exists and is up at the board's bit rate, e.g. `sudo ip link set {iface} up type can bitrate {bit_rate}`"
                ),
            ))
        })
    }
    #[cfg(not(target_os = "linux"))]
    {
        let _ = bit_rate;
        Err(Error::BusUnavailable(Problem::new(
            format!("--can {iface}"),
            "SocketCAN is Linux only",
            "a Linux host; elsewhere log the bus with another tool and use `motorgen identify … --candump LOG`",
        )))
    }
}

#[cfg(target_os = "linux")]
impl LiveBus {
    /// Opens and binds the socket.
    pub fn open(iface: &str) -> std::io::Result<Self> {
        Ok(LiveBus {
            socket: CanSocket::open(iface)?,
            start: Instant::now(),
        })
    }
}

#[cfg(target_os = "linux")]
impl FrameBus for LiveBus {
    fn send(&mut self, f: &Frame) -> Result<(), String> {
        let id = StandardId::new(f.id).ok_or_else(|| format!("identifier {:#x} is not 11 bits", f.id))?;
        let frame = CanFrame::new(id, f.bytes()).ok_or("a frame of more than 8 bytes")?;
        self.socket
            .write_frame_insist(&frame)
            .map_err(|e| format!("cannot send: {e}"))
    }

    fn receive(&mut self, timeout: Duration) -> Result<Option<BusFrame>, String> {
        let deadline = Instant::now() + timeout;
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            if left.is_zero() {
                return Ok(None);
            }
            match self.socket.read_frame_timeout(left) {
                Ok(CanFrame::Data(d)) => {
                    return Ok(Some(BusFrame {
                        id: d.raw_id(),
                        extended: d.is_extended(),
                        data: d.data().to_vec(),
                    }));
                }
                // Remote and error frames: the drive sends neither.
                Ok(_) => {}
                Err(e) if matches!(e.kind(), std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut) => {
                    return Ok(None);
                }
                Err(e) => return Err(format!("cannot receive: {e}")),
            }
        }
    }

    fn elapsed(&self) -> Duration {
        self.start.elapsed()
    }

    fn timestamp(&self) -> f64 {
        SystemTime::now()
            .duration_since(UNIX_EPOCH)
            .map_or(0.0, |d| d.as_secs_f64())
    }
}

#[cfg(not(target_os = "linux"))]
impl FrameBus for LiveBus {
    fn send(&mut self, _: &Frame) -> Result<(), String> {
        match *self {}
    }

    fn receive(&mut self, _: Duration) -> Result<Option<BusFrame>, String> {
        match *self {}
    }

    fn elapsed(&self) -> Duration {
        match *self {}
    }

    fn timestamp(&self) -> f64 {
        match *self {}
    }
}
