//! More viscous friction than the model holds: d → d + Dd.

use super::{Coefficients, Magnitudes, PRIOR_SHARE, PhysicsTerm, TermParam, positive};
use crate::motor::Scalar;
use crate::parameter::Prior;

#[derive(Clone, Debug, PartialEq)]
pub struct ViscousFriction;

/// One sd: a tenth of the stall torque at the no-load speed.
fn prior(m: &Magnitudes) -> Prior {
    Prior::HalfNormal {
        scale: PRIOR_SHARE * m.torque / m.speed,
    }
}

impl PhysicsTerm for ViscousFriction {
    const NAME: &'static str = "viscous_friction";
    const EQUATION: &'static str = "d → d + Dd";
    const MECHANICAL: bool = true;
    const PARAMS: &'static [TermParam] = &[TermParam {
        key: "Dd",
        unit: "N·m·s/rad",
        default: 0.0,
        support: positive,
        prior,
    }];

    fn with_settings(_: &[f64]) -> Result<Self, String> {
        Ok(Self)
    }

    fn adjust<D: Scalar>(&self, p: &[D], c: &mut Coefficients<D>) {
        c.viscous_friction += p[0];
    }
}
