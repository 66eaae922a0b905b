//! The designed (continuous) responses the sampled figures are compared with, which are
//! `design::designed_response`'s (the sampled figures themselves are
//! [`motor_sim::figures`]).

pub use codegen::design::designed_response::{designed_rise_time, designed_step};
