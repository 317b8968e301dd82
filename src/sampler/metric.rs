//! The Euclidean metric of Hamiltonian Monte Carlo: momenta p ~ N(0, M), kinetic energy
//! ½ pᵀM⁻¹p. The sampler stores the *inverse* mass M⁻¹ because that is what warm-up estimates
//! (the posterior covariance) and what the integrator multiplies by.

use nalgebra::{DMatrix, DVectorView, DVectorViewMut};
use rand::RngExt;
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use serde::{Deserialize, Serialize};

use crate::density::{DensityError, FisherMetric};

/// Which shape of metric a sampler uses; the metric itself carries its values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MetricKind {
    Diagonal,
    Dense,
}

impl MetricKind {
    /// The suffix of kernel names ("nuts-diag", "hmc-dense"), as in Stan's `diag_e`/`dense_e`.
    pub fn suffix(self) -> &'static str {
        match self {
            MetricKind::Diagonal => "diag",
            MetricKind::Dense => "dense",
        }
    }
}

/// A positive-definite inverse mass matrix.
///
/// Serialised as `{"diagonal": {"inverse_mass": [..]}}` or
/// `{"dense": {"inverse_mass": [[..], ..]}}` (rows); the Cholesky factor is recomputed, and
/// checked, on loading.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(into = "MetricRepr", try_from = "MetricRepr")]
pub enum Metric {
    /// The diagonal of M⁻¹ (per-coordinate posterior variances once adapted).
    Diagonal(Vec<f64>),
    Dense(DenseMetric),
}

/// A dense M⁻¹ with its lower Cholesky factor L (M⁻¹ = LLᵀ), kept together so that they
/// cannot disagree.
#[derive(Clone, Debug, PartialEq)]
pub struct DenseMetric {
    inverse_mass: DMatrix<f64>,
    cholesky: DMatrix<f64>,
}

impl DenseMetric {
    pub fn new(inverse_mass: DMatrix<f64>) -> Result<Self, String> {
        if !inverse_mass.is_square() {
            return Err(format!(
                "a dense metric must be square, not {}×{}",
                inverse_mass.nrows(),
                inverse_mass.ncols()
            ));
        }
        if inverse_mass.iter().any(|v| !v.is_finite()) {
            return Err("the inverse mass matrix has a non-finite entry".into());
        }
        // An inverse computed numerically (of a finite-difference Hessian, say) is symmetric
        // only to rounding: symmetrise that, but reject a matrix that is not meant to be.
        let asymmetry = (&inverse_mass - inverse_mass.transpose()).amax();
        if asymmetry > 1e-8 * inverse_mass.amax() {
            return Err(format!(
                "the inverse mass matrix is not symmetric (asymmetry {asymmetry:e})"
            ));
        }
        let inverse_mass = if asymmetry > 0.0 {
            (&inverse_mass + inverse_mass.transpose()) * 0.5
        } else {
            inverse_mass
        };
        let cholesky = inverse_mass
            .clone()
            .cholesky()
            .ok_or("the inverse mass matrix is not positive definite")?
            .unpack();
        Ok(Self {
            inverse_mass,
            cholesky,
        })
    }

    pub fn inverse_mass(&self) -> &DMatrix<f64> {
        &self.inverse_mass
    }

    /// L with M⁻¹ = LLᵀ.
    pub fn cholesky(&self) -> &DMatrix<f64> {
        &self.cholesky
    }
}

impl Metric {
    /// M = I, where warm-up starts when nothing better is known.
    pub fn identity(dim: usize, kind: MetricKind) -> Self {
        match kind {
            MetricKind::Diagonal => Metric::Diagonal(vec![1.0; dim]),
            MetricKind::Dense => Metric::Dense(
                DenseMetric::new(DMatrix::identity(dim, dim)).expect("the identity is a metric"),
            ),
        }
    }

    /// A diagonal metric from M⁻¹'s diagonal (e.g. posterior variances).
    pub fn diagonal(inverse_mass: Vec<f64>) -> Result<Self, String> {
        if let Some(bad) = inverse_mass.iter().find(|v| !(v.is_finite() && **v > 0.0)) {
            return Err(format!(
                "a diagonal inverse mass must be finite and positive, got {bad}"
            ));
        }
        Ok(Metric::Diagonal(inverse_mass))
    }

    /// A dense metric from M⁻¹ (e.g. a posterior covariance, or the inverse of the negative
    /// Hessian at the MAP).
    pub fn dense(inverse_mass: DMatrix<f64>) -> Result<Self, String> {
        DenseMetric::new(inverse_mass).map(Metric::Dense)
    }

    /// A metric from a precision-like matrix (the negative Hessian of the log density at the
    /// mode, or a Fisher information): M⁻¹ = precision⁻¹, or its diagonal — the marginal
    /// variances, not the reciprocals of the precision's diagonal, which would understate
    /// the scale of correlated coordinates.
    pub fn from_precision(precision: &DMatrix<f64>, kind: MetricKind) -> Result<Self, String> {
        let chol = precision
            .clone()
            .cholesky()
            .ok_or("the precision matrix is not positive definite")?;
        let covariance = chol.inverse();
        match kind {
            MetricKind::Dense => Metric::dense(covariance),
            MetricKind::Diagonal => {
                Metric::diagonal(covariance.diagonal().iter().copied().collect())
            }
        }
    }

    /// A metric from the density's Fisher metric at `x` (typically the MAP): the Laplace
    /// approximation's covariance, a warm start that makes warm-up's first windows useful.
    pub fn from_fisher<P: FisherMetric>(
        density: &mut P,
        x: &[f64],
        kind: MetricKind,
    ) -> Result<Self, DensityError> {
        let d = density.dim();
        let mut information = DMatrix::zeros(d, d);
        density.fisher_metric(x, &mut information)?;
        Metric::from_precision(&information, kind).map_err(DensityError::fatal)
    }

    /// The diagonal of M⁻¹ (the marginal variances).
    pub fn inverse_mass_diagonal(&self) -> Vec<f64> {
        match self {
            Metric::Diagonal(v) => v.clone(),
            Metric::Dense(d) => d.inverse_mass().diagonal().iter().copied().collect(),
        }
    }

    pub fn kind(&self) -> MetricKind {
        match self {
            Metric::Diagonal(_) => MetricKind::Diagonal,
            Metric::Dense(_) => MetricKind::Dense,
        }
    }

    pub fn dim(&self) -> usize {
        match self {
            Metric::Diagonal(v) => v.len(),
            Metric::Dense(m) => m.inverse_mass.nrows(),
        }
    }

    /// M⁻¹ as a matrix (for reports and comparisons).
    pub fn inverse_mass_matrix(&self) -> DMatrix<f64> {
        match self {
            Metric::Diagonal(v) => DMatrix::from_diagonal(&nalgebra::DVector::from_column_slice(v)),
            Metric::Dense(m) => m.inverse_mass.clone(),
        }
    }

    /// Writes the velocity dq/dt = M⁻¹p into `velocity` (Stan's `dtau_dp`, the "sharp"
    /// momentum of the U-turn criterion).
    pub fn velocity(&self, p: &[f64], velocity: &mut [f64]) {
        match self {
            Metric::Diagonal(inv) => {
                for ((v, p), m) in velocity.iter_mut().zip(p).zip(inv) {
                    *v = m * p;
                }
            }
            Metric::Dense(m) => {
                let n = p.len();
                DVectorViewMut::from_slice(velocity, n).gemv(
                    1.0,
                    &m.inverse_mass,
                    &DVectorView::from_slice(p, n),
                    0.0,
                );
            }
        }
    }

    /// ½ pᵀM⁻¹p, given the velocity M⁻¹p already computed.
    pub fn kinetic_energy(p: &[f64], velocity: &[f64]) -> f64 {
        0.5 * p.iter().zip(velocity).map(|(a, b)| a * b).sum::<f64>()
    }

    /// Draws p ~ N(0, M) into `p`.
    pub fn sample_momentum(&self, rng: &mut ChaCha8Rng, p: &mut [f64]) {
        for v in p.iter_mut() {
            *v = rng.sample(StandardNormal);
        }
        match self {
            Metric::Diagonal(inv) => {
                for (v, m) in p.iter_mut().zip(inv) {
                    *v /= m.sqrt();
                }
            }
            Metric::Dense(m) => {
                // With M⁻¹ = LLᵀ, M = L⁻ᵀL⁻¹, so L⁻ᵀz has covariance M: one triangular
                // solve in place instead of factoring M.
                let n = p.len();
                m.cholesky
                    .tr_solve_lower_triangular_mut(&mut DVectorViewMut::from_slice(p, n));
            }
        }
    }
}

#[derive(Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
enum MetricRepr {
    Diagonal { inverse_mass: Vec<f64> },
    Dense { inverse_mass: Vec<Vec<f64>> },
}

impl From<Metric> for MetricRepr {
    fn from(metric: Metric) -> Self {
        match metric {
            Metric::Diagonal(inverse_mass) => MetricRepr::Diagonal { inverse_mass },
            Metric::Dense(m) => MetricRepr::Dense {
                inverse_mass: m
                    .inverse_mass
                    .row_iter()
                    .map(|r| r.iter().copied().collect())
                    .collect(),
            },
        }
    }
}

impl TryFrom<MetricRepr> for Metric {
    type Error = String;

    fn try_from(repr: MetricRepr) -> Result<Self, String> {
        match repr {
            MetricRepr::Diagonal { inverse_mass } => Metric::diagonal(inverse_mass),
            MetricRepr::Dense { inverse_mass } => {
                let n = inverse_mass.len();
                if let Some(row) = inverse_mass.iter().position(|r| r.len() != n) {
                    return Err(format!(
                        "row {} of the {n}×{n} inverse mass matrix has {} entries",
                        row + 1,
                        inverse_mass[row].len()
                    ));
                }
                Metric::dense(DMatrix::from_fn(n, n, |i, j| inverse_mass[i][j]))
            }
        }
    }
}
