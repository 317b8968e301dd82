//! A sampling-based check of the Laplace approximation for the leading candidates: the log
//! evidence (default priors) by importance sampling ([`crate::evidence`]). Where the estimate
//! and the Laplace value differ, the difference is the Gaussian approximation's error, and the
//! candidate's score is corrected by it: the score's Occam term assumes the same Gaussian shape.

use crate::error::Error;
use crate::evidence::importance_sampling;
use crate::optimize::{MapSettings, find_map};

use super::candidate::{Candidate, Confirmation};

/// Draws of the importance sampler: enough for a standard error of a few hundredths of a nat
/// when the proposal is close, which is when the correction is small.
pub const DRAWS: usize = 2000;

/// The candidate's log evidence by importance sampling around its MAP, polished once more
/// from where the ranking left it.
pub fn importance_evidence(fit: &Candidate, seed: u64) -> Result<Confirmation, Error> {
    let mut posterior = fit.posterior.clone();
    let map = find_map(&mut posterior, &fit.map.x, &MapSettings::ranking())?;
    importance_sampling(&mut posterior, &map, DRAWS, seed).map_err(Error::Numerical)
}
