//! `motorcal fit`: calibrate a nominal model on a user's recording with BM1 or BM2(K).

use std::path::PathBuf;

use serde::Serialize;

use crate::bayes::ModelSettings;
use crate::density::LogDensity;
use crate::diagnostics::ParameterSummary;

use super::problem::Problem;
use super::run::{RunSettings, map_estimate, run_sampler, write_draws};
use super::{AppError, predictive, provenance};

#[derive(Clone, Debug)]
pub struct FitOptions {
    pub data: PathBuf,
    pub model: PathBuf,
    pub settings: ModelSettings,
    /// `None`: the MAP and its Laplace approximation only.
    pub run: Option<RunSettings>,
    pub out: PathBuf,
}

/// The MAP with Laplace standard deviations, per unconstrained coordinate.
#[derive(Clone, Debug, Serialize)]
pub struct MapRow {
    pub name: String,
    pub value: f64,
    pub laplace_sd: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct FitReport {
    pub data: String,
    pub model: String,
    pub settings: ModelSettings,
    pub map: Vec<MapRow>,
    pub map_log_density: f64,
    pub log_evidence_laplace: f64,
    pub sampler: Option<String>,
    pub summaries: Vec<ParameterSummary>,
    pub max_rhat: Option<f64>,
    pub min_ess_bulk: Option<f64>,
    pub wall_seconds: Option<f64>,
    pub outputs: Vec<String>,
    pub provenance: Vec<(String, String)>,
}

pub fn fit(options: &FitOptions) -> Result<FitReport, AppError> {
    options.settings.validate().map_err(AppError::Usage)?;
    if let Some(run) = &options.run {
        run.validate()?;
    }
    let problem = Problem::from_files(&options.data, &options.model)?;
    let mut posterior = problem.posterior(&options.settings)?;
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
        data: options.data.display().to_string(),
        model: options.model.display().to_string(),
        settings: options.settings.clone(),
        map: map_rows,
        map_log_density: map.log_density,
        log_evidence_laplace: map.log_evidence_laplace,
        sampler: None,
        summaries: Vec::new(),
        max_rhat: None,
        min_ess_bulk: None,
        wall_seconds: None,
        outputs: Vec::new(),
        provenance: provenance(),
    };
    if let Some(run_settings) = &options.run {
        let run = run_sampler(&mut posterior, run_settings, &options.settings.label())?;
        let mut meta = provenance();
        meta.push(("data".into(), report.data.clone()));
        meta.push(("model_file".into(), report.model.clone()));
        meta.push(("model".into(), options.settings.label()));
        meta.push((
            "settings".into(),
            serde_json::to_string(run_settings).unwrap_or_default(),
        ));
        meta.push(("seed".into(), run_settings.seed.to_string()));
        for path in write_draws(&options.out, "fit", &run, &meta)? {
            report.outputs.push(path.display().to_string());
        }
        let p = predictive::posterior_predictive(&mut posterior, &run.chains)?;
        let csv = options.out.join("predictive.csv");
        predictive::write_predictive_csv(&csv, &p)?;
        let png = options.out.join("predictive.png");
        let title = format!(
            "{} — {} on {}",
            options.settings.label(),
            run.sampler,
            report.data
        );
        predictive::plot_predictive(&png, &title, &p)?;
        let traces = options.out.join("traces.png");
        let theta: Vec<(&str, Option<f64>)> = run
            .summaries
            .iter()
            .take(3)
            .map(|s| (s.name.as_str(), None))
            .collect();
        predictive::plot_traces(&traces, &title, &run.chains, &theta)?;
        if options.settings.discrepancy_degree.is_some() {
            let png = options.out.join("discrepancy.png");
            predictive::plot_discrepancy(&png, &format!("δ of {title}"), &p, None)?;
            report.outputs.push(png.display().to_string());
        }
        report
            .outputs
            .extend([csv, png, traces].iter().map(|p| p.display().to_string()));
        report.sampler = Some(run.sampler.clone());
        report.max_rhat = Some(run.max_rhat);
        report.min_ess_bulk = Some(run.min_ess_bulk);
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

pub fn format_report(report: &FitReport) -> String {
    let mut out = format!(
        "{} on {} (model {})\n",
        report.settings.label(),
        report.data,
        report.model
    );
    out.push_str(&format!(
        "MAP: log density {:.3}, Laplace log evidence {:.3}\n",
        report.map_log_density, report.log_evidence_laplace
    ));
    if report.summaries.is_empty() {
        out.push_str(&format!(
            "{:<16} {:>14} {:>12}\n",
            "parameter", "MAP", "Laplace sd"
        ));
        for row in &report.map {
            out.push_str(&format!(
                "{:<16} {:>14.6e} {:>12.4e}\n",
                row.name, row.value, row.laplace_sd
            ));
        }
    } else {
        out.push_str(&format!(
            "sampler {}: max R-hat {:.4}, min bulk ESS {:.0}, {:.1} s\n",
            report.sampler.as_deref().unwrap_or("?"),
            report.max_rhat.unwrap_or(f64::NAN),
            report.min_ess_bulk.unwrap_or(f64::NAN),
            report.wall_seconds.unwrap_or(f64::NAN)
        ));
        out.push_str(&super::summarize::format_table(&report.summaries));
    }
    for o in &report.outputs {
        out.push_str(&format!("wrote {o}\n"));
    }
    out
}
