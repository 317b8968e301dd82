//! Univariate priors with the derivatives the samplers and the metric need.

use serde::{Deserialize, Serialize};

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
