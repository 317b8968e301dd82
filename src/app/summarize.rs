//! `motorcal summarize`: convergence diagnostics for any draws files.

use std::path::PathBuf;

use crate::diagnostics::{ParameterSummary, summarize};
use crate::io::read_draws;

use super::AppError;

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
