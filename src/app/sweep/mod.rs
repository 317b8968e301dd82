//! `motorcal sweep`: BM2 for each K on the paper's data, with the paper's error measures
//! (Definition 4.2 for R, σ_I, σ_ω against the truth; Definition 4.3 for δ_I, δ_ω against the
//! reference discrepancy d0), convergence, and the figures mirroring Figures 8–11.

pub mod select;

use std::path::PathBuf;
use std::time::Instant;

use serde::{Deserialize, Serialize};

use crate::app::AppError;
use crate::app::problem::{Problem, Reference};
use crate::bayes::{CoefficientPrior, ModelSettings};
use crate::diagnostics::ParameterSummary;
use crate::evidence::importance_sampling;
use crate::pipeline::{RunCost, RunOutput, RunSettings, map_estimate, run_sampler};
use crate::plot::{self, KSeries};

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
pub fn run_k(
    problem: &Problem,
    data_seed: u64,
    k: usize,
    options: &SweepOptions,
) -> Result<SweepRecord, AppError> {
    let reference: &Reference = problem
        .reference
        .as_ref()
        .ok_or_else(|| AppError::Usage("sweep needs a synthetic problem with a truth".into()))?;
    let mut settings = ModelSettings::bm2(k);
    settings.coefficient_prior = options.coefficient_prior;
    settings
        .validate()
        .map_err(|e| AppError::Usage(format!("--k {k}: {e}")))?;
    let started = Instant::now();
    let mut posterior = problem.posterior(&settings)?;
    let run = run_sampler(&mut posterior, &options.run, &settings.label())?;
    let wall_s = started.elapsed().as_secs_f64();
    let map = map_estimate(&mut posterior)?;
    let evidence = importance_sampling(&mut posterior, &map, EVIDENCE_DRAWS, EVIDENCE_SEED)
        .map_err(AppError::Numerical)?;
    let summary = |name: &str| {
        run.summary(name)
            .ok_or_else(|| AppError::Numerical(format!("no summary of {name}")))
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
    if options.figures_at.contains(&k) {
        k_figures(&mut posterior, &run, reference, k, options)?;
    }
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

/// δ's band with d0, and the coefficients' marginals with d0's least-squares coefficients, at K.
fn k_figures(
    posterior: &mut crate::bayes::CalibrationPosterior,
    run: &RunOutput,
    reference: &Reference,
    k: usize,
    options: &SweepOptions,
) -> Result<(), AppError> {
    std::fs::create_dir_all(&options.out)?;
    let predictive = crate::app::predictive::posterior_predictive(posterior, &run.chains, 0)?;
    crate::app::predictive::plot_discrepancy(
        &options.out.join(format!("fig13-delta-k{k}.png")),
        &format!(
            "δ at K = {k} with the reference d₀ ({})",
            options.coefficient_prior.label()
        ),
        &predictive,
        Some(&reference.discrepancy),
    )?;
    let n_x = crate::density::LogDensity::dim(posterior);
    let mut channels = Vec::new();
    for (c, name) in ["I", "omega"].iter().enumerate() {
        let range = posterior
            .coefficient_range(0, c)
            .ok_or_else(|| AppError::Numerical("BM2 without coefficients".into()))?;
        // The basis columns: δ is linear in the coefficients.
        let m = reference.discrepancy[c].len();
        let mut basis = nalgebra::DMatrix::zeros(m, range.len());
        for (col, j) in range.clone().enumerate() {
            let mut x = vec![0.0; n_x];
            x[j] = 1.0;
            let column = posterior.discrepancy(&x, 0, c);
            for i in 0..m {
                basis[(i, col)] = column[i];
            }
        }
        let d0 = nalgebra::DVector::from_column_slice(&reference.discrepancy[c]);
        let least_squares = (basis.transpose() * &basis)
            .cholesky()
            .map(|ch| ch.solve(&(basis.transpose() * d0)));
        let summaries: Vec<&crate::diagnostics::ParameterSummary> = (1..=range.len())
            .map(|j| {
                run.summary(&format!("a_{name}.{j}"))
                    .ok_or_else(|| AppError::Numerical(format!("no summary of a_{name}.{j}")))
            })
            .collect::<Result<_, _>>()?;
        channels.push(plot::CoefficientMarginals {
            name: (*name).into(),
            unit: if c == 0 { "A" } else { "rad/s" }.into(),
            mean: summaries.iter().map(|s| s.mean).collect(),
            lower: summaries.iter().map(|s| s.q025).collect(),
            upper: summaries.iter().map(|s| s.q975).collect(),
            reference: least_squares.map(|v| v.iter().copied().collect()),
        });
    }
    plot::coefficient_marginals(
        &options.out.join(format!("fig14-coefficients-k{k}.png")),
        &format!(
            "Coefficients at K = {k} ({})",
            options.coefficient_prior.label()
        ),
        &channels,
    )
    .map_err(|e| AppError::Output(e.to_string()))
}

/// Every grid point of this shard (all of them without `--shard`), on the paper's set-up with
/// each data seed.
pub fn sweep(options: &SweepOptions) -> Result<Vec<SweepRecord>, AppError> {
    if options.ks.is_empty() {
        return Err(AppError::Usage("--k: no degree given".into()));
    }
    if options.data_seeds.is_empty() {
        return Err(AppError::Usage("--data-seed: no seed given".into()));
    }
    if let Some((i, n)) = options.shard
        && !(n >= 1 && (1..=n).contains(&i))
    {
        return Err(AppError::Usage(format!("--shard {i}/{n}: need 1 ≤ i ≤ n")));
    }
    options.run.validate()?;
    for &k in &options.ks {
        let mut settings = ModelSettings::bm2(k);
        settings.coefficient_prior = options.coefficient_prior;
        settings
            .validate()
            .map_err(|e| AppError::Usage(format!("--k {k}: {e}")))?;
    }
    let mut records = Vec::new();
    let mut problem: Option<(u64, Problem)> = None;
    for (seed, k) in shard_of(options) {
        if problem.as_ref().is_none_or(|(s, _)| *s != seed) {
            problem = Some((seed, Problem::paper(seed)?));
        }
        let (_, p) = problem.as_ref().expect("made above");
        records.push(run_k(p, seed, k, options)?);
    }
    Ok(records)
}

/// Shards' records back into one run's: every grid point once, in the grid's order.
pub fn merge(mut parts: Vec<Vec<SweepRecord>>) -> Result<Vec<SweepRecord>, AppError> {
    let mut all: Vec<SweepRecord> = parts.drain(..).flatten().collect();
    all.sort_by_key(|r| (r.data_seed, r.k));
    for pair in all.windows(2) {
        if (pair[0].data_seed, pair[0].k) == (pair[1].data_seed, pair[1].k) {
            return Err(AppError::Usage(format!(
                "merge: K = {} with data seed {} appears in two shards",
                pair[0].k, pair[0].data_seed
            )));
        }
    }
    Ok(all)
}

/// `sweep.csv`, `sweep.json` (or `--json`) and the figures.
pub fn write_outputs(
    records: &[SweepRecord],
    options: &SweepOptions,
) -> Result<Vec<PathBuf>, AppError> {
    std::fs::create_dir_all(&options.out)?;
    let mut written = Vec::new();
    let mut csv = String::from(
        "k,prior,data_seed,chain_seed,sampler,\
         R_mean,R_sd,R_q05,R_q95,R_q025,R_q975,R_bias,R_variance,R_mse,\
         sigma_I_mean,sigma_I_sd,sigma_I_q025,sigma_I_q975,sigma_I_bias,sigma_I_variance,sigma_I_mse,\
         sigma_omega_mean,sigma_omega_sd,sigma_omega_q025,sigma_omega_q975,sigma_omega_bias,sigma_omega_variance,sigma_omega_mse,\
         delta_I_nbias,delta_I_nv,delta_I_nmse,delta_I_nmse_bound,\
         delta_omega_nbias,delta_omega_nv,delta_omega_nmse,delta_omega_nmse_bound,\
         max_rhat,min_ess_bulk,min_ess_tail,divergences,wall_s,\
         log_evidence,log_evidence_se,log_evidence_ess,log_evidence_laplace,\
         map_cpu_s,warmup_cpu_s,sampling_cpu_s,total_cpu_s,evaluations,all_evaluations,\
         min_ess_per_s,min_ess_per_total_s,min_ess_per_eval,min_ess_per_all_evals\n",
    );
    for r in records {
        let s = |x: &ScalarStats| {
            format!(
                "{},{},{},{},{},{},{}",
                x.mean, x.sd, x.q025, x.q975, x.bias, x.variance, x.mse
            )
        };
        let d =
            |x: &DiscrepancyStats| format!("{},{},{},{}", x.n_bias, x.n_v, x.n_mse, x.n_mse_bound);
        csv.push_str(&format!(
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n",
            r.k,
            r.prior,
            r.data_seed,
            r.chain_seed,
            r.sampler,
            r.r.mean,
            r.r.sd,
            r.r.q05,
            r.r.q95,
            r.r.q025,
            r.r.q975,
            r.r.bias,
            r.r.variance,
            r.r.mse,
            s(&r.sigma_i),
            s(&r.sigma_omega),
            d(&r.delta_i),
            d(&r.delta_omega),
            r.max_rhat,
            r.min_ess_bulk,
            r.min_ess_tail,
            r.divergences,
            r.wall_s,
            r.evidence.log_evidence,
            r.evidence.standard_error,
            r.evidence.effective_draws,
            r.evidence.log_evidence_laplace,
            cost_columns(&r.cost),
        ));
    }
    let path = options.out.join("sweep.csv");
    crate::io::write_atomically(&path, csv.as_bytes())?;
    written.push(path);
    let path = options
        .json
        .clone()
        .unwrap_or_else(|| options.out.join("sweep.json"));
    let text =
        serde_json::to_string_pretty(records).map_err(|e| AppError::Output(e.to_string()))?;
    crate::io::write_atomically(&path, text.as_bytes())?;
    written.push(path);
    // Figures against K are of one data set; a grid over several seeds is for the tables.
    let one_seed = records.windows(2).all(|w| w[0].data_seed == w[1].data_seed);
    if one_seed && !records.is_empty() {
        written.extend(figures(records, options)?);
    }
    Ok(written)
}

fn cost_columns(c: &RunCost) -> String {
    format!(
        "{},{},{},{},{},{},{},{},{},{}",
        c.map.cpu_seconds,
        c.warmup.cpu_seconds,
        c.sampling.cpu_seconds,
        c.total_cpu_s,
        c.evaluations,
        c.all_evaluations,
        c.min_ess_per_s,
        c.min_ess_per_total_s,
        c.min_ess_per_eval,
        c.min_ess_per_all_evals
    )
}

fn figures(records: &[SweepRecord], options: &SweepOptions) -> Result<Vec<PathBuf>, AppError> {
    let ks: Vec<f64> = records.iter().map(|r| r.k as f64).collect();
    let series = |name: &str, unit: &str, f: &dyn Fn(&SweepRecord) -> f64, log_y: bool| KSeries {
        name: name.into(),
        unit: unit.into(),
        k: ks.clone(),
        mean: records.iter().map(f).collect(),
        log_y,
        ..KSeries::default()
    };
    let marginal = |name: &str, unit: &str, f: &dyn Fn(&SweepRecord) -> &ScalarStats| KSeries {
        name: name.into(),
        unit: unit.into(),
        k: ks.clone(),
        mean: records.iter().map(|r| f(r).mean).collect(),
        lower: Some(records.iter().map(|r| f(r).q025).collect()),
        upper: Some(records.iter().map(|r| f(r).q975).collect()),
        sd: Some(records.iter().map(|r| f(r).sd).collect()),
        reference: records.first().map(|r| f(r).reference),
        log_y: false,
    };
    let prior = records.first().map(|r| r.prior.clone()).unwrap_or_default();
    let plot_error = |e: plot::PlotError| AppError::Output(e.to_string());
    let mut written = Vec::new();
    let fig8 = options.out.join("fig8-marginals.png");
    plot::k_study(
        &fig8,
        &format!("Marginal posteriors against K ({prior})"),
        &[
            marginal("R", "Ω", &|r| &r.r),
            marginal("σ_I", "A", &|r| &r.sigma_i),
            marginal("σ_ω", "rad/s", &|r| &r.sigma_omega),
        ],
    )
    .map_err(plot_error)?;
    written.push(fig8);
    let fig9 = options.out.join("fig9-r-error.png");
    plot::k_study(
        &fig9,
        "Bias², variance and MSE of R against K",
        &[
            series("Bias(R)²", "Ω²", &|r| r.r.bias * r.r.bias, true),
            series("V(R)", "Ω²", &|r| r.r.variance, true),
            series("MSE(R)", "Ω²", &|r| r.r.mse, true),
        ],
    )
    .map_err(plot_error)?;
    written.push(fig9);
    let fig10 = options.out.join("fig10-sigma-error.png");
    plot::k_study(
        &fig10,
        "MSE of the noise standard deviations against K",
        &[
            series("MSE(σ_I)", "A²", &|r| r.sigma_i.mse, true),
            series("MSE(σ_ω)", "(rad/s)²", &|r| r.sigma_omega.mse, true),
        ],
    )
    .map_err(plot_error)?;
    written.push(fig10);
    let fig11 = options.out.join("fig11-delta-error.png");
    plot::k_study(
        &fig11,
        "nBias, nV and nMSE of δ against K",
        &[
            series("nBias(δ_I)", "A", &|r| r.delta_i.n_bias, true),
            series("nMSE(δ_I)", "A²", &|r| r.delta_i.n_mse, true),
            series("nBias(δ_ω)", "rad/s", &|r| r.delta_omega.n_bias, true),
            series("nMSE(δ_ω)", "(rad/s)²", &|r| r.delta_omega.n_mse, true),
        ],
    )
    .map_err(plot_error)?;
    written.push(fig11);
    Ok(written)
}

/// The table a user reads.
pub fn format_table(records: &[SweepRecord]) -> String {
    let mut s = format!(
        "{:>3} {:>11} {:>10} {:>10} {:>8} {:>8} {:>9} {:>9} {:>7} {:>7} {:>6}\n",
        "K", "R mean", "R sd", "MSE(R)", "σ_I", "σ_ω", "nBias δI", "nBias δω", "R-hat", "ESS", "s"
    );
    for r in records {
        s.push_str(&format!(
            "{:>3} {:>11.6} {:>10.2e} {:>10.2e} {:>8.4} {:>8.4} {:>9.3} {:>9.3} {:>7.4} {:>7.0} {:>6.1}\n",
            r.k,
            r.r.mean,
            r.r.sd,
            r.r.mse,
            r.sigma_i.mean,
            r.sigma_omega.mean,
            r.delta_i.n_bias,
            r.delta_omega.n_bias,
            r.max_rhat,
            r.min_ess_bulk,
            r.wall_s
        ));
    }
    s
}
