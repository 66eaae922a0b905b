//! A plain-text summary of a design for the terminal (`motorgen design`).

use std::fmt::Write;

use crate::Design;

/// Renders the headline constants of `d`, one per line with unit and equation.
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
        if let Some(x) = &m.flux_cross_check {
            writeln!(
                s,
                "  ψ_M cross-check: K_t → {:.5} Wb, K_e → {:.5} Wb, disagreement {:.2} %",
                x.from_torque_constant_wb, x.from_back_emf_constant_wb, x.disagreement_percent
            )?;
        }
        writeln!(
            s,
            "  f_e,max = {:.1} Hz; f_s = {} Hz ≥ 12·f_e,max = {:.0} Hz (1.1)",
            m.max_electrical_frequency_hz, d.drive.switching_frequency_hz, d.drive.min_switching_frequency_hz
        )?;
        writeln!(
            s,
            "current loop: {:?}, α = {:.3} rad/s (limit {:.0} rad/s)",
            c.method, c.bandwidth_rad_s, c.bandwidth_limit_rad_s
        )?;
        if let Some([td, tq]) = c.sampled_rise_time_s {
            writeln!(
                s,
                "  rise time 10–90 %: ln 9/α = {:.3} ms; sampled loop with 1.5·T_s delay: d {:.3} ms, q {:.3} ms{}",
                9f64.ln() / c.bandwidth_rad_s * 1e3,
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
        for (axis, g) in [("d", &c.d), ("q", &c.q)] {
            writeln!(
                s,
                "  {axis}: K_p = {:.6} V/A, K_i = {:.6} V/(A·s); K_a = {:.6}, K_b = {:.4} rad/s (5.7); R_a = {:.4} Ω",
                g.kp, g.ki, g.ka, g.kb, g.active_damping_ohm
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
            "  K_p = {}, K_i = {} (4.15); Q1.31: K̃_p = {}, K̃_i = {} (4.22)",
            o.kp, o.ki, o.kp_q31, o.ki_q31
        )?;
        writeln!(
            s,
            "  n_p/n_r = {}; lead {} samples = {:.1}° at max speed (4.23)",
            o.electrical_per_resolver, o.lead_samples, o.lead_at_max_speed_deg
        )?;
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
        for w in &d.warnings {
            writeln!(s, "warning: {w}")?;
        }
        Ok(())
    })();
    s
}
