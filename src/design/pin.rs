//! The pin objective: D-optimal design on the Fisher matrix FᵢⱼΣ = Σ_rows wᵣ² ∂Gᵣ/∂θᵢ ∂Gᵣ/∂θⱼ
//! from the forward sensitivities, for named parameters or a ratio of two (`c_g/J`, which a
//! record of I and ω identifies where c_g and J alone it may not). The expected posterior sd of
//! a target g(θ) is √(∇gᵀ F⁺ ∇g) (the pseudo-inverse, valid when ∇g lies in F's range; a target
//! with a component in F's null space is not identifiable and its sd is infinite); the search
//! minimises ln det of the targets' covariance.

use std::collections::BTreeMap;

use nalgebra::{DMatrix, DVector};

use crate::error::Error;
use crate::forward::ForwardModel;
use crate::io::CalibrateEntry;
use crate::motor::VoltageInput;
use crate::parameter::ParamId;
use crate::study::Problem;

use super::experiment::{Candidate, Experiment};
use super::limits::Limits;

/// A quantity to pin: a parameter, or the ratio of two.
#[derive(Clone, Debug, PartialEq)]
pub enum Target {
    Parameter(String),
    Ratio(String, String),
}

impl Target {
    pub fn parse(text: &str) -> Self {
        match text.split_once('/') {
            Some((a, b)) => Target::Ratio(a.trim().into(), b.trim().into()),
            None => Target::Parameter(text.trim().into()),
        }
    }

    pub fn name(&self) -> String {
        match self {
            Target::Parameter(p) => p.clone(),
            Target::Ratio(a, b) => format!("{a}/{b}"),
        }
    }

    fn parameters(&self) -> Vec<&str> {
        match self {
            Target::Parameter(p) => vec![p],
            Target::Ratio(a, b) => vec![a, b],
        }
    }
}

/// The model at its values with what it calibrates and every parameter the targets name
/// calibrated too: the candidate whose Fisher matrix the design is judged on.
pub fn pin_candidate(
    base: &Problem,
    values: &BTreeMap<String, f64>,
    targets: &[Target],
) -> Result<Candidate, Error> {
    let mut problem = base.clone();
    calibrate_targets(&mut problem, targets)?;
    for (key, &v) in values {
        problem.model.set_value(&ParamId::parse(key), v);
    }
    let calibrated = problem.calibrated_names()?;
    let forward = problem.forward(crate::ode::SolverSettings::default())?;
    Ok(Candidate {
        name: "model".into(),
        added: Vec::new(),
        theta: forward.nominal_calibrated(),
        calibrated,
        problem,
    })
}

/// `problem` with every parameter the targets name calibrated beside what it calibrates (R
/// alone where it names nothing); a target the model has no parameter for is one error.
fn calibrate_targets(problem: &mut Problem, targets: &[Target]) -> Result<(), Error> {
    let known = problem.model_for(problem.recording())?.parameter_names();
    let calibrate = problem.model.calibrate.get_or_insert_with(|| {
        vec![CalibrateEntry {
            id: ParamId::parse("R"),
            prior: None,
        }]
    });
    for t in targets {
        for p in t.parameters() {
            if !known.iter().any(|k| k == p) {
                return Err(Error::setting(
                    "pin",
                    t.name(),
                    format!(
                        "unknown parameter '{p}' (the model has {})",
                        known.join(", ")
                    ),
                ));
            }
            let id = ParamId::parse(p);
            if !calibrate.iter().any(|e| e.id == id) {
                calibrate.push(CalibrateEntry { id, prior: None });
            }
        }
    }
    if problem.model.schema < 2 {
        problem.model.schema = 2;
    }
    Ok(())
}

/// Where the recordings put the model: the MAP of BM1 on `recorded` (the model as given, the
/// targets calibrated beside what it calibrates) and σ per channel from that fit. A design
/// then pins the targets where the rig is, not where the model file guessed (its Fisher
/// matrix depends on the values: c_g/J's sd on the speed the motor reaches).
pub fn pin_values_from(
    recorded: &Problem,
    targets: &[Target],
) -> Result<(BTreeMap<String, f64>, Vec<f64>), Error> {
    let mut problem = recorded.clone();
    calibrate_targets(&mut problem, targets)?;
    let fit = crate::discover::fit_candidate(&problem, &[])?;
    Ok((fit.theta.clone(), fit.noise_sd()))
}

/// Fᵢⱼ = Σᵣ wᵣ² Jᵣᵢ Jᵣⱼ at θ.
pub fn fisher(
    forward: &ForwardModel,
    theta: &[f64],
    weights: &[f64],
) -> Result<DMatrix<f64>, Error> {
    let n = forward.n_outputs();
    let mut out = vec![0.0; n];
    let mut jac = DMatrix::zeros(n, theta.len());
    forward
        .simulate_with_sensitivities(theta, &mut out, &mut jac)
        .map_err(|e| Error::Numerical(e.to_string()))?;
    for (r, w) in weights.iter().enumerate() {
        for c in 0..theta.len() {
            jac[(r, c)] *= w;
        }
    }
    Ok(jac.transpose() * jac)
}

/// The targets' expected posterior sds under an input, and the ln det of their covariance
/// (the D-criterion; +∞ when a target is not identifiable).
#[derive(Clone, Debug, serde::Serialize)]
pub struct Pinned {
    pub sd: BTreeMap<String, f64>,
    /// sd over |value|.
    pub relative_sd: BTreeMap<String, f64>,
    pub log_det: f64,
}

pub fn pinned(
    candidate: &Candidate,
    experiment: &Experiment,
    targets: &[Target],
    input: &VoltageInput,
) -> Result<Pinned, Error> {
    let forward = candidate.forward(input, &experiment.times)?;
    let f = fisher(&forward, &candidate.theta, &experiment.weights())?;
    let d = candidate.theta.len();
    let index = |p: &str| candidate.calibrated.iter().position(|c| c == p);
    let mut grads = Vec::new();
    let mut values = Vec::new();
    for t in targets {
        let mut g = DVector::zeros(d);
        let value = match t {
            Target::Parameter(p) => {
                let i = index(p).ok_or_else(|| Error::invalid(format!("{p} is not calibrated")))?;
                g[i] = 1.0;
                candidate.theta[i]
            }
            Target::Ratio(a, b) => {
                let (i, j) = (
                    index(a).ok_or_else(|| Error::invalid(format!("{a} is not calibrated")))?,
                    index(b).ok_or_else(|| Error::invalid(format!("{b} is not calibrated")))?,
                );
                let (x, y) = (candidate.theta[i], candidate.theta[j]);
                g[i] = 1.0 / y;
                g[j] = -x / (y * y);
                x / y
            }
        };
        grads.push(g);
        values.push(value);
    }
    // In the basis where each parameter's own information is one: a parameter known to a
    // micrometre (a position offset) beside one known to a kilogram would otherwise put the
    // second's eigenvalue under the tolerance of the first's.
    let scale: Vec<f64> = (0..d)
        .map(|i| {
            let fii = f[(i, i)];
            if fii > 0.0 { 1.0 / fii.sqrt() } else { 1.0 }
        })
        .collect();
    let f = DMatrix::from_fn(d, d, |i, j| f[(i, j)] * scale[i] * scale[j]);
    for g in &mut grads {
        for (gi, si) in g.iter_mut().zip(&scale) {
            *gi *= si;
        }
    }
    let eig = f.symmetric_eigen();
    let top = eig.eigenvalues.iter().fold(0.0f64, |a, &l| a.max(l));
    let mut cov = DMatrix::<f64>::zeros(targets.len(), targets.len());
    let mut identifiable = top > 0.0;
    for (k, lambda) in eig.eigenvalues.iter().enumerate() {
        let v = eig.eigenvectors.column(k);
        let proj: Vec<f64> = grads.iter().map(|g| v.dot(g)).collect();
        if *lambda <= 1e-12 * top {
            let scale = grads.iter().map(|g| g.norm()).fold(0.0, f64::max);
            if proj.iter().any(|p| p.abs() > 1e-6 * scale) {
                identifiable = false;
            }
            continue;
        }
        for a in 0..targets.len() {
            for b in 0..targets.len() {
                cov[(a, b)] += proj[a] * proj[b] / lambda;
            }
        }
    }
    let mut sd = BTreeMap::new();
    let mut relative_sd = BTreeMap::new();
    for (k, t) in targets.iter().enumerate() {
        let s = if identifiable {
            cov[(k, k)].max(0.0).sqrt()
        } else {
            f64::INFINITY
        };
        sd.insert(t.name(), s);
        relative_sd.insert(t.name(), s / values[k].abs());
    }
    let log_det = match (identifiable, cov.clone().cholesky()) {
        (true, Some(c)) => 2.0 * c.l().diagonal().iter().map(|x| x.ln()).sum::<f64>(),
        _ => f64::INFINITY,
    };
    Ok(Pinned {
        sd,
        relative_sd,
        log_det,
    })
}

/// The search's objective for pinning: ln det of the targets' covariance, or how far the
/// model's prediction passes the limits.
pub fn pin_cost(
    candidate: &Candidate,
    experiment: &Experiment,
    targets: &[Target],
    input: &VoltageInput,
    limits: &Limits,
) -> Result<Result<f64, f64>, Error> {
    let forward = candidate.forward(input, &experiment.times)?;
    let mut y = vec![0.0; forward.n_outputs()];
    forward
        .simulate(&candidate.theta, &mut y)
        .map_err(|e| Error::Numerical(e.to_string()))?;
    let excess = limits.excess(forward.channels(), &y, &experiment.times);
    if excess > 0.0 {
        return Ok(Err(excess));
    }
    Ok(Ok(pinned(candidate, experiment, targets, input)?.log_det))
}
