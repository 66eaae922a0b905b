//! A simulated drive on a simulated bus, for testing the commissioning path without a
//! board: the firmware's commissioning supervisor (`motor_control::commissioning_mode`)
//! with its CAN encoder, on the closed-loop bench of `verify` (firmware control step and
//! motor plant), behind the [`FrameBus`] a SocketCAN socket also implements.
//!
//! Each control period (simulated time T_s) it does what the image does: the
//! supervisor's step (the bench runs only while a routine demands; with the outputs
//! off the plant is held), then on the bus the vehicle unit's zero setpoint frame every
//! setpoint period, and the drive's status frame every status period
//! (`motor_config::can_commissioning::STATUS_PERIODS`: the setpoint period over T_s,
//! at least 1), else the next capture frame while one is being sent.

use std::collections::VecDeque;
use std::time::Duration;

use motor_control::SoftTrig;
use motor_control::can_protocol::{self as p, Frame};
use motor_control::commissioning_mode::{CommissioningMode, Control, Guards, Measured, ModeConfig, Sample};
use motor_sim::bench::Bench;

use super::candump::mode_config;
use super::commission::{BusFrame, FrameBus};
use codegen::design::Design;

/// The time stamp of period 0 \[s since the epoch\] (2023-11-14).
const EPOCH: f64 = 1.7e9;

/// A drive running the firmware's commissioning mode on a simulated motor.
pub struct SimulatedDrive {
    cfg: ModeConfig,
    mode: CommissioningMode,
    buffer: Vec<Sample>,
    bench: Bench,
    measured: Measured,
    /// The supervisor's safety inputs (tests set a torque, a fault or the break).
    pub guards: Guards,
    ts: f64,
    n: u64,
    status_periods: u64,
    setpoint: Frame,
    /// Frames on the bus not yet received.
    queue: VecDeque<BusFrame>,
    /// Commands the drive received.
    pub commands: usize,
}

impl SimulatedDrive {
    /// The drive of design `d` (on a board) with `bench`, whose rotor turns at `omega_e`
    /// \[rad/s\] electrical as the drive last measured it; `None` without a board.
    pub fn new(d: &Design, bench: Bench, omega_e: f32) -> Option<Self> {
        let (cfg, capacity) = mode_config(d)?;
        let board = &d.board.as_ref()?.board;
        let ts = d.drive.sample_period_s;
        Some(SimulatedDrive {
            cfg,
            mode: CommissioningMode::new(),
            buffer: vec![(0.0, 0.0); capacity],
            bench,
            measured: Measured {
                omega_e,
                ..Measured::default()
            },
            guards: Guards::default(),
            ts,
            n: 0,
            status_periods: ((board.setpoint_period_s as f32 / ts as f32) as u64).max(1),
            setpoint: Frame {
                id: board.setpoint_id,
                len: 2,
                data: [0; 8],
            },
            queue: VecDeque::new(),
            commands: 0,
        })
    }

    fn queue(&mut self, f: &Frame) {
        self.queue.push_back(BusFrame {
            id: u32::from(f.id),
            extended: false,
            data: f.bytes().to_vec(),
        });
    }

    /// One control period.
    fn period(&mut self) {
        if self.n.is_multiple_of(self.status_periods) {
            let setpoint = self.setpoint;
            self.queue(&setpoint);
        }
        let control = self
            .mode
            .step(&self.cfg, &self.guards, &self.measured, &mut SoftTrig, &mut self.buffer);
        if let Control::Demand(demand) = control {
            let o = self.bench.step(demand).out;
            self.measured = Measured {
                i_dq: o.i_dq,
                theta_r: o.theta_r,
                omega_e: o.omega_e,
                u_q: o.u_dq.q,
                u_d: o.u_dq.d,
                theta_e: o.theta_e,
                i_uvw: o.i_uvw,
            };
        }
        // The status frame has the slot at its period, as on the board.
        if (self.n + 1).is_multiple_of(self.status_periods) {
            let status = self.mode.status(&self.cfg, u8::from(self.guards.fault));
            self.queue(&status);
        } else if let Some(f) = self.mode.next_frame(&self.cfg, &self.buffer) {
            self.queue(&f);
        }
        self.n += 1;
    }
}

impl FrameBus for SimulatedDrive {
    fn send(&mut self, frame: &Frame) -> Result<(), String> {
        if let Some(c) = p::decode_command(&self.cfg.layout, frame.id, frame.bytes()) {
            self.commands += 1;
            let capacity = self.buffer.len();
            self.mode
                .command(&self.cfg, &c, &self.guards, self.measured.omega_e, capacity);
        }
        Ok(())
    }

    fn receive(&mut self, timeout: Duration) -> Result<Option<BusFrame>, String> {
        let until = self.n + (timeout.as_secs_f64() / self.ts).ceil() as u64;
        while self.queue.is_empty() && self.n < until {
            self.period();
        }
        Ok(self.queue.pop_front())
    }

    fn elapsed(&self) -> Duration {
        Duration::from_secs_f64(self.n as f64 * self.ts)
    }

    fn timestamp(&self) -> f64 {
        EPOCH + self.n as f64 * self.ts
    }
}
