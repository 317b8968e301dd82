//! Recordings: a time column and the measured channels, as CSV.

use std::io;
use std::path::Path;

use serde::{Deserialize, Serialize};

use super::atomic::{with_path, write_atomically};
use super::error::{InputError, read_text};
use super::table::{self, Line};
use crate::motor::{Base, DriveSettings, SampledDrive, VoltageInput};

/// Samples over which a position loop's measured axis speed is taken for its speed scale.
const POSITION_SPEED_WINDOW: usize = 10;

/// Which CSV column holds what the model needs. Keys in a model file's `[channels]` table.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ChannelMap {
    /// Time [s].
    pub t: String,
    /// Current I [A].
    #[serde(rename = "I")]
    pub current: String,
    /// Speed ω [rad/s].
    #[serde(rename = "omega")]
    pub speed: String,
    /// Voltage U [V], optional in the file: without it the model's constant U drives the motor.
    #[serde(rename = "U")]
    pub voltage: String,
    /// Position q [rad or m] (`position_loop`).
    pub q: String,
    /// Reference position of a position loop [rad or m].
    pub q_ref: String,
    /// The drive's force or torque, c_g times the controller output [N or N·m] (`position_loop`).
    pub force: String,
    /// A disturbance added to the controller output after its saturation (`position_loop`);
    /// zero when the record has no such column.
    pub disturbance: String,
}

impl Default for ChannelMap {
    fn default() -> Self {
        Self {
            t: "t".into(),
            current: "I".into(),
            speed: "omega".into(),
            voltage: "U".into(),
            q: "q".into(),
            q_ref: "q_ref".into(),
            force: "force".into(),
            disturbance: "disturbance".into(),
        }
    }
}

impl ChannelMap {
    /// The column that holds a model channel or input (`I`, `omega`, `U`, `q`, `q_ref`,
    /// `force`, `disturbance`; `t` for time); an unknown name is its own column.
    pub fn column<'a>(&'a self, model_name: &'a str) -> &'a str {
        match model_name {
            "t" => &self.t,
            "I" => &self.current,
            "omega" => &self.speed,
            "U" => &self.voltage,
            "q" => &self.q,
            "q_ref" => &self.q_ref,
            "force" => &self.force,
            "disturbance" => &self.disturbance,
            other => other,
        }
    }
}

/// A measured run: sample times, the model's channels at those times, and the voltage if it was
/// recorded.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Recording {
    /// Where it came from (the file path), for reports.
    pub source: String,
    pub time: Vec<f64>,
    /// The model's channels by their model names (`I`, `omega`), whatever the file called them.
    pub channels: Vec<(String, Vec<f64>)>,
    pub voltage: Option<Vec<f64>>,
    /// A drive base's recorded inputs by their model names (`I`; `q_ref`, `disturbance`).
    pub inputs: Vec<(String, Vec<f64>)>,
}

impl Recording {
    pub fn channel(&self, name: &str) -> Option<&[f64]> {
        self.channels
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_slice())
    }

    pub fn n_samples(&self) -> usize {
        self.time.len()
    }

    /// The recorded voltage held between samples, or the model's constant `U` without one.
    pub fn voltage_input(&self) -> VoltageInput {
        match &self.voltage {
            Some(values) => VoltageInput::Held {
                times: self.time.clone(),
                values: values.clone(),
            },
            None => VoltageInput::Constant,
        }
    }

    pub fn input(&self, name: &str) -> Option<&[f64]> {
        self.inputs
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_slice())
    }

    /// What a drive base takes from this record: the input series, the disturbance, where the
    /// axis starts and how fast the record moves; `None` for the voltage-driven motor or a
    /// record without the base's input.
    pub fn sampled_drive(&self, base: Base, settings: &DriveSettings) -> Option<SampledDrive> {
        let largest = |v: &[f64]| v.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        let m = self.n_samples();
        let (input, disturbance, initial_position, speed_scale) = match base {
            Base::VoltageDriven => return None,
            Base::CurrentDriven => (
                self.input("I")?.to_vec(),
                vec![0.0; m],
                0.0,
                self.channel("omega").map_or(1.0, largest),
            ),
            Base::PositionLoop => {
                let reference = self.input("q_ref")?;
                // The fastest a series moves over `w` samples.
                let fastest = |v: &[f64], w: usize| {
                    (w..m)
                        .map(|i| ((v[i] - v[i - w]) / (self.time[i] - self.time[i - w])).abs())
                        .fold(0.0f64, f64::max)
                };
                // The reference's speed, unless the axis moves slower: a stepped reference (a
                // designed one) jumps faster than any axis, and the scale is the axis's then.
                // The axis's speed is taken over ten samples, where the position's noise
                // weighs a tenth of what it does between two.
                let mut speed = fastest(reference, 1);
                if let Some(q) = self.channel("q") {
                    let axis = fastest(q, POSITION_SPEED_WINDOW.min(m.saturating_sub(1)).max(1));
                    if axis > 0.0 {
                        speed = speed.min(axis);
                    }
                }
                (
                    reference.to_vec(),
                    self.input("disturbance")
                        .map_or_else(|| vec![0.0; m], |d| d.to_vec()),
                    self.channel("q").map_or(reference[0], |q| q[0]),
                    speed,
                )
            }
        };
        Some(SampledDrive {
            times: self.time.clone(),
            input,
            disturbance,
            initial_position,
            speed_scale,
            settings: settings.clone(),
        })
    }

    /// The time of the last sample; 0 for an empty recording (which the reader never returns).
    pub fn last_time(&self) -> f64 {
        self.time.last().copied().unwrap_or(0.0)
    }
}

/// Reads a recording, with the columns named by `map`.
///
/// The first non-comment line is the header; other columns than the mapped ones are ignored. The
/// voltage column may be missing when `map` names the default `U`; a column the user named
/// explicitly must exist, since a typo there would otherwise silently drive the motor with the
/// constant U.
pub fn read_recording(path: &Path, map: &ChannelMap) -> Result<Recording, InputError> {
    read_recording_for(path, map, Base::VoltageDriven)
}

/// Which column plays which part for a base: (model name, column, required).
struct Roles {
    outputs: Vec<(&'static str, String)>,
    inputs: Vec<(&'static str, String, bool)>,
}

fn roles(map: &ChannelMap, base: Base) -> Roles {
    let input = |name: &'static str, required: bool| (name, map.column(name).to_string(), required);
    Roles {
        outputs: base
            .channels()
            .iter()
            .map(|&c| (c, map.column(c).to_string()))
            .collect(),
        inputs: match base {
            // A voltage column the user named must exist; the default `U` may be absent.
            Base::VoltageDriven => vec![input(
                base.input(),
                map.voltage != ChannelMap::default().voltage,
            )],
            Base::CurrentDriven => vec![input(base.input(), true)],
            // The disturbance is absent from ordinary records of a rig whose validation record
            // has it: 0 then, not an error.
            Base::PositionLoop => vec![input(base.input(), true), input("disturbance", false)],
        },
    }
}

/// Reads a recording for a base: the columns its channels and inputs need, named by `map`.
pub fn read_recording_for(
    path: &Path,
    map: &ChannelMap,
    base: Base,
) -> Result<Recording, InputError> {
    let text = read_text(path, |text, line, column| {
        table::column_at(text, line, column)
    })?;
    let err = |message: String| InputError::new(path, message);

    let Some((header_line, names)) = table::header(&text) else {
        return Err(err(
            "no header line: the file is empty or has only comments".into(),
        ));
    };
    let find = |wanted: &str| -> Result<Option<usize>, InputError> {
        let mut hits = names
            .iter()
            .enumerate()
            .filter(|(_, n)| **n == wanted)
            .map(|(i, _)| i);
        let first = hits.next();
        if hits.next().is_some() {
            return Err(err(format!(
                "column '{wanted}' appears more than once in the header"
            ))
            .at_line(header_line)
            .for_field(wanted));
        }
        Ok(first)
    };
    let require = |wanted: &str, role: &str| -> Result<usize, InputError> {
        find(wanted)?.ok_or_else(|| {
            err(format!(
                "no {role} column '{wanted}'; the header has {} (say which column is which in the \
                 model file's [channels] table)",
                quoted_list(&names)
            ))
            .at_line(header_line)
            .for_field(wanted)
        })
    };
    let roles = roles(map, base);
    let t_col = require(&map.t, "time")?;
    let mut columns = vec![t_col];
    for (name, column) in &roles.outputs {
        columns.push(require(column, &format!("{name} channel"))?);
    }
    let mut input_columns: Vec<(&str, Option<usize>)> = Vec::new();
    for (name, column, required) in &roles.inputs {
        let found = if *required {
            Some(require(column, &format!("{name} input"))?)
        } else {
            find(column)?
        };
        input_columns.push((name, found));
        columns.extend(found);
    }
    let mut values: Vec<Vec<f64>> = vec![Vec::new(); columns.len()];
    let mut last_line = header_line;
    for entry in table::lines(&text) {
        let Line::Cells { line, cells } = entry else {
            continue;
        };
        if line == header_line {
            continue;
        }
        if cells.len() != names.len() {
            let e = err(format!(
                "{} cells, but the header has {} columns",
                cells.len(),
                names.len()
            ))
            .at_line(line);
            // A short row is missing the columns at its end: name the first of them.
            return Err(match names.get(cells.len()) {
                Some(missing) => e.for_field(*missing),
                None => e,
            });
        }
        for (slot, &col) in values.iter_mut().zip(&columns) {
            let v = table::parse_number(cells[col])
                .map_err(|m| err(m).at_line(line).for_field(names[col]))?;
            slot.push(v);
        }
        let time = &values[0];
        let t = time[time.len() - 1];
        if t < 0.0 {
            return Err(err(format!("time {t} is negative"))
                .at_line(line)
                .for_field(names[t_col]));
        }
        if let [.., before, _] = time.as_slice()
            && t <= *before
        {
            return Err(err(format!(
                "time {t} does not increase (the row before has {before}); rows must be in time \
                 order without repeats"
            ))
            .at_line(line)
            .for_field(names[t_col]));
        }
        last_line = line;
    }
    let n = values[0].len();
    if n < 2 {
        return Err(
            err(format!("only {n} data rows; a recording needs at least 2"))
                .at_line(last_line)
                .for_field(names[t_col]),
        );
    }

    let mut values = values.into_iter();
    let mut next = || values.next().unwrap_or_default();
    let time = next();
    let channels = roles
        .outputs
        .iter()
        .map(|(name, _)| (name.to_string(), next()))
        .collect();
    let mut voltage = None;
    let mut inputs = Vec::new();
    for (name, found) in input_columns {
        if found.is_none() {
            continue;
        }
        let series = next();
        if base == Base::VoltageDriven {
            voltage = Some(series);
        } else {
            inputs.push((name.to_string(), series));
        }
    }
    Ok(Recording {
        source: path.display().to_string(),
        time,
        channels,
        voltage,
        inputs,
    })
}

/// Writes `t`, the channels and `U` (when recorded) as CSV with round-trip precision.
pub fn write_recording(path: &Path, recording: &Recording) -> io::Result<()> {
    write_recording_as(path, recording, &ChannelMap::default())
}

/// As [`write_recording`], each column named as `map` names it: the file a model file with that
/// `[channels]` table reads back (a rig's `t_s`, `w_rad_s`, …).
pub fn write_recording_as(path: &Path, recording: &Recording, map: &ChannelMap) -> io::Result<()> {
    let invalid =
        |message: String| with_path(path, io::Error::new(io::ErrorKind::InvalidInput, message));
    let n = recording.time.len();
    let mut columns: Vec<(&str, &[f64])> = vec![(map.column("t"), &recording.time)];
    columns.extend(
        recording
            .channels
            .iter()
            .map(|(name, v)| (map.column(name), v.as_slice())),
    );
    if let Some(u) = &recording.voltage {
        columns.push((map.column("U"), u));
    }
    columns.extend(
        recording
            .inputs
            .iter()
            .map(|(name, v)| (map.column(name), v.as_slice())),
    );
    for (name, v) in &columns {
        if v.len() != n {
            return Err(invalid(format!(
                "column '{name}' has {} values for {n} times",
                v.len()
            )));
        }
        if name.contains([',', '\n', '\r', '"']) || name.starts_with('#') || name.trim() != *name {
            return Err(invalid(format!(
                "column name '{name}' cannot be written to a CSV header"
            )));
        }
        // The reader refuses non-finite values, so writing one would make a file it cannot read.
        if let Some(v) = v.iter().find(|v| !v.is_finite()) {
            return Err(invalid(format!(
                "column '{name}' holds {v}; only finite values can be written"
            )));
        }
    }

    let mut out = String::with_capacity(32 * n * columns.len());
    let names: Vec<&str> = columns.iter().map(|(name, _)| *name).collect();
    out.push_str(&names.join(","));
    out.push('\n');
    for i in 0..n {
        for (j, (_, v)) in columns.iter().enumerate() {
            if j > 0 {
                out.push(',');
            }
            table::push_number(&mut out, v[i]);
        }
        out.push('\n');
    }
    write_atomically(path, out.as_bytes())
}

fn quoted_list(names: &[&str]) -> String {
    if names.is_empty() {
        return "no columns".into();
    }
    let shown: Vec<String> = names
        .iter()
        .take(20)
        .map(|n| format!("'{}'", table::truncate(n, 40)))
        .collect();
    let more = names.len().saturating_sub(shown.len());
    if more > 0 {
        format!("{} and {more} more", shown.join(", "))
    } else {
        shown.join(", ")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    fn scratch(name: &str, contents: &[u8]) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("motorcal-rec-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(name);
        std::fs::write(&path, contents).unwrap();
        path
    }

    #[test]
    fn a_position_loop_s_speed_scale_is_the_axis_s_where_its_reference_jumps() {
        let time: Vec<f64> = (0..40).map(|i| i as f64 * 0.001).collect();
        // A reference stepping 0.05 m at one sample (50 m/s) and an axis moving at 0.2 m/s.
        let reference: Vec<f64> = time
            .iter()
            .map(|&t| if t < 0.0015 { 0.0 } else { 0.05 })
            .collect();
        let axis: Vec<f64> = time.iter().map(|&t| 0.2 * t).collect();
        let record = |q: Vec<f64>, q_ref: Vec<f64>| Recording {
            time: time.clone(),
            channels: vec![("q".into(), q), ("force".into(), vec![0.0; 40])],
            inputs: vec![("q_ref".into(), q_ref)],
            ..Recording::default()
        };
        let scale = |r: &Recording| {
            r.sampled_drive(Base::PositionLoop, &DriveSettings::default())
                .unwrap()
                .speed_scale
        };
        assert!((scale(&record(axis.clone(), reference)) - 0.2).abs() < 1e-9);
        // A reference the axis follows (EMPS's) keeps its own speed, and an axis at rest (a
        // placeholder before a simulation) leaves the reference's.
        let slower: Vec<f64> = time.iter().map(|&t| 0.1 * t).collect();
        assert!((scale(&record(axis, slower.clone())) - 0.1).abs() < 1e-9);
        assert!((scale(&record(vec![0.0; 40], slower)) - 0.1).abs() < 1e-9);
    }

    #[test]
    fn columns_are_found_by_map_and_named_by_model() {
        let path = scratch(
            "mapped.csv",
            b"# rig 3\nextra,time_s,amps,speed\n\nx,0,1.5,2\n# pause\ny,0.1,1.25,3\n",
        );
        let map = ChannelMap {
            t: "time_s".into(),
            current: "amps".into(),
            speed: "speed".into(),
            ..ChannelMap::default()
        };
        let rec = read_recording(&path, &map).unwrap();
        assert_eq!(rec.time, [0.0, 0.1]);
        assert_eq!(rec.channel("I"), Some(&[1.5, 1.25][..]));
        assert_eq!(rec.channel("omega"), Some(&[2.0, 3.0][..]));
        assert_eq!(rec.voltage, None);
        assert_eq!(rec.voltage_input(), VoltageInput::Constant);
        assert_eq!(rec.last_time(), 0.1);
    }

    #[test]
    fn an_explicit_voltage_column_must_exist() {
        let path = scratch("nov.csv", b"t,I,omega\n0,1,2\n1,1,2\n");
        let map = ChannelMap {
            voltage: "V_supply".into(),
            ..ChannelMap::default()
        };
        let e = read_recording(&path, &map).unwrap_err();
        assert_eq!(e.field.as_deref(), Some("V_supply"));
        assert!(read_recording(&path, &ChannelMap::default()).is_ok());
    }

    #[test]
    fn a_duplicated_column_is_ambiguous() {
        let path = scratch("dup.csv", b"t,I,omega,I\n0,1,2,3\n1,1,2,3\n");
        let e = read_recording(&path, &ChannelMap::default()).unwrap_err();
        assert_eq!((e.line, e.field.as_deref()), (Some(1), Some("I")));
    }

    #[test]
    fn invalid_utf8_names_line_and_column() {
        let path = scratch("latin1.csv", b"t,I,omega\n0,1,2\n1,\xB01,2\n");
        let e = read_recording(&path, &ChannelMap::default()).unwrap_err();
        assert_eq!((e.line, e.field.as_deref()), (Some(3), Some("I")));
    }

    #[test]
    fn the_writer_refuses_what_the_reader_would_refuse() {
        let dir = std::env::temp_dir().join(format!("motorcal-rec-{}", std::process::id()));
        let rec = Recording {
            source: String::new(),
            time: vec![0.0, 1.0],
            channels: vec![("I".into(), vec![1.0, f64::NAN])],
            voltage: None,
            inputs: Vec::new(),
        };
        let err = write_recording(&dir.join("nan.csv"), &rec).unwrap_err();
        assert!(err.to_string().contains("nan.csv"), "{err}");
        assert!(!dir.join("nan.csv").exists());
    }
}
