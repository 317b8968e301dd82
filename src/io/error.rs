//! The one error type for input the tool cannot use, and the helpers that locate a failure in a
//! file's text.

use std::fmt;
use std::path::{Path, PathBuf};

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

/// The whole file as text. Invalid UTF-8 is reported at the line of the first bad byte, and at its
/// field if `name_field` can name it from the (lossily decoded) text, the 1-based line and the byte
/// offset within that line: a CSV saved in a legacy encoding usually has one odd character in one
/// header or cell, and the user needs to find it.
pub(crate) fn read_text(
    path: &Path,
    name_field: impl Fn(&str, usize, usize) -> Option<String>,
) -> Result<String, InputError> {
    let mut bytes = std::fs::read(path).map_err(|e| InputError::unreadable(path, &e))?;
    // Spreadsheet programs prepend a byte-order mark that would otherwise stick to the first
    // column's name.
    if bytes.starts_with(b"\xEF\xBB\xBF") {
        bytes.drain(..3);
    }
    if let Some(at) = bytes.iter().position(|&b| b == 0) {
        let (line, _) = line_and_column(&bytes, at);
        return Err(
            InputError::new(path, "NUL byte: this is a binary file, not text").at_line(line),
        );
    }
    String::from_utf8(bytes).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        let (line, column) = line_and_column(e.as_bytes(), at);
        let lossy = String::from_utf8_lossy(e.as_bytes());
        InputError::new(path, "not valid UTF-8 text (save the file as UTF-8)")
            .at_line(line)
            .for_field_opt(name_field(&lossy, line, column))
    })
}

/// 1-based line number and 0-based byte offset within the line of byte `at`.
pub(crate) fn line_and_column(bytes: &[u8], at: usize) -> (usize, usize) {
    let at = at.min(bytes.len());
    let before = &bytes[..at];
    let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
    let line_start = before
        .iter()
        .rposition(|&b| b == b'\n')
        .map_or(0, |n| n + 1);
    (line, at - line_start)
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

    #[test]
    fn lines_and_columns_are_counted_from_the_bytes() {
        assert_eq!(line_and_column(b"ab\ncd\n", 0), (1, 0));
        assert_eq!(line_and_column(b"ab\ncd\n", 4), (2, 1));
        assert_eq!(line_and_column(b"ab\ncd\n", 99), (3, 0));
    }
}
