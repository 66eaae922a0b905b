//! `motor-commission`'s integration tests, one binary.

mod can_dbc;
mod commission;
mod frequency_response;
mod fuzz;
mod identify;
