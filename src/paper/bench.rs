//! The samplers' effective samples per second across K, measured side by side on the same data
//! and seeds: every sampler at every K and thread count, each run extended until it converges
//! (or reaches its cap). Returns the records; the command (`motorcal bench`) writes and prints
//! them.

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use crate::bayes::{CalibrationPosterior, CoefficientPrior, ModelSettings};
use crate::error::Error;
use crate::pipeline::{
    MetricAdaptation, RunCost, RunOutput, RunSettings, SamplerKind, default_warmup, run_sampler,
};
use crate::sampler::ChainSettings;
use crate::study::Problem;
use crate::synthetic::DEFAULT_SEED;

/// The K values of the study unless told otherwise.
pub const DEFAULT_KS: [usize; 7] = [0, 3, 6, 9, 12, 15, 20];
/// The paper ran 100000 draws per chain; an unconverged baseline is extended up to this.
pub const MAX_BASELINE_DRAWS: usize = 100_000;
/// Gradient samplers are extended up to this many draws when they have not converged.
pub const MAX_GRADIENT_DRAWS: usize = 16_000;

#[derive(Clone, Debug, Serialize)]
pub struct BenchOptions {
    pub ks: Vec<usize>,
    pub samplers: Vec<SamplerKind>,
    /// Thread counts to measure at (1 is the per-core figure).
    pub threads: Vec<usize>,
    pub chains: usize,
    /// Draws per chain of the first attempt (default per sampler when `None`).
    pub draws: Option<usize>,
    pub warmup: Option<usize>,
    pub seed: u64,
    /// A recording and its model to bench on; the paper's synthetic data when both are absent.
    pub data: Option<PathBuf>,
    pub model: Option<PathBuf>,
    /// No progress bars.
    pub quiet: bool,
    /// The discrepancy coefficients' prior (§5's decaying variance, or the paper's).
    pub coefficient_prior: CoefficientPrior,
    /// How HMC and NUTS tune their metric in warm-up.
    pub metric_adaptation: MetricAdaptation,
    /// Ends the runs between transitions when set (see [`RunSettings::stop`]).
    #[serde(skip)]
    pub stop: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
}

impl Default for BenchOptions {
    fn default() -> Self {
        Self {
            ks: DEFAULT_KS.to_vec(),
            samplers: SamplerKind::ALL.to_vec(),
            threads: vec![
                1,
                std::thread::available_parallelism().map_or(1, |n| n.get()),
            ],
            chains: 4,
            draws: None,
            warmup: None,
            seed: DEFAULT_SEED,
            data: None,
            model: None,
            quiet: false,
            coefficient_prior: CoefficientPrior::default(),
            metric_adaptation: MetricAdaptation::default(),
            stop: None,
        }
    }
}

/// One (sampler, K, threads) measurement: the stable contract of `--json`. The cost and the
/// speed figures (`wall_s`, `min_ess_per_s`, `min_ess_per_total_s`, …) are [`RunCost`]'s,
/// written at the record's top level.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct BenchRecord {
    pub sampler: String,
    pub k: usize,
    pub threads: usize,
    pub chains: usize,
    pub warmup: usize,
    pub draws: usize,
    pub min_ess_bulk: f64,
    pub max_rhat: f64,
    /// R-hat ≤ 1.01 and min bulk-ESS ≥ 100.
    pub converged: bool,
    /// The run did not converge even at the longest length tried: its ESS is not to be
    /// trusted (it overstates the sampler), so ratios against it are lower bounds.
    pub lower_bound: bool,
    pub divergences: usize,
    #[serde(flatten)]
    pub cost: RunCost,
    /// The coefficient prior the run used (empty in files written before it was recorded).
    #[serde(default)]
    pub prior: String,
    /// How HMC and NUTS tuned their metric ("laplace" or "windows"; empty for the other
    /// samplers and in files written before it was recorded).
    #[serde(default)]
    pub metric_adaptation: String,
    /// laplace-is, independence: the Pareto shape k̂ of their proposals' importance weights
    /// (independence: its warm-up's; null for the other samplers
    /// and in files written before it was recorded).
    #[serde(default)]
    pub khat: Option<f64>,
    /// laplace-is, independence: k̂ > 0.7 and NUTS drew instead; the cost is the whole of both.
    #[serde(default)]
    pub fell_back: bool,
}

fn first_attempt(sampler: SamplerKind, options: &BenchOptions) -> ChainSettings {
    let (warmup, draws) = match sampler {
        SamplerKind::Metropolis => (500, 5000),
        SamplerKind::AdaptiveMetropolis => (5000, 5000),
        _ => (default_warmup(sampler, options.metric_adaptation), 1000),
    };
    ChainSettings {
        warmup: options.warmup.unwrap_or(warmup),
        draws: options.draws.unwrap_or(draws),
        keep: None,
    }
}

/// The bench's convergence rule: R-hat ≤ 1.01 and min bulk-ESS ≥ 100.
pub fn converged(run: &RunOutput) -> bool {
    run.max_rhat <= 1.01 && run.min_ess_bulk >= 100.0
}

/// Runs a sampler, four times longer each time it has not converged, up to its cap.
fn run_until_converged(
    posterior: &mut CalibrationPosterior,
    sampler: SamplerKind,
    threads: usize,
    options: &BenchOptions,
    label: &str,
) -> Result<(RunOutput, ChainSettings), Error> {
    let cap = if sampler.uses_gradient() {
        MAX_GRADIENT_DRAWS
    } else {
        MAX_BASELINE_DRAWS
    };
    let mut chain = first_attempt(sampler, options);
    loop {
        let settings = RunSettings {
            sampler,
            chains: options.chains,
            chain: chain.clone(),
            seed: options.seed,
            threads: Some(threads),
            quiet: options.quiet,
            metric_adaptation: options.metric_adaptation,
            stop: options.stop.clone(),
            ..RunSettings::default()
        };
        let run = run_sampler(posterior, &settings, label)?;
        if converged(&run) || chain.draws >= cap || options.draws.is_some() {
            return Ok((run, chain));
        }
        chain.draws = (chain.draws * 4).min(cap);
    }
}

/// The record of a run of `sampler` at K = `k` on `threads` threads (the paper's prior, no
/// metric adaptation named; [`bench_with`] fills in the run's).
pub fn record(
    sampler: SamplerKind,
    k: usize,
    threads: usize,
    chains: usize,
    chain: &ChainSettings,
    run: &RunOutput,
) -> BenchRecord {
    let ok = converged(run);
    BenchRecord {
        sampler: sampler.name().into(),
        k,
        threads,
        chains,
        warmup: chain.warmup,
        draws: chain.draws,
        min_ess_bulk: run.min_ess_bulk,
        max_rhat: run.max_rhat,
        converged: ok,
        lower_bound: !ok,
        divergences: run.divergences,
        cost: RunCost::of(run, sampler.uses_gradient() || run.fell_back),
        prior: CoefficientPrior::default().label(),
        metric_adaptation: String::new(),
        khat: run.khat,
        fell_back: run.fell_back,
    }
}

/// Every sampler at every K and thread count, in that order (K outermost).
pub fn bench(options: &BenchOptions) -> Result<Vec<BenchRecord>, Error> {
    bench_with(options, |_| Ok::<_, Error>(()))
}

/// As [`bench`], showing `on_record` the records so far after each measurement (the command
/// prints the new one and rewrites its files there, so that a stopped bench keeps what it
/// measured).
///
/// Settings it cannot use are refused before any measuring: no K, sampler or thread count
/// (an error about no one setting), a K its basis cannot hold (`k`), a zero thread count or
/// chain count (`threads/chains`), a recording without its model or the reverse
/// (`data/model`).
pub fn bench_with<E: From<Error>>(
    options: &BenchOptions,
    mut on_record: impl FnMut(&[BenchRecord]) -> Result<(), E>,
) -> Result<Vec<BenchRecord>, E> {
    if options.ks.is_empty() || options.samplers.is_empty() || options.threads.is_empty() {
        return Err(Error::invalid("bench: name at least one K, sampler and thread count").into());
    }
    // Every K is checked up front, by the settings' own rule, before any measuring starts.
    let settings_for = |k: usize| {
        let mut settings = ModelSettings::bm2(k);
        settings.coefficient_prior = options.coefficient_prior;
        settings
    };
    for &k in &options.ks {
        settings_for(k)
            .validate()
            .map_err(|e| Error::setting("k", k, e))?;
    }
    if options.threads.contains(&0) || options.chains == 0 {
        return Err(Error::setting("threads/chains", "", "must be at least 1").into());
    }
    let problem = match (&options.data, &options.model) {
        (Some(d), Some(m)) => Problem::from_files(std::slice::from_ref(d), m)?,
        (None, None) => Problem::paper(options.seed)?,
        _ => return Err(Error::setting("data/model", "", "go together").into()),
    };
    let mut records = Vec::new();
    for &k in &options.ks {
        let mut posterior = problem.posterior(&settings_for(k))?;
        for &sampler in &options.samplers {
            for &threads in &options.threads {
                let label = format!("K={k} t={threads}");
                let (run, chain) =
                    run_until_converged(&mut posterior, sampler, threads, options, &label)?;
                records.push(BenchRecord {
                    prior: options.coefficient_prior.label(),
                    metric_adaptation: if sampler.is_hamiltonian() {
                        options.metric_adaptation.name().into()
                    } else {
                        String::new()
                    },
                    ..record(sampler, k, threads, options.chains, &chain, &run)
                });
                on_record(&records)?;
            }
        }
    }
    Ok(records)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A run with these diagnostics and `pipeline::cost`'s test costs (8 CPU-s of sampling,
    /// 9.5 of the whole cost).
    pub(crate) fn run(min_ess: f64, max_rhat: f64) -> RunOutput {
        RunOutput {
            max_rhat,
            ..crate::pipeline::cost::tests::run(min_ess)
        }
    }

    pub(crate) fn settings() -> ChainSettings {
        ChainSettings {
            warmup: 100,
            draws: 400,
            keep: None,
        }
    }

    #[test]
    fn convergence_needs_both_rhat_and_ess() {
        assert!(converged(&run(100.0, 1.01)));
        assert!(!converged(&run(99.9, 1.0)));
        assert!(!converged(&run(5000.0, 1.011)));
        assert!(!converged(&run(f64::NAN, 1.0)));
    }

    #[test]
    fn speed_is_per_cpu_second_whatever_the_thread_count() {
        let r = run(800.0, 1.0);
        let at = |threads| record(SamplerKind::NutsDense, 9, threads, 4, &settings(), &r);
        assert_eq!(at(1).cost.min_ess_per_s, 100.0);
        assert_eq!(at(2).cost.min_ess_per_s, 100.0);
        assert_eq!(at(1).cost.min_ess_per_total_s, 800.0 / 9.5);
        // Gradient samplers are counted per gradient, the others per density evaluation.
        assert_eq!(at(1).cost.eval_kind, "gradient");
        assert_eq!(at(1).cost.min_ess_per_eval, 800.0 / 8000.0);
        let metropolis = record(SamplerKind::Metropolis, 9, 1, 4, &settings(), &r);
        assert_eq!(metropolis.cost.eval_kind, "density");
        assert_eq!(metropolis.cost.min_ess_per_eval, 800.0 / 12000.0);
    }

    #[test]
    fn the_json_is_flat_and_reads_files_written_before_the_cost_was_split() {
        let r = record(
            SamplerKind::NutsDense,
            9,
            1,
            4,
            &settings(),
            &run(800.0, 1.0),
        );
        let v = serde_json::to_value(&r).unwrap();
        for key in [
            "wall_s",
            "min_ess_per_s",
            "min_ess_per_total_s",
            "min_ess_per_wall_s",
            "min_ess_per_eval",
            "min_ess_per_all_evals",
            "all_evaluations",
            "sampling_cpu_s",
            "warmup_cpu_s",
            "map_cpu_s",
        ] {
            assert!(v.get(key).is_some_and(|x| x.is_number()), "{key} in {v}");
        }
        let back: BenchRecord = serde_json::from_value(v).unwrap();
        assert_eq!(back.cost, r.cost);
        // A record of papers/john2018/bench/bench.json, written before.
        let old = r#"{"sampler": "metropolis", "k": 0, "threads": 1, "chains": 4, "warmup": 500,
            "draws": 5000, "min_ess_bulk": 377.5, "min_ess_per_s": 275.0, "min_ess_per_eval": 0.0037,
            "eval_kind": "density", "evaluations": 100000, "max_rhat": 1.009, "converged": true,
            "lower_bound": false, "wall_s": 1.75, "warmup_s": 0.057, "sampling_cpu_s": 1.37,
            "divergences": 0}"#;
        let old: BenchRecord = serde_json::from_str(old).unwrap();
        assert_eq!(old.cost.min_ess_per_s, 275.0);
        assert_eq!(old.cost.warmup.wall_seconds, 0.057);
        assert_eq!(old.cost.evaluations, 100000);
        assert_eq!(old.prior, "");
    }

    #[test]
    fn impossible_settings_are_refused_by_field_before_any_measuring() {
        let refused = |options: BenchOptions| bench(&options).unwrap_err();
        let setting = |e: Error| match e {
            Error::Settings(s) => s.name,
            e => panic!("{e}"),
        };
        assert_eq!(
            setting(refused(BenchOptions {
                ks: vec![3, 100],
                ..BenchOptions::default()
            })),
            "k"
        );
        assert_eq!(
            setting(refused(BenchOptions {
                chains: 0,
                ..BenchOptions::default()
            })),
            "threads/chains"
        );
        assert_eq!(
            setting(refused(BenchOptions {
                data: Some("recording.csv".into()),
                ..BenchOptions::default()
            })),
            "data/model"
        );
        assert_eq!(
            setting(refused(BenchOptions {
                samplers: Vec::new(),
                ..BenchOptions::default()
            })),
            ""
        );
    }
}
