//! The `motorcal` command line: parses options and calls the library (`motorcal::app`).

use std::path::PathBuf;
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

fn run(cli: Cli) -> Result<(), AppError> {
    match cli.command {
        None => Err(AppError::Usage("no command yet".into())),
        Some(Command::Simulate {
            truth,
            nominal,
            out,
            seed,
            input,
            noise_sd,
            samples,
            t_end,
        }) => {
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
