//! The posterior given θ: y = G(θ) + B·a + ε is Gaussian and linear in the discrepancy's
//! coefficients a, so with G(θ) solved once, each channel's least-squares coefficients and the
//! residual they leave are a few small matrix products. `collapsed-is` draws σ and a from the
//! conditionals these describe, so that only θ is proposed from the Laplace approximation.

use nalgebra::DVector;

use super::CalibrationPosterior;
use crate::density::{Conditionals, DensityError, LinearBlock};

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
                let basis = match &ch.discrepancy {
                    None => None,
                    Some(d) => {
                        let l = d.gram_factor.as_ref().ok_or_else(|| {
                            DensityError::fatal("the discrepancy basis is rank deficient")
                        })?;
                        Some((d.offset, &d.basis, l))
                    }
                };
                let priors = ch.discrepancy.as_ref().map(|d| &d.priors);
                let block = LinearBlock::least_squares(ch.log_sigma_index, &r, basis, |j, a| {
                    priors.map_or(0.0, |p| p[j].gradient(a))
                })
                .ok_or_else(|| DensityError::fatal("singular Gram factor"))?;
                blocks.push(block);
            }
        }
        Ok(Conditionals { leading, blocks })
    }
}
