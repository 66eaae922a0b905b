//! ADC codes → physical values (phase currents, DC-link voltage).
//!
//! Affine scaling `x = (code − offset)·scale` per channel; the offset absorbs the
//! mid-scale bias of bipolar current sensors, the scale (which may be negative for an
//! inverting front end) the sensor and amplifier gain.

use crate::transforms::{AlphaBeta, Uvw, clarke, clarke_uv};

/// Which phase currents are measured.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum MeasuredPhases {
    /// All three; the Clarke transformation (2.7) uses all of them (a zero-sequence
    /// part is rejected).
    #[default]
    Three,
    /// Phases u and v; w follows from (2.1) `i_u + i_v + i_w = 0`.
    UV,
}

/// Phase-current sensing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CurrentSense {
    /// Code at zero current, per phase u, v, w \[LSB\].
    pub offset: [i32; 3],
    /// Current per code, per phase \[A/LSB\].
    pub amps_per_lsb: [f32; 3],
    /// Which phases enter the Clarke transformation.
    pub phases: MeasuredPhases,
}

/// DC-link voltage sensing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DcLinkSense {
    /// Code at 0 V \[LSB\].
    pub offset: i32,
    /// Voltage per code \[V/LSB\].
    pub volts_per_lsb: f32,
}

fn scale(code: u16, offset: i32, per_lsb: f32) -> f32 {
    // In i32, which the FPU's VCVT converts in one instruction (an i64 takes the software
    // `__aeabi_l2f`, some 35 instructions per channel in the control interrupt). For an
    // offset that is a code (0 … 65 535), |code − offset| < 2^16: the difference and its
    // f32 are exact; a far-off offset saturates instead of wrapping.
    i32::from(code).saturating_sub(offset) as f32 * per_lsb
}

impl CurrentSense {
    /// Phase currents \[A\] from the codes of phases u, v, w (w unused for
    /// [`MeasuredPhases::UV`], and then reported as `−i_u − i_v`).
    pub fn currents(&self, codes: [u16; 3]) -> Uvw {
        let [cu, cv, cw] = codes;
        let [ou, ov, ow] = self.offset;
        let [su, sv, sw] = self.amps_per_lsb;
        let u = scale(cu, ou, su);
        let v = scale(cv, ov, sv);
        let w = match self.phases {
            MeasuredPhases::Three => scale(cw, ow, sw),
            MeasuredPhases::UV => -u - v,
        };
        Uvw { u, v, w }
    }

    /// αβ current \[A\] (2.7), from three phases or from two with (2.1).
    pub fn alpha_beta(&self, codes: [u16; 3]) -> AlphaBeta {
        self.alpha_beta_of(self.currents(codes))
    }

    /// αβ current \[A\] (2.7) of phase currents from [`CurrentSense::currents`].
    pub fn alpha_beta_of(&self, i: Uvw) -> AlphaBeta {
        match self.phases {
            MeasuredPhases::Three => clarke(i),
            MeasuredPhases::UV => clarke_uv(i.u, i.v),
        }
    }
}

impl DcLinkSense {
    /// DC-link voltage \[V\].
    pub fn volts(&self, code: u16) -> f32 {
        scale(code, self.offset, self.volts_per_lsb)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scaling_against_f64() {
        let s = CurrentSense {
            offset: [2048, 2050, 2046],
            amps_per_lsb: [0.05, -0.05, 0.049],
            phases: MeasuredPhases::Three,
        };
        let i = s.currents([2148, 2000, 4095]);
        // (code − offset)·scale, one f32 rounding each: ≤ ε_f32·|x|.
        assert!((f64::from(i.u) - 100.0 * 0.05).abs() < 1e-6);
        assert!((f64::from(i.v) - (-50.0 * -0.05)).abs() < 1e-6);
        assert!((f64::from(i.w) - 2049.0 * 0.049).abs() < 1e-4);
        let d = DcLinkSense {
            offset: 0,
            volts_per_lsb: 0.2,
        };
        assert!((d.volts(3000) - 600.0).abs() < 1e-3);
        let two = CurrentSense {
            phases: MeasuredPhases::UV,
            ..s
        };
        let i = two.currents([2148, 2000, 0]);
        assert!((i.u + i.v + i.w).abs() < 1e-6);
    }
}
