//! The bus: routes each access to its register model, checks the peripheral's RCC clock
//! enable, keeps emulated time, and carries the signals between blocks (TIM1's trigger
//! to the ADCs and TIM3, the break pin to TIM1, the ADC interrupt to the NVIC).

use codegen::board::Signal;

use crate::periph::adc::{Adc, JEXTSEL_TIM1_TRGO2};
use crate::periph::clock::{self, AHB1ENR, AHB2ENR, APB1ENR1, APB2ENR, Clocks};
use crate::periph::fdcan::{self, Fdcan};
use crate::periph::gpio::{Mode, Port};
use crate::periph::math::{Cordic, Fmac};
use crate::periph::system::{IRQ_ADC1_2, Iwdg, Scs, Syscfg};
use crate::periph::tim1::{Tim1, TimerEvent};
use crate::periph::tim3::Tim3;
use crate::violation::{Broken, Violation};

/// Bus time unit: 1/8 of a 170 MHz cycle, so 16, 85 and 170 MHz cycles are whole
/// numbers of units (85, 16 and 8).
pub const UNITS_PER_S: f64 = 1.36e9;

/// A pin: port (0 = A), number, alternate function.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Pin {
    /// Port index (0 = A).
    pub port: u8,
    /// Pin number.
    pub number: u8,
    /// Alternate function of its board signal.
    pub af: u8,
}

/// How the board connects the chip: from the board file (codegen's pin and ADC data).
#[derive(Clone, Debug)]
pub struct Wiring {
    /// Gate pins: u, v, w high sides, then u, v, w low sides.
    pub gates: [Pin; 6],
    /// TIM1_BKIN.
    pub break_pin: Pin,
    /// TIM3_CH1 (resolver excitation).
    pub excitation: Pin,
    /// ADC1 and ADC2 inputs: (channel, signal).
    pub adc_inputs: [Vec<(u8, Signal)>; 2],
    /// V_REF+ \[V\].
    pub vref: f64,
    /// Break input level when the comparator is idle (the inactive level).
    pub break_idle_high: bool,
}

/// The analog inputs, as the test drives them.
pub trait Analog: std::any::Any {
    /// Voltage at the pin of `signal` at `t` \[s\]; `excitation_high` is the resolver
    /// excitation's sign at that instant (the level of its square wave).
    fn volts(&mut self, signal: Signal, t: f64, excitation_high: bool) -> f64;

    /// From `t` \[s\] on the bridge applies `duties` (each high side's on-time fraction
    /// of the carrier period; `None`: not switching). Called at every TIM1 update event
    /// (where the preloaded compare values become active, RM0440 §28.3.10) and whenever
    /// MOE changes. A source that does not depend on the bridge ignores it.
    fn bridge(&mut self, _t: f64, _duties: Option<[f64; 3]>) {}
}

/// Something the bus recorded.
#[derive(Clone, Debug, PartialEq)]
pub enum Note {
    /// MOE changed to the value at the time \[s\].
    MainOutput(f64, bool),
    /// The first update event with MOE = 1 (the first enabled PWM period) \[s\].
    FirstEnabledPeriod(f64),
}

/// Fault injection into the sequence the emulator sees (the defect tests).
#[derive(Clone, Debug, Default)]
pub struct Patches {
    /// ADC_CR writes that set ADEN again after the first are dropped, as if the image
    /// wrote ADEN once and then waited (the bring-up before review fix 1).
    pub single_aden_write: bool,
    /// The image's first TIM1_BDTR write is split into the write without LOCK and a
    /// second write adding it (the bring-up before review fix 4).
    pub bdtr_lock_second_write: bool,
    /// TIM1's trigger no longer reaches the ADCs: the control interrupt stalls.
    pub drop_triggers: bool,
}

/// The chip around the core.
pub struct Soc {
    /// Emulated time in [`UNITS_PER_S`].
    pub now: u64,
    /// Instructions executed.
    pub instructions: u64,
    /// Time units per instruction at the current HCLK (one instruction per cycle).
    pub cost: u64,
    /// Run until this time.
    pub deadline: u64,
    /// Address of the instruction being executed.
    pub pc: u32,
    /// The first strict-mode failure.
    pub violation: Option<Violation>,
    /// RCC, PWR, FLASH.
    pub clocks: Clocks,
    /// GPIOA–C.
    pub gpio: [Port; 3],
    /// SYSCFG.
    pub syscfg: Syscfg,
    /// NVIC/SCB/SysTick/MPU/DBGMCU.
    pub scs: Scs,
    /// TIM1.
    pub tim1: Tim1,
    /// TIM3.
    pub tim3: Tim3,
    /// ADC1, ADC2.
    pub adc: [Adc; 2],
    adc_ccr: u32,
    /// CORDIC.
    pub cordic: Cordic,
    /// FMAC.
    pub fmac: Fmac,
    /// FDCAN1.
    pub fdcan: Fdcan,
    /// IWDG.
    pub iwdg: Iwdg,
    /// Board wiring.
    pub wiring: Wiring,
    /// Analog inputs.
    pub analog: Box<dyn Analog>,
    /// The break comparator asserts its active level.
    pub break_asserted: bool,
    /// What happened.
    pub notes: Vec<Note>,
    /// Injected faults.
    pub patches: Patches,
    aden_writes: [u32; 2],
    /// TIM1 events before these times (update, trigger) have been delivered.
    tim1_cursor: [u64; 2],
    /// The watchdog reset the chip at this time \[s\].
    pub watchdog_reset: Option<f64>,
    /// The control interrupt's handler is running (set by the core).
    pub irq_active: bool,
    /// The core executed WFI and sleeps until an enabled interrupt is pending (ARMv7-M
    /// B1.5.18: WFI suspends execution until a wake-up event; an interrupt wakes it even
    /// while PRIMASK masks it). The harness skips the time in between.
    pub sleeping: bool,
    /// Address of a WFI the code hook stopped at (it then resumes after it, asleep).
    pub wfi_at: Option<u32>,
}

/// Which block an address belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Block {
    Tim3,
    Iwdg,
    Fdcan,
    FdcanRam,
    Pwr,
    Syscfg,
    Tim1,
    Cordic,
    Rcc,
    Fmac,
    Flash,
    Gpio(usize),
    Adc(usize),
    AdcCommon,
    Scs,
}

/// An RCC enable register and bit.
type Gate = Option<(u32, u32)>;

/// Address map (RM0440 §2.2.2, Table 4) and RCC enable bit of each block (RM0440 §7.4).
fn decode(addr: u32) -> Option<(Block, u32, Gate)> {
    let b = |base: u32, len: u32| (base..base + len).contains(&addr).then_some(addr - base);
    let table: [(u32, u32, Block, Gate); 17] = [
        (0x4000_0400, 0x400, Block::Tim3, Some((APB1ENR1, 1))),
        (0x4000_3000, 0x400, Block::Iwdg, None),
        (0x4000_6400, 0x400, Block::Fdcan, Some((APB1ENR1, 25))),
        (0x4000_7000, 0x400, Block::Pwr, Some((APB1ENR1, 28))),
        (fdcan::RAM_BASE, fdcan::RAM_BYTES, Block::FdcanRam, Some((APB1ENR1, 25))),
        (0x4001_0000, 0x400, Block::Syscfg, Some((APB2ENR, 0))),
        (0x4001_2C00, 0x400, Block::Tim1, Some((APB2ENR, 11))),
        (0x4002_0C00, 0x400, Block::Cordic, Some((AHB1ENR, 3))),
        (0x4002_1000, 0x400, Block::Rcc, None),
        (0x4002_1400, 0x400, Block::Fmac, Some((AHB1ENR, 4))),
        (0x4002_2000, 0x400, Block::Flash, Some((AHB1ENR, 8))),
        (0x4800_0000, 0x400, Block::Gpio(0), Some((AHB2ENR, 0))),
        (0x4800_0400, 0x400, Block::Gpio(1), Some((AHB2ENR, 1))),
        (0x4800_0800, 0x400, Block::Gpio(2), Some((AHB2ENR, 2))),
        (0x5000_0000, 0x100, Block::Adc(0), Some((AHB2ENR, 13))),
        (0x5000_0100, 0x100, Block::Adc(1), Some((AHB2ENR, 13))),
        (0x5000_0300, 0x100, Block::AdcCommon, Some((AHB2ENR, 13))),
    ];
    for (base, len, block, gate) in table {
        if let Some(off) = b(base, len) {
            return Some((block, off, gate));
        }
    }
    b(0xE000_0000, 0x10_0000).map(|off| (Block::Scs, off, None))
}

fn block_name(block: Block) -> String {
    match block {
        Block::Gpio(k) => format!("GPIO{}", char::from(b'A' + k as u8)),
        Block::Adc(k) => format!("ADC{}", k + 1),
        b => format!("{b:?}").to_uppercase(),
    }
}

impl Soc {
    /// The chip at reset with FLASH_OPTR = `optr`.
    pub fn new(wiring: Wiring, analog: Box<dyn Analog>, optr: u32, patches: Patches) -> Self {
        let mut soc = Self {
            now: 0,
            instructions: 0,
            cost: 85,
            deadline: 0,
            pc: 0,
            violation: None,
            clocks: Clocks::new(optr),
            gpio: [Port::new(0), Port::new(1), Port::new(2)],
            syscfg: Syscfg::default(),
            scs: Scs::default(),
            tim1: Tim1::new(),
            tim3: Tim3::default(),
            adc: [Adc::new("ADC1"), Adc::new("ADC2")],
            adc_ccr: 0,
            cordic: Cordic::default(),
            fmac: Fmac::default(),
            fdcan: Fdcan::new(),
            iwdg: Iwdg::default(),
            wiring,
            analog,
            break_asserted: false,
            notes: Vec::new(),
            patches,
            aden_writes: [0; 2],
            tim1_cursor: [0; 2],
            watchdog_reset: None,
            irq_active: false,
            sleeping: false,
            wfi_at: None,
        };
        soc.update_clock();
        soc
    }

    /// Emulated time \[s\].
    pub fn time_s(&self) -> f64 {
        self.now as f64 / UNITS_PER_S
    }

    fn update_clock(&mut self) {
        self.cost = (UNITS_PER_S / self.clocks.hclk_hz()).round().max(1.0) as u64;
    }

    /// One ADC clock period \[s\] (ADC12_CCR.CKMODE: HCLK/1, /2, /4; RM0440 §21.4.3);
    /// `None` for the asynchronous clock, which the model does not have.
    fn adc_clock_s(&self) -> Option<f64> {
        let div = match (self.adc_ccr >> 16) & 3 {
            1 => 1.0,
            2 => 2.0,
            3 => 4.0,
            _ => return None,
        };
        Some(div / self.clocks.hclk_hz())
    }

    /// Level of a pin: whatever drives it (output data, TIM1/TIM3 through the alternate
    /// function the board names) or, for the break pin, the comparator.
    pub fn pin_level(&self, port: u8, number: u8) -> bool {
        let p = &self.gpio[usize::from(port)];
        let w = &self.wiring;
        let is = |pin: &Pin| pin.port == port && pin.number == number;
        if is(&w.break_pin) {
            return self.break_asserted != w.break_idle_high;
        }
        match p.mode(number) {
            Mode::Output => p.odr(number),
            Mode::Alternate(af) => {
                if let Some(k) = w.gates.iter().position(|g| is(g) && g.af == af) {
                    self.tim1.gate_levels(self.now)[k]
                } else if is(&w.excitation) && w.excitation.af == af {
                    self.tim3.output(self.now)
                } else {
                    false
                }
            }
            Mode::Input | Mode::Analog => false,
        }
    }

    /// The six gate signals as driven now (high u, v, w; low u, v, w).
    pub fn gates(&self) -> [bool; 6] {
        self.wiring.gates.map(|g| self.pin_level(g.port, g.number))
    }

    /// Whether any gate pin can switch on: routed to TIM1 with MOE = 1, or a GPIO output
    /// driven high.
    pub fn gates_can_switch(&self) -> bool {
        self.wiring.gates.iter().any(|g| {
            let p = &self.gpio[usize::from(g.port)];
            match p.mode(g.number) {
                Mode::Alternate(af) => af == g.af && self.tim1.moe(),
                Mode::Output => p.odr(g.number),
                _ => false,
            }
        })
    }

    /// TIM1's BKIN as the timer sees it: the pin if routed to TIM1_BKIN, else low (an
    /// unrouted input reads 0; with active-low polarity that is a break — review defect 3).
    fn bkin_level(&self) -> bool {
        let b = self.wiring.break_pin;
        match self.gpio[usize::from(b.port)].mode(b.number) {
            Mode::Alternate(af) if af == b.af => self.pin_level(b.port, b.number),
            _ => false,
        }
    }

    /// Re-evaluates the break after anything that can change it.
    pub fn update_break(&mut self) {
        self.tim1.break_active = self.tim1.break_input_active(self.bkin_level());
        let moe = self.tim1.moe();
        self.tim1.apply_break();
        if moe && !self.tim1.moe() {
            self.notes.push(Note::MainOutput(self.time_s(), false));
            self.bridge_changed(self.now);
        }
    }

    /// Tells the analog source what the bridge applies from `t` (bus units) on.
    fn bridge_changed(&mut self, t: u64) {
        let duties = self.tim1.duties();
        self.analog.bridge(t as f64 / UNITS_PER_S, duties);
    }

    /// Records a strict-mode failure (the first one counts).
    pub fn fail(&mut self, b: Broken) {
        if self.violation.is_none() {
            self.violation = Some(Violation {
                pc: self.pc,
                register: b.register,
                rule: b.rule,
                at_s: self.time_s(),
            });
        }
    }

    /// A bus read of `size` bytes at `addr`.
    pub fn read(&mut self, addr: u32, size: usize) -> Result<u32, Broken> {
        let (block, off, gate) = self.route(addr, size)?;
        let t = self.now;
        let ts = self.time_s();
        self.service();
        let v = match block {
            Block::Tim3 => self.tim3.read(off, t)?,
            Block::Iwdg => self.iwdg.read(off)?,
            Block::Fdcan => self.fdcan.read(off)?,
            Block::FdcanRam => self.fdcan.ram[(off / 4) as usize],
            Block::Pwr => self.clocks.pwr_read(off)?,
            Block::Syscfg => self.syscfg.read(off)?,
            Block::Tim1 => self.tim1.read(off, t)?,
            Block::Cordic => self.cordic.read(off)?,
            Block::Rcc => self.clocks.rcc_read(off)?,
            Block::Fmac => self.fmac.read(off)?,
            Block::Flash => self.clocks.flash_read(off)?,
            Block::Gpio(k) => {
                let idr = (0..16u8).fold(0, |acc, n| acc | (u32::from(self.pin_level(k as u8, n)) << n));
                self.gpio[k].read(&block_name(block), off, idr)?
            }
            Block::Adc(k) => self.adc[k].read(off, ts)?,
            Block::AdcCommon => match off {
                0x08 => self.adc_ccr,
                // CSR: the ADRDY/EOC/... copies of both converters (RM0440 §21.8.1).
                0x00 => self.adc[0].read(0, ts)? | (self.adc[1].read(0, ts)? << 16),
                0x0C => 0,
                _ => return Err(clock::unknown("ADC12_COMMON", off)),
            },
            Block::Scs => self.scs.read(off)?,
        };
        let _ = gate;
        self.reschedule();
        Ok(v)
    }

    /// An access may have scheduled an earlier event (a counter started, a conversion
    /// begun): the running slice ends there.
    fn reschedule(&mut self) {
        let next = self.next_event();
        self.deadline = self.deadline.min(next.max(self.now));
    }

    /// A bus write.
    pub fn write(&mut self, addr: u32, size: usize, value: u32) -> Result<(), Broken> {
        let (block, off, _) = self.route(addr, size)?;
        let t = self.now;
        let ts = self.time_s();
        self.service();
        match block {
            Block::Tim3 => self.tim3.write(off, value, t)?,
            Block::Iwdg => self.iwdg.write(off, value, ts)?,
            Block::Fdcan => self.fdcan.write(off, value)?,
            Block::FdcanRam => self.fdcan.ram[(off / 4) as usize] = value,
            Block::Pwr => self.clocks.pwr_write(off, value)?,
            Block::Syscfg => self.syscfg.write(off, value)?,
            Block::Tim1 => {
                let moe = self.tim1.moe();
                if off == 0x00 && value & 1 != 0 {
                    self.tim1.tick = (UNITS_PER_S / self.clocks.tim_apb2_hz()).round() as u64;
                    self.tim1_cursor = [t; 2];
                }
                if off == 0x44 && self.patches.bdtr_lock_second_write {
                    self.patches.bdtr_lock_second_write = false;
                    self.tim1.write(off, value & !(3 << 8), t)?;
                }
                self.tim1.write(off, value, t)?;
                self.update_break();
                if moe != self.tim1.moe() {
                    self.notes.push(Note::MainOutput(ts, self.tim1.moe()));
                    self.bridge_changed(t);
                }
            }
            Block::Cordic => self.cordic.write(off, value)?,
            Block::Rcc => {
                self.clocks.rcc_write(off, value, ts)?;
                self.update_clock();
            }
            Block::Fmac => self.fmac.write(off, value)?,
            Block::Flash => self.clocks.flash_write(off, value)?,
            Block::Gpio(k) => {
                self.gpio[k].write(&block_name(block), off, value)?;
                self.update_break();
            }
            Block::Adc(k) => {
                let mut v = value;
                if off == 0x08 && v & 1 != 0 && !self.adc[k].enabled() {
                    self.aden_writes[k] += 1;
                    if self.patches.single_aden_write && self.aden_writes[k] > 1 {
                        v &= !1;
                    }
                }
                let clk = self.adc_clock_s();
                self.adc[k].write(off, v, ts, clk)?;
            }
            Block::AdcCommon => match off {
                0x08 => {
                    if self.adc.iter().any(Adc::enabled) {
                        return Err(Broken::new(
                            "ADC12_CCR",
                            "CKMODE/PRESC written with an ADC enabled (ADEN = 1, RM0440 §21.8.2)",
                        ));
                    }
                    self.adc_ccr = value;
                }
                _ => return Err(clock::unknown("ADC12_COMMON", off)),
            },
            Block::Scs => self.scs.write(off, value)?,
        }
        self.reschedule();
        Ok(())
    }

    /// Decodes an address and checks the access: a known block, whole words, its clock
    /// enabled (RM0440 §7.4: with the enable bit clear the peripheral's registers are
    /// not clocked and cannot be accessed).
    fn route(&mut self, addr: u32, size: usize) -> Result<(Block, u32, Gate), Broken> {
        let Some((block, off, gate)) = decode(addr) else {
            return Err(Broken::new(
                format!("{addr:#010x}"),
                "no peripheral model at this address (RM0440 §2.2.2 memory map)",
            ));
        };
        // IWDG registers also take half-word accesses (RM0440 §41.4).
        let half_ok = block == Block::Iwdg && size == 2;
        if (size != 4 && !half_ok) || off % 4 != 0 {
            return Err(Broken::new(
                format!("{}+{off:#05x}", block_name(block)),
                format!("{size}-byte access: only aligned word accesses are modelled"),
            ));
        }
        if let Some((enr, bit)) = gate
            && self.clocks.enr(enr) & (1 << bit) == 0
        {
            return Err(Broken::new(
                format!("{}+{off:#05x}", block_name(block)),
                format!(
                    "accessed with its clock disabled (RCC+{enr:#04x} bit {bit} = 0): enable the peripheral clock first (RM0440 §7.4)"
                ),
            ));
        }
        Ok((block, off, gate))
    }

    /// The next time something happens by itself (timer events, conversions, the
    /// watchdog), in bus units.
    pub fn next_event(&mut self) -> u64 {
        let mut next = u64::MAX;
        for (k, e) in [TimerEvent::Update, TimerEvent::Trigger].into_iter().enumerate() {
            if let Some(t) = self.tim1.next(e, self.tim1_cursor[k]) {
                next = next.min(t);
            }
        }
        for a in &self.adc {
            if let Some(t) = a.next_event() {
                next = next.min((t * UNITS_PER_S).ceil() as u64);
            }
        }
        if let Some(t) = self.iwdg.expires_at {
            next = next.min((t * UNITS_PER_S).ceil() as u64);
        }
        next
    }

    /// Runs every event due by now, in time order.
    pub fn service(&mut self) {
        loop {
            let now = self.now;
            let tim = [TimerEvent::Update, TimerEvent::Trigger]
                .into_iter()
                .enumerate()
                .filter_map(|(k, e)| self.tim1.next(e, self.tim1_cursor[k]).map(|t| (t, k, e)))
                .filter(|&(t, _, _)| t <= now)
                .min_by_key(|&(t, k, _)| (t, k));
            let adc_due = self
                .adc
                .iter()
                .filter_map(Adc::next_event)
                .map(|t| (t * UNITS_PER_S).ceil() as u64)
                .filter(|&t| t <= now)
                .min();
            match (tim, adc_due) {
                (Some((t, k, e)), a) if a.is_none_or(|a| t <= a) => {
                    self.tim1_cursor[k] = t + 1;
                    self.timer_event(t, e);
                }
                (_, Some(a)) => self.convert(a),
                _ => break,
            }
        }
        if let Some(t) = self.iwdg.expires_at
            && self.time_s() >= t
            && self.watchdog_reset.is_none()
        {
            self.watchdog_reset = Some(t);
        }
        // A level-sensitive interrupt pends while its line is asserted and it is not
        // active; still asserted at the handler's return, it pends again (ARMv7-M B3.4.1).
        let line = self.adc.iter().any(Adc::irq);
        if line && !self.irq_active {
            self.scs.set_pending(IRQ_ADC1_2, true);
        }
    }

    fn timer_event(&mut self, t: u64, e: TimerEvent) {
        match e {
            TimerEvent::Trigger => {
                self.tim1.triggers += 1;
                self.tim3.trgo(t);
                if self.tim1.trgo2_is_oc4ref() && !self.patches.drop_triggers {
                    let ts = t as f64 / UNITS_PER_S;
                    if let Some(clk) = self.adc_clock_s() {
                        for a in &mut self.adc {
                            a.trigger(JEXTSEL_TIM1_TRGO2, ts, clk);
                        }
                    }
                }
            }
            TimerEvent::Update => {
                self.tim1.update();
                self.bridge_changed(t);
                if self.tim1.moe() && !self.notes.iter().any(|n| matches!(n, Note::FirstEnabledPeriod(_))) {
                    self.notes.push(Note::FirstEnabledPeriod(t as f64 / UNITS_PER_S));
                }
            }
        }
    }

    /// Completes the conversions due at `t` units.
    fn convert(&mut self, t: u64) {
        // Half a unit later: the rank's end time was rounded up to `t` units.
        let ts = (t as f64 + 0.5) / UNITS_PER_S;
        let vref = self.wiring.vref;
        for k in 0..2 {
            let inputs = self.wiring.adc_inputs[k].clone();
            let analog = &mut self.analog;
            let tim3 = &self.tim3;
            let mut unwired = None;
            self.adc[k].complete(ts, |ch, at| {
                let Some(&(_, signal)) = inputs.iter().find(|(c, _)| *c == ch) else {
                    unwired = Some(ch);
                    return 0;
                };
                let v = analog.volts(signal, at, tim3.output((at * UNITS_PER_S) as u64));
                // Ideal 12-bit conversion: code = V/V_REF·4096, clamped (RM0440 §21.4.1).
                (v / vref * 4096.0).floor().clamp(0.0, 4095.0) as u16
            });
            if let Some(ch) = unwired {
                let name = self.adc[k].name;
                self.fail(Broken::new(
                    format!("{name}_JSQR"),
                    format!("channel {ch} converted but the board wires no signal to it"),
                ));
            }
        }
    }
}
