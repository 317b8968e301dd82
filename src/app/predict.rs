//! `motorcal predict`: a calibrated model (the `model.toml` that `diagnose --out` writes, or any
//! model file) run on records it was not fitted to, at the file's values, with the residual RMS
//! per record and channel: the estimation → validation cross-test.

use std::path::PathBuf;

use serde::Serialize;

use crate::io::write_atomically;
use crate::ode::SolverSettings;

use super::AppError;
use super::problem::Problem;

#[derive(Clone, Debug)]
pub struct PredictOptions {
    pub data: Vec<PathBuf>,
    pub model: PathBuf,
    /// Per-sample CSV (t, measured, predicted, residual per channel), one file per record.
    pub csv: Option<PathBuf>,
    pub json: Option<PathBuf>,
}

/// One record's channel: how far the model's prediction is from what was measured.
#[derive(Clone, Debug, Serialize)]
pub struct ChannelResidual {
    pub record: String,
    pub channel: String,
    pub unit: String,
    pub samples: usize,
    pub residual_rms: f64,
    /// RMS of the measured channel, so that the residual reads as a share of it.
    pub measured_rms: f64,
    pub relative: f64,
}

/// What the model predicts for one record.
#[derive(Clone, Debug)]
pub struct RecordPrediction {
    pub source: String,
    pub times: Vec<f64>,
    pub channels: Vec<(String, Vec<f64>, Vec<f64>)>,
}

/// Simulates every record at the model file's values.
pub fn predict_records(problem: &Problem) -> Result<Vec<RecordPrediction>, AppError> {
    let forwards = problem.forward_models(SolverSettings::default())?;
    let mut out = Vec::new();
    for (forward, recording) in forwards.iter().zip(&problem.recordings) {
        let mut values = vec![0.0; forward.n_outputs()];
        forward
            .simulate(&forward.nominal_calibrated(), &mut values)
            .map_err(|e| AppError::Numerical(format!("{}: {e}", recording.source)))?;
        let m = forward.n_samples();
        let channels = forward
            .channels()
            .iter()
            .enumerate()
            .map(|(c, name)| {
                let measured = recording.channel(name).ok_or_else(|| {
                    AppError::Usage(format!("{}: no channel '{name}'", recording.source))
                })?;
                Ok((
                    name.to_string(),
                    measured.to_vec(),
                    values[c * m..(c + 1) * m].to_vec(),
                ))
            })
            .collect::<Result<Vec<_>, AppError>>()?;
        out.push(RecordPrediction {
            source: recording.source.clone(),
            times: recording.time.clone(),
            channels,
        });
    }
    Ok(out)
}

fn rms(values: impl Iterator<Item = f64>) -> f64 {
    let (sum, n) = values.fold((0.0, 0usize), |(s, n), v| (s + v * v, n + 1));
    (sum / n.max(1) as f64).sqrt()
}

/// The residual RMS per record and channel.
pub fn residuals(problem: &Problem, predictions: &[RecordPrediction]) -> Vec<ChannelResidual> {
    predictions
        .iter()
        .flat_map(|p| {
            p.channels.iter().map(move |(name, measured, predicted)| {
                let residual_rms = rms(measured.iter().zip(predicted).map(|(y, g)| y - g));
                let measured_rms = rms(measured.iter().copied());
                ChannelResidual {
                    record: p.source.clone(),
                    channel: name.clone(),
                    unit: problem.model.base.channel_unit(name).to_string(),
                    samples: measured.len(),
                    residual_rms,
                    measured_rms,
                    relative: residual_rms / measured_rms,
                }
            })
        })
        .collect()
}

/// The whole command: read, simulate, report; writes nothing if anything fails before.
pub fn predict(options: &PredictOptions) -> Result<Vec<ChannelResidual>, AppError> {
    let problem = Problem::from_files(&options.data, &options.model)?;
    let predictions = predict_records(&problem)?;
    let table = residuals(&problem, &predictions);
    if let Some(path) = &options.csv {
        let mut text = String::new();
        for (r, p) in predictions.iter().enumerate() {
            if r == 0 {
                text.push_str("record,t");
                for (name, _, _) in &p.channels {
                    text.push_str(&format!(
                        ",{name}_measured,{name}_predicted,{name}_residual"
                    ));
                }
                text.push('\n');
            }
            for (i, t) in p.times.iter().enumerate() {
                text.push_str(&format!("{r},{t}"));
                for (_, measured, predicted) in &p.channels {
                    let (y, g) = (measured[i], predicted[i]);
                    text.push_str(&format!(",{y},{g},{}", y - g));
                }
                text.push('\n');
            }
        }
        write_atomically(path, text.as_bytes())?;
    }
    if let Some(path) = &options.json {
        let json =
            serde_json::to_string_pretty(&table).map_err(|e| AppError::Output(e.to_string()))?;
        write_atomically(path, json.as_bytes())?;
    }
    Ok(table)
}

/// The table a person reads.
pub fn format_residuals(table: &[ChannelResidual]) -> String {
    let mut out = format!(
        "{:<48} {:>8} {:>10} {:>14} {:>14} {:>9}\n",
        "record", "channel", "samples", "residual RMS", "measured RMS", "relative"
    );
    for r in table {
        out.push_str(&format!(
            "{:<48} {:>8} {:>10} {:>14} {:>14} {:>8.2}%\n",
            r.record,
            r.channel,
            r.samples,
            format!("{:.4e} {}", r.residual_rms, r.unit),
            format!("{:.4e} {}", r.measured_rms, r.unit),
            100.0 * r.relative
        ));
    }
    out
}
