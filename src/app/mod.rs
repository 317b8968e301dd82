//! The commands behind the binary: each declares its options (a clap `Args` struct), turns them
//! into library calls, writes the files and prints (`<command>::run`). Kept in the library so
//! that tests drive them exactly as a user does.

// What the commands share: the chains' options, lists of degrees, and the command line's
// reading of the library's enums (clap's `ValueEnum`).
pub mod args;
pub mod bench;
pub mod cases;
pub mod design;
pub mod diagnose;
pub mod figures;
pub mod fit;
pub mod merge;
pub mod predict;
/// The fit pipeline, where the commands have always found it.
pub use crate::pipeline as run;
pub mod select_k;
pub mod simulate;
pub mod summarize;
pub mod sweep;
pub mod table1;

use std::fmt;

use crate::density::DensityError;
use crate::error::Error;
use crate::io::InputError;

/// Everything a command can fail with, printed as one line by the binary.
#[derive(Debug)]
pub enum AppError {
    Input(InputError),
    Usage(String),
    Numerical(String),
    Output(String),
}

impl fmt::Display for AppError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            AppError::Input(e) => write!(f, "{e}"),
            AppError::Usage(m) => write!(f, "{m}"),
            AppError::Numerical(m) => write!(f, "numerical failure: {m}"),
            AppError::Output(m) => write!(f, "could not write output: {m}"),
        }
    }
}

impl std::error::Error for AppError {}

impl From<InputError> for AppError {
    fn from(e: InputError) -> Self {
        AppError::Input(e)
    }
}

/// A library error as the command line says it: a setting is named by its flag.
impl From<Error> for AppError {
    fn from(e: Error) -> Self {
        match e {
            Error::Input(e) => AppError::Input(e),
            Error::Settings(e) if e.name.is_empty() => AppError::Usage(e.message),
            Error::Settings(e) => AppError::Usage(format!(
                "{}{}: {}",
                flag(&e.name),
                e.value.map(|v| format!(" {v}")).unwrap_or_default(),
                e.message
            )),
            Error::Numerical(m) => AppError::Numerical(m),
            Error::Output(m) => AppError::Output(m),
        }
    }
}

/// The plausibility check every command runs on its recordings first: its findings, one line
/// each, as the error; with `force` they are returned for the report instead.
pub fn plausible(
    problem: &crate::study::Problem,
    force: bool,
) -> Result<Vec<crate::study::plausibility::Finding>, AppError> {
    let findings = crate::study::plausibility::check(problem)?;
    if findings.is_empty() || force {
        return Ok(findings);
    }
    let lines: Vec<String> = findings.iter().map(|f| f.to_string()).collect();
    Err(AppError::Usage(format!(
        "{}
these recordings cannot be this motor as set up: check the files (or --force)",
        lines.join("\n")
    )))
}

/// The flag of a settings field: `chains` → `--chains`, `keep/draws` → `--keep/--draws`.
pub fn flag(field: &str) -> String {
    field
        .split('/')
        .map(|f| format!("--{}", f.replace('_', "-")))
        .collect::<Vec<_>>()
        .join("/")
}

impl From<DensityError> for AppError {
    fn from(e: DensityError) -> Self {
        AppError::Numerical(e.message)
    }
}

impl From<std::io::Error> for AppError {
    fn from(e: std::io::Error) -> Self {
        AppError::Output(e.to_string())
    }
}

pub use crate::io::provenance;
