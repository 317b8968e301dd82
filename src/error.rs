//! The library's one error: input it cannot use, settings that cannot work together, a
//! numerical failure, or output it could not write. No command-line flag is named here: the
//! shell (`app`) wraps this error and says which flag a setting came from.

use std::fmt;
use std::path::{Path, PathBuf};

/// Everything a library call can fail with, displayed as one line.
#[derive(Clone, Debug, PartialEq)]
pub enum Error {
    /// A file, record or field the library cannot use (names the file, line and field).
    Input(InputError),
    /// A setting the call cannot use, or settings that cannot work together; named by the
    /// settings' field (`chains`, `keep/draws`), never by a flag.
    Settings(SettingError),
    /// A computation that failed: an integrator that gave up, a singular Hessian, no finite
    /// log density anywhere it looked.
    Numerical(String),
    /// A file that could not be written.
    Output(String),
}

impl Error {
    /// A setting `name` whose value cannot be used, and why.
    pub fn setting(name: &str, value: impl fmt::Display, message: impl Into<String>) -> Self {
        let value = value.to_string();
        Error::Settings(SettingError {
            name: name.into(),
            value: (!value.is_empty()).then_some(value),
            message: message.into(),
        })
    }

    /// A request the problem cannot answer, not about one setting (a candidate the model
    /// already has, a recording too short to diagnose).
    pub fn invalid(message: impl Into<String>) -> Self {
        Error::Settings(SettingError {
            name: String::new(),
            value: None,
            message: message.into(),
        })
    }

    pub fn numerical(message: impl fmt::Display) -> Self {
        Error::Numerical(message.to_string())
    }
}

/// The one of `all` whose name is `text`, for the library's enums' `FromStr`; otherwise a
/// settings error on `setting` that lists the names.
pub(crate) fn parse_name<T: Copy>(
    setting: &str,
    text: &str,
    all: &[T],
    name: impl Fn(&T) -> &'static str,
) -> Result<T, Error> {
    all.iter()
        .copied()
        .find(|t| name(t) == text)
        .ok_or_else(|| {
            let names: Vec<&str> = all.iter().map(name).collect();
            Error::setting(
                setting,
                text,
                format!("expected one of {}", names.join(", ")),
            )
        })
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Input(e) => write!(f, "{e}"),
            Error::Settings(e) => write!(f, "{e}"),
            Error::Numerical(m) => write!(f, "numerical failure: {m}"),
            Error::Output(m) => write!(f, "could not write output: {m}"),
        }
    }
}

impl std::error::Error for Error {}

impl From<InputError> for Error {
    fn from(e: InputError) -> Self {
        Error::Input(e)
    }
}

impl From<std::io::Error> for Error {
    fn from(e: std::io::Error) -> Self {
        Error::Output(e.to_string())
    }
}

/// A setting the library cannot use: its field name (empty when the failure is about no one
/// setting), the value it had, and what is wrong.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SettingError {
    pub name: String,
    pub value: Option<String>,
    pub message: String,
}

impl fmt::Display for SettingError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match (self.name.is_empty(), &self.value) {
            (true, _) => f.write_str(&self.message),
            (false, Some(v)) => write!(f, "{} = {v}: {}", self.name, self.message),
            (false, None) => write!(f, "{}: {}", self.name, self.message),
        }
    }
}

/// Input the tool cannot use: which file, where in it, which field, and what is wrong.
///
/// Displayed as one line, `path:line: field 'x': message`, with the parts that are unknown left
/// out, so that editors and terminals can jump to the spot.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct InputError {
    pub file: PathBuf,
    /// 1-based line number in the file.
    pub line: Option<usize>,
    /// The column, key or parameter the failure is about.
    pub field: Option<String>,
    pub message: String,
}

impl InputError {
    pub fn new(file: impl Into<PathBuf>, message: impl Into<String>) -> Self {
        Self {
            file: file.into(),
            line: None,
            field: None,
            message: message.into(),
        }
    }

    pub fn at_line(mut self, line: usize) -> Self {
        self.line = Some(line);
        self
    }

    pub fn at_line_opt(mut self, line: Option<usize>) -> Self {
        self.line = line;
        self
    }

    pub fn for_field(mut self, field: impl Into<String>) -> Self {
        self.field = Some(field.into());
        self
    }

    pub fn for_field_opt(mut self, field: Option<String>) -> Self {
        self.field = field;
        self
    }

    /// The file could not be read at all (missing, a directory, no permission).
    pub(crate) fn unreadable(file: &Path, err: &std::io::Error) -> Self {
        Self::new(file, format!("cannot read the file: {err}"))
    }
}

impl fmt::Display for InputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // Parts are joined by ": "; an error about no file in particular starts with the field or
        // the message.
        let mut parts = Vec::with_capacity(3);
        if !self.file.as_os_str().is_empty() {
            let mut location = self.file.display().to_string();
            if let Some(line) = self.line {
                location.push_str(&format!(":{line}"));
            }
            parts.push(location);
        }
        if let Some(field) = &self.field {
            parts.push(format!("field '{}'", one_line(field)));
        }
        parts.push(one_line(&self.message));
        f.write_str(&parts.join(": "))
    }
}

impl std::error::Error for InputError {}

/// Field names and messages come from user files and library errors; a newline or control byte in
/// them would break the one-line contract (and could garble a terminal), so they are escaped.
fn one_line(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        if c.is_control() {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn display_leaves_out_unknown_parts() {
        let full = InputError::new("a/b.csv", "not a number")
            .at_line(3)
            .for_field("I");
        assert_eq!(full.to_string(), "a/b.csv:3: field 'I': not a number");
        assert_eq!(
            InputError::new("x.toml", "empty").to_string(),
            "x.toml: empty"
        );
        assert_eq!(
            InputError::new("x.toml", "bad").at_line(2).to_string(),
            "x.toml:2: bad"
        );
        assert_eq!(
            InputError::new("x", "bad").for_field("k").to_string(),
            "x: field 'k': bad"
        );
        assert_eq!(InputError::new("", "no files").to_string(), "no files");
    }

    #[test]
    fn display_stays_on_one_line() {
        let e = InputError::new("f", "two\nlines").for_field("a\rb");
        assert!(!e.to_string().contains('\n'));
        assert!(!e.to_string().contains('\r'));
    }
}
