//! `motorcal reproduce table1`: the paper's Table 1 (BM1 and BM2(K = 9) on its synthetic data)
//! with the paper's Metropolis protocol, beside other samplers on the same data.

use std::path::PathBuf;

use serde::Serialize;

use crate::bayes::{CalibrationPosterior, ModelSettings};
use crate::sampler::ChainSettings;
use crate::synthetic::DEFAULT_SEED;

use crate::error::Error;
use crate::io::provenance;
use crate::pipeline::{MetricAdaptation, RunOutput, RunSettings, SamplerKind, run_sampler};
use crate::study::{Problem, Reference};

/// Table 1 of the paper, quoted for comparison only: posterior means of R, σ_I, σ_ω and their
/// relative errors as the paper prints them (recomputing the errors from its rounded means
/// would give other digits: BM1's σ_ω, 1.03e+01, would read 3.0e-2 instead of its 2.79e-2).
pub const PAPER_TABLE1: [(&str, [f64; 3], [f64; 3]); 2] = [
    ("BM1", [9.03e-2, 6.29, 10.3], [9.66e-2, 2.14, 2.79e-2]),
    (
        "BM2(K=9)",
        [9.92e-2, 2.02, 9.95],
        [8.48e-3, 1.03e-2, 4.89e-3],
    ),
];
/// §4.2: relative L² error of the posterior-mean δ against d0, for I and ω (K = 9).
pub const PAPER_DISCREPANCY_ERROR: [f64; 2] = [0.10, 0.092];

/// Options of `motorcal reproduce table1`.
#[derive(Clone, Debug, Serialize)]
pub struct Table1Options {
    pub seed: u64,
    /// Shorter BM2 runs (10% of the paper's length), for a first look.
    pub quick: bool,
    pub samplers: Vec<SamplerKind>,
    pub chains: usize,
    pub threads: Option<usize>,
    pub out: PathBuf,
    pub quiet: bool,
    /// How NUTS tunes its metric: Stan's windows by default, as the table in papers/john2018
    /// §1 was made (its draws are pinned).
    pub metric_adaptation: MetricAdaptation,
}

impl Default for Table1Options {
    fn default() -> Self {
        Self {
            seed: DEFAULT_SEED,
            quick: false,
            samplers: vec![
                SamplerKind::Metropolis,
                SamplerKind::AdaptiveMetropolis,
                SamplerKind::NutsDense,
            ],
            chains: 3,
            threads: None,
            out: PathBuf::from("out/table1"),
            quiet: false,
            metric_adaptation: MetricAdaptation::Windows,
        }
    }
}

/// One row of the reproduced table.
#[derive(Clone, Debug, Serialize)]
pub struct Table1Row {
    pub model: String,
    pub sampler: String,
    pub warmup: usize,
    pub draws: usize,
    pub kept: usize,
    pub chains: usize,
    pub mean_r: f64,
    pub mean_sigma_i: f64,
    pub mean_sigma_omega: f64,
    pub rel_error_r: f64,
    pub rel_error_sigma_i: f64,
    pub rel_error_sigma_omega: f64,
    /// ‖E[δ] − d0‖ / ‖d0‖ per channel (BM2 only).
    pub discrepancy_rel_error: Option<[f64; 2]>,
    pub max_rhat: f64,
    pub min_ess_bulk: f64,
    pub wall_seconds: f64,
    pub converged: bool,
}

/// The whole reproduction: rows plus the data's realised noise.
#[derive(Clone, Debug, Serialize)]
pub struct Table1Report {
    pub seed: u64,
    pub realised_noise_sd: Vec<f64>,
    pub rows: Vec<Table1Row>,
    pub provenance: Vec<(String, String)>,
    pub options: Table1Options,
}

/// The paper's protocol (§4.1–4.2): 3 chains, 500 tuning iterations (PyMC3's default),
/// BM1 1500 draws keeping the last 700, BM2 100000 draws keeping the last 40000.
pub fn paper_protocol(bm2: bool, quick: bool) -> ChainSettings {
    match (bm2, quick) {
        (false, _) => ChainSettings {
            warmup: 500,
            draws: 1500,
            keep: Some(700),
        },
        (true, false) => ChainSettings {
            warmup: 500,
            draws: 100_000,
            keep: Some(40_000),
        },
        (true, true) => ChainSettings {
            warmup: 500,
            draws: 10_000,
            keep: Some(4_000),
        },
    }
}

/// The run length per sampler. The paper's Metropolis follows the paper; the adaptive
/// Metropolis, a baseline meant to converge, gets a longer warm-up (its covariance is learnt
/// there) and, for BM1, all of ten times the paper's draws: random-walk proposals in 3
/// dimensions give about 0.1 effective draws per draw, so 700 kept draws cannot show
/// R-hat ≤ 1.01.
pub fn protocol(sampler: SamplerKind, bm2: bool, quick: bool) -> ChainSettings {
    match sampler {
        SamplerKind::Metropolis => paper_protocol(bm2, quick),
        SamplerKind::AdaptiveMetropolis => match (bm2, quick) {
            (false, _) => ChainSettings {
                warmup: 1000,
                draws: 10_000,
                keep: None,
            },
            (true, false) => ChainSettings {
                warmup: 5000,
                draws: 100_000,
                keep: Some(40_000),
            },
            (true, true) => ChainSettings {
                warmup: 5000,
                draws: 10_000,
                keep: Some(4_000),
            },
        },
        // Gradient samplers: Stan's default lengths.
        _ if quick => ChainSettings {
            warmup: 500,
            draws: 500,
            keep: None,
        },
        _ => ChainSettings {
            warmup: 1000,
            draws: 1000,
            keep: None,
        },
    }
}

fn relative_error(estimate: f64, reference: f64) -> f64 {
    (estimate - reference).abs() / reference.abs()
}

/// ‖E[δ] − d0‖/‖d0‖ per channel from the posterior mean of the coefficients.
fn discrepancy_errors(
    posterior: &CalibrationPosterior,
    run: &RunOutput,
    d0: &[Vec<f64>],
) -> Option<[f64; 2]> {
    let mut mean = vec![0.0; posterior.dim_of_outputs()];
    for (j, s) in run.summaries.iter().enumerate() {
        mean[j] = s.mean;
    }
    let mut out = [0.0; 2];
    for (c, slot) in out.iter_mut().enumerate() {
        posterior.coefficient_range(0, c)?;
        let delta = posterior.discrepancy(&mean, 0, c);
        let num: f64 = delta.iter().zip(&d0[c]).map(|(a, b)| (a - b).powi(2)).sum();
        let den: f64 = d0[c].iter().map(|b| b * b).sum();
        *slot = (num / den).sqrt();
    }
    Some(out)
}

/// One run of the table as it finishes, for a caller that keeps its draws and figures.
pub struct Table1Run<'a> {
    /// BM1 or BM2(K=9).
    pub model: String,
    pub settings: &'a RunSettings,
    pub run: &'a RunOutput,
    pub posterior: &'a mut CalibrationPosterior,
    /// The truth of R, σ_I, σ_ω, and the reference discrepancy d0 per channel.
    pub truth: [f64; 3],
    pub reference: &'a Reference,
}

/// Table 1 on the paper's synthetic data: BM1 and BM2(K = 9) with each sampler.
pub fn reproduce_table1(options: &Table1Options) -> Result<Table1Report, Error> {
    reproduce_table1_with(options, |_| Ok::<_, Error>(()))
}

/// As [`reproduce_table1`]; `on_run` sees every run as it finishes (the command writes its
/// draws and figures there).
pub fn reproduce_table1_with<E: From<Error>>(
    options: &Table1Options,
    mut on_run: impl FnMut(Table1Run<'_>) -> Result<(), E>,
) -> Result<Table1Report, E> {
    if options.samplers.is_empty() {
        return Err(Error::setting("samplers", "", "name at least one sampler").into());
    }
    let problem = Problem::paper(options.seed)?;
    let reference = problem
        .reference
        .clone()
        .expect("the paper's problem has a reference");
    let truth = [
        reference.truth.resistance,
        reference.noise_sd[0],
        reference.noise_sd[1],
    ];
    let mut rows = Vec::new();
    for settings in [ModelSettings::bm1(), ModelSettings::bm2(9)] {
        let bm2 = settings.discrepancy_degree.is_some();
        let mut posterior = problem.posterior(&settings)?;
        for &sampler in &options.samplers {
            let run_settings = RunSettings {
                sampler,
                chains: options.chains,
                chain: protocol(sampler, bm2, options.quick),
                seed: options.seed,
                threads: options.threads,
                quiet: options.quiet,
                metric_adaptation: options.metric_adaptation,
                ..RunSettings::default()
            };
            let run = run_sampler(&mut posterior, &run_settings, &settings.label())?;
            let mean = |name: &str| run.summary(name).map_or(f64::NAN, |s| s.mean);
            let means = [mean("R"), mean("sigma_I"), mean("sigma_omega")];
            let discrepancy_rel_error = if bm2 {
                discrepancy_errors(&posterior, &run, &reference.discrepancy)
            } else {
                None
            };
            rows.push(Table1Row {
                model: settings.label(),
                sampler: run.sampler.clone(),
                warmup: run_settings.chain.warmup,
                draws: run_settings.chain.draws,
                kept: run_settings.chain.kept(),
                chains: options.chains,
                mean_r: means[0],
                mean_sigma_i: means[1],
                mean_sigma_omega: means[2],
                rel_error_r: relative_error(means[0], truth[0]),
                rel_error_sigma_i: relative_error(means[1], truth[1]),
                rel_error_sigma_omega: relative_error(means[2], truth[2]),
                discrepancy_rel_error,
                max_rhat: run.max_rhat,
                min_ess_bulk: run.min_ess_bulk,
                wall_seconds: run.wall_seconds,
                converged: run.max_rhat <= 1.01 && run.min_ess_bulk >= 100.0,
            });
            on_run(Table1Run {
                model: settings.label(),
                settings: &run_settings,
                run: &run,
                posterior: &mut posterior,
                truth,
                reference: &reference,
            })?;
        }
    }
    Ok(Table1Report {
        seed: options.seed,
        realised_noise_sd: reference.realised_noise_sd.clone(),
        rows,
        provenance: provenance(),
        options: options.clone(),
    })
}
