//! Q1.15 quantisation with Σ taps = 2^15 exactly and exact symmetry.

use super::Q15_ONE;

/// Rounds symmetric taps to Q1.15 and forces Σ = 32768 keeping h[n] = h[N−1−n].
///
/// The deficit 32768 − Σ round(h·2^15) is removed one step at a time: a symmetric
/// pair moves by ±1 each (2 LSB of sum) or, for odd N, the centre tap by ±1,
/// choosing the candidate whose rounding residual points furthest in the needed
/// direction. Returns `Err(tap)` with the offending value if a tap leaves i16.
pub(super) fn quantise(taps: &[f64]) -> Result<Vec<i16>, f64> {
    let n = taps.len();
    let one = f64::from(Q15_ONE);
    let mut scaled: Vec<f64> = taps.iter().map(|h| h * one).collect();
    for i in 0..n / 2 {
        let v = 0.5 * (scaled[i] + scaled[n - 1 - i]);
        scaled[i] = v;
        scaled[n - 1 - i] = v;
    }
    if let Some(&bad) = scaled.iter().find(|v| !(v.is_finite() && v.abs() < 4.0 * one)) {
        return Err(bad / one);
    }
    // |scaled| < 2^17, so the casts are exact after rounding.
    let mut q: Vec<i64> = scaled.iter().map(|v| v.round() as i64).collect();
    let mut deficit = i64::from(Q15_ONE) - q.iter().sum::<i64>();
    let centre = (n % 2 == 1).then_some(n / 2);
    // Each step reduces |deficit| by 1 or 2; the bound only guards against a logic error.
    for _ in 0..(4 * n + 8) {
        if deficit == 0 {
            break;
        }
        let dir = deficit.signum();
        let residual = |i: usize| (scaled[i] - q[i] as f64) * dir as f64;
        let pick = if deficit.abs() == 1 {
            centre
        } else {
            (0..n / 2)
                .chain(centre)
                .max_by(|&a, &b| residual(a).total_cmp(&residual(b)))
        };
        let Some(i) = pick else { break };
        q[i] += dir;
        if Some(i) == centre {
            deficit -= dir;
        } else {
            q[n - 1 - i] += dir;
            deficit -= 2 * dir;
        }
    }
    if deficit != 0 {
        // Only reachable for an even N with an odd deficit, impossible as Σ of pairs is even.
        return Err(f64::NAN);
    }
    q.iter()
        .map(|&v| i16::try_from(v).map_err(|_| v as f64 / one))
        .collect()
}
