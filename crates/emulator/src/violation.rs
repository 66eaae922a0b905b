//! Strict mode: what the image did that RM0440 forbids or that no model knows.

use std::fmt;

/// A strict-mode failure: the instruction, the register and the rule.
#[derive(Clone, Debug, PartialEq)]
pub struct Violation {
    /// Address of the instruction that made the access.
    pub pc: u32,
    /// The register (`TIM1_BDTR`) or address that was accessed.
    pub register: String,
    /// The rule, with the RM0440 (or DS12288, ARMv7-M) section that states it.
    pub rule: String,
    /// Emulated time of the access \[s\].
    pub at_s: f64,
}

impl fmt::Display for Violation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "strict mode: {} at PC {:#010x} (t = {:.3} µs): {}",
            self.register,
            self.pc,
            self.at_s * 1e6,
            self.rule
        )
    }
}

impl std::error::Error for Violation {}

/// A register access rule broken inside a model (the bus adds the PC and time).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Broken {
    /// Register name.
    pub register: String,
    /// Rule text with its source.
    pub rule: String,
}

impl Broken {
    /// `register`: `rule`.
    pub fn new(register: impl Into<String>, rule: impl Into<String>) -> Self {
        Self {
            register: register.into(),
            rule: rule.into(),
        }
    }
}
