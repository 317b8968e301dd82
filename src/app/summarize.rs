//! `motorcal summarize`: convergence diagnostics for any draws files.

use std::path::PathBuf;

use crate::diagnostics::{ParameterSummary, summarize};
use crate::io::read_draws;

use super::AppError;

#[derive(clap::Args, Clone, Debug)]
pub struct SummarizeArgs {
    #[arg(required = true)]
    pub draws: Vec<PathBuf>,
    /// Also write the summary as JSON.
    #[arg(long)]
    pub json: Option<PathBuf>,
}

/// `motorcal summarize`: the table, and the JSON if asked.
pub fn run(args: &SummarizeArgs) -> Result<(), AppError> {
    let (summaries, chains, n) = summarize_files(&args.draws)?;
    println!("{chains} chains × {n} draws");
    print!("{}", format_table(&summaries));
    if let Some(path) = &args.json {
        let text = serde_json::to_string_pretty(&summaries)
            .map_err(|e| AppError::Output(e.to_string()))?;
        crate::io::write_atomically(path, text.as_bytes())?;
        println!("wrote {}", path.display());
    }
    Ok(())
}

/// Summaries of every parameter in the draws files (ours or the peers' long layout).
pub fn summarize_files(
    paths: &[PathBuf],
) -> Result<(Vec<ParameterSummary>, usize, usize), AppError> {
    let set = read_draws(paths)?;
    let summaries = set
        .names
        .iter()
        .map(|name| {
            summarize(
                name.clone(),
                &set.parameter(name).expect("name from the set"),
            )
        })
        .collect();
    Ok((summaries, set.n_chains(), set.n_draws()))
}

/// The human table: one row per parameter.
pub fn format_table(summaries: &[ParameterSummary]) -> String {
    let width = summaries
        .iter()
        .map(|s| s.name.len())
        .max()
        .unwrap_or(4)
        .max(9);
    let mut out = format!(
        "{:<width$} {:>12} {:>11} {:>11} {:>11} {:>11} {:>10} {:>9} {:>9} {:>7}\n",
        "parameter",
        "mean",
        "sd",
        "q05",
        "q50",
        "q95",
        "mcse_mean",
        "ess_bulk",
        "ess_tail",
        "r_hat"
    );
    for s in summaries {
        out.push_str(&format!(
            "{:<width$} {:>12.5e} {:>11.4e} {:>11.4e} {:>11.4e} {:>11.4e} {:>10.3e} {:>9.0} {:>9.0} {:>7.4}\n",
            s.name, s.mean, s.sd, s.q05, s.q50, s.q95, s.mcse_mean, s.ess_bulk, s.ess_tail, s.rhat
        ));
    }
    out
}
