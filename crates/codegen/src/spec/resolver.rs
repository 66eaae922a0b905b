//! `[resolver]`: resolver pole pairs and the offset θ_off of (4.5), which an identified
//! `motor.identified.resolver_offset` overrides.

use super::raw::{RawSpec, Val};
use super::resolve::ResolveContext;
use super::{Param, Provenance};

/// The resolved resolver.
#[derive(Debug, Clone, PartialEq)]
pub struct Resolver {
    /// n_r.
    pub pole_pairs: u32,
    /// θ_off \[rad\] in resolver angle (4.5), if known.
    pub offset: Option<Param>,
}

impl ResolveContext<'_> {
    pub(super) fn resolver(&mut self, raw: &RawSpec) -> Option<Resolver> {
        let r = raw.resolver.get_ref();
        let pole_pairs = self.integer(
            "resolver.pole_pairs",
            &r.pole_pairs,
            1,
            64,
            "a whole number of resolver pole pairs from 1 to 64, e.g. 1",
        );
        let ident = raw
            .motor
            .get_ref()
            .identified
            .as_ref()
            .and_then(|s| s.get_ref().resolver_offset.as_ref());
        let offset = match ident {
            Some(v) => self.angle("motor.identified.resolver_offset", v, Provenance::Identified),
            None => r
                .offset
                .as_ref()
                .and_then(|v| self.angle("resolver.offset", v, Provenance::Datasheet)),
        };
        Some(Resolver {
            pole_pairs: pole_pairs?.0 as u32,
            offset,
        })
    }

    fn angle(&mut self, key: &str, v: &Val, prov: Provenance) -> Option<Param> {
        let accepted = "an angle such as \"0.52 rad\" or \"30 deg\" (units: rad, deg, °)";
        let text = match v.get_ref() {
            toml::Value::String(s) => s.clone(),
            other => {
                self.err(
                    v.span(),
                    key,
                    format!(
                        "expected an angle string with its unit, found {} `{other}`",
                        other.type_str()
                    ),
                    accepted,
                );
                return None;
            }
        };
        let parsed = text
            .trim()
            .strip_suffix("rad")
            .map(|n| (n, 1.0))
            .or_else(|| {
                text.trim()
                    .strip_suffix("deg")
                    .map(|n| (n, std::f64::consts::PI / 180.0))
            })
            .or_else(|| text.trim().strip_suffix('°').map(|n| (n, std::f64::consts::PI / 180.0)))
            .and_then(|(n, k)| n.trim().parse::<f64>().ok().filter(|x| x.is_finite()).map(|x| x * k));
        match parsed {
            Some(value) => Some(Param {
                value,
                source: prov,
                key: key.into(),
                span: v.span(),
                note: None,
            }),
            None => {
                self.err(v.span(), key, format!("\"{text}\" is not an angle"), accepted);
                None
            }
        }
    }
}
