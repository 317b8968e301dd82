//! An input profile as a file: the `t,U` table that `motorcal design` writes and `simulate
//! --input FILE` (or a test bench) takes — `t,I` for a current-driven model, whose input is the
//! commanded current; other columns are ignored.

use std::io;
use std::path::Path;

use super::atomic::{with_path, write_atomically};
use super::error::{InputError, read_text};
use super::table::{self, Line};

/// An input held between sample times: `values[i]` from `times[i]` on (and before `times[0]`).
/// A voltage, or for a current-driven model the current.
#[derive(Clone, Debug, PartialEq)]
pub struct VoltageProfile {
    pub times: Vec<f64>,
    pub values: Vec<f64>,
}

/// Reads a `t,U` file: non-negative, strictly increasing times, finite voltages, at least two
/// rows.
pub fn read_voltage_profile(path: &Path) -> Result<VoltageProfile, InputError> {
    read_input_profile(path, "U")
}

/// Reads a `t,<column>` file (`U`, or `I` for a current command) as [`read_voltage_profile`]
/// reads a `t,U` one.
pub fn read_input_profile(path: &Path, input: &str) -> Result<VoltageProfile, InputError> {
    let text = read_text(path, |text, line, column| {
        table::column_at(text, line, column)
    })?;
    let err = |message: String| InputError::new(path, message);
    let Some((header_line, names)) = table::header(&text) else {
        return Err(err(
            "no header line: the file is empty or has only comments".into(),
        ));
    };
    let column = |wanted: &str| {
        let mut hits = names.iter().enumerate().filter(|(_, n)| **n == wanted);
        match (hits.next(), hits.next()) {
            (Some((i, _)), None) => Ok(i),
            (Some(_), Some(_)) => Err(err(format!(
                "column '{wanted}' appears more than once in the header"
            ))
            .at_line(header_line)
            .for_field(wanted)),
            (None, _) => Err(err(format!(
                "no column '{wanted}'; this model's input file has the columns t,{input} (the \
                 header has {})",
                names.join(",")
            ))
            .at_line(header_line)
            .for_field(wanted)),
        }
    };
    let (t_col, u_col) = (column("t")?, column(input)?);
    let mut profile = VoltageProfile {
        times: Vec::new(),
        values: Vec::new(),
    };
    let mut last_line = header_line;
    for entry in table::lines(&text) {
        let Line::Cells { line, cells } = entry else {
            continue;
        };
        if line == header_line {
            continue;
        }
        if cells.len() != names.len() {
            return Err(err(format!(
                "{} cells, but the header has {} columns",
                cells.len(),
                names.len()
            ))
            .at_line(line));
        }
        let number = |col: usize| {
            table::parse_number(cells[col]).map_err(|m| err(m).at_line(line).for_field(names[col]))
        };
        let (t, u) = (number(t_col)?, number(u_col)?);
        if t < 0.0 {
            return Err(err(format!("time {t} is negative"))
                .at_line(line)
                .for_field("t"));
        }
        if let Some(&before) = profile.times.last()
            && t <= before
        {
            return Err(err(format!(
                "time {t} does not increase (the row before has {before})"
            ))
            .at_line(line)
            .for_field("t"));
        }
        profile.times.push(t);
        profile.values.push(u);
        last_line = line;
    }
    if profile.times.len() < 2 {
        return Err(err(format!(
            "only {} data rows; an input needs at least 2",
            profile.times.len()
        ))
        .at_line(last_line)
        .for_field("t"));
    }
    Ok(profile)
}

/// Writes a profile as `t,U` with round-trip precision.
pub fn write_voltage_profile(path: &Path, profile: &VoltageProfile) -> io::Result<()> {
    write_input_profile(path, "U", profile)
}

/// Writes a profile as `t,<column>` (`U`, or `I` for a current command).
pub fn write_input_profile(path: &Path, input: &str, profile: &VoltageProfile) -> io::Result<()> {
    if profile.times.len() != profile.values.len()
        || profile
            .times
            .iter()
            .chain(&profile.values)
            .any(|v| !v.is_finite())
    {
        return Err(with_path(
            path,
            io::Error::new(
                io::ErrorKind::InvalidInput,
                "an input profile needs as many finite values as times",
            ),
        ));
    }
    let mut out = format!("t,{input}\n");
    for (t, u) in profile.times.iter().zip(&profile.values) {
        table::push_number(&mut out, *t);
        out.push(',');
        table::push_number(&mut out, *u);
        out.push('\n');
    }
    write_atomically(path, out.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str, contents: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("motorcal-input-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(name);
        std::fs::write(&path, contents).unwrap();
        path
    }

    #[test]
    fn a_profile_round_trips() {
        let profile = VoltageProfile {
            times: vec![0.001, 0.002, 0.003],
            values: vec![24.0, -1.0 / 3.0, 0.0],
        };
        let path = scratch("round.csv", "");
        write_voltage_profile(&path, &profile).unwrap();
        assert_eq!(read_voltage_profile(&path).unwrap(), profile);
        let current = scratch("current.csv", "");
        write_input_profile(&current, "I", &profile).unwrap();
        assert!(
            std::fs::read_to_string(&current)
                .unwrap()
                .starts_with("t,I\n")
        );
        assert_eq!(read_input_profile(&current, "I").unwrap(), profile);
        assert!(read_voltage_profile(&current).is_err());
    }

    #[test]
    fn bad_files_name_line_and_field() {
        let cases = [
            ("nou.csv", "t,I\n0,1\n1,2\n", Some(1), "U"),
            ("text.csv", "t,U\n0,1\n1,abc\n", Some(3), "U"),
            ("back.csv", "t,U\n0,1\n0.5,2\n0.5,3\n", Some(4), "t"),
            ("short.csv", "# c\nt,U\n0,1\n", Some(3), "t"),
        ];
        for (name, text, line, field) in cases {
            let e = read_voltage_profile(&scratch(name, text)).unwrap_err();
            assert_eq!(
                (e.line, e.field.as_deref()),
                (line, Some(field)),
                "{name}: {e}"
            );
        }
    }
}
