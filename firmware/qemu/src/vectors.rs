//! The test vectors: a deterministic input generator ([`XorShift32`]), a hash of
//! output bit patterns ([`Fnv1a64`]) and one run per control-core function
//! ([`run_all`]).
//!
//! Bit-exactness: the integer and fixed-point paths are exact by construction. The
//! `f32` paths use only IEEE-754 operations that are correctly rounded on both sides
//! (add, sub, mul, div, `libm::sqrtf`, int↔float conversions, comparisons); Rust
//! never contracts `a·b + c` into an FMA, and the Cortex-M4F FPU runs with
//! flush-to-zero and default-NaN off after reset, like the host's SSE unit. The one
//! thing IEEE-754 leaves to the platform is the sign and payload of a NaN, so
//! [`Fnv1a64::f32`] hashes every NaN as the canonical quiet NaN `0x7fc0_0000`;
//! every other `f32`, including the sign of zero, is hashed as its exact bit
//! pattern. One exception: Rust leaves the sign of a zero returned by
//! `f32::min`/`f32::max` for operands ±0 to the platform, and
//! [`motor_control::pi::limit_voltage`] with `DAxisPriority` produces such zeros
//! for u_q, so `pi_d_axis_priority` hashes u_q with ±0 merged
//! ([`Fnv1a64::f32_unsigned_zero`]); all its other outputs are exact.

use core::fmt;

use fixed::types::I1F31;
use motor_control::adc::{CurrentSense, DcLinkSense, MeasuredPhases};
use motor_control::angle::ResolverToElectrical;
use motor_control::ato::{AtoConfig, AtoState, ObserverError, ResolverSample};
use motor_control::estimator::{EstimatorConfig, EstimatorInput, EstimatorState, InjectionConfig, ResettingConfig};
use motor_control::feedforward::{FeedForwardConfig, dc_link_gain, effective_dc_link};
use motor_control::fir::{FirState, FmacFir};
use motor_control::modulation::{compare_values, thpwm};
use motor_control::pi::{CurrentPiConfig, CurrentPiState, PiConfig, VoltageLimit};
use motor_control::step::{AdcSample, ControllerConfig, ControllerState, Demand};
use motor_control::torque::{MTPA_POINTS, TorqueConfig, TorqueParameters, TorqueState};
use motor_control::transforms::{AlphaBeta, Dq, Uvw, clarke, clarke_uv, inverse_clarke, inverse_park, park};
use motor_control::trig::{SoftTrig, atan2_q31, sin_cos_q31};

/// Seed of the input generator (any non-zero value; fixed so both sides agree).
pub const SEED: u32 = 0x2545_f491;

/// Samples per function.
pub const SAMPLES: u32 = 4096;

/// Number of [`Summary`] lines [`run_all`] produces.
pub const FUNCTIONS: usize = 16;

/// Marsaglia's xorshift32 (shifts 13, 17, 5): a deterministic, platform-independent
/// stream of `u32`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct XorShift32 {
    state: u32,
}

impl XorShift32 {
    /// A generator started at `seed` (0, the generator's fixed point, is replaced by
    /// [`SEED`]).
    pub const fn new(seed: u32) -> Self {
        Self {
            state: if seed == 0 { SEED } else { seed },
        }
    }

    /// The next 32 random bits.
    pub fn next_u32(&mut self) -> u32 {
        let mut x = self.state;
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        self.state = x;
        x
    }

    /// The next 32 random bits as a signed integer (uniform over all of `i32`).
    pub fn next_i32(&mut self) -> i32 {
        self.next_u32() as i32
    }

    /// Uniform in `[0, 1)` with 24 random bits (exact in `f32`).
    pub fn unit_f32(&mut self) -> f32 {
        // 2^-24; `(x >> 8) as f32` is exact (< 2^24), so is the product.
        const LSB: f32 = 1.0 / 16_777_216.0;
        (self.next_u32() >> 8) as f32 * LSB
    }

    /// Uniform in `[lo, hi)` (one rounding in `lo + (hi − lo)·u`).
    pub fn range_f32(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.unit_f32()
    }

    /// Uniform `u16` in `[lo, lo + span)` (`span` > 0; a multiply-shift, no bias
    /// worth caring about for test vectors).
    pub fn range_u16(&mut self, lo: u16, span: u16) -> u16 {
        let offset = (u64::from(self.next_u32()) * u64::from(span)) >> 32;
        lo.wrapping_add(offset as u16)
    }

    /// A Q1.15 sample covering the whole `i16` range.
    pub fn next_i16(&mut self) -> i16 {
        (self.next_u32() >> 16) as u16 as i16
    }
}

/// 64-bit FNV-1a over the little-endian bytes of each value written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Fnv1a64 {
    hash: u64,
}

impl Default for Fnv1a64 {
    fn default() -> Self {
        Self::new()
    }
}

impl Fnv1a64 {
    /// FNV-1a 64-bit offset basis.
    pub const OFFSET_BASIS: u64 = 0xcbf2_9ce4_8422_2325;
    /// FNV-1a 64-bit prime.
    pub const PRIME: u64 = 0x0000_0100_0000_01b3;

    /// The empty hash.
    pub const fn new() -> Self {
        Self {
            hash: Self::OFFSET_BASIS,
        }
    }

    /// Folds in `bytes`.
    pub fn bytes(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.hash = (self.hash ^ u64::from(b)).wrapping_mul(Self::PRIME);
        }
    }

    /// Folds in a `u32` (little endian).
    pub fn u32(&mut self, x: u32) {
        self.bytes(&x.to_le_bytes());
    }

    /// Folds in an `i32`'s two's-complement bits.
    pub fn i32(&mut self, x: i32) {
        self.u32(x as u32);
    }

    /// Folds in an `i16`'s two's-complement bits (two bytes).
    pub fn i16(&mut self, x: i16) {
        self.bytes(&x.to_le_bytes());
    }

    /// Folds in a `u16` (two bytes).
    pub fn u16(&mut self, x: u16) {
        self.bytes(&x.to_le_bytes());
    }

    /// Folds in a `bool` (one byte, 0 or 1).
    pub fn bool(&mut self, x: bool) {
        self.bytes(&[u8::from(x)]);
    }

    /// Folds in an `f32`'s bit pattern; every NaN as the canonical quiet NaN
    /// `0x7fc0_0000` (NaN sign and payload are platform-specific, see the module
    /// docs).
    pub fn f32(&mut self, x: f32) {
        self.u32(if x.is_nan() { 0x7fc0_0000 } else { x.to_bits() });
    }

    /// Folds in an `f32` like [`Self::f32`], but ±0 both as `+0.0`: for results of
    /// `f32::min`/`f32::max`, which may return either zero when the operands are
    /// ±0 (Rust leaves the choice to the platform; x86 and Arm differ).
    pub fn f32_unsigned_zero(&mut self, x: f32) {
        self.f32(if x == 0.0 { 0.0 } else { x });
    }

    /// Folds in both components of a dq vector.
    pub fn dq(&mut self, x: Dq) {
        self.f32(x.d);
        self.f32(x.q);
    }

    /// Folds in both components of an αβ vector.
    pub fn alpha_beta(&mut self, x: AlphaBeta) {
        self.f32(x.alpha);
        self.f32(x.beta);
    }

    /// Folds in three phase values.
    pub fn uvw(&mut self, x: Uvw) {
        self.f32(x.u);
        self.f32(x.v);
        self.f32(x.w);
    }

    /// The hash so far.
    pub const fn finish(&self) -> u64 {
        self.hash
    }
}

/// Result of one function's vectors: prints as `<name> <count> <hash as 16 hex
/// digits>`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Summary {
    /// Function (or variant) name, without spaces.
    pub name: &'static str,
    /// Number of samples run.
    pub count: u32,
    /// FNV-1a 64 of all outputs' bit patterns.
    pub hash: u64,
}

impl fmt::Display for Summary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} {} {:016x}", self.name, self.count, self.hash)
    }
}

/// Runs `body` [`SAMPLES`] times with one generator (seeded from [`SEED`] and the
/// name, so each function's inputs are independent of the others) and one hash.
fn run(name: &'static str, mut body: impl FnMut(&mut XorShift32, &mut Fnv1a64)) -> Summary {
    let mut name_hash = Fnv1a64::new();
    name_hash.bytes(name.as_bytes());
    let mut rng = XorShift32::new(SEED ^ (name_hash.finish() as u32));
    let mut hash = Fnv1a64::new();
    for _ in 0..SAMPLES {
        body(&mut rng, &mut hash);
    }
    Summary {
        name,
        count: SAMPLES,
        hash: hash.finish(),
    }
}

/// A phase current in ±500 A.
fn amps(rng: &mut XorShift32) -> f32 {
    rng.range_f32(-500.0, 500.0)
}

/// A voltage in ±400 V.
fn volts(rng: &mut XorShift32) -> f32 {
    rng.range_f32(-400.0, 400.0)
}

/// A resolver sample at the angle `theta` with envelope amplitude 0.9 and ±2^-12
/// noise per channel.
fn resolver_at(rng: &mut XorShift32, theta: i32) -> ResolverSample {
    let sc = sin_cos_q31(theta);
    // 0.9 in Q1.31, rounded.
    const AMPLITUDE: i64 = 1_932_735_283;
    let mut channel = |x: i32| {
        let scaled = (i64::from(x) * AMPLITUDE + (1 << 30)) >> 31;
        let noise = i64::from(rng.next_i32() >> 12);
        (scaled + noise).clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32
    };
    ResolverSample {
        sin: channel(sc.sin),
        cos: channel(sc.cos),
    }
}

/// ATO run: the true angle accelerates from rest with a constant per-sample speed
/// increment plus random jitter; hashes θ̂, ω̂ and ẽ every sample.
fn ato(name: &'static str, config: AtoConfig) -> Summary {
    let mut state = AtoState::new();
    let mut trig = SoftTrig;
    let (mut theta, mut omega) = (0i32, 0i32);
    run(name, move |rng, h| {
        // Up to ~0.04 turn per sample at the end of the ramp (≈ 780 Hz at 20 kHz).
        omega = omega.wrapping_add(41_000 + (rng.next_i32() >> 20));
        theta = theta.wrapping_add(omega);
        let sample = resolver_at(rng, theta);
        let out = config.process(&mut state, &mut trig, sample);
        h.i32(out);
        h.i32(state.omega);
        h.i32(state.error);
    })
}

/// Current controllers with active damping (thesis B IMC design: `k_p = α·L`,
/// `R_a = α·L − R`, `k_i = α·(R + R_a)`) for L = 0.393 mH, R = 0.126 Ω, α = 2000 rad/s.
fn current_pi(limit: VoltageLimit) -> CurrentPiConfig {
    let axis = PiConfig {
        kp: 0.786,
        ki: 1572.0,
        anti_windup: 1.0 / 0.786,
        active_damping: 0.66,
        reference_filter: 0.1,
    };
    CurrentPiConfig {
        d: axis,
        q: axis,
        limit,
    }
}

/// PI run: random references, measurements, feed-forward and voltage-circle radius
/// (the circle limit is often active); every 512th measurement is NaN
/// to exercise the reset path. Hashes ū_dq and both axes' state.
fn pi(name: &'static str, config: CurrentPiConfig) -> Summary {
    let mut state = CurrentPiState::default();
    let mut n = 0u32;
    run(name, move |rng, h| {
        let reference = Dq {
            d: rng.range_f32(-100.0, 0.0),
            q: amps(rng),
        };
        let mut measured = Dq {
            d: reference.d + rng.range_f32(-50.0, 50.0),
            q: reference.q + rng.range_f32(-50.0, 50.0),
        };
        if n % 512 == 511 {
            measured.q = f32::NAN;
        }
        n = n.wrapping_add(1);
        let feed_forward = Dq {
            d: rng.range_f32(-100.0, 100.0),
            q: rng.range_f32(-100.0, 300.0),
        };
        let v_max = rng.range_f32(20.0, 400.0);
        let u = config.process(
            &mut state,
            reference,
            measured,
            feed_forward,
            v_max,
            5.0e-5,
            &mut SoftTrig,
        );
        h.f32(u.d);
        if config.limit == VoltageLimit::DAxisPriority {
            // DAxisPriority clamps u_q with `f32::max`/`f32::min` against ±q_max,
            // which is ±0 whenever u_d is on the circle: the sign of a zero u_q is
            // then platform-specific (x86 and the M4F differ; see
            // [`Fnv1a64::f32_unsigned_zero`]). The integrators are unaffected
            // (ū − v is the same for either zero) and hashed exactly.
            h.f32_unsigned_zero(u.q);
        } else {
            h.f32(u.q);
        }
        h.f32(state.d.integral);
        h.f32(state.d.reference);
        h.f32(state.q.integral);
        h.f32(state.q.reference);
    })
}

/// 21-tap (order 20) Hann-windowed sinc low-pass, cut-off 0.1·f_s, quantised to
/// Q1.15 with Σb = 32768 (unity DC gain).
const FIR_TAPS: [i16; 21] = [
    0, -16, -117, -288, -349, 0, 991, 2592, 4430, 5906, 6470, 5906, 4430, 2592, 991, 0, -349, -288, -117, -16, 0,
];

/// The torque stage of the `torque_stage` vector and of [`controller`]: thesis B motor
/// (Table B.2) with L_d = 0.40 mH so that ψ_M = 0.104 Wb < L_d·I_max and the MTPV path
/// runs; the MTPA table is a monotone stand-in (the vectors test bit-exactness, not the
/// curve).
fn torque_stage() -> TorqueConfig {
    let mut mtpa_id = [0.0f32; MTPA_POINTS];
    for (k, x) in mtpa_id.iter_mut().enumerate() {
        *x = -4.0 * (k * k) as f32 / 16.0;
    }
    TorqueConfig::from_parameters(&TorqueParameters {
        sample_period: 1e-4,
        pole_pairs: 2,
        psi_m: 0.104,
        ld: 0.40e-3,
        lq: 0.56e-3,
        bandwidth: 147.0,
        base_speed: 1256.6,
        voltage_fraction: 0.9,
        current_max: 316.8,
        mtpa_torque_max: 120.0,
        mtpa_id,
    })
}

/// Controller for [`step`]: Fischer TI085-like motor (4 pole pairs, L = 0.393 mH,
/// ψ_M = 0.058 Wb), f_s = 20 kHz, 12-bit current ADC at 0.25 A/LSB, DC link
/// 0.2 V/LSB, trig-identity observer with ω_n = 2000 rad/s, ζ = 1.
fn controller() -> ControllerConfig {
    ControllerConfig {
        sample_period: 5.0e-5,
        // π·f_s/2^31 = π·20000/2^31.
        speed_per_lsb: 2.925_836_2e-5,
        current_sense: CurrentSense {
            offset: [2048, 2047, 2049],
            amps_per_lsb: [0.25, 0.25, -0.25],
            phases: MeasuredPhases::Three,
        },
        dc_link_sense: DcLinkSense {
            offset: 0,
            volts_per_lsb: 0.2,
        },
        observer: AtoConfig {
            // K_p/(f_s·π) = 4000/(20000·π) and K_i/(f_s²·π) = 4·10⁶/(4·10⁸·π), Q1.31.
            kp: I1F31::from_bits(136_713_055),
            ki: I1F31::from_bits(6_835_653),
            error: ObserverError::TrigIdentity,
        },
        angle: ResolverToElectrical {
            motor_pole_pairs: 4,
            resolver_pole_pairs: 1,
            offset: 0x1234_5678,
        },
        angle_lead: 3 << 15,
        current_loop: current_pi(VoltageLimit::Proportional),
        feed_forward: FeedForwardConfig {
            ld: 0.393e-3,
            lq: 0.393e-3,
            psi_m: 0.058,
        },
        dc_link_min: 432.0,
        voltage_margin: 0.95,
        pwm_period: 4250,
        max_duty: 1.0,
        torque: torque_stage(),
    }
}

/// Hashes all fields of a step output.
fn hash_step(h: &mut Fnv1a64, out: &motor_control::StepOutput) {
    for d in out.duties {
        h.f32(d);
    }
    for c in out.compare {
        h.u16(c);
    }
    h.i32(out.theta_r);
    h.i32(out.omega_r);
    h.i32(out.theta_e);
    h.f32(out.omega_e);
    h.dq(out.i_dq);
    h.dq(out.u_dq);
    h.alpha_beta(out.u_alpha_beta);
    h.f32(out.u_dc);
    h.bool(out.dc_link_low);
}

/// Runs every function's vectors, in a fixed order.
pub fn run_all() -> [Summary; FUNCTIONS] {
    [
        run("clarke", |rng, h| {
            let x = Uvw {
                u: amps(rng),
                v: amps(rng),
                w: amps(rng),
            };
            h.alpha_beta(clarke(x));
        }),
        run("clarke_uv", |rng, h| {
            let (u, v) = (amps(rng), amps(rng));
            h.alpha_beta(clarke_uv(u, v));
        }),
        run("park", |rng, h| {
            let x = AlphaBeta {
                alpha: amps(rng),
                beta: amps(rng),
            };
            let sc = sin_cos_q31(rng.next_i32()).to_f32();
            h.dq(park(x, sc));
        }),
        run("inverse_park_clarke", |rng, h| {
            let x = Dq {
                d: volts(rng),
                q: volts(rng),
            };
            let sc = sin_cos_q31(rng.next_i32()).to_f32();
            let ab = inverse_park(x, sc);
            h.alpha_beta(ab);
            h.uvw(inverse_clarke(ab));
        }),
        run("sin_cos_q31", |rng, h| {
            let sc = sin_cos_q31(rng.next_i32());
            h.i32(sc.sin);
            h.i32(sc.cos);
        }),
        run("atan2_q31", |rng, h| {
            // Full-range operands, then a point on the 0.9 circle.
            let (y, x) = (rng.next_i32(), rng.next_i32());
            h.i32(atan2_q31(y, x));
            let on_circle = resolver_at(rng, x);
            h.i32(atan2_q31(on_circle.sin, on_circle.cos));
        }),
        ato(
            "ato_trig_identity",
            AtoConfig {
                // K_p/(f_s·π), K_i/(f_s²·π) for ω_n = 2000 rad/s, ζ = 1, f_s = 20 kHz.
                kp: I1F31::from_bits(136_713_055),
                ki: I1F31::from_bits(6_835_653),
                error: ObserverError::TrigIdentity,
            },
        ),
        ato(
            "ato_atan2",
            AtoConfig {
                // The same loop with π-times larger gains: K_p/f_s, K_i/f_s².
                kp: I1F31::from_bits(429_496_730),
                ki: I1F31::from_bits(21_474_836),
                error: ObserverError::Atan2,
            },
        ),
        pi("pi_proportional", current_pi(VoltageLimit::Proportional)),
        pi("pi_d_axis_priority", current_pi(VoltageLimit::DAxisPriority)),
        run("thpwm", |rng, h| {
            // |u_αβ| up to ~1.8·U_dc/√3: past the linear limit U_dc/√3 the duties
            // saturate; below 432 V the modulator uses U_dc,min.
            let u_dc = rng.range_f32(300.0, 800.0);
            let u = AlphaBeta {
                alpha: rng.range_f32(-0.75, 0.75) * u_dc,
                beta: rng.range_f32(-0.75, 0.75) * u_dc,
            };
            let eff = effective_dc_link(u_dc, 432.0);
            let duties = thpwm(u, eff, dc_link_gain(u_dc, 432.0), &mut SoftTrig);
            for d in duties {
                h.f32(d);
            }
            for c in compare_values(duties, 4250) {
                h.u16(c);
            }
        }),
        {
            let fir = FmacFir::new(FIR_TAPS);
            let mut state = FirState::new();
            run("fmac_fir", move |rng, h| h.i16(fir.process(&mut state, rng.next_i16())))
        },
        {
            // Output gain 2^3 without clipping: exercises the FMAC's wrap-around.
            let fir = FmacFir {
                taps: FIR_TAPS,
                gain_shift: 3,
                clip: false,
            };
            let mut state = FirState::new();
            run("fmac_fir_gain8_wrap", move |rng, h| {
                h.i16(fir.process(&mut state, rng.next_i16()))
            })
        },
        {
            let config = controller();
            let mut state = ControllerState::new();
            let mut trig = SoftTrig;
            let (mut theta, mut omega, mut n) = (0i32, 0i32, 0u32);
            run("step", move |rng, h| {
                omega = omega.wrapping_add(20_000 + (rng.next_i32() >> 21));
                theta = theta.wrapping_add(omega);
                let sample = AdcSample {
                    phase_currents: [
                        rng.range_u16(1848, 400),
                        rng.range_u16(1848, 400),
                        rng.range_u16(1848, 400),
                    ],
                    resolver: resolver_at(rng, theta),
                    // 400 V to 640 V: below and above dc_link_min.
                    dc_link: rng.range_u16(2000, 1200),
                };
                // A phase of 1024 samples per demand kind.
                let demand = match (n / 1024) % 5 {
                    4 => Demand::Torque(rng.range_f32(-150.0, 150.0)),
                    0 => Demand::Current {
                        id: -10.0,
                        iq: rng.range_f32(0.0, 60.0),
                        feed_forward: true,
                    },
                    1 => Demand::VoltageDq(Dq {
                        d: volts(rng),
                        q: volts(rng),
                    }),
                    2 => Demand::VoltageAlphaBeta(AlphaBeta {
                        alpha: volts(rng),
                        beta: volts(rng),
                    }),
                    _ => {
                        if n % 2 == 0 {
                            Demand::Off
                        } else {
                            Demand::Current {
                                id: 0.0,
                                iq: amps(rng),
                                feed_forward: false,
                            }
                        }
                    }
                };
                n = n.wrapping_add(1);
                let out = config.process(&mut state, &mut trig, &sample, demand);
                hash_step(h, &out);
            })
        },
        {
            // Thesis B motor with L_d = 0.40 mH (ψ_M < L_d·I_max: the MTPV path runs too),
            // α_fw = 147 rad/s, V'_max = 0.9·V_max, I_max = 1.4 pu.
            let config = torque_stage();
            let mut state = TorqueState::new();
            let mut trig = SoftTrig;
            run("torque_stage", move |rng, h| {
                state.voltage = Dq {
                    d: rng.range_f32(-200.0, 200.0),
                    q: rng.range_f32(-200.0, 200.0),
                };
                let torque = rng.range_f32(-150.0, 150.0);
                let omega = rng.range_f32(-4000.0, 4000.0);
                let v_max = rng.range_f32(150.0, 200.0);
                let i = config.process(&mut state, &mut trig, torque, omega, v_max);
                // i_d^ref and |i_q^ref| pass through f32::min/max (±0 left to the platform).
                h.f32_unsigned_zero(i.d);
                h.f32_unsigned_zero(i.q);
                h.f32_unsigned_zero(state.id_ref);
                h.f32_unsigned_zero(state.iq_cut);
            })
        },
        {
            let config = EstimatorConfig {
                sample_period: 1e-4,
                rho: 125.7,
                rs: 7.9e-3,
                ld: 0.23e-3,
                lq: 0.56e-3,
                psi_m: 0.104,
                resetting: Some(ResettingConfig {
                    lower: 125.7,
                    upper: 251.4,
                    speed_max: 2513.0,
                }),
                injection: Some(InjectionConfig {
                    amplitude: 28.0,
                    frequency: 3141.6,
                    gain: 1.5,
                    highpass: 18.85,
                    lowpass: 628.5,
                    delay: 2.5,
                    low_speed: 246.0,
                    high_speed: 492.0,
                }),
            };
            let mut state = EstimatorState::default();
            let mut trig = SoftTrig;
            run("estimator", move |rng, h| {
                let input = EstimatorInput {
                    current: Dq {
                        d: amps(rng),
                        q: amps(rng),
                    },
                    voltage: Dq {
                        d: rng.range_f32(-200.0, 200.0),
                        q: rng.range_f32(-200.0, 200.0),
                    },
                    reference: Dq {
                        d: amps(rng),
                        q: amps(rng),
                    },
                };
                let out = config.process(&mut state, &mut trig, input);
                h.i32(out.theta);
                h.f32(out.omega);
                h.i32(out.omega_increment);
                h.dq(out.injection);
                h.f32(out.iq_limit);
                h.f32(out.gamma0);
                h.f32(out.speed_error);
                h.f32(out.blend);
                h.f32(out.error);
            })
        },
    ]
}
