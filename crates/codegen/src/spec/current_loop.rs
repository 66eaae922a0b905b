//! `[current_loop]`: the tuning method and its bandwidth, damping and delay-compensation choices.

use std::ops::Range;

use super::raw::{Method, RawSpec};
use super::resolve::ResolveContext;
use super::{Param, Provenance};
use crate::units::Kind;

/// The resolved current-loop request.
#[derive(Debug, Clone, PartialEq)]
pub struct CurrentLoopSpec {
    /// Tuning method.
    pub method: Method,
    /// Span of the method value.
    pub method_span: Range<usize>,
    /// Closed-loop bandwidth α [rad/s].
    pub bandwidth: Param,
    /// ζ for pole placement.
    pub damping: Option<Param>,
    /// Design each axis so that the sampled loop with its loop delay (1.5·T_s, or the board's) delivers α (the
    /// rise time ln 9/α of the first-order methods, the dominant pole pair of pole
    /// placement; see `design::current_loop::discrete`). On unless `compensate_delay = false`.
    pub compensate_delay: bool,
}

impl ResolveContext<'_> {
    pub(super) fn current_loop(&mut self, raw: &RawSpec) -> Option<CurrentLoopSpec> {
        let c = raw.current_loop.get_ref();
        let method = *c.method.get_ref();
        let bandwidth = self.quantity(
            "current_loop.bandwidth",
            &c.bandwidth,
            Kind::AngularFrequency,
            Provenance::Datasheet,
            true,
        );
        let damping = match (&c.damping, method) {
            (Some(v), Method::PolePlacement) => self.number(
                "current_loop.damping",
                v,
                0.0,
                10.0,
                "a damping ratio ζ with 0 < ζ < 10, e.g. 0.7071 (= 1/√2, thesis A §5.4.1)",
            ),
            (Some(v), _) => {
                self.err(
                    v.span(),
                    "current_loop.damping",
                    "`damping` is only used by method = \"pole_placement\"",
                    "remove `damping`, or set method = \"pole_placement\"",
                );
                None
            }
            (None, Method::PolePlacement) => {
                self.err(
                    raw.current_loop.span(),
                    "current_loop.damping",
                    "method = \"pole_placement\" needs `damping`",
                    "damping = 0.7071 (ζ = 1/√2, recommended in thesis A §5.4.1)",
                );
                None
            }
            (None, _) => None,
        };
        let compensate_delay = c.compensate_delay.as_ref().is_none_or(|v| *v.get_ref());
        Some(CurrentLoopSpec {
            method,
            method_span: c.method.span(),
            bandwidth: bandwidth?,
            damping,
            compensate_delay,
        })
    }
}
