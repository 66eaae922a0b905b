//! The `motorgen` command line run as a user runs it (the built binary, its exit codes,
//! stdout and stderr, the files it writes), one test binary.

mod can_round_trip;
mod cli;
mod commission;
mod common;
mod contract;
mod firmware_image;
mod identify;
mod output;
mod report;
mod writeback;
