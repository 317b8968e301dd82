//! A voltage drop that does not grow with the current (brushes, a diode, a driver stage):
//! −U_b·tanh(I/I_s) on the right of L dI/dt, smoothed through zero current by the setting I_s.

use super::{
    Balance, Magnitudes, PRIOR_SHARE, PhysicsTerm, Site, TermParam, TermSetting, positive,
    positive_setting, tanh,
};
use crate::motor::Scalar;
use crate::parameter::Prior;

#[derive(Clone, Debug, PartialEq)]
pub struct VoltageDrop {
    pub current_scale: f64,
}

/// One sd: a tenth of the supply voltage.
fn prior(m: &Magnitudes) -> Prior {
    Prior::HalfNormal {
        scale: PRIOR_SHARE * m.voltage,
    }
}

impl PhysicsTerm for VoltageDrop {
    const NAME: &'static str = "voltage_drop";
    const EQUATION: &'static str = "L dI/dt += −U_b·tanh(I/I_s)";
    const PARAMS: &'static [TermParam] = &[TermParam {
        key: "U_b",
        unit: "V",
        default: 0.0,
        support: positive,
        prior,
    }];
    const SETTINGS: &'static [TermSetting] = &[TermSetting {
        key: "I_s",
        unit: "A",
        default: 1.0,
        speed_share: None,
        choices: &[],
    }];

    fn with_settings(s: &[f64]) -> Result<Self, String> {
        Ok(Self {
            current_scale: positive_setting(Self::NAME, "I_s", s[0])?,
        })
    }

    fn settings(&self) -> Vec<f64> {
        vec![self.current_scale]
    }

    fn contribute<D: Scalar>(&self, site: &Site<D>, b: &mut Balance<D>) {
        b.voltage -= site.params[0] * tanh(site.current / self.current_scale);
    }
}
