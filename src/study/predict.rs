//! A model file run on records it was not fitted to, at the file's values, with the residual
//! RMS per record and channel: the estimation → validation cross-test.

use serde::Serialize;

use crate::error::Error;
use crate::ode::SolverSettings;

use super::Problem;

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
pub fn predict_records(problem: &Problem) -> Result<Vec<RecordPrediction>, Error> {
    let forwards = problem.forward_models(SolverSettings::default())?;
    let mut out = Vec::new();
    for (forward, recording) in forwards.iter().zip(&problem.recordings) {
        let mut values = vec![0.0; forward.n_outputs()];
        forward
            .simulate(&forward.nominal_calibrated(), &mut values)
            .map_err(|e| Error::Numerical(format!("{}: {e}", recording.source)))?;
        let m = forward.n_samples();
        let channels = forward
            .channels()
            .iter()
            .enumerate()
            .map(|(c, name)| {
                let measured = recording.channel(name).ok_or_else(|| {
                    Error::invalid(format!("{}: no channel '{name}'", recording.source))
                })?;
                Ok((
                    name.to_string(),
                    measured.to_vec(),
                    values[c * m..(c + 1) * m].to_vec(),
                ))
            })
            .collect::<Result<Vec<_>, Error>>()?;
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
