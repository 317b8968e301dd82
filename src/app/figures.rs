//! The files and figures made from a fit's predictive: `predictive.csv`, the fit with its band,
//! δ with its band, the traces.

use std::path::Path;

use crate::plot::{self, ChannelPrediction, DiscrepancyBand, PredictivePlot, TraceSeries};
use crate::sampler::ChainOutput;
use crate::study::Predictive;

use super::AppError;

/// `predictive.csv`: one row per channel and time.
pub fn write_predictive_csv(path: &Path, p: &Predictive) -> Result<(), AppError> {
    let mut text = String::from(
        "channel,t,measured,model_at_mean,mean,lower_95,upper_95,residual,discrepancy_mean,discrepancy_lower_95,discrepancy_upper_95\n",
    );
    for ch in &p.channels {
        for (i, t) in p.times.iter().enumerate() {
            text.push_str(&format!(
                "{},{t:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?}\n",
                ch.name,
                ch.measured[i],
                ch.model[i],
                ch.mean[i],
                ch.lower[i],
                ch.upper[i],
                ch.measured[i] - ch.mean[i],
                ch.discrepancy_mean[i],
                ch.discrepancy_lower[i],
                ch.discrepancy_upper[i]
            ));
        }
    }
    crate::io::write_atomically(path, text.as_bytes())?;
    Ok(())
}

fn plot_error(e: plot::PlotError) -> AppError {
    AppError::Output(e.to_string())
}

/// The data with the fit and its band, and the residuals.
pub fn plot_predictive(path: &Path, title: &str, p: &Predictive) -> Result<(), AppError> {
    let plot = PredictivePlot {
        title: title.into(),
        times: p.times.clone(),
        channels: p
            .channels
            .iter()
            .map(|c| ChannelPrediction {
                name: c.name.clone(),
                unit: c.unit.clone(),
                measured: c.measured.clone(),
                model: c.model.clone(),
                mean: c.mean.clone(),
                lower: c.lower.clone(),
                upper: c.upper.clone(),
                sigma: c.sigma,
            })
            .collect(),
    };
    plot::posterior_predictive(path, &plot).map_err(plot_error)
}

/// δ with its band, and the reference discrepancy where it is known (Figures 13/16).
pub fn plot_discrepancy(
    path: &Path,
    title: &str,
    p: &Predictive,
    reference: Option<&[Vec<f64>]>,
) -> Result<(), AppError> {
    let bands: Vec<DiscrepancyBand> = p
        .channels
        .iter()
        .enumerate()
        .map(|(c, ch)| DiscrepancyBand {
            name: ch.name.clone(),
            unit: ch.unit.clone(),
            mean: ch.discrepancy_mean.clone(),
            lower: ch.discrepancy_lower.clone(),
            upper: ch.discrepancy_upper.clone(),
            reference: reference.map(|r| r[c].clone()),
        })
        .collect();
    plot::discrepancy_band(path, title, &p.times, &bands).map_err(plot_error)
}

/// Trace plots of the named quantities (Figures 6/12/15), with reference values where known.
pub fn plot_traces(
    path: &Path,
    title: &str,
    chains: &[ChainOutput],
    names: &[(&str, Option<f64>)],
) -> Result<(), AppError> {
    let Some(first) = chains.first() else {
        return Err(AppError::Numerical("no chains".into()));
    };
    let series: Vec<TraceSeries> = names
        .iter()
        .filter_map(|(name, reference)| {
            let j = first.names.iter().position(|n| n == name)?;
            Some(TraceSeries {
                name: name.to_string(),
                chains: chains.iter().map(|c| c.column(j)).collect(),
                reference: *reference,
            })
        })
        .collect();
    plot::traces(path, title, &series).map_err(plot_error)
}
