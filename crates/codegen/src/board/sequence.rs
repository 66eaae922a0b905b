//! Which converter samples which analog input, in which rank, for how long.
//!
//! The firmware triggers ADC1 and ADC2 together from TIM1 and converts up to four
//! injected ranks each (ADC_JSQR.JL = 0…3, RM0440 §21.7.16). The plan puts every input
//! on a converter that has it as a channel and prefers, in this order: the resolver's
//! SIN and COS on different converters, at the same rank where that delays no current's
//! sample (`align_resolver`; with the lock-step below they are then held at the same
//! instant — held Δt apart, the observer reads the angle of (sin(θ − ε), cos(θ + ε)),
//! ε = ω_r·Δt/2, and the excitation's envelope at two phases: `board::resolver_skew`);
//! the phase currents in the first ranks (a rank-k conversion samples k−1 conversions after the
//! trigger, and low-side shunts carry the current only inside the low-side pulse); equal
//! sequence lengths, ADC1 the longer one (the control interrupt runs on ADC1's end of
//! sequence and then waits for ADC2).
//!
//! The two converters then run in lock-step (`lock_step`): ES0430 (STM32G47x errata,
//! ADC) — two ADCs converting concurrently disturb each other unless they share the
//! clock and the hardware trigger (the image's ADC1/ADC2 do: HCLK/4, TIM1_TRGO2) and
//! every sampling phase of one starts and ends with the other's; moteus (an STM32G474
//! drive, `fw/bldc_servo.cc`) cites ES0430 §2.7.11 for this and converts one rank on
//! every ADC. So both sequences get the same number of ranks (the shorter padded with a
//! repeat of its last channel whose code the firmware ignores) and each rank the longer
//! of the two sampling times (longer sampling settles an input at least as well,
//! DS12288 Table 67).

use serde::Serialize;

use super::chip::{self, Chip};
use super::raw::RawBoard;
use super::sampling::{self, Sampling};
use super::{ADC_CLOCK_HZ, PinUse, Signal};
use crate::spec::{Param, ResolveContext};

/// ADC1 or ADC2.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Converter {
    /// ADC1.
    Adc1,
    /// ADC2.
    Adc2,
}

impl Converter {
    /// Peripheral name in the chip data.
    pub fn name(self) -> &'static str {
        match self {
            Converter::Adc1 => "ADC1",
            Converter::Adc2 => "ADC2",
        }
    }
}

/// One injected rank.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AdcSlot {
    /// The input.
    pub signal: Signal,
    /// Its pin.
    pub pin: &'static str,
    /// Channel number (ADC_JSQR.JSQx).
    pub channel: u8,
    /// The sampling chosen for it: the shortest that settles it, or the longer one the
    /// other converter's rank needs (`lock_step`).
    pub sampling: Sampling,
    /// A repeat that only keeps the sequences the same length (`lock_step`): its
    /// conversion is discarded (signal code `u8::MAX` in the firmware's tables).
    pub padding: bool,
}

/// ES0430's lock-step (module documentation): the shorter sequence padded with repeats
/// of its last rank, each rank's sampling the longer of the two converters'.
pub fn lock_step(mut seqs: [Vec<AdcSlot>; 2]) -> [Vec<AdcSlot>; 2] {
    let n = seqs[0].len().max(seqs[1].len());
    for q in &mut seqs {
        while let Some(last) = q.last().filter(|_| q.len() < n) {
            let pad = AdcSlot {
                padding: true,
                ..last.clone()
            };
            q.push(pad);
        }
    }
    for k in 0..n {
        let [a, b] = &mut seqs;
        let (Some(x), Some(y)) = (a.get_mut(k), b.get_mut(k)) else {
            continue;
        };
        if x.sampling.cycles < y.sampling.cycles {
            x.sampling.smp_code = y.sampling.smp_code;
            x.sampling.cycles = y.sampling.cycles;
        } else {
            y.sampling.smp_code = x.sampling.smp_code;
            y.sampling.cycles = x.sampling.cycles;
        }
    }
    seqs
}

/// The lock-stepped sequences with SIN and COS at the same rank where the plan put them
/// on different converters at different ranks: the inputs after the resolver on the
/// converter where it comes first (never a current: they come before it) are moved
/// ahead of it, one at a time, until the ranks match — kept only if no phase current is
/// then held later (a slow input moved into a current's rank would lengthen that rank's
/// sampling through the lock-step, and a low-side shunt's window with it).
fn align_resolver(seqs: [Vec<AdcSlot>; 2]) -> [Vec<AdcSlot>; 2] {
    let locked = lock_step(seqs.clone());
    let rank = |q: &[AdcSlot]| {
        q.iter()
            .position(|s| matches!(s.signal, Signal::ResolverSin | Signal::ResolverCos))
    };
    let (Some(a), Some(b)) = (rank(&seqs[0]), rank(&seqs[1])) else {
        return locked;
    };
    let (early, mut at, target) = if a < b { (0, a, b) } else { (1, b, a) };
    let mut moved = seqs;
    let q = &mut moved[early];
    while at < target && at + 1 < q.len() {
        let next = q.remove(at + 1);
        q.insert(at, next);
        at += 1;
    }
    if at != target {
        return locked;
    }
    let aligned = lock_step(moved);
    let currents = [Signal::CurrentU, Signal::CurrentV, Signal::CurrentW];
    let later = currents.iter().any(|&c| {
        match (
            super::hold_instant(&aligned, c, ADC_CLOCK_HZ),
            super::hold_instant(&locked, c, ADC_CLOCK_HZ),
        ) {
            (Some(x), Some(y)) => x > y,
            _ => false,
        }
    });
    if later { locked } else { aligned }
}

/// Rank order within one converter: currents, resolver, DC link.
fn priority(s: Signal) -> u8 {
    match s {
        Signal::CurrentU => 0,
        Signal::CurrentV => 1,
        Signal::CurrentW => 2,
        Signal::ResolverSin | Signal::ResolverCos => 3,
        _ => 4,
    }
}

/// Cost of one assignment (lower is better), see the module documentation.
fn cost(seqs: &[Vec<Signal>; 2]) -> u32 {
    let same_resolver = seqs
        .iter()
        .any(|s| s.contains(&Signal::ResolverSin) && s.contains(&Signal::ResolverCos));
    let current_ranks: u32 = seqs
        .iter()
        .flat_map(|s| {
            s.iter()
                .enumerate()
                .filter(|(_, x)| priority(**x) <= 2)
                .map(|(k, _)| k as u32)
        })
        .sum();
    let (n1, n2) = (seqs[0].len() as u32, seqs[1].len() as u32);
    u32::from(same_resolver) * 1000 + current_ranks * 10 + n1.abs_diff(n2) + u32::from(n2 > n1)
}

/// The sequences of ADC1 and ADC2, or located errors.
pub(super) fn plan(
    cx: &mut ResolveContext<'_>,
    raw: &RawBoard,
    chip: &'static Chip,
    pins: &[PinUse],
    [r_current, r_dc, r_resolver]: [&Param; 3],
    fixed: Option<&(u8, Param)>,
) -> Option<[Vec<AdcSlot>; 2]> {
    let _ = raw;
    let analog: Vec<&PinUse> = pins
        .iter()
        .filter(|p| matches!(p.signal.need(), super::Need::Analog))
        .collect();
    let conv = [Converter::Adc1, Converter::Adc2];
    let mut best: Option<(u32, [Vec<Signal>; 2])> = None;
    for mask in 0u32..(1 << analog.len()) {
        let mut seqs: [Vec<Signal>; 2] = [Vec::new(), Vec::new()];
        let feasible = analog.iter().enumerate().all(|(k, p)| {
            let c = ((mask >> k) & 1) as usize;
            seqs[c].push(p.signal);
            chip.adc_channel(p.pin, conv[c].name()).is_some()
        });
        if !feasible || seqs.iter().any(|s| s.len() > 4) {
            continue;
        }
        for s in &mut seqs {
            s.sort_by_key(|x| (priority(*x), *x));
        }
        let c = cost(&seqs);
        if best.as_ref().is_none_or(|(b, _)| c < *b) {
            best = Some((c, seqs));
        }
    }
    let Some((_, seqs)) = best else {
        let p = analog.first()?;
        cx.err(
            p.span.clone(),
            &format!("pins.{}", p.signal.key()),
            "the analog inputs cannot be shared out over ADC1 and ADC2 (at most four injected conversions each, ADC_JSQR.JL, RM0440 §21.7.16)",
            "analog pins that ADC1 and ADC2 both convert (ADC12 inputs), at most four on a converter",
        );
        return None;
    };
    let mut out: [Vec<AdcSlot>; 2] = [Vec::new(), Vec::new()];
    let mut ok = true;
    // Inputs a board-wide `sampling_cycles` is too short for: (cycles needed, slow, message).
    let mut too_short: Vec<(f64, bool, String)> = Vec::new();
    for (c, seq) in seqs.iter().enumerate() {
        for signal in seq {
            let Some(p) = analog.iter().find(|p| p.signal == *signal) else {
                continue;
            };
            let channel = chip.adc_channel(p.pin, conv[c].name())?;
            let fast = chip::is_fast_channel(channel);
            let r = match signal {
                Signal::CurrentU | Signal::CurrentV | Signal::CurrentW => r_current,
                Signal::DcLink => r_dc,
                _ => r_resolver,
            };
            let class = if fast { "fast" } else { "slow" };
            let what = format!("{} is {}_IN{channel}, a {class} channel", p.pin, conv[c].name());
            match sampling::sampling(r.value, fast, ADC_CLOCK_HZ) {
                Ok(mut s) => {
                    if let Some((code, given)) = fixed {
                        if *code < s.smp_code {
                            too_short.push((s.cycles, !fast, format!(
                                "{} cycles is too short for `pins.{}`: {what}; {:.0} Ω needs ≥ {} cycles at {:.1} MHz (DS12288 Table 67: {:.0} ns, thesis A (7.4): {:.1} ns)",
                                given.value,
                                signal.key(),
                                r.value,
                                s.cycles,
                                ADC_CLOCK_HZ / 1e6,
                                s.table_time_s * 1e9,
                                s.settling_time_s * 1e9
                            )));
                        } else {
                            s.smp_code = *code;
                            s.cycles = given.value;
                        }
                    }
                    out[c].push(AdcSlot {
                        signal: *signal,
                        pin: p.pin,
                        channel,
                        sampling: s,
                        padding: false,
                    });
                }
                Err(e) => {
                    cx.err(
                        r.span.clone(),
                        &r.key,
                        format!("{:.0} Ω is too high for `pins.{}`: {what}, which settles at most {:.0} Ω even at 640.5 cycles (DS12288 Table 67)", r.value, signal.key(), e.max_ohm),
                        format!("a source resistance up to {:.0} Ω (buffer the signal), or a fast channel (IN1–IN5)", e.max_ohm),
                    );
                    ok = false;
                }
            }
        }
    }
    // One error, for the input that needs the most (a slow one first on a tie).
    if let (Some((code, given)), Some((cycles, _, problem))) = (
        fixed,
        too_short.iter().max_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1))),
    ) {
        let _ = code;
        cx.err(
            given.span.clone(),
            "sensing.sampling_cycles",
            problem.clone(),
            format!("sampling_cycles = {cycles} or more, or leave the key out to let each input get the shortest time that settles it"),
        );
        ok = false;
    }
    ok.then(|| align_resolver(out))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn slot(signal: Signal, channel: u8, smp_code: u8, cycles: f64) -> AdcSlot {
        AdcSlot {
            signal,
            pin: "PA0",
            channel,
            sampling: Sampling {
                fast: true,
                source_resistance_ohm: 100.0,
                table_time_s: 0.0,
                settling_time_s: 0.0,
                smp_code,
                cycles,
            },
            padding: false,
        }
    }

    /// Three ranks against two (a board measuring two phase currents): ADC2 gets a
    /// third rank repeating its last channel, marked padding; rank by rank both take the
    /// longer sampling (codes of RM0440 §21.7.6: 3 = 24.5, 6 = 247.5
    /// cycles).
    #[test]
    fn shorter_sequence_padded_and_longer_sampling_shared() {
        let a = vec![
            slot(Signal::CurrentU, 1, 3, 24.5),
            slot(Signal::ResolverSin, 2, 3, 24.5),
            slot(Signal::DcLink, 12, 6, 247.5),
        ];
        let b = vec![slot(Signal::CurrentV, 3, 3, 24.5), slot(Signal::ResolverCos, 4, 0, 2.5)];
        let [a, b] = lock_step([a, b]);
        assert_eq!(b.len(), 3);
        assert!(b[2].padding && !b[1].padding && !a.iter().any(|s| s.padding));
        assert_eq!((b[2].channel, b[2].signal), (4, Signal::ResolverCos));
        let cycles = |q: &[AdcSlot]| q.iter().map(|s| s.sampling.cycles).collect::<Vec<_>>();
        assert_eq!(cycles(&a), [24.5, 24.5, 247.5]);
        assert_eq!(cycles(&b), [24.5, 24.5, 247.5]);
        assert_eq!(b[2].sampling.smp_code, 6);
    }

    /// The reference board's plan, ADC1 [u, SIN, DC link], ADC2 [v, w, COS], all 24.5
    /// cycles: the DC link moves ahead of SIN, both resolver ranks third; the currents'
    /// ranks unchanged.
    #[test]
    fn resolver_aligned_where_no_current_waits() {
        let [a, b] = align_resolver([
            vec![
                slot(Signal::CurrentU, 1, 3, 24.5),
                slot(Signal::ResolverSin, 2, 3, 24.5),
                slot(Signal::DcLink, 3, 3, 24.5),
            ],
            vec![
                slot(Signal::CurrentV, 3, 3, 24.5),
                slot(Signal::CurrentW, 17, 3, 24.5),
                slot(Signal::ResolverCos, 4, 3, 24.5),
            ],
        ]);
        let signals = |q: &[AdcSlot]| q.iter().map(|s| s.signal).collect::<Vec<_>>();
        assert_eq!(signals(&a), [Signal::CurrentU, Signal::DcLink, Signal::ResolverSin]);
        assert_eq!(signals(&b), [Signal::CurrentV, Signal::CurrentW, Signal::ResolverCos]);
    }

    /// The NUCLEO's plan, ADC1 [w, SIN, DC link at 247.5 cycles], ADC2 [u, v, COS]: moving
    /// the DC link into rank 2 would sample current v for 247.5 cycles (the lock-step), so
    /// the plan stays as it was.
    #[test]
    fn resolver_left_apart_where_a_current_would_wait() {
        let plan = [
            vec![
                slot(Signal::CurrentW, 6, 3, 24.5),
                slot(Signal::ResolverSin, 11, 3, 24.5),
                slot(Signal::DcLink, 2, 6, 247.5),
            ],
            vec![
                slot(Signal::CurrentU, 1, 3, 24.5),
                slot(Signal::CurrentV, 7, 3, 24.5),
                slot(Signal::ResolverCos, 17, 6, 247.5),
            ],
        ];
        let [a, _] = align_resolver(plan.clone());
        assert_eq!(
            a.iter().map(|s| s.signal).collect::<Vec<_>>(),
            [Signal::CurrentW, Signal::ResolverSin, Signal::DcLink]
        );
        assert_eq!(align_resolver(plan.clone()), lock_step(plan));
    }
}
