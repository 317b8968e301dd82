//! Viscous friction that differs between the two directions of motion: −k_a·|ω| on the right of
//! J dω/dt, so that the viscous coefficient is d + k_a forwards and d − k_a backwards (a worn
//! screw, a seal that drags one way). |ω| is smoothed as ω·tanh(ω/ω_s), like Coulomb
//! friction's sign. A direction-dependent Coulomb level is not a separate term: over moving
//! samples it is a constant, which `load_torque` already is.

use super::{
    Balance, Magnitudes, PRIOR_SHARE, PhysicsTerm, Site, TermParam, TermSetting, positive_setting,
    real, tanh,
};
use crate::motor::Scalar;
use crate::parameter::Prior;

#[derive(Clone, Debug, PartialEq)]
pub struct AsymmetricFriction {
    pub omega_s: f64,
}

/// Either sign; one sd is a tenth of the stall torque at the no-load speed, as for
/// `viscous_friction`.
fn prior(m: &Magnitudes) -> Prior {
    Prior::Normal {
        mean: 0.0,
        sd: PRIOR_SHARE * m.torque / m.speed,
    }
}

impl PhysicsTerm for AsymmetricFriction {
    const NAME: &'static str = "asymmetric_friction";
    const EQUATION: &'static str = "J dω/dt += −k_a·ω·tanh(ω/ω_s)";
    const MECHANICAL: bool = true;
    const PARAMS: &'static [TermParam] = &[TermParam {
        key: "k_a",
        unit: "N·m·s/rad",
        default: 0.0,
        support: real,
        prior,
    }];
    const SETTINGS: &'static [TermSetting] = &[TermSetting {
        key: "omega_s",
        unit: "rad/s",
        default: 1.0,
        speed_share: Some(0.01),
        choices: &[],
    }];

    fn with_settings(s: &[f64]) -> Result<Self, String> {
        Ok(Self {
            omega_s: positive_setting(Self::NAME, "omega_s", s[0])?,
        })
    }

    fn settings(&self) -> Vec<f64> {
        vec![self.omega_s]
    }

    fn contribute<D: Scalar>(&self, site: &Site<D>, b: &mut Balance<D>) {
        b.torque -= site.params[0] * site.speed * tanh(site.speed / self.omega_s);
    }
}
