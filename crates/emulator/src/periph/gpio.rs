//! GPIO ports A–C (RM0440 §9): mode, output data, alternate functions; the input data
//! register reads the pin, whatever drives it (RM0440 §9.3.10: in alternate-function
//! mode the input buffer stays on).

use super::clock::unknown;
use crate::violation::Broken;

/// Pin modes (GPIOx_MODER, RM0440 §9.4.1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// 00
    Input,
    /// 01
    Output,
    /// 10
    Alternate(u8),
    /// 11 (reset state of most pins)
    Analog,
}

/// One port.
#[derive(Clone, Debug)]
pub struct Port {
    /// MODER, OTYPER, OSPEEDR, PUPDR, IDR (unused), ODR, BSRR (unused), LCKR, AFRL, AFRH.
    regs: [u32; 11],
}

const MODER: usize = 0;
const ODR: usize = 5;
const AFRL: usize = 8;

impl Port {
    /// Reset state of port `index` (0 = A): RM0440 §9.4.1 MODER reset 0xABFF_FFFF for
    /// port A (PA13/14/15 debug), 0xFFFF_FEBF for port B (PB3/PB4), 0xFFFF_FFFF
    /// otherwise; §9.4.3 OSPEEDR 0x0C00_0000 (A) / 0; §9.4.4 PUPDR 0x6400_0000 (A),
    /// 0x0000_0100 (B).
    pub fn new(index: usize) -> Self {
        let mut regs = [0; 11];
        regs[MODER] = match index {
            0 => 0xABFF_FFFF,
            1 => 0xFFFF_FEBF,
            _ => 0xFFFF_FFFF,
        };
        regs[2] = if index == 0 { 0x0C00_0000 } else { 0 };
        regs[3] = match index {
            0 => 0x6400_0000,
            1 => 0x0000_0100,
            _ => 0,
        };
        Self { regs }
    }

    /// Mode of pin `n`.
    pub fn mode(&self, n: u8) -> Mode {
        let n = u32::from(n);
        match (self.regs[MODER] >> (2 * n)) & 3 {
            0 => Mode::Input,
            1 => Mode::Output,
            2 => {
                let afr = self.regs[AFRL + (n / 8) as usize];
                Mode::Alternate(((afr >> (4 * (n % 8))) & 0xF) as u8)
            }
            _ => Mode::Analog,
        }
    }

    /// The level pin `n`'s pull-up or pull-down holds it at while undriven (GPIOx_PUPDR,
    /// RM0440 §9.4.4: 01 pull-up, 10 pull-down; active in input, output and alternate-
    /// function modes, not in analog mode), `None` without one.
    pub fn pull(&self, n: u8) -> Option<bool> {
        if self.mode(n) == Mode::Analog {
            return None;
        }
        match (self.regs[3] >> (2 * u32::from(n))) & 3 {
            0b01 => Some(true),
            0b10 => Some(false),
            _ => None,
        }
    }

    /// Output data bit of pin `n`.
    pub fn odr(&self, n: u8) -> bool {
        self.regs[ODR] & (1 << n) != 0
    }

    /// Register read; `idr` is the pins' levels (computed by the bus).
    pub fn read(&self, name: &str, off: u32, idr: u32) -> Result<u32, Broken> {
        match off {
            0x10 => Ok(idr),
            0x18 | 0x28 => Ok(0),
            0x00..=0x24 if off.is_multiple_of(4) => Ok(self.regs[(off / 4) as usize]),
            _ => Err(unknown(name, off)),
        }
    }

    /// Register write.
    pub fn write(&mut self, name: &str, off: u32, value: u32) -> Result<(), Broken> {
        match off {
            // BSRR: set bits 0–15, reset bits 16–31 (reset wins only if both, RM0440 §9.4.7
            // says set has priority).
            0x18 => {
                self.regs[ODR] &= !(value >> 16);
                self.regs[ODR] |= value & 0xFFFF;
            }
            // BRR (RM0440 §9.4.11).
            0x28 => self.regs[ODR] &= !(value & 0xFFFF),
            0x10 => {
                return Err(Broken::new(format!("{name}_IDR"), "IDR is read-only (RM0440 §9.4.5)"));
            }
            0x00..=0x24 if off.is_multiple_of(4) => self.regs[(off / 4) as usize] = value,
            _ => return Err(unknown(name, off)),
        }
        Ok(())
    }
}
