//! The Bayesian models of §3: priors, discrepancy bases, and the posterior as a log density.

pub mod basis;
mod posterior;
mod prior;
mod settings;

pub use basis::{DiscrepancyBasis, Legendre};
pub use posterior::{CalibrationPosterior, Observations};
pub use prior::{Prior, ln_gamma};
pub use settings::{CoefficientFamily, CoefficientPrior, ModelSettings, SpreadReading};
