//! `codegen`: a motor description (TOML) in, every tuned controller constant out.
//!
//! The library does no file I/O: [`design_source`] takes the file's name and
//! text and returns the [`Design`] or located [`Diagnostics`]. The `motorgen`
//! CLI, the firmware's build script and the proc-macros all call it, so a
//! constant cannot differ between the three paths.

pub mod constants;
pub mod design;
pub mod diagnostic;
pub mod escape;
#[cfg(feature = "identify")]
pub mod identify;
pub mod render;
#[cfg(feature = "verify")]
pub mod report;
pub mod spec;
pub mod summary;
pub mod units;
#[cfg(feature = "verify")]
pub mod verify;

pub use design::Design;
pub use diagnostic::{Diagnostic, Diagnostics, Source};

/// Parses, resolves and designs one spec. `file` is only used in messages.
pub fn design_source(file: &str, text: &str) -> Result<Design, Diagnostics> {
    let source = Source { file, text };
    let spec = spec::parse(source)?;
    design::design(&spec, source)
}
