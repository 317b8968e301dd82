//! `Recording` and `Model`: a recording from a CSV file or from arrays, a model from a TOML file
//! or a dict. A recording is read for the model it is fitted with (its `[channels]` and base),
//! as the command line reads `--data` for `--model`.

use std::path::{Path, PathBuf};

use motorcal::error::{Error, InputError};
use motorcal::io::{ChannelMap, ModelFile, parse_model_file, read_model_file, read_recording_for};
use motorcal::motor::Base;
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::{py_error, to_json, to_python};

/// Where a recording's values come from.
#[derive(Clone, Debug)]
enum Source {
    /// A CSV file, read with a model's `[channels]` for its base.
    File(PathBuf),
    /// Columns by their model names (`t`, `I`, `omega`, `U`, `q`, `q_ref`, `force`,
    /// `disturbance`).
    Arrays(Vec<(String, Vec<f64>)>),
}

/// One measured run: sample times and the model's channels (and inputs) at those times.
#[pyclass(module = "motorcal", frozen, from_py_object)]
#[derive(Clone, Debug)]
pub struct Recording {
    source: Source,
    /// As read for `read_for` (the default channels and the voltage-driven motor unless a model
    /// was given).
    read: motorcal::io::Recording,
    read_for: (ChannelMap, Base),
}

impl Recording {
    /// The recording as a model reads it: its columns by the model's `[channels]` and base.
    pub fn for_model(&self, model: &ModelFile) -> Result<motorcal::io::Recording, Error> {
        if self.read_for == (model.channels.clone(), model.base) {
            return Ok(self.read.clone());
        }
        match &self.source {
            Source::File(path) => Ok(read_recording_for(path, &model.channels, model.base)?),
            Source::Arrays(columns) => Ok(from_columns(columns, model.base)?),
        }
    }
}

/// The columns a base reads: its channels, then (name, required) of its inputs.
fn inputs_of(base: Base) -> &'static [(&'static str, bool)] {
    match base {
        Base::VoltageDriven => &[("U", false)],
        Base::CurrentDriven => &[("I", true)],
        Base::PositionLoop => &[("q_ref", true), ("disturbance", false)],
    }
}

/// A recording from named columns, checked as the CSV reader checks a file: every column the
/// base needs, of one length, finite, at least two samples, times ≥ 0 and increasing.
fn from_columns(
    columns: &[(String, Vec<f64>)],
    base: Base,
) -> Result<motorcal::io::Recording, InputError> {
    let err = |field: &str, message: String| InputError::new("", message).for_field(field);
    let get = |name: &str| columns.iter().find(|(n, _)| n == name).map(|(_, v)| v);
    let given: Vec<&str> = columns.iter().map(|(n, _)| n.as_str()).collect();
    let require = |name: &str, role: &str| {
        get(name).ok_or_else(|| {
            err(
                name,
                format!(
                    "no {role} '{name}' (given: {}); a {} record needs {}",
                    given.join(", "),
                    base.name(),
                    needed(base).join(", ")
                ),
            )
        })
    };
    let time = require("t", "time")?;
    let n = time.len();
    for (name, values) in columns {
        if values.len() != n {
            return Err(err(name, format!("{} values, but t has {n}", values.len())));
        }
        if let Some((i, v)) = values.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(err(
                name,
                format!("value {v} at index {i} is not a finite number"),
            ));
        }
    }
    if n < 2 {
        return Err(err(
            "t",
            format!("only {n} samples; a recording needs at least 2"),
        ));
    }
    if time[0] < 0.0 {
        return Err(err("t", format!("time {} is negative", time[0])));
    }
    if let Some(i) = (1..n).find(|&i| time[i] <= time[i - 1]) {
        return Err(err(
            "t",
            format!(
                "time {} at index {i} does not increase (the one before is {}); samples must be \
                 in time order without repeats",
                time[i],
                time[i - 1]
            ),
        ));
    }
    let mut channels = Vec::new();
    for &name in base.channels() {
        channels.push((name.to_string(), require(name, "channel")?.clone()));
    }
    let mut voltage = None;
    let mut inputs = Vec::new();
    for &(name, required) in inputs_of(base) {
        let series = if required {
            Some(require(name, "input")?)
        } else {
            get(name)
        };
        match (series, base) {
            (Some(s), Base::VoltageDriven) => voltage = Some(s.clone()),
            (Some(s), _) => inputs.push((name.to_string(), s.clone())),
            (None, _) => {}
        }
    }
    Ok(motorcal::io::Recording {
        source: "arrays".into(),
        time: time.clone(),
        channels,
        voltage,
        inputs,
    })
}

fn needed(base: Base) -> Vec<&'static str> {
    let mut names = vec!["t"];
    names.extend(base.channels());
    names.extend(inputs_of(base).iter().filter(|(_, r)| *r).map(|(n, _)| *n));
    names
}

/// A 1-D float64 copy of an array-like, or a ValueError naming the field.
fn column(obj: &Bound<'_, PyAny>, field: &str) -> PyResult<Vec<f64>> {
    let py = obj.py();
    let kwargs = PyDict::new(py);
    kwargs.set_item("dtype", "float64")?;
    let array = py
        .import("numpy")?
        .call_method("ascontiguousarray", (obj,), Some(&kwargs))
        .map_err(|e| {
            py_error(Error::Input(
                InputError::new("", format!("not an array of numbers: {e}")).for_field(field),
            ))
        })?;
    let array = array.cast::<PyArray1<f64>>().map_err(|_| {
        let ndim = array
            .getattr("ndim")
            .and_then(|d| d.extract::<usize>())
            .unwrap_or(0);
        py_error(Error::Input(
            InputError::new("", format!("{ndim}-dimensional; a column is 1-dimensional"))
                .for_field(field),
        ))
    })?;
    Ok(array.readonly().as_slice()?.to_vec())
}

fn model_file(model: Option<&Model>) -> ModelFile {
    model.map(|m| m.file.clone()).unwrap_or_default()
}

#[pymethods]
impl Recording {
    /// A recording from a CSV file (`t`, `I`, `omega`[, `U`], or the columns `model`'s
    /// `[channels]` names for its base). Read now, so a bad file fails here; read again with
    /// another model's `[channels]` when fitted with one.
    #[staticmethod]
    #[pyo3(signature = (path, model=None))]
    fn from_csv(path: PathBuf, model: Option<&Model>) -> PyResult<Self> {
        let file = model_file(model);
        let read =
            read_recording_for(&path, &file.channels, file.base).map_err(|e| py_error(e.into()))?;
        Ok(Self {
            source: Source::File(path),
            read,
            read_for: (file.channels, file.base),
        })
    }

    /// A recording from arrays, by the model's channel names: `t`, `I`, `omega`, the voltage
    /// `U` (absent: the model's constant U), and for the drive bases `q`, `q_ref`, `force`,
    /// `disturbance`. The values are copied (float64).
    #[staticmethod]
    #[pyo3(signature = (t, I=None, omega=None, U=None, model=None, **more))]
    #[allow(non_snake_case)]
    fn from_arrays(
        t: &Bound<'_, PyAny>,
        I: Option<&Bound<'_, PyAny>>,
        omega: Option<&Bound<'_, PyAny>>,
        U: Option<&Bound<'_, PyAny>>,
        model: Option<&Model>,
        more: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let mut columns = vec![("t".to_string(), column(t, "t")?)];
        for (name, value) in [("I", I), ("omega", omega), ("U", U)] {
            if let Some(v) = value {
                columns.push((name.to_string(), column(v, name)?));
            }
        }
        for (key, value) in more.into_iter().flat_map(|d| d.iter()) {
            let name: String = key.extract()?;
            const KNOWN: [&str; 4] = ["q", "q_ref", "force", "disturbance"];
            if !KNOWN.contains(&name.as_str()) {
                return Err(py_error(Error::Input(
                    InputError::new(
                        "",
                        "not a channel or input (known: t, I, omega, U, q, q_ref, force, \
                         disturbance)",
                    )
                    .for_field(name),
                )));
            }
            columns.push((name.clone(), column(&value, &name)?));
        }
        let file = model_file(model);
        let read = from_columns(&columns, file.base).map_err(|e| py_error(e.into()))?;
        Ok(Self {
            source: Source::Arrays(columns),
            read,
            read_for: (file.channels, file.base),
        })
    }

    /// Where the recording came from (its path, or "arrays").
    #[getter]
    fn source(&self) -> String {
        match &self.source {
            Source::File(p) => p.display().to_string(),
            Source::Arrays(_) => "arrays".into(),
        }
    }

    /// The sample times.
    #[getter]
    fn t<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.read.time)
    }

    /// Every column by its model name (`t`, the channels, the voltage or inputs), as arrays.
    fn columns<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let out = PyDict::new(py);
        out.set_item("t", PyArray1::from_slice(py, &self.read.time))?;
        for (name, values) in self.read.channels.iter().chain(&self.read.inputs) {
            out.set_item(name, PyArray1::from_slice(py, values))?;
        }
        if let Some(u) = &self.read.voltage {
            out.set_item("U", PyArray1::from_slice(py, u))?;
        }
        Ok(out)
    }

    /// Writes the recording as CSV (`t`, the channels, `U` or the inputs) with round-trip
    /// precision.
    fn to_csv(&self, path: PathBuf) -> PyResult<()> {
        motorcal::io::write_recording(&path, &self.read).map_err(|e| py_error(e.into()))
    }

    fn __len__(&self) -> usize {
        self.read.n_samples()
    }

    fn __repr__(&self) -> String {
        let names: Vec<&str> = self.read.channels.iter().map(|(n, _)| n.as_str()).collect();
        format!(
            "Recording({}: {} samples of {}{})",
            self.source(),
            self.read.n_samples(),
            names.join(", "),
            if self.read.voltage.is_some() {
                ", U"
            } else {
                ""
            }
        )
    }
}

/// A model file: the nominal motor, its terms, what is calibrated with which prior, the
/// discrepancy, and which column is which.
#[pyclass(module = "motorcal", frozen, from_py_object)]
#[derive(Clone, Debug)]
pub struct Model {
    pub file: ModelFile,
    pub source: String,
}

#[pymethods]
impl Model {
    /// A model file (TOML, schema 1 or 2), checked as `motorcal fit --model` checks it.
    #[staticmethod]
    fn from_toml(path: PathBuf) -> PyResult<Self> {
        let file = read_model_file(&path).map_err(|e| py_error(e.into()))?;
        Ok(Self {
            file,
            source: path.display().to_string(),
        })
    }

    /// A model from a dict laid out as the TOML file is (`{"schema": 2, "motor": {...},
    /// "terms": {...}, "calibrate": {...}, ...}`); errors name the field.
    #[staticmethod]
    fn from_dict(d: &Bound<'_, PyDict>) -> PyResult<Self> {
        let value = to_json(d.as_any())?;
        let source = Path::new("dict");
        let bad = |m: String| py_error(Error::Input(InputError::new(source, m)));
        let toml_value: toml::Value = serde_json::from_value(value)
            .map_err(|e| bad(format!("not a model file's tables: {e}")))?;
        let text = toml::to_string(&toml_value)
            .map_err(|e| bad(format!("not a model file's tables: {e}")))?;
        // The line is the generated TOML's: the field names the place.
        let file =
            parse_model_file(&text, source).map_err(|e| py_error(e.at_line_opt(None).into()))?;
        Ok(Self {
            file,
            source: "dict".into(),
        })
    }

    /// The model file's text (TOML), as `motorcal` writes model files.
    fn to_toml(&self) -> String {
        motorcal::io::to_toml_string(&self.file)
    }

    /// The model as a dict laid out as its TOML file.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let value: toml::Value = toml::from_str(&self.to_toml())
            .map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))?;
        to_python(py, &value)
    }

    /// Writes the model file (TOML).
    fn write(&self, path: PathBuf) -> PyResult<()> {
        motorcal::io::write_model_file(&path, &self.file).map_err(|e| py_error(e.into()))
    }

    /// The terms switched on, by name.
    #[getter]
    fn terms<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        PyList::new(py, self.file.terms.iter().map(|t| t.term.name()))
    }

    /// The base: `voltage_driven`, `current_driven` or `position_loop`.
    #[getter]
    fn base(&self) -> &'static str {
        self.file.base.name()
    }

    fn __repr__(&self) -> String {
        format!(
            "Model({}: {} base, terms [{}])",
            self.source,
            self.base(),
            {
                let names: Vec<&str> = self.file.terms.iter().map(|t| t.term.name()).collect();
                names.join(", ")
            }
        )
    }
}

impl Recording {
    /// A recording the library made (a simulation), as read for `file`.
    pub fn from_library(read: motorcal::io::Recording, file: &ModelFile) -> Self {
        let mut columns = vec![("t".to_string(), read.time.clone())];
        columns.extend(read.channels.iter().cloned());
        columns.extend(read.inputs.iter().cloned());
        if let Some(u) = &read.voltage {
            columns.push(("U".into(), u.clone()));
        }
        Self {
            source: Source::Arrays(columns),
            read,
            read_for: (file.channels.clone(), file.base),
        }
    }
}
