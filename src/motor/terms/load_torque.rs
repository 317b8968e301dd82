//! A constant load torque opposing the drive: −T_0 on the right of J dω/dt (the base model's
//! T_L of schema-1 files, made a term).

use super::{Balance, Magnitudes, PRIOR_SHARE, PhysicsTerm, Site, TermParam, real};
use crate::motor::Scalar;
use crate::parameter::Prior;

#[derive(Clone, Debug, PartialEq)]
pub struct LoadTorque;

/// Either sign; one sd is a tenth of the stall torque.
fn prior(m: &Magnitudes) -> Prior {
    Prior::Normal {
        mean: 0.0,
        sd: PRIOR_SHARE * m.torque,
    }
}

impl PhysicsTerm for LoadTorque {
    const NAME: &'static str = "load_torque";
    const EQUATION: &'static str = "J dω/dt += −T_0";
    const MECHANICAL: bool = true;
    const PARAMS: &'static [TermParam] = &[TermParam {
        key: "T_0",
        unit: "N·m",
        default: 0.0,
        support: real,
        prior,
    }];

    fn with_settings(_: &[f64]) -> Result<Self, String> {
        Ok(Self)
    }

    fn contribute<D: Scalar>(&self, site: &Site<D>, b: &mut Balance<D>) {
        b.torque -= site.params[0];
    }
}
