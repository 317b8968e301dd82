//! The helpers that locate a failure in a file's text; the error they build, [`InputError`], is
//! the crate's (`crate::error`).

use std::path::Path;

pub use crate::error::InputError;

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
    fn lines_and_columns_are_counted_from_the_bytes() {
        assert_eq!(line_and_column(b"ab\ncd\n", 0), (1, 0));
        assert_eq!(line_and_column(b"ab\ncd\n", 4), (2, 1));
        assert_eq!(line_and_column(b"ab\ncd\n", 99), (3, 0));
    }
}
