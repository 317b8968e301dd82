//! The Laplace approximation as a proposal: a multivariate Student-t (or, with infinite degrees
//! of freedom, the Gaussian) centred at the MAP with the inverse MAP Hessian as its scale
//! matrix, widened by a factor. The independence sampler proposes from it, importance sampling
//! weighs its draws, and `discover` draws from its Gaussian form on long records.
//!
//! A draw is x = x̂ + s·L⁻ᵀz·√(ν/u) with H = LLᵀ, z ~ N(0, I) and u ~ χ²_ν (u = ν when ν = ∞).

use nalgebra::{DMatrix, DVector};
use rand_distr::{ChiSquared, Distribution, StandardNormal};

use super::ChainRng;
use crate::parameter::ln_gamma;

/// A Student-t (or Gaussian) proposal at the MAP with the Laplace scale matrix.
#[derive(Clone, Debug)]
pub struct LaplaceProposal {
    mean: DVector<f64>,
    /// L⁻ᵀ: x̂ + L⁻ᵀz is a draw of N(x̂, H⁻¹).
    l_inv_t: DMatrix<f64>,
    /// Lᵀ: whitens a displacement, Lᵀ(x − x̂) ~ N(0, I) under the Gaussian.
    l_t: DMatrix<f64>,
    /// ½ log det H.
    half_log_det: f64,
    df: f64,
    scale: f64,
}

impl LaplaceProposal {
    /// The Gaussian N(mean, precision⁻¹); widen it or give it tails with
    /// [`with_shape`](Self::with_shape).
    pub fn new(mean: &[f64], precision: &DMatrix<f64>) -> Result<Self, String> {
        let d = mean.len();
        if precision.nrows() != d || precision.ncols() != d {
            return Err(format!(
                "a {}×{} precision for a mean of dimension {d}",
                precision.nrows(),
                precision.ncols()
            ));
        }
        let chol = precision
            .clone()
            .cholesky()
            .ok_or("the Hessian at the MAP is not positive definite")?;
        let l_t = chol.l().transpose();
        // The inverse as `MapEstimate::whitening` computes it, so that the Gaussian's draws are
        // the ones `discover` has always made.
        let l_inv_t = l_t.clone().try_inverse().ok_or("singular Hessian")?;
        let half_log_det = chol.l().diagonal().iter().map(|v| v.ln()).sum::<f64>();
        Ok(Self {
            mean: DVector::from_column_slice(mean),
            l_inv_t,
            l_t,
            half_log_det,
            df: f64::INFINITY,
            scale: 1.0,
        })
    }

    /// Degrees of freedom ν (> 0; ∞ for the Gaussian) and scale factor s (> 0).
    pub fn with_shape(mut self, df: f64, scale: f64) -> Result<Self, String> {
        self.set_shape(df, scale)?;
        Ok(self)
    }

    pub fn set_shape(&mut self, df: f64, scale: f64) -> Result<(), String> {
        if !(df > 0.0) {
            return Err(format!("degrees of freedom must be positive, got {df}"));
        }
        if !(scale > 0.0 && scale.is_finite()) {
            return Err(format!("a scale must be positive and finite, got {scale}"));
        }
        self.df = df;
        self.scale = scale;
        Ok(())
    }

    pub fn dim(&self) -> usize {
        self.mean.len()
    }

    pub fn df(&self) -> f64 {
        self.df
    }

    pub fn scale(&self) -> f64 {
        self.scale
    }

    /// The centre (the MAP, or where recentring moved it).
    pub fn mean(&self) -> &[f64] {
        self.mean.as_slice()
    }

    /// The same scale matrix and shape centred at `mean`.
    pub fn recentred(&self, mean: &[f64]) -> Self {
        Self {
            mean: DVector::from_column_slice(mean),
            ..self.clone()
        }
    }

    /// Lᵀ(x − centre): the point in the coordinates where the Laplace scale matrix is the
    /// identity.
    pub fn whiten(&self, x: &[f64]) -> DVector<f64> {
        let r = DVector::from_iterator(
            self.dim(),
            x.iter().zip(self.mean.iter()).map(|(a, m)| a - m),
        );
        &self.l_t * r
    }

    /// centre + L⁻ᵀz: the inverse of [`whiten`](Self::whiten).
    pub fn unwhiten(&self, z: &DVector<f64>) -> Vec<f64> {
        (&self.mean + &self.l_inv_t * z).iter().copied().collect()
    }

    /// One draw.
    pub fn draw(&self, rng: &mut ChainRng) -> Vec<f64> {
        let d = self.dim();
        let z: Vec<f64> = (0..d).map(|_| StandardNormal.sample(rng)).collect();
        let mut dx = &self.l_inv_t * DVector::from_column_slice(&z);
        let mut factor = self.scale;
        if self.df.is_finite() {
            let u: f64 = ChiSquared::new(self.df)
                .expect("positive degrees of freedom")
                .sample(rng);
            factor *= (self.df / u).sqrt();
        }
        if factor != 1.0 {
            dx *= factor;
        }
        self.mean
            .iter()
            .zip(dx.iter())
            .map(|(a, b)| a + b)
            .collect()
    }

    /// The normalised log density at `x`.
    pub fn log_density(&self, x: &[f64]) -> f64 {
        let d = self.dim() as f64;
        let q = self.whiten(x).norm_squared() / (self.scale * self.scale);
        let log_jacobian = self.half_log_det - d * self.scale.ln();
        if self.df.is_finite() {
            let nu = self.df;
            ln_gamma(0.5 * (nu + d))
                - ln_gamma(0.5 * nu)
                - 0.5 * d * (nu * std::f64::consts::PI).ln()
                + log_jacobian
                - 0.5 * (nu + d) * (q / nu).ln_1p()
        } else {
            -0.5 * d * (2.0 * std::f64::consts::PI).ln() + log_jacobian - 0.5 * q
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::driver::chain_rng;

    fn precision() -> DMatrix<f64> {
        DMatrix::from_row_slice(2, 2, &[4.0, 1.0, 1.0, 2.0])
    }

    #[test]
    fn the_density_integrates_to_one_and_the_draws_have_its_covariance() {
        // Riemann sum over a grid wide enough for ν = 5 with s = 1.3 to leave < 1e-3 outside.
        for (df, scale) in [(f64::INFINITY, 1.0), (5.0, 1.3)] {
            let p = LaplaceProposal::new(&[0.5, -1.0], &precision())
                .unwrap()
                .with_shape(df, scale)
                .unwrap();
            let h = 0.02;
            let mut total = 0.0;
            for i in -1000..1000 {
                for j in -1000..1000 {
                    let x = [0.5 + i as f64 * h, -1.0 + j as f64 * h];
                    total += p.log_density(&x).exp() * h * h;
                }
            }
            assert!((total - 1.0).abs() < 2e-3, "ν = {df}: ∫q = {total}");
            // Covariance s² ν/(ν − 2) H⁻¹ (s² H⁻¹ for the Gaussian).
            let factor = scale * scale * if df.is_finite() { df / (df - 2.0) } else { 1.0 };
            let cov = precision().try_inverse().unwrap() * factor;
            let mut rng = chain_rng(7, 0);
            let n = 200_000;
            let mut m2 = DMatrix::<f64>::zeros(2, 2);
            for _ in 0..n {
                let x = p.draw(&mut rng);
                let r = DVector::from_vec(vec![x[0] - 0.5, x[1] + 1.0]);
                m2 += &r * r.transpose() / n as f64;
            }
            for k in 0..4 {
                let rel = (m2[k] - cov[k]).abs() / cov[(k % 2, k % 2)];
                assert!(rel < 0.03, "ν = {df}: covariance {m2} vs {cov}");
            }
        }
    }

    #[test]
    fn invalid_shapes_are_refused() {
        let p = LaplaceProposal::new(&[0.0, 0.0], &precision()).unwrap();
        assert!(p.clone().with_shape(0.0, 1.0).is_err());
        assert!(p.clone().with_shape(3.0, -1.0).is_err());
        assert!(LaplaceProposal::new(&[0.0], &precision()).is_err());
        assert!(LaplaceProposal::new(&[0.0, 0.0], &(-precision())).is_err());
    }
}
