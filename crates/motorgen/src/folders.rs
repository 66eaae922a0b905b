//! Where the motors and boards folders are: `--motors-dir`/`--boards-dir`, else the
//! environment (`MOTORGEN_MOTORS_DIR`, `MOTORGEN_BOARDS_DIR`), else `motors/` in the
//! working directory and `boards/` beside the motors folder. Never the source tree the
//! binary was built from: an installed `motorgen` run elsewhere says what to give
//! instead (issue 31).

use std::path::{Path, PathBuf};

use crate::exit::{Exit, Failure};

/// The environment variable naming the motors folder.
pub const MOTORS_ENV: &str = "MOTORGEN_MOTORS_DIR";
/// The environment variable naming the boards folder.
pub const BOARDS_ENV: &str = "MOTORGEN_BOARDS_DIR";

/// The motors folder: `given` (the option, or its environment variable, as clap read
/// them), else `motors/` in the working directory; a usage error when neither exists.
pub fn motors(given: Option<PathBuf>) -> Result<PathBuf, Failure> {
    if let Some(dir) = given {
        return Ok(dir);
    }
    let here = PathBuf::from("motors");
    if here.is_dir() {
        return Ok(here);
    }
    Err(Failure::new(
        Exit::Usage,
        format!(
            "error: no motors folder: --motors-dir is not given, {MOTORS_ENV} is not set and there is no motors/ in the working directory {}\n  accepted: --motors-dir DIR, {MOTORS_ENV}=DIR, or run motorgen in the folder that holds motors/",
            working_directory()
        ),
    ))
}

/// The boards folder: `given`, else `boards/` beside the motors folder `motors`, else
/// `boards/` in the working directory; a usage error when none exists.
pub fn boards(given: Option<PathBuf>, motors: &Path) -> Result<PathBuf, Failure> {
    if let Some(dir) = given {
        return Ok(dir);
    }
    let beside = motors.join("..").join("boards");
    if beside.is_dir() {
        return Ok(beside);
    }
    let here = PathBuf::from("boards");
    if here.is_dir() {
        return Ok(here);
    }
    Err(Failure::new(
        Exit::Usage,
        format!(
            "error: no boards folder: --boards-dir is not given, {BOARDS_ENV} is not set and there is no boards/ beside {} or in the working directory {}\n  accepted: --boards-dir DIR, {BOARDS_ENV}=DIR, or a boards/ folder beside the motors folder",
            motors.display(),
            working_directory()
        ),
    ))
}

fn working_directory() -> String {
    std::env::current_dir().map_or_else(|e| format!("(unknown: {e})"), |d| d.display().to_string())
}
