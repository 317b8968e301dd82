//! What a model says about each of its parameters — name, unit, nominal value, support and a
//! default prior — and the maps to unconstrained coordinates that the samplers move in.
//!
//! This sits below both the physics (which declares parameters) and the Bayesian model (which
//! puts densities on them), so that neither has to import the other.

mod id;
mod prior;

pub use id::ParamId;
pub use prior::{Prior, ln_gamma};

use serde::{Deserialize, Serialize};

/// Where a parameter may lie.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Support {
    Real,
    /// x ≥ 0 (the boundary 0 itself means "absent": a friction of zero).
    Positive,
    Bounded {
        lower: f64,
        upper: f64,
    },
}

impl Support {
    fn bounds(&self) -> (f64, f64) {
        match *self {
            Support::Real => (f64::NEG_INFINITY, f64::INFINITY),
            Support::Positive => (0.0, f64::INFINITY),
            Support::Bounded { lower, upper } => (lower, upper),
        }
    }

    fn from_bounds(lower: f64, upper: f64) -> Support {
        match (lower == f64::NEG_INFINITY, upper == f64::INFINITY) {
            (true, true) => Support::Real,
            (false, true) if lower == 0.0 => Support::Positive,
            _ => Support::Bounded { lower, upper },
        }
    }

    /// Where both hold: a parameter's own support with its prior's (a uniform prior on a
    /// friction bounds it on both sides). An interval open on one side other than [0, ∞) has no
    /// transform here and is refused.
    pub fn intersect(&self, other: &Support) -> Result<Support, String> {
        let (a, b) = self.bounds();
        let (c, d) = other.bounds();
        let (lower, upper) = (a.max(c), b.min(d));
        if !(lower < upper) {
            return Err(format!(
                "the prior's support [{c}, {d}] does not overlap the parameter's [{a}, {b}]"
            ));
        }
        if lower.is_finite() != upper.is_finite() && !(lower == 0.0 && upper == f64::INFINITY) {
            return Err(format!(
                "a support [{lower}, {upper}] open on one side must be [0, ∞)"
            ));
        }
        Ok(Support::from_bounds(lower, upper))
    }

    pub fn contains(&self, x: f64) -> bool {
        let (lower, upper) = self.bounds();
        x >= lower && x <= upper
    }

    /// Strictly inside: a point an unconstrained coordinate can reach.
    pub fn interior(&self, x: f64) -> bool {
        let (lower, upper) = self.bounds();
        x > lower && x < upper
    }

    pub fn describe(&self) -> String {
        match *self {
            Support::Real => "real".into(),
            Support::Positive => "≥ 0".into(),
            Support::Bounded { lower, upper } => format!("[{lower}, {upper}]"),
        }
    }
}

/// A parameter as a model declares it.
#[derive(Clone, Debug, PartialEq)]
pub struct ParameterSpec {
    /// Which parameter; its text is the key in model files and reports: `R` for a base
    /// parameter, `coulomb_friction.T_c` for a term's.
    pub id: ParamId,
    pub unit: &'static str,
    pub nominal: f64,
    pub support: Support,
    /// The prior used when a model file calibrates the parameter without naming one, scaled by
    /// the model's own magnitudes.
    pub default_prior: Prior,
}

impl ParameterSpec {
    /// The key in model files and reports (`R`, `coulomb_friction.T_c`).
    pub fn name(&self) -> String {
        self.id.to_string()
    }

    /// The name in draws files (`coulomb_friction__T_c`): see [`ParamId::column_name`].
    pub fn column_name(&self) -> String {
        self.id.column_name()
    }
}

/// The map from an unconstrained coordinate u to the parameter x.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub enum Transform {
    Identity,
    /// x = exp(u), for [0, ∞).
    Log,
    /// x = lower + (upper − lower)·logistic(u).
    Logit {
        lower: f64,
        upper: f64,
    },
}

/// x(u) with the derivatives the gradient and the metric need, and the log-Jacobian
/// log|dx/du| with its first two derivatives in u.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mapped {
    pub x: f64,
    pub dx: f64,
    pub d2x: f64,
    pub log_jacobian: f64,
    pub d_log_jacobian: f64,
    pub d2_log_jacobian: f64,
}

impl Transform {
    /// Log for [0, ∞), logit for a bounded interval, none on the real line.
    pub fn for_support(support: &Support) -> Transform {
        match *support {
            Support::Real => Transform::Identity,
            Support::Positive => Transform::Log,
            Support::Bounded { lower, upper } => Transform::Logit { lower, upper },
        }
    }

    pub fn map(&self, u: f64) -> Mapped {
        match *self {
            Transform::Identity => Mapped {
                x: u,
                dx: 1.0,
                d2x: 0.0,
                log_jacobian: 0.0,
                d_log_jacobian: 0.0,
                d2_log_jacobian: 0.0,
            },
            Transform::Log => {
                let x = u.exp();
                Mapped {
                    x,
                    dx: x,
                    d2x: x,
                    log_jacobian: u,
                    d_log_jacobian: 1.0,
                    d2_log_jacobian: 0.0,
                }
            }
            Transform::Logit { lower, upper } => {
                let width = upper - lower;
                // logistic(u) and 1 − logistic(u) each from the side that does not cancel.
                let (s, s1) = if u >= 0.0 {
                    let e = (-u).exp();
                    (1.0 / (1.0 + e), e / (1.0 + e))
                } else {
                    let e = u.exp();
                    (e / (1.0 + e), 1.0 / (1.0 + e))
                };
                let dx = width * s * s1;
                Mapped {
                    x: lower + width * s,
                    dx,
                    d2x: dx * (s1 - s),
                    log_jacobian: width.ln() + s.ln() + s1.ln(),
                    d_log_jacobian: s1 - s,
                    d2_log_jacobian: -2.0 * s * s1,
                }
            }
        }
    }

    /// u(x); x must lie strictly inside the support.
    pub fn inverse(&self, x: f64) -> f64 {
        match *self {
            Transform::Identity => x,
            Transform::Log => x.ln(),
            Transform::Logit { lower, upper } => {
                let s = (x - lower) / (upper - lower);
                s.ln() - (1.0 - s).ln()
            }
        }
    }

    /// The prefix of the unconstrained coordinate's name (`log_`, `logit_`, or none).
    pub fn prefix(&self) -> &'static str {
        match self {
            Transform::Identity => "",
            Transform::Log => "log_",
            Transform::Logit { .. } => "logit_",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transforms_invert_and_their_derivatives_match_finite_differences() {
        let h = 1e-5;
        for t in [
            Transform::Identity,
            Transform::Log,
            Transform::Logit {
                lower: -2.0,
                upper: 5.0,
            },
        ] {
            for u in [-3.0, -0.2, 0.0, 0.7, 4.0] {
                let m = t.map(u);
                assert!((t.inverse(m.x) - u).abs() < 1e-9, "{t:?} at {u}");
                let (p, q) = (t.map(u + h), t.map(u - h));
                let fd = |a: f64, b: f64| (a - b) / (2.0 * h);
                assert!((fd(p.x, q.x) - m.dx).abs() < 1e-6 * (1.0 + m.dx.abs()));
                assert!((fd(p.dx, q.dx) - m.d2x).abs() < 1e-6 * (1.0 + m.d2x.abs()));
                assert!((m.log_jacobian - m.dx.abs().ln()).abs() < 1e-12);
                assert!((fd(p.log_jacobian, q.log_jacobian) - m.d_log_jacobian).abs() < 1e-6);
                assert!((fd(p.d_log_jacobian, q.d_log_jacobian) - m.d2_log_jacobian).abs() < 1e-6);
            }
        }
    }

    #[test]
    fn supports_intersect_to_what_both_allow() {
        let uniform = Support::Bounded {
            lower: 0.0,
            upper: 2.0,
        };
        assert_eq!(Support::Positive.intersect(&uniform), Ok(uniform));
        assert_eq!(
            Support::Real.intersect(&Support::Positive),
            Ok(Support::Positive)
        );
        assert_eq!(Support::Real.intersect(&Support::Real), Ok(Support::Real));
        let negative = Support::Bounded {
            lower: -3.0,
            upper: -1.0,
        };
        assert!(Support::Positive.intersect(&negative).is_err());
    }
}
