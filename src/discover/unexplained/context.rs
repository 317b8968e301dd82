//! What every alternative of the verdict is scored on: one record's whitened residuals at a
//! model's MAP, the model's whitened sensitivities to project against, and the fine-grid
//! prediction the timing and slope alternatives differentiate.

use nalgebra::{DMatrix, DVector};

use crate::error::Error;
use crate::study::Problem;

use super::super::candidate::Candidate;
use super::super::coincide::input_steps;
use super::regression::{Explained, Projector, explain};
use super::resonance;
use super::timing::FinePrediction;
use super::torque_response::{Added, TorqueResponse};

/// Input steps (besides the record's start) a ringing oscillation is fitted after at most: the
/// largest ones; a long real record's many small steps ring too little to matter.
const MAX_STEPS: usize = 6;
/// An alternative's explained part and its score (gain − penalty, nats).
#[derive(Clone, Debug)]
pub struct Scored {
    pub explained: Explained,
    pub score: f64,
}

impl Scored {
    pub fn new(explained: Explained, penalty: f64) -> Self {
        let score = explained.gain - penalty;
        Self { explained, score }
    }
}

/// One record's residuals at a model's MAP, whitened and stacked channel after channel, with
/// the model's whitened sensitivities to project alternatives against.
pub struct Context {
    pub times: Vec<f64>,
    pub n: usize,
    pub channels: Vec<String>,
    pub sigma: Vec<f64>,
    pub y: DVector<f64>,
    /// y with the part the model's parameters can still take removed.
    pub y_perp: DVector<f64>,
    pub projector: Projector,
    /// The record's start and its largest input steps [s].
    pub steps: Vec<f64>,
    /// The prediction on a grid ten times finer, from t = 0.
    pub fine: FinePrediction,
    /// Where the model holds a sensor lag: its channel (index in `channels`), its τ and the
    /// fine prediction with the lag switched off (τ = 0), what a resonant sensor replaces it on.
    pub lagged: Option<(usize, f64, FinePrediction)>,
    /// What a torque added to the balances does to I and ω on the fine grid (the order search's
    /// columns); none on a drive base.
    pub torque: Option<TorqueResponse>,
    /// And what a voltage added to the voltage balance does (`knocks` of the supply).
    pub supply: Option<TorqueResponse>,
    pub ln_n: f64,
}

impl Context {
    pub fn m(&self) -> usize {
        self.n * self.channels.len()
    }

    /// The record's mean sampling interval [s].
    pub fn interval(&self) -> f64 {
        (self.times[self.n - 1] - self.times[0]) / (self.n - 1).max(1) as f64
    }

    /// The angle θ at the record's samples, the predicted speed's integral from t = 0 (as the
    /// law's own state is); none without a speed channel.
    pub fn angle(&self) -> Option<Vec<f64>> {
        let speed = self.channels.iter().position(|c| c == "omega")?;
        Some(self.fine.integral_at(speed, &self.times))
    }

    pub(super) fn of(problem: &Problem, fit: &Candidate, record: usize) -> Result<Self, Error> {
        let mut posterior = fit.posterior.clone();
        let x = &fit.map.x;
        let residuals = posterior.residuals(x, record)?;
        let names = posterior.channel_names(record);
        let forward = posterior.forward(record).clone();
        let theta = posterior.theta_of(x);
        let mut outputs = vec![0.0; forward.n_outputs()];
        let mut jacobian = DMatrix::zeros(forward.n_outputs(), forward.n_calibrated());
        forward
            .simulate_with_sensitivities(&theta, &mut outputs, &mut jacobian)
            .map_err(|e| Error::Numerical(format!("the unexplained-structure check: {e}")))?;
        let n = forward.n_samples();
        let times = forward.times().to_vec();
        let m = n * names.len();
        let mut y = DVector::zeros(m);
        let mut j = DMatrix::zeros(m, forward.n_calibrated());
        let mut sigma = Vec::new();
        for (c, name) in names.iter().enumerate() {
            let s = x[posterior.log_sigma_index(record, c)].exp();
            let k = forward
                .channels()
                .iter()
                .position(|f| f == name)
                .ok_or_else(|| Error::Numerical(format!("channel {name} is not simulated")))?;
            for i in 0..n {
                y[c * n + i] = residuals[c][i] / s;
                for p in 0..forward.n_calibrated() {
                    j[(c * n + i, p)] = jacobian[(k * n + i, p)] / s;
                }
            }
            sigma.push(s);
        }
        let fine = FinePrediction::of(&forward, &theta, &names)?;
        let torque = TorqueResponse::of(&forward, &theta, fine.step());
        let supply = TorqueResponse::of_added(&forward, &theta, fine.step(), Added::Voltage);
        let lagged = resonance::unlagged(&forward, &theta, &names)?;
        let projector = Projector::new(j);
        let y_perp = DVector::from_column_slice(
            projector
                .residualize(&DMatrix::from_column_slice(m, 1, y.as_slice()))
                .as_slice(),
        );
        let recording = &problem.recordings[record];
        let mut steps: Vec<(f64, f64)> = input_steps(problem, recording)
            .into_iter()
            .filter(|s| !s.record_start)
            .map(|s| (s.time, s.size.abs()))
            .collect();
        steps.sort_by(|a, b| b.1.total_cmp(&a.1));
        steps.truncate(MAX_STEPS);
        let mut steps: Vec<f64> = std::iter::once(0.0)
            .chain(steps.into_iter().map(|s| s.0))
            .collect();
        steps.sort_by(f64::total_cmp);
        Ok(Self {
            times,
            n,
            channels: names,
            sigma,
            y,
            y_perp,
            projector,
            steps,
            fine,
            lagged,
            torque,
            supply,
            ln_n: (problem.n_observations() as f64).ln(),
        })
    }

    pub(super) fn score(&self, b: &DMatrix<f64>, extra_penalty: f64) -> Scored {
        self.score_residualized(&self.projector.residualize(b), extra_penalty)
    }

    /// [`Self::score`] of columns already residualized on the model's sensitivities (a caller
    /// that needs them too, for the coefficients' sds).
    pub(super) fn score_residualized(&self, b_perp: &DMatrix<f64>, extra_penalty: f64) -> Scored {
        let e = explain(&self.y, b_perp);
        let penalty = 0.5 * e.rank as f64 * self.ln_n + extra_penalty;
        Scored::new(e, penalty)
    }

    /// Columns `columns` of a forward model's sensitivities (`jacobian`, its outputs channel by
    /// channel as `simulated` names them), in this context's stacked rows, each channel
    /// whitened by its σ: regressors for a term the model does not hold yet.
    pub fn whitened_columns(
        &self,
        simulated: &[&str],
        jacobian: &DMatrix<f64>,
        columns: &[usize],
    ) -> Result<DMatrix<f64>, Error> {
        let n = self.n;
        let mut b = DMatrix::zeros(self.m(), columns.len());
        for (c, name) in self.channels.iter().enumerate() {
            let k = simulated
                .iter()
                .position(|f| f == name)
                .ok_or_else(|| Error::Numerical(format!("channel {name} is not simulated")))?;
            for i in 0..n {
                for (j, &p) in columns.iter().enumerate() {
                    b[(c * n + i, j)] = jacobian[(k * n + i, p)] / self.sigma[c];
                }
            }
        }
        Ok(b)
    }

    /// Columns `values` (n × d) placed in channel c's rows.
    pub(super) fn in_channel(&self, c: usize, values: &DMatrix<f64>) -> DMatrix<f64> {
        let mut b = DMatrix::zeros(self.m(), values.ncols());
        b.view_mut((c * self.n, 0), (self.n, values.ncols()))
            .copy_from(values);
        b
    }

    /// dŷ/dt of channel c (central differences on the fine grid), whitened.
    pub(super) fn derivative(&self, c: usize) -> Vec<f64> {
        let y = &self.fine.channels[c];
        let h = self.fine.step();
        self.times
            .iter()
            .map(|&t| {
                let k = self.fine.interior_index(t);
                (y[k + 1] - y[k - 1]) / (2.0 * h) / self.sigma[c]
            })
            .collect()
    }
}
