//! `motorcal bench`: effective samples per second of every sampler across K, measured side by
//! side on the same data and seeds.

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use crate::bayes::ModelSettings;
use crate::plot::{self, SamplerCurve};
use crate::sampler::ChainSettings;
use crate::synthetic::DEFAULT_SEED;

use super::AppError;
use super::problem::Problem;
use super::run::{RunOutput, RunSettings, SamplerKind, run_sampler};

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
    pub data: Option<PathBuf>,
    pub model: Option<PathBuf>,
    pub out: PathBuf,
    pub json: Option<PathBuf>,
    pub quiet: bool,
    /// Redraw the table and figures from an earlier run's JSON instead of measuring.
    pub from_json: Option<PathBuf>,
    /// The discrepancy coefficients' prior (§5's decaying variance, or the paper's).
    pub coefficient_prior: crate::bayes::CoefficientPrior,
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
            out: PathBuf::from("out/bench"),
            json: None,
            quiet: false,
            from_json: None,
            coefficient_prior: crate::bayes::CoefficientPrior::default(),
        }
    }
}

/// One (sampler, K, threads) measurement: the stable contract of `--json`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct BenchRecord {
    pub sampler: String,
    pub k: usize,
    pub threads: usize,
    pub chains: usize,
    pub warmup: usize,
    pub draws: usize,
    pub min_ess_bulk: f64,
    /// min bulk-ESS over all parameters per second of the sampling phase (warm-up excluded).
    pub min_ess_per_s: f64,
    /// min bulk-ESS per gradient evaluation (gradient samplers) or per density evaluation.
    pub min_ess_per_eval: f64,
    pub eval_kind: String,
    pub evaluations: u64,
    pub max_rhat: f64,
    /// R-hat ≤ 1.01 and min bulk-ESS ≥ 100.
    pub converged: bool,
    /// The run did not converge even at the longest length tried: its ESS is not to be
    /// trusted (it overstates the sampler), so ratios against it are lower bounds.
    pub lower_bound: bool,
    pub wall_s: f64,
    pub warmup_s: f64,
    /// Sampling time summed over chains (CPU seconds of the sampling phase).
    pub sampling_cpu_s: f64,
    pub divergences: usize,
    /// min bulk-ESS per second of wall time of the whole run a user waits for: MAP, initial
    /// points, warm-up and sampling (`wall_s`), beside `min_ess_per_s` of the sampling phase.
    #[serde(default)]
    pub min_ess_per_wall_s: f64,
    /// Every evaluation of the kind `eval_kind` counts: the MAP's (its Fisher and observed
    /// metrics counted as one gradient each: each is one sensitivity solve), the warm-up's and
    /// the sampling's; and min bulk-ESS per one of them.
    #[serde(default)]
    pub all_evaluations: u64,
    #[serde(default)]
    pub min_ess_per_all_evals: f64,
    /// Wall seconds of the MAP search.
    #[serde(default)]
    pub map_s: f64,
    /// The coefficient prior the run used (empty in files written before it was recorded).
    #[serde(default)]
    pub prior: String,
}

fn first_attempt(sampler: SamplerKind, options: &BenchOptions) -> ChainSettings {
    let (warmup, draws) = match sampler {
        SamplerKind::Metropolis => (500, 5000),
        SamplerKind::AdaptiveMetropolis => (5000, 5000),
        _ => (1000, 1000),
    };
    ChainSettings {
        warmup: options.warmup.unwrap_or(warmup),
        draws: options.draws.unwrap_or(draws),
        keep: None,
    }
}

fn converged(run: &RunOutput) -> bool {
    run.max_rhat <= 1.01 && run.min_ess_bulk >= 100.0
}

/// Runs a sampler, four times longer each time it has not converged, up to its cap.
fn run_until_converged(
    posterior: &mut crate::bayes::CalibrationPosterior,
    sampler: SamplerKind,
    threads: usize,
    options: &BenchOptions,
    label: &str,
) -> Result<(RunOutput, ChainSettings), AppError> {
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
            ..RunSettings::default()
        };
        let run = run_sampler(posterior, &settings, label)?;
        if converged(&run) || chain.draws >= cap || options.draws.is_some() {
            return Ok((run, chain));
        }
        chain.draws = (chain.draws * 4).min(cap);
    }
}

fn record(
    sampler: SamplerKind,
    k: usize,
    threads: usize,
    chains: usize,
    chain: &ChainSettings,
    run: &RunOutput,
) -> BenchRecord {
    let sampling_cpu_s: f64 = run.chains.iter().map(|c| c.sampling_seconds).sum();
    // Chains run min(threads, chains) at a time, so the sampling phase's wall time is its
    // CPU time shared among them.
    let sampling_wall = sampling_cpu_s / threads.min(chains).max(1) as f64;
    let (evaluations, eval_kind) = if sampler.uses_gradient() {
        (run.sampling_gradient_evaluations, "gradient")
    } else {
        (run.sampling_density_evaluations, "density")
    };
    let all_evaluations = if sampler.uses_gradient() {
        run.map_gradient_evaluations
            + run.map_metric_evaluations
            + run.warmup_gradient_evaluations
            + run.sampling_gradient_evaluations
    } else {
        run.map_density_evaluations
            + run.map_gradient_evaluations
            + run.map_metric_evaluations
            + run.warmup_density_evaluations
            + run.sampling_density_evaluations
    };
    let ok = converged(run);
    BenchRecord {
        sampler: sampler.name().into(),
        k,
        threads,
        chains,
        warmup: chain.warmup,
        draws: chain.draws,
        min_ess_bulk: run.min_ess_bulk,
        min_ess_per_s: run.min_ess_bulk / sampling_wall,
        min_ess_per_eval: run.min_ess_bulk / evaluations.max(1) as f64,
        eval_kind: eval_kind.into(),
        evaluations,
        max_rhat: run.max_rhat,
        converged: ok,
        lower_bound: !ok,
        wall_s: run.wall_seconds,
        warmup_s: run.warmup_seconds,
        sampling_cpu_s,
        divergences: run.divergences,
        min_ess_per_wall_s: run.min_ess_bulk / run.wall_seconds,
        all_evaluations,
        min_ess_per_all_evals: run.min_ess_bulk / all_evaluations.max(1) as f64,
        map_s: run.map_seconds,
        prior: crate::bayes::CoefficientPrior::default().label(),
    }
}

pub fn bench(options: &BenchOptions) -> Result<Vec<BenchRecord>, AppError> {
    if let Some(path) = &options.from_json {
        let text = std::fs::read_to_string(path).map_err(|e| {
            AppError::Input(crate::io::InputError::new(
                path,
                format!("cannot read: {e}"),
            ))
        })?;
        let records: Vec<BenchRecord> = serde_json::from_str(&text).map_err(|e| {
            AppError::Input(crate::io::InputError::new(path, e.to_string()).at_line(e.line()))
        })?;
        let mut options = options.clone();
        options.threads = records.iter().map(|r| r.threads).collect();
        options.threads.sort();
        options.threads.dedup();
        write_outputs(&options, &records)?;
        return Ok(records);
    }
    if options.ks.is_empty() || options.samplers.is_empty() || options.threads.is_empty() {
        return Err(AppError::Usage(
            "bench: name at least one K, sampler and thread count".into(),
        ));
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
            .map_err(|e| AppError::Usage(format!("--k {k}: {e}")))?;
    }
    if options.threads.contains(&0) || options.chains == 0 {
        return Err(AppError::Usage(
            "--threads and --chains must be at least 1".into(),
        ));
    }
    let problem = match (&options.data, &options.model) {
        (Some(d), Some(m)) => Problem::from_files(std::slice::from_ref(d), m)?,
        (None, None) => Problem::paper(options.seed)?,
        _ => return Err(AppError::Usage("--data and --model go together".into())),
    };
    let mut records = Vec::new();
    for &k in &options.ks {
        let mut posterior = problem.posterior(&settings_for(k))?;
        for &sampler in &options.samplers {
            for &threads in &options.threads {
                let label = format!("K={k} t={threads}");
                let (run, chain) =
                    run_until_converged(&mut posterior, sampler, threads, options, &label)?;
                let r = BenchRecord {
                    prior: options.coefficient_prior.label(),
                    ..record(sampler, k, threads, options.chains, &chain, &run)
                };
                if !options.quiet {
                    eprintln!("{}", format_record(&r));
                }
                records.push(r);
                // Written after every record: a long bench that is stopped keeps what it measured.
                write_records(options, &records)?;
            }
        }
    }
    write_outputs(options, &records)?;
    Ok(records)
}

fn format_record(r: &BenchRecord) -> String {
    format!(
        "{:<20} K={:<3} t={:<2} draws {:>6}  min ESS {:>8.0}  ESS/s {:>10.2}  ESS/{} {:>9.5}  R-hat {:>6.3}  wall {:>7.1} s{}",
        r.sampler,
        r.k,
        r.threads,
        r.draws,
        r.min_ess_bulk,
        r.min_ess_per_s,
        r.eval_kind,
        r.min_ess_per_eval,
        r.max_rhat,
        r.wall_s,
        if r.converged {
            ""
        } else {
            "  NOT CONVERGED (bound)"
        }
    )
}

/// The table, and the ratio of the best gradient sampler to each baseline per K.
pub fn format_table(records: &[BenchRecord]) -> String {
    let mut out = String::new();
    out.push_str(&format!(
        "{:<20} {:>3} {:>3} {:>7} {:>9} {:>11} {:>11} {:>9} {:>7} {:>8} {:>8}\n",
        "sampler",
        "K",
        "thr",
        "draws",
        "min ESS",
        "ESS/s",
        "ESS/eval",
        "eval",
        "R-hat",
        "wall s",
        "conv"
    ));
    for r in records {
        out.push_str(&format!(
            "{:<20} {:>3} {:>3} {:>7} {:>9.0} {:>11.2} {:>11.5} {:>9} {:>7.3} {:>8.1} {:>8}\n",
            r.sampler,
            r.k,
            r.threads,
            r.draws,
            r.min_ess_bulk,
            r.min_ess_per_s,
            r.min_ess_per_eval,
            r.eval_kind,
            r.max_rhat,
            r.wall_s,
            if r.converged { "yes" } else { "no" }
        ));
    }
    let mut keys: Vec<(usize, usize)> = records.iter().map(|r| (r.k, r.threads)).collect();
    keys.dedup();
    keys.sort();
    keys.dedup();
    out.push('\n');
    for (k, threads) in keys {
        let here: Vec<&BenchRecord> = records
            .iter()
            .filter(|r| r.k == k && r.threads == threads)
            .collect();
        let best = here
            .iter()
            .filter(|r| r.eval_kind == "gradient" && r.converged)
            .max_by(|a, b| a.min_ess_per_s.total_cmp(&b.min_ess_per_s));
        let Some(best) = best else { continue };
        for base in here.iter().filter(|r| r.eval_kind == "density") {
            let ratio = best.min_ess_per_s / base.min_ess_per_s;
            out.push_str(&format!(
                "K={k:<3} threads={threads}: {} / {} = {}{:.1}×{}\n",
                best.sampler,
                base.sampler,
                if base.lower_bound { "≥ " } else { "" },
                ratio,
                if base.lower_bound {
                    " (baseline not converged at its longest run)"
                } else {
                    ""
                }
            ));
        }
    }
    out
}

fn write_records(options: &BenchOptions, records: &[BenchRecord]) -> Result<(), AppError> {
    let json =
        serde_json::to_string_pretty(records).map_err(|e| AppError::Output(e.to_string()))?;
    let json_path = options
        .json
        .clone()
        .unwrap_or_else(|| options.out.join("bench.json"));
    crate::io::write_atomically(&json_path, json.as_bytes())?;
    let mut csv = String::from(
        "sampler,k,threads,chains,warmup,draws,min_ess_bulk,min_ess_per_s,min_ess_per_eval,eval_kind,evaluations,max_rhat,converged,lower_bound,wall_s,warmup_s,sampling_cpu_s,divergences,min_ess_per_wall_s,all_evaluations,min_ess_per_all_evals,map_s,prior\n",
    );
    for r in records {
        csv.push_str(&format!(
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},\"{}\"\n",
            r.sampler,
            r.k,
            r.threads,
            r.chains,
            r.warmup,
            r.draws,
            r.min_ess_bulk,
            r.min_ess_per_s,
            r.min_ess_per_eval,
            r.eval_kind,
            r.evaluations,
            r.max_rhat,
            r.converged,
            r.lower_bound,
            r.wall_s,
            r.warmup_s,
            r.sampling_cpu_s,
            r.divergences,
            r.min_ess_per_wall_s,
            r.all_evaluations,
            r.min_ess_per_all_evals,
            r.map_s,
            r.prior
        ));
    }
    crate::io::write_atomically(&options.out.join("bench.csv"), csv.as_bytes())?;
    Ok(())
}

fn write_outputs(options: &BenchOptions, records: &[BenchRecord]) -> Result<(), AppError> {
    write_records(options, records)?;
    for threads in options.threads.iter().copied() {
        let curves = |value: fn(&BenchRecord) -> f64| -> Vec<SamplerCurve> {
            options
                .samplers
                .iter()
                .map(|s| SamplerCurve {
                    sampler: s.name().into(),
                    points: records
                        .iter()
                        .filter(|r| r.sampler == s.name() && r.threads == threads)
                        .map(|r| (r.k as f64, value(r), r.lower_bound))
                        .collect(),
                })
                .filter(|c| !c.points.is_empty())
                .collect()
        };
        let err = |e: plot::PlotError| AppError::Output(e.to_string());
        plot::ess_per_second(
            &options.out.join(format!("ess_per_second_t{threads}.png")),
            &format!(
                "min bulk-ESS per second of sampling, {threads} thread(s), {} chains",
                options.chains
            ),
            "min ESS / s",
            &curves(|r| r.min_ess_per_s),
        )
        .map_err(err)?;
        plot::ess_per_second(
            &options.out.join(format!("ess_per_eval_t{threads}.png")),
            &format!("min bulk-ESS per gradient (or density) evaluation, {threads} thread(s)"),
            "min ESS / evaluation",
            &curves(|r| r.min_ess_per_eval),
        )
        .map_err(err)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::ChainOutput;

    /// A run of `chains` chains, each `sampling_s` seconds of sampling, with these diagnostics.
    fn run(chains: usize, sampling_s: f64, min_ess: f64, max_rhat: f64) -> RunOutput {
        let chain = |c: usize| ChainOutput {
            chain: c,
            sampler: "x".into(),
            names: Vec::new(),
            draws: Vec::new(),
            unconstrained: Vec::new(),
            records: Vec::new(),
            warmup_seconds: 1.0,
            sampling_seconds: sampling_s,
            warmup_density_evaluations: 0,
            warmup_gradient_evaluations: 0,
            sampling_density_evaluations: 3000,
            sampling_gradient_evaluations: 2000,
            uses_gradient: true,
            divergences: 0,
            mean_accept_stat: 0.8,
            final_step_size: 0.1,
        };
        RunOutput {
            sampler: "x".into(),
            chains: (0..chains).map(chain).collect(),
            summaries: Vec::new(),
            max_rhat,
            min_ess_bulk: min_ess,
            wall_seconds: 9.0,
            warmup_seconds: 1.0,
            sampling_seconds: sampling_s,
            sampling_density_evaluations: 3000 * chains as u64,
            sampling_gradient_evaluations: 2000 * chains as u64,
            map_seconds: 0.5,
            map_density_evaluations: 40,
            map_gradient_evaluations: 60,
            map_metric_evaluations: 10,
            warmup_density_evaluations: 500 * chains as u64,
            warmup_gradient_evaluations: 700 * chains as u64,
            divergences: 0,
            map_log_density: 0.0,
            log_evidence_laplace: 0.0,
        }
    }

    fn settings() -> ChainSettings {
        ChainSettings {
            warmup: 100,
            draws: 400,
            keep: None,
        }
    }

    #[test]
    fn convergence_needs_both_rhat_and_ess() {
        assert!(converged(&run(4, 1.0, 100.0, 1.01)));
        assert!(!converged(&run(4, 1.0, 99.9, 1.0)));
        assert!(!converged(&run(4, 1.0, 5000.0, 1.011)));
        assert!(!converged(&run(4, 1.0, f64::NAN, 1.0)));
    }

    #[test]
    fn ess_per_second_shares_the_sampling_time_among_the_chains_running_at_once() {
        // Four chains of 2 s each: on one thread 8 s of wall time, on two threads 4 s, on four
        // 2 s, and threads beyond one per chain do not help.
        let r = run(4, 2.0, 800.0, 1.0);
        let per_s = |threads| record(SamplerKind::NutsDense, 9, threads, 4, &settings(), &r);
        let one = per_s(1);
        assert_eq!(one.min_ess_per_s, 100.0);
        assert_eq!(per_s(2).min_ess_per_s, 200.0);
        assert_eq!(per_s(4).min_ess_per_s, 400.0);
        assert_eq!(per_s(8).min_ess_per_s, 400.0);
        assert_eq!(one.sampling_cpu_s, 8.0);
        // Gradient samplers are counted per gradient, the others per density evaluation.
        assert_eq!(one.eval_kind, "gradient");
        assert_eq!(one.min_ess_per_eval, 800.0 / 8000.0);
        let metropolis = record(SamplerKind::Metropolis, 9, 1, 4, &settings(), &r);
        assert_eq!(metropolis.eval_kind, "density");
        assert_eq!(metropolis.min_ess_per_eval, 800.0 / 12000.0);
    }

    #[test]
    fn the_whole_cost_counts_the_map_and_the_warm_up_too() {
        let r = run(4, 2.0, 800.0, 1.0);
        let nuts = record(SamplerKind::NutsDense, 9, 1, 4, &settings(), &r);
        // MAP: 60 gradients + 10 metrics; warm-up 4 × 700; sampling 4 × 2000.
        assert_eq!(nuts.all_evaluations, 60 + 10 + 2800 + 8000);
        assert_eq!(nuts.min_ess_per_all_evals, 800.0 / 10870.0);
        // Random walks count densities, and the MAP's gradients and metrics as well.
        let metropolis = record(SamplerKind::Metropolis, 9, 1, 4, &settings(), &r);
        assert_eq!(metropolis.all_evaluations, 40 + 60 + 10 + 2000 + 12000);
        // The whole run's wall time (9 s) against the sampling phase's (8 s on one thread).
        assert_eq!(nuts.min_ess_per_wall_s, 800.0 / 9.0);
        assert_eq!(nuts.map_s, 0.5);
    }

    #[test]
    fn an_unconverged_run_is_a_bound_and_its_ratios_say_so() {
        let gradient = record(
            SamplerKind::NutsDense,
            9,
            1,
            4,
            &settings(),
            &run(4, 1.0, 4000.0, 1.002),
        );
        let baseline_ok = record(
            SamplerKind::AdaptiveMetropolis,
            9,
            1,
            4,
            &settings(),
            &run(4, 1.0, 200.0, 1.004),
        );
        let baseline_bad = BenchRecord {
            sampler: "metropolis".into(),
            ..record(
                SamplerKind::Metropolis,
                9,
                1,
                4,
                &settings(),
                &run(4, 1.0, 8.0, 1.4),
            )
        };
        assert!(gradient.converged && !gradient.lower_bound);
        assert!(!baseline_bad.converged && baseline_bad.lower_bound);
        let table = format_table(&[gradient.clone(), baseline_ok, baseline_bad]);
        // 4000/4 = 1000 ESS/s against 200/4 = 50 and 8/4 = 2.
        assert!(
            table.contains("nuts-dense / adaptive-metropolis = 20.0×\n"),
            "{table}"
        );
        assert!(
            table.contains(
                "nuts-dense / metropolis = ≥ 500.0× (baseline not converged at its longest run)"
            ),
            "{table}"
        );
        assert!(table.contains("NOT CONVERGED") || table.contains(" no\n"));
        // Without a converged gradient sampler there is no ratio to print.
        let unconverged_gradient = BenchRecord {
            converged: false,
            lower_bound: true,
            ..gradient
        };
        let table = format_table(&[unconverged_gradient]);
        assert!(!table.contains('×'), "{table}");
    }
}
