//! `motorcal predict`: a calibrated model (the `model.toml` that `diagnose --out` writes, or any
//! model file) run on records it was not fitted to, at the file's values, with the residual RMS
//! per record and channel: the estimation → validation cross-test.

use std::path::PathBuf;

use crate::io::write_atomically;

use super::AppError;
use crate::study::{ChannelResidual, Problem, predict_records, residuals};

// The command's options, as the command line and the tests give them.
#[derive(clap::Args, Clone, Debug)]
pub struct PredictOptions {
    /// The model (e.g. the model.toml that `diagnose --out` writes).
    #[arg(long)]
    pub model: PathBuf,
    /// A recording; repeat for several.
    #[arg(long, required = true)]
    pub data: Vec<PathBuf>,
    /// Write measured, predicted and residual per sample as CSV.
    #[arg(long)]
    pub csv: Option<PathBuf>,
    /// Write the residual table as JSON.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Go on when a recording cannot be this motor as set up.
    #[arg(long)]
    pub force: bool,
}

/// `motorcal predict`: the residual table.
pub fn run(options: &PredictOptions) -> Result<(), AppError> {
    let table = predict(options)?;
    print!("{}", format_residuals(&table));
    Ok(())
}

/// The whole command: read, simulate, report; writes nothing if anything fails before.
pub fn predict(options: &PredictOptions) -> Result<Vec<ChannelResidual>, AppError> {
    let problem = Problem::from_files(&options.data, &options.model)?;
    super::plausible(&problem, options.force)?;
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
