//! Targets with known moments, on which every sampler is tested.

use nalgebra::{DMatrix, DVector};

use crate::density::{DensityError, FisherMetric, LogDensity};

/// N(mean, covariance) in any dimension.
#[derive(Clone, Debug)]
pub struct Gaussian {
    pub mean: DVector<f64>,
    pub covariance: DMatrix<f64>,
    precision: DMatrix<f64>,
    log_normaliser: f64,
}

impl Gaussian {
    pub fn new(mean: Vec<f64>, covariance: DMatrix<f64>) -> Self {
        let d = mean.len();
        let chol = covariance
            .clone()
            .cholesky()
            .expect("covariance must be positive definite");
        let log_det: f64 = 2.0 * chol.l().diagonal().iter().map(|v| v.ln()).sum::<f64>();
        let precision = chol.inverse();
        Self {
            mean: DVector::from_vec(mean),
            covariance,
            precision,
            log_normaliser: -0.5 * (d as f64 * (2.0 * std::f64::consts::PI).ln() + log_det),
        }
    }

    /// A correlated Gaussian with standard deviations spanning `scale_ratio` and correlation
    /// `rho` between neighbours (an AR(1) correlation matrix): a small stand-in for the motor
    /// posterior's bad conditioning.
    pub fn correlated(d: usize, rho: f64, scale_ratio: f64) -> Self {
        let sd: Vec<f64> = (0..d)
            .map(|i| {
                if d == 1 {
                    1.0
                } else {
                    scale_ratio.powf(i as f64 / (d - 1) as f64)
                }
            })
            .collect();
        let cov = DMatrix::from_fn(d, d, |i, j| {
            sd[i] * sd[j] * rho.powi((i as i32 - j as i32).abs())
        });
        let mean = (0..d).map(|i| i as f64 - 0.5 * d as f64).collect();
        Self::new(mean, cov)
    }

    pub fn variances(&self) -> Vec<f64> {
        self.covariance.diagonal().iter().copied().collect()
    }
}

impl LogDensity for Gaussian {
    fn dim(&self) -> usize {
        self.mean.len()
    }

    fn parameter_names(&self) -> Vec<String> {
        (0..self.dim()).map(|i| format!("x.{}", i + 1)).collect()
    }

    fn log_density(&mut self, x: &[f64]) -> Result<f64, DensityError> {
        let r = DVector::from_column_slice(x) - &self.mean;
        Ok(self.log_normaliser - 0.5 * r.dot(&(&self.precision * &r)))
    }

    fn log_density_and_gradient(
        &mut self,
        x: &[f64],
        grad: &mut [f64],
    ) -> Result<f64, DensityError> {
        let r = DVector::from_column_slice(x) - &self.mean;
        let pr = &self.precision * &r;
        for (g, v) in grad.iter_mut().zip(pr.iter()) {
            *g = -v;
        }
        Ok(self.log_normaliser - 0.5 * r.dot(&pr))
    }
}

impl FisherMetric for Gaussian {
    fn fisher_metric(&mut self, _x: &[f64], metric: &mut DMatrix<f64>) -> Result<(), DensityError> {
        metric.copy_from(&self.precision);
        Ok(())
    }
}

/// Checks draws against a Gaussian's known moments: every mean within `k` Monte Carlo standard
/// errors, and every variance within `k` MCSE of the variance estimate (the MCSE of the mean of
/// the squared deviations, which accounts for autocorrelation). Returns the worst z-scores, or
/// the first violation.
pub fn check_gaussian_moments(
    chains: &[crate::sampler::ChainOutput],
    target: &Gaussian,
    k: f64,
) -> Result<(f64, f64), String> {
    use crate::diagnostics::mcse_mean;
    let d = target.mean.len();
    let variances = target.variances();
    let (mut worst_mean, mut worst_var) = (0.0f64, 0.0f64);
    for j in 0..d {
        let columns: Vec<Vec<f64>> = chains.iter().map(|c| c.column(j)).collect();
        let n: usize = columns.iter().map(|c| c.len()).sum();
        let mean = columns.iter().flatten().sum::<f64>() / n as f64;
        let z_mean = (mean - target.mean[j]) / mcse_mean(&columns);
        let squares: Vec<Vec<f64>> = columns
            .iter()
            .map(|c| c.iter().map(|v| (v - target.mean[j]).powi(2)).collect())
            .collect();
        let var = squares.iter().flatten().sum::<f64>() / n as f64;
        let z_var = (var - variances[j]) / mcse_mean(&squares);
        worst_mean = worst_mean.max(z_mean.abs());
        worst_var = worst_var.max(z_var.abs());
        if !(z_mean.abs() <= k) {
            return Err(format!(
                "mean of x.{} = {mean} vs {} ({z_mean:.2} MCSE)",
                j + 1,
                target.mean[j]
            ));
        }
        if !(z_var.abs() <= k) {
            return Err(format!(
                "variance of x.{} = {var} vs {} ({z_var:.2} MCSE)",
                j + 1,
                variances[j]
            ));
        }
    }
    Ok((worst_mean, worst_var))
}

/// A banana (Haario et al. 1999, twisted Gaussian): x₁ ~ N(0, 1), x₂ | x₁ ~ N(b(x₁² − 1), s²).
/// Its mode is (0, −b) with Hessian diag(1, 1/s²), so the Laplace approximation there has
/// var x₂ = s² where the target's is s² + 2b²: a poor approximation that importance sampling's
/// k̂ must flag. Known moments: E x = (0, 0), var x₁ = 1.
#[derive(Clone, Debug)]
pub struct Banana {
    pub bend: f64,
    pub width: f64,
}

impl Banana {
    /// The two residuals r = (x₁, (x₂ − b(x₁² − 1))/s), log π = −½|r|² (up to a constant),
    /// and their Jacobian.
    fn residuals(&self, x: &[f64]) -> ([f64; 2], [[f64; 2]; 2]) {
        let r2 = (x[1] - self.bend * (x[0] * x[0] - 1.0)) / self.width;
        let j = [
            [1.0, 0.0],
            [-2.0 * self.bend * x[0] / self.width, 1.0 / self.width],
        ];
        ([x[0], r2], j)
    }
}

impl LogDensity for Banana {
    fn dim(&self) -> usize {
        2
    }

    fn parameter_names(&self) -> Vec<String> {
        vec!["x.1".into(), "x.2".into()]
    }

    fn log_density(&mut self, x: &[f64]) -> Result<f64, DensityError> {
        let (r, _) = self.residuals(x);
        Ok(-0.5 * (r[0] * r[0] + r[1] * r[1]))
    }

    fn log_density_and_gradient(
        &mut self,
        x: &[f64],
        grad: &mut [f64],
    ) -> Result<f64, DensityError> {
        let (r, j) = self.residuals(x);
        for (k, g) in grad.iter_mut().enumerate() {
            *g = -(r[0] * j[0][k] + r[1] * j[1][k]);
        }
        Ok(-0.5 * (r[0] * r[0] + r[1] * r[1]))
    }
}

/// Gauss–Newton: JᵀJ of the residuals, the exact Hessian at the mode.
impl FisherMetric for Banana {
    fn fisher_metric(&mut self, x: &[f64], metric: &mut DMatrix<f64>) -> Result<(), DensityError> {
        let (_, j) = self.residuals(x);
        for a in 0..2 {
            for b in 0..2 {
                metric[(a, b)] = j[0][a] * j[0][b] + j[1][a] * j[1][b];
            }
        }
        Ok(())
    }
}

impl crate::density::StartingPoint for Banana {
    fn initial_point(&mut self) -> Result<Vec<f64>, DensityError> {
        Ok(vec![0.3, 0.0])
    }
}

/// Bayesian linear regression y = θ·g + B·a + ε, ε ~ N(0, σ²I), with flat priors on θ, a and σ,
/// in the coordinates (θ, log σ, a): θ stands for a physical parameter, a for the discrepancy's
/// coefficients. Its posterior is known in closed form (Normal–InvGamma): σ² ~ InvGamma((n − p
/// − 1)/2, S/2) and (θ, a) | σ² ~ N(β̂, σ²(XᵀX)⁻¹) with X = [g B], p = 1 + k, β̂ and S the least
/// squares' coefficients and residual sum of squares.
#[derive(Clone, Debug)]
pub struct LinearRegression {
    pub g: DVector<f64>,
    pub basis: DMatrix<f64>,
    pub y: DVector<f64>,
}

impl LinearRegression {
    fn design(&self) -> DMatrix<f64> {
        let (n, k) = self.basis.shape();
        DMatrix::from_fn(n, k + 1, |i, j| {
            if j == 0 {
                self.g[i]
            } else {
                self.basis[(i, j - 1)]
            }
        })
    }

    /// β̂ = (θ̂, â), (XᵀX)⁻¹ and S.
    pub fn least_squares(&self) -> (DVector<f64>, DMatrix<f64>, f64) {
        let x = self.design();
        let inverse = (x.transpose() * &x).try_inverse().expect("full rank");
        let beta = &inverse * x.transpose() * &self.y;
        let s = (&self.y - x * &beta).norm_squared();
        (beta, inverse, s)
    }
}

impl LogDensity for LinearRegression {
    fn dim(&self) -> usize {
        2 + self.basis.ncols()
    }
    fn parameter_names(&self) -> Vec<String> {
        let mut names = vec!["theta".to_string(), "log_sigma".to_string()];
        names.extend((1..=self.basis.ncols()).map(|j| format!("a.{j}")));
        names
    }
    fn log_density(&mut self, x: &[f64]) -> Result<f64, DensityError> {
        let n = self.y.len() as f64;
        let a = DVector::from_column_slice(&x[2..]);
        let r = &self.y - &self.g * x[0] - &self.basis * a;
        // σ flat in σ: the density in log σ carries its Jacobian σ.
        Ok(-(n - 1.0) * x[1] - 0.5 * r.norm_squared() * (-2.0 * x[1]).exp())
    }
    fn log_density_and_gradient(
        &mut self,
        _x: &[f64],
        _grad: &mut [f64],
    ) -> Result<f64, DensityError> {
        Err(DensityError::fatal(
            "no gradient: a target for gradient-free samplers",
        ))
    }
    fn linear_conditionals(
        &mut self,
        x: &[f64],
    ) -> Result<Option<crate::density::Conditionals>, DensityError> {
        let r = &self.y - &self.g * x[0];
        let l = (self.basis.transpose() * &self.basis)
            .cholesky()
            .expect("full rank")
            .l();
        let block = crate::density::LinearBlock::least_squares(
            1,
            &r,
            Some((2, &self.basis, &l)),
            |_, _| 0.0,
        )
        .expect("full rank");
        Ok(Some(crate::density::Conditionals {
            leading: 1,
            blocks: vec![block],
        }))
    }
    fn conditioned_on(&self) -> Option<usize> {
        Some(1)
    }
}

/// A standard multivariate Student-t with `df` degrees of freedom in `dim` dimensions: tails
/// polynomial, heavier than any Gaussian's, so that a proposal whose own tails are lighter gives
/// importance weights that grow without bound in them. Known moments: E x = 0, var xᵢ =
/// df/(df − 2) (df > 2).
#[derive(Clone, Debug)]
pub struct StudentT {
    pub df: f64,
    pub dim: usize,
}

impl StudentT {
    pub fn variance(&self) -> f64 {
        self.df / (self.df - 2.0)
    }
}

impl LogDensity for StudentT {
    fn dim(&self) -> usize {
        self.dim
    }

    fn parameter_names(&self) -> Vec<String> {
        (1..=self.dim).map(|i| format!("x.{i}")).collect()
    }

    fn log_density(&mut self, x: &[f64]) -> Result<f64, DensityError> {
        let r2: f64 = x.iter().map(|v| v * v).sum();
        Ok(-0.5 * (self.df + self.dim as f64) * (r2 / self.df).ln_1p())
    }

    fn log_density_and_gradient(
        &mut self,
        x: &[f64],
        grad: &mut [f64],
    ) -> Result<f64, DensityError> {
        let r2: f64 = x.iter().map(|v| v * v).sum();
        let slope = (self.df + self.dim as f64) / (self.df + r2);
        for (g, v) in grad.iter_mut().zip(x) {
            *g = -slope * v;
        }
        self.log_density(x)
    }
}

/// The Fisher information of the t's location, ((df + d)/(df + d + 2))·I: the expected negative
/// Hessian, constant in x.
impl FisherMetric for StudentT {
    fn fisher_metric(&mut self, _x: &[f64], metric: &mut DMatrix<f64>) -> Result<(), DensityError> {
        let d = self.dim as f64;
        metric.fill_with_identity();
        *metric *= (self.df + d) / (self.df + d + 2.0);
        Ok(())
    }
}

impl crate::density::StartingPoint for StudentT {
    fn initial_point(&mut self) -> Result<Vec<f64>, DensityError> {
        Ok(vec![0.1; self.dim])
    }
}
