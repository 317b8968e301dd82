//! Univariate priors with the derivatives the samplers and the metric need.

use serde::{Deserialize, Serialize};

use super::Support;

const LN_2PI: f64 = 1.837_877_066_409_345_5;

/// A prior on one scalar, fully normalised (the Laplace evidence needs the constants).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "family", rename_all = "snake_case", deny_unknown_fields)]
pub enum Prior {
    Normal {
        mean: f64,
        sd: f64,
    },
    Laplace {
        location: f64,
        scale: f64,
    },
    /// On a positive quantity x: density ∝ x^{−shape−1} exp(−scale/x).
    InverseGamma {
        shape: f64,
        scale: f64,
    },
    /// log x ~ N(ln median, sigma²), on a positive quantity.
    LogNormal {
        median: f64,
        sigma: f64,
    },
    /// |N(0, scale²)| on a non-negative quantity.
    HalfNormal {
        scale: f64,
    },
    Uniform {
        lower: f64,
        upper: f64,
    },
}

impl Prior {
    pub fn log_density(&self, x: f64) -> f64 {
        match *self {
            Prior::Normal { mean, sd } => {
                let z = (x - mean) / sd;
                -0.5 * z * z - sd.ln() - 0.5 * LN_2PI
            }
            Prior::Laplace { location, scale } => {
                -(x - location).abs() / scale - (2.0 * scale).ln()
            }
            Prior::InverseGamma { shape, scale } => {
                if x <= 0.0 {
                    return f64::NEG_INFINITY;
                }
                shape * scale.ln() - ln_gamma(shape) - (shape + 1.0) * x.ln() - scale / x
            }
            Prior::LogNormal { median, sigma } => {
                if x <= 0.0 {
                    return f64::NEG_INFINITY;
                }
                let z = (x.ln() - median.ln()) / sigma;
                -0.5 * z * z - sigma.ln() - x.ln() - 0.5 * LN_2PI
            }
            Prior::HalfNormal { scale } => {
                if x < 0.0 {
                    return f64::NEG_INFINITY;
                }
                let z = x / scale;
                -0.5 * z * z - scale.ln() - 0.5 * LN_2PI + std::f64::consts::LN_2
            }
            Prior::Uniform { lower, upper } => {
                if x < lower || x > upper {
                    return f64::NEG_INFINITY;
                }
                -(upper - lower).ln()
            }
        }
    }

    /// d/dx log p(x). The Laplace prior's kink at its location gets the subgradient 0.
    pub fn gradient(&self, x: f64) -> f64 {
        match *self {
            Prior::Normal { mean, sd } => -(x - mean) / (sd * sd),
            Prior::Laplace { location, scale } => {
                let d = x - location;
                if d > 0.0 {
                    -1.0 / scale
                } else if d < 0.0 {
                    1.0 / scale
                } else {
                    0.0
                }
            }
            Prior::InverseGamma { shape, scale } => -(shape + 1.0) / x + scale / (x * x),
            Prior::LogNormal { median, sigma } => {
                -((x.ln() - median.ln()) / (sigma * sigma) + 1.0) / x
            }
            Prior::HalfNormal { scale } => -x / (scale * scale),
            Prior::Uniform { .. } => 0.0,
        }
    }

    /// −d²/dx² log p(x), the prior's share of a metric. Zero for the Laplace prior: its curvature
    /// is a point mass at the kink, which no smooth metric can hold.
    pub fn curvature(&self, x: f64) -> f64 {
        match *self {
            Prior::Normal { sd, .. } => 1.0 / (sd * sd),
            Prior::Laplace { .. } => 0.0,
            Prior::InverseGamma { shape, scale } => {
                -(shape + 1.0) / (x * x) + 2.0 * scale / (x * x * x)
            }
            Prior::LogNormal { median, sigma } => {
                let s2 = sigma * sigma;
                (1.0 - s2 - (x.ln() - median.ln())) / (s2 * x * x)
            }
            Prior::HalfNormal { scale } => 1.0 / (scale * scale),
            Prior::Uniform { .. } => 0.0,
        }
    }

    /// Where the density is positive: the quantity's support as far as the prior is concerned.
    pub fn support(&self) -> Support {
        match *self {
            Prior::Normal { .. } | Prior::Laplace { .. } => Support::Real,
            Prior::InverseGamma { .. } | Prior::LogNormal { .. } | Prior::HalfNormal { .. } => {
                Support::Positive
            }
            Prior::Uniform { lower, upper } => Support::Bounded { lower, upper },
        }
    }

    /// The prior's median: where a search starts when the nominal value lies on the boundary
    /// of the support (a friction of 0 means "absent so far", not a point to start from).
    pub fn median(&self) -> f64 {
        match *self {
            Prior::Normal { mean, .. } => mean,
            Prior::Laplace { location, .. } => location,
            // No closed form; the mode β/(α+1) is inside the support, which is what matters.
            Prior::InverseGamma { shape, scale } => scale / (shape + 1.0),
            Prior::LogNormal { median, .. } => median,
            Prior::HalfNormal { scale } => 0.674_489_750_196_081_7 * scale,
            Prior::Uniform { lower, upper } => 0.5 * (lower + upper),
        }
    }

    pub fn mean(&self) -> f64 {
        match *self {
            Prior::Normal { mean, .. } => mean,
            Prior::Laplace { location, .. } => location,
            Prior::InverseGamma { shape, scale } => {
                if shape > 1.0 {
                    scale / (shape - 1.0)
                } else {
                    f64::INFINITY
                }
            }
            Prior::LogNormal { median, sigma } => median * (0.5 * sigma * sigma).exp(),
            Prior::HalfNormal { scale } => scale * (2.0 / std::f64::consts::PI).sqrt(),
            Prior::Uniform { lower, upper } => 0.5 * (lower + upper),
        }
    }

    /// Checks the arguments: scales positive, bounds ordered, everything finite.
    pub fn validate(&self) -> Result<(), String> {
        let positive = |name: &str, v: f64| {
            if v > 0.0 && v.is_finite() {
                Ok(())
            } else {
                Err(format!("{name} = {v} must be a positive number"))
            }
        };
        let finite = |name: &str, v: f64| {
            if v.is_finite() {
                Ok(())
            } else {
                Err(format!("{name} = {v} must be a finite number"))
            }
        };
        match *self {
            Prior::Normal { mean, sd } => finite("mean", mean).and(positive("sd", sd)),
            Prior::Laplace { location, scale } => {
                finite("location", location).and(positive("scale", scale))
            }
            Prior::InverseGamma { shape, scale } => {
                positive("shape", shape).and(positive("scale", scale))
            }
            Prior::LogNormal { median, sigma } => {
                positive("median", median).and(positive("sigma", sigma))
            }
            Prior::HalfNormal { scale } => positive("scale", scale),
            Prior::Uniform { lower, upper } => {
                finite("lower", lower)?;
                finite("upper", upper)?;
                if lower < upper {
                    Ok(())
                } else {
                    Err(format!("lower = {lower} must be below upper = {upper}"))
                }
            }
        }
    }

    pub fn variance(&self) -> f64 {
        match *self {
            Prior::Normal { sd, .. } => sd * sd,
            Prior::Laplace { scale, .. } => 2.0 * scale * scale,
            Prior::InverseGamma { shape, scale } => {
                if shape > 2.0 {
                    scale * scale / ((shape - 1.0).powi(2) * (shape - 2.0))
                } else {
                    f64::INFINITY
                }
            }
            Prior::LogNormal { median, sigma } => {
                let s2 = sigma * sigma;
                (s2.exp() - 1.0) * median * median * s2.exp()
            }
            Prior::HalfNormal { scale } => scale * scale * (1.0 - 2.0 / std::f64::consts::PI),
            Prior::Uniform { lower, upper } => (upper - lower).powi(2) / 12.0,
        }
    }
}

/// ln Γ(x) for x > 0 (Lanczos, g = 7, n = 9; ~15 significant digits).
pub fn ln_gamma(x: f64) -> f64 {
    const G: f64 = 7.0;
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        return (std::f64::consts::PI / (std::f64::consts::PI * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut a = C[0];
    let t = x + G + 0.5;
    for (i, &c) in C.iter().enumerate().skip(1) {
        a += c / (x + i as f64);
    }
    0.5 * LN_2PI + (x + 0.5) * t.ln() - t + a.ln()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn integrate(prior: Prior, lo: f64, hi: f64) -> f64 {
        let n = 200_000;
        let h = (hi - lo) / n as f64;
        (0..n)
            .map(|i| prior.log_density(lo + (i as f64 + 0.5) * h).exp() * h)
            .sum()
    }

    #[test]
    fn priors_are_normalised() {
        assert!(
            (integrate(
                Prior::Normal {
                    mean: 0.1,
                    sd: 0.02
                },
                -0.1,
                0.3
            ) - 1.0)
                .abs()
                < 1e-6
        );
        assert!(
            (integrate(
                Prior::Laplace {
                    location: 0.0,
                    scale: 10.0
                },
                -400.0,
                400.0
            ) - 1.0)
                .abs()
                < 1e-6
        );
        // InvGamma(3, 2) has light enough tails to integrate on a finite grid.
        assert!(
            (integrate(
                Prior::InverseGamma {
                    shape: 3.0,
                    scale: 2.0
                },
                1e-9,
                400.0
            ) - 1.0)
                .abs()
                < 1e-4
        );
        for (prior, lo, hi) in [
            (
                Prior::LogNormal {
                    median: 0.5,
                    sigma: 0.3,
                },
                1e-9,
                5.0,
            ),
            (Prior::HalfNormal { scale: 2.0 }, 0.0, 30.0),
            (
                Prior::Uniform {
                    lower: -1.0,
                    upper: 3.0,
                },
                -1.0,
                3.0,
            ),
        ] {
            assert!((integrate(prior, lo, hi) - 1.0).abs() < 1e-6, "{prior:?}");
            // First and second moments by quadrature against the closed forms.
            let n = 200_000;
            let h = (hi - lo) / n as f64;
            let (mut m1, mut m2) = (0.0, 0.0);
            for i in 0..n {
                let x = lo + (i as f64 + 0.5) * h;
                let w = prior.log_density(x).exp() * h;
                m1 += w * x;
                m2 += w * x * x;
            }
            assert!((m1 - prior.mean()).abs() < 1e-6, "{prior:?} mean {m1}");
            assert!(
                (m2 - m1 * m1 - prior.variance()).abs() < 1e-5,
                "{prior:?} variance"
            );
        }
    }

    #[test]
    fn gradients_and_curvatures_match_finite_differences() {
        let h = 1e-5;
        for (prior, x) in [
            (
                Prior::Normal {
                    mean: 0.1,
                    sd: 0.02,
                },
                0.13,
            ),
            (
                Prior::Laplace {
                    location: 0.0,
                    scale: 10.0,
                },
                -3.0,
            ),
            (
                Prior::InverseGamma {
                    shape: 1.0,
                    scale: 1.0,
                },
                1.7,
            ),
            (
                Prior::LogNormal {
                    median: 0.5,
                    sigma: 0.3,
                },
                0.8,
            ),
            (Prior::HalfNormal { scale: 2.0 }, 1.3),
            (
                Prior::Uniform {
                    lower: -1.0,
                    upper: 3.0,
                },
                0.4,
            ),
        ] {
            let fd = (prior.log_density(x + h) - prior.log_density(x - h)) / (2.0 * h);
            assert!(
                (fd - prior.gradient(x)).abs() < 1e-6 * (1.0 + fd.abs()),
                "{prior:?}"
            );
            let fd2 = -(prior.gradient(x + h) - prior.gradient(x - h)) / (2.0 * h);
            assert!(
                (fd2 - prior.curvature(x)).abs() < 1e-5 * (1.0 + fd2.abs()),
                "{prior:?}"
            );
        }
    }

    #[test]
    fn ln_gamma_matches_known_values() {
        assert!(ln_gamma(1.0).abs() < 1e-14);
        assert!((ln_gamma(5.0) - 24f64.ln()).abs() < 1e-13);
        assert!((ln_gamma(0.5) - std::f64::consts::PI.sqrt().ln()).abs() < 1e-13);
    }
}
