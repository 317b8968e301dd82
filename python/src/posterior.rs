//! The posterior a fit samples, from Python: its log density and gradient in the sampler's
//! unconstrained coordinates (the BridgeStan use: a user's own sampler on our posterior).

use motorcal::bayes::{CalibrationPosterior, CoefficientPrior, ModelSettings};
use motorcal::density::LogDensity;
use motorcal::error::Error;
use motorcal::pipeline::map_estimate;
use motorcal::study::Problem;
use numpy::{PyArray1, PyArrayMethods};
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::data::{Model, Recording};
use crate::py_error;

/// One recording or a list of them (extracted once per call: the size of one variant does not
/// matter).
#[derive(FromPyObject)]
#[allow(clippy::large_enum_variant)]
pub enum Recordings {
    One(Recording),
    Many(Vec<Recording>),
}

impl Recordings {
    fn list(&self) -> Vec<&Recording> {
        match self {
            Recordings::One(r) => vec![r],
            Recordings::Many(rs) => rs.iter().collect(),
        }
    }
}

/// What a model is calibrated as: BM1/BM2, K and the coefficients' prior, as `motorcal fit`'s
/// `--bm`, `--k`, `--prior-family` and `--prior-decay` say.
#[derive(Clone, Debug)]
pub struct Calibration {
    pub bm: Option<u8>,
    pub k: Option<usize>,
    pub prior_family: String,
    pub prior_decay: f64,
    pub force: bool,
}

/// The problem the recordings and the model pose, each recording read as the model reads it.
pub fn problem(recordings: &Recordings, model: &Model) -> Result<Problem, Error> {
    let list = recordings.list();
    if list.is_empty() {
        return Err(Error::setting("recordings", "", "no recording given"));
    }
    let recordings = list
        .iter()
        .map(|r| r.for_model(&model.file))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(Problem {
        label: recordings
            .iter()
            .map(|r| r.source.clone())
            .collect::<Vec<_>>()
            .join(" + "),
        recordings,
        model: model.file.clone(),
        reference: None,
    })
}

/// The plausibility check `fit` runs first: its findings as the error, unless `force`; with
/// `force` they are returned.
pub fn plausible(
    problem: &Problem,
    force: bool,
) -> Result<Vec<motorcal::study::plausibility::Finding>, Error> {
    let findings = motorcal::study::plausibility::check(problem)?;
    if findings.is_empty() || force {
        return Ok(findings);
    }
    let lines: Vec<String> = findings.iter().map(|f| f.to_string()).collect();
    Err(Error::invalid(format!(
        "{}\nthese recordings cannot be this motor as set up: check the files (or force=True)",
        lines.join("\n")
    )))
}

impl Calibration {
    /// The model settings: the model file's `[discrepancy]` unless `bm`/`k` say otherwise.
    pub fn settings(&self, problem: &Problem) -> Result<ModelSettings, Error> {
        if let Some(bm) = self.bm
            && !(1..=2).contains(&bm)
        {
            return Err(Error::setting("bm", bm, "expected 1 or 2"));
        }
        let mut settings = problem.model_settings(self.bm, self.k);
        settings.coefficient_prior = CoefficientPrior {
            family: self.prior_family.parse()?,
            decay_power: self.prior_decay,
            ..CoefficientPrior::default()
        };
        settings.validate().map_err(|e| match self.k {
            Some(k) => Error::setting("k", k, e),
            None => Error::invalid(e),
        })?;
        Ok(settings)
    }
}

/// The posterior of `model` on `recordings`, checked as `fit` checks them.
#[pyclass(module = "motorcal")]
pub struct Posterior {
    pub inner: CalibrationPosterior,
    pub settings: ModelSettings,
}

impl Posterior {
    pub fn build(
        recordings: &Recordings,
        model: &Model,
        calibration: &Calibration,
    ) -> Result<Self, Error> {
        let problem = problem(recordings, model)?;
        plausible(&problem, calibration.force)?;
        let settings = calibration.settings(&problem)?;
        let inner = problem.posterior(&settings)?;
        Ok(Self { inner, settings })
    }

    fn check_theta(&self, theta: &[f64]) -> PyResult<()> {
        if theta.len() != self.inner.dim() {
            return Err(py_error(Error::setting(
                "theta",
                format!("of length {}", theta.len()),
                format!(
                    "the posterior has {} coordinates ({})",
                    self.inner.dim(),
                    self.inner.parameter_names().join(", ")
                ),
            )));
        }
        Ok(())
    }
}

/// A density failure: a point where the solver gives up is outside the support for a sampler
/// (−∞, rejected as the library's samplers reject it); anything else is an error.
fn or_rejected(r: Result<f64, motorcal::density::DensityError>) -> PyResult<f64> {
    match r {
        Ok(v) => Ok(v),
        Err(e) if e.recoverable => Ok(f64::NEG_INFINITY),
        Err(e) => Err(PyRuntimeError::new_err(format!("numerical failure: {e}"))),
    }
}

fn theta_vec(theta: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
    let py = theta.py();
    let kwargs = PyDict::new(py);
    kwargs.set_item("dtype", "float64")?;
    let array = py
        .import("numpy")?
        .call_method("ascontiguousarray", (theta,), Some(&kwargs))?;
    let array = array.cast::<PyArray1<f64>>().map_err(|_| {
        py_error(Error::setting(
            "theta",
            "",
            "must be a 1-D array of numbers",
        ))
    })?;
    Ok(array.readonly().as_slice()?.to_vec())
}

#[pymethods]
impl Posterior {
    /// The posterior of BM1/BM2(K) of `model` on `recordings` (one or a list), as `motorcal
    /// fit` builds it for the same options.
    #[new]
    #[allow(clippy::too_many_arguments)]
    #[pyo3(signature = (recordings, model, bm=None, k=None, prior_family="laplace", prior_decay=0.0, force=false))]
    fn new(
        py: Python<'_>,
        recordings: Recordings,
        model: Model,
        bm: Option<u8>,
        k: Option<usize>,
        prior_family: &str,
        prior_decay: f64,
        force: bool,
    ) -> PyResult<Self> {
        let calibration = Calibration {
            bm,
            k,
            prior_family: prior_family.into(),
            prior_decay,
            force,
        };
        py.detach(|| Self::build(&recordings, &model, &calibration))
            .map_err(py_error)
    }

    /// The number of unconstrained coordinates.
    #[getter]
    fn dim(&self) -> usize {
        self.inner.dim()
    }

    /// Names of the unconstrained coordinates (`log_R`, `log_sigma_I`, `a_I.1`, …).
    #[getter]
    fn parameter_names(&self) -> Vec<String> {
        self.inner.parameter_names()
    }

    /// Names of the reported quantities (the draws' columns: `R`, `sigma_I`, …).
    #[getter]
    fn output_names(&self) -> Vec<String> {
        self.inner.output_names()
    }

    /// "BM1" or "BM2(K = 9)".
    #[getter]
    fn label(&self) -> String {
        self.settings.label()
    }

    /// log π(θ) up to a constant, θ unconstrained; −∞ outside the support or where the solver
    /// gives up.
    fn log_density(&mut self, py: Python<'_>, theta: &Bound<'_, PyAny>) -> PyResult<f64> {
        let theta = theta_vec(theta)?;
        self.check_theta(&theta)?;
        let inner = &mut self.inner;
        or_rejected(py.detach(|| inner.log_density(&theta)))
    }

    /// (log π(θ), ∇ log π(θ)), the gradient exact (forward sensitivities of the solver).
    fn log_density_gradient<'py>(
        &mut self,
        py: Python<'py>,
        theta: &Bound<'py, PyAny>,
    ) -> PyResult<(f64, Bound<'py, PyArray1<f64>>)> {
        let theta = theta_vec(theta)?;
        self.check_theta(&theta)?;
        let mut grad = vec![0.0; theta.len()];
        let inner = &mut self.inner;
        let lp = or_rejected(py.detach(|| inner.log_density_and_gradient(&theta, &mut grad)))?;
        Ok((lp, PyArray1::from_vec(py, grad)))
    }

    /// The reported quantities at θ (σ rather than log σ), in the order of `output_names`.
    fn constrain<'py>(
        &self,
        py: Python<'py>,
        theta: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let theta = theta_vec(theta)?;
        self.check_theta(&theta)?;
        let mut out = Vec::new();
        self.inner.constrain(&theta, &mut out);
        Ok(PyArray1::from_vec(py, out))
    }

    /// Where the MAP search starts (the nominal model, a least-squares δ, the noise left).
    fn initial_point<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let inner = &mut self.inner;
        let x = py
            .detach(|| inner.initial_point())
            .map_err(|e| PyRuntimeError::new_err(format!("numerical failure: {e}")))?;
        Ok(PyArray1::from_vec(py, x))
    }

    /// The MAP and its Laplace approximation: `{x, log_density, laplace_sd, hessian,
    /// log_evidence_laplace}` (x unconstrained).
    fn map<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let inner = &mut self.inner;
        let map = py.detach(|| map_estimate(inner)).map_err(py_error)?;
        let out = PyDict::new(py);
        out.set_item("x", PyArray1::from_slice(py, &map.x))?;
        out.set_item("log_density", map.log_density)?;
        out.set_item("laplace_sd", PyArray1::from_vec(py, map.laplace_sd()))?;
        let d = map.x.len();
        let hessian: Vec<f64> = map.hessian.transpose().iter().copied().collect();
        out.set_item("hessian", PyArray1::from_vec(py, hessian).reshape([d, d])?)?;
        out.set_item("log_evidence_laplace", map.log_evidence_laplace)?;
        Ok(out)
    }

    fn __repr__(&self) -> String {
        format!(
            "Posterior({}, {} coordinates)",
            self.settings.label(),
            self.inner.dim()
        )
    }
}

/// log π(θ) of BM1/BM2(K) of `model` on `recordings` (builds the posterior each call: keep a
/// `Posterior` for many points).
#[pyfunction]
#[pyo3(signature = (model, recordings, theta, bm=None, k=None, prior_family="laplace", prior_decay=0.0, force=false))]
#[allow(clippy::too_many_arguments)]
pub fn log_density(
    py: Python<'_>,
    model: Model,
    recordings: Recordings,
    theta: &Bound<'_, PyAny>,
    bm: Option<u8>,
    k: Option<usize>,
    prior_family: &str,
    prior_decay: f64,
    force: bool,
) -> PyResult<f64> {
    let mut p = Posterior::new(
        py,
        recordings,
        model,
        bm,
        k,
        prior_family,
        prior_decay,
        force,
    )?;
    p.log_density(py, theta)
}

/// (log π(θ), ∇ log π(θ)) of BM1/BM2(K) of `model` on `recordings`.
#[pyfunction]
#[pyo3(signature = (model, recordings, theta, bm=None, k=None, prior_family="laplace", prior_decay=0.0, force=false))]
#[allow(clippy::too_many_arguments)]
pub fn log_density_gradient<'py>(
    py: Python<'py>,
    model: Model,
    recordings: Recordings,
    theta: &Bound<'py, PyAny>,
    bm: Option<u8>,
    k: Option<usize>,
    prior_family: &str,
    prior_decay: f64,
    force: bool,
) -> PyResult<(f64, Bound<'py, PyArray1<f64>>)> {
    let mut p = Posterior::new(
        py,
        recordings,
        model,
        bm,
        k,
        prior_family,
        prior_decay,
        force,
    )?;
    p.log_density_gradient(py, theta)
}
