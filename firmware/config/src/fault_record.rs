//! The fault record kept across a reset (pure): why the outputs were switched off, where
//! the core was (the stacked PC of a HardFault) and the control state of the last
//! period, as words in a RAM section that the start-up code neither loads nor zeroes
//! (`.uninit`, NOLOAD), so the image reads it again after the watchdog reset that
//! follows every fault. SRAM keeps its contents through a system reset (watchdog,
//! NRST, lockup) but not through a power-on reset (RM0440 §7.1: a system reset resets
//! the registers, a power reset also cuts the SRAM's supply): a record is therefore sealed with [`MAGIC`] and a CRC-32 over all its
//! other words, so the random contents after power-up are told apart from a record
//! ([`FaultRecord::from_words`]).
//!
//! Two word arrays, both owned by the board layer (`motor-firmware`, `board/fault.rs`):
//! * the live control state ([`ControlState`], [`STATE_WORDS`] words), written by the
//!   control interrupt every period and zeroed at boot;
//! * the sealed record ([`RECORD_WORDS`] words), written once by the fault path.
//!
//! At boot [`at_boot`] turns them and the reset cause (RCC_CSR.IWDGRSTF) into the record
//! to report: a sealed record, or — after a watchdog reset that no fault path sealed
//! (the main loop stalled, or the control interrupt stopped) — a record of cause
//! [`FaultCause::Watchdog`] carrying the live state the control interrupt left.
#![forbid(unsafe_code)]

use motor_control::can_protocol::{Crc32, FaultMeasurement, MEASUREMENT_INDEX_MASK};
use motor_control::preflight::PreflightFault;

/// Words of the sealed record: magic, cause, flags, PC, CFSR, HFSR, the start-up check's
/// measurement, the control state ([`STATE_WORDS`]), CRC.
pub const RECORD_WORDS: usize = HEAD_WORDS + STATE_WORDS + 1;
/// Words before the control state.
const HEAD_WORDS: usize = 7;
/// Words of the live control state.
pub const STATE_WORDS: usize = 8;
/// First word of a sealed record ("MFR3" in ASCII, little-endian bytes `3RFM`): a
/// version of this layout; a record of another layout fails the check. Version 2 (issue
/// 26) added the CAN bus-off count to the state, version 3 the start-up check's
/// measurement; a record of an older version (`MFR1` 14 words, `MFR2` 15) left by an
/// older image is not read.
pub const MAGIC: u32 = 0x4D46_5233;

/// Why the outputs were switched off. The numbers are the record's and the CAN
/// frame's encoding (never reuse one).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum FaultCause {
    /// A HardFault (or a configurable fault escalated to it) with the stack intact.
    HardFault = 1,
    /// A HardFault whose exception frame could not be stacked: the stack overflowed
    /// into the unmapped space below RAM (CFSR.STKERR, or the stack pointer below the
    /// stack's bottom).
    StackOverflow = 2,
    /// TIM1's break flag (BIF) was found set: the board's over-current comparator or
    /// a source routed by SYSCFG_CFGR2 (lockup, SRAM parity, flash ECC) stopped the
    /// outputs in hardware.
    Break = 3,
    /// A software trip of the control interrupt: a phase current beyond the
    /// over-current level or at an ADC rail, the DC link beyond the over-voltage
    /// level, or the speed beyond the over-speed level (the state tells which).
    Trip = 4,
    /// The injected conversions of a period were missing.
    LostConversion = 5,
    /// Bring-up stopped (clock, option bytes, break input active, CORDIC/FMAC
    /// self-test, ADC or FDCAN not ready).
    BringUp = 6,
    /// An interrupt without a handler.
    UnhandledInterrupt = 7,
    /// A panic (development builds only; a release image has no panic path).
    Panic = 8,
    /// An independent-watchdog reset that no fault path recorded.
    Watchdog = 9,
    /// The current sensing's zero level, averaged at start-up with the gates off
    /// (`board::OFFSET_SAMPLES` conversions per phase), lies further from the board's
    /// nominal level than `board::OFFSET_BOUND_CODE` on some phase: a wrong offset in
    /// the board file, a sensor or amplifier without supply, a broken channel. The
    /// outputs were never switched on. (Numbers 10–19 are issue 26's start-up checks.)
    CurrentOffset = 10,
    /// Pre-flight check (`motor_control::preflight`, CAN routine 6): the pulse's current
    /// had the wrong sign — the current sensing is inverted.
    PreflightInvertedSensing = 11,
    /// Pre-flight: R from the pulses (or a current above what the lowest accepted R
    /// draws) outside the bound of the spec's R.
    PreflightResistance = 12,
    /// Pre-flight: L from the pulse's rise outside the bound of the spec's L_d.
    PreflightInductance = 13,
    /// Pre-flight: the three measured phase currents do not sum to zero.
    PreflightCurrentSum = 14,
    /// Pre-flight: a phase carried less than half its expected current (open lead,
    /// connector or winding; dead sensor).
    PreflightOpenPhase = 15,
    /// Pre-flight: the resolver turned against the rotating field (two motor leads
    /// swapped, or the resolver's SIN/COS).
    PreflightDirection = 16,
    /// Pre-flight: the rotor did not follow, or the resolver turned by another ratio than
    /// n_r/n_p (a wrong pole-pair count).
    PreflightPolePairRatio = 17,
    /// Pre-flight: the rotor came to rest away from the commanded electrical angle (a
    /// wrong resolver offset).
    PreflightResolverOffset = 18,
    /// The resolver signal measured at start-up with the gates off
    /// (`motor_config::resolver_check`: the RMS √mean(sin² + cos²) over the second half
    /// of the offset calibration) is outside `board::RESOLVER_SIGNAL_MIN` … `_MAX` of the one the
    /// observer's gains are designed for (`board::RESOLVER_SIGNAL`): no excitation, a
    /// resolver unplugged, a front end unlike the board file's `sensing.resolver_amplitude`.
    /// The outputs were never switched on.
    ResolverSignal = 19,
}

impl From<PreflightFault> for FaultCause {
    fn from(f: PreflightFault) -> Self {
        match f {
            PreflightFault::InvertedSensing => Self::PreflightInvertedSensing,
            PreflightFault::Resistance => Self::PreflightResistance,
            PreflightFault::Inductance => Self::PreflightInductance,
            PreflightFault::CurrentSum => Self::PreflightCurrentSum,
            PreflightFault::OpenPhase => Self::PreflightOpenPhase,
            PreflightFault::Direction => Self::PreflightDirection,
            PreflightFault::PolePairRatio => Self::PreflightPolePairRatio,
            PreflightFault::ResolverOffset => Self::PreflightResolverOffset,
        }
    }
}

impl FaultCause {
    /// The cause of an encoded number, `None` for an unknown one.
    pub fn from_code(code: u32) -> Option<Self> {
        use FaultCause::*;
        [
            HardFault,
            StackOverflow,
            Break,
            Trip,
            LostConversion,
            BringUp,
            UnhandledInterrupt,
            Panic,
            Watchdog,
            CurrentOffset,
            PreflightInvertedSensing,
            PreflightResistance,
            PreflightInductance,
            PreflightCurrentSum,
            PreflightOpenPhase,
            PreflightDirection,
            PreflightPolePairRatio,
            PreflightResolverOffset,
            ResolverSignal,
        ]
        .into_iter()
        .find(|c| *c as u32 == code)
    }
}

/// The control state of the last period before the fault.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ControlState {
    /// Measured i_d \[A\].
    pub i_d: f32,
    /// Measured i_q \[A\].
    pub i_q: f32,
    /// Electrical angle θ_e (π-scaled Q1.31).
    pub theta_e: i32,
    /// Electrical speed ω_e \[rad/s\].
    pub omega_e: f32,
    /// DC-link voltage \[V\].
    pub u_dc: f32,
    /// Control periods run since start-up (wrapping).
    pub periods: u32,
    /// CAN bus-off events the drive recovered from since start-up (FDCAN_PSR.BO, RM0440
    /// §44.3.1 "Bus-off recovery"; saturating).
    pub bus_off: u32,
    /// The outputs were switched on in that period.
    pub running: bool,
    /// A trip or break was latched.
    pub tripped: bool,
}

/// Flag bits of the state's last word.
const STATE_RUNNING: u32 = 1;
const STATE_TRIPPED: u32 = 1 << 1;
/// Set in every word written by the control interrupt; the boot code zeroes the
/// state, so a state without it was never written since start-up.
const STATE_WRITTEN: u32 = 1 << 31;

impl ControlState {
    /// The words the control interrupt writes.
    pub fn to_words(&self) -> [u32; STATE_WORDS] {
        let flags =
            STATE_WRITTEN | if self.running { STATE_RUNNING } else { 0 } | if self.tripped { STATE_TRIPPED } else { 0 };
        [
            self.i_d.to_bits(),
            self.i_q.to_bits(),
            self.theta_e as u32,
            self.omega_e.to_bits(),
            self.u_dc.to_bits(),
            self.periods,
            self.bus_off,
            flags,
        ]
    }

    /// The state of written words, `None` if the control interrupt never wrote them.
    pub fn from_words(w: &[u32; STATE_WORDS]) -> Option<Self> {
        let [i_d, i_q, theta_e, omega_e, u_dc, periods, bus_off, flags] = *w;
        (flags & STATE_WRITTEN != 0).then_some(Self {
            i_d: f32::from_bits(i_d),
            i_q: f32::from_bits(i_q),
            theta_e: theta_e as i32,
            omega_e: f32::from_bits(omega_e),
            u_dc: f32::from_bits(u_dc),
            periods,
            bus_off,
            running: flags & STATE_RUNNING != 0,
            tripped: flags & STATE_TRIPPED != 0,
        })
    }
}

/// A decoded fault record.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FaultRecord {
    /// Why the outputs were switched off.
    pub cause: FaultCause,
    /// Address of the instruction that faulted (stacked PC), when the exception frame
    /// was readable.
    pub pc: Option<u32>,
    /// SCB CFSR and HFSR at the fault (PM0214 §4.4.11, §4.4.12); zero outside a
    /// HardFault.
    pub cfsr: u32,
    /// See `cfsr`.
    pub hfsr: u32,
    /// The control state of the last period, if the control interrupt had run.
    pub state: Option<ControlState>,
    /// Already sent on CAN after a boot (sent once, kept for a probe).
    pub reported: bool,
    /// What the start-up check that refused the drive measured (causes 10–19; the
    /// figure and unit by cause: README, "What a refusal reports").
    pub measured: Option<FaultMeasurement>,
}

/// Flag bits of the record's flags word.
const HAS_PC: u32 = 1;
const HAS_STATE: u32 = 1 << 1;
const REPORTED: u32 = 1 << 2;
const HAS_MEASURED: u32 = 1 << 3;
/// The measurement's index, bits 4–5.
const INDEX_SHIFT: u32 = 4;
const INDEX_BITS: u32 = (MEASUREMENT_INDEX_MASK as u32) << INDEX_SHIFT;

impl FaultRecord {
    /// A record of `cause` alone: no PC, fault status, state or measurement, not sent.
    pub const fn of(cause: FaultCause) -> Self {
        Self {
            cause,
            pc: None,
            cfsr: 0,
            hfsr: 0,
            state: None,
            reported: false,
            measured: None,
        }
    }

    /// The sealed words: [`MAGIC`], cause, flags (bit 0 PC, 1 state, 2 reported, 3
    /// measurement, 4–5 its index), PC, CFSR, HFSR, the measurement (f32 bits, 0 when
    /// none), state, CRC-32 of the words before it.
    pub fn to_words(&self) -> [u32; RECORD_WORDS] {
        let mut w = [0; RECORD_WORDS];
        let flags = if self.pc.is_some() { HAS_PC } else { 0 }
            | if self.state.is_some() { HAS_STATE } else { 0 }
            | if self.reported { REPORTED } else { 0 }
            | self.measured.map_or(0, |m| {
                HAS_MEASURED | (u32::from(m.index & MEASUREMENT_INDEX_MASK) << INDEX_SHIFT)
            });
        let head: [u32; HEAD_WORDS] = [
            MAGIC,
            self.cause as u32,
            flags,
            self.pc.unwrap_or(0),
            self.cfsr,
            self.hfsr,
            self.measured.map_or(0, |m| m.value.to_bits()),
        ];
        let state = self.state.map_or([0; STATE_WORDS], |s| s.to_words());
        for (slot, v) in w.iter_mut().zip(head.into_iter().chain(state)) {
            *slot = v;
        }
        let crc = crc32_words(w.get(..RECORD_WORDS - 1).unwrap_or(&[]));
        if let Some(last) = w.last_mut() {
            *last = crc;
        }
        w
    }

    /// The record of sealed words; `None` unless the magic, the CRC, the cause and the
    /// flags all check (power-up contents, a torn write, another layout).
    pub fn from_words(w: &[u32; RECORD_WORDS]) -> Option<Self> {
        let (body, crc) = w.split_at(RECORD_WORDS - 1);
        if crc != [crc32_words(body)] {
            return None;
        }
        let [magic, cause, flags, pc, cfsr, hfsr, measured, ..] = *w;
        if magic != MAGIC || flags & !(HAS_PC | HAS_STATE | REPORTED | HAS_MEASURED | INDEX_BITS) != 0 {
            return None;
        }
        // Only what `to_words` writes: an index or a measurement word without its flag is
        // another layout's record.
        if flags & HAS_MEASURED == 0 && (flags & INDEX_BITS != 0 || measured != 0) {
            return None;
        }
        let mut state = [0; STATE_WORDS];
        state.copy_from_slice(body.get(HEAD_WORDS..HEAD_WORDS + STATE_WORDS)?);
        let state = if flags & HAS_STATE != 0 {
            Some(ControlState::from_words(&state)?)
        } else {
            None
        };
        Some(Self {
            cause: FaultCause::from_code(cause)?,
            pc: (flags & HAS_PC != 0).then_some(pc),
            cfsr,
            hfsr,
            state,
            reported: flags & REPORTED != 0,
            measured: (flags & HAS_MEASURED != 0)
                .then(|| FaultMeasurement::at(f32::from_bits(measured), ((flags & INDEX_BITS) >> INDEX_SHIFT) as u8)),
        })
    }
}

/// The record to report after a reset: the sealed one if it checks; else, after an
/// independent-watchdog reset, a [`FaultCause::Watchdog`] record with the live state the
/// control interrupt left (if it had run); else none (a cold boot, a reset by the pin or
/// the debugger with nothing recorded).
pub fn at_boot(record: &[u32; RECORD_WORDS], state: &[u32; STATE_WORDS], watchdog_reset: bool) -> Option<FaultRecord> {
    FaultRecord::from_words(record).or_else(|| {
        watchdog_reset.then(|| FaultRecord {
            state: ControlState::from_words(state),
            ..FaultRecord::of(FaultCause::Watchdog)
        })
    })
}

/// CFSR.STKERR: a BusFault on exception-entry stacking (PM0214 §4.4.11, BFSR bit 4 =
/// CFSR bit 12).
pub const CFSR_STKERR: u32 = 1 << 12;
/// CFSR.MSTKERR: a MemManage fault on exception-entry stacking (MMFSR bit 4).
pub const CFSR_MSTKERR: u32 = 1 << 4;
/// Bytes of the basic exception frame (R0–R3, R12, LR, PC, xPSR; PM0214 §2.3.7); the
/// stacked PC is its seventh word, at offset 24.
pub const FRAME_BYTES: u32 = 32;
/// Offset of the stacked PC in the frame.
pub const FRAME_PC_OFFSET: u32 = 24;

/// A HardFault's cause and the address of its stacked PC: `sp` is the stack pointer
/// the exception was stacked on, `stack` the stack's `[bottom, top)` addresses. The
/// stack overflowed if stacking failed (CFSR.STKERR/MSTKERR) or `sp` lies below the
/// bottom; the PC is readable only if the whole frame lies inside the stack (reading
/// below it would fault again, inside the HardFault handler: lockup).
pub fn classify_hard_fault(sp: u32, stack: (u32, u32), cfsr: u32) -> (FaultCause, Option<u32>) {
    let (bottom, top) = stack;
    let overflow = cfsr & (CFSR_STKERR | CFSR_MSTKERR) != 0 || sp < bottom;
    let frame_inside = sp >= bottom && sp.checked_add(FRAME_BYTES).is_some_and(|end| end <= top);
    let cause = if overflow {
        FaultCause::StackOverflow
    } else {
        FaultCause::HardFault
    };
    (
        cause,
        (frame_inside && !overflow).then(|| sp.wrapping_add(FRAME_PC_OFFSET)),
    )
}

/// CRC-32 (IEEE 802.3, `motor_control::can_protocol::Crc32`: the capture's check too) of
/// the words' little-endian bytes.
pub fn crc32_words(words: &[u32]) -> u32 {
    let mut crc = Crc32::new();
    for w in words {
        crc.update(&w.to_le_bytes());
    }
    crc.value()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record() -> FaultRecord {
        FaultRecord {
            pc: Some(0x0800_1234),
            state: Some(ControlState {
                i_d: -1.5,
                i_q: 212.25,
                theta_e: -0x4000_0000,
                omega_e: 1234.5,
                u_dc: 598.0,
                periods: 40_000,
                bus_off: 2,
                running: true,
                tripped: true,
            }),
            ..FaultRecord::of(FaultCause::Trip)
        }
    }

    /// The record's CRC runs over the words' little-endian bytes: the words of the
    /// ASCII "12345678" give CRC-32/ISO-HDLC("12345678") = 0x9AE0DAAF (Python
    /// `zlib.crc32(b"12345678")`); no words give 0 (initial value XOR final value).
    #[test]
    fn crc_over_little_endian_words() {
        let words = [u32::from_le_bytes(*b"1234"), u32::from_le_bytes(*b"5678")];
        assert_eq!(crc32_words(&words), 0x9AE0_DAAF);
        assert_eq!(crc32_words(&[]), 0);
    }

    #[test]
    fn round_trip() {
        let r = record();
        assert_eq!(FaultRecord::from_words(&r.to_words()), Some(r));
        let bare = FaultRecord {
            cfsr: CFSR_STKERR,
            hfsr: 1 << 30,
            reported: true,
            ..FaultRecord::of(FaultCause::StackOverflow)
        };
        assert_eq!(FaultRecord::from_words(&bare.to_words()), Some(bare));
        // A start-up check's refusal with its figure: phase w's zero level 2 992 codes
        // below nominal (the offset test's case), and a NaN kept bit for bit.
        let offset = FaultRecord {
            cause: FaultCause::CurrentOffset,
            measured: Some(FaultMeasurement::at(-2_992.0, 2)),
            ..record()
        };
        assert_eq!(FaultRecord::from_words(&offset.to_words()), Some(offset));
        let nan = FaultRecord {
            measured: Some(FaultMeasurement::of(f32::NAN)),
            ..offset
        };
        let back = FaultRecord::from_words(&nan.to_words()).and_then(|r| r.measured);
        assert_eq!(
            back.map(|m| (m.value.to_bits(), m.index)),
            Some((f32::NAN.to_bits(), 0))
        );
        for code in 1..=19 {
            let c = FaultCause::from_code(code).expect("codes 1–19 are causes");
            assert_eq!(c as u32, code);
        }
        assert_eq!(FaultCause::from_code(0), None);
        assert_eq!(FaultCause::from_code(20), None);
        // The pre-flight check's refusals keep their numbers in the record.
        for f in [
            PreflightFault::InvertedSensing,
            PreflightFault::Resistance,
            PreflightFault::Inductance,
            PreflightFault::CurrentSum,
            PreflightFault::OpenPhase,
            PreflightFault::Direction,
            PreflightFault::PolePairRatio,
            PreflightFault::ResolverOffset,
        ] {
            assert_eq!(FaultCause::from(f) as u8, f.code());
        }
    }

    /// Layout: word 0 is the magic, word 1 the cause code, the last word the CRC of the
    /// others (so a probe can decode it by hand, README "Fault record").
    #[test]
    fn layout() {
        let w = record().to_words();
        // "MFR3": 'M' 0x4D, 'F' 0x46, 'R' 0x52, '3' 0x33.
        assert_eq!(w[0], 0x4D46_5233);
        assert_eq!(w[1], 4);
        assert_eq!(w[2], 0b011);
        assert_eq!(w[3], 0x0800_1234);
        assert_eq!(w[6], 0, "no measurement");
        assert_eq!(w[8], 212.25f32.to_bits());
        // Words 7–14 the state (README "Fault record"): periods in 12, bus-off count in
        // 13, the flags (bit 31 written) in 14, the CRC in 15.
        assert_eq!(RECORD_WORDS, 16);
        assert_eq!((w[12], w[13]), (40_000, 2));
        assert_eq!(w[14] >> 31, 1);
        assert_eq!(w[RECORD_WORDS - 1], crc32_words(&w[..RECORD_WORDS - 1]));
        // A measurement: flag bit 3, index 2 in bits 4–5 (0b10_1011 with PC and state),
        // −2 992.0 = 0xC53B_0000 in word 6 (sign 1, exponent 11 + 127 = 138 = 0x8A,
        // mantissa 2992/2048 − 1 = 0.4609375 = 0x3B0000/2^23).
        let w = FaultRecord {
            measured: Some(FaultMeasurement::at(-2_992.0, 2)),
            ..record()
        }
        .to_words();
        assert_eq!(w[2], 0b10_1011);
        assert_eq!(w[6], 0xC53B_0000);
    }

    /// Every single-bit error anywhere in the record is rejected (CRC-32 detects all
    /// single-bit errors).
    #[test]
    fn any_flipped_bit_is_rejected() {
        let w = record().to_words();
        for i in 0..RECORD_WORDS {
            for bit in 0..32 {
                let mut bad = w;
                bad[i] ^= 1 << bit;
                assert_eq!(FaultRecord::from_words(&bad), None, "word {i} bit {bit}");
            }
        }
    }

    /// A valid CRC is not enough: another magic (another layout), an unknown cause or
    /// unknown flags are refused too (each re-sealed with a correct CRC).
    #[test]
    fn resealed_nonsense_is_rejected() {
        let reseal = |k: usize, v: u32| {
            let mut w = record().to_words();
            w[k] = v;
            w[RECORD_WORDS - 1] = crc32_words(&w[..RECORD_WORDS - 1]);
            FaultRecord::from_words(&w)
        };
        assert_eq!(reseal(0, MAGIC ^ 1), None);
        assert_eq!(reseal(1, 0), None);
        assert_eq!(reseal(1, 77), None);
        assert_eq!(reseal(2, 1 << 6), None);
        // An index (bits 4–5) or a measurement word without the measurement's flag.
        assert_eq!(reseal(2, 0b11 | (1 << 4)), None);
        assert_eq!(reseal(6, 1.5f32.to_bits()), None);
        // HAS_STATE with state words the interrupt never wrote.
        assert_eq!(reseal(HEAD_WORDS + STATE_WORDS - 1, 0), None);
        assert!(
            reseal(3, 0x0800_0000).is_some(),
            "the check itself accepts a resealed record"
        );
    }

    /// Power-up RAM: all zeros, all ones, and pseudo-random patterns (xorshift32,
    /// Marsaglia 2003) are never taken for a record.
    #[test]
    fn cold_boot_garbage_is_rejected() {
        assert_eq!(FaultRecord::from_words(&[0; RECORD_WORDS]), None);
        assert_eq!(FaultRecord::from_words(&[u32::MAX; RECORD_WORDS]), None);
        let mut x: u32 = 0x2545_F491;
        for _ in 0..10_000 {
            let mut w = [0; RECORD_WORDS];
            for slot in &mut w {
                x ^= x << 13;
                x ^= x >> 17;
                x ^= x << 5;
                *slot = x;
            }
            // Even with the right magic in front.
            let mut with_magic = w;
            with_magic[0] = MAGIC;
            assert_eq!(FaultRecord::from_words(&w), None);
            assert_eq!(FaultRecord::from_words(&with_magic), None);
        }
        assert_eq!(at_boot(&[0; RECORD_WORDS], &[0; STATE_WORDS], false), None);
    }

    /// After a watchdog reset without a sealed record the live state is reported if the
    /// control interrupt wrote it, and not if the boot's zeroes are still there.
    #[test]
    fn watchdog_reset_without_record() {
        let state = record().state.unwrap();
        let r = at_boot(&[0; RECORD_WORDS], &state.to_words(), true).unwrap();
        assert_eq!(r.cause, FaultCause::Watchdog);
        assert_eq!(r.state, Some(state));
        assert_eq!(r.pc, None);
        let r = at_boot(&[0; RECORD_WORDS], &[0; STATE_WORDS], true).unwrap();
        assert_eq!(r.state, None);
        // A sealed record wins over the reset flag.
        let sealed = record();
        assert_eq!(at_boot(&sealed.to_words(), &[0; STATE_WORDS], true), Some(sealed));
    }

    /// Stack [0x2000_0000, 0x2000_8000): a frame at 0x2000_7000 is readable, its PC at
    /// +24; a stacking error or a stack pointer below the bottom is an overflow with no
    /// PC; a frame reaching past the top is not read.
    #[test]
    fn hard_fault_classification() {
        let stack = (0x2000_0000, 0x2000_8000);
        assert_eq!(
            classify_hard_fault(0x2000_7000, stack, 0),
            (FaultCause::HardFault, Some(0x2000_7018))
        );
        assert_eq!(
            classify_hard_fault(0x2000_0000, stack, CFSR_STKERR),
            (FaultCause::StackOverflow, None)
        );
        assert_eq!(
            classify_hard_fault(0x1FFF_FFE0, stack, 0),
            (FaultCause::StackOverflow, None)
        );
        assert_eq!(
            classify_hard_fault(0x2000_7FF0, stack, 0),
            (FaultCause::HardFault, None)
        );
        assert_eq!(
            classify_hard_fault(0xFFFF_FFF0, stack, 0),
            (FaultCause::HardFault, None)
        );
    }
}
