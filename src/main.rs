//! The `motorcal` command line: the tree of commands; each command's options, and what it does
//! with them, are in `motorcal::app`.

use std::process::ExitCode;

use clap::{Parser, Subcommand};
use motorcal::app::{self, AppError};

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
    Simulate(app::simulate::SimulateOptions),
    /// Calibrate a model file on a recording with BM1 or BM2(K): MAP, then MCMC.
    Fit(app::fit::FitArgs),
    /// Effective samples per second of every sampler across K, side by side.
    Bench(app::bench::BenchArgs),
    /// BM2 for each K on the paper's data: the error measures of §4.2 and Figures 8–11.
    Sweep(app::sweep::SweepArgs),
    /// Choose K by §3.2.3's rule: the smallest K whose σ posteriors stay put for K + 1..3.
    SelectK(app::sweep::SweepArgs),
    /// Join the JSON of sweep shards into what one unsharded sweep writes.
    Merge(app::merge::MergeArgs),
    /// Find the physics the model left out: locate the mismatch, rank candidate terms by
    /// evidence, add the best, refit, and show the fit improve.
    Diagnose(app::diagnose::DiagnoseArgs),
    /// The input to record next, within the drive's limits: one that tells a diagnosis's tied
    /// candidates apart (--separate) or pins parameters (--pin).
    Design(app::design::DesignArgs),
    /// Reproduce a result of the paper.
    Reproduce {
        #[command(subcommand)]
        what: Reproduce,
    },
    /// A model file's prediction of records it was not fitted to, with the residual RMS per
    /// channel (the estimation → validation cross-test).
    Predict(app::predict::PredictOptions),
    /// Print ESS, R-hat and MCSE for draws files (CmdStan CSV, or a long chain,draw,… table).
    Summarize(app::summarize::SummarizeArgs),
}

#[derive(Subcommand)]
enum Reproduce {
    /// Table 1: BM1 and BM2(K = 9) on the paper's synthetic data, with the paper's protocol.
    Table1(app::table1::Table1Args),
}

fn run(cli: Cli) -> Result<(), AppError> {
    match cli.command {
        None => app::table1::run_default(),
        Some(Command::Reproduce {
            what: Reproduce::Table1(args),
        }) => app::table1::run(&args),
        Some(Command::Simulate(args)) => app::simulate::run(&args),
        Some(Command::Fit(args)) => app::fit::run(&args),
        Some(Command::Bench(args)) => app::bench::run(&args),
        Some(Command::Sweep(args)) => app::sweep::run(&args),
        Some(Command::SelectK(args)) => app::select_k::run(&args),
        Some(Command::Merge(args)) => app::merge::run(&args),
        Some(Command::Diagnose(args)) => app::diagnose::run(&args),
        Some(Command::Predict(args)) => app::predict::run(&args),
        Some(Command::Design(args)) => app::design::run(&args),
        Some(Command::Summarize(args)) => app::summarize::run(&args),
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
