//! A sampling-based check of the Laplace approximation for the leading candidates: the log
//! evidence (default priors) by importance sampling, with a multivariate Student-t proposal
//! centred at the MAP with the Laplace covariance (heavy tails, so that the weights stay bounded
//! where the posterior is skewed or piled against a bound). Where the estimate and the Laplace
//! value differ, the difference is the Gaussian approximation's error, and the candidate's score
//! is corrected by it: the score's Occam term assumes the same Gaussian shape.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{ChiSquared, Distribution, StandardNormal};

use crate::app::AppError;
use crate::app::problem::Problem;
use crate::bayes::ModelSettings;
use crate::density::LogDensity;
use crate::optimize::{MapSettings, find_map};
use statrs::function::gamma::ln_gamma;

use super::candidates::{CandidateFit, problem_with};

/// Draws of the importance sampler: enough for a standard error of a few hundredths of a nat
/// when the proposal is close, which is when the correction is small.
pub const DRAWS: usize = 2000;

/// Degrees of freedom of the proposal's Student-t.
const NU: f64 = 5.0;

/// The importance-sampling estimate of the log evidence and its Monte Carlo standard error.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct Confirmation {
    pub log_evidence: f64,
    pub standard_error: f64,
    pub log_evidence_laplace: f64,
    /// Effective sample size of the weights (Kish).
    pub effective_draws: f64,
}

pub fn importance_evidence(
    base: &Problem,
    fit: &CandidateFit,
    seed: u64,
) -> Result<Confirmation, AppError> {
    let problem = problem_with(base, &fit.added)?;
    let mut posterior = problem.posterior(&ModelSettings::bm1())?;
    let map = find_map(&mut posterior, &fit.x, &MapSettings::default())?;
    let d = map.x.len();
    // x = x̂ + L⁻ᵀ z √(ν/χ²): Student-t with scale matrix H⁻¹.
    let (l_inv_t, log_det_h) = map.whitening().map_err(AppError::Numerical)?;
    let log_t_norm = ln_gamma((NU + d as f64) / 2.0)
        - ln_gamma(NU / 2.0)
        - 0.5 * d as f64 * (NU * std::f64::consts::PI).ln()
        + 0.5 * log_det_h;
    let chi = ChiSquared::new(NU).expect("ν > 0");
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut log_weights = Vec::with_capacity(DRAWS);
    for _ in 0..DRAWS {
        let z: Vec<f64> = (0..d).map(|_| StandardNormal.sample(&mut rng)).collect();
        let scale = (NU / chi.sample(&mut rng)).sqrt();
        let z = nalgebra::DVector::from_vec(z);
        let dx = &l_inv_t * &z * scale;
        let x: Vec<f64> = map.x.iter().zip(dx.iter()).map(|(a, b)| a + b).collect();
        // (x − x̂)ᵀ H (x − x̂) = |z|² · scale².
        let q = z.norm_squared() * scale * scale;
        let log_q = log_t_norm - 0.5 * (NU + d as f64) * (1.0 + q / NU).ln();
        let log_p = match posterior.log_density(&x) {
            Ok(v) if v.is_finite() => v,
            _ => f64::NEG_INFINITY,
        };
        log_weights.push(log_p - log_q);
    }
    let max = log_weights
        .iter()
        .copied()
        .fold(f64::NEG_INFINITY, f64::max);
    let w: Vec<f64> = log_weights.iter().map(|l| (l - max).exp()).collect();
    let n = w.len() as f64;
    let mean = w.iter().sum::<f64>() / n;
    let var = w.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    let sum_sq: f64 = w.iter().map(|v| v * v).sum();
    Ok(Confirmation {
        log_evidence: max + mean.ln(),
        // Delta method: sd of the mean over the mean.
        standard_error: (var / n).sqrt() / mean,
        log_evidence_laplace: map.log_evidence_laplace,
        effective_draws: w.iter().sum::<f64>().powi(2) / sum_sq,
    })
}
