//! Model files: the nominal motor the user believes and how their recording's columns are named,
//! as TOML.

use std::io;
use std::path::Path;

use serde::Deserialize;

use super::atomic::write_atomically;
use super::error::{InputError, read_text};
use super::model_tables::{
    CalibrateEntry, DiscrepancyChoice, RawDiscrepancy, parse_calibrate, parse_discrepancy,
    parse_terms, toml_number, write_tables,
};
use super::recording::{ChannelMap, Recording};
use super::toml_lines::{key_paths, table_headers, toml_error};
use crate::motor::{
    ActiveTerm, Base, DriveSettings, MotorModel, MotorParam, MotorParameters, VoltageInput,
};
use crate::parameter::ParamId;

/// The newest model-file format version this build reads and writes. Schema 1 (the motor and
/// the channels) is still read, and means what it always meant.
pub const MODEL_FILE_SCHEMA: u32 = 2;

/// A model file: the nominal motor, the physics terms switched on, what is calibrated with
/// which prior, the discrepancy, and which recorded column is which.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelFile {
    pub schema: u32,
    /// The physics the terms are added to (`base = "voltage_driven"`, the paper's motor).
    pub base: Base,
    pub motor: MotorParameters,
    /// `[terms.NAME]`, in the canonical order of [`crate::motor::Term::NAMES`].
    pub terms: Vec<ActiveTerm>,
    /// `[calibrate]`; `None` when the table is absent: R alone, with the paper's prior, sampled
    /// as itself (what schema-1 files always meant).
    pub calibrate: Option<Vec<CalibrateEntry>>,
    /// `[discrepancy]`; `None` leaves BM1/BM2 and K to the command line's defaults.
    pub discrepancy: Option<DiscrepancyChoice>,
    /// `[drive]`: how a drive base turns its recorded input into torque.
    pub drive: DriveSettings,
    pub channels: ChannelMap,
}

impl Default for ModelFile {
    fn default() -> Self {
        Self {
            schema: 1,
            base: Base::VoltageDriven,
            motor: MotorParameters::default(),
            terms: Vec::new(),
            calibrate: None,
            discrepancy: None,
            drive: DriveSettings::default(),
            channels: ChannelMap::default(),
        }
    }
}

impl ModelFile {
    /// The model driven by `input`, with the file's terms switched on.
    pub fn model(&self, input: VoltageInput) -> Result<MotorModel, String> {
        MotorModel::with_base(self.base, self.motor.clone(), input, self.terms.clone())
    }

    /// The model of a recording: driven by its voltage, or for a drive base by its recorded
    /// input through the `[drive]` settings.
    pub fn model_for_recording(&self, recording: &Recording) -> Result<MotorModel, String> {
        let model = self.model(recording.voltage_input())?;
        if !self.base.is_drive() {
            return Ok(model);
        }
        let drive = recording
            .sampled_drive(self.base, &self.drive)
            .ok_or_else(|| {
                format!(
                    "{}: a {} model needs the record's input column",
                    recording.source,
                    self.base.name()
                )
            })?;
        Ok(model.with_drive(drive))
    }

    /// Sets a parameter's nominal value (`R`, `coulomb_friction.T_c`); false when the motor has
    /// no such parameter or the term is not on.
    pub fn set_value(&mut self, id: &ParamId, value: f64) -> bool {
        match id {
            ParamId::Term { term, key } => {
                let Some(active) = self.terms.iter_mut().find(|t| t.term.name() == term) else {
                    return false;
                };
                let Some(i) = active.term.params().iter().position(|p| p.key == key) else {
                    return false;
                };
                active.values[i] = value;
                true
            }
            ParamId::Base(key) => match MotorParam::from_key(key) {
                Some(p) => {
                    self.motor.set(p, value);
                    true
                }
                None => false,
            },
        }
    }

    /// Whether anything needs schema 2 to be written.
    fn needs_schema_2(&self) -> bool {
        !self.terms.is_empty()
            || self.calibrate.is_some()
            || self.discrepancy.is_some()
            || self.base != Base::VoltageDriven
            || self.drive != DriveSettings::default()
    }
}

/// The file as TOML hands it over; every table refuses unknown keys, so a misspelt key is an
/// error instead of a silently ignored setting; missing keys take their defaults.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawModelFile {
    #[serde(default = "schema_1")]
    schema: u32,
    base: Option<String>,
    #[serde(default)]
    motor: MotorParameters,
    terms: Option<toml::Table>,
    calibrate: Option<toml::Table>,
    discrepancy: Option<RawDiscrepancy>,
    drive: Option<DriveSettings>,
    #[serde(default)]
    channels: ChannelMap,
}

fn schema_1() -> u32 {
    1
}

/// Reads and checks a model file: TOML syntax, known keys, value types, the schema version and
/// the motor's physical plausibility ([`MotorParameters::validate`]).
pub fn read_model_file(path: &Path) -> Result<ModelFile, InputError> {
    let text = read_text(path, |text, line, _| {
        key_paths(text).get(line - 1).cloned().flatten()
    })?;
    parse_model_file(&text, path)
}

/// Parses model-file text; `path` only names the file in errors.
pub fn parse_model_file(text: &str, path: &Path) -> Result<ModelFile, InputError> {
    let raw: RawModelFile = toml::from_str(text).map_err(|e| toml_error(text, path, &e))?;
    let paths = key_paths(text);
    let headers = table_headers(text);
    // A key's own line, or else the header of the table it names, or else the line of the first
    // key inside it.
    let line_of = |key: &str| {
        let position = |list: &[Option<String>], wanted: &str| {
            list.iter()
                .position(|p| p.as_deref() == Some(wanted))
                .map(|i| i + 1)
        };
        position(&paths, key)
            .or_else(|| position(&headers, key))
            .or_else(|| {
                let prefix = format!("{key}.");
                let starts =
                    |p: &Option<String>| p.as_deref().is_some_and(|p| p.starts_with(&prefix));
                let first = |list: &[Option<String>]| list.iter().position(starts);
                match (first(&headers), first(&paths)) {
                    (Some(a), Some(b)) => Some(a.min(b) + 1),
                    (a, b) => a.or(b).map(|i| i + 1),
                }
            })
            .or_else(|| {
                // A missing prior argument is reported for `calibrate.NAME.arg`: point at NAME.
                let parent = key.rsplit_once('.')?.0;
                position(&paths, parent)
            })
    };

    if !(1..=MODEL_FILE_SCHEMA).contains(&raw.schema) {
        return Err(InputError::new(
            path,
            format!(
                "schema {} is not supported; this version of motorcal reads schemas 1 and {MODEL_FILE_SCHEMA}",
                raw.schema
            ),
        )
        .at_line_opt(line_of("schema"))
        .for_field("schema"));
    }
    if raw.schema == 1 {
        for (table, present) in [
            ("base", raw.base.is_some()),
            ("terms", raw.terms.is_some()),
            ("calibrate", raw.calibrate.is_some()),
            ("discrepancy", raw.discrepancy.is_some()),
            ("drive", raw.drive.is_some()),
        ] {
            if present {
                return Err(InputError::new(
                    path,
                    format!("a [{table}] table needs `schema = 2` at the top of the file"),
                )
                .at_line_opt(line_of(table))
                .for_field(table));
            }
        }
    }
    let base = match raw.base.as_deref() {
        None => Base::VoltageDriven,
        Some(name) => Base::from_name(name).ok_or_else(|| {
            InputError::new(
                path,
                format!(
                    "unknown base model '{name}' (known: {})",
                    Base::ALL.map(|b| b.name()).join(", ")
                ),
            )
            .at_line_opt(line_of("base"))
            .for_field("base")
        })?,
    };
    let mut terms = match &raw.terms {
        Some(table) => parse_terms(table, path, &line_of)?,
        None => Vec::new(),
    };
    let calibrate = match &raw.calibrate {
        Some(table) => Some(parse_calibrate(table, &mut terms, path, &line_of)?),
        None => None,
    };
    let discrepancy = match &raw.discrepancy {
        Some(d) => Some(parse_discrepancy(d, path, &line_of)?),
        None => None,
    };
    terms.sort_by_key(|t| t.term.rank());
    let model = ModelFile {
        schema: raw.schema,
        base,
        motor: raw.motor,
        terms,
        calibrate,
        discrepancy,
        drive: raw.drive.clone().unwrap_or_default(),
        channels: raw.channels,
    };
    if let Err(message) = model.drive.validate(model.base) {
        let key = message.split(" = ").next().unwrap_or("drive").to_string();
        return Err(InputError::new(path, message)
            .at_line_opt(line_of(&key).or_else(|| line_of("drive")))
            .for_field(key));
    }
    // A parameter of one base alone (a position loop's initial offset) is set or calibrated
    // only on that base.
    for p in MotorParam::ALL {
        let Some(base) = p.only_on().filter(|&b| b != model.base) else {
            continue;
        };
        let key = p.key();
        let calibrated = model
            .calibrate
            .iter()
            .flatten()
            .any(|c| c.id == ParamId::base(key));
        if model.motor.get(p) != 0.0 || calibrated {
            let field = format!("{}.{key}", if calibrated { "calibrate" } else { "motor" });
            return Err(InputError::new(
                path,
                format!(
                    "{key} is a parameter of a {} model only; this one is {}",
                    base.name(),
                    model.base.name()
                ),
            )
            .at_line_opt(line_of(&field))
            .for_field(field));
        }
    }
    if let Err(message) = model.motor.validate() {
        // validate() reports "KEY = value ..."; the key tells which line to point at.
        let key = message
            .split(" = ")
            .next()
            .and_then(MotorParam::from_key)
            .map(|p| p.key());
        let field = key.map(|k| format!("motor.{k}"));
        let line = field.as_deref().and_then(line_of);
        return Err(InputError::new(path, message)
            .at_line_opt(line)
            .for_field_opt(field));
    }
    if let Err(message) = model.model(VoltageInput::Constant) {
        let field = (model.motor.load_torque != 0.0).then(|| "motor.T_L".to_string());
        let line = field.as_deref().and_then(line_of);
        return Err(InputError::new(path, message)
            .at_line_opt(line)
            .for_field_opt(field));
    }
    Ok(model)
}

/// The TOML text of a model file, which [`read_model_file`] reads back to the same values:
/// schema 1 when nothing needs more, so that plain files stay readable by older versions.
pub fn to_toml_string(model: &ModelFile) -> String {
    let schema = if model.needs_schema_2() { 2 } else { 1 };
    let mut out = format!("schema = {schema}\n");
    if schema == 2 {
        out.push_str(&format!("base = \"{}\"\n", model.base.name()));
    }
    out.push_str("\n[motor]\n");
    for p in MotorParam::ALL {
        // A parameter of one base alone is written where it is set, so that the other files
        // read as they always have.
        if p.only_on().is_some() && model.motor.get(p) == 0.0 {
            continue;
        }
        out.push_str(&format!(
            "{} = {}\n",
            p.key(),
            toml_number(model.motor.get(p))
        ));
    }
    if model.motor.load_torque != 0.0 {
        out.push_str(&format!("T_L = {}\n", toml_number(model.motor.load_torque)));
    }
    write_tables(
        &mut out,
        &model.terms,
        model.calibrate.as_deref(),
        model.discrepancy.as_ref(),
    );
    if model.drive != DriveSettings::default() {
        let d = &model.drive;
        out.push_str("\n[drive]\n");
        if let Some(limit) = d.input_limit {
            out.push_str(&format!("input_limit = {}\n", toml_number(limit)));
        }
        out.push_str(&format!(
            "position_gain = {}\nvelocity_gain = {}\ndelay_samples = {}\nsubsteps = {}\n",
            toml_number(d.position_gain),
            toml_number(d.velocity_gain),
            d.delay_samples,
            d.substeps
        ));
    }
    let c = &model.channels;
    out.push_str(&format!(
        "\n[channels]\nt = {:?}\nI = {:?}\nomega = {:?}\nU = {:?}\n",
        c.t, c.current, c.speed, c.voltage
    ));
    let defaults = ChannelMap::default();
    for (key, value, default) in [
        ("q", &c.q, &defaults.q),
        ("q_ref", &c.q_ref, &defaults.q_ref),
        ("force", &c.force, &defaults.force),
        ("disturbance", &c.disturbance, &defaults.disturbance),
    ] {
        if value != default {
            out.push_str(&format!("{key} = {value:?}\n"));
        }
    }
    out
}

/// Writes a model file atomically.
pub fn write_model_file(path: &Path, model: &ModelFile) -> io::Result<()> {
    write_atomically(path, to_toml_string(model).as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<ModelFile, InputError> {
        parse_model_file(text, Path::new("m.toml"))
    }

    /// Each text fails with one line naming this line, this key and this message.
    fn assert_errors(cases: &[(&str, usize, &str, &str)]) {
        for &(text, line, field, message) in cases {
            let e = parse(text).unwrap_err();
            assert_eq!(e.line, Some(line), "{text:?}: {e}");
            assert_eq!(e.field.as_deref(), Some(field), "{text:?}: {e}");
            assert!(e.message.contains(message), "{text:?}: {e}");
            assert!(!e.to_string().contains('\n'));
        }
    }

    #[test]
    fn missing_keys_and_tables_take_defaults() {
        assert_eq!(parse("").unwrap(), ModelFile::default());
        let m = parse("[motor]\nR = 0.2\n[channels]\nt = \"time\"\n").unwrap();
        assert_eq!(
            m.motor,
            MotorParameters {
                resistance: 0.2,
                ..MotorParameters::default()
            }
        );
        assert_eq!(m.channels.t, "time");
        assert_eq!(m.channels.current, "I");
        // An integer where a float is expected is what people write.
        assert_eq!(parse("[motor]\nU = 12\n").unwrap().motor.voltage, 12.0);
    }

    #[test]
    fn errors_point_at_line_and_key() {
        let cases = [
            ("[motor]\nR = 0.1\nRr = 2\n", 3, "motor.Rr", "unknown field"),
            ("[motor]\nR = \"a\"\n", 2, "motor.R", "invalid type"),
            ("[motor]\nR = 1e400\n", 2, "motor.R", "overflow"),
            ("[motorr]\nR = 1\n", 1, "motorr", "unknown field"),
            ("schema = 3\n", 1, "schema", "not supported"),
            ("schema = -1\n", 1, "schema", "u32"),
            ("\n[motor]\nL = 0.0\n", 3, "motor.L", "positive"),
            ("[motor]\nJ = -1e-5\n", 2, "motor.J", "positive"),
            ("[motor]\nc_m = nan\n", 2, "motor.c_m", "finite"),
            ("[motor]\nd = inf\n", 2, "motor.d", "finite"),
            (
                "[channels]\nspeed = \"w\"\n",
                2,
                "channels.speed",
                "unknown field",
            ),
        ];
        assert_errors(&cases);
        let e = parse("[motor\nR = 1\n").unwrap_err();
        assert_eq!(e.line, Some(1), "{e}");
    }

    #[test]
    fn schema_2_mistakes_name_their_line_and_key() {
        let cases = [
            (
                "schema = 2\n[terms.coulomb]\nT_c = 1.0\n",
                2,
                "terms.coulomb",
                "unknown term",
            ),
            (
                "schema = 2\n[terms.coulomb_friction]\nTc = 1.0\n",
                3,
                "terms.coulomb_friction.Tc",
                "unknown key",
            ),
            (
                "schema = 2\n[terms.coulomb_friction]\nomega_s = 0.0\n",
                2,
                "terms.coulomb_friction",
                "positive",
            ),
            (
                "schema = 2\n[calibrate]\n\"coulomb_friction.Tc\" = {}\n",
                3,
                "calibrate.coulomb_friction.Tc",
                "no parameter 'Tc'",
            ),
            (
                "schema = 2\n[calibrate]\nRR = {}\n",
                3,
                "calibrate.RR",
                "unknown parameter",
            ),
            (
                "schema = 2\n[calibrate]\nR = { prior = \"cauchy\", mean = 0.1 }\n",
                3,
                "calibrate.R.prior",
                "unknown prior family",
            ),
            (
                "schema = 2\n\n[calibrate]\nR = { prior = \"normal\", mean = 0.1 }\n",
                4,
                "calibrate.R.sd",
                "needs 'sd'",
            ),
            (
                "schema = 2\n[calibrate]\nR = { prior = \"normal\", mean = 0.1, sd = -1 }\n",
                3,
                "calibrate.R",
                "positive",
            ),
            (
                "schema = 2\n[calibrate]\nR = { prior = \"half_normal\", scale = 1, sd = 2 }\n",
                3,
                "calibrate.R.sd",
                "takes scale",
            ),
            ("[terms.speed_gain]\ng = 0.1\n", 1, "terms", "schema = 2"),
            (
                "schema = 2\n[discrepancy]\nbasis = \"fourier\"\n",
                3,
                "discrepancy.basis",
                "unknown basis",
            ),
            (
                "schema = 2\nbase = \"flux_driven\"\n",
                2,
                "base",
                "unknown base model",
            ),
            (
                "schema = 2\n[discrepancy]\nbasis = \"bspline\"\ndegree = 2\n",
                4,
                "discrepancy.degree",
                "B-spline basis needs degree",
            ),
            (
                "schema = 2\n[discrepancy]\ndegree = 99\n",
                3,
                "discrepancy.degree",
                "larger than",
            ),
        ];
        assert_errors(&cases);
    }

    #[test]
    fn a_schema_2_file_reads_back_to_the_same_values() {
        let text = "schema = 2\n[motor]\nR = 0.1\nc_g = 0.01\n[terms.coulomb_friction]\n\
                    T_c = 0.0\nomega_s = 1.0\n[calibrate]\nR = { prior = \"normal\", mean = 0.1, \
                    sd = 0.02 }\n\"coulomb_friction.T_c\" = { prior = \"half_normal\", scale = 0.5 }\n\
                    load_step.t_s = {}\n[discrepancy]\nbasis = \"legendre\"\ndegree = 9\n";
        let model = parse(text).unwrap();
        assert_eq!(model.schema, 2);
        // load_step is switched on by being calibrated; terms come in their canonical order.
        let names: Vec<&str> = model.terms.iter().map(|t| t.term.name()).collect();
        assert_eq!(names, ["coulomb_friction", "load_step"]);
        let calibrate = model.calibrate.as_ref().unwrap();
        assert_eq!(calibrate.len(), 3);
        assert_eq!(
            calibrate[1].prior,
            Some(crate::parameter::Prior::HalfNormal { scale: 0.5 })
        );
        assert_eq!(model.discrepancy.as_ref().unwrap().degree, 9);
        assert_eq!(parse(&to_toml_string(&model)).unwrap(), model);
        // A file with nothing of schema 2 is written as schema 1.
        assert!(to_toml_string(&ModelFile::default()).starts_with("schema = 1"));
    }

    #[test]
    fn the_toml_text_reads_back_to_the_same_values() {
        let mut model = ModelFile::default();
        model.motor.resistance = 1.0 / 3.0;
        model.motor.inertia = 1.234_567_890_123e-7;
        model.motor.voltage = 1e300;
        model.channels.speed = "w rad/s".into();
        let back = parse(&to_toml_string(&model)).unwrap();
        assert_eq!(back, model);
    }
}
