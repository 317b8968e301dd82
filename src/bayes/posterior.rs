//! The posterior of BM1/BM2 (eqs. 12–22) over the unconstrained coordinates
//! x = (u(θ), log σ per record and channel, discrepancy coefficients per record and channel),
//! where each calibrated physical parameter θ_k is reached through its own transform u_k.
//!
//! The likelihood is per channel and per recording, each with its own noise level; the
//! discrepancy basis is per channel. The gradient in θ comes from the forward sensitivities,
//! the one in a is exact (δ is linear in a), and G(θ) is computed once per θ, not once per
//! coefficient: a cache keeps it while only σ or a move.

use std::ops::Range;

use nalgebra::DMatrix;

use super::calibrated::{CalibratedParameter, PriorInU};
use super::settings::ModelSettings;
use crate::density::{DensityError, SolveCounter};
use crate::forward::ForwardModel;
use crate::parameter::Prior;

// The density, its gradient and the metrics: the loops over every channel at a point.
mod evaluation;
// The likelihood's Gaussian structure in σ and the coefficients given θ.
mod conditional;

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
    /// L with BᵀB = LLᵀ, for the coefficients' conditional given θ (`None` if B is rank
    /// deficient).
    gram_factor: Option<DMatrix<f64>>,
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

/// One solve of the forward model: at which θ, how much of it, and what it gave.
#[derive(Clone, Debug)]
struct Solve {
    kind: Cached,
    theta: Vec<f64>,
    outputs: Vec<f64>,
    jacobian: DMatrix<f64>,
}

impl Solve {
    fn empty(n_out: usize, n_par: usize) -> Self {
        Self {
            kind: Cached::Nothing,
            theta: Vec::new(),
            outputs: vec![0.0; n_out],
            jacobian: DMatrix::zeros(n_out, n_par),
        }
    }

    fn serves(&self, theta: &[f64], sensitivities: bool) -> bool {
        self.kind != Cached::Nothing
            && self.theta == theta
            && (!sensitivities || self.kind == Cached::WithSensitivities)
    }
}

#[derive(Clone, Debug)]
struct RecordTerm {
    label: String,
    forward: ForwardModel,
    channels: Vec<ChannelTerm>,
    current: Solve,
    /// The solve before the current one, kept so that a rejected proposal in θ costs no
    /// second solve when the chain's next evaluation returns to the old θ (the paper's
    /// variable-at-a-time Metropolis does exactly that, several times a sweep).
    previous: Solve,
    residual: Vec<f64>,
    /// The solves this record's cache did not serve.
    solves: SolveCounter,
}

impl RecordTerm {
    fn ensure_forward(&mut self, theta: &[f64], sensitivities: bool) -> Result<(), DensityError> {
        if self.current.serves(theta, sensitivities) {
            return Ok(());
        }
        // Whatever happens next, the current solve becomes the previous one.
        std::mem::swap(&mut self.current, &mut self.previous);
        if self.current.serves(theta, sensitivities) {
            return Ok(());
        }
        let solve = &mut self.current;
        solve.kind = Cached::Nothing;
        if sensitivities {
            self.solves.0.dual += 1;
            self.solves.0.directions += theta.len() as u64;
        } else {
            self.solves.0.plain += 1;
        }
        let result = if sensitivities {
            self.forward
                .simulate_with_sensitivities(theta, &mut solve.outputs, &mut solve.jacobian)
        } else {
            self.forward.simulate(theta, &mut solve.outputs)
        };
        // A solve that gave up after its step cap did that work too; the other failures end
        // early and are not counted.
        self.solves.0.rhs_evaluations += match &result {
            Ok(stats) => stats.rhs_evaluations as u64,
            Err(crate::ode::OdeError::TooManySteps { max_steps, .. }) => {
                (crate::ode::RHS_PER_STEP * max_steps) as u64
            }
            Err(_) => 0,
        };
        result.map_err(|e| DensityError::recoverable(format!("{}: {e}", self.label)))?;
        solve.theta.clear();
        solve.theta.extend_from_slice(theta);
        solve.kind = if sensitivities {
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
        let g = &self.current.outputs[c * m..(c + 1) * m];
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

    /// Sensitivities of channel `c` to θ_k.
    fn sensitivities(&self, k: usize, c: usize) -> &[f64] {
        let m = self.forward.n_samples();
        column_rows(&self.current.jacobian, k, c * m..(c + 1) * m)
    }
}

/// The posterior of one or several recordings under BM1 or BM2(K).
#[derive(Clone, Debug)]
pub struct CalibrationPosterior {
    settings: ModelSettings,
    theta: Vec<CalibratedParameter>,
    theta_names: Vec<String>,
    /// θ in the model's own coordinates at the last evaluation (scratch).
    theta_x: Vec<f64>,
    noise_prior: Prior,
    records: Vec<RecordTerm>,
    dim: usize,
    names: Vec<String>,
    output_names: Vec<String>,
    blocks: Vec<Range<usize>>,
}

impl CalibrationPosterior {
    /// The posterior of a schema-1 model: every calibrated parameter gets the paper's prior of
    /// R (centred on the nominal value, spread proportional to it) and is sampled as itself,
    /// with zero density outside its support. Every record's forward model must calibrate the
    /// same parameters.
    pub fn new(
        records: Vec<(ForwardModel, Observations)>,
        settings: &ModelSettings,
    ) -> Result<Self, String> {
        let Some((first, _)) = records.first() else {
            return Err("no recordings".into());
        };
        let theta = first
            .calibrated_specs()
            .iter()
            .map(|spec| {
                CalibratedParameter::untransformed(
                    spec,
                    settings.resistance_prior(spec.nominal.abs()),
                )
            })
            .collect();
        Self::with_parameters(records, theta, settings)
    }

    /// The posterior with each calibrated parameter's own prior and transform, in the order of
    /// the forward models' calibrated parameters.
    pub fn with_parameters(
        records: Vec<(ForwardModel, Observations)>,
        theta: Vec<CalibratedParameter>,
        settings: &ModelSettings,
    ) -> Result<Self, String> {
        settings.validate()?;
        let Some((first, _)) = records.first() else {
            return Err("no recordings".into());
        };
        let calibrated = first.calibrated_names();
        if calibrated.len() != theta.len()
            || calibrated.iter().zip(&theta).any(|(a, b)| *a != b.name)
        {
            return Err(format!(
                "the priors name {:?}, the model calibrates {calibrated:?}",
                theta.iter().map(|t| t.name.as_str()).collect::<Vec<_>>()
            ));
        }
        let theta_names: Vec<String> = theta.iter().map(|t| t.coordinate_name()).collect();
        let noise_prior = Prior::InverseGamma {
            shape: settings.noise_prior_shape,
            scale: settings.noise_prior_scale,
        };

        let several = records.len() > 1;
        let mut names: Vec<String> = theta_names.clone();
        let mut output_names: Vec<String> = theta.iter().map(|t| t.output_name()).collect();
        let mut blocks: Vec<Range<usize>> = (0..theta_names.len()).map(|i| i..i + 1).collect();
        let mut next = theta_names.len();
        let mut terms = Vec::new();
        let mut pending_coefficients = Vec::new();
        for (r, (forward, obs)) in records.into_iter().enumerate() {
            if forward.calibrated_names() != calibrated {
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
                let basis = settings.discrepancy_basis.build(k, t_end)?;
                let b = basis.matrix(forward.times());
                for c in 0..channels.len() {
                    pending_coefficients.push((
                        terms.len(),
                        c,
                        b.clone(),
                        basis.describe(),
                        suffix.clone(),
                    ));
                }
            }
            let n_out = forward.n_outputs();
            let n_par = forward.n_calibrated();
            terms.push(RecordTerm {
                label: obs.label,
                channels,
                current: Solve::empty(n_out, n_par),
                previous: Solve::empty(n_out, n_par),
                residual: vec![0.0; m],
                solves: SolveCounter::default(),
                forward,
            });
        }
        // Coefficients come last, after every σ, so that the small, well-identified
        // coordinates lead the parameter vector as in the paper's tables.
        for (r, c, b, description, suffix) in pending_coefficients {
            let term = &mut terms[r];
            let n = b.ncols();
            let gram = b.transpose() * &b;
            let ch = &mut term.channels[c];
            for j in 0..n {
                let name = format!("a_{}{suffix}.{}", ch.name, j + 1);
                names.push(name.clone());
                output_names.push(name);
            }
            blocks.push(next..next + n);
            ch.discrepancy = Some(Discrepancy {
                description,
                basis: b,
                gram_factor: gram.clone().cholesky().map(|c| c.l()),
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
            theta_x: vec![0.0; theta.len()],
            theta,
            theta_names,
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

    /// Names of the unconstrained coordinates of θ.
    pub fn theta_names(&self) -> &[String] {
        &self.theta_names
    }

    /// The calibrated parameters with their priors and transforms.
    pub fn calibrated(&self) -> &[CalibratedParameter] {
        &self.theta
    }

    /// θ in the model's own coordinates from the unconstrained point x.
    pub fn theta_of(&self, x: &[f64]) -> Vec<f64> {
        self.theta
            .iter()
            .zip(x)
            .map(|(t, &u)| t.transform.map(u).x)
            .collect()
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

    /// The residuals y − G(θ) − δ(a) of every channel of a record at x.
    pub fn residuals(&mut self, x: &[f64], record: usize) -> Result<Vec<Vec<f64>>, DensityError> {
        let theta = self.theta_of(x);
        let term = &mut self.records[record];
        term.ensure_forward(&theta, false)?;
        let mut out = Vec::with_capacity(term.channels.len());
        for c in 0..term.channels.len() {
            term.residual(c, x);
            out.push(term.residual.clone());
        }
        Ok(out)
    }

    /// The log likelihood at x, priors and Jacobians left out: the fit's own measure, comparable
    /// between models with different priors.
    pub fn log_likelihood(&mut self, x: &[f64]) -> Result<f64, DensityError> {
        let mut total = 0.0;
        for r in 0..self.records.len() {
            for (c, residual) in self.residuals(x, r)?.iter().enumerate() {
                let s = x[self.records[r].channels[c].log_sigma_index];
                let ss: f64 = residual.iter().map(|v| v * v).sum();
                total +=
                    -(residual.len() as f64) * (s + 0.5 * LN_2PI) - 0.5 * ss * (-2.0 * s).exp();
            }
        }
        Ok(total)
    }

    /// Names of a record's channels.
    pub fn channel_names(&self, record: usize) -> Vec<String> {
        self.records[record]
            .channels
            .iter()
            .map(|c| c.name.clone())
            .collect()
    }

    /// The label a record was given (its file, for several recordings).
    pub fn record_label(&self, record: usize) -> &str {
        &self.records[record].label
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
        let theta = self.theta_of(x);
        let term = &mut self.records[record];
        term.ensure_forward(&theta, false)?;
        Ok(term.current.outputs.clone())
    }

    /// A sensible start: nominal θ (or its prior's median where the nominal value is on the
    /// boundary of the support), the discrepancy that least-squares fits the nominal residual,
    /// and the noise level of what is left.
    pub fn initial_point(&mut self) -> Result<Vec<f64>, DensityError> {
        let mut x = vec![0.0; self.dim];
        let theta: Vec<f64> = self.theta.iter().map(|t| t.start).collect();
        for (k, t) in self.theta.iter().enumerate() {
            x[k] = t.to_unconstrained(theta[k]);
        }
        for term in &mut self.records {
            term.ensure_forward(&theta, false)?;
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
}

/// Rows `rows` of column `k` of a column-major matrix, as a slice.
fn column_rows(matrix: &DMatrix<f64>, k: usize, rows: Range<usize>) -> &[f64] {
    let n = matrix.nrows();
    &matrix.as_slice()[k * n + rows.start..k * n + rows.end]
}
