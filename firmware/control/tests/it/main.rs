//! The control core's integration tests, one binary: the control step in closed loop
//! with the simulated drive, and the commissioning routines.

mod closed_loop;
mod commissioning;
mod common;
mod preflight;
