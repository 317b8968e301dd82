//! The posterior given θ: y = G(θ) + B·a + ε is Gaussian and linear in the discrepancy's
//! coefficients a, so with G(θ) solved once, each channel's least-squares coefficients and the
//! residual they leave are a few small matrix products. `collapsed-is` draws σ and a from the
//! conditionals these describe, so that only θ is proposed from the Laplace approximation.

use nalgebra::DVector;

use super::CalibrationPosterior;
use crate::density::{Conditionals, DensityError, LinearBlock, LinearCoefficients};

impl CalibrationPosterior {
    /// Every channel's block at the θ in the leading coordinates of `x` (the rest is not read).
    pub(super) fn conditionals_at(&mut self, x: &[f64]) -> Result<Conditionals, DensityError> {
        let leading = self.n_theta();
        if x.len() < leading {
            return Err(DensityError::fatal(format!(
                "a point of dimension {} for θ of dimension {leading}",
                x.len()
            )));
        }
        if self.theta_priors(x).is_none() {
            return Err(DensityError::recoverable("θ outside the prior's support"));
        }
        let theta = &self.theta_x;
        let mut blocks = Vec::new();
        for term in &mut self.records {
            term.ensure_forward(theta, false)?;
            let m = term.forward.n_samples();
            for (c, ch) in term.channels.iter().enumerate() {
                let g = &term.current.outputs[c * m..(c + 1) * m];
                let r = DVector::from_iterator(m, ch.observed.iter().zip(g).map(|(y, g)| y - g));
                let mut residual_ss = r.norm_squared();
                let coefficients = match &ch.discrepancy {
                    None => None,
                    Some(d) => {
                        let l = d.gram_factor.as_ref().ok_or_else(|| {
                            DensityError::fatal("the discrepancy basis is rank deficient")
                        })?;
                        let projected = d.basis.tr_mul(&r);
                        let least_squares = l
                            .solve_lower_triangular(&projected)
                            .and_then(|w| l.tr_solve_lower_triangular(&w))
                            .ok_or_else(|| DensityError::fatal("singular Gram factor"))?;
                        // ‖r − Bâ‖² = ‖r‖² − âᵀBᵀr, since Bᵀ(r − Bâ) = 0.
                        residual_ss -= least_squares.dot(&projected);
                        let prior_slope = DVector::from_iterator(
                            least_squares.len(),
                            d.priors
                                .iter()
                                .zip(least_squares.iter())
                                .map(|(p, &a)| p.gradient(a)),
                        );
                        Some(LinearCoefficients {
                            offset: d.offset,
                            least_squares,
                            gram_factor: l.clone(),
                            prior_slope,
                        })
                    }
                };
                blocks.push(LinearBlock {
                    log_sigma: ch.log_sigma_index,
                    observations: m,
                    residual_ss: residual_ss.max(0.0),
                    coefficients,
                });
            }
        }
        Ok(Conditionals { leading, blocks })
    }
}
