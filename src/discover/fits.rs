//! The sampled fits before and after the selected terms: noise, RMSE, log likelihood, the
//! posterior means of the parameters, residual whiteness (Ljung–Box), convergence, and where
//! BM2's discrepancy band excludes zero.

use std::collections::BTreeMap;

use serde::Serialize;
use statrs::distribution::{ChiSquared, ContinuousCDF};

use crate::bayes::{CalibrationPosterior, ModelSettings};
use crate::density::LogDensity;
use crate::diagnostics::{autocovariance, khat_threshold};
use crate::error::Error;
use crate::optimize::{MapSettings, find_map};
use crate::pipeline::{
    MapSearch, RunOutput, RunSettings, SamplerKind, default_warmup, finish_run, run_sampler,
};
use crate::sampler::driver::chain_rng;
use crate::sampler::proposal::LaplaceProposal;
use crate::sampler::{ChainOutput, DrawRecord, PhaseCost};
use crate::study::{Predictive, Problem, posterior_predictive};

use super::settings::{LAPLACE_DRAWS, uses_laplace};
use crate::pipeline::posterior_mean;

/// Lags of the Ljung–Box statistic: 20, the usual choice for a few hundred samples, long enough
/// to see the slow drifts a missing term leaves and short against 501 samples.
pub const LJUNG_BOX_LAGS: usize = 20;

/// Ljung–Box Q over the first `LJUNG_BOX_LAGS` lags and its p-value under whiteness (χ² with as
/// many degrees of freedom).
#[derive(Clone, Debug, Serialize)]
pub struct Whiteness {
    pub q: f64,
    pub lags: usize,
    pub p_value: f64,
}

pub fn ljung_box(residual: &[f64]) -> Whiteness {
    let n = residual.len();
    let lags = LJUNG_BOX_LAGS.min(n.saturating_sub(2)).max(1);
    let mean = residual.iter().sum::<f64>() / n as f64;
    let centred: Vec<f64> = residual.iter().map(|v| v - mean).collect();
    let acov = autocovariance(&centred);
    let q = if acov[0] > 0.0 {
        (1..=lags)
            .map(|k| (acov[k] / acov[0]).powi(2) / (n - k) as f64)
            .sum::<f64>()
            * (n * (n + 2)) as f64
    } else {
        0.0
    };
    let p_value = ChiSquared::new(lags as f64)
        .map(|d| 1.0 - d.cdf(q))
        .unwrap_or(f64::NAN);
    Whiteness { q, lags, p_value }
}

/// One sampled BM1 fit, as the report shows it.
#[derive(Clone, Debug, Serialize)]
pub struct FitSummary {
    /// The noise σ per channel (posterior mean), keyed by the recording's column name; with
    /// several recordings, `column@record`.
    pub sigma: BTreeMap<String, f64>,
    /// RMSE of y − G(θ) at the posterior mean, keyed likewise.
    pub rmse: BTreeMap<String, f64>,
    /// The log likelihood at the posterior mean.
    pub log_likelihood: f64,
    /// Posterior means of the calibrated parameters (physical values).
    pub params_mean: BTreeMap<String, f64>,
    /// 95% intervals of the calibrated parameters.
    pub params_95: BTreeMap<String, [f64; 2]>,
    pub whiteness: BTreeMap<String, Whiteness>,
}

/// R-hat, ESS and divergences of one run.
#[derive(Clone, Debug, Serialize)]
pub struct Convergence {
    pub sampler: String,
    pub max_rhat: f64,
    pub min_ess_bulk: f64,
    pub divergences: usize,
    pub wall_s: f64,
    /// PSIS k̂ of importance sampling from the Laplace approximation (null where it was not
    /// tried: a long record's Laplace draws).
    pub khat: Option<f64>,
    /// Whether k̂ above the line of [`khat_threshold`] sent the fit to NUTS.
    pub fell_back: bool,
    /// Whether that NUTS run spent its budget ([`FALLBACK_GRADIENTS_PER_TRANSITION`]) and the
    /// importance sample with the lower k̂ stands, `khat` its own: a summary to read as the
    /// Laplace approximation's.
    pub fallback_stopped: bool,
}

impl Convergence {
    pub fn of(run: &RunOutput) -> Self {
        Self {
            sampler: run.sampler.clone(),
            max_rhat: run.max_rhat,
            min_ess_bulk: run.min_ess_bulk,
            divergences: run.divergences,
            wall_s: run.wall_seconds,
            khat: run.khat,
            fell_back: run.fell_back,
            fallback_stopped: run.fallback_stopped,
        }
    }
}

/// A sampled fit and its posterior, for the figures.
#[derive(Clone, Debug)]
pub struct SampledFit {
    pub posterior: CalibrationPosterior,
    pub run: RunOutput,
}

/// Samples `problem` (a candidate problem: terms on, calibrated) under `settings`: importance
/// sampling from the Laplace approximation where its Pareto k̂ says the weights can be trusted,
/// NUTS (`run`'s sampler) where not, and for long records independent draws from the Laplace
/// approximation at the MAP.
pub fn sample(
    problem: &Problem,
    settings: &ModelSettings,
    run: &RunSettings,
    label: &str,
) -> Result<SampledFit, Error> {
    let mut posterior = problem.posterior(settings)?;
    let run = if uses_laplace(problem) {
        laplace_run(&mut posterior, run.seed)?
    } else {
        importance_or_sampler(&mut posterior, run, label)?
    };
    Ok(SampledFit { posterior, run })
}

/// What a diagnosis's NUTS fallback may spend per transition on average, per chain, in
/// gradients at the integrator's work of one at the MAP, before the importance sample with the
/// lower k̂ stands instead (`RunSettings::fallback_budget`). Where the Laplace or the windowed
/// metric captures the posterior, NUTS's trees are 2–3 levels deep (7 leapfrog steps a draw on
/// compliant_coupling-740010's fit after, dense NUTS with Stan's windows); 16, a level deeper
/// on average over warm-up and draws, is room for a posterior a few times longer than its
/// metric says. A fallback that needs more is one whose geometry neither metric holds — a
/// term's parameter the record cannot pin, a ridge — where its draws would not be trusted
/// either, and where it cost minutes: a dead compliant coupling beside the law on
/// gear_ripple-730002 took a diagnosis to 487 s, and `fit --sampler laplace-is` on that model
/// 807 s (papers/beyond-library.md, session 8). The bound is the model's own cost: 4 × 1500 ×
/// 16 gradients at the mode's price, which a model dear to solve makes long still.
pub const FALLBACK_GRADIENTS_PER_TRANSITION: u64 = 16;

/// `laplace-is` with `run`'s chains × draws proposals, kept where k̂ is below the line at
/// which a Pareto-smoothed estimate from that many weights is reliable, min(1 − 1/log₁₀ S, 0.7)
/// (Vehtari et al. 2024, eq. 13: 0.697 at diagnose's 4 × 500); above it, a second, wider
/// proposal judged by the same line (`RunSettings::defensive_proposal`), and above that too,
/// laplace-is's own fallback (NUTS on the same problem, the first k̂ kept). The line was 0.5 (the older paper's
/// "finite variance" bound) until a bearing's fit at k̂ 0.55 spent 37 s of a 47-s diagnosis in
/// a NUTS run with 77 divergences (papers/beyond-library.md, session 4). The calibration
/// posteriors are close to Gaussian in their unconstrained coordinates, so most fits stay on
/// the importance path: one plain solve per proposal against a dual-number solve per leapfrog
/// step.
fn importance_or_sampler(
    posterior: &mut CalibrationPosterior,
    run: &RunSettings,
    label: &str,
) -> Result<RunOutput, Error> {
    let importance = RunSettings {
        sampler: SamplerKind::LaplaceIs,
        fallback: true,
        fallback_above: khat_threshold(run.chains * run.chain.draws),
        defensive_proposal: true,
        fallback_budget: Some(FALLBACK_GRADIENTS_PER_TRANSITION),
        // The fit starts at a candidate's MAP, found by the ranking's search.
        map_search: MapSearch::Ranking,
        // The run's warm-up is NUTS's; importance sampling's is its own recentring (BM2 fits
        // only: see `pipeline::importance`).
        chain: crate::sampler::ChainSettings {
            warmup: default_warmup(SamplerKind::LaplaceIs, run.metric_adaptation),
            ..run.chain.clone()
        },
        ..run.clone()
    };
    run_sampler(posterior, &importance, label)
}

/// x = MAP + L⁻ᵀ z with z ~ N(0, I) and L Lᵀ the Hessian at the MAP (the Gaussian form of
/// the samplers' [`LaplaceProposal`]), as one "chain" of independent draws, so that every
/// summary and figure downstream reads it like a sampled run.
fn laplace_run(posterior: &mut CalibrationPosterior, seed: u64) -> Result<RunOutput, Error> {
    let started = std::time::Instant::now();
    let start = posterior.initial_point()?;
    let map = find_map(posterior, &start, &MapSettings::ranking())?;
    let proposal = LaplaceProposal::new(&map.x, &map.hessian).map_err(Error::Numerical)?;
    let mut rng = chain_rng(seed ^ 0x1a91_ace0, 0);
    let names = posterior.output_names();
    let mut draws = Vec::with_capacity(LAPLACE_DRAWS);
    let mut unconstrained = Vec::with_capacity(LAPLACE_DRAWS);
    for _ in 0..LAPLACE_DRAWS {
        let x = proposal.draw(&mut rng);
        let mut out = Vec::new();
        posterior.constrain(&x, &mut out);
        draws.push(out);
        unconstrained.push(x);
    }
    let chain = ChainOutput {
        chain: 0,
        sampler: LAPLACE.into(),
        names,
        draws,
        unconstrained,
        records: vec![DrawRecord::default(); LAPLACE_DRAWS],
        warmup: PhaseCost::default(),
        sampling: PhaseCost {
            wall_seconds: started.elapsed().as_secs_f64(),
            ..PhaseCost::default()
        },
        uses_gradient: true,
        divergences: 0,
        mean_accept_stat: 1.0,
        final_step_size: 0.0,
        warmup_draws: Vec::new(),
        warmup_records: Vec::new(),
    };
    Ok(finish_run(LAPLACE, vec![chain], &map, started))
}

/// The sampler name a Laplace fit reports.
pub const LAPLACE: &str = "laplace (draws from the Gaussian at the MAP)";

/// The recording's own name of a model channel.
pub fn column_name(problem: &Problem, channel: &str) -> String {
    problem.model.channels.column(channel).to_string()
}

fn key(problem: &Problem, record: usize, channel: &str) -> String {
    let column = column_name(problem, channel);
    if problem.recordings.len() > 1 {
        format!("{column}@{}", problem.recordings[record].source)
    } else {
        column
    }
}

pub fn summarize_fit(problem: &Problem, fit: &mut SampledFit) -> Result<FitSummary, Error> {
    let mean = posterior_mean(&fit.run);
    let posterior = &mut fit.posterior;
    let mut sigma = BTreeMap::new();
    let mut rmse = BTreeMap::new();
    let mut whiteness = BTreeMap::new();
    for r in 0..posterior.n_records() {
        let residuals = posterior.residuals(&mean, r)?;
        for (c, name) in posterior.channel_names(r).into_iter().enumerate() {
            let k = key(problem, r, &name);
            let res = &residuals[c];
            rmse.insert(
                k.clone(),
                (res.iter().map(|v| v * v).sum::<f64>() / res.len() as f64).sqrt(),
            );
            let s = fit
                .run
                .summary(&format!("sigma_{}", sigma_suffix(posterior, r, c)))
                .map(|s| s.mean)
                .unwrap_or_else(|| mean[posterior.log_sigma_index(r, c)].exp());
            sigma.insert(k.clone(), s);
            whiteness.insert(k, ljung_box(res));
        }
    }
    let mut params_mean = BTreeMap::new();
    let mut params_95 = BTreeMap::new();
    for c in posterior.calibrated() {
        if let Some(s) = fit.run.summary(&c.output_name()) {
            params_mean.insert(c.name.clone(), s.mean);
            params_95.insert(c.name.clone(), [s.q025, s.q975]);
        }
    }
    Ok(FitSummary {
        sigma,
        rmse,
        log_likelihood: posterior.log_likelihood(&mean)?,
        params_mean,
        params_95,
        whiteness,
    })
}

/// The suffix the run's summaries give a channel's σ (`I`, `omega`, or `I_2` for a second
/// recording), read from the posterior's own names.
fn sigma_suffix(posterior: &CalibrationPosterior, record: usize, channel: usize) -> String {
    let names = posterior.parameter_names();
    names[posterior.log_sigma_index(record, channel)]
        .trim_start_matches("log_sigma_")
        .to_string()
}

/// Where BM2's 95% band of δ excludes zero, per record and channel.
#[derive(Clone, Debug, Serialize)]
pub struct Mismatch {
    pub channel: String,
    pub t_start: f64,
    pub t_end: f64,
    /// The largest |posterior mean of δ| in the interval, over the channel's noise σ.
    pub max_over_sigma: f64,
}

/// The share of a record an interval must cover to count as a mismatch when judging whether any
/// is left: a pointwise 95% band over hundreds of samples excludes zero on a few isolated samples
/// by chance, a missing effect does so on a stretch.
pub const MISMATCH_MIN_SHARE: f64 = 0.05;

pub fn mismatches(
    problem: &Problem,
    fit: &mut SampledFit,
) -> Result<(Vec<Mismatch>, Vec<Predictive>), Error> {
    let mut out = Vec::new();
    let mut predictives = Vec::new();
    for r in 0..fit.posterior.n_records() {
        let p = posterior_predictive(&mut fit.posterior, &fit.run.chains, r)?;
        for ch in &p.channels {
            let mut start: Option<usize> = None;
            let m = p.times.len();
            for i in 0..=m {
                let excludes =
                    i < m && (ch.discrepancy_lower[i] > 0.0 || ch.discrepancy_upper[i] < 0.0);
                match (excludes, start) {
                    (true, None) => start = Some(i),
                    (false, Some(s)) => {
                        let peak = (s..i)
                            .map(|j| ch.discrepancy_mean[j].abs())
                            .fold(0.0, f64::max);
                        out.push(Mismatch {
                            channel: key(problem, r, &ch.name),
                            t_start: p.times[s],
                            t_end: p.times[i - 1],
                            max_over_sigma: peak / ch.sigma,
                        });
                        let _ = s;
                        start = None;
                    }
                    _ => {}
                }
            }
        }
        predictives.push(p);
    }
    Ok((out, predictives))
}

/// Whether a mismatch covers enough of its record to say the model still lacks something.
pub fn substantial(mismatch: &Mismatch, problem: &Problem) -> bool {
    let duration = problem
        .recordings
        .iter()
        .map(|r| r.last_time() - r.time.first().copied().unwrap_or(0.0))
        .fold(0.0, f64::max);
    mismatch.t_end - mismatch.t_start >= MISMATCH_MIN_SHARE * duration
}
