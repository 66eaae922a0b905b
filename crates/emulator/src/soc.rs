//! The bus: routes each access to its register model, checks the peripheral's RCC clock
//! enable, keeps emulated time, and carries the signals between blocks (TIM1's trigger
//! to the ADCs and TIM3, the break pin to TIM1, the ADC interrupt to the NVIC) and out to
//! the board ([`crate::hardware`]): the gate pins through each pin's GPIO mode and
//! alternate function into the gate driver and the switches ([`crate::bridge`]), the
//! analog pins from the board's sensing through the ADC's sampling.

use crate::bridge::{self, LegSwitches, PinWave, Wave};
use crate::hardware::{Analog as Signal, Hardware, port_pin};
use crate::periph::adc::{Adc, JEXTSEL_TIM1_TRGO2, SAR_CYCLES};
use crate::periph::clock::{self, AHB1ENR, AHB2ENR, APB1ENR1, APB2ENR, Clocks};
use crate::periph::fdcan::{self, Fdcan};
use crate::periph::gpio::{Mode, Port};
use crate::periph::math::{Cordic, Fmac};
use crate::periph::system::{IRQ_ADC1_2, Iwdg, Scs, Syscfg};
use crate::periph::tim1::{Tim1, TimerEvent};
use crate::periph::tim3::Tim3;
use crate::violation::{Broken, Violation};

pub use crate::periph::UNITS_PER_S;

/// FLASH_OPTR.nSWBOOT0 (RM0440 §3.7.8): 1 = BOOT0 taken from the PB8-BOOT0 pin.
pub const OPTR_NSWBOOT0: u32 = 1 << 26;

/// TIM1's digital break filter BKF = 0011: f_CK_INT, N = 8 (RM0440 TIMx_BDTR BKF): a
/// pulse shorter than 8 timer clocks is filtered out.
const BREAK_FILTER_TICKS: u64 = 8;

/// The board around the chip: its hardware ([`Hardware`]) with the pins resolved.
#[derive(Clone, Debug)]
pub struct Wiring {
    /// The board's description.
    pub hw: Hardware,
    /// Gate pins (port, number): u/v/w high, then u/v/w low.
    pub gates: [(u8, u8); 6],
    /// The over-current comparator's pin (TIM1_BKIN).
    pub break_pin: (u8, u8),
    /// The resolver excitation pin (TIM3_CH1).
    pub excitation: (u8, u8),
    /// V_REF+ \[V\].
    pub vref: f64,
    /// The pin each channel of ADC1 and ADC2 converts (the chip's table,
    /// [`Hardware::adc_pin`]), looked up once here instead of at every conversion.
    pub adc_pins: [[Option<&'static str>; ADC_CHANNELS]; 2],
}

/// Channels of one ADC, 0–18 (RM0440 §21.4.4: ADCx_INP0 … ADCx_INP18).
const ADC_CHANNELS: usize = 19;

impl Wiring {
    /// The wiring of `hw`.
    pub fn new(hw: Hardware) -> Self {
        let adc_pins = std::array::from_fn(|k| std::array::from_fn(|ch| hw.adc_pin(k + 1, ch as u8)));
        Self {
            gates: hw.gate_inputs().map(|i| port_pin(i.pin)),
            break_pin: port_pin(hw.break_pin),
            excitation: port_pin(hw.excitation_pin),
            vref: hw.vref,
            adc_pins,
            hw,
        }
    }
}

/// The analog inputs, as the test drives them.
pub trait Analog: std::any::Any {
    /// Voltage at the pin of `signal` at `t` \[s\]; `excitation` is the resolver
    /// excitation at that instant, normalised to ±1 at its peaks
    /// ([`crate::periph::tim3::Tim3::excitation`]).
    fn volts(&mut self, signal: Signal, t: f64, excitation: f64) -> f64;

    /// From `t` \[s\] on the bridge applies `duties` (each leg's high-side share of the
    /// carrier period, from the switches the gate driver turns on; `None`: not
    /// switching). Called at every TIM1 update event (where the preloaded compare values
    /// become active, RM0440 §28.3.10) and whenever the outputs change otherwise. A source
    /// that does not depend on the bridge ignores it.
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

/// Fault injection into the sequence the emulator sees: each reproduces one defect of
/// the image's board layer at the bus, without rebuilding the image.
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
    /// TIM1_BDTR is written with DTG = 0: no dead time.
    pub dead_time_zero: bool,
    /// TIM1_BDTR is written with OSSI = OSSR = 0.
    pub drop_ossi_ossr: bool,
    /// The u low-side gate pin's alternate function is written as AF0 (not TIM1_CH1N).
    pub low_side_wrong_af: bool,
    /// SYSCFG_CFGR2 is written without CLL: a core lockup no longer breaks TIM1.
    pub drop_cll: bool,
    /// Within one control interrupt every TIM1_SR read returns what the first returned:
    /// MOE decided from a BIF read at the start of the interrupt.
    pub stale_bif: bool,
    /// ADC_SMPR writes give every slow channel (all but IN1–IN5) 2.5 cycles.
    pub slow_channels_2_5_cycles: bool,
    /// When the image enables the control interrupt, its priority is set to 0x80 by a
    /// byte write to NVIC_IPR and BASEPRI to 0x80: the interrupt is masked.
    pub basepri_masks_control: bool,
    /// FLASH_OPTR reads as nSWBOOT0 = 0 whatever the chip holds: the image's check of
    /// the boot option bytes sees them programmed (the check removed).
    pub optr_reads_programmed: bool,
    /// ADC_CR writes that start the injected conversions (JADSTART) carry ADEN = 1 as
    /// well, as the image's former read-modify-write did (issue 26 item 5).
    pub jadstart_rewrites_aden: bool,
    /// TIM1_CCR1–3 writes of at least this compare value are written one tick above it:
    /// a duty one timer tick beyond the sampling window's limit (`board::MAX_COMPARE`),
    /// as a modulator without the duty limit would exceed it (issue 26 item 3).
    pub compare_beyond: Option<u16>,
    /// TIM3_CCR1 writes are replaced by half TIM3's period, (ARR + 1)/2: the excitation
    /// toggles half a carrier period after TIM1's reset, so its fundamental peaks at the
    /// ADC trigger, not where SIN and COS are held (the image before stop 40).
    pub excitation_peak_at_trigger: bool,
    /// TIM3_CCER writes are made with CC1E cleared: the excitation pin never toggles (a
    /// dead excitation: the resolver's windings carry nothing).
    pub excitation_off: bool,
}

/// A break pulse the test schedules on the comparator.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Pulse {
    /// From `start` to `end` (bus units).
    At(u64, u64),
    /// Asserted, released at this time (bus units).
    Active(u64),
    /// Starting right after the first TIM1_SR read inside the control interrupt at or
    /// after `after` (bus units), lasting `len` (bus units).
    AfterSrReadInIrq {
        /// Not before this time.
        after: u64,
        /// Its length.
        len: u64,
    },
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
    /// FLASH_OPTR as the chip holds it (the option bytes loaded at reset).
    pub optr: u32,
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
    /// Break pulses to come.
    pub pulses: Vec<Pulse>,
    /// What happened.
    pub notes: Vec<Note>,
    /// Injected faults.
    pub patches: Patches,
    /// BASEPRI the core is to take (a patch), applied by the harness.
    pub basepri_request: Option<u32>,
    aden_writes: [u32; 2],
    /// TIM1 events before these times (update, trigger) have been delivered.
    tim1_cursor: [u64; 2],
    /// The watchdog reset the chip at this time \[s\].
    pub watchdog_reset: Option<f64>,
    /// The control interrupt's handler is running (set by the core).
    pub irq_active: bool,
    /// TIM1_SR as first read in the running control interrupt (for `stale_bif`).
    sr_in_irq: Option<u32>,
    /// TIM1's counter has been started: from then on every gate pin must be driven.
    bridge_armed: bool,
    /// The switches as last analysed.
    pub switches: Option<[LegSwitches; 3]>,
    /// The analysis before that: the carrier period before the last update event, whose
    /// tail holds the low-side turn-on a sampling at the update's carrier extreme
    /// follows (the rule "ADC sampling inside a switching edge").
    pub previous_switches: Option<[LegSwitches; 3]>,
    /// Whether `switches` was analysed with MOE = 1.
    switches_enabled: bool,
    /// The core executed WFI and sleeps until an enabled interrupt is pending (ARMv7-M
    /// B1.5.18: WFI suspends execution until a wake-up event; an interrupt wakes it even
    /// while PRIMASK masks it). The harness skips the time in between.
    pub sleeping: bool,
    /// Address of a WFI the code hook stopped at (it then resumes after it, asleep).
    pub wfi_at: Option<u32>,
    /// The phase currents held since the last ADC trigger.
    currents_held: Holds,
    /// The resolver's SIN and COS held since the last ADC trigger.
    resolver_held: Holds,
    /// Measured: per ADC trigger, the mean instant after it at which its conversions
    /// held the phase currents \[s\] (min, max, triggers) — each phase's first
    /// conversion, a later one of the same phase being a repeat the image discards
    /// (ES0430 lock-step padding).
    pub current_sample_instant: Option<(f64, f64, u64)>,
    /// The same for the resolver's SIN and COS.
    pub resolver_sample_instant: Option<(f64, f64, u64)>,
    /// Measured: the instant \[s\] SIN and the instant COS was last held, and the resolver
    /// excitation ([`Tim3::excitation`]) there — the envelope gain each winding was read
    /// at (equal gains: the angle is undistorted, thesis A §4.3).
    pub resolver_excitation: [Option<(f64, f64)>; 2],
}

/// The inputs of one kind held after one ADC trigger, for [`Soc::current_sample_instant`]
/// and [`Soc::resolver_sample_instant`].
#[derive(Clone, Copy, Debug, Default)]
struct Holds {
    /// The trigger \[bus units\].
    trigger: u64,
    /// Σ (held instant − trigger) \[s\].
    sum_s: f64,
    /// The inputs seen, as bits.
    seen: u8,
    /// How many.
    n: u32,
}

impl Holds {
    /// Input `input` held at `held` \[s\] after the trigger at `trigger` (bus units;
    /// none yet: ignored): a new trigger first closes the last one's mean into `stat`
    /// (min, max, triggers); a second hold of the same input after one trigger (a
    /// padding repeat) is not counted.
    fn add(&mut self, trigger: Option<u64>, input: usize, held: f64, stat: &mut Option<(f64, f64, u64)>) {
        let Some(trigger) = trigger else {
            return;
        };
        if self.trigger != trigger {
            if self.n > 0 {
                *stat = crate::periph::spread(*stat, self.sum_s / f64::from(self.n));
            }
            *self = Holds {
                trigger,
                ..Holds::default()
            };
        }
        let bit = 1u8 << input.min(7);
        if self.seen & bit == 0 {
            self.sum_s += held - trigger as f64 / UNITS_PER_S;
            self.seen |= bit;
            self.n += 1;
        }
    }
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

/// NVIC_IPR0..59 (offsets from 0xE000_0000): byte-accessible (ARMv7-M B3.4.9).
const NVIC_IPR: std::ops::Range<u32> = 0xE400..0xE4F0;

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

/// The six gates' names for messages.
const GATE_NAMES: [&str; 6] = [
    "u high side",
    "v high side",
    "w high side",
    "u low side",
    "v low side",
    "w low side",
];

/// TIM1's output signals in the order of [`crate::periph::tim1::Tim1::outputs`].
const TIM1_OUTPUTS: [&str; 6] = ["CH1", "CH2", "CH3", "CH1N", "CH2N", "CH3N"];

impl Soc {
    /// The chip at reset with FLASH_OPTR = `optr`, on the board `wiring`.
    pub fn new(wiring: Wiring, analog: Box<dyn Analog>, optr: u32, patches: Patches) -> Self {
        let mut soc = Self {
            now: 0,
            instructions: 0,
            cost: 85,
            deadline: 0,
            pc: 0,
            violation: None,
            clocks: Clocks::new(optr),
            optr,
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
            pulses: Vec::new(),
            notes: Vec::new(),
            patches,
            basepri_request: None,
            aden_writes: [0; 2],
            tim1_cursor: [0; 2],
            watchdog_reset: None,
            irq_active: false,
            sr_in_irq: None,
            bridge_armed: false,
            switches: None,
            previous_switches: None,
            switches_enabled: false,
            sleeping: false,
            wfi_at: None,
            currents_held: Holds::default(),
            resolver_held: Holds::default(),
            current_sample_instant: None,
            resolver_sample_instant: None,
            resolver_excitation: [None; 2],
        };
        soc.clocks.hse_crystal_hz = soc.wiring.hw.hse_crystal_hz;
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

    /// The peripheral signal a pin in alternate-function mode `af` carries.
    fn af_signal(&self, port: u8, number: u8, af: u8) -> Option<(&'static str, &'static str)> {
        self.wiring.hw.af_signal(&crate::hardware::pin_name(port, number), af)
    }

    /// Level of a pin now: whatever drives it (output data, TIM1/TIM3 through the
    /// alternate function the chip routes there, the break comparator) or its pull;
    /// `false` for a floating pin.
    pub fn pin_level(&self, port: u8, number: u8) -> bool {
        let p = &self.gpio[usize::from(port)];
        let w = &self.wiring;
        if (port, number) == w.break_pin {
            // The comparator drives the line: low on over-current for an active-low one.
            return self.break_asserted != w.hw.break_active_low;
        }
        let undriven = || p.pull(number).unwrap_or(false);
        match p.mode(number) {
            Mode::Output => p.odr(number),
            Mode::Alternate(af) => match self.af_signal(port, number, af) {
                Some(("TIM1", s)) => match TIM1_OUTPUTS.iter().position(|o| *o == s) {
                    Some(k) => self.tim1.outputs_at(self.now)[k].unwrap_or_else(undriven),
                    None => undriven(),
                },
                Some(("TIM3", "CH1")) => self.tim3.output(self.now),
                _ => undriven(),
            },
            Mode::Input => undriven(),
            Mode::Analog => false,
        }
    }

    /// What gate pin `k` does over the window: driven (GPIO output, TIM1 output through
    /// its alternate function) or not, and why.
    fn gate_wave(&self, k: usize, tim1: &[Option<Wave>; 6], len: f64) -> PinWave {
        let (port, number) = self.wiring.gates[k];
        let p = &self.gpio[usize::from(port)];
        let name = crate::hardware::pin_name(port, number);
        let undriven = |why: String| PinWave::Undriven {
            gpio_pull: p.pull(number),
            why,
        };
        match p.mode(number) {
            Mode::Output => PinWave::Driven(Wave::constant(p.odr(number), len)),
            Mode::Alternate(af) => match self.af_signal(port, number, af) {
                Some(("TIM1", s)) if TIM1_OUTPUTS.contains(&s) => {
                    let k = TIM1_OUTPUTS.iter().position(|o| *o == s).unwrap_or(0);
                    match &tim1[k] {
                        Some(w) => PinWave::Driven(w.clone()),
                        None => undriven(format!(
                            "{name} is TIM1_{s} (AF{af}), whose output TIM1 leaves in Hi-Z (MOE = {}, OSSI = {}, OSSR = {}: RM0440 Table \"Output control bits for complementary tim_ocx and tim_ocxn channels with break feature\")",
                            u8::from(self.tim1.moe()),
                            (self.tim1.bdtr() >> 10) & 1,
                            (self.tim1.bdtr() >> 11) & 1
                        )),
                    }
                }
                Some((per, s)) => undriven(format!("AF{af} routes {per}_{s} to {name}, not a TIM1 output")),
                None => undriven(format!(
                    "AF{af} routes no signal to {name} (DS12288 alternate functions)"
                )),
            },
            Mode::Input => undriven(format!("{name} is an input")),
            Mode::Analog => undriven(format!("{name} is in analog mode (its reset state)")),
        }
    }

    /// The six gate pins and the switches they command over one carrier period from the
    /// last update event (or a short window with the counter stopped), through the
    /// board's gate driver. `Err` names a gate input that floats.
    fn bridge_now(&self) -> Result<([PinWave; 6], [LegSwitches; 3]), Broken> {
        let tim1 = self.tim1.outputs(self.tim1.tick_s());
        let len = tim1[0].as_ref().map_or(1e-6, |w| w.len);
        let pins: [PinWave; 6] = std::array::from_fn(|k| self.gate_wave(k, &tim1, len));
        let inputs = self.wiring.hw.gate_inputs();
        let mut levels = Vec::new();
        for (k, (pin, input)) in pins.iter().zip(inputs.iter()).enumerate() {
            match bridge::input_level(pin, input, len) {
                Some(w) => levels.push(w),
                None => {
                    let why = match pin {
                        PinWave::Undriven { why, .. } => why.clone(),
                        PinWave::Driven(_) => String::new(),
                    };
                    return Err(Broken::new(
                        format!("{} ({})", input.pin, GATE_NAMES[k]),
                        format!(
                            "gate pin left floating into a driver input: {why}, and neither the pin's pull nor the board ({}) holds the input",
                            self.wiring.hw.driver.part
                        ),
                    ));
                }
            }
        }
        let d = &self.wiring.hw.driver;
        let legs = std::array::from_fn(|leg| {
            bridge::leg(d, [&inputs[leg], &inputs[leg + 3]], [&levels[leg], &levels[leg + 3]])
        });
        Ok((pins, legs))
    }

    /// Analyses the bridge after anything that can change it and applies the strict
    /// rules of the power stage: no gate input floating; every gate pin driven by the MCU
    /// once TIM1 runs; no leg's two switches conducting together (shoot-through); no
    /// switch on while the image means the outputs off (MOE = 0). Returns the legs'
    /// duties for the plant (`None`: not switching).
    fn analyse_bridge(&mut self) -> Option<[f64; 3]> {
        let (pins, legs) = match self.bridge_now() {
            Ok(x) => x,
            Err(b) => {
                self.fail(b);
                return None;
            }
        };
        let hw = &self.wiring.hw;
        let inputs = hw.gate_inputs();
        let mut broken = None;
        if self.bridge_armed
            && let Some(k) = pins.iter().position(|p| matches!(p, PinWave::Undriven { .. }))
            && let PinWave::Undriven { why, .. } = &pins[k]
        {
            broken = Some(Broken::new(
                format!("{} ({})", inputs[k].pin, GATE_NAMES[k]),
                format!(
                    "gate pin left floating into a driver input while the bridge runs (TIM1 started): {why}; only the {}'s own input bias holds it — every gate pin must be driven (TIM1 with OSSI/OSSR = 1, or a GPIO output)",
                    hw.driver.part
                ),
            ));
        }
        for (leg, s) in legs.iter().enumerate() {
            let both = bridge::overlap(&hw.driver, s);
            if broken.is_none() && both > 0.0 {
                broken = Some(Broken::new(
                    format!(
                        "{}/{} (leg {})",
                        inputs[leg].pin,
                        inputs[leg + 3].pin,
                        ["u", "v", "w"][leg]
                    ),
                    format!(
                        "shoot-through: both switches of the leg conduct together for {:.0} ns per period — TIM1's dead time ({:.0} ns) and the {}'s own ({:.0} ns) do not cover the switches' {:.0} ns turn-off",
                        both * 1e9,
                        self.tim1.dead_ticks() as f64 * self.tim1.tick_s() * 1e9,
                        hw.driver.part,
                        hw.driver.dead_time_s * 1e9,
                        hw.driver.turn_off_s * 1e9
                    ),
                ));
            }
        }
        if broken.is_none() && !self.tim1.moe() {
            let on: Vec<usize> = (0..6)
                .filter(|&k| {
                    let s = &legs[k % 3];
                    if k < 3 { s.high.any() } else { s.low.any() }
                })
                .collect();
            if !on.is_empty() {
                let lows = on.iter().filter(|&&k| k >= 3).count();
                let what = if lows >= 2 {
                    "phases shorted through the low sides while the image means the outputs off"
                } else {
                    "a switch conducts while the image means the outputs off"
                };
                let detail: Vec<String> = on
                    .iter()
                    .map(|&k| {
                        let level = match &pins[k] {
                            PinWave::Driven(w) => {
                                if w.at(0.0) {
                                    "high"
                                } else {
                                    "low"
                                }
                            }
                            PinWave::Undriven { .. } => "undriven",
                        };
                        format!(
                            "{} on ({} {level}, the {} input is active {})",
                            GATE_NAMES[k],
                            inputs[k].pin,
                            hw.driver.part,
                            if inputs[k].logic == crate::hardware::Logic::ActiveLow {
                                "low"
                            } else {
                                "high"
                            }
                        )
                    })
                    .collect();
                broken = Some(Broken::new(
                    "TIM1 outputs (MOE = 0)",
                    format!(
                        "{what}: {} — idle levels OISx/OISxN and the polarities CCxP/CCxNP must make every input's off level (RM0440 TIMx_CR2, TIMx_CCER)",
                        detail.join("; ")
                    ),
                ));
            }
        }
        if let Some(b) = broken {
            self.fail(b);
        }
        let duties = if self.tim1.moe() {
            let d: Vec<Option<f64>> = legs.iter().map(bridge::duty).collect();
            if d.iter().all(Option::is_some) {
                Some([d[0].unwrap_or(0.5), d[1].unwrap_or(0.5), d[2].unwrap_or(0.5)])
            } else {
                None
            }
        } else {
            None
        };
        // The previous period counts only when the bridge switched in it too (MOE = 1 in
        // both analyses): the first period after enabling has no low-side history.
        let moe = self.tim1.moe();
        let previous = self.switches.replace(legs);
        self.previous_switches = previous.filter(|_| moe && self.switches_enabled);
        self.switches_enabled = moe;
        duties
    }

    /// The six gate signals as driven now (high u, v, w; low u, v, w).
    pub fn gates(&self) -> [bool; 6] {
        self.wiring.gates.map(|(p, n)| self.pin_level(p, n))
    }

    /// Whether any switch of the bridge is commanded on (now, or anywhere in the carrier
    /// period under way), through the board's gate driver.
    pub fn gates_can_switch(&self) -> bool {
        match self.bridge_now() {
            Ok((_, legs)) => legs.iter().any(|s| s.high.any() || s.low.any()),
            // A floating input may turn its switch on.
            Err(_) => true,
        }
    }

    /// TIM1's BKIN as the timer sees it: the pin if routed to TIM1_BKIN, else low (an
    /// unrouted input reads 0; with active-low polarity that is a break — review defect 3).
    fn bkin_level(&self) -> bool {
        let (port, number) = self.wiring.break_pin;
        match self.gpio[usize::from(port)].mode(number) {
            Mode::Alternate(af) if self.af_signal(port, number, af) == Some(("TIM1", "BKIN")) => {
                self.pin_level(port, number)
            }
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
        let duties = self.analyse_bridge();
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

    /// FLASH_OPTR as the image reads it.
    fn optr_read(&self) -> u32 {
        if self.patches.optr_reads_programmed {
            self.optr & !OPTR_NSWBOOT0
        } else {
            self.optr
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
            Block::Fdcan => self.fdcan.read(off, ts)?,
            Block::FdcanRam => self.fdcan.ram[(off / 4) as usize],
            Block::Pwr => self.clocks.pwr_read(off)?,
            Block::Syscfg => self.syscfg.read(off)?,
            Block::Tim1 => {
                let v = self.tim1.read(off, t)?;
                if off == 0x10 { self.sr_read(v) } else { v }
            }
            Block::Cordic => self.cordic.read(off)?,
            Block::Rcc => self.clocks.rcc_read(off)?,
            Block::Fmac => self.fmac.read(off)?,
            Block::Flash if off == 0x20 => self.optr_read(),
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
            Block::Scs if NVIC_IPR.contains(&off) && size < 4 => self.scs.read_ipr(off, size),
            Block::Scs => self.scs.read(off)?,
        };
        let _ = gate;
        self.reschedule();
        Ok(v)
    }

    /// A TIM1_SR read inside the control interrupt: arms a pulse waiting for it, and with
    /// `stale_bif` answers every later read of the same interrupt with the first value.
    fn sr_read(&mut self, v: u32) -> u32 {
        if !self.irq_active {
            self.sr_in_irq = None;
            return v;
        }
        // Only the interrupt's first read arms the pulse: a run that stops inside an
        // interrupt must not start it right after that interrupt's BIF re-read.
        let first_read = self.sr_in_irq.is_none();
        for p in &mut self.pulses {
            if let Pulse::AfterSrReadInIrq { after, len } = *p
                && first_read
                && self.now >= after
            {
                // One instruction after the read.
                let start = self.now + self.cost;
                *p = Pulse::At(start, start + len);
            }
        }
        match self.sr_in_irq {
            Some(first) if self.patches.stale_bif => first,
            Some(_) => v,
            None => {
                self.sr_in_irq = Some(v);
                v
            }
        }
    }

    /// The core left the control interrupt.
    pub fn irq_exit(&mut self) {
        self.sr_in_irq = None;
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
            Block::Tim3 => {
                let value = if off == 0x34 && self.patches.excitation_peak_at_trigger {
                    self.tim3.period_ticks() / 2
                } else if off == 0x20 && self.patches.excitation_off {
                    value & !1
                } else {
                    value
                };
                self.tim3.write(off, value, t)?
            }
            Block::Iwdg => self.iwdg.write(off, value, ts)?,
            Block::Fdcan => {
                let kernel = self.clocks.fdcan_kernel_hz();
                self.fdcan.write(off, value, ts, kernel)?
            }
            Block::FdcanRam => self.fdcan.ram[(off / 4) as usize] = value,
            Block::Pwr => self.clocks.pwr_write(off, value)?,
            Block::Syscfg => {
                let mut v = value;
                if off == 0x1C && self.patches.drop_cll {
                    v &= !1;
                }
                self.syscfg.write(off, v)?;
            }
            Block::Tim1 => self.write_tim1(off, value, t, ts)?,
            Block::Cordic => self.cordic.write(off, value)?,
            Block::Rcc => {
                self.clocks.rcc_write(off, value, ts)?;
                self.update_clock();
            }
            Block::Fmac => self.fmac.write(off, value)?,
            Block::Flash => self.clocks.flash_write(off, value)?,
            Block::Gpio(k) => {
                let v = self.patch_gpio(k, off, value);
                self.gpio[k].write(&block_name(block), off, v)?;
                self.update_break();
                self.bridge_changed(t);
            }
            Block::Adc(k) => {
                let mut v = value;
                if off == 0x08 && v & 1 != 0 && !self.adc[k].enabled() {
                    self.aden_writes[k] += 1;
                    if self.patches.single_aden_write && self.aden_writes[k] > 1 {
                        v &= !1;
                    }
                }
                if off == 0x08 && v & (1 << 3) != 0 && self.patches.jadstart_rewrites_aden {
                    v |= 1;
                }
                if (off == 0x14 || off == 0x18) && self.patches.slow_channels_2_5_cycles {
                    // Every slow channel's field (all but IN1–IN5) to code 0, 2.5 cycles.
                    let first = if off == 0x14 { 0 } else { 10 };
                    for f in 0..10u32 {
                        let ch = first + f;
                        if !codegen::board::chip::is_fast_channel(ch as u8) {
                            v &= !(0b111 << (3 * f));
                        }
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
            Block::Scs if NVIC_IPR.contains(&off) && size < 4 => self.scs.write_ipr(off, size, value),
            Block::Scs => {
                self.scs.write(off, value)?;
                // NVIC_ISER0 enabling ADC1_2: the `basepri_masks_control` patch raises its
                // priority value by a byte write and masks it with BASEPRI.
                if off == 0xE100 && value & (1 << IRQ_ADC1_2) != 0 && self.patches.basepri_masks_control {
                    self.scs.write_ipr(0xE400 + IRQ_ADC1_2, 1, 0x80);
                    self.basepri_request = Some(0x80);
                }
            }
        }
        self.reschedule();
        Ok(())
    }

    /// A TIM1 register write (with the patches that change it) and what follows from it.
    fn write_tim1(&mut self, off: u32, value: u32, t: u64, ts: f64) -> Result<(), Broken> {
        let moe = self.tim1.moe();
        let mut value = value;
        // CR1 written with CEN already set (the image's UDIS around its compare writes)
        // neither starts the counter again nor changes the outputs.
        let cen_changes = off == 0x00 && (value ^ self.tim1.reg(0)) & 1 != 0;
        if off == 0x00 && value & 1 != 0 && cen_changes {
            self.tim1.tick = (UNITS_PER_S / self.clocks.tim_apb2_hz()).round() as u64;
            self.tim1_cursor = [t; 2];
            self.bridge_armed = true;
        }
        if let (0x34..=0x3C, Some(limit)) = (off, self.patches.compare_beyond)
            && value >= u32::from(limit)
        {
            value = u32::from(limit) + 1;
        }
        if off == 0x44 {
            if self.patches.dead_time_zero {
                value &= !0xFF;
            }
            if self.patches.drop_ossi_ossr {
                value &= !(3 << 10);
            }
            if self.patches.bdtr_lock_second_write {
                self.patches.bdtr_lock_second_write = false;
                self.tim1.write(off, value & !(3 << 8), t)?;
            }
        }
        self.tim1.write(off, value, t)?;
        self.update_break();
        if moe != self.tim1.moe() {
            self.notes.push(Note::MainOutput(ts, self.tim1.moe()));
            if self.tim1.moe() {
                self.check_boot_source();
            }
        }
        // Writes that change the outputs now: control, polarity, idle levels, BDTR, modes,
        // a forced update; compare values wait for the update event.
        if cen_changes || matches!(off, 0x04 | 0x14 | 0x18 | 0x1C | 0x20 | 0x44) {
            self.bridge_changed(t);
        }
        Ok(())
    }

    /// The `low_side_wrong_af` patch: AF0 in the u low-side pin's AFR field.
    fn patch_gpio(&self, port: usize, off: u32, value: u32) -> u32 {
        if !self.patches.low_side_wrong_af {
            return value;
        }
        let (p, n) = self.wiring.gates[3];
        let reg = if n < 8 { 0x20 } else { 0x24 };
        if usize::from(p) == port && off == reg {
            value & !(0xF << (4 * (u32::from(n) % 8)))
        } else {
            value
        }
    }

    /// Outputs enabled: with the chip's option bytes letting PB8 select the boot mode on
    /// a board whose PB8 may be high at a reset, the next reset can start the system
    /// bootloader — the image must have refused to run.
    fn check_boot_source(&mut self) {
        if self.optr & OPTR_NSWBOOT0 != 0 && self.wiring.hw.boot0_may_be_high {
            self.fail(Broken::new(
                "TIM1_BDTR.MOE",
                "outputs enabled on a chip whose option bytes take BOOT0 from PB8 (FLASH_OPTR.nSWBOOT0 = 1, the factory value) on a board whose PB8 carries CAN RXD, which idles high: the next reset can start the system bootloader instead of the image (RM0440 §3.4.1, DS12288 §3.7) — the image must check FLASH_OPTR and stay off",
            ));
        }
    }

    /// Decodes an address and checks the access: a known block, whole words (half words
    /// for the IWDG, bytes and half words for NVIC_IPR), its clock enabled (RM0440 §7.4:
    /// with the enable bit clear the peripheral's registers are not clocked and cannot be
    /// accessed).
    fn route(&mut self, addr: u32, size: usize) -> Result<(Block, u32, Gate), Broken> {
        let Some((block, off, gate)) = decode(addr) else {
            return Err(Broken::new(
                format!("{addr:#010x}"),
                "no peripheral model at this address (RM0440 §2.2.2 memory map)",
            ));
        };
        // IWDG registers also take half-word accesses (RM0440 §42.4); NVIC_IPR bytes and
        // half words (ARMv7-M B3.4.9, "byte-accessible").
        let narrow_ok = (block == Block::Iwdg && size == 2) || (block == Block::Scs && NVIC_IPR.contains(&off));
        let aligned = off % (size as u32).max(1) == 0;
        if (size != 4 && !narrow_ok) || (size == 4 && off % 4 != 0) || !aligned {
            return Err(Broken::new(
                format!("{}+{off:#05x}", block_name(block)),
                format!("{size}-byte access: only aligned word accesses are modelled here"),
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

    /// The next time something happens by itself (timer events, conversions, break
    /// pulses, the watchdog), in bus units.
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
        for p in &self.pulses {
            match *p {
                Pulse::At(s, _) | Pulse::Active(s) => next = next.min(s),
                Pulse::AfterSrReadInIrq { .. } => {}
            }
        }
        if let Some(t) = self.iwdg.expires_at {
            next = next.min((t * UNITS_PER_S).ceil() as u64);
        }
        next
    }

    /// Break pulses whose edges have come: the comparator's output follows; a pulse
    /// shorter than the break filter (BKF = 0011: 8 timer clocks) does not reach TIM1, a
    /// longer one latches BIF and clears MOE however short it is (RM0440 §28.3.16).
    fn service_pulses(&mut self) {
        let now = self.now;
        let filter = BREAK_FILTER_TICKS * self.tim1.tick;
        let mut out = Vec::new();
        for p in std::mem::take(&mut self.pulses) {
            match p {
                Pulse::At(s, e) if now >= s => {
                    let passes = e.saturating_sub(s) >= filter;
                    if passes {
                        self.break_asserted = true;
                        self.update_break();
                        if now >= e {
                            self.break_asserted = false;
                            self.update_break();
                        } else {
                            out.push(Pulse::Active(e));
                        }
                    }
                }
                Pulse::Active(e) if now >= e => {
                    self.break_asserted = false;
                    self.update_break();
                }
                p => out.push(p),
            }
        }
        self.pulses.extend(out);
    }

    /// Runs every event due by now, in time order.
    pub fn service(&mut self) {
        self.service_pulses();
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
                self.tim1.last_trigger_at = Some(t);
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
                if let Some(b) = self.tim1.repetition_broken() {
                    self.fail(b);
                }
                self.tim1.update_at(t);
                self.bridge_changed(t);
                if self.tim1.moe() && !self.notes.iter().any(|n| matches!(n, Note::FirstEnabledPeriod(_))) {
                    self.notes.push(Note::FirstEnabledPeriod(t as f64 / UNITS_PER_S));
                }
            }
        }
    }

    /// Completes the conversions due at `t` units: each rank reads the board's signal on
    /// the pin its channel is (the chip's table) at the end of its sampling phase — the
    /// sample-and-hold opens then and the 12.5 SAR cycles convert the held voltage
    /// (RM0440 §21.4.12: t_CONV = t_SMPL + t_SAR, the input is sampled during t_SMPL) —
    /// after checking that its sampling time settles the input's source (DS12288
    /// Table 67).
    fn convert(&mut self, t: u64) {
        // Half a unit later: the rank's end time was rounded up to `t` units.
        let ts = (t as f64 + 0.5) / UNITS_PER_S;
        let vref = self.wiring.vref;
        let clk = self.adc_clock_s().unwrap_or(0.0);
        for k in 0..2 {
            let hw = &self.wiring.hw;
            let pins = &self.wiring.adc_pins[k];
            let analog = &mut self.analog;
            let tim3 = &self.tim3;
            let mut problem = None;
            let smp: [f64; ADC_CHANNELS] = std::array::from_fn(|ch| self.adc[k].smp_cycles(ch as u8));
            let name = self.adc[k].name;
            let mut currents = Vec::new();
            let mut resolver = Vec::new();
            let mut envelope = [None; 2];
            self.adc[k].complete(ts, |ch, at| {
                let pin = pins.get(usize::from(ch)).copied().flatten();
                let Some(input) = pin.and_then(|p| hw.analog_at(p)) else {
                    problem.get_or_insert(Broken::new(
                        format!("{name}_JSQR"),
                        format!(
                            "channel {ch} ({}) converted but the board wires no signal to it",
                            pin.unwrap_or("no pin")
                        ),
                    ));
                    return 0;
                };
                let fast = codegen::board::chip::is_fast_channel(ch);
                let cycles = smp.get(usize::from(ch)).copied().unwrap_or(0.0);
                let sampled = cycles * clk;
                let need = codegen::board::sampling::table_time(input.source_ohm, fast);
                let short = match need {
                    Ok(need) => (sampled < need * (1.0 - 1e-3)).then(|| format!("needs ≥ {:.2} ns", need * 1e9)),
                    Err(_) => Some("is beyond what any sampling time settles".to_string()),
                };
                if let Some(need) = short {
                    problem.get_or_insert(Broken::new(
                        format!("{name}_SMPR"),
                        format!(
                            "ADC sampling does not settle: channel {ch} ({}, a {} channel) sampled for {cycles} cycles = {:.1} ns, but its source ({}, {:.0} Ω) {need} to settle to 12 bits (DS12288 Table 67, maximum R_AIN per sampling time{})",
                            input.pin,
                            if fast { "fast" } else { "slow" },
                            sampled * 1e9,
                            input.source,
                            input.source_ohm,
                            if fast { "" } else { "; 2.5 cycles N/A on slow channels" }
                        ),
                    ));
                }
                // The rank ends at `at`; its input was held SAR_CYCLES earlier, at the end
                // of its sampling phase (§21.4.12).
                let held = at - SAR_CYCLES * clk;
                let excitation = tim3.excitation((held * UNITS_PER_S) as u64);
                match input.signal {
                    crate::hardware::Analog::Current(phase) => currents.push((ch, phase, (held - sampled, held))),
                    crate::hardware::Analog::Sin => {
                        resolver.push((0, held));
                        envelope[0] = Some((held, excitation));
                    }
                    crate::hardware::Analog::Cos => {
                        resolver.push((1, held));
                        envelope[1] = Some((held, excitation));
                    }
                    crate::hardware::Analog::DcLink => {}
                }
                let v = analog.volts(input.signal, held, excitation);
                // Ideal 12-bit conversion: code = V/V_REF·4096, clamped (RM0440 §21.4.1).
                (v / vref * 4096.0).floor().clamp(0.0, 4095.0) as u16
            });
            if let Some(b) = problem {
                self.fail(b);
            }
            for (k, e) in envelope.into_iter().enumerate() {
                if e.is_some() {
                    self.resolver_excitation[k] = e;
                }
            }
            let trigger = self.tim1.last_trigger_at;
            for (input, held) in resolver {
                self.resolver_held
                    .add(trigger, input, held, &mut self.resolver_sample_instant);
            }
            for (ch, phase, sampling) in currents {
                self.currents_held
                    .add(trigger, phase, sampling.1, &mut self.current_sample_instant);
                if let Some(b) = self.sampling_window(name, ch, phase, sampling) {
                    self.fail(b);
                }
            }
        }
    }

    /// The strict rule "ADC sampling inside a switching edge" for a board with low-side
    /// shunts ([`crate::hardware::Hardware::low_side_settling_s`]): while the bridge
    /// switches (MOE = 1), a conversion of phase `phase`'s current must sample — over
    /// `sampling` = (start, end) \[s\] — inside one low-side pulse of that leg, at least
    /// the stage's settling time after the low side switched on and ending before it
    /// switches off: a shunt whose low side is off carries no phase current, and one
    /// that just switched on still rings. The leg's low side is the gate driver's
    /// output ([`crate::bridge::leg`]: TIM1's complementary output with both dead times).
    fn sampling_window(&self, adc: &str, ch: u8, phase: usize, sampling: (f64, f64)) -> Option<Broken> {
        let settle = self.wiring.hw.low_side_settling_s?;
        if !self.tim1.moe() {
            return None;
        }
        // Not checked in the first period after the outputs were enabled (no previous
        // switching period to hold the low side's turn-on).
        let previous = self.previous_switches.as_ref()?;
        let now = &self.switches.as_ref()?[phase].low;
        let len = now.len;
        let (a, b) = (
            self.tim1.window_phase_s(sampling.0)?,
            self.tim1.window_phase_s(sampling.1)?,
        );
        // The low side over the period before the last update (shifted to [−len, 0))
        // and this one, intervals meeting at the update joined: a sampling that starts
        // before the update (b < a) starts in the previous period.
        let mut iv: Vec<(f64, f64)> = previous[phase]
            .low
            .high
            .iter()
            .map(|&(x, y)| (x - len, y - len))
            .collect();
        let eps = 1e-12;
        for &(x, y) in &now.high {
            match iv.last_mut() {
                Some(last) if (last.1 - x).abs() <= eps => last.1 = y,
                _ => iv.push((x, y)),
            }
        }
        let a = if b < a { a - len } else { a };
        let leg = ["u", "v", "w"][phase];
        let cut = |what: String| {
            Some(Broken::new(
                format!("{adc} channel {ch}"),
                format!(
                    "ADC sampling inside a switching edge: the phase {leg} current (low-side shunt) sampled from {:.1} to {:.1} ns from the last update event, but {what} — the duty must leave the low side on around the sampling for the settling time and the sampling (the design's board::MAX_DUTY, codegen::design::duty_limit)",
                    a * 1e9,
                    b * 1e9
                ),
            ))
        };
        let Some(&(on, _)) = iv.iter().find(|&&(on, off)| on <= a + eps && b <= off + eps) else {
            let near = iv
                .iter()
                .map(|&(on, off)| format!("{:.1}…{:.1} ns", on * 1e9, off * 1e9))
                .collect::<Vec<_>>();
            return cut(format!(
                "the {leg} low side is not on throughout (on {})",
                if near.is_empty() {
                    "never".to_string()
                } else {
                    near.join(", ")
                }
            ));
        };
        // An interval from the start of the analysed span continues from before it: no
        // edge seen.
        if on > -len + eps && a - on < settle - eps {
            return cut(format!(
                "the {leg} low side switched on at {:.1} ns, only {:.1} ns before (settling {:.0} ns)",
                on * 1e9,
                (a - on) * 1e9,
                settle * 1e9
            ));
        }
        None
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::hardware;

    /// Every analog input at 0 V (the unit tests' source).
    pub(crate) struct Quiet;
    impl Analog for Quiet {
        fn volts(&mut self, _: Signal, _: f64, _: f64) -> f64 {
            0.0
        }
    }

    fn soc(board: &str) -> Soc {
        let hw = hardware::for_board(board).unwrap();
        let mut s = Soc::new(Wiring::new(hw), Box::new(Quiet), OPTR_NSWBOOT0, Patches::default());
        // Clocks for GPIOA–C and TIM1 (RCC_AHB2ENR bits 0–2, RCC_APB2ENR bit 11).
        s.write(0x4002_1000 + AHB2ENR, 4, 0b111).unwrap();
        s.write(0x4002_1000 + APB2ENR, 4, 1 << 11).unwrap();
        s
    }

    /// NVIC_IPR is byte-accessible (ARMv7-M B3.4.9): a byte write sets one interrupt's
    /// priority, of which the G474 keeps the upper four bits; words and half words read
    /// the same bytes back.
    #[test]
    fn nvic_priorities_take_byte_writes() {
        let mut s = soc("motorgen-reference");
        s.write(0xE000_E400 + IRQ_ADC1_2, 1, 0x8F).unwrap();
        assert_eq!(s.scs.priority(IRQ_ADC1_2), 0x80);
        assert_eq!(s.read(0xE000_E410, 4).unwrap(), 0x0080_0000);
        assert_eq!(s.read(0xE000_E412, 2).unwrap(), 0x0080);
        // Other registers stay word-only.
        assert!(s.write(0x4001_2C00, 1, 0).is_err());
    }

    /// Gate pins at reset (analog mode) are held by the drivers' pulls: the L6398's HIN
    /// low, LIN high — every switch off; routed to TIM1 with MOE = 0 and OSSI = 1 they
    /// drive OISx/OISxN: with OIS1N..3N = 0 (the image before issue 25) all three low
    /// sides turn on, which is the rule "phases shorted through the low sides".
    #[test]
    fn l6398_low_sides_on_with_idle_low() {
        let mut s = soc("nucleo-g474re-ihm08m1");
        assert!(!s.gates_can_switch());
        // TIM1: CCER = 0x555 (all six outputs enabled, no polarity), BDTR OSSI = 1.
        s.write(0x4001_2C20, 4, 0x555).unwrap();
        s.write(0x4001_2C44, 4, 1 << 10).unwrap();
        // Route PA7, PB0, PB1 (CH1N..CH3N, AF6) and PA8–PA10 (CH1..CH3, AF6).
        s.write(0x4800_0020, 4, 6 << 28).unwrap(); // GPIOA_AFRL: PA7 AF6
        s.write(0x4800_0024, 4, 0x666).unwrap(); // GPIOA_AFRH: PA8–PA10 AF6
        s.write(0x4800_0420, 4, 0x66).unwrap(); // GPIOB_AFRL: PB0, PB1 AF6
        assert!(s.violation.is_none(), "{:?}", s.violation);
        s.write(0x4800_0400, 4, 0xFFFF_FEBA).unwrap(); // PB0, PB1 alternate: v, w low sides
        s.write(0x4800_0000, 4, 0xABEA_BFFF).unwrap(); // PA7..PA10 alternate
        let v = s.violation.clone().expect("the low sides conduct");
        assert!(v.rule.contains("phases shorted through the low sides"), "{v:?}");
        // With OIS1N..OIS3N set (bits 9, 11, 13) no switch is on.
        let mut s = soc("nucleo-g474re-ihm08m1");
        s.write(0x4001_2C04, 4, 0x2A00).unwrap();
        s.write(0x4001_2C20, 4, 0xDDD).unwrap();
        s.write(0x4001_2C44, 4, 1 << 10).unwrap();
        s.write(0x4800_0020, 4, 6 << 28).unwrap();
        s.write(0x4800_0024, 4, 0x666).unwrap();
        s.write(0x4800_0420, 4, 0x66).unwrap();
        s.write(0x4800_0000, 4, 0xABEA_BFFF).unwrap();
        s.write(0x4800_0400, 4, 0xFFFF_FEBA).unwrap();
        assert!(s.violation.is_none(), "{:?}", s.violation);
        assert!(!s.gates_can_switch());
    }
}
