//! Bit-level model of the STM32G474 FMAC running the filter (RM0440 §17.3.7–17.3.8).

/// Bit-exact model of what the FMAC computes for one FIR output sample
/// (0 dB gain, CLIPEN set), in q1.15 [LSB of 2^−15].
///
/// `window` holds the most recent input samples, newest last; `taps_q15[k]`
/// multiplies the input k samples old: y[n] = Σ_k b[k]·x[n − k]. If the slices
/// differ in length only the newest min(len) samples are used (older ones count
/// as zero, like a cleared input buffer). See [`fmac_fir_output_with`].
pub fn fmac_fir_output(taps_q15: &[i16], window: &[i16]) -> i16 {
    fmac_fir_output_with(taps_q15, window, 0, true)
}

/// Bit-exact FMAC FIR output with output gain 2^`gain_shift` (FMAC_PARAM.R,
/// 0–7 ⇒ 0–42 dB; larger values are taken as 7) and clipping on or off, in q1.15 [LSB of 2^−15].
///
/// Assumed arithmetic (RM0440 §17.3.7 fixes the formats; the product alignment
/// and the truncation are this model's assumptions):
/// 1. each product b·x of two q1.15 values is a q2.30 integer; it enters the
///    26-bit q4.22 accumulator shifted right by 8 bits, arithmetic shift, i.e.
///    truncated towards −∞: p = (b·x) >> 8;
/// 2. the accumulator wraps at 26 bits (two's complement, range −8 to +8 − 2^−22),
///    without saturation;
/// 3. the output is the accumulator shifted left by the gain, then right by 7
///    (q4.22 → q1.15, truncated towards −∞); with CLIPEN it is saturated to
///    [−32768, 32767], without it only its 16 low bits are kept.
///
/// Error bound (no saturation, no wrapping): with y = Σ b·x·2^−30 exact, each
/// product loses [0, 255]·2^−30 and the final shift [0, 127]·2^−22, so at 0 dB
/// y − out·2^−15 ∈ [0, N·255·2^−30 + 127·2^−22], i.e. out is below the exact
/// value by less than N·255/2^15 + 127/128 LSB (1.16 LSB for N = 21).
pub fn fmac_fir_output_with(taps_q15: &[i16], window: &[i16], gain_shift: u32, clip: bool) -> i16 {
    const ACC_BITS: u32 = 26;
    let wrap = |v: i64| (v << (64 - ACC_BITS)) >> (64 - ACC_BITS);
    let n = taps_q15.len().min(window.len());
    let acc = taps_q15
        .iter()
        .zip(window.iter().rev())
        .take(n)
        .fold(0_i64, |acc, (&b, &x)| wrap(acc + ((i64::from(b) * i64::from(x)) >> 8)));
    let out = (acc << gain_shift.min(7)) >> 7;
    if clip {
        // Clamped into the i16 range, so the narrowing is exact.
        out.clamp(i64::from(i16::MIN), i64::from(i16::MAX)) as i16
    } else {
        // Truncation to the low 16 bits (intended wrap).
        out as i16
    }
}
