//! `motorcal reproduce table1`: the paper's Table 1 (`paper::table1`), its draws, figures,
//! JSON, CSV and the human table.

use std::path::{Path, PathBuf};

use crate::io::provenance;
use crate::pipeline::{SamplerKind, write_draws};
use crate::study::posterior_predictive;

use super::AppError;
use super::args::ChainArgs;
use super::figures::{plot_discrepancy, plot_predictive, plot_traces};

pub use crate::paper::table1::*;

#[derive(clap::Args, Clone, Debug)]
pub struct Table1Args {
    /// BM2 runs of 10000 instead of 100000 draws.
    #[arg(long)]
    pub quick: bool,
    /// Samplers to run, comma separated.
    #[arg(long, value_enum, value_delimiter = ',', default_values_t = [SamplerKind::Metropolis, SamplerKind::AdaptiveMetropolis, SamplerKind::NutsDense])]
    pub samplers: Vec<SamplerKind>,
    #[command(flatten)]
    pub chains: ChainArgs,
    /// Worker threads (default: all cores); draws do not depend on it.
    #[arg(long)]
    pub threads: Option<usize>,
    /// Output folder for draws, table1.json and table1.csv.
    #[arg(long, default_value = "out/table1")]
    pub out: PathBuf,
}

impl Table1Args {
    /// The reproduction these flags ask for; what is not given is the paper's protocol.
    pub fn options(&self) -> Table1Options {
        let defaults = Table1Options::default();
        Table1Options {
            seed: self.chains.seed,
            quick: self.quick,
            samplers: self.samplers.clone(),
            chains: self.chains.chains_or(defaults.chains),
            threads: self.threads,
            out: self.out.clone(),
            quiet: self.chains.quiet,
            metric_adaptation: self
                .chains
                .metric_adaptation
                .unwrap_or(defaults.metric_adaptation),
        }
    }
}

/// `motorcal reproduce table1`: the table, and what it wrote.
pub fn run(args: &Table1Args) -> Result<(), AppError> {
    run_options(&args.options())
}

/// `motorcal` without a command: Table 1 by the paper's protocol.
pub fn run_default() -> Result<(), AppError> {
    println!(
        "motorcal: reproducing the paper's Table 1 (see `motorcal --help` for the other commands)\n"
    );
    run_options(&Table1Options::default())
}

fn run_options(options: &Table1Options) -> Result<(), AppError> {
    let report = table1(options)?;
    print!("{}", format_report(&report));
    println!();
    println!(
        "wrote {}/table1.json, table1.csv, figures and the draws (CmdStan CSV)",
        options.out.display()
    );
    Ok(())
}

/// The whole command: runs, then the draws and figures of each as it finishes, then the report.
pub fn table1(options: &Table1Options) -> Result<Table1Report, AppError> {
    let mut metadata = provenance();
    metadata.push(("seed".into(), options.seed.to_string()));
    metadata.push((
        "data".into(),
        format!("paper synthetic data (seed {})", options.seed),
    ));
    let report = reproduce_table1_with(options, |r| write_run(options, &metadata, r))?;
    write_report(&options.out, &report)?;
    Ok(report)
}

fn write_run(
    options: &Table1Options,
    metadata: &[(String, String)],
    r: Table1Run<'_>,
) -> Result<(), AppError> {
    let Table1Run {
        model,
        settings,
        run,
        posterior,
        truth,
        reference,
    } = r;
    let mut meta = metadata.to_vec();
    meta.push(("model".into(), model.clone()));
    meta.push((
        "settings".into(),
        serde_json::to_string(settings).unwrap_or_default(),
    ));
    let prefix = model.replace(['(', ')', '='], "").to_lowercase();
    write_draws(&options.out, &prefix, run, &meta)?;
    let title = format!("{model} — {} ({} chains)", run.sampler, options.chains);
    plot_traces(
        &options
            .out
            .join(format!("traces-{prefix}-{}.png", run.sampler)),
        &title,
        &run.chains,
        &[
            ("R", Some(truth[0])),
            ("sigma_I", Some(truth[1])),
            ("sigma_omega", Some(truth[2])),
        ],
    )?;
    if posterior.coefficient_range(0, 0).is_some() {
        let predictive = posterior_predictive(posterior, &run.chains, 0)?;
        plot_discrepancy(
            &options
                .out
                .join(format!("discrepancy-{prefix}-{}.png", run.sampler)),
            &format!("δ of {title}; dashed: the reference d0"),
            &predictive,
            Some(&reference.discrepancy),
        )?;
        plot_predictive(
            &options
                .out
                .join(format!("predictive-{prefix}-{}.png", run.sampler)),
            &title,
            &predictive,
        )?;
    }
    Ok(())
}

fn write_report(dir: &Path, report: &Table1Report) -> Result<(), AppError> {
    let json = serde_json::to_string_pretty(report).map_err(|e| AppError::Output(e.to_string()))?;
    crate::io::write_atomically(&dir.join("table1.json"), json.as_bytes())?;
    let mut csv = String::from(
        "model,sampler,warmup,draws,kept,chains,mean_R,mean_sigma_I,mean_sigma_omega,rel_err_R,rel_err_sigma_I,rel_err_sigma_omega,delta_rel_err_I,delta_rel_err_omega,max_rhat,min_ess_bulk,wall_s,converged\n",
    );
    for r in &report.rows {
        let (di, dw) = r
            .discrepancy_rel_error
            .map_or((f64::NAN, f64::NAN), |d| (d[0], d[1]));
        csv.push_str(&format!(
            "{},{},{},{},{},{},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{},{},{},{}\n",
            r.model,
            r.sampler,
            r.warmup,
            r.draws,
            r.kept,
            r.chains,
            r.mean_r,
            r.mean_sigma_i,
            r.mean_sigma_omega,
            r.rel_error_r,
            r.rel_error_sigma_i,
            r.rel_error_sigma_omega,
            di,
            dw,
            r.max_rhat,
            r.min_ess_bulk,
            r.wall_seconds,
            r.converged
        ));
    }
    crate::io::write_atomically(&dir.join("table1.csv"), csv.as_bytes())?;
    Ok(())
}

/// The human table, with the paper's numbers beside ours.
pub fn format_report(report: &Table1Report) -> String {
    let mut out = String::new();
    out.push_str(&format!(
        "Table 1 — paper's synthetic data, seed {} (realised noise sd: I {:.3} A, omega {:.3} rad/s)\n\n",
        report.seed, report.realised_noise_sd[0], report.realised_noise_sd[1]
    ));
    out.push_str(&format!(
        "{:<10} {:<20} {:>10} {:>9} {:>9} {:>9} {:>9} {:>9} {:>13} {:>7} {:>8} {:>7}\n",
        "model",
        "sampler",
        "R",
        "sigma_I",
        "sigma_w",
        "err R",
        "err s_I",
        "err s_w",
        "err delta I/w",
        "R-hat",
        "min ESS",
        "wall s"
    ));
    for (model, means, e) in PAPER_TABLE1 {
        let delta = if model == "BM1" {
            "".to_string()
        } else {
            format!(
                "{:.3}/{:.3}",
                PAPER_DISCREPANCY_ERROR[0], PAPER_DISCREPANCY_ERROR[1]
            )
        };
        out.push_str(&format!(
            "{:<10} {:<20} {:>10.3e} {:>9.3} {:>9.3} {:>9.2e} {:>9.2e} {:>9.2e} {:>13} {:>7} {:>8} {:>7}\n",
            model, "paper (PyMC3 MH)", means[0], means[1], means[2], e[0], e[1], e[2], delta, "", "", ""
        ));
    }
    for r in &report.rows {
        let delta = r
            .discrepancy_rel_error
            .map_or(String::new(), |d| format!("{:.3}/{:.3}", d[0], d[1]));
        out.push_str(&format!(
            "{:<10} {:<20} {:>10.3e} {:>9.3} {:>9.3} {:>9.2e} {:>9.2e} {:>9.2e} {:>13} {:>7.3} {:>8.0} {:>7.1}{}\n",
            r.model,
            r.sampler,
            r.mean_r,
            r.mean_sigma_i,
            r.mean_sigma_omega,
            r.rel_error_r,
            r.rel_error_sigma_i,
            r.rel_error_sigma_omega,
            delta,
            r.max_rhat,
            r.min_ess_bulk,
            r.wall_seconds,
            if r.converged { "" } else { "  (not converged)" }
        ));
    }
    out
}
