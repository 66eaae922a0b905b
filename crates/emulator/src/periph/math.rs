//! The maths accelerators: CORDIC (RM0440 §17) and FMAC (RM0440 §18), computed from
//! their documented number formats, independently of the firmware's software models
//! (the image's start-up self-tests compare the two).

use super::clock::unknown;
use crate::violation::Broken;

/// Q1.31 scale.
const Q31: f64 = 2147483648.0;

fn q31(x: f64) -> u32 {
    ((x * Q31).round().clamp(-Q31, Q31 - 1.0) as i64) as i32 as u32
}

fn from_q31(x: u32) -> f64 {
    f64::from(x as i32) / Q31
}

/// CORDIC in 32-bit mode (ARGSIZE = RESSIZE = 0, Q1.31).
#[derive(Debug)]
pub struct Cordic {
    csr: u32,
    args: Vec<u32>,
    /// ARG2 as last written: a one-argument calculation (NARGS = 0) uses it (RM0440
    /// §17.4.2, CORDIC_WDATA: with NARGS = 0 only ARG1 is written; embassy-stm32's driver
    /// sets ARG2 = +1 by a two-argument calculation before switching to one argument).
    /// +1 (0x7FFF_FFFF) after reset.
    arg2: u32,
    results: Vec<u32>,
    /// Calculations done.
    pub calculations: u64,
}

impl Default for Cordic {
    fn default() -> Self {
        Self {
            csr: 0,
            args: Vec::new(),
            arg2: 0x7FFF_FFFF,
            results: Vec::new(),
            calculations: 0,
        }
    }
}

impl Cordic {
    /// Register read.
    pub fn read(&mut self, off: u32) -> Result<u32, Broken> {
        match off {
            // RRDY (bit 31) while a result waits (RM0440 §17.4.1).
            0x00 => Ok(self.csr | (u32::from(!self.results.is_empty()) << 31)),
            0x04 => Ok(0),
            0x08 => {
                if self.results.is_empty() {
                    return Err(Broken::new(
                        "CORDIC_RDATA",
                        "read with no calculation pending: the bus would stall forever (RM0440 §17.3.6)",
                    ));
                }
                Ok(self.results.remove(0))
            }
            _ => Err(unknown("CORDIC", off)),
        }
    }

    /// Register write.
    pub fn write(&mut self, off: u32, value: u32) -> Result<(), Broken> {
        match off {
            0x00 => {
                if value & (3 << 21) != 0 {
                    return Err(Broken::new(
                        "CORDIC_CSR",
                        "16-bit ARGSIZE/RESSIZE not modelled (RM0440 §17.4.1)",
                    ));
                }
                self.csr = value & !(1 << 31);
                self.args.clear();
                self.results.clear();
                Ok(())
            }
            0x04 => {
                self.args.push(value);
                let nargs = if self.csr & (1 << 20) != 0 { 2 } else { 1 };
                if self.args.len() == nargs {
                    self.calculate()?;
                }
                Ok(())
            }
            0x08 => Err(Broken::new("CORDIC_RDATA", "read-only (RM0440 §17.4.3)")),
            _ => Err(unknown("CORDIC", off)),
        }
    }

    /// One calculation (RM0440 §17.3.2, Table 117–122): cosine: ARG1 = θ/π, ARG2 = m,
    /// RES1 = m·cos θ, RES2 = m·sin θ; phase: ARG1 = x, ARG2 = y, RES1 = atan2(y, x)/π,
    /// RES2 = √(x² + y²). With one argument, ARG2 is the last one written (+1 after reset).
    fn calculate(&mut self) -> Result<(), Broken> {
        let a1 = from_q31(self.args[0]);
        if let Some(&a) = self.args.get(1) {
            self.arg2 = a;
        }
        let a2 = from_q31(self.arg2);
        self.args.clear();
        let (r1, r2) = match self.csr & 0xF {
            0 => {
                let th = a1 * std::f64::consts::PI;
                (a2 * th.cos(), a2 * th.sin())
            }
            1 => {
                let th = a1 * std::f64::consts::PI;
                (a2 * th.sin(), a2 * th.cos())
            }
            2 => (a2.atan2(a1) / std::f64::consts::PI, (a1 * a1 + a2 * a2).sqrt()),
            3 => ((a1 * a1 + a2 * a2).sqrt(), a2.atan2(a1) / std::f64::consts::PI),
            f => {
                return Err(Broken::new(
                    "CORDIC_CSR",
                    format!("FUNC {f} not modelled (cosine, sine, phase, modulus are; RM0440 §17.4.1)"),
                ));
            }
        };
        self.results.push(q31(r1));
        if self.csr & (1 << 19) != 0 {
            self.results.push(q31(r2));
        }
        self.calculations += 1;
        Ok(())
    }
}

/// FMAC (RM0440 §18): the load functions and the FIR with its q4.22 accumulator.
#[derive(Debug, Default)]
pub struct Fmac {
    regs: [u32; 8],
    coefficients: Vec<i16>,
    /// Input history, oldest first.
    x1: Vec<i16>,
    /// Loads still expected by a running load function.
    load_left: usize,
    y: Vec<i16>,
    fir_taps: usize,
}

const PARAM: usize = 3;
const CR: usize = 4;

impl Fmac {
    /// Register read.
    pub fn read(&mut self, off: u32) -> Result<u32, Broken> {
        match off {
            // SR: YEMPTY (bit 0), X1FULL (bit 1) never: inputs are consumed at once.
            0x14 => Ok(u32::from(self.y.is_empty())),
            0x1C => {
                if self.y.is_empty() {
                    return Err(Broken::new(
                        "FMAC_RDATA",
                        "read with Y empty (YEMPTY = 1, RM0440 §18.3.7)",
                    ));
                }
                Ok(u32::from(self.y.remove(0) as u16))
            }
            0x00..=0x18 if off.is_multiple_of(4) => Ok(self.regs[(off / 4) as usize]),
            _ => Err(unknown("FMAC", off)),
        }
    }

    /// Register write.
    pub fn write(&mut self, off: u32, value: u32) -> Result<(), Broken> {
        match off {
            0x0C => self.param(value),
            0x10 => {
                if value & (1 << 16) != 0 {
                    // RESET: buffers and state cleared, RESET reads back 0 (§18.4.5).
                    *self = Self::default();
                    self.regs[CR] = value & !(1 << 16);
                } else {
                    self.regs[CR] = value;
                }
                Ok(())
            }
            0x18 => {
                self.wdata(value as u16 as i16);
                Ok(())
            }
            0x1C => Err(Broken::new("FMAC_RDATA", "read-only (RM0440 §18.4.8)")),
            0x00..=0x08 if off.is_multiple_of(4) => {
                self.regs[(off / 4) as usize] = value;
                Ok(())
            }
            _ => Err(unknown("FMAC", off)),
        }
    }

    fn param(&mut self, value: u32) -> Result<(), Broken> {
        self.regs[PARAM] = value;
        if value & (1 << 31) == 0 {
            self.fir_taps = 0;
            return Ok(());
        }
        let func = (value >> 24) & 0x7F;
        let p = (value & 0xFF) as usize;
        match func {
            1 => {
                self.x1.clear();
                self.load_left = p;
            }
            2 => {
                self.coefficients.clear();
                self.load_left = p;
            }
            8 => {
                if self.coefficients.len() != p {
                    return Err(Broken::new(
                        "FMAC_PARAM",
                        format!(
                            "FIR with P = {p} but {} coefficients loaded in X2 (RM0440 §18.3.8)",
                            self.coefficients.len()
                        ),
                    ));
                }
                self.fir_taps = p;
                self.load_left = 0;
            }
            f => {
                return Err(Broken::new(
                    "FMAC_PARAM",
                    format!("FUNC {f} not modelled (RM0440 §18.4.4)"),
                ));
            }
        }
        if self.load_left == 0 && func != 8 {
            self.regs[PARAM] &= !(1 << 31);
        }
        Ok(())
    }

    fn wdata(&mut self, x: i16) {
        let func = (self.regs[PARAM] >> 24) & 0x7F;
        if self.regs[PARAM] & (1 << 31) == 0 {
            return;
        }
        match func {
            1 | 2 => {
                if func == 1 {
                    self.x1.push(x);
                } else {
                    self.coefficients.push(x);
                }
                self.load_left = self.load_left.saturating_sub(1);
                if self.load_left == 0 {
                    // START clears when a load function completes (RM0440 §18.4.4).
                    self.regs[PARAM] &= !(1 << 31);
                }
            }
            _ => {
                self.x1.push(x);
                let n = self.fir_taps;
                if self.x1.len() > n {
                    self.x1.remove(0);
                }
                if self.x1.len() == n {
                    self.y.push(self.fir_output());
                }
            }
        }
    }

    /// y = Σ b_k·x(n−k) (RM0440 §18.3.5, §18.3.8): Q1.15 × Q1.15 products, the 8 LSBs
    /// of each Q2.30 product dropped into a 26-bit q4.22 accumulator (wrapping), gain
    /// 2^R, output bits \[22:7\], saturated with CLIPEN else truncated.
    fn fir_output(&self) -> i16 {
        let mut acc: i64 = 0;
        for (k, &b) in self.coefficients.iter().enumerate() {
            let x = self.x1[self.x1.len() - 1 - k];
            acc += (i64::from(b) * i64::from(x)) >> 8;
            acc = (acc << 38) >> 38;
        }
        let r = ((self.regs[PARAM] >> 16) & 0xFF).min(7);
        let y = (acc << r) >> 7;
        if self.regs[CR] & (1 << 15) != 0 {
            y.clamp(i64::from(i16::MIN), i64::from(i16::MAX)) as i16
        } else {
            y as i16
        }
    }
}
