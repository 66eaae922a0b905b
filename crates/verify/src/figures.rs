//! The designed (continuous) responses the sampled figures are compared with, which are
//! `design::current_loop::continuous`'s (the sampled figures themselves are
//! [`motor_sim::figures`]).

pub use codegen::design::current_loop::continuous::{designed_rise_time, designed_step};
