//! Register encodings computed from times and frequencies: TIM1 dead time, watchdog
//! prescaler and reload (the TIM1 period is the control core's
//! `motor_control::modulation::centre_aligned_period`). The functions are the control
//! core's [`motor_control::timing`], shared with the code generator, whose `motorgen
//! check` refuses at its key any value they cannot encode (host-tested there).
#![forbid(unsafe_code)]

pub use motor_control::timing::{dead_time_dtg, dtg_ticks, iwdg_for_timeout, iwdg_setting};
