//! `motorcal fit`: calibrate a model file on one or more recordings with BM1 or BM2(K).

use std::path::PathBuf;

use serde::Serialize;

use crate::bayes::{CalibrationPosterior, ModelSettings};
use crate::density::LogDensity;
use crate::diagnostics::ParameterSummary;
use crate::pipeline::{
    RunOutput, RunSettings, map_estimate, posterior_mean, run_sampler, write_draws,
};

use super::args::{ChainArgs, coefficient_prior};
use super::figures::{plot_discrepancy, plot_predictive, plot_traces, write_predictive_csv};
use super::{AppError, provenance};
use crate::bayes::CoefficientFamily;
use crate::pipeline::SamplerKind;
use crate::study::{Problem, posterior_predictive};

#[derive(Clone, Debug)]
pub struct FitOptions {
    /// One or more recordings: the physics is shared, noise and δ are per recording.
    pub data: Vec<PathBuf>,
    pub model: PathBuf,
    /// BM1 or BM2 (`Some(1)`, `Some(2)`); `None` takes the model file's `[discrepancy]`.
    pub bm: Option<u8>,
    /// The degree K; `None` takes the model file's, else 9.
    pub k: Option<usize>,
    /// The coefficients' prior (family, decay); its degree and basis come from `bm`/`k`.
    pub coefficient_prior: crate::bayes::CoefficientPrior,
    /// `None`: the MAP and its Laplace approximation only.
    pub run: Option<RunSettings>,
    pub out: PathBuf,
    /// Go on when a recording cannot be this motor as set up.
    pub force: bool,
}

#[derive(clap::Args, Clone, Debug)]
pub struct FitArgs {
    /// A recording (CSV with t, I, omega[, U]); repeat for several recordings, which share the
    /// physics and have their own noise and discrepancy.
    #[arg(long, required = true)]
    pub data: Vec<PathBuf>,
    /// The nominal model (TOML, schema 1 or 2).
    #[arg(long)]
    pub model: PathBuf,
    /// Bayesian model: 1 (noise only) or 2 (noise + discrepancy); default: the model file's
    /// [discrepancy], else 2.
    #[arg(long, value_parser = clap::value_parser!(u8).range(1..=2))]
    pub bm: Option<u8>,
    /// Degree K of the discrepancy (BM2); default: the model file's, else 9.
    #[arg(long)]
    pub k: Option<usize>,
    /// Decay power p of the coefficient prior variance V0/(j+1)^p (0: the paper's prior).
    #[arg(long, default_value_t = 0.0)]
    pub prior_decay: f64,
    /// Family of the coefficient prior.
    #[arg(long, value_enum, default_value_t = CoefficientFamily::Laplace)]
    pub prior_family: CoefficientFamily,
    /// Only the MAP and its Laplace approximation, no sampling.
    #[arg(long)]
    pub map_only: bool,
    /// Go on when a recording cannot be this motor as set up (a dead channel, a unit, sign or
    /// swap, time in ms).
    #[arg(long)]
    pub force: bool,
    #[command(flatten)]
    pub run: RunArgs,
    /// Output folder.
    #[arg(long, default_value = "out/fit")]
    pub out: PathBuf,
}

// Options of a command that runs one sampler.
#[derive(clap::Args, Clone, Debug)]
pub struct RunArgs {
    #[arg(long, value_enum, default_value_t = SamplerKind::NutsDense)]
    pub sampler: SamplerKind,
    #[command(flatten)]
    pub chains: ChainArgs,
    /// Warm-up per chain (default: 100 for HMC/NUTS on the Laplace metric, else 1000).
    #[arg(long)]
    pub warmup: Option<usize>,
    #[arg(long, default_value_t = 1000)]
    pub draws: usize,
    /// Keep only the last N draws of each chain.
    #[arg(long)]
    pub keep: Option<usize>,
    /// Worker threads (default: all cores); draws do not depend on it.
    #[arg(long)]
    pub threads: Option<usize>,
    /// HMC/NUTS: save the adapted step size and metric (TOML) for a later warm start.
    #[arg(long)]
    pub save_adaptation: Option<PathBuf>,
    /// HMC/NUTS: start from a saved adaptation and skip adapting (use with a short --warmup).
    #[arg(long)]
    pub load_adaptation: Option<PathBuf>,
    /// laplace-is, independence: keep the Laplace sampler even when k̂ says the Laplace
    /// approximation cannot be trusted (above 0.7 for laplace-is, 0.5 for independence;
    /// default: fall back to NUTS).
    #[arg(long)]
    pub no_fallback: bool,
    /// laplace-is: gradients per transition its NUTS fallback may spend on average, per
    /// chain, each priced at the integrator's work of one gradient at the MAP; a chain past it
    /// stops the fallback and the importance sample with the lower k̂ stands (diagnose's fits:
    /// 16). Default: no limit.
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..))]
    pub fallback_budget: Option<u64>,
}

impl RunArgs {
    pub fn settings(&self) -> RunSettings {
        let mut run = self.chains.run(self.sampler, self.warmup, self.draws);
        run.chain.keep = self.keep;
        run.threads = self.threads;
        run.save_adaptation = self.save_adaptation.clone();
        run.load_adaptation = self.load_adaptation.clone();
        run.fallback = !self.no_fallback;
        run.fallback_budget = self.fallback_budget;
        run
    }
}

impl FitArgs {
    /// The fit these flags ask for.
    pub fn options(&self) -> FitOptions {
        FitOptions {
            data: self.data.clone(),
            model: self.model.clone(),
            bm: self.bm,
            k: self.k,
            coefficient_prior: coefficient_prior(self.prior_family, self.prior_decay),
            run: (!self.map_only).then(|| self.run.settings()),
            out: self.out.clone(),
            force: self.force,
        }
    }
}

/// `motorcal fit`: the fit, then its report.
pub fn run(args: &FitArgs) -> Result<(), AppError> {
    let report = fit(&args.options())?;
    print!("{}", format_report(&report));
    Ok(())
}

/// The MAP with Laplace standard deviations, per unconstrained coordinate.
#[derive(Clone, Debug, Serialize)]
pub struct MapRow {
    pub name: String,
    pub value: f64,
    pub laplace_sd: f64,
}

/// How well one recording's channel is fitted at the posterior mean (the MAP without sampling).
#[derive(Clone, Debug, Serialize)]
pub struct ChannelFit {
    pub record: String,
    pub channel: String,
    /// RMS of y − G(θ) − δ(a) at the point.
    pub rmse: f64,
    /// The noise σ at the point.
    pub sigma: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct FitReport {
    pub data: Vec<String>,
    pub model: String,
    pub settings: ModelSettings,
    /// What was calibrated (the model's names, `term.key` for a term's parameters).
    pub calibrated: Vec<String>,
    pub map: Vec<MapRow>,
    pub map_log_density: f64,
    /// The log likelihood (priors excluded) at the MAP.
    pub map_log_likelihood: f64,
    pub log_evidence_laplace: f64,
    pub sampler: Option<String>,
    /// The run's settings, seed included (absent for `--map-only`).
    pub run_settings: Option<RunSettings>,
    pub seed: Option<u64>,
    pub summaries: Vec<ParameterSummary>,
    /// The log likelihood at the posterior mean (in the unconstrained coordinates).
    pub posterior_mean_log_likelihood: Option<f64>,
    /// RMSE per channel and recording at the posterior mean (at the MAP without sampling).
    pub fit: Vec<ChannelFit>,
    pub max_rhat: Option<f64>,
    pub min_ess_bulk: Option<f64>,
    pub divergences: Option<usize>,
    /// laplace-is, independence: the Pareto shape k̂ of the importance weights of their
    /// proposals (independence: its warm-up's; null for the other samplers).
    pub khat: Option<f64>,
    /// laplace-is, independence: k̂ above the sampler's line (0.7, 0.5) and NUTS drew instead.
    pub fell_back: bool,
    /// laplace-is: NUTS was to draw instead but spent `--fallback-budget`; the importance
    /// sample with the lower k̂ stands.
    pub fallback_stopped: bool,
    pub wall_seconds: Option<f64>,
    pub outputs: Vec<String>,
    /// What the plausibility check found, when `--force` went on regardless.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub implausible: Vec<crate::study::plausibility::Finding>,
    pub provenance: Vec<(String, String)>,
}

/// The settings a fit runs with: the model file's discrepancy unless `bm`/`k` override it.
pub fn model_settings(problem: &Problem, options: &FitOptions) -> Result<ModelSettings, AppError> {
    let mut settings = problem.model_settings(options.bm, options.k);
    settings.coefficient_prior = options.coefficient_prior;
    settings.validate().map_err(|e| {
        AppError::Usage(match options.k {
            Some(k) => format!("--k {k}: {e}"),
            None => e,
        })
    })?;
    Ok(settings)
}

pub fn fit(options: &FitOptions) -> Result<FitReport, AppError> {
    if let Some(run) = &options.run {
        run.validate()?;
    }
    let problem = Problem::from_files(&options.data, &options.model)?;
    let implausible = super::plausible(&problem, options.force)?;
    let settings = model_settings(&problem, options)?;
    let mut posterior = problem.posterior(&settings)?;
    let map = map_estimate(&mut posterior)?;
    let names = posterior.parameter_names();
    let sd = map.laplace_sd();
    let map_rows = names
        .iter()
        .zip(&map.x)
        .zip(&sd)
        .map(|((name, &value), &laplace_sd)| MapRow {
            name: name.clone(),
            value,
            laplace_sd,
        })
        .collect();
    let mut report = FitReport {
        data: options
            .data
            .iter()
            .map(|p| p.display().to_string())
            .collect(),
        model: options.model.display().to_string(),
        settings: settings.clone(),
        calibrated: posterior
            .calibrated()
            .iter()
            .map(|c| c.name.clone())
            .collect(),
        map: map_rows,
        map_log_density: map.log_density,
        map_log_likelihood: posterior.log_likelihood(&map.x)?,
        log_evidence_laplace: map.log_evidence_laplace,
        sampler: None,
        run_settings: options.run.clone(),
        seed: options.run.as_ref().map(|r| r.seed),
        summaries: Vec::new(),
        posterior_mean_log_likelihood: None,
        fit: channel_fits(&mut posterior, &map.x)?,
        max_rhat: None,
        min_ess_bulk: None,
        divergences: None,
        khat: None,
        fell_back: false,
        fallback_stopped: false,
        wall_seconds: None,
        outputs: Vec::new(),
        implausible,
        provenance: provenance(),
    };
    if let Some(run_settings) = &options.run {
        let run = run_sampler(&mut posterior, run_settings, &settings.label())?;
        write_run_outputs(&mut posterior, &run, options, &settings, &mut report)?;
        let mean = posterior_mean(&run);
        report.posterior_mean_log_likelihood = Some(posterior.log_likelihood(&mean)?);
        report.fit = channel_fits(&mut posterior, &mean)?;
        report.sampler = Some(run.sampler.clone());
        report.max_rhat = Some(run.max_rhat);
        report.min_ess_bulk = Some(run.min_ess_bulk);
        report.divergences = Some(run.divergences);
        report.khat = run.khat;
        report.fell_back = run.fell_back;
        report.fallback_stopped = run.fallback_stopped;
        report.wall_seconds = Some(run.wall_seconds);
        report.summaries = run.summaries;
    }
    let json = options.out.join("fit.json");
    report.outputs.push(json.display().to_string());
    let text =
        serde_json::to_string_pretty(&report).map_err(|e| AppError::Output(e.to_string()))?;
    crate::io::write_atomically(&json, text.as_bytes())?;
    Ok(report)
}

/// RMSE and σ of every recording's channels at x.
pub fn channel_fits(
    posterior: &mut CalibrationPosterior,
    x: &[f64],
) -> Result<Vec<ChannelFit>, AppError> {
    let mut fits = Vec::new();
    for r in 0..posterior.n_records() {
        let residuals = posterior.residuals(x, r)?;
        for (c, name) in posterior.channel_names(r).into_iter().enumerate() {
            let res = &residuals[c];
            fits.push(ChannelFit {
                record: posterior.record_label(r).to_string(),
                channel: name,
                rmse: (res.iter().map(|v| v * v).sum::<f64>() / res.len() as f64).sqrt(),
                sigma: x[posterior.log_sigma_index(r, c)].exp(),
            });
        }
    }
    Ok(fits)
}

/// Draws, and per recording the predictive CSV and the figures.
fn write_run_outputs(
    posterior: &mut CalibrationPosterior,
    run: &RunOutput,
    options: &FitOptions,
    settings: &ModelSettings,
    report: &mut FitReport,
) -> Result<(), AppError> {
    let mut meta = provenance();
    meta.push(("data".into(), report.data.join(" ")));
    meta.push(("model_file".into(), report.model.clone()));
    meta.push(("model".into(), settings.label()));
    if let Some(run_settings) = &options.run {
        meta.push((
            "settings".into(),
            serde_json::to_string(run_settings).unwrap_or_default(),
        ));
        meta.push(("seed".into(), run_settings.seed.to_string()));
    }
    for path in write_draws(&options.out, "fit", run, &meta)? {
        report.outputs.push(path.display().to_string());
    }
    let several = posterior.n_records() > 1;
    for r in 0..posterior.n_records() {
        let suffix = if several {
            format!("-r{}", r + 1)
        } else {
            String::new()
        };
        let p = posterior_predictive(posterior, &run.chains, r)?;
        let csv = options.out.join(format!("predictive{suffix}.csv"));
        write_predictive_csv(&csv, &p)?;
        let png = options.out.join(format!("predictive{suffix}.png"));
        let title = format!(
            "{} — {} on {}",
            settings.label(),
            run.sampler,
            posterior.record_label(r)
        );
        plot_predictive(&png, &title, &p)?;
        report
            .outputs
            .extend([&csv, &png].iter().map(|p| p.display().to_string()));
        if settings.discrepancy_degree.is_some() {
            let png = options.out.join(format!("discrepancy{suffix}.png"));
            plot_discrepancy(&png, &format!("δ of {title}"), &p, None)?;
            report.outputs.push(png.display().to_string());
        }
    }
    let traces = options.out.join("traces.png");
    let title = format!("{} — {}", settings.label(), run.sampler);
    let shown: Vec<(&str, Option<f64>)> = run
        .summaries
        .iter()
        .take(3)
        .map(|s| (s.name.as_str(), None))
        .collect();
    plot_traces(&traces, &title, &run.chains, &shown)?;
    report.outputs.push(traces.display().to_string());
    Ok(())
}

pub fn format_report(report: &FitReport) -> String {
    let mut out = format!(
        "{} on {} (model {}; calibrated: {})\n",
        report.settings.label(),
        report.data.join(" + "),
        report.model,
        report.calibrated.join(", ")
    );
    out.push_str(&format!(
        "MAP: log density {:.3}, log likelihood {:.3}, Laplace log evidence {:.3}\n",
        report.map_log_density, report.map_log_likelihood, report.log_evidence_laplace
    ));
    for finding in &report.implausible {
        out.push_str(&format!("implausible (went on with --force): {finding}\n"));
    }
    if report.summaries.is_empty() {
        out.push_str(&format!(
            "{:<24} {:>14} {:>12}\n",
            "parameter", "MAP", "Laplace sd"
        ));
        for row in &report.map {
            out.push_str(&format!(
                "{:<24} {:>14.6e} {:>12.4e}\n",
                row.name, row.value, row.laplace_sd
            ));
        }
    } else {
        out.push_str(&format!(
            "sampler {}: max R-hat {:.4}, min bulk ESS {:.0}, {} divergences, {:.1} s\n",
            report.sampler.as_deref().unwrap_or("?"),
            report.max_rhat.unwrap_or(f64::NAN),
            report.min_ess_bulk.unwrap_or(f64::NAN),
            report.divergences.unwrap_or(0),
            report.wall_seconds.unwrap_or(f64::NAN)
        ));
        if let Some(khat) = report.khat {
            out.push_str(&khat_line(khat, report.fell_back, report.fallback_stopped));
        }
        out.push_str(&super::summarize::format_table(&report.summaries));
    }
    for f in &report.fit {
        out.push_str(&format!(
            "fit {} {}: RMSE {:.4}, sigma {:.4}\n",
            f.record, f.channel, f.rmse, f.sigma
        ));
    }
    for o in &report.outputs {
        out.push_str(&format!("wrote {o}\n"));
    }
    out
}

/// What k̂ says about the Laplace approximation, and what the run did about it.
pub fn khat_line(khat: f64, fell_back: bool, fallback_stopped: bool) -> String {
    use crate::diagnostics::{KHAT_GOOD, KHAT_UNRELIABLE};
    let verdict = if khat <= KHAT_GOOD {
        "the Laplace approximation is good"
    } else if khat <= KHAT_UNRELIABLE {
        "the Laplace approximation is usable, the estimates converge slowly"
    } else {
        "the Laplace approximation cannot be trusted"
    };
    let action = if fell_back {
        "; NUTS drew instead"
    } else if fallback_stopped {
        "; NUTS, to draw instead, spent its --fallback-budget: these draws stand"
    } else if khat > KHAT_UNRELIABLE || khat.is_nan() {
        "; kept as asked (--no-fallback)"
    } else {
        ""
    };
    format!("importance weights: Pareto k̂ = {khat:.3}: {verdict}{action}\n")
}
