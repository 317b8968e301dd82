//! Figures of the tool, one function each, rendered to PNG with plotters' bitmap backend.
//!
//! Every function takes plain data, validates it (empty or inconsistent input is a
//! [`PlotError`] and no file is touched), renders into a temporary file next to the
//! target and renames it into place, so a failed plot never leaves a half-written file.
//!
//! Text is rendered with an embedded copy of DejaVu Sans (`assets/DejaVuSans.ttf`, see
//! `assets/DejaVuSans-LICENSE.txt`), registered once, thread-safely, as `"sans-serif"`.
//!
//! Robustness: non-finite values are skipped, a zero-width data range is padded, and on a
//! logarithmic axis non-positive values are skipped.

mod coefficients;
mod design;
mod discrepancy;
mod ess;
mod frame;
mod k_study;
mod missing_torque;
mod predictive;
#[cfg(test)]
mod tests;
mod traces;
mod unexplained;

use std::fmt;

use plotters::prelude::DrawingAreaErrorKind;

pub use coefficients::{CoefficientMarginals, coefficient_marginals};
pub use design::{DesignChannel, DesignPlot, design_figure};
pub use discrepancy::{DiscrepancyBand, discrepancy_band};
pub use ess::{SamplerCurve, ess_per_second};
pub use k_study::{KSeries, k_study};
pub use missing_torque::{MissingTorqueCurve, MissingTorquePlot, missing_torque};
pub use predictive::{ChannelPrediction, PredictivePlot, posterior_predictive};
pub use traces::{TraceSeries, traces};
pub use unexplained::{UnexplainedPlot, UnexplainedRow, unexplained};

/// Error of a plotting function: a human-readable message.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PlotError {
    message: String,
}

impl PlotError {
    /// A new error with the given message.
    pub fn new(message: impl Into<String>) -> Self {
        Self {
            message: message.into(),
        }
    }

    /// The message of the error.
    pub fn message(&self) -> &str {
        &self.message
    }
}

impl fmt::Display for PlotError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "plot error: {}", self.message)
    }
}

impl std::error::Error for PlotError {}

impl<E: std::error::Error + Send + Sync> From<DrawingAreaErrorKind<E>> for PlotError {
    fn from(e: DrawingAreaErrorKind<E>) -> Self {
        Self::new(format!("drawing failed: {e}"))
    }
}
