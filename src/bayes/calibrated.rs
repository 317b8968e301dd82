//! A calibrated physical parameter as the posterior sees it: its prior, its support, and the
//! unconstrained coordinate u the samplers move in, x = T(u), with the Jacobian.
//!
//! The density in u is p(T(u))·|T'(u)|, so a positive parameter whose nominal value is 0 (an
//! absent friction) is a coordinate like any other, and no sampler meets a wall. Schema-1 models
//! keep R's original parameterisation (x itself, a wall at 0) so that their draws do not move.

use crate::parameter::{ParamId, ParameterSpec, Prior, Support, Transform};

#[derive(Clone, Debug, PartialEq)]
pub struct CalibratedParameter {
    /// Which parameter.
    pub id: ParamId,
    /// Its text, the model's name for it (`R`, `coulomb_friction.T_c`), as reports key it.
    pub name: String,
    pub unit: &'static str,
    pub prior: Prior,
    /// Where both the parameter and its prior allow it to be.
    pub support: Support,
    pub transform: Transform,
    /// Where a search starts, in x: the nominal value if it lies inside the support, else the
    /// prior's median (a nominal value on the boundary means "absent so far").
    pub start: f64,
}

/// The prior's share of the log density in u at one point, with what the chain rule and the
/// metric need.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PriorInU {
    pub x: f64,
    /// dx/du and d²x/du², to carry the likelihood's derivatives in x over to u.
    pub dx: f64,
    pub d2x: f64,
    /// log p(x(u)) + log|x'(u)|.
    pub log_density: f64,
    /// Its derivative in u.
    pub gradient: f64,
    /// Its exact negative second derivative in u (for the observed information).
    pub curvature: f64,
    /// A non-negative stand-in for the metric: the prior's curvature in x carried to u, or the
    /// exact one where that is larger.
    pub metric: f64,
}

impl CalibratedParameter {
    /// A parameter named in a model file's `[calibrate]` table, with its prior (or the model's
    /// default), sampled through the transform its support calls for.
    pub fn new(spec: &ParameterSpec, prior: Option<Prior>) -> Result<Self, String> {
        let prior = prior.unwrap_or(spec.default_prior);
        prior
            .validate()
            .map_err(|e| format!("{}: prior {e}", spec.id))?;
        let support = spec
            .support
            .intersect(&prior.support())
            .map_err(|e| format!("{}: {e}", spec.id))?;
        let start = if support.interior(spec.nominal) {
            spec.nominal
        } else {
            let median = prior.median();
            if !support.interior(median) {
                return Err(format!(
                    "{}: neither the nominal value {} nor the prior's median {median} lies \
                     inside the support {}",
                    spec.id,
                    spec.nominal,
                    support.describe()
                ));
            }
            median
        };
        Ok(Self {
            id: spec.id.clone(),
            name: spec.name(),
            unit: spec.unit,
            prior,
            support,
            transform: Transform::for_support(&support),
            start,
        })
    }

    /// The parameterisation of schema-1 models: x itself, zero density outside the support.
    pub fn untransformed(spec: &ParameterSpec, prior: Prior) -> Self {
        Self {
            id: spec.id.clone(),
            name: spec.name(),
            unit: spec.unit,
            prior,
            support: spec.support,
            transform: Transform::Identity,
            start: spec.nominal,
        }
    }

    /// The name in draws files and summaries (constrained).
    pub fn output_name(&self) -> String {
        self.id.column_name()
    }

    /// The name of the unconstrained coordinate (`log_R`, `logit_load_step__t_s`).
    pub fn coordinate_name(&self) -> String {
        format!("{}{}", self.transform.prefix(), self.output_name())
    }

    pub fn to_unconstrained(&self, x: f64) -> f64 {
        self.transform.inverse(x)
    }

    /// The prior's contribution at u, or `None` where the density is zero (only an
    /// untransformed parameter can leave its support).
    pub fn at(&self, u: f64) -> Option<PriorInU> {
        let m = self.transform.map(u);
        if self.transform == Transform::Identity
            && self.support != Support::Real
            && !self.support.interior(m.x)
        {
            return None;
        }
        let log_p = self.prior.log_density(m.x);
        if !log_p.is_finite() {
            return None;
        }
        let g = self.prior.gradient(m.x);
        let c = self.prior.curvature(m.x);
        let curvature = c * m.dx * m.dx - g * m.d2x - m.d2_log_jacobian;
        Some(PriorInU {
            x: m.x,
            dx: m.dx,
            d2x: m.d2x,
            log_density: log_p + m.log_jacobian,
            gradient: g * m.dx + m.d_log_jacobian,
            curvature,
            metric: curvature.max(c * m.dx * m.dx).max(0.0),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(nominal: f64, support: Support) -> ParameterSpec {
        ParameterSpec {
            id: ParamId::of_term("term", "p"),
            unit: "1",
            nominal,
            support,
            default_prior: Prior::HalfNormal { scale: 2.0 },
        }
    }

    #[test]
    fn a_nominal_value_on_the_boundary_starts_at_the_prior_median() {
        let p = CalibratedParameter::new(&spec(0.0, Support::Positive), None).unwrap();
        assert_eq!(p.transform, Transform::Log);
        assert!((p.start - 0.674_489_750_196_081_7 * 2.0).abs() < 1e-12);
        assert_eq!(p.coordinate_name(), "log_term__p");
        assert_eq!(p.output_name(), "term__p");
        // A uniform prior bounds a positive parameter on both sides.
        let u = CalibratedParameter::new(
            &spec(0.5, Support::Positive),
            Some(Prior::Uniform {
                lower: 0.0,
                upper: 2.0,
            }),
        )
        .unwrap();
        assert_eq!(
            u.transform,
            Transform::Logit {
                lower: 0.0,
                upper: 2.0
            }
        );
        assert_eq!(u.start, 0.5);
    }

    #[test]
    fn the_density_in_u_has_the_derivatives_it_claims() {
        let h = 1e-5;
        for (p, u) in [
            (
                CalibratedParameter::new(&spec(0.0, Support::Positive), None).unwrap(),
                0.3,
            ),
            (
                CalibratedParameter::new(
                    &spec(1.0, Support::Positive),
                    Some(Prior::LogNormal {
                        median: 1.0,
                        sigma: 0.5,
                    }),
                )
                .unwrap(),
                -0.4,
            ),
            (
                CalibratedParameter::new(
                    &spec(1.0, Support::Positive),
                    Some(Prior::Uniform {
                        lower: 0.0,
                        upper: 3.0,
                    }),
                )
                .unwrap(),
                0.8,
            ),
            (
                CalibratedParameter::new(
                    &spec(1.0, Support::Positive),
                    Some(Prior::Normal { mean: 1.0, sd: 0.3 }),
                )
                .unwrap(),
                0.1,
            ),
        ] {
            let (a, b, c) = (p.at(u).unwrap(), p.at(u + h).unwrap(), p.at(u - h).unwrap());
            let fd = (b.log_density - c.log_density) / (2.0 * h);
            assert!((fd - a.gradient).abs() < 1e-6, "{p:?}");
            let fd2 = -(b.gradient - c.gradient) / (2.0 * h);
            assert!((fd2 - a.curvature).abs() < 1e-5, "{p:?}");
            assert!(a.metric >= 0.0);
        }
    }
}
