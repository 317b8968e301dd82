//! The K study: BM2 for each K on the paper's data, with the paper's error measures
//! (Definition 4.2 for R, σ_I, σ_ω against the truth; Definition 4.3 for δ_I, δ_ω against the
//! reference discrepancy d0), convergence, and the figures mirroring Figures 8–11.

pub mod select;

use std::path::PathBuf;
use std::time::Instant;

use serde::{Deserialize, Serialize};

use crate::bayes::{CoefficientPrior, ModelSettings};
use crate::diagnostics::ParameterSummary;
use crate::error::Error;
use crate::evidence::importance_sampling;
use crate::pipeline::{RunCost, RunOutput, RunSettings, map_estimate, run_sampler};
use crate::study::{Problem, Reference};

/// Draws used for δ's pointwise moments: plenty for a mean and a variance per sample time.
const DELTA_DRAWS: usize = 1000;

/// Importance draws of the evidence per K (about 0.1–0.3 s at K = 20).
const EVIDENCE_DRAWS: usize = 4000;
/// Their seed, apart from the chains'.
const EVIDENCE_SEED: u64 = 0xe71d_e9ce;

#[derive(Clone, Debug)]
pub struct SweepOptions {
    pub ks: Vec<usize>,
    pub coefficient_prior: CoefficientPrior,
    /// Seeds of the synthetic noise (the paper's data: 20180823); the grid is K × seed.
    pub data_seeds: Vec<u64>,
    /// `(i, n)`: run only the grid points whose index is i − 1 modulo n (1 ≤ i ≤ n).
    pub shard: Option<(usize, usize)>,
    pub run: RunSettings,
    pub out: PathBuf,
    pub json: Option<PathBuf>,
    /// Degrees at which to draw δ's band against d0 (Figures 13/16) and the coefficients'
    /// marginals against d0's least-squares coefficients (Figures 14/17).
    pub figures_at: Vec<usize>,
}

/// Definition 4.2 of one scalar against its reference, with the posterior's summary.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ScalarStats {
    pub mean: f64,
    pub sd: f64,
    pub q05: f64,
    pub q95: f64,
    pub q025: f64,
    pub q975: f64,
    pub reference: f64,
    pub bias: f64,
    pub variance: f64,
    pub mse: f64,
}

/// Definition 4.3 of δ on one channel against d0 (L² norms over the sample times).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct DiscrepancyStats {
    pub n_bias: f64,
    pub n_v: f64,
    pub n_mse: f64,
    /// nBias² + nV, the bound (27).
    pub n_mse_bound: f64,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SweepRecord {
    pub k: usize,
    pub prior: String,
    pub data_seed: u64,
    pub chain_seed: u64,
    pub sampler: String,
    pub r: ScalarStats,
    pub sigma_i: ScalarStats,
    pub sigma_omega: ScalarStats,
    pub delta_i: DiscrepancyStats,
    pub delta_omega: DiscrepancyStats,
    pub max_rhat: f64,
    pub min_ess_bulk: f64,
    pub min_ess_tail: f64,
    pub divergences: usize,
    /// Wall time of the whole K: the run, the evidence, the statistics and figures.
    pub wall_s: f64,
    /// The run's cost by phase, and min bulk-ESS per CPU second and per evaluation of the
    /// sampling phase and of the whole cost (absent from files written before it was).
    #[serde(default)]
    pub cost: RunCost,
    /// The log evidence p(y | K) by importance sampling from the Laplace approximation, and
    /// the Laplace value itself (which misses the coefficient prior's kink at 0).
    pub evidence: crate::evidence::Evidence,
    /// Pooled draws of σ_I and σ_ω, for `select-k` (not written).
    #[serde(skip, default)]
    pub sigma_draws: [Vec<f64>; 2],
}

fn scalar(summary: &ParameterSummary, reference: f64) -> ScalarStats {
    let bias = summary.mean - reference;
    let variance = summary.sd * summary.sd;
    ScalarStats {
        mean: summary.mean,
        sd: summary.sd,
        q05: summary.q05,
        q95: summary.q95,
        q025: summary.q025,
        q975: summary.q975,
        reference,
        bias,
        variance,
        mse: bias * bias + variance,
    }
}

fn pooled(run: &RunOutput, name: &str) -> Vec<f64> {
    run.chains
        .iter()
        .flat_map(|c| {
            let j = c.names.iter().position(|n| n == name);
            j.map(|j| c.column(j)).unwrap_or_default()
        })
        .collect()
}

/// One K on `problem`, the paper's set-up made with `data_seed`: the run and its statistics.
pub fn run_k<E: From<Error>>(
    problem: &Problem,
    data_seed: u64,
    k: usize,
    options: &SweepOptions,
    on_point: &mut impl FnMut(SweepPoint<'_>) -> Result<(), E>,
) -> Result<SweepRecord, E> {
    let reference: &Reference = problem
        .reference
        .as_ref()
        .ok_or_else(|| Error::invalid("sweep needs a synthetic problem with a truth"))?;
    let mut settings = ModelSettings::bm2(k);
    settings.coefficient_prior = options.coefficient_prior;
    settings.validate().map_err(|e| Error::setting("k", k, e))?;
    let started = Instant::now();
    let mut posterior = problem.posterior(&settings)?;
    let run = run_sampler(&mut posterior, &options.run, &settings.label())?;
    let wall_s = started.elapsed().as_secs_f64();
    let map = map_estimate(&mut posterior)?;
    let evidence = importance_sampling(&mut posterior, &map, EVIDENCE_DRAWS, EVIDENCE_SEED)
        .map_err(Error::Numerical)?;
    let summary = |name: &str| {
        run.summary(name)
            .ok_or_else(|| Error::Numerical(format!("no summary of {name}")))
    };
    let r = scalar(summary("R")?, reference.truth.resistance);
    let sigma_i = scalar(summary("sigma_I")?, reference.noise_sd[0]);
    let sigma_omega = scalar(summary("sigma_omega")?, reference.noise_sd[1]);
    let all: Vec<&Vec<f64>> = run
        .chains
        .iter()
        .flat_map(|c| c.unconstrained.iter())
        .collect();
    let stride = (all.len() / DELTA_DRAWS).max(1);
    let picked: Vec<&Vec<f64>> = all.iter().step_by(stride).copied().collect();
    let mut deltas = Vec::new();
    for c in 0..2 {
        let d0 = &reference.discrepancy[c];
        let m = d0.len();
        let mut mean = vec![0.0; m];
        let mut second = vec![0.0; m];
        for x in &picked {
            let delta = posterior.discrepancy(x, 0, c);
            for i in 0..m {
                mean[i] += delta[i];
                second[i] += delta[i] * delta[i];
            }
        }
        let n = picked.len() as f64;
        let norm = |v: &[f64]| v.iter().map(|a| a * a).sum::<f64>().sqrt();
        let variance: Vec<f64> = (0..m)
            .map(|i| (second[i] / n - (mean[i] / n).powi(2)).max(0.0) * n / (n - 1.0))
            .collect();
        let bias: Vec<f64> = (0..m).map(|i| mean[i] / n - d0[i]).collect();
        let mse: Vec<f64> = (0..m).map(|i| bias[i] * bias[i] + variance[i]).collect();
        let (n_bias, n_v) = (norm(&bias), norm(&variance));
        deltas.push(DiscrepancyStats {
            n_bias,
            n_v,
            n_mse: norm(&mse),
            n_mse_bound: n_bias * n_bias + n_v,
        });
    }
    on_point(SweepPoint {
        k,
        posterior: &mut posterior,
        run: &run,
        reference,
    })?;
    let delta_omega = deltas.pop().expect("two channels");
    let delta_i = deltas.pop().expect("two channels");
    Ok(SweepRecord {
        k,
        prior: options.coefficient_prior.label(),
        data_seed,
        chain_seed: options.run.seed,
        sampler: run.sampler.clone(),
        r,
        sigma_i,
        sigma_omega,
        delta_i,
        delta_omega,
        max_rhat: run.max_rhat,
        min_ess_bulk: run.min_ess_bulk,
        min_ess_tail: run
            .summaries
            .iter()
            .map(|s| s.ess_tail)
            .fold(f64::INFINITY, f64::min),
        divergences: run.divergences,
        wall_s,
        cost: RunCost::of(&run, options.run.sampler.uses_gradient()),
        evidence,
        sigma_draws: [pooled(&run, "sigma_I"), pooled(&run, "sigma_omega")],
    })
}

/// The grid in its fixed order: data seed, then K.
pub fn grid(options: &SweepOptions) -> Vec<(u64, usize)> {
    options
        .data_seeds
        .iter()
        .flat_map(|&s| options.ks.iter().map(move |&k| (s, k)))
        .collect()
}

/// The grid points of a shard.
pub fn shard_of(options: &SweepOptions) -> Vec<(u64, usize)> {
    let all = grid(options);
    match options.shard {
        None => all,
        Some((i, n)) => all
            .into_iter()
            .enumerate()
            .filter(|(j, _)| j % n == i - 1)
            .map(|(_, p)| p)
            .collect(),
    }
}

/// A fitted K as [`run_k`] shows it to its caller.
pub struct SweepPoint<'a> {
    pub k: usize,
    pub posterior: &'a mut crate::bayes::CalibrationPosterior,
    pub run: &'a RunOutput,
    pub reference: &'a Reference,
}

/// Every grid point of this shard (all of them without `--shard`), on the paper's set-up with
/// each data seed.
pub fn sweep(options: &SweepOptions) -> Result<Vec<SweepRecord>, Error> {
    sweep_with(options, |_| Ok::<_, Error>(()))
}

/// As [`sweep`], showing `on_point` every fitted K as it finishes (the command draws its
/// figures there).
pub fn sweep_with<E: From<Error>>(
    options: &SweepOptions,
    mut on_point: impl FnMut(SweepPoint<'_>) -> Result<(), E>,
) -> Result<Vec<SweepRecord>, E> {
    if options.ks.is_empty() {
        return Err(Error::setting("k", "", "no degree given").into());
    }
    if options.data_seeds.is_empty() {
        return Err(Error::setting("data_seed", "", "no seed given").into());
    }
    if let Some((i, n)) = options.shard
        && !(n >= 1 && (1..=n).contains(&i))
    {
        return Err(Error::setting("shard", format!("{i}/{n}"), "need 1 ≤ i ≤ n").into());
    }
    options.run.validate()?;
    for &k in &options.ks {
        let mut settings = ModelSettings::bm2(k);
        settings.coefficient_prior = options.coefficient_prior;
        settings.validate().map_err(|e| Error::setting("k", k, e))?;
    }
    let mut records = Vec::new();
    let mut problem: Option<(u64, Problem)> = None;
    for (seed, k) in shard_of(options) {
        if problem.as_ref().is_none_or(|(s, _)| *s != seed) {
            problem = Some((seed, Problem::paper(seed)?));
        }
        let (_, p) = problem.as_ref().expect("made above");
        records.push(run_k(p, seed, k, options, &mut on_point)?);
    }
    Ok(records)
}

/// Shards' records back into one run's: every grid point once, in the grid's order.
pub fn merge(mut parts: Vec<Vec<SweepRecord>>) -> Result<Vec<SweepRecord>, Error> {
    let mut all: Vec<SweepRecord> = parts.drain(..).flatten().collect();
    all.sort_by_key(|r| (r.data_seed, r.k));
    for pair in all.windows(2) {
        if (pair[0].data_seed, pair[0].k) == (pair[1].data_seed, pair[1].k) {
            return Err(Error::invalid(format!(
                "merge: K = {} with data seed {} appears in two shards",
                pair[0].k, pair[0].data_seed
            )));
        }
    }
    Ok(all)
}
