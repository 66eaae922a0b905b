//! A plain-text summary of a design for the terminal (`motorgen design`).

use std::fmt::Write;

use crate::Design;

/// Renders the headline constants of `d`, one per line with unit and equation. The
/// design's warnings are not part of it: every command prints them once, on stderr.
pub fn summary(d: &Design) -> String {
    let mut s = String::new();
    let m = &d.motor;
    let c = &d.current_loop;
    let o = &d.angle_observer;
    let f = &d.fir;
    // Writing to a String cannot fail.
    let _ = (|| -> std::fmt::Result {
        writeln!(s, "{} ({})", d.name, d.spec_file)?;
        writeln!(s, "motor")?;
        writeln!(
            s,
            "  n_p = {}, R_s = {:.6} Ω, L_d = {:.6e} H, L_q = {:.6e} H",
            m.pole_pairs, m.phase_resistance_ohm, m.d_inductance_h, m.q_inductance_h
        )?;
        match m.flux_linkage_wb {
            Some(p) => writeln!(
                s,
                "  ψ_M = {p:.6} Wb ({})",
                m.provenance
                    .get("flux_linkage")
                    .map_or("?".into(), |o| format!("{:?}", o.source).to_lowercase())
            )?,
            None => writeln!(s, "  ψ_M unknown")?,
        }
        for x in &m.cross_checks {
            writeln!(
                s,
                "  cross-check {}: {:.5} vs {:.5}, {:.2} % apart{} ({} vs {})",
                x.quantity,
                x.a,
                x.b,
                x.disagreement_percent,
                if x.fails() { " — above 5 %" } else { "" },
                x.a_from,
                x.b_from
            )?;
        }
        writeln!(
            s,
            "  f_e,max = {:.1} Hz; f_s = {} Hz ≥ 12·f_e,max = {:.0} Hz (1.1)",
            m.max_electrical_frequency_hz, d.drive.switching_frequency_hz, d.drive.min_switching_frequency_hz
        )?;
        writeln!(
            s,
            "current loop: {:?}, α = {:.3} rad/s (guideline of thesis A §5.4.1: below {:.0} rad/s)",
            c.method, c.bandwidth_rad_s, c.bandwidth_limit_rad_s
        )?;
        if let Some([td, tq]) = c.sampled_rise_time_s {
            writeln!(
                s,
                "  rise time 10–90 %: ln 9/α = {:.3} ms; sampled loop with {:.4}·T_s delay: d {:.3} ms, q {:.3} ms{}",
                9f64.ln() / c.bandwidth_rad_s * 1e3,
                c.loop_delay_s / d.drive.sample_period_s,
                td * 1e3,
                tq * 1e3,
                if c.compensate_delay {
                    format!(
                        " (delay-compensated: α_d = {:.1}, α_q = {:.1} rad/s)",
                        c.d.bandwidth_rad_s, c.q.bandwidth_rad_s
                    )
                } else {
                    String::new()
                }
            )?;
        }
        writeln!(
            s,
            "  delay compensation: {}; floors: phase margin ≥ {}°, gain margin ≥ {} dB, overshoot ≤ {:.1} %",
            if c.compensate_delay {
                "on (default; compensate_delay = false turns it off)"
            } else {
                "off (compensate_delay = false)"
            },
            c.floors.min_phase_margin_deg,
            c.floors.min_gain_margin_db,
            c.floors.max_overshoot_pct
        )?;
        for (axis, g) in [("d", &c.d), ("q", &c.q)] {
            writeln!(
                s,
                "  {axis}: K_p = {:.6} V/A, K_i = {:.6} V/(A·s); K_a = {:.6}, K_b = {:.4} rad/s (5.7); R_a = {:.4} Ω",
                g.kp, g.ki, g.ka, g.kb, g.active_damping_ohm
            )?;
            writeln!(s, "     {}", g.sampled.describe())?;
        }
        if let (Some(t), Some(du)) = (d.drive.dead_time_s, d.drive.dead_time_voltage_error_v) {
            writeln!(
                s,
                "  dead time {:.0} ns: voltage error U_dc·t_d·f_s = {du:.3} V ({:.2} % of V_max = U_dc/√3), a disturbance the integral action removes",
                t * 1e9,
                100.0 * du / (d.drive.dc_link_voltage_v / 3f64.sqrt())
            )?;
        }
        if let Some(k) = c.feedforward.iq_per_nm {
            writeln!(s, "  torque → i_q: {k:.5} A/(N·m) (2.34)")?;
        }
        writeln!(
            s,
            "angle observer: {:?}, ω_n = {} rad/s, ζ = {}",
            o.error, o.natural_frequency_rad_s, o.damping
        )?;
        writeln!(
            s,
            "  K_p = 2ζω_n = {} 1/s, K_i = ω_n² = {} 1/s² (4.15); Q1.31: K̃_p = {}, K̃_i = {} (4.22){}",
            o.gains.kp,
            o.gains.ki,
            o.gains.kp_q31,
            o.gains.ki_q31,
            if o.gains.signal_gain == 1.0 {
                String::new()
            } else {
                format!(
                    ", divided by the resolver signal's {:.4} of full scale (4.10)",
                    o.gains.signal_gain
                )
            }
        )?;
        writeln!(
            s,
            "  drive's largest acceleration {:.1} rad/s² ({:.0} rpm/s; {}): type-2 lag {:.2}° electrical (allowed {}°)",
            d.drive.max_acceleration_rad_s2,
            d.drive.max_acceleration_rad_s2 * 30.0 / std::f64::consts::PI,
            d.drive.max_acceleration_rule.describe(),
            o.lag_at_max_acceleration_deg,
            o.max_lag_deg
        )?;
        writeln!(
            s,
            "  n_p/n_r = {}; lead {} samples = {:.1}° at max speed (4.23)",
            o.electrical_per_resolver, o.lead_samples, o.lead_at_max_speed_deg
        )?;
        let b = &d.per_unit.bases;
        let opt = |x: Option<f64>, unit: &str| x.map_or("—".to_string(), |x| format!("{x:.6} {unit}"));
        writeln!(
            s,
            "per-unit bases (thesis B App. A): V_base = {:.6} V, I_base = {}, Z_base = {}, ω_base = {}",
            b.voltage_v,
            opt(b.current_a, "A"),
            opt(b.impedance_ohm, "Ω"),
            opt(b.angular_frequency_rad_s, "rad/s")
        )?;
        if !d.per_unit.missing.is_empty() {
            writeln!(s, "  not determined: {}", d.per_unit.missing.join("; "))?;
        }
        writeln!(s, "scalings")?;
        for (name, sc) in [
            ("phase current", &d.scaling.phase_current),
            ("phase voltage", &d.scaling.phase_voltage),
            ("DC link", &d.scaling.dc_link_voltage),
            ("angle", &d.scaling.angle),
            ("speed", &d.scaling.speed),
            ("observer error", &d.scaling.observer_error),
        ] {
            writeln!(
                s,
                "  {name:<15} A = {:.6} {}, {}, resolution {:.3e} {}",
                sc.full_scale, sc.unit, sc.q_format, sc.resolution, sc.unit
            )?;
        }
        writeln!(
            s,
            "FIR: order {}, group delay {} samples = {:.3} ms, ripple {:.2e}, attenuation {:.1} dB (Q1.15)",
            f.order,
            f.group_delay_samples,
            f.group_delay_s * 1e3,
            f.pass_ripple_quantised,
            f.stop_attenuation_db_quantised
        )?;
        writeln!(s, "  taps_q15 = {:?}", f.taps_q15)?;
        writeln!(
            s,
            "ADC: settle {} τ (7.4){}",
            d.adc.settling_multiple,
            d.adc.sample_time.as_ref().map_or(String::new(), |t| format!(
                ", SMP code {} = {} cycles",
                t.smp_code, t.cycles
            ))
        )?;
        if let Some(fw) = &d.field_weakening {
            writeln!(
                s,
                "field weakening: V'_max = {} V_max = {:.2} V, α_fw = {:.2} rad/s ({:?}), ω_base = {:.1} rad/s ({}), γ(ω_base) = {:.5} A/(V²·s) (2.60)",
                fw.voltage_fraction,
                fw.voltage_limit_v,
                fw.bandwidth_rad_s,
                fw.bandwidth_rule,
                fw.base_speed_rad_s,
                match (d.per_unit.bases.angular_frequency_rad_s, fw.corner_speed_rad_s) {
                    (Some(_), Some(w)) => format!("2π·f_n; full-current corner speed with R_s {w:.1} rad/s"),
                    (Some(_), None) => "2π·f_n".to_string(),
                    (None, _) => "full-current corner speed at V'_max, R_s included".to_string(),
                },
                fw.gain_at_base_speed
            )?;
            writeln!(
                s,
                "  {:.2} A ≤ i_d^ref ≤ i_d,MTPA (2.56); MTPA at I_max: i_d = {:.2} A, mode-B i_q = {:.2} A (2.57); {}-point MTPA table, max interpolation error {:.4} A (3.10)",
                fw.id_min_a,
                fw.id_mtpa_at_current_max_a,
                fw.iq_mode_b_at_mtpa_a,
                fw.mtpa.iq_a.len(),
                fw.mtpa.max_interpolation_error_a
            )?;
            if let Some(lm) = &fw.loss_minimisation {
                writeln!(
                    s,
                    "  loss-minimising i_d: {}×{} table (speed × i_q), max interpolation error {:.3} A (3.3)–(3.14)",
                    lm.table.speeds_rad_s.len(),
                    lm.table.iq_a.len(),
                    lm.table.max_interpolation_error_a
                )?;
            }
        }
        if let Some(se) = &d.sensorless {
            writeln!(
                s,
                "sensorless: ρ = {:.1} rad/s ({:?}, ≤ α_c/10 = {:.1}), γ1 = ρ² = {:.1} 1/s², γ2 = 2ρ = {:.1} 1/s (4.7)",
                se.rho_rad_s, se.rho_rule, se.rho_max_rad_s, se.gamma1, se.gamma2
            )?;
            if let Some(inj) = &se.injection {
                writeln!(
                    s,
                    "  injection: ω_e = {:.0} rad/s (range {:.0} … {:.0}, 4.34), V_e = {:.2} V (≥ {:.2} V, 4.35), K_e = {:.3} A (4.19)",
                    inj.frequency_rad_s,
                    inj.frequency_min_rad_s,
                    inj.frequency_max_rad_s,
                    inj.voltage_v,
                    inj.voltage_min_v,
                    inj.gain_ke_a
                )?;
            }
            if let Some(why) = &se.no_injection {
                writeln!(s, "  no signal injection — {why}")?;
            }
            writeln!(
                s,
                "  ω_min1 = {:.1} (4.59), ω_min2 = {:.1} (4.69, i_d = {:.2} A at I_base), ω_ls = {:.1}, ω_hs = {:.1} rad/s (Table 4.1)",
                se.omega_min1_rad_s, se.omega_min2_rad_s, se.id_at_base_current_a, se.omega_ls_rad_s, se.omega_hs_rad_s
            )?;
        }
        if let Some(b) = &d.board {
            s.push_str(&board(b, d));
        }
        Ok(())
    })();
    s
}

/// The board section of a design on a board, for the terminal (`motorgen design --board`,
/// `check --board`): what the board measures against what the motor needs, the trip levels
/// the image uses and which limit set each, the CAN bit timing.
pub fn board(b: &crate::design::BoardOut, d: &Design) -> String {
    let mut s = String::new();
    let rpm = 30.0 / std::f64::consts::PI;
    let t = &b.trips;
    let c = &b.can_timing;
    let _ = (|| -> std::fmt::Result {
        writeln!(s, "board: {} ({})", b.board.name, b.board.file)?;
        writeln!(
            s,
            "  sensing: current ±{:.1} A (the motor's peak current {:.1} A), DC link up to {:.1} V (U_dc = {} V)",
            b.current_full_scale_a, d.motor.peak_current_a, b.dc_link_full_scale_v, d.drive.dc_link_voltage_v
        )?;
        writeln!(
            s,
            "  trips the image uses (the lower of the motor's limit and the board's ceiling):"
        )?;
        writeln!(
            s,
            "    over-current {:.2} A, {}",
            t.over_current_a.value,
            t.over_current_a.describe("A", 1.0)
        )?;
        writeln!(
            s,
            "    over-voltage {:.2} V, {}",
            t.over_voltage_v.value,
            t.over_voltage_v.describe("V", 1.0)
        )?;
        writeln!(
            s,
            "    over-speed {:.0} rpm, {}",
            t.over_speed_rad_s.value * rpm,
            t.over_speed_rad_s.describe("rpm", rpm)
        )?;
        writeln!(
            s,
            "  CAN {} bit/s from {} MHz: prescaler {}, {} quanta (1 + {} + {}), sample point {:.2} %, SJW {}, FDCAN_NBTP = {:#010x}",
            c.bit_rate,
            f64::from(c.kernel_clock_hz) / 1e6,
            c.prescaler,
            c.tq_per_bit,
            c.tseg1,
            c.tseg2,
            c.sample_point * 100.0,
            c.sjw,
            c.nbtp
        )?;
        writeln!(
            s,
            "  dead time {} ns; conversions {:.2} µs after the trigger",
            b.dead_time_ns,
            b.conversion_time_s * 1e6
        )?;
        if b.resolver_skew_s == 0.0 {
            writeln!(
                s,
                "  resolver SIN and COS held together {:.2} µs after the trigger, where the excitation peaks (TIM3 shift {} ticks)",
                b.resolver_sample_instant_s * 1e6,
                b.excitation_shift_ticks
            )?;
        } else {
            writeln!(
                s,
                "  resolver COS held {:.2} µs after SIN, the excitation peaking at their mean {:.2} µs (TIM3 shift {} ticks): the angle ripples by ±{:.2}° electrical at twice the resolver angle at the over-speed trip ({:.0} rpm)",
                b.resolver_skew_s * 1e6,
                b.resolver_sample_instant_s * 1e6,
                b.excitation_shift_ticks,
                b.resolver_skew_ripple_rad.to_degrees(),
                b.trips.over_speed_rad_s.value * 30.0 / std::f64::consts::PI
            )?;
        }
        let l = &b.duty_limit;
        let why = match l.bound {
            crate::design::duty_limit::DutyBound::DeadTime => format!(
                "every compare value at least the {:.0} ns dead time ({} ticks) from either end, so each edge's dead interval stays in its own period (in-line sensing reads the current whatever the switches do)",
                l.dead_time_s * 1e9,
                l.min_pulse
            ),
            crate::design::duty_limit::DutyBound::Settling => format!(
                "low-side shunts: ±{:.2} µs of low-side pulse about the carrier maximum, dead time {:.0} ns + settling {:.0} ns before the first current rank samples",
                l.half_window_s * 1e6,
                l.dead_time_s * 1e9,
                l.settling_time_s * 1e9
            ),
            crate::design::duty_limit::DutyBound::SamplingEnd => format!(
                "low-side shunts: ±{:.2} µs of low-side pulse about the carrier maximum, until the last current rank's sampling ends",
                l.half_window_s * 1e6
            ),
        };
        writeln!(
            s,
            "  maximum duty {:.4} (compare {}): {why}; usable voltage {:.2} V = {:.1} % of U_dc/√3",
            l.max_duty,
            l.max_compare,
            d.modulation.usable_phase_voltage_v,
            l.usable_voltage_fraction * 100.0
        )?;
        Ok(())
    })();
    s
}
