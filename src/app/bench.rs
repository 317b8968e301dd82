//! `motorcal bench`: effective samples per second of every sampler across K, measured side by
//! side on the same data and seeds.

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use crate::bayes::ModelSettings;
use crate::plot::{self, SamplerCurve};
use crate::sampler::ChainSettings;
use crate::synthetic::DEFAULT_SEED;

use super::AppError;
use super::run::{
    MetricAdaptation, RunCost, RunOutput, RunSettings, SamplerKind, default_warmup, ratio_2sf,
    run_sampler,
};
use crate::study::Problem;

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
    /// How HMC and NUTS tune their metric in warm-up.
    pub metric_adaptation: MetricAdaptation,
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
            metric_adaptation: MetricAdaptation::default(),
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
            metric_adaptation: options.metric_adaptation,
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
        cost: RunCost::of(run, sampler.uses_gradient()),
        prior: crate::bayes::CoefficientPrior::default().label(),
        metric_adaptation: String::new(),
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
                    metric_adaptation: if sampler.is_hamiltonian() {
                        options.metric_adaptation.name().into()
                    } else {
                        String::new()
                    },
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
        "{:<20} K={:<3} t={:<2} draws {:>6}  min ESS {:>8.0}  ESS/CPU-s {:>9.2} sampling, {:>9.2} all  ESS/{} {:>9.5}, {:>9.5} all  R-hat {:>6.3}  wall {:>7.1} s{}",
        r.sampler,
        r.k,
        r.threads,
        r.draws,
        r.min_ess_bulk,
        r.cost.min_ess_per_s,
        r.cost.min_ess_per_total_s,
        r.cost.eval_kind,
        r.cost.min_ess_per_eval,
        r.cost.min_ess_per_all_evals,
        r.max_rhat,
        r.cost.wall_s,
        if r.converged {
            ""
        } else {
            "  NOT CONVERGED (bound)"
        }
    )
}

/// The table, and the ratios of the best gradient sampler to each baseline per K: per CPU
/// second of sampling and per CPU second of the whole cost.
pub fn format_table(records: &[BenchRecord]) -> String {
    let mut out = String::new();
    out.push_str(&format!(
        "{:<20} {:>3} {:>3} {:>7} {:>9} {:>11} {:>11} {:>11} {:>11} {:>9} {:>7} {:>8} {:>8} {:>8}\n",
        "sampler",
        "K",
        "thr",
        "draws",
        "min ESS",
        "ESS/CPU-s",
        "ESS/all-s",
        "ESS/eval",
        "ESS/all-ev",
        "eval",
        "R-hat",
        "CPU s",
        "wall s",
        "conv"
    ));
    for r in records {
        out.push_str(&format!(
            "{:<20} {:>3} {:>3} {:>7} {:>9.0} {:>11.2} {:>11.2} {:>11.5} {:>11.5} {:>9} {:>7.3} {:>8.1} {:>8.1} {:>8}\n",
            r.sampler,
            r.k,
            r.threads,
            r.draws,
            r.min_ess_bulk,
            r.cost.min_ess_per_s,
            r.cost.min_ess_per_total_s,
            r.cost.min_ess_per_eval,
            r.cost.min_ess_per_all_evals,
            r.cost.eval_kind,
            r.max_rhat,
            r.cost.total_cpu_s,
            r.cost.wall_s,
            if r.converged { "yes" } else { "no" }
        ));
    }
    let mut keys: Vec<(usize, usize)> = records.iter().map(|r| (r.k, r.threads)).collect();
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
            .filter(|r| r.cost.eval_kind == "gradient" && r.converged)
            .max_by(|a, b| a.cost.min_ess_per_s.total_cmp(&b.cost.min_ess_per_s));
        let Some(best) = best else { continue };
        for base in here.iter().filter(|r| r.cost.eval_kind == "density") {
            let bound = if base.lower_bound { "≥ " } else { "" };
            out.push_str(&format!(
                "K={k:<3} threads={threads}: {} / {} = {bound}{}× per CPU-s of sampling, {bound}{}× of the whole cost{}\n",
                best.sampler,
                base.sampler,
                ratio_2sf(best.cost.min_ess_per_s / base.cost.min_ess_per_s),
                ratio_2sf(best.cost.min_ess_per_total_s / base.cost.min_ess_per_total_s),
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
        "sampler,k,threads,chains,warmup,draws,min_ess_bulk,max_rhat,converged,lower_bound,divergences,\
         wall_s,map_wall_s,map_cpu_s,warmup_wall_s,warmup_cpu_s,sampling_wall_s,sampling_cpu_s,total_cpu_s,\
         eval_kind,evaluations,all_evaluations,\
         min_ess_per_s,min_ess_per_total_s,min_ess_per_wall_s,min_ess_per_eval,min_ess_per_all_evals,prior,metric_adaptation\n",
    );
    for r in records {
        let c = &r.cost;
        csv.push_str(&format!(
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},\"{}\",{}\n",
            r.sampler,
            r.k,
            r.threads,
            r.chains,
            r.warmup,
            r.draws,
            r.min_ess_bulk,
            r.max_rhat,
            r.converged,
            r.lower_bound,
            r.divergences,
            c.wall_s,
            c.map.wall_seconds,
            c.map.cpu_seconds,
            c.warmup.wall_seconds,
            c.warmup.cpu_seconds,
            c.sampling.wall_seconds,
            c.sampling.cpu_seconds,
            c.total_cpu_s,
            c.eval_kind,
            c.evaluations,
            c.all_evaluations,
            c.min_ess_per_s,
            c.min_ess_per_total_s,
            c.min_ess_per_wall_s,
            c.min_ess_per_eval,
            c.min_ess_per_all_evals,
            r.prior,
            r.metric_adaptation
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
                "min bulk-ESS per CPU second of sampling, {threads} thread(s), {} chains",
                options.chains
            ),
            "min ESS / CPU s",
            &curves(|r| r.cost.min_ess_per_s),
        )
        .map_err(err)?;
        plot::ess_per_second(
            &options.out.join(format!("ess_per_total_second_t{threads}.png")),
            &format!(
                "min bulk-ESS per CPU second of MAP + warm-up + sampling, {threads} thread(s), {} chains",
                options.chains
            ),
            "min ESS / CPU s",
            &curves(|r| r.cost.min_ess_per_total_s),
        )
        .map_err(err)?;
        plot::ess_per_second(
            &options.out.join(format!("ess_per_eval_t{threads}.png")),
            &format!("min bulk-ESS per gradient (or density) evaluation, {threads} thread(s)"),
            "min ESS / evaluation",
            &curves(|r| r.cost.min_ess_per_eval),
        )
        .map_err(err)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A run with these diagnostics and `pipeline::cost`'s test costs (8 CPU-s of sampling,
    /// 9.5 of the whole cost).
    fn run(min_ess: f64, max_rhat: f64) -> RunOutput {
        RunOutput {
            max_rhat,
            ..crate::pipeline::cost::tests::run(min_ess)
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
    fn an_unconverged_run_is_a_bound_and_its_ratios_say_so() {
        let gradient = record(
            SamplerKind::NutsDense,
            9,
            1,
            4,
            &settings(),
            &run(4000.0, 1.002),
        );
        let baseline_ok = record(
            SamplerKind::AdaptiveMetropolis,
            9,
            1,
            4,
            &settings(),
            &run(200.0, 1.004),
        );
        let baseline_bad = record(
            SamplerKind::Metropolis,
            9,
            1,
            4,
            &settings(),
            &run(8.0, 1.4),
        );
        assert!(gradient.converged && !gradient.lower_bound);
        assert!(!baseline_bad.converged && baseline_bad.lower_bound);
        let table = format_table(&[gradient.clone(), baseline_ok, baseline_bad]);
        // Same costs: 4000 against 200 and 8 effective draws, on both counts.
        assert!(
            table.contains(
                "nuts-dense / adaptive-metropolis = 20× per CPU-s of sampling, 20× of the whole cost\n"
            ),
            "{table}"
        );
        assert!(
            table.contains(
                "nuts-dense / metropolis = ≥ 500× per CPU-s of sampling, ≥ 500× of the whole cost (baseline not converged at its longest run)"
            ),
            "{table}"
        );
        assert!(table.contains(" no\n"), "{table}");
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
