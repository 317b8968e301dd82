//! A sampling-based check of the Laplace approximation for the leading candidates: the log
//! evidence (default priors) by importance sampling ([`crate::evidence`]). Where the estimate
//! and the Laplace value differ, the difference is the Gaussian approximation's error, and the
//! candidate's score is corrected by it: the score's Occam term assumes the same Gaussian shape.

use crate::app::AppError;
use crate::app::problem::Problem;
use crate::bayes::ModelSettings;
use crate::evidence::{Evidence, importance_sampling};
use crate::optimize::{MapSettings, find_map};

use super::candidates::{CandidateFit, problem_with};

/// Draws of the importance sampler: enough for a standard error of a few hundredths of a nat
/// when the proposal is close, which is when the correction is small.
pub const DRAWS: usize = 2000;

pub type Confirmation = Evidence;

pub fn importance_evidence(
    base: &Problem,
    fit: &CandidateFit,
    seed: u64,
) -> Result<Confirmation, AppError> {
    let problem = problem_with(base, &fit.added)?;
    let mut posterior = problem.posterior(&ModelSettings::bm1())?;
    let map = find_map(&mut posterior, &fit.x, &MapSettings::default())?;
    importance_sampling(&mut posterior, &map, DRAWS, seed).map_err(AppError::Numerical)
}
