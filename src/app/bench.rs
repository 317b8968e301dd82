//! `motorcal bench`: its options, the measuring by the library (`paper::bench`), and its files
//! (`bench.json`, `bench.csv`, the ESS-per-second figures) and table.

use std::path::{Path, PathBuf};

use crate::bayes::CoefficientFamily;
use crate::error::Error;
use crate::plot::{self, SamplerCurve};

use super::AppError;
use super::args::{ChainArgs, coefficient_prior, parse_ks};
use super::run::{SamplerKind, ratio_2sf};

pub use crate::paper::bench::{
    BenchOptions, BenchRecord, DEFAULT_KS, MAX_BASELINE_DRAWS, MAX_GRADIENT_DRAWS,
};

#[derive(clap::Args, Clone, Debug)]
pub struct BenchArgs {
    /// Discrepancy degrees: a comma list or a range (0..=20).
    #[arg(long, default_value = "0,3,6,9,12,15,20")]
    pub k: String,
    /// Samplers, comma separated (default: all).
    #[arg(long, value_enum, value_delimiter = ',')]
    pub samplers: Vec<SamplerKind>,
    /// Thread counts, comma separated (default: 1 and all cores): the bench measures each, so
    /// unlike the other commands it takes a list.
    #[arg(long, value_delimiter = ',')]
    pub threads: Vec<usize>,
    #[command(flatten)]
    pub chains: ChainArgs,
    /// Draws per chain (default: per sampler, extended until converged).
    #[arg(long)]
    pub draws: Option<usize>,
    #[arg(long)]
    pub warmup: Option<usize>,
    /// A recording to bench on instead of the paper's data (with --model).
    #[arg(long)]
    pub data: Option<PathBuf>,
    #[arg(long)]
    pub model: Option<PathBuf>,
    #[arg(long, default_value = "out/bench")]
    pub out: PathBuf,
    /// Write the records as JSON here (default: OUT/bench.json).
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Redraw the table, CSV and figures from an earlier run's bench.json (no measuring).
    #[arg(long)]
    pub from_json: Option<PathBuf>,
    /// Decay power p of the coefficient prior variance V0/(j+1)^p (0: the paper's prior).
    #[arg(long, default_value_t = 0.0)]
    pub prior_decay: f64,
    #[arg(long, value_enum, default_value_t = CoefficientFamily::Laplace)]
    pub prior_family: CoefficientFamily,
}

impl BenchArgs {
    /// The library's options: a list not given is the library's default.
    pub fn options(&self) -> Result<BenchOptions, AppError> {
        let defaults = BenchOptions::default();
        Ok(BenchOptions {
            ks: parse_ks(&self.k).map_err(|e| AppError::Usage(format!("--k {e}")))?,
            samplers: or_default(&self.samplers, defaults.samplers),
            threads: or_default(&self.threads, defaults.threads),
            chains: self.chains.chains_or(defaults.chains),
            draws: self.draws,
            warmup: self.warmup,
            seed: self.chains.seed,
            data: self.data.clone(),
            model: self.model.clone(),
            quiet: self.chains.quiet,
            coefficient_prior: coefficient_prior(self.prior_family, self.prior_decay),
            metric_adaptation: self.chains.metric_adaptation.unwrap_or_default(),
            stop: None,
        })
    }
}

/// `given`, or `default` when the flag was not given.
fn or_default<T: Clone>(given: &[T], default: Vec<T>) -> Vec<T> {
    if given.is_empty() {
        default
    } else {
        given.to_vec()
    }
}

/// Where the files go, and what the figures draw: the samplers and thread counts, in order.
struct Outputs {
    out: PathBuf,
    json: Option<PathBuf>,
    samplers: Vec<SamplerKind>,
    threads: Vec<usize>,
    chains: usize,
}

/// The whole command: measure (or read `--from-json`), write, print the table.
pub fn run(args: &BenchArgs) -> Result<(), AppError> {
    let options = args.options()?;
    let mut outputs = Outputs {
        out: args.out.clone(),
        json: args.json.clone(),
        samplers: options.samplers.clone(),
        threads: options.threads.clone(),
        chains: options.chains,
    };
    let records = match &args.from_json {
        Some(path) => {
            let records = read_records(path)?;
            outputs.threads = records.iter().map(|r| r.threads).collect();
            outputs.threads.sort();
            outputs.threads.dedup();
            records
        }
        None => crate::paper::bench::bench_with(&options, |records| {
            let r = records.last().expect("called after each record");
            if !options.quiet {
                eprintln!("{}", format_record(r));
            }
            // Written after every record: a long bench that is stopped keeps what it measured.
            write_records(&outputs, records).map_err(|e| match e {
                AppError::Output(m) => Error::Output(m),
                e => Error::Output(e.to_string()),
            })
        })
        .map_err(flag_error)?,
    };
    write_outputs(&outputs, &records)?;
    print!("{}", format_table(&records));
    println!(
        "wrote {}/bench.csv, bench.json and ess_per_*.png",
        args.out.display()
    );
    Ok(())
}

/// The library's refusals, in the words the bench has always used for these two.
fn flag_error(e: Error) -> AppError {
    match e {
        Error::Settings(s) if s.name == "threads/chains" => {
            AppError::Usage("--threads and --chains must be at least 1".into())
        }
        Error::Settings(s) if s.name == "data/model" => {
            AppError::Usage("--data and --model go together".into())
        }
        e => e.into(),
    }
}

/// The records of an earlier run's `bench.json`.
pub fn read_records(path: &Path) -> Result<Vec<BenchRecord>, AppError> {
    let text = std::fs::read_to_string(path).map_err(|e| {
        AppError::Input(crate::io::InputError::new(
            path,
            format!("cannot read: {e}"),
        ))
    })?;
    serde_json::from_str(&text).map_err(|e| {
        AppError::Input(crate::io::InputError::new(path, e.to_string()).at_line(e.line()))
    })
}

fn format_record(r: &BenchRecord) -> String {
    format!(
        "{:<20} K={:<3} t={:<2} draws {:>6}  min ESS {:>8.0}  ESS/CPU-s {:>9.2} sampling, {:>9.2} all  ESS/{} {:>9.5}, {:>9.5} all  ESS/solve-eq {:>7.4}  R-hat {:>6.3}  wall {:>7.1} s{}",
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
        r.cost.min_ess_per_solve,
        r.max_rhat,
        r.cost.wall_s,
        if r.converged {
            ""
        } else {
            "  NOT CONVERGED (bound)"
        }
    ) + &khat_note(r)
}

/// The Laplace samplers' k̂ and whether they fell back to NUTS; nothing for the others.
fn khat_note(r: &BenchRecord) -> String {
    match r.khat {
        Some(k) if r.fell_back => format!("  k̂ {k:.3} (fell back to NUTS)"),
        Some(k) => format!("  k̂ {k:.3}"),
        None => String::new(),
    }
}

/// The table, and the ratios of the best gradient sampler to each baseline per K: per CPU
/// second of sampling and per CPU second of the whole cost.
pub fn format_table(records: &[BenchRecord]) -> String {
    let mut out = String::new();
    out.push_str(&format!(
        "{:<20} {:>3} {:>3} {:>7} {:>9} {:>11} {:>11} {:>11} {:>11} {:>9} {:>10} {:>7} {:>8} {:>8} {:>8} {:>7}\n",
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
        "ESS/solve",
        "R-hat",
        "CPU s",
        "wall s",
        "conv",
        "k̂"
    ));
    for r in records {
        out.push_str(&format!(
            "{:<20} {:>3} {:>3} {:>7} {:>9.0} {:>11.2} {:>11.2} {:>11.5} {:>11.5} {:>9} {:>10.4} {:>7.3} {:>8.1} {:>8.1} {:>8} {:>7}\n",
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
            r.cost.min_ess_per_solve,
            r.max_rhat,
            r.cost.total_cpu_s,
            r.cost.wall_s,
            if r.converged { "yes" } else { "no" },
            match r.khat {
                Some(k) if r.fell_back => format!("{k:.2}→NUTS"),
                Some(k) => format!("{k:.3}"),
                None => "-".into(),
            }
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
        // The random walks are the baselines; the Laplace samplers are compared the other way.
        let random_walk = |r: &&&BenchRecord| {
            matches!(
                r.sampler.parse::<SamplerKind>(),
                Ok(SamplerKind::Metropolis | SamplerKind::AdaptiveMetropolis)
            )
        };
        let laplace = |r: &&&BenchRecord| {
            matches!(
                r.sampler.parse::<SamplerKind>(),
                Ok(SamplerKind::Independence | SamplerKind::LaplaceIs | SamplerKind::CollapsedIs)
            )
        };
        for new in here.iter().filter(laplace) {
            out.push_str(&format!(
                "K={k:<3} threads={threads}: {} / {} = {}× per CPU-s of sampling, {}× of the whole cost{}\n",
                new.sampler,
                best.sampler,
                ratio_2sf(new.cost.min_ess_per_s / best.cost.min_ess_per_s),
                ratio_2sf(new.cost.min_ess_per_total_s / best.cost.min_ess_per_total_s),
                if new.converged { "" } else { " (not converged)" }
            ));
        }
        for base in here.iter().filter(random_walk) {
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

fn write_records(options: &Outputs, records: &[BenchRecord]) -> Result<(), AppError> {
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
         min_ess_per_s,min_ess_per_total_s,min_ess_per_wall_s,min_ess_per_eval,min_ess_per_all_evals,prior,metric_adaptation,khat,fell_back,\
         plain_solves,dual_solves,solve_directions,solve_equivalents,min_ess_per_solve\n",
    );
    for r in records {
        let c = &r.cost;
        csv.push_str(&format!(
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},\"{}\",{},{},{},{},{},{},{},{}\n",
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
            r.metric_adaptation,
            r.khat.map_or(String::new(), |k| k.to_string()),
            r.fell_back,
            c.solves.plain,
            c.solves.dual,
            c.solves.directions,
            c.solves.equivalents(),
            c.min_ess_per_solve
        ));
    }
    crate::io::write_atomically(&options.out.join("bench.csv"), csv.as_bytes())?;
    Ok(())
}

fn write_outputs(options: &Outputs, records: &[BenchRecord]) -> Result<(), AppError> {
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
    use crate::paper::bench::record;
    use crate::paper::bench::tests::{run, settings};

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
        assert!(table.contains(" no       -\n"), "{table}");
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
