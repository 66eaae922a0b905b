//! Deterministic control-core test vectors shared by the emulated Cortex-M4F binary
//! (`src/main.rs`, run under QEMU) and the host (`tests/qemu.rs`), so the two can be
//! compared bit for bit.
//!
//! [`vectors::run_all`] drives a fixed set of [`motor_control`] functions with inputs
//! from a seeded xorshift32 generator and folds every output's bit pattern into a
//! 64-bit FNV-1a hash; each [`vectors::Summary`] prints as `<name> <count> <hash>`.
#![no_std]
#![forbid(unsafe_code)]

#[cfg(not(target_os = "none"))]
pub mod host;
pub mod icount;
pub mod motor_config;
pub mod vectors;
