//! Bit-exact model of an FIR filter on the STM32G474 FMAC (RM0440 §"FMAC": fixed
//! point representation, FIR filters), used for the identification low-pass of
//! thesis A §6.2 (20th-order, unity DC gain, Q1.15 taps).
//!
//! `y(n) = Σ_{k=0}^{N−1} b_k·x(n−k)` computed as the FMAC does:
//! * taps b_k and samples x are Q1.15 (`i16`);
//! * each product is Q2.30; the FMAC drops its 8 LSBs (`(x·b) >> 8`, arithmetic shift
//!   = truncation towards −∞) and adds it to a 26-bit q4.22 accumulator;
//! * the accumulator is modular: partial sums outside [−8, 8) wrap (the hardware
//!   sets the SAT flag but does not saturate), which is harmless if later terms undo
//!   it — so the result is independent of the accumulation order;
//! * the optional output gain `2^R`, R ∈ 0..=7 (0 to 42 dB) is applied to the
//!   accumulator, then bits \[22:7\] form the Q1.15 output (`>> 7`, truncation);
//! * with CLIPEN the output saturates to \[−1, 1 − 2^-15\], otherwise the unused high
//!   bits are dropped (wraps).
//!
//! Capacity: N taps, 1 ≤ N ≤ 127 (the FMAC's 256-word memory holds 2N + 1 words),
//! checked at compile time.

/// Largest FIR length the FMAC supports.
pub const MAX_TAPS: usize = 127;

/// Bits of the FMAC accumulator (q4.22).
const ACC_BITS: u32 = 26;

/// FIR configuration: Q1.15 taps `b_0 … b_{N−1}` and the FMAC output options.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FmacFir<const N: usize> {
    /// Coefficients b_k, Q1.15; `b_0` multiplies the newest sample.
    pub taps: [i16; N],
    /// Output gain R: the accumulator is multiplied by 2^R (0..=7; larger values are
    /// treated as 7).
    pub gain_shift: u8,
    /// CLIPEN: saturate the output instead of truncating it.
    pub clip: bool,
}

/// Ring buffer of the last N input samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FirState<const N: usize> {
    samples: [i16; N],
    /// Index of the newest sample.
    head: usize,
}

impl<const N: usize> Default for FirState<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> FirState<N> {
    /// All-zero history.
    pub const fn new() -> Self {
        Self {
            samples: [0; N],
            head: 0,
        }
    }
}

/// Keeps the low 26 bits of `x`, sign-extended: the q4.22 accumulator's modular
/// arithmetic. (`<<` discards bits by definition; no overflow can occur.)
const fn wrap_acc(x: i32) -> i32 {
    (x << (32 - ACC_BITS)) >> (32 - ACC_BITS)
}

/// One output sample y(n) = Σ_k b_k·x(n−k) (Q1.15) computed as the FMAC does, from the
/// taps and the input history newest first (`history` yields x(n), x(n−1), …): the pairs
/// run to the shorter of the two, so a short history counts as cleared (zero) samples.
/// `gain_shift` is the output gain R (2^R, 0..=7; larger values are treated as 7) and
/// `clip` is CLIPEN. [`FmacFir::process`] runs this on its ring buffer; the code
/// generator checks its filter designs and identification against it.
pub fn output<'a>(taps: &[i16], history: impl IntoIterator<Item = &'a i16>, gain_shift: u8, clip: bool) -> i16 {
    let mut acc: i32 = 0;
    for (&b, &s) in taps.iter().zip(history) {
        // Q1.15·Q1.15 = Q2.30, |product| ≤ 2^30; drop 8 LSBs → q4.22 term,
        // |term| ≤ 2^22; acc stays within 26 bits, so neither operation can
        // saturate — the only wrap is the accumulator's own, in `wrap_acc`.
        let term = i32::from(b).saturating_mul(i32::from(s)) >> 8;
        acc = wrap_acc(acc.saturating_add(term));
    }
    // Output stage: gain 2^R, bits \[22:7\] → Q1.15, clip or truncate.
    let r = u32::from(gain_shift.min(7));
    // |acc| < 2^25, so acc·2^R < 2^32 in i64.
    let y = (i64::from(acc) << r) >> 7;
    if clip {
        y.clamp(i64::from(i16::MIN), i64::from(i16::MAX)) as i16
    } else {
        // Unused high bits dropped: keep the low 16 bits.
        y as i16
    }
}

impl<const N: usize> FmacFir<N> {
    /// A filter with output gain 1 (R = 0) and clipping on.
    pub const fn new(taps: [i16; N]) -> Self {
        const { assert!(N >= 1 && N <= MAX_TAPS, "the FMAC supports 1 to 127 taps") };
        Self {
            taps,
            gain_shift: 0,
            clip: true,
        }
    }

    /// Pushes sample `x` (Q1.15) and returns y(n) (Q1.15), bit-exact with the FMAC.
    pub fn process(&self, state: &mut FirState<N>, x: i16) -> i16 {
        const { assert!(N >= 1 && N <= MAX_TAPS, "the FMAC supports 1 to 127 taps") };
        let next = state.head.saturating_add(1);
        let head = if next >= N { 0 } else { next };
        state.head = head;
        if let Some(slot) = state.samples.get_mut(head) {
            *slot = x;
        }
        // Newest first: samples[head], samples[head−1], …, samples[0],
        // samples[N−1], …, samples[head+1].
        let (older_wrapped, newer) = match state.samples.split_at_checked(head.saturating_add(1)) {
            Some(parts) => (parts.1, parts.0),
            None => (&[][..], &state.samples[..]),
        };
        let history = newer.iter().rev().chain(older_wrapped.iter().rev());
        output(&self.taps, history, self.gain_shift, self.clip)
    }

    /// Clears the sample history.
    pub fn reset(&self, state: &mut FirState<N>) {
        *state = FirState::new();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The 21-tap identification low-pass produced by the code generator for the
    /// Fischer spec (Σ = 32768).
    const TAPS: [i16; 21] = [
        -852, -332, -177, 176, 730, 1447, 2256, 3054, 3730, 4182, 4340, 4182, 3730, 3054, 2256, 1447, 730, 176, -177,
        -332, -852,
    ];

    /// Independent reference: convolution with the FMAC's arithmetic written out on
    /// i64, with an explicit history vector (no ring buffer).
    fn reference(taps: &[i16], xs: &[i16], gain: u32, clip: bool) -> Vec<i16> {
        let mut out = vec![];
        for n in 0..xs.len() {
            let mut acc: i64 = 0;
            for (k, &b) in taps.iter().enumerate() {
                let x = if n >= k { xs[n - k] } else { 0 };
                acc += (i64::from(b) * i64::from(x)).div_euclid(256);
                // 26-bit two's complement wrap
                acc = (acc + (1 << 25)).rem_euclid(1 << 26) - (1 << 25);
            }
            let y = (acc * (1 << gain)).div_euclid(128);
            out.push(if clip {
                y.clamp(-32768, 32767) as i16
            } else {
                (y.rem_euclid(65536) - if y.rem_euclid(65536) >= 32768 { 65536 } else { 0 }) as i16
            });
        }
        out
    }

    fn run<const N: usize>(f: &FmacFir<N>, xs: &[i16]) -> Vec<i16> {
        let mut st = FirState::new();
        xs.iter().map(|&x| f.process(&mut st, x)).collect()
    }

    /// Hand values of the slice form: output gain, clipping, the 26-bit wrap and short
    /// histories.
    #[test]
    fn gain_clip_wrap_by_hand() {
        // Tap 0.5 (16384) × input 0.75 (24576) = 0.375; +6 dB ⇒ 0.75 = 24576.
        assert_eq!(output(&[16384], &[24576], 1, true), 24576);
        // +12 dB ⇒ 1.5: clipped to 32767, or truncated to 16 bits: 49152 − 65536 = −16384.
        assert_eq!(output(&[16384], &[24576], 2, true), 32767);
        assert_eq!(output(&[16384], &[24576], 2, false), -16384);
        // The accumulator wraps at 26 bits: 9 products (−1)·(−1) = +1 sum to 9 ≥ 8 ⇒
        // 9 − 16 = −7 ⇒ clipped to −1.
        assert_eq!(output(&[i16::MIN; 9], &[i16::MIN; 9], 0, true), i16::MIN);
        // A history shorter than the taps: the missing (older) samples count as zero.
        assert_eq!(output(&[16384, 16384], &[8192], 0, true), 4096);
        assert_eq!(output(&[], &[], 0, true), 0);
    }

    #[test]
    fn taps_sum_to_one() {
        assert_eq!(TAPS.iter().map(|&b| i32::from(b)).sum::<i32>(), 32768);
    }

    /// Impulse −1.0 (0x8000) → −b_k exactly: (−2^15·b) >> 8 = −128·b, >> 7 = −b.
    #[test]
    fn impulse_gives_taps() {
        let f = FmacFir::new(TAPS);
        let mut xs = vec![0i16; 30];
        xs[0] = i16::MIN;
        let y = run(&f, &xs);
        for k in 0..21 {
            assert_eq!(y[k], -TAPS[k], "tap {k}");
        }
        assert!(y[21..].iter().all(|&v| v == 0));
        // A positive impulse 0x7FFF gives b_k − 1 for b_k > 0 and b_k otherwise:
        // (2^15 − 1)·b/2^15 truncated towards −∞ — the FMAC's truncation, 1 LSB.
        xs[0] = i16::MAX;
        let y = run(&f, &xs);
        for k in 0..21 {
            let want = if TAPS[k] > 0 { TAPS[k] - 1 } else { TAPS[k] };
            assert_eq!(y[k], want, "tap {k}");
        }
    }

    /// DC in → DC out for Σb = 32768 once the window is full: exact when every
    /// product c·b_k is a multiple of 256 (no truncation), otherwise at most 1 LSB
    /// low (each of the N ≤ 127 truncations loses < 2^-22, together < 2^-15).
    #[test]
    fn dc_gain_is_one() {
        let f = FmacFir::new(TAPS);
        for c in [-32768i16, -256 * 100, 0, 256, 256 * 127] {
            let y = run(&f, &[c; 40]);
            assert!(y[20..].iter().all(|&v| v == c), "c = {c}: {:?}", &y[20..]);
        }
        for c in [-32767i16, -1234, -1, 1, 77, 12345, 32767] {
            let y = run(&f, &[c; 40]);
            assert!(y[20..].iter().all(|&v| v == c || v == c - 1), "c = {c}: {:?}", &y[20..]);
        }
    }

    proptest! {
        /// Bit-exact against the written-out reference for random taps (including
        /// sums far from 1 that wrap the accumulator), lengths, gains and both
        /// output modes.
        #[test]
        fn bit_exact(taps in proptest::collection::vec(any::<i16>(), 8),
                     xs in proptest::collection::vec(any::<i16>(), 1..60),
                     gain in 0u8..=7, clip in any::<bool>()) {
            let mut t = [0i16; 8];
            t.copy_from_slice(&taps);
            let f = FmacFir { taps: t, gain_shift: gain, clip };
            prop_assert_eq!(run(&f, &xs), reference(&taps, &xs, u32::from(gain), clip));
        }

        #[test]
        fn bit_exact_long(taps in proptest::collection::vec(-2000i16..2000, 127),
                          xs in proptest::collection::vec(any::<i16>(), 130..300)) {
            let mut t = [0i16; 127];
            t.copy_from_slice(&taps);
            let f = FmacFir::new(t);
            prop_assert_eq!(run(&f, &xs), reference(&taps, &xs, 0, true));
        }
    }

    #[test]
    fn single_tap_and_reset() {
        let f = FmacFir::new([16384i16]); // 0.5
        let mut st = FirState::new();
        assert_eq!(f.process(&mut st, 1000), 500);
        assert_eq!(f.process(&mut st, -1000), -500);
        f.reset(&mut st);
        assert_eq!(st, FirState::new());
    }
}
