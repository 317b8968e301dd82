//! A load torque switched on during the record: −T_s·H(t − t_s) on the right of J dω/dt.
//!
//! A hard step has no derivative in t_s, so by default the step is a logistic ramp of a stated
//! width (a setting, 1 ms: about one sample of the paper's records), which makes t_s
//! calibratable. Width 0 gives the hard step with a breakpoint at t_s, which the integrator
//! lands on exactly; t_s is then fixed (profile it over a grid of model files).

use super::{
    Balance, Magnitudes, PRIOR_SHARE, PhysicsTerm, Site, TermParam, TermSetting, logistic, real,
};
use crate::motor::Scalar;
use crate::parameter::{Prior, Support};

#[derive(Clone, Debug, PartialEq)]
pub struct LoadStep {
    /// Width of the logistic ramp [s]; 0 for a hard step.
    pub width: f64,
}

/// Either sign; one sd is a tenth of the stall torque.
fn torque_prior(m: &Magnitudes) -> Prior {
    Prior::Normal {
        mean: 0.0,
        sd: PRIOR_SHARE * m.torque,
    }
}

/// Anywhere in the record.
fn time_support(m: &Magnitudes) -> Support {
    Support::Bounded {
        lower: 0.0,
        upper: m.duration,
    }
}

fn time_prior(m: &Magnitudes) -> Prior {
    Prior::Uniform {
        lower: 0.0,
        upper: m.duration,
    }
}

impl PhysicsTerm for LoadStep {
    const NAME: &'static str = "load_step";
    const EQUATION: &'static str = "J dω/dt += −T_s·H(t − t_s) (logistic of width `width`)";
    const MECHANICAL: bool = true;
    const RECORD_TIME: bool = true;
    const PARAMS: &'static [TermParam] = &[
        TermParam {
            key: "T_s",
            unit: "N·m",
            default: 0.0,
            support: real,
            prior: torque_prior,
        },
        TermParam {
            key: "t_s",
            unit: "s",
            default: 0.0,
            support: time_support,
            prior: time_prior,
        },
    ];
    const SETTINGS: &'static [TermSetting] = &[TermSetting {
        key: "width",
        unit: "s",
        default: 1e-3,
        speed_share: None,
        choices: &[],
    }];

    fn with_settings(s: &[f64]) -> Result<Self, String> {
        let width = s[0];
        if !(width >= 0.0 && width.is_finite()) {
            return Err(format!("load_step.width = {width} must be ≥ 0"));
        }
        Ok(Self { width })
    }

    fn settings(&self) -> Vec<f64> {
        vec![self.width]
    }

    fn check_calibrated(&self, key: &str) -> Result<(), String> {
        if key == "t_s" && self.width == 0.0 {
            return Err(
                "load_step.t_s cannot be calibrated with a hard step (width = 0): give the \
                 step a width"
                    .into(),
            );
        }
        Ok(())
    }

    fn contribute<D: Scalar>(&self, site: &Site<D>, b: &mut Balance<D>) {
        let (torque, switch_time) = (site.params[0], site.params[1]);
        if self.width == 0.0 {
            if site.segment_start >= switch_time.re() {
                b.torque -= torque;
            }
        } else {
            b.torque -= torque * logistic((-switch_time + site.t) / self.width);
        }
    }

    fn breakpoints(&self, params: &[f64]) -> Vec<f64> {
        if self.width == 0.0 {
            vec![params[1]]
        } else {
            Vec::new()
        }
    }
}
