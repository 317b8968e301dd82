//! The plain comma-separated text that recordings and draws share: one record per line, `#` lines
//! are comments, blank lines are skipped, cells are trimmed and may be wrapped in double quotes.
//! Quoted commas are not supported: no file this tool reads needs them, and a line-based reader
//! keeps every error on the line the user sees in an editor.

/// One meaningful line of a table file.
pub(crate) enum Line<'a> {
    /// A `#` line, without the `#` and surrounding blanks.
    Comment(&'a str),
    Cells {
        line: usize,
        cells: Vec<&'a str>,
    },
}

/// The comment and data lines of `text`, numbered from 1 as in an editor.
pub(crate) fn lines(text: &str) -> impl Iterator<Item = Line<'_>> {
    text.lines().enumerate().filter_map(|(i, raw)| {
        let trimmed = raw.trim();
        if trimmed.is_empty() {
            None
        } else if let Some(comment) = trimmed.strip_prefix('#') {
            Some(Line::Comment(comment.trim()))
        } else {
            Some(Line::Cells {
                line: i + 1,
                cells: split(trimmed),
            })
        }
    })
}

fn split(line: &str) -> Vec<&str> {
    line.split(',')
        .map(|cell| {
            let cell = cell.trim();
            cell.strip_prefix('"')
                .and_then(|c| c.strip_suffix('"'))
                .unwrap_or(cell)
        })
        .collect()
}

/// The first data line's cells: the header.
pub(crate) fn header(text: &str) -> Option<(usize, Vec<&str>)> {
    lines(text).find_map(|l| match l {
        Line::Cells { line, cells } => Some((line, cells)),
        Line::Comment(_) => None,
    })
}

/// The column that byte `column` of line `line` falls in, for errors found before the table could
/// be parsed (bad encoding): the header's name for it, or the header cell itself.
pub(crate) fn column_at(text: &str, line: usize, column: usize) -> Option<String> {
    let line_text = text.lines().nth(line.checked_sub(1)?)?;
    let index = line_text.get(..column)?.matches(',').count();
    // When the bad byte is in the header itself, this names the column with the odd character
    // replaced, which is still recognisable.
    let (_, names) = header(text)?;
    names.get(index).map(|s| s.to_string())
}

/// A finite number from a cell, or what is wrong with it.
pub(crate) fn parse_number(cell: &str) -> Result<f64, String> {
    if cell.is_empty() {
        return Err("empty cell, expected a number".to_owned());
    }
    match cell.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(v) if v.is_nan() => Err(format!("'{cell}' is not a number (NaN is not allowed)")),
        Ok(_) if cell.to_ascii_lowercase().contains("inf") => {
            Err(format!("'{cell}' is infinite; every value must be finite"))
        }
        Ok(_) => Err(format!(
            "'{cell}' overflows a 64-bit float; every value must be finite"
        )),
        Err(_) => Err(format!("'{}' is not a number", truncate(cell, 40))),
    }
}

/// A cell quoted back in an error message, shortened: a binary line can be megabytes long.
pub(crate) fn truncate(text: &str, max_chars: usize) -> String {
    match text.char_indices().nth(max_chars) {
        Some((at, _)) => format!("{}…", &text[..at]),
        None => text.to_owned(),
    }
}

/// The round-trip text of a number: Rust's shortest representation that parses back to the same
/// bits (`{:?}` keeps the `.0` and switches to exponents for very small or large magnitudes).
pub(crate) fn push_number(out: &mut String, v: f64) {
    use std::fmt::Write;
    // Writing into a String cannot fail.
    let _ = write!(out, "{v:?}");
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn comments_and_blank_lines_keep_line_numbers() {
        let text = "# note\n\nt, I\n  \n\"1\",2\r\n";
        let got: Vec<_> = lines(text)
            .map(|l| match l {
                Line::Comment(text) => format!("#{text}"),
                Line::Cells { line, cells } => format!("{line}:{}", cells.join("|")),
            })
            .collect();
        assert_eq!(got, ["#note", "3:t|I", "5:1|2"]);
    }

    #[test]
    fn numbers_must_be_finite() {
        assert_eq!(parse_number(" 1e-3".trim()), Ok(1e-3));
        assert!(parse_number("NaN").unwrap_err().contains("NaN"));
        assert!(parse_number("-inf").unwrap_err().contains("infinite"));
        assert!(parse_number("1e999").unwrap_err().contains("overflows"));
        assert!(parse_number("abc").unwrap_err().contains("not a number"));
        assert!(parse_number("").unwrap_err().contains("empty"));
    }

    #[test]
    fn numbers_round_trip() {
        for v in [
            0.1,
            1.0 / 3.0,
            1e-300,
            5e-324,
            1.7976931348623157e308,
            -24.0,
            0.0,
        ] {
            let mut s = String::new();
            push_number(&mut s, v);
            assert_eq!(s.parse::<f64>().unwrap().to_bits(), v.to_bits(), "{s}");
        }
    }
}
