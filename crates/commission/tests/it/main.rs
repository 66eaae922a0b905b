//! `motor-commission`'s integration tests, one binary.

mod can_dbc;
mod commission;
mod fuzz;
mod identify;
