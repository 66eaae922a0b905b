//! `motor-verify`'s integration tests, one binary.

mod bandwidth_sweep;
mod verify;
