//! `[gate_driver]`: the inputs the board's gate driver presents to TIM1's outputs, from
//! its part (the parts table, [`super::parts`]) or stated fact by fact, and what the
//! firmware derives from them: TIM1's output polarities (CCxP/CCxNP) and idle levels
//! (OISx/OISxN), and the level each gate pin is driven to when the outputs are off.
//!
//! RM0440, advanced-control timers: with CCxE = CCxNE = 1 and MOE = 1 the pins carry
//! OCxREF (dead time on the rising edges) XOR CCxP and its complement XOR CCxNP; with
//! MOE = 0 and OSSI = 1 they carry OISx and OISxN (Table "Output control bits for
//! complementary tim_ocx and tim_ocxn channels with break feature"). So an inverted
//! (active-low) input needs its polarity bit set — "active" becomes low — and its idle
//! bit set — "off" becomes high. TIMx_CR2.OISx/OISxN are frozen by BDTR's LOCK level 1
//! (RM0440 TIMx_BDTR LOCK\[1:0\] = 01), so they are written before the BDTR write.

use std::ops::Range;

use serde::Serialize;
use serde_spanned::Spanned;

use super::parts::{self, GateDriverPart};
use super::raw::{InputLogic, InputPull, RawGateDriver};
use crate::spec::{Provenance, ResolveContext};
use crate::units::Kind;

/// One driver input as the board presents it to an MCU pin.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct GateInput {
    /// How it turns its switch on.
    pub logic: InputLogic,
    /// What holds it while undriven.
    pub pull: InputPull,
}

/// The resolved gate driver.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GateDriver {
    /// The part named by the board, if any.
    pub part: Option<String>,
    /// The inputs TIM1_CH1..3 drive.
    pub high_side: GateInput,
    /// The inputs TIM1_CH1N..3N drive.
    pub low_side: GateInput,
    /// Both switches of a leg are kept off when both inputs ask for on.
    pub interlock: bool,
    /// Dead time the driver inserts itself \[s\] (`None`: none relied on).
    pub dead_time_s: Option<f64>,
}

/// A located warning: span, key, problem.
pub type Warning = (Range<usize>, String, String);

/// TIMx_CCER polarity bits (RM0440 TIMx_CCER: CCxP at bit 4·(x−1)+1, CCxNP at
/// 4·(x−1)+3) for channels 1–3: CCxP set for an inverted high-side input, CCxNP for an
/// inverted low-side input.
pub fn ccer_polarity(d: &GateDriver) -> u32 {
    let mut v = 0;
    for ch in 0..3 {
        if d.high_side.logic == InputLogic::Inverted {
            v |= 1 << (4 * ch + 1);
        }
        if d.low_side.logic == InputLogic::Inverted {
            v |= 1 << (4 * ch + 3);
        }
    }
    v
}

/// TIMx_CR2 idle levels (RM0440 TIMx_CR2: OISx at bit 8 + 2·(x−1), OISxN at 9 + 2·(x−1))
/// for channels 1–3: each input's off level, so MOE = 0 with OSSI = 1 switches every
/// switch off.
pub fn cr2_idle(d: &GateDriver) -> u32 {
    let mut v = 0;
    for ch in 0..3 {
        if parts::off_level(d.high_side.logic) {
            v |= 1 << (8 + 2 * ch);
        }
        if parts::off_level(d.low_side.logic) {
            v |= 1 << (9 + 2 * ch);
        }
    }
    v
}

/// The level each gate pin is driven to with the outputs off (u/v/w high, u/v/w low):
/// 1 for an inverted input, 0 for an in-phase one.
pub fn off_levels(d: &GateDriver) -> [u8; 6] {
    let h = u8::from(parts::off_level(d.high_side.logic));
    let l = u8::from(parts::off_level(d.low_side.logic));
    [h, h, h, l, l, l]
}

fn logic_name(l: InputLogic) -> &'static str {
    match l {
        InputLogic::InPhase => "in_phase",
        InputLogic::Inverted => "inverted",
    }
}

fn pull_name(p: InputPull) -> &'static str {
    match p {
        InputPull::Down => "down",
        InputPull::Up => "up",
        InputPull::None => "none",
    }
}

/// A stated fact, or the part's; a warning when both exist and differ.
fn fact<T: PartialEq + Copy>(
    stated: Option<&Spanned<T>>,
    from_part: Option<(T, &'static str, &'static str)>,
    part_span: &Range<usize>,
    key: &str,
    name: fn(T) -> String,
    warnings: &mut Vec<Warning>,
) -> Option<(T, Range<usize>)> {
    match (stated, from_part) {
        (Some(s), Some((p, part, source))) => {
            let v = *s.get_ref();
            if v != p {
                warnings.push((
                    s.span(),
                    key.to_string(),
                    format!(
                        "the board states {} but its part {part} has {} ({source}); the stated value is used — check the schematic (an inverter between the MCU and the driver would explain it)",
                        name(v),
                        name(p)
                    ),
                ));
            }
            Some((v, s.span()))
        }
        (Some(s), None) => Some((*s.get_ref(), s.span())),
        (None, Some((p, _, _))) => Some((p, part_span.clone())),
        (None, None) => None,
    }
}

/// Resolves `[gate_driver]` (`section` is its span for "missing key" errors).
pub(super) fn resolve(
    cx: &mut ResolveContext<'_>,
    raw: &Spanned<RawGateDriver>,
    spans: &mut Vec<(String, Range<usize>)>,
    warnings: &mut Vec<Warning>,
) -> Option<GateDriver> {
    let g = raw.get_ref();
    let part: Option<&'static GateDriverPart> = match &g.part {
        None => None,
        Some(name) => {
            spans.push(("gate_driver.part".into(), name.span()));
            match parts::gate_driver(name.get_ref()) {
                Some(p) => Some(p),
                None => {
                    cx.err(
                        name.span(),
                        "gate_driver.part",
                        format!("\"{}\" is not in the parts table", name.get_ref()),
                        format!(
                            "one of {} (codegen/src/board/parts.rs, each fact with its datasheet), or no `part` and the facts stated: high_side_input, low_side_input (\"in_phase\" | \"inverted\"), high_side_pull, low_side_pull (\"down\" | \"up\" | \"none\"), interlock (true | false)",
                            parts::gate_driver_names()
                        ),
                    );
                    return None;
                }
            }
        }
    };
    let part_span = g.part.as_ref().map_or_else(|| raw.span(), Spanned::span);
    let ln = |l: InputLogic| logic_name(l).to_string();
    let pn = |p: InputPull| pull_name(p).to_string();
    let bn = |b: bool| b.to_string();
    let sides = [
        (
            "high_side",
            g.high_side_input.as_ref(),
            g.high_side_pull.as_ref(),
            part.map(|p| p.high_side),
        ),
        (
            "low_side",
            g.low_side_input.as_ref(),
            g.low_side_pull.as_ref(),
            part.map(|p| p.low_side),
        ),
    ];
    let mut inputs = Vec::new();
    let mut ok = true;
    for (side, logic, pull, from_part) in sides {
        let name = part.map_or("", |p| p.part);
        let logic_key = format!("gate_driver.{side}_input");
        let pull_key = format!("gate_driver.{side}_pull");
        let l = fact(
            logic,
            from_part.map(|f| (f.logic, name, f.logic_source)),
            &part_span,
            &logic_key,
            ln,
            warnings,
        );
        let p = fact(
            pull,
            from_part.map(|f| (f.pull, name, f.pull_source)),
            &part_span,
            &pull_key,
            pn,
            warnings,
        );
        let Some((l, lspan)) = l else {
            cx.err(
                raw.span(),
                &logic_key,
                format!("missing `{logic_key}`: without a part the board must state how the {side} input turns its switch on"),
                format!("{side}_input = \"in_phase\" (a high input turns the switch on) or \"inverted\" (a low input does), from the driver's datasheet; or `part` = one of {}", parts::gate_driver_names()),
            );
            ok = false;
            continue;
        };
        spans.push((logic_key.clone(), lspan));
        // An input without a stated pull and no part floats: the board must say what holds it.
        let (p, pspan) = p.unwrap_or((InputPull::None, raw.span()));
        spans.push((pull_key.clone(), pspan.clone()));
        let safe = parts::safe_pull(l);
        if p != safe {
            cx.err(
                pspan,
                &pull_key,
                format!(
                    "the {side} input is {} and held {} while nothing drives it: at reset, before the image routes its pin (RM0440 GPIO: analog mode, no pull), or with TIM1's outputs in Hi-Z, {}",
                    logic_name(l),
                    pull_name(p),
                    if p == InputPull::None {
                        "it floats and may turn its switch on"
                    } else {
                        "it turns its switch on"
                    }
                ),
                format!(
                    "{side}_pull = \"{}\" (the driver's internal bias or a resistor on the board, from the schematic)",
                    pull_name(safe)
                ),
            );
            ok = false;
        }
        inputs.push(GateInput { logic: l, pull: p });
    }
    let interlock = fact(
        g.interlock.as_ref(),
        part.map(|p| (p.interlock, p.part, p.interlock_source)),
        &part_span,
        "gate_driver.interlock",
        bn,
        warnings,
    );
    let interlock = match interlock {
        Some((v, span)) => {
            spans.push(("gate_driver.interlock".into(), span));
            v
        }
        None => {
            cx.err(
                raw.span(),
                "gate_driver.interlock",
                "missing `gate_driver.interlock`: without a part the board must state whether the driver keeps a leg's two switches off when both inputs ask for on",
                "interlock = true or false, from the driver's datasheet (truth table); or `part`",
            );
            ok = false;
            false
        }
    };
    let dead_time_s = match &g.dead_time {
        Some(v) => {
            spans.push(("gate_driver.dead_time".into(), v.span()));
            let d = cx.quantity("gate_driver.dead_time", v, Kind::Time, Provenance::Datasheet, true)?;
            if let Some(p) = part
                && p.dead_time_s.is_some_and(|pd| (pd - d.value).abs() > 1e-12)
            {
                warnings.push((
                    v.span(),
                    "gate_driver.dead_time".into(),
                    format!(
                        "the board states {} ns but its part {} has {:.0} ns ({})",
                        d.value * 1e9,
                        p.part,
                        p.dead_time_s.unwrap_or(0.0) * 1e9,
                        p.dead_time_source
                    ),
                ));
            }
            Some(d.value)
        }
        None => part.and_then(|p| p.dead_time_s),
    };
    if !ok {
        return None;
    }
    Some(GateDriver {
        part: part.map(|p| p.part.to_string()),
        high_side: inputs[0],
        low_side: inputs[1],
        interlock,
        dead_time_s,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn driver(high: InputLogic, low: InputLogic) -> GateDriver {
        let input = |logic| GateInput {
            logic,
            pull: parts::safe_pull(logic),
        };
        GateDriver {
            part: None,
            high_side: input(high),
            low_side: input(low),
            interlock: true,
            dead_time_s: None,
        }
    }

    /// By hand from RM0440's TIMx_CCER and TIMx_CR2 layouts: an L6398 (HIN in phase, LIN
    /// inverted) sets CC1NP, CC2NP, CC3NP = bits 3, 7, 11 → 0x888 and OIS1N, OIS2N, OIS3N =
    /// bits 9, 11, 13 → 0x2A00, and drives the three low-side pins high when off; an
    /// all-in-phase driver (the reference board's) sets nothing and drives all six low.
    #[test]
    fn polarities_and_idle_levels_by_hand() {
        let l6398 = driver(InputLogic::InPhase, InputLogic::Inverted);
        assert_eq!(ccer_polarity(&l6398), 0x0888);
        assert_eq!(cr2_idle(&l6398), 0x2A00);
        assert_eq!(off_levels(&l6398), [0, 0, 0, 1, 1, 1]);
        let plain = driver(InputLogic::InPhase, InputLogic::InPhase);
        assert_eq!((ccer_polarity(&plain), cr2_idle(&plain)), (0, 0));
        assert_eq!(off_levels(&plain), [0; 6]);
        // Both inverted: CC1P..CC3P = bits 1, 5, 9 (0x222) with the N bits; OIS1..OIS3N all.
        let both = driver(InputLogic::Inverted, InputLogic::Inverted);
        assert_eq!(ccer_polarity(&both), 0x0AAA);
        assert_eq!(cr2_idle(&both), 0x3F00);
    }
}
