//! The separation objective. For each candidate as the truth, its noise-free prediction under
//! the input is fitted by every rival (weighted least squares with the recording's σ, the
//! oracle's Levenberg–Marquardt); the truth's expected score lead over the best-fitting rival is
//! ½·SS/σ² + ½·(d_rival − d_truth)·ln N nats, the score `diagnose` ranks by. The search
//! maximises the smallest lead over the truths; the reported gap repeats the comparison on
//! noisy records (noise and parameter draws), each candidate refitted and scored as `diagnose`
//! scores it: with each channel's σ estimated from the record, not given ([`profiled`]).

use nalgebra::{DMatrix, DVector};
use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;

use crate::error::Error;
use crate::motor::VoltageInput;
use crate::parameter::{ParameterSpec, Support};
use crate::study::cases::oracle::levenberg_marquardt;

use super::experiment::{Candidate, Experiment};
use super::limits::Limits;

/// A truth's noise-free lead over its best-fitting rival.
#[derive(Clone, Debug)]
pub struct Lead {
    pub truth: usize,
    pub rival: usize,
    /// Nats.
    pub gap: f64,
}

/// What an input gives: the truths' leads, or how far it passes the limits.
#[derive(Clone, Debug)]
pub enum Evaluation {
    Feasible {
        leads: Vec<Lead>,
        /// Each rival's fit to each truth's prediction: `fits[truth][rival]`.
        fits: Vec<Vec<Vec<f64>>>,
    },
    Infeasible {
        excess: f64,
    },
}

impl Evaluation {
    /// The smallest lead (the design's guarantee), or −∞ past the limits.
    pub fn worst(&self) -> f64 {
        match self {
            Evaluation::Feasible { leads, .. } => {
                leads.iter().map(|l| l.gap).fold(f64::INFINITY, f64::min)
            }
            Evaluation::Infeasible { .. } => f64::NEG_INFINITY,
        }
    }
}

fn numerical(e: crate::ode::OdeError) -> Error {
    Error::Numerical(e.to_string())
}

/// The candidates' noise-free predictions under `input` and how far they pass the limits.
pub fn predictions(
    experiment: &Experiment,
    input: &VoltageInput,
    limits: &Limits,
) -> Result<(Vec<Vec<f64>>, f64), Error> {
    let mut out = Vec::new();
    let mut excess = 0.0;
    for c in &experiment.candidates {
        let forward = c.forward(input, &experiment.times)?;
        let mut y = vec![0.0; forward.n_outputs()];
        forward.simulate(&c.theta, &mut y).map_err(numerical)?;
        excess += limits.excess(forward.channels(), &y, &experiment.times);
        out.push(y);
    }
    Ok((out, excess))
}

/// Gauss–Newton steps the search's rival fits take ([`noise_free_leads`] without polish).
pub const SEARCH_STEPS: usize = 3;

/// The search's objective: every truth's noise-free lead over its best-fitting rival, each
/// rival fitted from its own estimate — by [`SEARCH_STEPS`] safeguarded Gauss–Newton steps in
/// the search, to convergence (Levenberg–Marquardt) with `polish` for what is reported.
pub fn noise_free_leads(
    experiment: &Experiment,
    input: &VoltageInput,
    limits: &Limits,
    polish: bool,
) -> Result<Evaluation, Error> {
    let (truths, excess) = predictions(experiment, input, limits)?;
    if excess > 0.0 {
        return Ok(Evaluation::Infeasible { excess });
    }
    let candidates = &experiment.candidates;
    let mut leads = Vec::new();
    let mut fits = Vec::new();
    for (a, truth) in candidates.iter().enumerate() {
        let mut best = Lead {
            truth: a,
            rival: a,
            gap: f64::INFINITY,
        };
        let mut row = Vec::new();
        for (b, rival) in candidates.iter().enumerate() {
            if a == b {
                row.push(truth.theta.clone());
                continue;
            }
            let (gap, theta) = lead_over(experiment, input, &truths[a], truth, rival, polish)?;
            if gap < best.gap {
                best = Lead {
                    truth: a,
                    rival: b,
                    gap,
                };
            }
            row.push(theta);
        }
        leads.push(best);
        fits.push(row);
    }
    Ok(Evaluation::Feasible { leads, fits })
}

/// `rival` fitted to `target`, the noise-free prediction of `truth` under `input`, from the
/// rival's estimate (weighted least squares at the experiment's σ: [`SEARCH_STEPS`]
/// Gauss–Newton steps, or Levenberg–Marquardt to convergence with `polish`), and the truth's
/// expected score lead over it, ½·SS/σ² + ½·(d_rival − d_truth)·ln N nats; with the fit.
pub(super) fn lead_over(
    experiment: &Experiment,
    input: &VoltageInput,
    target: &[f64],
    truth: &Candidate,
    rival: &Candidate,
    polish: bool,
) -> Result<(f64, Vec<f64>), Error> {
    let weights = experiment.weights();
    let ln_n = (experiment.n_observations() as f64).ln();
    let forward = rival.forward(input, &experiment.times)?;
    let specs = forward.calibrated_specs();
    let (ss, theta) = if polish {
        levenberg_marquardt(&forward, &specs, target, &weights, rival.theta.clone())?
    } else {
        gauss_newton(&forward, &specs, target, &weights, rival.theta.clone())?
    };
    let d = rival.theta.len() as f64 - truth.theta.len() as f64;
    Ok((0.5 * ss + 0.5 * d * ln_n, theta))
}

/// The reported gap of one truth: mean and spread over noisy records.
#[derive(Clone, Debug, serde::Serialize)]
pub struct ExpectedGap {
    pub truth: String,
    /// The rival that fits the noise-free prediction best.
    pub rival: String,
    pub noise_free_gap_nats: f64,
    /// The mean lead with σ estimated per channel, as `diagnose` ranks.
    pub expected_gap_nats: f64,
    pub sd_nats: f64,
    /// The same records scored at the σ given (what the search's objective assumes): far above
    /// `expected_gap_nats` where a rival misfits by many σ, since `diagnose`'s σ̂ then grows.
    pub known_sigma_gap_nats: f64,
    pub draws: usize,
}

/// For each truth: records simulated at parameter draws (Gaussian at its estimate with the
/// covariance this input's Fisher matrix leaves) plus noise at σ, the truth and every rival
/// refitted (from their noise-free fits), and the truth's score lead over the best rival with
/// σ estimated ([`profiled`]); mean and sd over `draws` records, and the mean at σ given. Draw k of truth a uses its own seeded stream, so the
/// result does not depend on the thread count.
pub fn expected_gaps(
    experiment: &Experiment,
    input: &VoltageInput,
    limits: &Limits,
    draws: usize,
    seed: u64,
) -> Result<Vec<ExpectedGap>, Error> {
    let Evaluation::Feasible { leads, fits } = noise_free_leads(experiment, input, limits, true)?
    else {
        return Err(Error::invalid("the input passes the limits"));
    };
    let weights = experiment.weights();
    let ln_n = (experiment.n_observations() as f64).ln();
    let candidates = &experiment.candidates;
    let mut out = Vec::new();
    for lead in &leads {
        let a = lead.truth;
        let truth = &candidates[a];
        let forward = truth.forward(input, &experiment.times)?;
        let specs = forward.calibrated_specs();
        let spread = parameter_spread(&forward, &truth.theta, &weights)?;
        let forwards = candidates
            .iter()
            .map(|c| c.forward(input, &experiment.times))
            .collect::<Result<Vec<_>, _>>()?;
        let gaps: Vec<(f64, f64)> = (0..draws)
            .into_par_iter()
            .map(|k| -> Result<(f64, f64), Error> {
                let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(
                    seed ^ (0x5eed_0000 + (a as u64) * 1_000_003 + k as u64),
                );
                let theta = draw(&truth.theta, spread.as_ref(), &specs, &mut rng);
                let mut y = vec![0.0; forward.n_outputs()];
                forward.simulate(&theta, &mut y).map_err(numerical)?;
                for (v, w) in y.iter_mut().zip(&weights) {
                    let e: f64 = StandardNormal.sample(&mut rng);
                    *v += e / w;
                }
                let m = experiment.times.len();
                let (ss_truth, theta_truth) =
                    levenberg_marquardt(&forward, &specs, &y, &weights, truth.theta.clone())?;
                let p_truth = profiled(&forward, &specs, &y, m, theta_truth)?;
                let (mut best, mut best_known) = (f64::INFINITY, f64::INFINITY);
                for (b, rival) in candidates.iter().enumerate() {
                    if b == a {
                        continue;
                    }
                    let f = &forwards[b];
                    let rival_specs = f.calibrated_specs();
                    let (ss, theta) =
                        levenberg_marquardt(f, &rival_specs, &y, &weights, fits[a][b].clone())?;
                    let p_rival = profiled(f, &rival_specs, &y, m, theta)?;
                    let penalty =
                        0.5 * (rival.theta.len() as f64 - truth.theta.len() as f64) * ln_n;
                    best = best.min(p_truth - p_rival + penalty);
                    best_known = best_known.min(0.5 * (ss - ss_truth) + penalty);
                }
                Ok((best, best_known))
            })
            .collect::<Result<_, _>>()?;
        let n = gaps.len().max(1) as f64;
        let mean = gaps.iter().map(|g| g.0).sum::<f64>() / n;
        let var = gaps.iter().map(|g| (g.0 - mean).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
        out.push(ExpectedGap {
            truth: truth.name.clone(),
            rival: candidates[lead.rival].name.clone(),
            noise_free_gap_nats: lead.gap,
            expected_gap_nats: mean,
            sd_nats: var.sqrt(),
            known_sigma_gap_nats: gaps.iter().map(|g| g.1).sum::<f64>() / n,
            draws,
        });
    }
    Ok(out)
}

/// The log likelihood of `y` with each channel's σ estimated, maximised over θ and σ from
/// `theta` (a fit at the σ given), up to a constant: −Σ_c (m/2)·ln(SS_c/m), SS_c channel c's
/// sum of squares over its m samples. `diagnose` fits σ with θ, so a rival that misfits raises
/// its own σ̂ and loses ln σ̂ per sample, not the squared misfit over σ². One majorise–minimise
/// step refits θ at the σ̂ its residuals give (ln SS_c lies below its tangent at the current
/// SS_c, so the weighted fit at weights 1/σ̂_c never lowers it); the better of the two is kept.
fn profiled(
    forward: &crate::forward::ForwardModel,
    specs: &[ParameterSpec],
    y: &[f64],
    m: usize,
    theta: Vec<f64>,
) -> Result<f64, Error> {
    let log_likelihood = |theta: &[f64]| -> Result<(f64, Vec<f64>), Error> {
        let mut g = vec![0.0; y.len()];
        forward.simulate(theta, &mut g).map_err(numerical)?;
        let (mut value, mut weights) = (0.0, Vec::with_capacity(y.len()));
        for (channel, fit) in y.chunks(m).zip(g.chunks(m)) {
            let ss: f64 = channel.iter().zip(fit).map(|(a, b)| (a - b).powi(2)).sum();
            let sigma2 = (ss / m as f64).max(f64::MIN_POSITIVE);
            value -= 0.5 * m as f64 * sigma2.ln();
            weights.extend(std::iter::repeat_n(1.0 / sigma2.sqrt(), m));
        }
        Ok((value, weights))
    };
    let (first, weights) = log_likelihood(&theta)?;
    let (_, refit) = levenberg_marquardt(forward, specs, y, &weights, theta)?;
    let (second, _) = log_likelihood(&refit)?;
    Ok(first.max(second))
}

/// The Cholesky factor of the inverse Fisher matrix at θ (`None` when it is singular: the
/// draws then vary the noise only).
fn parameter_spread(
    forward: &crate::forward::ForwardModel,
    theta: &[f64],
    weights: &[f64],
) -> Result<Option<DMatrix<f64>>, Error> {
    let fisher = super::pin::fisher(forward, theta, weights)?;
    Ok(fisher
        .cholesky()
        .and_then(|c| c.inverse().cholesky())
        .map(|c| c.l()))
}

fn draw(
    theta: &[f64],
    spread: Option<&DMatrix<f64>>,
    specs: &[ParameterSpec],
    rng: &mut rand_chacha::ChaCha8Rng,
) -> Vec<f64> {
    let Some(l) = spread else {
        return theta.to_vec();
    };
    let z = DVector::from_iterator(
        theta.len(),
        (0..theta.len()).map(|_| StandardNormal.sample(rng)),
    );
    let dx = l * z;
    theta
        .iter()
        .zip(dx.iter())
        .zip(specs)
        .map(|((t, d), s)| match s.support {
            Support::Positive => (t + d).max(0.0),
            Support::Bounded { lower, upper } => (t + d).clamp(lower, upper),
            Support::Real => t + d,
        })
        .collect()
}

/// The worst-separated pair under an input, for the figure: the truth's noise-free prediction
/// and its best-fitting rival's fit to it (channel-major), with the channels' names.
pub struct LeadCurves {
    pub lead: Lead,
    pub channels: Vec<String>,
    pub truth: Vec<f64>,
    pub rival_fit: Vec<f64>,
}

pub fn lead_curves(experiment: &Experiment, input: &VoltageInput) -> Result<LeadCurves, Error> {
    let evaluation = noise_free_leads(experiment, input, &Limits::open(), true)?;
    let Evaluation::Feasible { leads, fits } = evaluation else {
        return Err(Error::invalid("no limits to pass"));
    };
    let lead = leads
        .iter()
        .min_by(|a, b| a.gap.total_cmp(&b.gap))
        .cloned()
        .ok_or_else(|| Error::invalid("no candidates"))?;
    let run = |c: usize, theta: &[f64]| -> Result<(Vec<String>, Vec<f64>), Error> {
        let forward = experiment.candidates[c].forward(input, &experiment.times)?;
        let mut y = vec![0.0; forward.n_outputs()];
        forward.simulate(theta, &mut y).map_err(numerical)?;
        Ok((
            forward.channels().iter().map(|s| s.to_string()).collect(),
            y,
        ))
    };
    let (channels, truth) = run(lead.truth, &experiment.candidates[lead.truth].theta)?;
    let (_, rival_fit) = run(lead.rival, &fits[lead.truth][lead.rival])?;
    Ok(LeadCurves {
        lead,
        channels,
        truth,
        rival_fit,
    })
}

/// A few Gauss–Newton steps on the weighted residual, each kept only if it lowers the sum of
/// squares (projected into the supports): the search's cheap rival fit.
fn gauss_newton(
    forward: &crate::forward::ForwardModel,
    specs: &[ParameterSpec],
    target: &[f64],
    weights: &[f64],
    mut theta: Vec<f64>,
) -> Result<(f64, Vec<f64>), Error> {
    let n = forward.n_outputs();
    let d = theta.len();
    let mut out = vec![0.0; n];
    let mut jac = DMatrix::zeros(n, d);
    let ss_of = |out: &[f64]| -> f64 {
        out.iter()
            .zip(target)
            .zip(weights)
            .map(|((g, y), w)| ((y - g) * w).powi(2))
            .sum()
    };
    forward
        .simulate_with_sensitivities(&theta, &mut out, &mut jac)
        .map_err(numerical)?;
    let mut ss = ss_of(&out);
    for step in 0..SEARCH_STEPS {
        for (r, w) in weights.iter().enumerate() {
            for c in 0..d {
                jac[(r, c)] *= w;
            }
        }
        let r = DVector::from_iterator(n, (0..n).map(|i| (target[i] - out[i]) * weights[i]));
        let jtj = jac.transpose() * &jac;
        let jtr = jac.transpose() * r;
        let mut a = jtj.clone();
        for j in 0..d {
            a[(j, j)] += 1e-9 * jtj[(j, j)].max(1e-300);
        }
        let Some(delta) = a.cholesky().map(|c| c.solve(&jtr)) else {
            break;
        };
        let trial: Vec<f64> = theta
            .iter()
            .zip(delta.iter())
            .zip(specs)
            .map(|((t, s), spec)| match spec.support {
                Support::Positive => (t + s).max(0.0),
                Support::Bounded { lower, upper } => (t + s).clamp(lower, upper),
                Support::Real => t + s,
            })
            .collect();
        let mut trial_out = vec![0.0; n];
        let last = step + 1 == SEARCH_STEPS;
        let result = if last {
            forward.simulate(&trial, &mut trial_out).map(|_| ())
        } else {
            forward
                .simulate_with_sensitivities(&trial, &mut trial_out, &mut jac)
                .map(|_| ())
        };
        if result.is_err() {
            break;
        }
        let trial_ss = ss_of(&trial_out);
        if !(trial_ss < ss) {
            break;
        }
        theta = trial;
        ss = trial_ss;
        out = trial_out;
    }
    Ok((ss, theta))
}
