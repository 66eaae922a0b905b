//! The commissioning group's pre-flight rotation rate against hand calculations from the
//! spec and board files' own numbers (not from the design).

use codegen::design::Design;

/// `motors/<motor>.toml` designed on `boards/<board>.toml`.
fn design(motor: &str, board: &str) -> Design {
    let spec_file = format!("motors/{motor}.toml");
    let board_file = format!("boards/{board}.toml");
    let spec = motor_test_support::read(&spec_file);
    let board_text = motor_test_support::read(&board_file);
    codegen::design_with_board(&spec_file, &spec, &board_file, &board_text)
        .unwrap_or_else(|e| panic!("{motor} on {board}: {e}"))
}

/// A generated constant of the `commissioning` group.
fn constant(d: &Design, name: &str) -> f64 {
    let groups = codegen::constants::constants(d);
    codegen::constants::group_named(&groups, "commissioning")
        .and_then(|g| g.number(name))
        .unwrap_or_else(|| panic!("no constant {name}"))
}

/// chalmers-hev50 (thesis B Tables B.1/B.2: R = 7.9 mΩ, ψ_M = 104 mWb, I_n = 160 A rms,
/// f_s = 10 kHz) on the 400 A board (trip 400 A): I_p = ¼·min(√2·160, 400) = 56.569 A,
/// V = R·I_p = 0.44689 V. At one turn per second a following rotor would induce
/// ψ_M·2π = 0.6535 V > V, so the rate is ω = V/(2ψ_M) = 2.14852 rad/s (the turn in
/// 2.9244 s) and the step 2^32·T_s·ω/2π = 146 865.1 → 146 865 LSB.
///
/// fischer-ti085 (thesis A Tables 1.1/1.2: R = 0.126 Ω, K_t = 0.492 N·m/A rms, 4 pole
/// pairs, I_n = 22.6 A rms, f_s = 20 kHz) on the reference board (trip 100 A): I_p =
/// ¼·√2·22.6 = 7.990 A, ½·V = 0.5034 V; ψ_M = K_t/(1.5·√2·n_p) = 0.05798 Wb induces
/// 0.3643 V at one turn per second, below it: one turn per second, 2^32·T_s = 214 748.4
/// → 214 748 LSB.
#[test]
fn the_preflight_rotation_slows_where_the_back_emf_would_exceed_half_its_voltage() {
    let chalmers = design("chalmers-hev50", "motorgen-reference-400a");
    assert_eq!(constant(&chalmers, "PREFLIGHT_ROTATION_STEP"), 146_865.0);
    assert_eq!(
        constant(&chalmers, "ROTATION_STEP"),
        429_497.0,
        "§6.4's own rotation keeps 1 turn/s"
    );
    let fischer = design("fischer-ti085", "motorgen-reference");
    assert_eq!(constant(&fischer, "PREFLIGHT_ROTATION_STEP"), 214_748.0);
    assert_eq!(constant(&fischer, "ROTATION_STEP"), 214_748.0);
}
