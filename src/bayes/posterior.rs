//! The posterior of BM1/BM2 (eqs. 12–22) over the unconstrained coordinates
//! x = (θ, log σ per record and channel, discrepancy coefficients per record and channel).
//!
//! The likelihood is per channel and per recording, each with its own noise level; the
//! discrepancy basis is per channel. The gradient in θ comes from the forward sensitivities,
//! the one in a is exact (δ is linear in a), and G(θ) is computed once per θ, not once per
//! coefficient: a cache keeps it while only σ or a move.

use std::ops::Range;

use nalgebra::DMatrix;

use super::basis::{DiscrepancyBasis, Legendre};
use super::prior::Prior;
use super::settings::ModelSettings;
use crate::density::{DensityError, FisherMetric, LogDensity};
use crate::forward::ForwardModel;
use crate::motor::MotorParam;

const LN_2PI: f64 = 1.837_877_066_409_345_5;

/// Measured channels of one recording, in the forward model's channel order.
#[derive(Clone, Debug)]
pub struct Observations {
    pub label: String,
    pub channels: Vec<Vec<f64>>,
}

#[derive(Clone, Debug)]
struct Discrepancy {
    description: String,
    /// B[i, j] = p_j(t_i).
    basis: DMatrix<f64>,
    /// BᵀB, for the metric.
    gram: DMatrix<f64>,
    offset: usize,
    priors: Vec<Prior>,
}

#[derive(Clone, Debug)]
struct ChannelTerm {
    name: String,
    observed: Vec<f64>,
    log_sigma_index: usize,
    discrepancy: Option<Discrepancy>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Cached {
    Nothing,
    Values,
    WithSensitivities,
}

#[derive(Clone, Debug)]
struct RecordTerm {
    label: String,
    forward: ForwardModel,
    channels: Vec<ChannelTerm>,
    cached: Cached,
    cached_theta: Vec<f64>,
    /// The solve before the current one, kept so that a rejected proposal in θ costs no
    /// second solve when the chain's next evaluation returns to the old θ (the paper's
    /// variable-at-a-time Metropolis does exactly that, several times a sweep).
    previous: Cached,
    previous_theta: Vec<f64>,
    previous_outputs: Vec<f64>,
    previous_jacobian: DMatrix<f64>,
    outputs: Vec<f64>,
    jacobian: DMatrix<f64>,
    residual: Vec<f64>,
}

impl RecordTerm {
    fn ensure_forward(&mut self, theta: &[f64], sensitivities: bool) -> Result<(), DensityError> {
        let usable = |kind: Cached, at: &[f64]| {
            kind != Cached::Nothing
                && at == theta
                && (!sensitivities || kind == Cached::WithSensitivities)
        };
        if usable(self.cached, &self.cached_theta) {
            return Ok(());
        }
        // Whatever happens next, the current solve becomes the previous one.
        std::mem::swap(&mut self.cached, &mut self.previous);
        std::mem::swap(&mut self.cached_theta, &mut self.previous_theta);
        std::mem::swap(&mut self.outputs, &mut self.previous_outputs);
        std::mem::swap(&mut self.jacobian, &mut self.previous_jacobian);
        if usable(self.cached, &self.cached_theta) {
            return Ok(());
        }
        self.cached = Cached::Nothing;
        let result = if sensitivities {
            self.forward
                .simulate_with_sensitivities(theta, &mut self.outputs, &mut self.jacobian)
        } else {
            self.forward.simulate(theta, &mut self.outputs)
        };
        result.map_err(|e| DensityError::recoverable(format!("{}: {e}", self.label)))?;
        self.cached_theta.clear();
        self.cached_theta.extend_from_slice(theta);
        self.cached = if sensitivities {
            Cached::WithSensitivities
        } else {
            Cached::Values
        };
        Ok(())
    }

    /// Fills `residual` with y − G(θ) − δ(a) for channel `c`.
    fn residual(&mut self, c: usize, x: &[f64]) {
        let m = self.forward.n_samples();
        let ch = &self.channels[c];
        let g = &self.outputs[c * m..(c + 1) * m];
        for ((r, &y), &gi) in self.residual.iter_mut().zip(&ch.observed).zip(g) {
            *r = y - gi;
        }
        if let Some(d) = &ch.discrepancy {
            let coefficients = &x[d.offset..d.offset + d.priors.len()];
            for (j, &a) in coefficients.iter().enumerate() {
                let column = column_rows(&d.basis, j, 0..m);
                for (r, &b) in self.residual.iter_mut().zip(column) {
                    *r -= a * b;
                }
            }
        }
    }
}

/// The posterior of one or several recordings under BM1 or BM2(K).
#[derive(Clone, Debug)]
pub struct CalibrationPosterior {
    settings: ModelSettings,
    theta_names: Vec<String>,
    theta_priors: Vec<Prior>,
    theta_positive: Vec<bool>,
    noise_prior: Prior,
    records: Vec<RecordTerm>,
    dim: usize,
    names: Vec<String>,
    output_names: Vec<String>,
    blocks: Vec<Range<usize>>,
}

impl CalibrationPosterior {
    /// Builds the posterior. Every record's forward model must calibrate the same parameters.
    pub fn new(
        records: Vec<(ForwardModel, Observations)>,
        settings: &ModelSettings,
    ) -> Result<Self, String> {
        settings.validate()?;
        let Some((first, _)) = records.first() else {
            return Err("no recordings".into());
        };
        let theta_names: Vec<String> = first
            .calibrated_names()
            .iter()
            .map(|s| s.to_string())
            .collect();
        let nominal = first.nominal_calibrated();
        let mut theta_priors = Vec::new();
        let mut theta_positive = Vec::new();
        for (name, &value) in theta_names.iter().zip(&nominal) {
            // Every calibrated motor parameter gets the paper's prior of R: centred on the
            // nominal value, with a spread proportional to it.
            theta_priors.push(settings.resistance_prior(value.abs()));
            theta_positive.push(MotorParam::from_key(name).is_some_and(|p| p.must_be_positive()));
        }
        let noise_prior = Prior::InverseGamma {
            shape: settings.noise_prior_shape,
            scale: settings.noise_prior_scale,
        };

        let several = records.len() > 1;
        let mut names: Vec<String> = theta_names.clone();
        let mut output_names: Vec<String> = theta_names.clone();
        let mut blocks: Vec<Range<usize>> = (0..theta_names.len()).map(|i| i..i + 1).collect();
        let mut next = theta_names.len();
        let mut terms = Vec::new();
        let mut pending_coefficients = Vec::new();
        for (r, (forward, obs)) in records.into_iter().enumerate() {
            if forward.calibrated_names() != first_names(&theta_names) {
                return Err(format!(
                    "recording '{}' calibrates other parameters than the first",
                    obs.label
                ));
            }
            let channel_names = forward.channels();
            if obs.channels.len() != channel_names.len() {
                return Err(format!(
                    "recording '{}' has {} channels, the model measures {}",
                    obs.label,
                    obs.channels.len(),
                    channel_names.len()
                ));
            }
            let m = forward.n_samples();
            let suffix = if several {
                format!("_r{}", r + 1)
            } else {
                String::new()
            };
            let mut channels = Vec::new();
            for (name, observed) in channel_names.iter().zip(obs.channels) {
                if observed.len() != m {
                    return Err(format!(
                        "recording '{}', channel {name}: {} values for {m} times",
                        obs.label,
                        observed.len()
                    ));
                }
                names.push(format!("log_sigma_{name}{suffix}"));
                output_names.push(format!("sigma_{name}{suffix}"));
                blocks.push(next..next + 1);
                channels.push(ChannelTerm {
                    name: name.to_string(),
                    observed,
                    log_sigma_index: next,
                    discrepancy: None,
                });
                next += 1;
            }
            if let Some(k) = settings.discrepancy_degree {
                let t_end = *forward.times().last().expect("times are non-empty");
                let basis = Legendre::new(k, t_end)?;
                for c in 0..channels.len() {
                    pending_coefficients.push((terms.len(), c, basis.clone(), suffix.clone()));
                }
            }
            let n_out = forward.n_outputs();
            let n_par = forward.n_calibrated();
            terms.push(RecordTerm {
                label: obs.label,
                channels,
                cached: Cached::Nothing,
                cached_theta: Vec::new(),
                previous: Cached::Nothing,
                previous_theta: Vec::new(),
                previous_outputs: vec![0.0; n_out],
                previous_jacobian: DMatrix::zeros(n_out, n_par),
                outputs: vec![0.0; n_out],
                jacobian: DMatrix::zeros(n_out, n_par),
                residual: vec![0.0; m],
                forward,
            });
        }
        // Coefficients come last, after every σ, so that the small, well-identified
        // coordinates lead the parameter vector as in the paper's tables.
        for (r, c, basis, suffix) in pending_coefficients {
            let term = &mut terms[r];
            let n = basis.n_functions();
            let b = basis.matrix(term.forward.times());
            let gram = b.transpose() * &b;
            let ch = &mut term.channels[c];
            for j in 0..n {
                let name = format!("a_{}{suffix}.{}", ch.name, j + 1);
                names.push(name.clone());
                output_names.push(name);
            }
            blocks.push(next..next + n);
            ch.discrepancy = Some(Discrepancy {
                description: basis.describe(),
                basis: b,
                gram,
                offset: next,
                priors: (0..n)
                    .map(|j| settings.coefficient_prior.prior(j))
                    .collect(),
            });
            next += n;
        }
        Ok(Self {
            settings: settings.clone(),
            theta_names,
            theta_priors,
            theta_positive,
            noise_prior,
            records: terms,
            dim: next,
            names,
            output_names,
            blocks,
        })
    }

    pub fn settings(&self) -> &ModelSettings {
        &self.settings
    }

    pub fn n_theta(&self) -> usize {
        self.theta_names.len()
    }

    pub fn theta_names(&self) -> &[String] {
        &self.theta_names
    }

    /// Number of reported quantities (equal to the dimension: one per coordinate).
    pub fn dim_of_outputs(&self) -> usize {
        self.output_names.len()
    }

    pub fn n_records(&self) -> usize {
        self.records.len()
    }

    pub fn forward(&self, record: usize) -> &ForwardModel {
        &self.records[record].forward
    }

    pub fn observed(&self, record: usize, channel: usize) -> &[f64] {
        &self.records[record].channels[channel].observed
    }

    /// Index of log σ of a record's channel in x.
    pub fn log_sigma_index(&self, record: usize, channel: usize) -> usize {
        self.records[record].channels[channel].log_sigma_index
    }

    /// Range of a record's channel's discrepancy coefficients in x.
    pub fn coefficient_range(&self, record: usize, channel: usize) -> Option<Range<usize>> {
        let d = self.records[record].channels[channel]
            .discrepancy
            .as_ref()?;
        Some(d.offset..d.offset + d.priors.len())
    }

    pub fn discrepancy_description(&self) -> Option<String> {
        self.records
            .first()?
            .channels
            .first()?
            .discrepancy
            .as_ref()
            .map(|d| d.description.clone())
    }

    /// δ of a record's channel at the sample times for the coefficients in x (zeros in BM1).
    pub fn discrepancy(&self, x: &[f64], record: usize, channel: usize) -> Vec<f64> {
        let ch = &self.records[record].channels[channel];
        match &ch.discrepancy {
            None => vec![0.0; ch.observed.len()],
            Some(d) => {
                let a =
                    nalgebra::DVector::from_column_slice(&x[d.offset..d.offset + d.priors.len()]);
                (&d.basis * a).as_slice().to_vec()
            }
        }
    }

    /// G(θ) of a record (channel-major), at the θ in x.
    pub fn simulate(&mut self, x: &[f64], record: usize) -> Result<Vec<f64>, DensityError> {
        let p = self.n_theta();
        let term = &mut self.records[record];
        term.ensure_forward(&x[..p], false)?;
        Ok(term.outputs.clone())
    }

    /// A sensible start: nominal θ, the discrepancy that least-squares fits the nominal
    /// residual, and the noise level of what is left.
    pub fn initial_point(&mut self) -> Result<Vec<f64>, DensityError> {
        let mut x = vec![0.0; self.dim];
        let p = self.n_theta();
        x[..p].copy_from_slice(&self.records[0].forward.nominal_calibrated());
        for term in &mut self.records {
            term.ensure_forward(&x[..p], false)?;
            for c in 0..term.channels.len() {
                term.residual(c, &x);
                if let Some(d) = &term.channels[c].discrepancy {
                    let rhs =
                        d.basis.transpose() * nalgebra::DVector::from_column_slice(&term.residual);
                    let ridge = DMatrix::from_diagonal_element(
                        d.gram.nrows(),
                        d.gram.nrows(),
                        1e-9 * d.gram.trace(),
                    );
                    if let Some(chol) = (&d.gram + ridge).cholesky() {
                        let a = chol.solve(&rhs);
                        x[d.offset..d.offset + a.len()].copy_from_slice(a.as_slice());
                    }
                    term.residual(c, &x);
                }
                let m = term.residual.len() as f64;
                let rms = (term.residual.iter().map(|r| r * r).sum::<f64>() / m).sqrt();
                let scale = term.channels[c]
                    .observed
                    .iter()
                    .map(|v| v.abs())
                    .fold(0.0, f64::max);
                x[term.channels[c].log_sigma_index] = rms.max(1e-6 * scale.max(1e-300)).ln();
            }
        }
        Ok(x)
    }

    fn evaluate(&mut self, x: &[f64], mut grad: Option<&mut [f64]>) -> Result<f64, DensityError> {
        if x.len() != self.dim {
            return Err(DensityError::fatal(format!(
                "point of dimension {} for a density of dimension {}",
                x.len(),
                self.dim
            )));
        }
        if let Some(g) = grad.as_deref_mut() {
            g.fill(0.0);
        }
        let p = self.n_theta();
        let theta = &x[..p];
        if x.iter().any(|v| !v.is_finite()) {
            return Ok(f64::NEG_INFINITY);
        }
        for (k, &v) in theta.iter().enumerate() {
            if self.theta_positive[k] && v <= 0.0 {
                return Ok(f64::NEG_INFINITY);
            }
        }
        let mut lp = 0.0;
        for (k, &v) in theta.iter().enumerate() {
            lp += self.theta_priors[k].log_density(v);
            if let Some(g) = grad.as_deref_mut() {
                g[k] += self.theta_priors[k].gradient(v);
            }
        }
        let need_sensitivities = grad.is_some();
        for term in &mut self.records {
            term.ensure_forward(theta, need_sensitivities)?;
            let m = term.forward.n_samples();
            for c in 0..term.channels.len() {
                term.residual(c, x);
                let ch = &term.channels[c];
                let s = x[ch.log_sigma_index];
                let sigma = s.exp();
                let inv_var = (-2.0 * s).exp();
                let ss: f64 = term.residual.iter().map(|r| r * r).sum();
                // Likelihood, the InvGamma prior on σ, and the Jacobian of σ = exp(s).
                lp += -(m as f64) * (s + 0.5 * LN_2PI) - 0.5 * ss * inv_var;
                lp += self.noise_prior.log_density(sigma) + s;
                if let Some(g) = grad.as_deref_mut() {
                    g[ch.log_sigma_index] +=
                        -(m as f64) + ss * inv_var + self.noise_prior.gradient(sigma) * sigma + 1.0;
                    for k in 0..p {
                        let sens = column_rows(&term.jacobian, k, c * m..(c + 1) * m);
                        g[k] += inv_var * dot(sens, &term.residual);
                    }
                }
                if let Some(d) = &ch.discrepancy {
                    for (j, prior) in d.priors.iter().enumerate() {
                        let a = x[d.offset + j];
                        lp += prior.log_density(a);
                        if let Some(g) = grad.as_deref_mut() {
                            g[d.offset + j] += inv_var
                                * dot(d.basis.column(j).as_slice(), &term.residual)
                                + prior.gradient(a);
                        }
                    }
                }
            }
        }
        Ok(lp)
    }
}

fn first_names(names: &[String]) -> Vec<&str> {
    names.iter().map(|s| s.as_str()).collect()
}

/// Rows `rows` of column `k` of a column-major matrix, as a slice.
fn column_rows(matrix: &DMatrix<f64>, k: usize, rows: Range<usize>) -> &[f64] {
    let n = matrix.nrows();
    &matrix.as_slice()[k * n + rows.start..k * n + rows.end]
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

impl LogDensity for CalibrationPosterior {
    fn dim(&self) -> usize {
        self.dim
    }

    fn parameter_names(&self) -> Vec<String> {
        self.names.clone()
    }

    fn log_density(&mut self, x: &[f64]) -> Result<f64, DensityError> {
        self.evaluate(x, None)
    }

    fn log_density_and_gradient(
        &mut self,
        x: &[f64],
        grad: &mut [f64],
    ) -> Result<f64, DensityError> {
        self.evaluate(x, Some(grad))
    }

    fn output_names(&self) -> Vec<String> {
        self.output_names.clone()
    }

    fn constrain(&self, x: &[f64], out: &mut Vec<f64>) {
        out.clear();
        out.extend_from_slice(x);
        for term in &self.records {
            for ch in &term.channels {
                out[ch.log_sigma_index] = x[ch.log_sigma_index].exp();
            }
        }
    }

    fn blocks(&self) -> Vec<Range<usize>> {
        self.blocks.clone()
    }
}

impl FisherMetric for CalibrationPosterior {
    /// Σ_c σ_c⁻² [J_c B_c]ᵀ[J_c B_c] in (θ, a_c), 2·M_c for each log σ_c, plus the priors'
    /// curvature (zero for Laplace coefficients: their kink is not a curvature).
    fn fisher_metric(&mut self, x: &[f64], metric: &mut DMatrix<f64>) -> Result<(), DensityError> {
        let p = self.n_theta();
        metric.fill(0.0);
        let theta = &x[..p];
        for (k, &v) in theta.iter().enumerate() {
            metric[(k, k)] += self.theta_priors[k].curvature(v);
        }
        for term in &mut self.records {
            term.ensure_forward(theta, true)?;
            let m = term.forward.n_samples();
            for ch_index in 0..term.channels.len() {
                let ch = &term.channels[ch_index];
                let s = x[ch.log_sigma_index];
                let inv_var = (-2.0 * s).exp();
                let sigma = s.exp();
                // d²/ds² of −[log p(σ) + s] at σ = e^s for InvGamma(α, β): β/σ.
                let prior_curv = match self.noise_prior {
                    Prior::InverseGamma { scale, .. } => scale / sigma,
                    _ => 0.0,
                };
                metric[(ch.log_sigma_index, ch.log_sigma_index)] += 2.0 * m as f64 + prior_curv;
                let rows = ch_index * m..(ch_index + 1) * m;
                for k in 0..p {
                    let jk = column_rows(&term.jacobian, k, rows.clone());
                    for l in 0..=k {
                        let jl = column_rows(&term.jacobian, l, rows.clone());
                        let v = inv_var * dot(jk, jl);
                        metric[(k, l)] += v;
                        if l != k {
                            metric[(l, k)] += v;
                        }
                    }
                }
                if let Some(d) = &ch.discrepancy {
                    let n = d.priors.len();
                    for j in 0..n {
                        let bj = d.basis.column(j);
                        for k in 0..p {
                            let jk = column_rows(&term.jacobian, k, rows.clone());
                            let v = inv_var * dot(jk, bj.as_slice());
                            metric[(k, d.offset + j)] += v;
                            metric[(d.offset + j, k)] += v;
                        }
                        for i in 0..n {
                            metric[(d.offset + i, d.offset + j)] += inv_var * d.gram[(i, j)];
                        }
                        metric[(d.offset + j, d.offset + j)] +=
                            d.priors[j].curvature(x[d.offset + j]);
                    }
                }
            }
        }
        Ok(())
    }

    /// The metric with the noise-scale rows made exact: −∂²log π/∂s² = 2·SS/σ² (not its
    /// expectation 2M) and the couplings 2Jᵀr/σ², 2Bᵀr/σ² of log σ with θ and a. At the mode
    /// Bᵀr/σ² equals the Laplace prior's pull ±1/b, which the weakly identified R–δ direction
    /// feels; the residual curvature of G in θ is still left out.
    fn observed_information(
        &mut self,
        x: &[f64],
        out: &mut DMatrix<f64>,
    ) -> Result<(), DensityError> {
        self.fisher_metric(x, out)?;
        let p = self.n_theta();
        for term in &mut self.records {
            let m = term.forward.n_samples();
            for c in 0..term.channels.len() {
                term.residual(c, x);
                let ch = &term.channels[c];
                let si = ch.log_sigma_index;
                let inv_var = (-2.0 * x[si]).exp();
                let ss: f64 = term.residual.iter().map(|r| r * r).sum();
                out[(si, si)] += 2.0 * ss * inv_var - 2.0 * m as f64;
                for k in 0..p {
                    let v = 2.0
                        * inv_var
                        * dot(
                            column_rows(&term.jacobian, k, c * m..(c + 1) * m),
                            &term.residual,
                        );
                    out[(si, k)] += v;
                    out[(k, si)] += v;
                }
                if let Some(d) = &ch.discrepancy {
                    for j in 0..d.priors.len() {
                        let v = 2.0 * inv_var * dot(column_rows(&d.basis, j, 0..m), &term.residual);
                        out[(si, d.offset + j)] += v;
                        out[(d.offset + j, si)] += v;
                    }
                }
            }
        }
        Ok(())
    }
}
