//! Drag growing with the square of the speed: −k_q·ω|ω| on the right of J dω/dt.

use super::{Balance, Magnitudes, PRIOR_SHARE, PhysicsTerm, Site, TermParam, positive};
use crate::motor::Scalar;
use crate::parameter::Prior;

#[derive(Clone, Debug, PartialEq)]
pub struct QuadraticDrag;

/// One sd: a tenth of the stall torque at the no-load speed.
fn prior(m: &Magnitudes) -> Prior {
    Prior::HalfNormal {
        scale: PRIOR_SHARE * m.torque / (m.speed * m.speed),
    }
}

impl PhysicsTerm for QuadraticDrag {
    const NAME: &'static str = "quadratic_drag";
    const EQUATION: &'static str = "J dω/dt += −k_q·ω|ω|";
    const MECHANICAL: bool = true;
    const PARAMS: &'static [TermParam] = &[TermParam {
        key: "k_q",
        unit: "N·m·s²/rad²",
        default: 0.0,
        support: positive,
        prior,
    }];

    fn with_settings(_: &[f64]) -> Result<Self, String> {
        Ok(Self)
    }

    fn contribute<D: Scalar>(&self, site: &Site<D>, b: &mut Balance<D>) {
        b.torque -= site.params[0] * site.speed * site.speed.abs();
    }
}
