//! Test-only harness: the built STM32G474 image (`target/firmware/<motor>.elf`) run from
//! its reset vector on the Unicorn engine (QEMU's TCG Cortex-M), with register models of
//! the peripherals it touches ([`periph`]) behind a strict bus ([`soc`]): an access to a
//! register no model knows, a peripheral touched before its clock is enabled, or a
//! sequence RM0440 forbids stops the run with the PC, the register and the rule
//! ([`Violation`]).
//!
//! Time is instructions: one instruction per HCLK cycle (the Cortex-M4's pipeline,
//! flash wait states and the FPU's multi-cycle operations are not timed), so a duration
//! here is a lower bound of the silicon's. The NVIC's exception entry and return are
//! done by the harness ([`Machine`]): Unicorn has no NVIC.
//!
//! Licences: this crate's source is the workspace's; its test binaries link Debian's
//! GPL-2.0 `libunicorn`. It is never a dependency of `codegen`/`motorgen` or of the image.

pub mod bridge;
pub mod can_bus;
pub mod drive;
pub mod hardware;
pub mod image;
pub mod periph;
pub mod rig;
pub mod soc;
pub mod violation;
pub mod wiring;

use unicorn_engine::unicorn_const::{Arch, Mode, Permission};
use unicorn_engine::{RegisterARM, Unicorn};

pub use periph::fdcan::Frame;
pub use soc::{Analog, Note, Patches, Pulse, Soc, UNITS_PER_S, Wiring};
use violation::Broken;
pub use violation::Violation;

use image::Image;

/// Flash, its boot alias at 0 (RM0440 §2.6: boot from main flash aliases it at 0), SRAM1 +
/// SRAM2 + the CCM SRAM's alias as one 128 KiB block (RM0440 §2.3), the CCM SRAM at its own
/// address (not coherent with its alias in this model) — and the MMIO windows.
const FLASH: (u64, usize) = (0x0800_0000, 512 * 1024);
const SRAM: (u64, usize) = (0x2000_0000, 128 * 1024);
const CCM: (u64, usize) = (0x1000_0000, 32 * 1024);
const MMIO: [(u64, usize); 4] = [
    (0x4000_0000, 0x3_0000),
    (0x4800_0000, 0x2000),
    (0x5000_0000, 0x1000),
    (0xE000_0000, 0x10_0000),
];

/// EXC_RETURN for a return to thread mode on the main stack with an extended (FP)
/// frame (ARMv7-M B1.5.8, Table B1-8: 0xFFFF_FFE9).
const EXC_RETURN: u32 = 0xFFFF_FFE9;
/// Bytes of an extended exception frame: R0–R3, R12, LR, PC, xPSR, S0–S15, FPSCR and
/// one reserved word (ARMv7-M B1.5.7).
const FRAME_BYTES: u32 = 0x68;
/// Cycles from an exception's assertion to its handler's first instruction (Cortex-M4
/// TRM r0p1 §3.3.1 "Interrupt latency": 12 cycles with zero-wait-state memory).
const ENTRY_CYCLES: u64 = 12;

/// Exception numbers (ARMv7-M B1.5.2).
pub const HARD_FAULT: u32 = 3;

/// Why a run stopped early.
#[derive(Clone, Debug, PartialEq)]
pub enum Stop {
    /// A strict-mode rule was broken.
    Violation(Violation),
    /// The independent watchdog reset the chip at this time \[s\].
    WatchdogReset(f64),
    /// A fault inside the HardFault handler: the core locked up (ARMv7-M B1.5.15) at
    /// this time \[s\].
    Lockup(f64),
    /// The emulator failed outside any modelled behaviour.
    Emulator(String),
}

impl std::fmt::Display for Stop {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Stop::Violation(v) => write!(f, "{v}"),
            Stop::WatchdogReset(t) => write!(f, "watchdog reset at t = {:.3} ms", t * 1e3),
            Stop::Lockup(t) => write!(f, "core lockup at t = {:.3} ms", t * 1e3),
            Stop::Emulator(e) => write!(f, "emulator: {e}"),
        }
    }
}

/// One handled exception: number, entry and exit instruction counts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Handled {
    /// Exception number (16 + IRQ for interrupts).
    pub exception: u32,
    /// Instructions executed before entry.
    pub entry: u64,
    /// Instructions executed at return.
    pub exit: u64,
    /// Time of entry in bus units.
    pub at: u64,
}

/// Instructions between looks at an interrupt pending while PRIMASK masks it: the delay
/// the emulator adds to its entry after CPSIE (the Cortex-M4 takes it at once).
const MASKED_POLL_INSTRUCTIONS: u64 = 16;

/// The image on the emulated chip.
pub struct Machine {
    uc: Unicorn<'static, Soc>,
    vectors: Vec<u32>,
    active: Vec<(u32, u64, u64)>,
    /// Every exception handled so far.
    pub handled: Vec<Handled>,
    /// Exceptions the test asked for, raised at the next instruction boundary.
    injected: Vec<u32>,
    /// The last fault the emulator raised (Unicorn's error, the PC).
    pub last_fault: Option<String>,
    /// Since when (bus units) an enabled interrupt has been pending but masked.
    masked_since: Option<u64>,
    /// The image's symbols (name, address, size).
    symbols: Vec<(String, u32, u32)>,
}

fn uc_err(e: unicorn_engine::unicorn_const::uc_error) -> Stop {
    Stop::Emulator(format!("{e:?}"))
}

/// WFI, Thumb encoding T1 (ARMv7-M A7.7.261).
const WFI: u16 = 0xBF30;

/// The addresses of every WFI encoding in the image's flash, at the flash address and at
/// its alias at 0 (the boot mapping): a superset of the WFI instructions (a
/// halfword of data or of a 32-bit instruction can read 0xBF30 too), told apart at the
/// fetch by the instruction's width and address.
fn wfi_sites(image: &Image) -> Vec<u64> {
    let mut sites = Vec::new();
    for (seg_addr, bytes) in &image.segments {
        let a = u64::from(*seg_addr);
        if !(FLASH.0..FLASH.0 + FLASH.1 as u64).contains(&a) {
            continue;
        }
        let skew = (a & 1) as usize;
        for (k, h) in bytes[skew..].chunks_exact(2).enumerate() {
            if u16::from_le_bytes([h[0], h[1]]) == WFI {
                let at = a + (skew + 2 * k) as u64;
                sites.extend([at, at - FLASH.0]);
            }
        }
    }
    sites
}

impl Machine {
    /// Loads `image` and resets the core: SP and PC from the vector table (ARMv7-M
    /// B1.5.5).
    pub fn new(image: &Image, soc: Soc) -> Result<Self, Stop> {
        let mut uc = Unicorn::new_with_data(Arch::ARM, Mode::THUMB | Mode::MCLASS, soc).map_err(uc_err)?;
        for (base, len) in [FLASH, (0, FLASH.1)] {
            uc.mem_map(base, len, Permission::READ | Permission::EXEC)
                .map_err(uc_err)?;
        }
        for (base, len) in [SRAM, CCM] {
            uc.mem_map(base, len, Permission::ALL).map_err(uc_err)?;
        }
        for (seg_addr, bytes) in &image.segments {
            let a = u64::from(*seg_addr);
            uc.mem_write(a, bytes).map_err(uc_err)?;
            if (FLASH.0..FLASH.0 + FLASH.1 as u64).contains(&a) {
                uc.mem_write(a - FLASH.0, bytes).map_err(uc_err)?;
            }
        }
        for (base, len) in MMIO {
            uc.mmio_map(
                base,
                len,
                Some(move |uc: &mut Unicorn<'_, Soc>, off: u64, size: usize| {
                    let soc = uc.get_data_mut();
                    match soc.read((base + off) as u32, size) {
                        Ok(v) => u64::from(v),
                        Err(b) => {
                            soc.fail(b);
                            let _ = uc.emu_stop();
                            0
                        }
                    }
                }),
                Some(move |uc: &mut Unicorn<'_, Soc>, off: u64, size: usize, value: u64| {
                    let soc = uc.get_data_mut();
                    if let Err(b) = soc.write((base + off) as u32, size, value as u32) {
                        soc.fail(b);
                        let _ = uc.emu_stop();
                    }
                }),
            )
            .map_err(uc_err)?;
        }
        // Time: one instruction per HCLK cycle; stop at the deadline, and at a WFI (Thumb
        // encoding 0xBF30, ARMv7-M A7.7.261) outside a handler, whose sleep the harness
        // skips (`run_while`). Flash is mapped read/execute only, so its halfwords never
        // change: the WFI encodings in it are found once here (the images have one, at
        // two addresses with the boot alias), and an instruction fetched from flash is a
        // WFI when it is 16 bits wide at one of them. Code anywhere else (RAM) is read at
        // the fetch. One hook does both: Unicorn walks its list of code hooks at every
        // instruction, and separate hooks on the WFI sites and RAM made that walk a
        // quarter of the emulator's time (`perf`, issue 29); reading every instruction
        // back through `uc_mem_read` cost about a fifth.
        let wfi_sites = wfi_sites(image);
        let in_flash = |a: u64| (FLASH.0..FLASH.0 + FLASH.1 as u64).contains(&a) || a < FLASH.1 as u64;
        uc.add_code_hook(1, 0, move |uc: &mut Unicorn<'_, Soc>, addr: u64, size: u32| {
            let wfi = size == 2
                && if in_flash(addr) {
                    wfi_sites.contains(&addr)
                } else {
                    let mut op = [0u8; 2];
                    uc.mem_read(addr, &mut op).is_ok() && u16::from_le_bytes(op) == WFI
                };
            let soc = uc.get_data_mut();
            if soc.now + soc.cost > soc.deadline || soc.violation.is_some() {
                let _ = uc.emu_stop();
                return;
            }
            soc.now += soc.cost;
            soc.instructions += 1;
            soc.pc = addr as u32;
            if wfi && !soc.irq_active {
                soc.wfi_at = Some(addr as u32);
                let _ = uc.emu_stop();
            }
        })
        .map_err(uc_err)?;
        let vectors: Vec<u32> = image.vectors.clone();
        let mut m = Self {
            uc,
            vectors,
            active: Vec::new(),
            handled: Vec::new(),
            injected: Vec::new(),
            last_fault: None,
            masked_since: None,
            symbols: image.symbols.clone(),
        };
        let sp = m.vector(0)?;
        let reset = m.vector(1)?;
        m.reg_w(RegisterARM::MSP, sp)?;
        m.reg_w(RegisterARM::SP, sp)?;
        m.reg_w(RegisterARM::PC, reset & !1)?;
        Ok(m)
    }

    fn vector(&self, n: u32) -> Result<u32, Stop> {
        let vtor = self.uc.get_data().scs.vtor();
        if vtor != 0 && vtor != FLASH.0 as u32 {
            let mut b = [0; 4];
            self.uc.mem_read(u64::from(vtor + 4 * n), &mut b).map_err(uc_err)?;
            return Ok(u32::from_le_bytes(b));
        }
        self.vectors
            .get(n as usize)
            .copied()
            .ok_or_else(|| Stop::Emulator(format!("no vector {n} in the image")))
    }

    fn reg(&self, r: RegisterARM) -> Result<u32, Stop> {
        self.uc.reg_read(r).map(|v| v as u32).map_err(uc_err)
    }

    fn reg_w(&mut self, r: RegisterARM, v: u32) -> Result<(), Stop> {
        self.uc.reg_write(r, u64::from(v)).map_err(uc_err)
    }

    fn write_words(&mut self, addr: u32, words: &[u32]) -> Result<(), Stop> {
        let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
        self.uc.mem_write(u64::from(addr), &bytes).map_err(uc_err)
    }

    fn read_words<const N: usize>(&self, addr: u32) -> Result<[u32; N], Stop> {
        let mut b = vec![0; 4 * N];
        self.uc.mem_read(u64::from(addr), &mut b).map_err(uc_err)?;
        Ok(std::array::from_fn(|k| {
            u32::from_le_bytes([b[4 * k], b[4 * k + 1], b[4 * k + 2], b[4 * k + 3]])
        }))
    }

    fn read_word(&self, addr: u32) -> Result<u32, Stop> {
        let mut b = [0; 4];
        self.uc.mem_read(u64::from(addr), &mut b).map_err(uc_err)?;
        Ok(u32::from_le_bytes(b))
    }

    /// The chip.
    pub fn soc(&self) -> &Soc {
        self.uc.get_data()
    }

    /// The chip, to drive its inputs.
    pub fn soc_mut(&mut self) -> &mut Soc {
        self.uc.get_data_mut()
    }

    /// The address of the image's first symbol whose name contains `part`.
    pub fn symbol(&self, part: &str) -> Option<u32> {
        self.symbols.iter().find(|(n, _, _)| n.contains(part)).map(|s| s.1)
    }

    /// A word of memory (RAM or flash).
    pub fn peek(&self, addr: u32) -> Result<u32, Stop> {
        self.read_word(addr)
    }

    /// Raises exception `n` (e.g. [`HARD_FAULT`]) at the next instruction boundary.
    pub fn inject(&mut self, n: u32) {
        self.injected.push(n);
    }

    /// Exception entry (ARMv7-M B1.5.6–B1.5.7): the extended frame pushed on the main
    /// stack (8-byte aligned, xPSR bit 9 recording the padding), LR = EXC_RETURN, PC =
    /// the vector.
    fn enter(&mut self, n: u32) -> Result<(), Stop> {
        use RegisterARM::*;
        let mut sp = self.reg(SP)?;
        let pad = sp & 4;
        sp = (sp - pad).wrapping_sub(FRAME_BYTES);
        let mut xpsr = self.reg(XPSR)? & !(1 << 9);
        if pad != 0 {
            xpsr |= 1 << 9;
        }
        // The frame is assembled here and written with one store: each `uc_mem_write`
        // looks for translated code to invalidate in the pages it touches.
        let mut frame = [0u32; FRAME_BYTES as usize / 4];
        let core = [R0, R1, R2, R3, R12, LR, PC];
        for (k, r) in core.iter().enumerate() {
            frame[k] = self.reg(*r)?;
        }
        frame[7] = xpsr;
        for k in 0..16 {
            frame[8 + k] = self.uc.reg_read(i32::from(S0) + k as i32).map_err(uc_err)? as u32;
        }
        frame[24] = self.reg(FPSCR)?;
        self.write_words(sp, &frame)?;
        let handler = self.vector(n)?;
        self.reg_w(SP, sp)?;
        self.reg_w(LR, EXC_RETURN)?;
        self.reg_w(PC, handler & !1)?;
        let soc = self.uc.get_data_mut();
        soc.now += ENTRY_CYCLES * soc.cost;
        let (at, ins) = (soc.now, soc.instructions);
        if n >= 16 {
            soc.scs.set_pending(n - 16, false);
            soc.irq_active = true;
        }
        self.active.push((n, ins, at));
        Ok(())
    }

    /// Exception return: the frame popped, the registers restored.
    fn exit(&mut self) -> Result<(), Stop> {
        use RegisterARM::*;
        let sp = self.reg(SP)?;
        let frame: [u32; FRAME_BYTES as usize / 4] = self.read_words(sp)?;
        let core = [R0, R1, R2, R3, R12, LR, PC];
        for (k, r) in core.iter().enumerate() {
            self.reg_w(*r, frame[k])?;
        }
        let xpsr = frame[7];
        for k in 0..16 {
            self.uc
                .reg_write(i32::from(S0) + k as i32, u64::from(frame[8 + k]))
                .map_err(uc_err)?;
        }
        self.reg_w(FPSCR, frame[24])?;
        self.reg_w(APSR_NZCVQ, xpsr & 0xF800_0000)?;
        self.reg_w(SP, sp + FRAME_BYTES + ((xpsr >> 9) & 1) * 4)?;
        if let Some((n, ins, at)) = self.active.pop() {
            if n >= 16 {
                let soc = self.uc.get_data_mut();
                soc.irq_active = false;
                soc.irq_exit();
            }
            let exit = self.uc.get_data().instructions;
            self.handled.push(Handled {
                exception: n,
                entry: ins,
                exit,
                at,
            });
        }
        Ok(())
    }

    /// Runs until `seconds` of emulated time have passed since reset (or it stops).
    pub fn run_until(&mut self, seconds: f64) -> Result<(), Stop> {
        self.run_while(seconds, |_| true).map(|_| ())
    }

    /// Runs until `seconds` or until `go_on` returns false (checked at every event);
    /// returns whether `go_on` stopped it.
    pub fn run_while(&mut self, seconds: f64, mut go_on: impl FnMut(&Self) -> bool) -> Result<bool, Stop> {
        // Rounded up, so that the time reached is at least `seconds`.
        let end = (seconds * UNITS_PER_S).ceil() as u64;
        loop {
            {
                let soc = self.uc.get_data_mut();
                soc.service();
                if let Some(v) = soc.violation.clone() {
                    return Err(Stop::Violation(v));
                }
                if let Some(t) = soc.watchdog_reset {
                    return Err(Stop::WatchdogReset(t));
                }
            }
            if !go_on(self) {
                return Ok(true);
            }
            if self.uc.get_data().now >= end {
                return Ok(false);
            }
            let entered = self.handled.len() + self.active.len();
            self.take_exceptions()?;
            let soc = self.uc.get_data_mut();
            if self.handled.len() + self.active.len() != entered || soc.scs.active_irq().is_some() {
                // An exception taken, or an interrupt pending that PRIMASK holds off, wakes
                // a sleeping core (execution goes on after the WFI).
                soc.sleeping = false;
            }
            let mut next = self.uc.get_data_mut().next_event();
            // An enabled interrupt held off by PRIMASK is taken as soon as the core
            // clears it (CPSIE, ARMv7-M B1.5.4); the run stops every
            // `MASKED_POLL_INSTRUCTIONS` to look, instead of at the next peripheral event
            // (a whole period later, when the next trigger would merge with it).
            if self.active.is_empty() && self.uc.get_data().scs.active_irq().is_some() {
                let soc = self.uc.get_data();
                next = next.min(soc.now + MASKED_POLL_INSTRUCTIONS * soc.cost);
            }
            let soc = self.uc.get_data_mut();
            soc.deadline = next.min(end).max(soc.now + soc.cost);
            if soc.sleeping {
                // Asleep in WFI: nothing runs until the next event (an interrupt, or the
                // end of this run, after which the test may act and the sleep goes on).
                soc.now = soc.deadline.min(end).max(soc.now);
                continue;
            }
            let pc = self.reg(RegisterARM::PC)?;
            // No `until` address (0): Unicorn invalidates the translated code at the
            // `until` address after every run it stops (`resume_all_vcpus`), unless it is
            // 0, and the harness starts one run per peripheral event — that invalidation
            // was an eighth of the emulator's time (`perf`, issue 29). A handler's return,
            // the branch to EXC_RETURN, ends the run as an error instead (below). Address
            // 0 is flash's boot alias, the initial stack pointer's word: execution never
            // gets there but by a branch to it (to 0x1: a BX to an even address is an
            // INVSTATE UsageFault first, ARMv7-M A7.7.20), where the run stops.
            match self.uc.emu_start(u64::from(pc | 1), 0, 0, 0) {
                Ok(()) => {
                    if let Some(at) = self.uc.get_data_mut().wfi_at.take() {
                        // The WFI (a 16-bit instruction) is done: the core sleeps after it.
                        self.reg_w(RegisterARM::PC, at + 2)?;
                        self.uc.get_data_mut().sleeping = true;
                    } else if self.reg(RegisterARM::PC)? == EXC_RETURN & !1 {
                        self.exit()?;
                    } else if self.reg(RegisterARM::PC)? == 0 {
                        // A branch to address 0 executes the initial stack pointer (a RAM
                        // address, 0x2000_xxxx) as Thumb code: on the G474 an undefined
                        // instruction or a bus fault, escalated to HardFault (ARMv7-M
                        // B1.5.14) — here the fault at once.
                        let soc = self.uc.get_data_mut();
                        soc.pc = 0;
                        self.last_fault = Some("a branch to address 0".to_string());
                        self.fault()?;
                    }
                }
                Err(e) => {
                    if self.uc.get_data().violation.is_some() {
                        continue;
                    }
                    // A branch to EXC_RETURN is the handler's return: the M33 model in
                    // secure state raises its exception-exit exception for it even in
                    // thread mode (QEMU's FNC_RETURN / EXC_RETURN check), or the fetch
                    // from the unmapped address fails.
                    let pc = self.reg(RegisterARM::PC)?;
                    if !self.active.is_empty() && pc >= 0xFEFF_FFFE {
                        self.exit()?;
                        continue;
                    }
                    // A bus error, undefined instruction or other fault: escalated to
                    // HardFault, as the image enables no configurable fault handler
                    // (ARMv7-M B1.5.14).
                    self.last_fault = Some(format!("{e:?} at PC {:#010x}", self.uc.get_data().pc));
                    self.fault()?;
                }
            }
        }
    }

    /// A fault at the current instruction: HardFault, or lockup if already in it.
    fn fault(&mut self) -> Result<(), Stop> {
        if self.active.iter().any(|&(n, _, _)| n == HARD_FAULT) {
            let soc = self.uc.get_data_mut();
            let t = soc.time_s();
            // ARMv7-M B1.5.15: a fault in the HardFault handler locks the core up; with
            // SYSCFG_CFGR2.CLL the LOCKUP output is TIM1's break (RM0440 §10.2.8).
            if soc.syscfg.lockup_to_break() {
                soc.break_asserted = true;
                soc.update_break();
            } else if soc.gates_can_switch() {
                soc.fail(Broken::new(
                    "core LOCKUP",
                    "the core locked up (a fault inside the HardFault handler, ARMv7-M B1.5.15) with the bridge still switching and SYSCFG_CFGR2.CLL clear: TIM1 keeps running with the last compare values and no code can clear MOE — CLL routes LOCKUP to TIM1's break (RM0440 §10.2.8)",
                ));
                if let Some(v) = soc.violation.clone() {
                    return Err(Stop::Violation(v));
                }
            }
            return Err(Stop::Lockup(t));
        }
        let pc = self.uc.get_data().pc;
        self.reg_w(RegisterARM::PC, pc)?;
        self.enter(HARD_FAULT)
    }

    /// Takes an injected exception, or a pending enabled interrupt when no handler is
    /// active and neither PRIMASK nor BASEPRI masks it (the image has one interrupt;
    /// ARMv7-M B1.5.4: BASEPRI ≠ 0 masks every priority value ≥ BASEPRI; the G474's NVIC
    /// keeps the upper 4 bits). An interrupt held off for longer than a carrier period
    /// misses a control period: a strict-mode failure naming the mask.
    fn take_exceptions(&mut self) -> Result<(), Stop> {
        if let Some(b) = self.uc.get_data_mut().basepri_request.take() {
            self.reg_w(RegisterARM::BASEPRI, b)?;
        }
        if !self.injected.is_empty() {
            // All injected at once, before any instruction of a handler runs: a second
            // HardFault is a fault at the first one's first instruction.
            while let Some(n) = self.injected.pop() {
                if n == HARD_FAULT && self.active.iter().any(|&(a, _, _)| a == HARD_FAULT) {
                    self.fault()?;
                } else {
                    self.enter(n)?;
                }
            }
            return Ok(());
        }
        if !self.active.is_empty() {
            return Ok(());
        }
        let Some(irq) = self.uc.get_data().scs.active_irq() else {
            self.masked_since = None;
            return Ok(());
        };
        let primask = self.reg(RegisterARM::PRIMASK)? & 1 != 0;
        let basepri = self.reg(RegisterARM::BASEPRI)? & 0xF0;
        let soc = self.uc.get_data_mut();
        let prio = u32::from(soc.scs.priority(irq));
        let by_basepri = basepri != 0 && prio >= basepri;
        if !primask && !by_basepri {
            self.masked_since = None;
            return self.enter(16 + irq);
        }
        let since = *self.masked_since.get_or_insert(soc.now);
        let period = soc.tim1.period_ticks() * soc.tim1.tick;
        if period > 0 && soc.now - since > period {
            let mask = if by_basepri {
                format!("BASEPRI = {basepri:#04x} (its priority {prio:#04x} ≥ BASEPRI)")
            } else {
                "PRIMASK".to_string()
            };
            soc.fail(Broken::new(
                format!("NVIC IRQ {irq}"),
                format!(
                    "the control interrupt has been pending and enabled but masked by {mask} for {:.1} µs, longer than a carrier period ({:.1} µs): the control loop misses its periods (ARMv7-M B1.5.4, exception priorities and BASEPRI)",
                    (soc.now - since) as f64 / UNITS_PER_S * 1e6,
                    period as f64 / UNITS_PER_S * 1e6
                ),
            ));
        }
        Ok(())
    }

    /// A one-line account of the state, for failure messages.
    pub fn summary(&self) -> String {
        let s = self.soc();
        format!(
            "t = {:.1} µs, PC {:#010x}, {} instructions; TIM1 {} updates {} triggers, MOE {}, SR {:#x}; ADC sequences {}/{}, \
             missed triggers {}/{}, ADC1 CR {:#x} JSQR {:#x}, TIM1 CR2 {:#x}; NVIC enabled {:#x} pending {:#x}; handlers {:?}; active {:?}; FDCAN accepted {} rejected {}; IWDG refreshes {}; last fault {:?}",
            s.time_s() * 1e6,
            s.pc,
            s.instructions,
            s.tim1.updates,
            s.tim1.triggers,
            s.tim1.moe(),
            s.tim1.sr(),
            s.adc[0].sequences,
            s.adc[1].sequences,
            s.adc[0].missed_triggers,
            s.adc[1].missed_triggers,
            s.adc[0].reg(0x08),
            s.adc[0].reg(0x4C),
            s.tim1.reg(0x04),
            s.scs.enabled[0],
            s.scs.pending[0],
            self.handled.iter().map(|h| h.exception).take(8).collect::<Vec<_>>(),
            self.active,
            s.fdcan.accepted,
            s.fdcan.rejected,
            s.iwdg.refreshes,
            self.last_fault,
        )
    }

    /// Instructions of each completed handler of exception `n`.
    pub fn handler_instructions(&self, n: u32) -> Vec<u64> {
        self.handled
            .iter()
            .filter(|h| h.exception == n)
            .map(|h| h.exit - h.entry)
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::soc::tests::Quiet;

    /// A branch to address 0 (flash's boot alias, where the initial stack pointer's word
    /// is) is a HardFault: with no `until` address a run that stopped at 0 must not be
    /// started again at 0 for ever.
    #[test]
    fn a_branch_to_address_zero_is_a_hard_fault() {
        // Vector table: SP, reset → 0x0800_0201, HardFault → 0x0800_0301 (Thumb).
        let mut flash = vec![0u8; 0x400];
        let mut word = |at: usize, v: u32| flash[at..at + 4].copy_from_slice(&v.to_le_bytes());
        word(0, 0x2000_8000);
        word(4, 0x0800_0201);
        word(4 * HARD_FAULT as usize, 0x0800_0301);
        // Reset: MOVS r0, #1; BX r0 (to 0x0, Thumb). HardFault: B . (ARMv7-M A7.7.76,
        // A7.7.20, A7.7.12).
        flash[0x200..0x204].copy_from_slice(&[0x01, 0x20, 0x00, 0x47]);
        flash[0x300..0x302].copy_from_slice(&[0xFE, 0xE7]);
        let vectors = flash
            .chunks_exact(4)
            .take(16)
            .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect();
        let image = Image {
            segments: vec![(0x0800_0000, flash)],
            vectors,
            symbols: Vec::new(),
        };
        let hw = hardware::for_board("motorgen-reference").unwrap();
        let soc = Soc::new(Wiring::new(hw), Box::new(Quiet), 0, Patches::default());
        let mut m = Machine::new(&image, soc).unwrap();
        m.run_until(20e-6).unwrap();
        // Unicorn 2.0.1's M33 raises an exception for the BX itself (the error path,
        // `last_fault` naming the BX's address); the stop at 0 (the `Ok` path) is the
        // guard for a branch that reaches it. Either way: HardFault's handler runs.
        assert!(m.last_fault.is_some(), "{}", m.summary());
        assert_eq!(m.soc().pc, 0x0800_0300, "{}", m.summary());
    }
}
