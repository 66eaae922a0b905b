//! FDCAN1 (RM0440 §44) as a receiver and transmitter of classic frames: configuration
//! protection (INIT/CCE), the global filter (RXGFC) and standard filter elements in the
//! message RAM, RX FIFO 0 with its fill level, get/put indices and acknowledge; the Tx
//! FIFO (TXBC.TFQM = 0, the reset value: three Tx buffers used in request order,
//! RM0440 §44.3.3 "Tx FIFO") with TXFQS/TXBRP/TXBTO, each requested frame put on the bus
//! one after the other at the joined bit rate ([`frame_bits`]) and handed to the test
//! ([`Fdcan::take_sent`]). Frames to receive come from the test ([`crate::Frame`]). The bit timing the controller joins the bus with (NBTP and
//! the kernel clock RCC_CCIPR.FDCANSEL selects) is recorded; a bus-off can be injected
//! ([`Fdcan::bus_off`]): PSR.BO and CCCR.INIT set (RM0440 §44.3.2: INIT is set "by going
//! Bus_Off"), no frame received until software clears INIT and 128 occurrences of 11
//! recessive bits have passed at the bit rate (ISO 11898-1's bus-off recovery), then BO
//! clears.

use super::clock::unknown;
use crate::violation::Broken;

/// Message RAM base of FDCAN1 (RM0440 §44.3.3, SRAMCAN) and its size (212 words).
pub const RAM_BASE: u32 = 0x4000_A400;
/// Bytes of FDCAN1's message RAM.
pub const RAM_BYTES: u32 = 212 * 4;
/// RX FIFO 0 offset and elements (RM0440 §44.3.3, fixed layout: 3 elements of 18 words).
const RXF0: u32 = 0xB0;
const RX_ELEMENTS: u32 = 3;
const RX_ELEMENT_BYTES: u32 = 72;
/// Tx buffers offset and elements (RM0440 §44.3.3, fixed layout: 3 elements of 18 words
/// after the Tx event FIFO at 0x260).
const TXBUF: u32 = 0x278;
const TX_ELEMENTS: u32 = 3;
const TX_ELEMENT_BYTES: u32 = 72;

/// CCCR bits (RM0440 §44.4.6).
const INIT: u32 = 1;
const CCE: u32 = 1 << 1;
/// PSR.BO (RM0440 §44.4.13).
const BO: u32 = 1 << 7;
/// Bits of the bus-off recovery: 128 occurrences of 11 consecutive recessive bits
/// (ISO 11898-1).
pub const RECOVERY_BITS: f64 = 128.0 * 11.0;

/// The nominal bit timing the controller joined the bus with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Joined {
    /// Kernel clock \[Hz\] (RCC_CCIPR.FDCANSEL's source).
    pub kernel_hz: f64,
    /// Bit rate \[bit/s\]: kernel/((NBRP + 1)·(1 + NTSEG1 + 1 + NTSEG2 + 1)).
    pub bit_rate: f64,
    /// Sample point: (1 + NTSEG1 + 1)/quanta.
    pub sample_point: f64,
}

/// Bits a classic data frame occupies on the bus with `bytes` data bytes, stuff bits not
/// counted (ISO 11898-1 frame format): standard — SOF 1, identifier 11, RTR 1, IDE 1,
/// r0 1, DLC 4, data 8·n, CRC 15, CRC delimiter 1, ACK slot and delimiter 2, EOF 7,
/// intermission 3 = 47 + 8·n; extended — SRR, IDE, 18 more identifier bits and r1 make
/// 67 + 8·n. Stuff bits add at most (34 + 8·n − 1)/4 (standard), so the time a frame
/// takes here is a lower bound.
pub fn frame_bits(bytes: usize, extended: bool) -> f64 {
    let base = if extended { 67.0 } else { 47.0 };
    base + 8.0 * bytes.min(8) as f64
}

/// Known registers (RM0440 §44.4 register map).
const KNOWN: &[u32] = &[
    0x00, 0x04, 0x0C, 0x10, 0x14, 0x18, 0x1C, 0x20, 0x24, 0x28, 0x2C, 0x40, 0x44, 0x48, 0x50, 0x54, 0x58, 0x5C, 0x80,
    0x84, 0x88, 0x90, 0x94, 0x98, 0x9C, 0xC0, 0xC4, 0xC8, 0xCC, 0xD0, 0xD4, 0xD8, 0xDC, 0xE0, 0xE4, 0xE8, 0x100,
];
/// Registers writable only with CCE = 1 and INIT = 1 (RM0440 §44.4: DBTP, TEST, NBTP,
/// TSCC, TOCC, TDCR, RXGFC, XIDAM, TXBC).
const PROTECTED: &[u32] = &[0x0C, 0x10, 0x1C, 0x20, 0x28, 0x48, 0x80, 0x84, 0xC0];

/// A classic CAN frame on the bus.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Frame {
    /// Identifier (11 or 29 bits).
    pub id: u32,
    /// Extended identifier.
    pub extended: bool,
    /// Remote frame.
    pub remote: bool,
    /// Data bytes (0–8), DLC = len.
    pub data: Vec<u8>,
}

/// FDCAN1 and its message RAM.
#[derive(Debug)]
pub struct Fdcan {
    regs: [u32; 0x104 / 4],
    /// Message RAM words.
    pub ram: Vec<u32>,
    get: u32,
    fill: u32,
    /// Frames accepted into RX FIFO 0 / rejected by the filters / lost (FIFO full).
    pub accepted: u32,
    /// Frames the filters rejected.
    pub rejected: u32,
    /// Frames lost to a full FIFO.
    pub lost: u32,
    /// The last join (INIT cleared) with its bit timing.
    pub joined: Option<Joined>,
    /// Bus-offs injected.
    pub bus_offs: u32,
    /// Recoveries started by software (INIT cleared while PSR.BO).
    pub recoveries: u32,
    /// Frames the bus carried while the controller was bus-off or recovering.
    pub missed_while_bus_off: u32,
    /// End of the running bus-off recovery \[s\].
    recovery_until: Option<f64>,
    /// Requested Tx buffers in request order: (buffer index, frame, request time \[s\]).
    tx_pending: std::collections::VecDeque<(u32, Frame, f64)>,
    /// The Tx FIFO put index (TXFQS.TFQPI).
    tx_put: u32,
    /// The bus is free from this time on \[s\] (the last transmission's end).
    bus_free_s: f64,
    /// Transmitted frames not yet taken by the test, with the time each ended \[s\].
    sent: std::collections::VecDeque<(f64, Frame)>,
    /// Frames transmitted since reset.
    pub transmitted: u32,
    /// When the image last acknowledged an RX FIFO 0 element (RXF0A written) \[s\]: the
    /// instant it took a received frame.
    pub last_ack_s: Option<f64>,
}

impl Default for Fdcan {
    fn default() -> Self {
        Self::new()
    }
}

impl Fdcan {
    /// Reset state: CCCR = 0x0000_0001 (INIT), NBTP = 0x0600_0A03, CREL 0x3214_1218, ENDN
    /// 0x8765_4321, PSR 0x0000_0707 (RM0440 §44.4).
    pub fn new() -> Self {
        let mut regs = [0; 0x104 / 4];
        regs[0] = 0x3214_1218;
        regs[1] = 0x8765_4321;
        regs[0x18 / 4] = INIT;
        regs[0x1C / 4] = 0x0600_0A03;
        regs[0x44 / 4] = 0x0000_0707;
        Self {
            regs,
            ram: vec![0; (RAM_BYTES / 4) as usize],
            get: 0,
            fill: 0,
            accepted: 0,
            rejected: 0,
            lost: 0,
            joined: None,
            bus_offs: 0,
            recoveries: 0,
            missed_while_bus_off: 0,
            recovery_until: None,
            tx_pending: std::collections::VecDeque::new(),
            tx_put: 0,
            bus_free_s: 0.0,
            sent: std::collections::VecDeque::new(),
            transmitted: 0,
            last_ack_s: None,
        }
    }

    fn cccr(&self) -> u32 {
        self.regs[0x18 / 4]
    }

    /// Bus-off now (the test's fault on the bus): PSR.BO and CCCR.INIT set.
    pub fn bus_off(&mut self) {
        self.regs[0x44 / 4] |= BO;
        self.regs[0x18 / 4] |= INIT;
        self.recovery_until = None;
        self.bus_offs += 1;
    }

    /// The controller is bus-off (PSR.BO), recovering or waiting for software.
    pub fn is_bus_off(&self) -> bool {
        self.regs[0x44 / 4] & BO != 0
    }

    /// Ends a recovery whose 128 × 11 recessive bits have passed by `now` \[s\].
    fn advance(&mut self, now: f64) {
        if self.recovery_until.is_some_and(|t| now >= t) {
            self.recovery_until = None;
            self.regs[0x44 / 4] &= !BO;
        }
        while let Some(end) = self.next_tx_end() {
            if end > now {
                break;
            }
            let Some((index, frame, _)) = self.tx_pending.pop_front() else {
                break;
            };
            self.bus_free_s = end;
            // TXBTO: the buffer's transmission occurred (RM0440 §44.4.31), set when it
            // ends, cleared by a new request of the buffer.
            self.regs[0xD4 / 4] |= 1 << index;
            self.transmitted += 1;
            self.sent.push_back((end, frame));
        }
    }

    /// When the oldest pending frame ends on the bus \[s\], if the controller is on the
    /// bus (INIT = 0, not bus-off) and one is pending: it starts when requested or when
    /// the previous one ended, whichever is later.
    fn next_tx_end(&self) -> Option<f64> {
        if self.cccr() & INIT != 0 || self.is_bus_off() {
            return None;
        }
        let (_, frame, at) = self.tx_pending.front()?;
        let rate = self.joined?.bit_rate;
        Some(at.max(self.bus_free_s) + frame_bits(frame.data.len(), frame.extended) / rate)
    }

    /// Whether a transmitted frame is waiting for [`Fdcan::take_sent`] at `now` \[s\].
    pub fn has_sent_by(&self, now: f64) -> bool {
        !self.sent.is_empty() || self.next_tx_end().is_some_and(|end| end <= now)
    }

    /// The oldest frame transmitted by `now` \[s\] and the time its transmission ended.
    pub fn take_sent(&mut self, now: f64) -> Option<(f64, Frame)> {
        self.advance(now);
        self.sent.pop_front()
    }

    /// The frame in Tx buffer `index` (RM0440 §44.3.3, "Tx buffer element": T0 =
    /// ESI/XTD/RTR/ID (a standard identifier in bits 28:18), T1 = MM/EFC/FDF/BRS/DLC,
    /// then the data bytes little-endian).
    fn tx_element(&self, index: u32) -> Result<Frame, Broken> {
        let base = ((TXBUF + index * TX_ELEMENT_BYTES) / 4) as usize;
        let (t0, t1) = (self.ram[base], self.ram[base + 1]);
        if t1 & (1 << 21) != 0 {
            return Err(Broken::new(
                "FDCAN1 Tx buffer",
                "FDF set: an FD frame requested, only classic CAN is modelled (and CCCR.FDOE is not set)",
            ));
        }
        let extended = t0 & (1 << 30) != 0;
        let id = if extended { t0 & 0x1FFF_FFFF } else { (t0 >> 18) & 0x7FF };
        let dlc = ((t1 >> 16) & 0xF).min(8) as usize;
        let mut bytes = [0u8; 8];
        bytes[..4].copy_from_slice(&self.ram[base + 2].to_le_bytes());
        bytes[4..].copy_from_slice(&self.ram[base + 3].to_le_bytes());
        Ok(Frame {
            id,
            extended,
            remote: t0 & (1 << 29) != 0,
            data: bytes[..dlc].to_vec(),
        })
    }

    /// Register read at `now` \[s\].
    pub fn read(&mut self, off: u32, now: f64) -> Result<u32, Broken> {
        if !KNOWN.contains(&off) {
            return Err(unknown("FDCAN1", off));
        }
        self.advance(now);
        Ok(match off {
            // RXF0S: F0FL, F0GI, F0PI, F0F (RM0440 §44.4.22).
            0x90 => {
                let put = (self.get + self.fill) % RX_ELEMENTS;
                self.fill | (self.get << 8) | (put << 16) | (u32::from(self.fill == RX_ELEMENTS) << 24)
            }
            // TXFQS: TFFL free level, TFGI get index, TFQPI put index, TFQF full
            // (RM0440 §44.4.27).
            0xC4 => {
                let pending = self.tx_pending.len() as u32;
                let get = self.tx_pending.front().map_or(self.tx_put, |p| p.0);
                (TX_ELEMENTS - pending) | (get << 8) | (self.tx_put << 16) | (u32::from(pending == TX_ELEMENTS) << 21)
            }
            // TXBRP: the pending requests (RM0440 §44.4.28).
            0xC8 => self.tx_pending.iter().fold(0, |m, p| m | 1 << p.0),
            _ => self.regs[(off / 4) as usize],
        })
    }

    /// Register write at `now` \[s\] with the kernel clock `kernel_hz` (0: none running).
    pub fn write(&mut self, off: u32, value: u32, now: f64, kernel_hz: f64) -> Result<(), Broken> {
        if !KNOWN.contains(&off) {
            return Err(unknown("FDCAN1", off));
        }
        self.advance(now);
        if PROTECTED.contains(&off) && self.cccr() & (INIT | CCE) != (INIT | CCE) {
            return Err(Broken::new(
                format!("FDCAN1+{off:#04x}"),
                "protected register written without CCCR.INIT = 1 and CCE = 1 (RM0440 §44.4.6)",
            ));
        }
        match off {
            0x18 => {
                // CCE can only be set while INIT = 1; clearing INIT clears CCE (§44.4.6).
                let mut v = value;
                if v & INIT == 0 {
                    v &= !CCE;
                }
                if self.cccr() & INIT == 0 && v & INIT == 0 && v & CCE != 0 {
                    v &= !CCE;
                }
                if self.cccr() & INIT != 0 && v & INIT == 0 {
                    let nbtp = self.regs[0x1C / 4];
                    let prescaler = f64::from(((nbtp >> 16) & 0x1FF) + 1);
                    let tseg1 = f64::from(((nbtp >> 8) & 0xFF) + 1);
                    let quanta = 1.0 + tseg1 + f64::from((nbtp & 0x7F) + 1);
                    if kernel_hz <= 0.0 {
                        return Err(Broken::new(
                            "FDCAN1_CCCR",
                            "INIT cleared with no FDCAN kernel clock running (RCC_CCIPR.FDCANSEL: HSE without HSERDY, or the PLL Q output; RM0440 §7.4.26)",
                        ));
                    }
                    let bit_rate = kernel_hz / (prescaler * quanta);
                    self.joined = Some(Joined {
                        kernel_hz,
                        bit_rate,
                        sample_point: (1.0 + tseg1) / quanta,
                    });
                    if self.is_bus_off() {
                        self.recoveries += 1;
                        self.recovery_until = Some(now + RECOVERY_BITS / bit_rate);
                    }
                }
                self.regs[0x18 / 4] = v;
            }
            // RXF0A: acknowledge up to F0AI (RM0440 §44.4.23).
            0x94 => {
                let ai = value & 7;
                if ai >= RX_ELEMENTS || self.fill == 0 {
                    return Err(Broken::new(
                        "FDCAN1_RXF0A",
                        "acknowledge of an element not in RX FIFO 0",
                    ));
                }
                let n = (ai + RX_ELEMENTS - self.get) % RX_ELEMENTS + 1;
                if n > self.fill {
                    return Err(Broken::new(
                        "FDCAN1_RXF0A",
                        "acknowledge index beyond the fill level (RM0440 §44.4.23)",
                    ));
                }
                self.fill -= n;
                self.get = (ai + 1) % RX_ELEMENTS;
                self.regs[0x94 / 4] = ai;
                self.last_ack_s = Some(now);
            }
            // TXBAR: add requests (RM0440 §44.4.29); in FIFO mode the buffer is the put
            // index TXFQS.TFQPI, free (ST's HAL_FDCAN_AddMessageToTxFifoQ writes the
            // element at the put index and requests that buffer).
            0xCC => {
                for index in (0..TX_ELEMENTS).filter(|k| value & (1 << k) != 0) {
                    if self.tx_pending.len() as u32 == TX_ELEMENTS || index != self.tx_put {
                        return Err(Broken::new(
                            "FDCAN1_TXBAR",
                            format!(
                                "transmission requested in Tx buffer {index}, not the free put index TXFQS.TFQPI = {} of a Tx FIFO with {} of 3 pending (RM0440 §44.3.3, Tx FIFO)",
                                self.tx_put,
                                self.tx_pending.len()
                            ),
                        ));
                    }
                    let frame = self.tx_element(index)?;
                    self.regs[0xD4 / 4] &= !(1 << index);
                    self.tx_pending.push_back((index, frame, now));
                    self.tx_put = (index + 1) % TX_ELEMENTS;
                }
                self.regs[0xCC / 4] = value;
            }
            0x90 | 0x98 | 0x00 | 0x04 | 0x44 | 0xC4 | 0xC8 | 0xD4 | 0xD8 => {
                return Err(Broken::new(
                    format!("FDCAN1+{off:#04x}"),
                    "read-only register (RM0440 §44.4)",
                ));
            }
            _ => self.regs[(off / 4) as usize] = value,
        }
        Ok(())
    }

    /// Acceptance filtering (RM0440 §44.3.7, Figures 692–693): the standard filter
    /// elements (RXGFC.LSS of them at the start of the message RAM: SFT range / dual /
    /// classic mask, SFEC store-in-FIFO-0/1 or reject), then non-matching frames by
    /// ANFS/ANFE, remote frames by RRFS/RRFE. Returns the FIFO (0 or 1) or `None`.
    fn filter(&self, f: &Frame) -> Option<u32> {
        let gfc = self.regs[0x80 / 4];
        if f.remote {
            let reject = if f.extended { gfc & 1 } else { gfc & 2 };
            if reject != 0 {
                return None;
            }
        }
        if !f.extended {
            let lss = ((gfc >> 16) & 0x1F).min(28);
            for k in 0..lss {
                let e = self.ram[k as usize];
                let (sft, sfec, id1, id2) = (e >> 30, (e >> 27) & 7, (e >> 16) & 0x7FF, e & 0x7FF);
                let hit = match sft {
                    0 => (id1..=id2).contains(&f.id),
                    1 => f.id == id1 || f.id == id2,
                    2 => f.id & id2 == id1 & id2,
                    _ => false,
                };
                if hit {
                    return match sfec {
                        1 => Some(0),
                        2 => Some(1),
                        _ => None,
                    };
                }
            }
        }
        let anf = if f.extended { (gfc >> 2) & 3 } else { (gfc >> 4) & 3 };
        match anf {
            0 => Some(0),
            1 => Some(1),
            _ => None,
        }
    }

    /// A frame on the bus: stored in RX FIFO 0 if the controller is on the bus (INIT =
    /// 0) and the filters accept it into FIFO 0 (element format RM0440 §44.3.3, "Rx FIFO
    /// element": R0 = XTD/RTR/ID, R1 = DLC, then the data bytes little-endian).
    pub fn receive(&mut self, f: &Frame, now: f64) {
        self.advance(now);
        if self.is_bus_off() {
            self.missed_while_bus_off += 1;
            return;
        }
        if self.cccr() & INIT != 0 {
            return;
        }
        match self.filter(f) {
            Some(0) => {}
            _ => {
                self.rejected += 1;
                return;
            }
        }
        if self.fill == RX_ELEMENTS {
            self.lost += 1;
            return;
        }
        let put = (self.get + self.fill) % RX_ELEMENTS;
        let base = ((RXF0 + put * RX_ELEMENT_BYTES) / 4) as usize;
        let id = if f.extended {
            f.id & 0x1FFF_FFFF
        } else {
            (f.id & 0x7FF) << 18
        };
        self.ram[base] = id | (u32::from(f.extended) << 30) | (u32::from(f.remote) << 29);
        self.ram[base + 1] = (f.data.len().min(8) as u32) << 16;
        let mut bytes = [0u8; 8];
        for (b, d) in bytes.iter_mut().zip(&f.data) {
            *b = *d;
        }
        self.ram[base + 2] = u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]);
        self.ram[base + 3] = u32::from_le_bytes([bytes[4], bytes[5], bytes[6], bytes[7]]);
        self.fill += 1;
        self.accepted += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Joins at 500 kbit/s from a 170 MHz kernel clock: NBRP = 19 (÷20), 17 quanta
    /// (NTSEG1 = 13 → 14 + 1 sync, NTSEG2 = 1 → 2): 170 MHz/(20·17) = 500 kbit/s.
    fn joined() -> Fdcan {
        let mut f = Fdcan::new();
        f.write(0x18, INIT | CCE, 0.0, 170e6).unwrap();
        f.write(0x1C, (19 << 16) | (13 << 8) | 1, 0.0, 170e6).unwrap();
        f.write(0x18, 0, 0.0, 170e6).unwrap();
        f
    }

    /// Writes a standard frame (id, 8 bytes) into Tx buffer `k` as the image's
    /// `tx_element` does (RM0440 §44.3.3: T0 = ID << 18, T1 = DLC << 16).
    fn element(f: &mut Fdcan, k: u32, id: u32) {
        let base = ((TXBUF + k * TX_ELEMENT_BYTES) / 4) as usize;
        f.ram[base] = id << 18;
        f.ram[base + 1] = 8 << 16;
        f.ram[base + 2] = 0x0403_0201;
        f.ram[base + 3] = 0x0807_0605;
    }

    /// Two requests in FIFO order: TXFQS counts them, the bus carries them one after the
    /// other, 111 bits (47 + 64) each at 500 kbit/s = 222 µs; a request of a buffer other
    /// than the put index is a violation.
    #[test]
    fn tx_fifo_sends_in_order_at_the_bit_rate() {
        let mut f = joined();
        assert_eq!(f.read(0xC4, 0.0).unwrap(), 3, "reset: 3 free, put 0");
        element(&mut f, 0, 0x123);
        f.write(0xCC, 1, 1e-3, 170e6).unwrap();
        element(&mut f, 1, 0x124);
        f.write(0xCC, 2, 1e-3, 170e6).unwrap();
        let s = f.read(0xC4, 1e-3).unwrap();
        assert_eq!((s & 7, (s >> 8) & 3, (s >> 16) & 3, (s >> 21) & 1), (1, 0, 2, 0));
        assert_eq!(f.read(0xC8, 1e-3).unwrap(), 0b11);
        assert!(
            f.write(0xCC, 1, 1e-3, 170e6).is_err(),
            "buffer 0 is not the put index 2"
        );
        let first_end = 1e-3 + 111.0 / 500e3;
        assert!(!f.has_sent_by(first_end - 1e-9));
        let (t, frame) = f.take_sent(first_end + 1e-9).unwrap();
        assert!((t - first_end).abs() < 1e-12);
        assert_eq!((frame.id, frame.data.len(), frame.data[7]), (0x123, 8, 8));
        assert!(f.take_sent(first_end + 1e-9).is_none());
        let (t, frame) = f.take_sent(1.0).unwrap();
        assert!((t - (first_end + 222e-6)).abs() < 1e-12);
        assert_eq!(frame.id, 0x124);
        assert_eq!(f.read(0xC4, 1.0).unwrap() & 7, 3);
        assert_eq!(f.read(0xD4, 1.0).unwrap(), 0b11, "TXBTO: both transmitted");
    }
}
