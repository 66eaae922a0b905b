//! `motor-commission`'s integration tests, one binary.

mod can_dbc;
mod fuzz;
