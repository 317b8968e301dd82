//! motorcal from Python: thin bindings over the library (never `motorcal::app`). Recordings and
//! model files in, the posterior's log density and gradient, fits with the library's samplers,
//! the diagnosis, `bench` and `sweep`; the library's one-line errors as Python exceptions.
//! The Python side (`python/motorcal/__init__.py`) turns a fit into ArviZ's `InferenceData`.

use pyo3::exceptions::{PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;

mod background;
mod data;
mod fit;
mod posterior;
mod reports;

/// The library's error as Python's: input and settings it cannot use are `ValueError` with the
/// library's one line (file, line and field; a setting by its field name, which is the keyword
/// here), a numerical failure `RuntimeError`, output not written `OSError`.
pub(crate) fn py_error(e: motorcal::error::Error) -> PyErr {
    use motorcal::error::Error;
    match &e {
        Error::Input(_) | Error::Settings(_) => PyValueError::new_err(e.to_string()),
        Error::Numerical(_) => PyRuntimeError::new_err(e.to_string()),
        Error::Output(_) => PyOSError::new_err(e.to_string()),
    }
}

/// A settings error on the keyword `name`, as the library words one.
pub(crate) fn setting_error(name: &str, value: impl std::fmt::Display, message: &str) -> PyErr {
    py_error(motorcal::error::Error::setting(name, value, message))
}

/// A Python object as JSON-like data through Python's own `json` (a dict of a model file, …).
pub(crate) fn to_json(obj: &Bound<'_, PyAny>) -> PyResult<serde_json::Value> {
    let text: String = obj
        .py()
        .import("json")?
        .call_method1("dumps", (obj,))?
        .extract()?;
    serde_json::from_str(&text).map_err(|e| PyValueError::new_err(e.to_string()))
}

/// Serialisable library data (a report, records) as Python objects through `json.loads`:
/// floats round-trip exactly.
pub(crate) fn to_python<'py, T: serde::Serialize>(
    py: Python<'py>,
    value: &T,
) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(value).map_err(|e| PyValueError::new_err(e.to_string()))?;
    py.import("json")?.call_method1("loads", (text,))
}

#[pymodule]
fn _motorcal(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<data::Recording>()?;
    m.add_class::<data::Model>()?;
    m.add_class::<posterior::Posterior>()?;
    m.add_function(wrap_pyfunction!(posterior::log_density, m)?)?;
    m.add_function(wrap_pyfunction!(posterior::log_density_gradient, m)?)?;
    m.add_function(wrap_pyfunction!(fit::fit_raw, m)?)?;
    m.add_function(wrap_pyfunction!(reports::simulate, m)?)?;
    m.add_function(wrap_pyfunction!(reports::diagnose, m)?)?;
    m.add_function(wrap_pyfunction!(reports::bench, m)?)?;
    m.add_function(wrap_pyfunction!(reports::sweep, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("DEFAULT_SEED", motorcal::synthetic::DEFAULT_SEED)?;
    m.add(
        "SAMPLERS",
        motorcal::pipeline::SamplerKind::ALL
            .map(|s| s.name())
            .to_vec(),
    )?;
    Ok(())
}
