//! Standard output and error without panics.
//!
//! `print!` panics when stdout cannot be written (exit 101). Here instead:
//! * a closed pipe (`motorgen design … | head -1`) ends the program quietly with exit
//!   0: the reader has all it wanted. C tools die of SIGPIPE at that point; the Rust
//!   runtime ignores SIGPIPE, so the error arrives as `BrokenPipe` and this is its
//!   quiet equivalent (ripgrep's convention);
//! * any other error (`> /dev/full`: ENOSPC) is reported on stderr and ends the program
//!   with [`EXIT_IO`].
//!
//! Messages on stderr that cannot be written are dropped: there is nowhere left to say so.

use std::fmt::Arguments;
use std::io::{self, Write};

/// Exit code of an I/O failure (output, spec or file not writable): sysexits' EX_IOERR
/// ([`crate::exit::Exit::Io`]).
pub const EXIT_IO: u8 = 74;

/// Ends the program after stdout failed with `e` (see the module doc).
fn stdout_failed(e: &io::Error) -> ! {
    if e.kind() == io::ErrorKind::BrokenPipe {
        std::process::exit(0);
    }
    let _ = writeln!(io::stderr(), "error: cannot write to standard output: {e}");
    std::process::exit(i32::from(EXIT_IO));
}

/// Writes `args` to stdout (see the module doc for failures).
pub fn stdout(args: Arguments<'_>) {
    if let Err(e) = io::stdout().lock().write_fmt(args) {
        stdout_failed(&e);
    }
}

/// Flushes stdout before the program exits (errors as for [`stdout`]).
pub fn flush() {
    if let Err(e) = io::stdout().lock().flush() {
        stdout_failed(&e);
    }
}

/// Writes `args` to stderr, dropping it if stderr fails.
pub fn stderr(args: Arguments<'_>) {
    let _ = io::stderr().lock().write_fmt(args);
}

/// A `warning: …` line on stderr.
pub fn warn(args: Arguments<'_>) {
    stderr(format_args!("warning: {args}\n"));
}

/// Standard output as a [`std::fmt::Write`] (for the library's result tables), with
/// [`stdout`]'s handling of failures (it never returns an error).
pub struct Stdout;

impl std::fmt::Write for Stdout {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        stdout(format_args!("{s}"));
        Ok(())
    }
}

/// `print!` without the panic.
macro_rules! out {
    ($($t:tt)*) => { $crate::output::stdout(format_args!($($t)*)) };
}

/// `println!` without the panic.
macro_rules! outln {
    () => { $crate::output::stdout(format_args!("\n")) };
    ($($t:tt)*) => { $crate::output::stdout(format_args!("{}\n", format_args!($($t)*))) };
}

/// `eprint!` without the panic.
macro_rules! err {
    ($($t:tt)*) => { $crate::output::stderr(format_args!($($t)*)) };
}

/// `eprintln!` without the panic.
macro_rules! errln {
    () => { $crate::output::stderr(format_args!("\n")) };
    ($($t:tt)*) => { $crate::output::stderr(format_args!("{}\n", format_args!($($t)*))) };
}

pub(crate) use {err, errln, out, outln};
