//! The `motorcal` command line: parses options and calls the library (`motorcal::app`).

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use motorcal::app::{self, AppError};
use motorcal::bayes::{CoefficientFamily, CoefficientPrior};

#[derive(Parser)]
#[command(
    name = "motorcal",
    version,
    about = "Bayesian calibration of a DC-motor model that learns its own discrepancy"
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Write a synthetic recording, the nominal model a user would believe, and the truth.
    Simulate {
        /// Model file of the motor that makes the data (default: the paper's, c_g = 0.01).
        #[arg(long)]
        truth: Option<PathBuf>,
        /// Model file the user believes (default: the paper's c_g = 0.009, or the truth).
        #[arg(long)]
        nominal: Option<PathBuf>,
        /// Output folder for recording.csv, motor.toml and truth.toml.
        #[arg(long, default_value = "simulated")]
        out: PathBuf,
        #[arg(long, default_value_t = motorcal::synthetic::DEFAULT_SEED)]
        seed: u64,
        #[arg(long, value_enum, default_value_t = app::simulate::InputProfile::Constant)]
        input: app::simulate::InputProfile,
        /// Noise standard deviations of I [A] and ω [rad/s].
        #[arg(long, num_args = 2, value_names = ["SD_I", "SD_OMEGA"], default_values_t = [2.0, 10.0])]
        noise_sd: Vec<f64>,
        #[arg(long, default_value_t = 501)]
        samples: usize,
        /// Length of the record [s].
        #[arg(long, default_value_t = 0.5)]
        t_end: f64,
        /// A concealed-physics case instead: the hidden effect(s) (a term name, two comma
        /// separated, or `none`); writes recording.csv, motor.toml and answer.json.
        #[arg(long, value_delimiter = ',', conflicts_with_all = ["truth", "nominal"])]
        effect: Option<Vec<String>>,
        /// With --effect: the peak effect over the noise σ (default: drawn in 0.6..1.5).
        #[arg(long, requires = "effect", allow_negative_numbers = true)]
        magnitude: Option<f64>,
        /// With --effect: keep the effect below 1.5σ and redraw until it is identifiable.
        #[arg(long, requires = "effect")]
        conceal: bool,
    },
    /// Calibrate a model file on a recording with BM1 or BM2(K): MAP, then MCMC.
    Fit(FitArgs),
    /// Effective samples per second of every sampler across K, side by side.
    Bench(BenchArgs),
    /// BM2 for each K on the paper's data: the error measures of §4.2 and Figures 8–11.
    Sweep(SweepArgs),
    /// Choose K by §3.2.3's rule: the smallest K whose σ posteriors stay put for K + 1..3.
    SelectK(SweepArgs),
    /// Join the JSON of sweep shards into what one unsharded sweep writes.
    Merge {
        #[arg(required = true)]
        parts: Vec<PathBuf>,
        #[arg(long, default_value = "out/sweep")]
        out: PathBuf,
        #[arg(long)]
        json: Option<PathBuf>,
    },
    /// Find the physics the model left out: locate the mismatch, rank candidate terms by
    /// evidence, add the best, refit, and show the fit improve.
    Diagnose(DiagnoseArgs),
    /// Reproduce a result of the paper.
    Reproduce {
        #[command(subcommand)]
        what: Reproduce,
    },
    /// A model file's prediction of records it was not fitted to, with the residual RMS per
    /// channel (the estimation → validation cross-test).
    Predict {
        /// The model (e.g. the model.toml that `diagnose --out` writes).
        #[arg(long)]
        model: PathBuf,
        /// A recording; repeat for several.
        #[arg(long, required = true)]
        data: Vec<PathBuf>,
        /// Write measured, predicted and residual per sample as CSV.
        #[arg(long)]
        csv: Option<PathBuf>,
        /// Write the residual table as JSON.
        #[arg(long)]
        json: Option<PathBuf>,
    },
    /// Print ESS, R-hat and MCSE for draws files (CmdStan CSV, or a long chain,draw,… table).
    Summarize {
        #[arg(required = true)]
        draws: Vec<PathBuf>,
        /// Also write the summary as JSON.
        #[arg(long)]
        json: Option<PathBuf>,
    },
}

#[derive(Subcommand)]
enum Reproduce {
    /// Table 1: BM1 and BM2(K = 9) on the paper's synthetic data, with the paper's protocol.
    Table1(Table1Args),
}

#[derive(clap::Args)]
struct Table1Args {
    /// BM2 runs of 10000 instead of 100000 draws.
    #[arg(long)]
    quick: bool,
    /// Samplers to run, comma separated.
    #[arg(long, value_enum, value_delimiter = ',', default_values_t = [app::run::SamplerKind::Metropolis, app::run::SamplerKind::AdaptiveMetropolis, app::run::SamplerKind::NutsDense])]
    samplers: Vec<app::run::SamplerKind>,
    #[command(flatten)]
    chains: ChainArgs,
    /// Worker threads (default: all cores); draws do not depend on it.
    #[arg(long)]
    threads: Option<usize>,
    /// Output folder for draws, table1.json and table1.csv.
    #[arg(long, default_value = "out/table1")]
    out: PathBuf,
}

/// What every command that runs chains takes: how many, from which seed, shown or not.
#[derive(clap::Args, Clone)]
struct ChainArgs {
    /// Chains per run (default 4; `reproduce table1`: 3, as the paper ran).
    #[arg(long)]
    chains: Option<usize>,
    /// Seed of the chains (and of the paper's synthetic noise).
    #[arg(long, default_value_t = motorcal::synthetic::DEFAULT_SEED)]
    seed: u64,
    /// No progress bars.
    #[arg(long)]
    quiet: bool,
    /// HMC/NUTS warm-up: keep the Laplace metric and tune the step size (laplace; the default,
    /// but windows for `reproduce table1`), or re-estimate the metric in Stan's windows.
    #[arg(long, value_enum)]
    metric_adaptation: Option<app::run::MetricAdaptation>,
}

impl ChainArgs {
    fn chains_or(&self, default: usize) -> usize {
        self.chains.unwrap_or(default)
    }

    /// A run of `sampler` with these chains (default 4), seed and quietness; a warm-up not given is the sampler's default for the metric
    /// adaptation (see `app::run::default_warmup`).
    fn run(
        &self,
        sampler: app::run::SamplerKind,
        warmup: Option<usize>,
        draws: usize,
    ) -> app::run::RunSettings {
        self.run_adapting(
            sampler,
            warmup,
            draws,
            app::run::MetricAdaptation::default(),
        )
    }

    /// As [`ChainArgs::run`], with a command's own default metric adaptation.
    fn run_adapting(
        &self,
        sampler: app::run::SamplerKind,
        warmup: Option<usize>,
        draws: usize,
        default_metric: app::run::MetricAdaptation,
    ) -> app::run::RunSettings {
        let metric_adaptation = self.metric_adaptation.unwrap_or(default_metric);
        app::run::RunSettings {
            sampler,
            chains: self.chains_or(4),
            chain: motorcal::sampler::ChainSettings {
                warmup: warmup
                    .unwrap_or_else(|| app::run::default_warmup(sampler, metric_adaptation)),
                draws,
                keep: None,
            },
            seed: self.seed,
            quiet: self.quiet,
            metric_adaptation,
            ..app::run::RunSettings::default()
        }
    }
}

#[derive(clap::Args)]
struct FitArgs {
    /// A recording (CSV with t, I, omega[, U]); repeat for several recordings, which share the
    /// physics and have their own noise and discrepancy.
    #[arg(long, required = true)]
    data: Vec<PathBuf>,
    /// The nominal model (TOML, schema 1 or 2).
    #[arg(long)]
    model: PathBuf,
    /// Bayesian model: 1 (noise only) or 2 (noise + discrepancy); default: the model file's
    /// [discrepancy], else 2.
    #[arg(long, value_parser = clap::value_parser!(u8).range(1..=2))]
    bm: Option<u8>,
    /// Degree K of the discrepancy (BM2); default: the model file's, else 9.
    #[arg(long)]
    k: Option<usize>,
    /// Decay power p of the coefficient prior variance V0/(j+1)^p (0: the paper's prior).
    #[arg(long, default_value_t = 0.0)]
    prior_decay: f64,
    /// Family of the coefficient prior.
    #[arg(long, value_enum, default_value_t = CoefficientFamily::Laplace)]
    prior_family: CoefficientFamily,
    /// Only the MAP and its Laplace approximation, no sampling.
    #[arg(long)]
    map_only: bool,
    #[command(flatten)]
    run: RunArgs,
    /// Output folder.
    #[arg(long, default_value = "out/fit")]
    out: PathBuf,
}

/// Options of a command that runs one sampler.
#[derive(clap::Args, Clone)]
struct RunArgs {
    #[arg(long, value_enum, default_value_t = app::run::SamplerKind::NutsDense)]
    sampler: app::run::SamplerKind,
    #[command(flatten)]
    chains: ChainArgs,
    /// Warm-up per chain (default: 100 for HMC/NUTS on the Laplace metric, else 1000).
    #[arg(long)]
    warmup: Option<usize>,
    #[arg(long, default_value_t = 1000)]
    draws: usize,
    /// Keep only the last N draws of each chain.
    #[arg(long)]
    keep: Option<usize>,
    /// Worker threads (default: all cores); draws do not depend on it.
    #[arg(long)]
    threads: Option<usize>,
    /// HMC/NUTS: save the adapted step size and metric (TOML) for a later warm start.
    #[arg(long)]
    save_adaptation: Option<PathBuf>,
    /// HMC/NUTS: start from a saved adaptation and skip adapting (use with a short --warmup).
    #[arg(long)]
    load_adaptation: Option<PathBuf>,
}

impl RunArgs {
    fn settings(&self) -> app::run::RunSettings {
        let mut run = self.chains.run(self.sampler, self.warmup, self.draws);
        run.chain.keep = self.keep;
        run.threads = self.threads;
        run.save_adaptation = self.save_adaptation.clone();
        run.load_adaptation = self.load_adaptation.clone();
        run
    }
}

fn fit(args: FitArgs) -> Result<(), AppError> {
    let options = app::fit::FitOptions {
        data: args.data,
        model: args.model,
        bm: args.bm,
        k: args.k,
        coefficient_prior: CoefficientPrior {
            family: args.prior_family,
            decay_power: args.prior_decay,
            ..CoefficientPrior::default()
        },
        run: (!args.map_only).then(|| args.run.settings()),
        out: args.out,
    };
    let report = app::fit::fit(&options)?;
    print!("{}", app::fit::format_report(&report));
    Ok(())
}

/// Discrepancy degrees as a range (`0..=20`, `3..10`) or a comma list (`0,3,9`).
fn parse_ks(text: &str) -> Result<Vec<usize>, String> {
    let bad = |e: &dyn std::fmt::Display| format!("'{text}': {e}");
    if let Some((a, b)) = text.split_once("..") {
        let (inclusive, b) = match b.strip_prefix('=') {
            Some(b) => (true, b),
            None => (false, b),
        };
        let a: usize = a.trim().parse().map_err(|e| bad(&e))?;
        let b: usize = b.trim().parse().map_err(|e| bad(&e))?;
        let end = if inclusive { b + 1 } else { b };
        if end <= a {
            return Err(format!("'{text}': an empty range"));
        }
        return Ok((a..end).collect());
    }
    text.split(',')
        .map(|v| v.trim().parse::<usize>().map_err(|e| bad(&e)))
        .collect()
}

#[derive(clap::Args)]
struct SweepArgs {
    /// Degrees: a range (0..=20) or a comma list (default 0..=20).
    #[arg(long, default_value = "0..=20")]
    k: String,
    /// Seeds of the synthetic noise, apart from the chains' --seed: one, a list or a range
    /// (default: the paper's data, 20180823). The grid is every (seed, K).
    #[arg(long, default_value = "20180823")]
    data_seed: String,
    /// Run one slice of the grid: grid points whose index is i − 1 modulo n (`--shard 3/8`);
    /// `motorcal merge` joins the slices' JSON into what one run writes.
    #[arg(long)]
    shard: Option<String>,
    /// Decay power p of the coefficient prior variance V0/(j+1)^p (0: the paper's prior).
    #[arg(long, default_value_t = 0.0)]
    prior_decay: f64,
    #[arg(long, value_enum, default_value_t = CoefficientFamily::Laplace)]
    prior_family: CoefficientFamily,
    #[arg(long, value_enum, default_value_t = app::run::SamplerKind::NutsDense)]
    sampler: app::run::SamplerKind,
    #[command(flatten)]
    chains: ChainArgs,
    /// Warm-up per chain (default: 100 for HMC/NUTS on the Laplace metric, which keeps R-hat
    /// and ESS at every K; else 1000; papers/john2018, "The warm-up").
    #[arg(long)]
    warmup: Option<usize>,
    #[arg(long, default_value_t = 1000)]
    draws: usize,
    #[arg(long, default_value = "out/sweep")]
    out: PathBuf,
    /// Write the records (or, for select-k, the choice) as JSON here.
    #[arg(long)]
    json: Option<PathBuf>,
    /// Degrees at which to draw δ's band against d0 and the coefficients' marginals (a list).
    #[arg(long)]
    figures_at: Option<String>,
    /// select-k: `sigma-stabilisation` (§3.2.3) or `evidence` (the largest log marginal
    /// likelihood, by importance sampling).
    #[arg(long, default_value = "sigma-stabilisation")]
    rule: String,
}

fn sweep(args: SweepArgs, select: bool) -> Result<(), AppError> {
    let ks = parse_ks(&args.k).map_err(|e| AppError::Usage(format!("--k {e}")))?;
    if !["sigma-stabilisation", "evidence"].contains(&args.rule.as_str()) {
        return Err(AppError::Usage(format!(
            "--rule {}: known rules are sigma-stabilisation and evidence",
            args.rule
        )));
    }
    let options = app::sweep::SweepOptions {
        ks,
        coefficient_prior: CoefficientPrior {
            family: args.prior_family,
            decay_power: args.prior_decay,
            ..CoefficientPrior::default()
        },
        data_seeds: parse_ks(&args.data_seed)
            .map_err(|e| AppError::Usage(format!("--data-seed {e}")))?
            .into_iter()
            .map(|s| s as u64)
            .collect(),
        shard: match &args.shard {
            None => None,
            Some(text) => Some(parse_shard(text)?),
        },
        run: args.chains.run(args.sampler, args.warmup, args.draws),
        out: args.out,
        json: if select { None } else { args.json.clone() },
        figures_at: match &args.figures_at {
            None => Vec::new(),
            Some(text) => {
                parse_ks(text).map_err(|e| AppError::Usage(format!("--figures-at {e}")))?
            }
        },
    };
    if select && (options.shard.is_some() || options.data_seeds.len() > 1) {
        return Err(AppError::Usage(
            "select-k judges one whole sweep: no --shard, one --data-seed".into(),
        ));
    }
    let records = app::sweep::sweep(&options)?;
    print!("{}", app::sweep::format_table(&records));
    for path in app::sweep::write_outputs(&records, &options)? {
        println!("wrote {}", path.display());
    }
    if select && args.rule == "evidence" {
        let choice = app::sweep::select::evidence(&records);
        for e in &choice.evidences {
            println!(
                "K = {:>2}: log evidence {:.2} ± {:.2} ({:.0} effective draws{}), Laplace {:.2}",
                e.k,
                e.log_evidence,
                e.standard_error,
                e.effective_draws,
                if e.trusted { "" } else { ", not trusted" },
                e.log_evidence_laplace
            );
        }
        match choice.k {
            Some(k) => println!("chosen K = {k} (largest evidence)"),
            None => println!("no evidence estimate has enough effective draws"),
        }
        write_choice(args.json.as_deref(), &choice)?;
    } else if select {
        let choice = app::sweep::select::sigma_stabilisation(&records);
        for d in &choice.distances {
            println!("K = {:>2}: distance {:.3}", d.k, d.distance);
        }
        match choice.k {
            Some(k) => println!(
                "chosen K = {k} (σ posteriors within {} sd for K + 1..3)",
                choice.tolerance
            ),
            None => println!("no K of the sweep stabilises within {}", choice.tolerance),
        }
        write_choice(args.json.as_deref(), &choice)?;
    }
    Ok(())
}

fn parse_shard(text: &str) -> Result<(usize, usize), AppError> {
    let bad = || {
        AppError::Usage(format!(
            "--shard {text}: write i/n with 1 ≤ i ≤ n, e.g. 3/8"
        ))
    };
    let (i, n) = text.split_once('/').ok_or_else(bad)?;
    let (i, n): (usize, usize) = (
        i.trim().parse().map_err(|_| bad())?,
        n.trim().parse().map_err(|_| bad())?,
    );
    if !(n >= 1 && (1..=n).contains(&i)) {
        return Err(bad());
    }
    Ok((i, n))
}

fn merge(parts: Vec<PathBuf>, out: PathBuf, json: Option<PathBuf>) -> Result<(), AppError> {
    let mut loaded = Vec::new();
    for path in &parts {
        let text = std::fs::read_to_string(path)
            .map_err(|e| AppError::Usage(format!("{}: {e}", path.display())))?;
        let records: Vec<app::sweep::SweepRecord> = serde_json::from_str(&text)
            .map_err(|e| AppError::Usage(format!("{}: line {}: {e}", path.display(), e.line())))?;
        loaded.push(records);
    }
    let records = app::sweep::merge(loaded)?;
    let options = app::sweep::SweepOptions {
        ks: Vec::new(),
        coefficient_prior: CoefficientPrior::default(),
        data_seeds: Vec::new(),
        shard: None,
        run: app::run::RunSettings::default(),
        out,
        json,
        figures_at: Vec::new(),
    };
    print!("{}", app::sweep::format_table(&records));
    for path in app::sweep::write_outputs(&records, &options)? {
        println!("wrote {}", path.display());
    }
    Ok(())
}

fn write_choice<T: serde::Serialize>(path: Option<&Path>, choice: &T) -> Result<(), AppError> {
    if let Some(path) = path {
        let text =
            serde_json::to_string_pretty(choice).map_err(|e| AppError::Output(e.to_string()))?;
        motorcal::io::write_atomically(path, text.as_bytes())?;
        println!("wrote {}", path.display());
    }
    Ok(())
}

#[derive(clap::Args)]
struct DiagnoseArgs {
    /// A recording; repeat for several (shared physics, noise per recording).
    #[arg(long, required = true)]
    data: Vec<PathBuf>,
    /// The nominal model (TOML, schema 1 or 2).
    #[arg(long)]
    model: PathBuf,
    /// Degree K of the discrepancy that locates the mismatch (default 9).
    #[arg(long)]
    k: Option<usize>,
    /// Candidate terms, comma separated (default: every term the model lacks).
    #[arg(long, value_delimiter = ',')]
    candidates: Option<Vec<String>>,
    /// Write the report as JSON here.
    #[arg(long)]
    json: Option<PathBuf>,
    /// Write figures, fit.json and the amended model.toml here.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Rank and select only: no sampled fits before and after.
    #[arg(long)]
    rank_only: bool,
    #[command(flatten)]
    chains: ChainArgs,
    #[arg(long, default_value_t = 500)]
    warmup: usize,
    #[arg(long, default_value_t = 500)]
    draws: usize,
}

fn diagnose(args: DiagnoseArgs) -> Result<(), AppError> {
    let run = args.chains.run_adapting(
        app::run::SamplerKind::NutsDense,
        Some(args.warmup),
        args.draws,
        app::diagnose::METRIC_ADAPTATION,
    );
    let options = app::diagnose::DiagnoseOptions {
        data: args.data,
        model: args.model,
        k: args.k,
        candidates: args.candidates,
        run,
        out: args.out,
        json: args.json,
        rank_only: args.rank_only,
    };
    let diagnosis = app::diagnose::diagnose(&options)?;
    print!("{}", app::diagnose::format_diagnosis(&diagnosis));
    for path in &diagnosis.outputs {
        println!("wrote {path}");
    }
    Ok(())
}

#[derive(clap::Args)]
struct BenchArgs {
    /// Discrepancy degrees: a comma list or a range (0..=20).
    #[arg(long, default_value = "0,3,6,9,12,15,20")]
    k: String,
    /// Samplers, comma separated (default: all).
    #[arg(long, value_enum, value_delimiter = ',')]
    samplers: Vec<app::run::SamplerKind>,
    /// Thread counts, comma separated (default: 1 and all cores): the bench measures each, so
    /// unlike the other commands it takes a list.
    #[arg(long, value_delimiter = ',')]
    threads: Vec<usize>,
    #[command(flatten)]
    chains: ChainArgs,
    /// Draws per chain (default: per sampler, extended until converged).
    #[arg(long)]
    draws: Option<usize>,
    #[arg(long)]
    warmup: Option<usize>,
    /// A recording to bench on instead of the paper's data (with --model).
    #[arg(long)]
    data: Option<PathBuf>,
    #[arg(long)]
    model: Option<PathBuf>,
    #[arg(long, default_value = "out/bench")]
    out: PathBuf,
    /// Write the records as JSON here (default: OUT/bench.json).
    #[arg(long)]
    json: Option<PathBuf>,
    /// Redraw the table, CSV and figures from an earlier run's bench.json (no measuring).
    #[arg(long)]
    from_json: Option<PathBuf>,
    /// Decay power p of the coefficient prior variance V0/(j+1)^p (0: the paper's prior).
    #[arg(long, default_value_t = 0.0)]
    prior_decay: f64,
    #[arg(long, value_enum, default_value_t = CoefficientFamily::Laplace)]
    prior_family: CoefficientFamily,
}

fn bench(args: BenchArgs) -> Result<(), AppError> {
    let defaults = app::bench::BenchOptions::default();
    let options = app::bench::BenchOptions {
        ks: parse_ks(&args.k).map_err(|e| AppError::Usage(format!("--k {e}")))?,
        samplers: if args.samplers.is_empty() {
            defaults.samplers
        } else {
            args.samplers
        },
        threads: if args.threads.is_empty() {
            defaults.threads
        } else {
            args.threads
        },
        chains: args.chains.chains_or(defaults.chains),
        draws: args.draws,
        warmup: args.warmup,
        seed: args.chains.seed,
        data: args.data,
        model: args.model,
        out: args.out,
        json: args.json,
        quiet: args.chains.quiet,
        from_json: args.from_json,
        coefficient_prior: CoefficientPrior {
            family: args.prior_family,
            decay_power: args.prior_decay,
            ..CoefficientPrior::default()
        },
        metric_adaptation: args.chains.metric_adaptation.unwrap_or_default(),
    };
    let records = app::bench::bench(&options)?;
    print!("{}", app::bench::format_table(&records));
    println!(
        "wrote {}/bench.csv, bench.json and ess_per_*.png",
        options.out.display()
    );
    Ok(())
}

fn table1(args: Table1Args) -> Result<(), AppError> {
    run_table1(app::table1::Table1Options {
        seed: args.chains.seed,
        quick: args.quick,
        samplers: args.samplers,
        chains: args
            .chains
            .chains_or(app::table1::Table1Options::default().chains),
        threads: args.threads,
        out: args.out,
        quiet: args.chains.quiet,
        metric_adaptation: args
            .chains
            .metric_adaptation
            .unwrap_or(app::table1::Table1Options::default().metric_adaptation),
    })
}

fn run_table1(options: app::table1::Table1Options) -> Result<(), AppError> {
    let report = app::table1::table1(&options)?;
    print!("{}", app::table1::format_report(&report));
    println!();
    println!(
        "wrote {}/table1.json, table1.csv, figures and the draws (CmdStan CSV)",
        options.out.display()
    );
    Ok(())
}

fn run(cli: Cli) -> Result<(), AppError> {
    match cli.command {
        None => {
            println!(
                "motorcal: reproducing the paper's Table 1 (see `motorcal --help` for the other commands)\n"
            );
            run_table1(app::table1::Table1Options::default())
        }
        Some(Command::Reproduce {
            what: Reproduce::Table1(args),
        }) => table1(args),
        Some(Command::Fit(args)) => fit(args),
        Some(Command::Bench(args)) => bench(args),
        Some(Command::Diagnose(args)) => diagnose(args),
        Some(Command::Sweep(args)) => sweep(args, false),
        Some(Command::SelectK(args)) => sweep(args, true),
        Some(Command::Merge { parts, out, json }) => merge(parts, out, json),
        Some(Command::Simulate {
            truth,
            nominal,
            out,
            seed,
            input,
            noise_sd,
            samples,
            t_end,
            effect,
            magnitude,
            conceal,
        }) => {
            if let Some(effects) = effect {
                let answer = app::cases::write_case(
                    &motorcal::study::cases::CaseOptions {
                        effects,
                        magnitude,
                        input,
                        seed,
                        conceal,
                    },
                    &out,
                )?;
                println!(
                    "wrote {} (effect {}, peak {:.2}/{:.2} σ on I/ω, input {:?}{})",
                    out.display(),
                    answer.effect,
                    answer.max_abs_effect_over_sigma["I"],
                    answer.max_abs_effect_over_sigma["omega"],
                    answer.input,
                    if answer.input_fallback {
                        ", after falling back"
                    } else {
                        ""
                    }
                );
                return Ok(());
            }
            let options = app::simulate::SimulateOptions {
                truth,
                nominal,
                out,
                seed,
                input,
                noise_sd: [noise_sd[0], noise_sd[1]],
                samples,
                t_end,
            };
            let report = app::simulate::simulate(&options)?;
            println!("wrote {}", report.recording.display());
            println!(
                "wrote {} (the model a user would believe)",
                report.nominal.display()
            );
            println!(
                "wrote {} (the truth that made the data)",
                report.truth.display()
            );
            println!(
                "realised noise sd: I {:.4} A, omega {:.4} rad/s (seed {seed})",
                report.realised_noise_sd[0], report.realised_noise_sd[1]
            );
            Ok(())
        }
        Some(Command::Predict {
            model,
            data,
            csv,
            json,
        }) => {
            let options = app::predict::PredictOptions {
                data,
                model,
                csv,
                json,
            };
            let table = app::predict::predict(&options)?;
            print!("{}", app::predict::format_residuals(&table));
            Ok(())
        }
        Some(Command::Summarize { draws, json }) => {
            let (summaries, chains, n) = app::summarize::summarize_files(&draws)?;
            println!("{chains} chains × {n} draws");
            print!("{}", app::summarize::format_table(&summaries));
            if let Some(path) = json {
                let text = serde_json::to_string_pretty(&summaries)
                    .map_err(|e| AppError::Output(e.to_string()))?;
                motorcal::io::write_atomically(&path, text.as_bytes())?;
                println!("wrote {}", path.display());
            }
            Ok(())
        }
    }
}

fn main() -> ExitCode {
    match run(Cli::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}
