//! The design core's integration tests, one binary (STYLE.md: each file under `tests/`
//! would otherwise be a binary of its own, linking every dependency again).

mod board_files;
mod commissioning;
mod contract;
mod firmware_limits;
mod fuzz;
mod motor_data;
mod spec;
