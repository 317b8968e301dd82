//! Coulomb (dry) friction, smoothed through zero speed: −T_c·tanh(ω/ω_s) on the right of
//! J dω/dt. The smoothing keeps the right-hand side differentiable for the integrator and the
//! sensitivities; ω_s is a setting, small against the speeds the motor runs at.

use super::{
    Balance, Magnitudes, PRIOR_SHARE, PhysicsTerm, Site, TermParam, TermSetting, positive,
    positive_setting, tanh,
};
use crate::motor::Scalar;
use crate::parameter::Prior;

#[derive(Clone, Debug, PartialEq)]
pub struct CoulombFriction {
    pub omega_s: f64,
}

/// One sd: a tenth of the stall torque.
fn prior(m: &Magnitudes) -> Prior {
    Prior::HalfNormal {
        scale: PRIOR_SHARE * m.torque,
    }
}

impl PhysicsTerm for CoulombFriction {
    const NAME: &'static str = "coulomb_friction";
    const EQUATION: &'static str = "J dω/dt += −T_c·tanh(ω/ω_s)";
    const MECHANICAL: bool = true;
    const PARAMS: &'static [TermParam] = &[TermParam {
        key: "T_c",
        unit: "N·m",
        default: 0.0,
        support: positive,
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
        b.torque -= site.params[0] * tanh(site.speed / self.omega_s);
    }
}
