//! Armature reaction weakening the field at high current: c_g → c_g/(1 + κ|I|) in the torque
//! term (the back-EMF is left alone). κ = 1/I_sat, so κ = 0 is "no effect" and lies inside the
//! support's closure, where I_sat would be infinite.

use super::{Balance, Magnitudes, PRIOR_SHARE, PhysicsTerm, Site, TermParam, positive};
use crate::motor::Scalar;
use crate::parameter::Prior;

#[derive(Clone, Debug, PartialEq)]
pub struct ArmatureReaction;

/// One sd: the torque constant down by a tenth at the stall current.
fn prior(m: &Magnitudes) -> Prior {
    Prior::HalfNormal {
        scale: PRIOR_SHARE / m.current,
    }
}

impl PhysicsTerm for ArmatureReaction {
    const NAME: &'static str = "armature_reaction";
    const EQUATION: &'static str = "c_g → c_g/(1 + κ|I|) in the torque term, κ = 1/I_sat";
    const PARAMS: &'static [TermParam] = &[TermParam {
        key: "kappa",
        unit: "1/A",
        default: 0.0,
        support: positive,
        prior,
    }];

    fn with_settings(_: &[f64]) -> Result<Self, String> {
        Ok(Self)
    }

    fn contribute<D: Scalar>(&self, site: &Site<D>, b: &mut Balance<D>) {
        b.torque_constant /= site.params[0] * site.current.abs() + 1.0;
    }
}
