//! The proc-macros' compile errors as a user sees them: every error of `motor-macros`
//! is a `compile_error!` spanned at the offending argument, and `tests/ui/*.rs` with
//! their `.stderr` files are what rustc prints for each (trybuild).
//!
//! A crate of its own so that trybuild's project depends on `motor-macros` and `fixed`
//! only (see `Cargo.toml`). Accept an intended message change with
//! `TRYBUILD=overwrite cargo test -p motor-macro-diagnostics --test ui` and review the
//! `.stderr` diff.
//!
//! May depend on: `motor-macros` and what its expansions name (`fixed`), as
//! dev-dependencies; nothing depends on it.
