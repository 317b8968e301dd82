//! What defines a Bayesian model of the paper: BM1 or BM2(K), and its priors.

use serde::{Deserialize, Serialize};

/// How "0.2 R₀" in §4 is read: the paper says variance; we (and the peers) read it as the
/// standard deviation, since a variance of 0.02 Ω² would be a prior sd of 0.14 Ω, wider than R
/// itself. Both are offered.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SpreadReading {
    #[default]
    StandardDeviation,
    Variance,
}

/// The family of the discrepancy coefficients' priors.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CoefficientFamily {
    #[default]
    Laplace,
    Gaussian,
}

impl CoefficientFamily {
    /// The name files and labels use ("laplace", "gaussian").
    pub fn name(&self) -> &'static str {
        match self {
            CoefficientFamily::Laplace => "laplace",
            CoefficientFamily::Gaussian => "gaussian",
        }
    }

    pub const ALL: [CoefficientFamily; 2] =
        [CoefficientFamily::Laplace, CoefficientFamily::Gaussian];
}

/// A family by its [`CoefficientFamily::name`].
impl std::str::FromStr for CoefficientFamily {
    type Err = crate::error::Error;

    fn from_str(text: &str) -> Result<Self, crate::error::Error> {
        crate::error::parse_name("family", text, &Self::ALL, Self::name)
    }
}

/// Priors of the discrepancy coefficients: V[a_j] = V₀/(j+1)^p with V₀ the variance of the
/// paper's Laplace(0, b) (2b²); p = 0 with the Laplace family is the paper's prior, p > 0 is the
/// extension it proposes in §5.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CoefficientPrior {
    pub family: CoefficientFamily,
    /// b of Laplace(0, b). Figure 4 shows Laplace(0, 10); the text says "variance 10" — read
    /// as the scale, like the peers.
    pub scale: f64,
    pub decay_power: f64,
}

impl Default for CoefficientPrior {
    fn default() -> Self {
        Self {
            family: CoefficientFamily::Laplace,
            scale: 10.0,
            decay_power: 0.0,
        }
    }
}

impl CoefficientPrior {
    /// "laplace, p = 0" (the paper's), "gaussian, p = 2", …
    pub fn label(&self) -> String {
        format!("{}, p = {}", self.family.name(), self.decay_power)
    }

    /// The prior of coefficient a_j.
    pub fn prior(&self, j: usize) -> super::Prior {
        let variance = 2.0 * self.scale * self.scale / ((j + 1) as f64).powf(self.decay_power);
        match self.family {
            CoefficientFamily::Laplace => super::Prior::Laplace {
                location: 0.0,
                scale: (variance / 2.0).sqrt(),
            },
            CoefficientFamily::Gaussian => super::Prior::Normal {
                mean: 0.0,
                sd: variance.sqrt(),
            },
        }
    }
}

/// The family of functions δ is expanded in.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BasisKind {
    /// Orthonormal Legendre polynomials on [0, T] (the paper's choice).
    #[default]
    Legendre,
    /// Cubic B-splines on K − 2 equal spans, each scaled to unit mean square (long records).
    Bspline,
}

impl BasisKind {
    /// The basis of degree K on a recording ending at `t_end`.
    pub fn build(
        &self,
        degree: usize,
        t_end: f64,
    ) -> Result<Box<dyn super::DiscrepancyBasis>, String> {
        match self {
            BasisKind::Legendre => Ok(Box::new(super::Legendre::new(degree, t_end)?)),
            BasisKind::Bspline => Ok(Box::new(super::BSpline::new(degree, t_end)?)),
        }
    }

    pub fn max_degree(&self) -> usize {
        match self {
            BasisKind::Legendre => super::basis::MAX_LEGENDRE_DEGREE,
            BasisKind::Bspline => super::bspline::MAX_BSPLINE_DEGREE,
        }
    }

    pub fn name(&self) -> &'static str {
        match self {
            BasisKind::Legendre => "legendre",
            BasisKind::Bspline => "bspline",
        }
    }
}

/// BM1 (`discrepancy_degree = None`) or BM2(K) with its priors.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ModelSettings {
    pub discrepancy_degree: Option<usize>,
    pub discrepancy_basis: BasisKind,
    /// The prior of R is N(R_nominal, spread·R_nominal) in the reading below.
    pub resistance_prior_spread: f64,
    pub resistance_prior_reading: SpreadReading,
    pub coefficient_prior: CoefficientPrior,
    /// InvGamma(shape, scale) on each noise standard deviation σ.
    pub noise_prior_shape: f64,
    pub noise_prior_scale: f64,
}

impl Default for ModelSettings {
    fn default() -> Self {
        Self {
            discrepancy_degree: Some(9),
            discrepancy_basis: BasisKind::Legendre,
            resistance_prior_spread: 0.2,
            resistance_prior_reading: SpreadReading::StandardDeviation,
            coefficient_prior: CoefficientPrior::default(),
            noise_prior_shape: 1.0,
            noise_prior_scale: 1.0,
        }
    }
}

impl ModelSettings {
    pub fn bm1() -> Self {
        Self {
            discrepancy_degree: None,
            ..Self::default()
        }
    }

    pub fn bm2(k: usize) -> Self {
        Self {
            discrepancy_degree: Some(k),
            ..Self::default()
        }
    }

    pub fn label(&self) -> String {
        match self.discrepancy_degree {
            None => "BM1".into(),
            Some(k) => format!("BM2(K={k})"),
        }
    }

    pub fn validate(&self) -> Result<(), String> {
        if let Some(k) = self.discrepancy_degree
            && k > self.discrepancy_basis.max_degree()
        {
            return Err(format!(
                "discrepancy degree K = {k} is larger than the maximum {} of the {} basis",
                self.discrepancy_basis.max_degree(),
                self.discrepancy_basis.name()
            ));
        }
        let positive = [
            ("resistance_prior_spread", self.resistance_prior_spread),
            ("coefficient_prior.scale", self.coefficient_prior.scale),
            ("noise_prior_shape", self.noise_prior_shape),
            ("noise_prior_scale", self.noise_prior_scale),
        ];
        for (name, v) in positive {
            if !(v > 0.0 && v.is_finite()) {
                return Err(format!("{name} = {v} must be a positive number"));
            }
        }
        if !(self.coefficient_prior.decay_power >= 0.0
            && self.coefficient_prior.decay_power.is_finite())
        {
            return Err(format!(
                "coefficient_prior.decay_power = {} must be ≥ 0",
                self.coefficient_prior.decay_power
            ));
        }
        Ok(())
    }

    /// The prior of R around its nominal value.
    pub fn resistance_prior(&self, nominal: f64) -> super::Prior {
        let spread = self.resistance_prior_spread * nominal;
        let sd = match self.resistance_prior_reading {
            SpreadReading::StandardDeviation => spread,
            SpreadReading::Variance => spread.sqrt(),
        };
        super::Prior::Normal { mean: nominal, sd }
    }
}
