//! The Bayesian models of §3: priors, discrepancy bases, and the posterior as a log density.

pub mod basis;
pub mod bspline;
mod calibrated;
mod posterior;
mod settings;

pub use crate::parameter::{Prior, ln_gamma};
pub use basis::{DiscrepancyBasis, Legendre};
pub use bspline::BSpline;
pub use calibrated::{CalibratedParameter, PriorInU};
pub use posterior::{CalibrationPosterior, Observations};
pub use settings::{BasisKind, CoefficientFamily, CoefficientPrior, ModelSettings, SpreadReading};
