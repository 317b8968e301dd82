//! A drive whose input acts late: the supply voltage the motor sees at t is what was applied at
//! t − τ (a dead time of the drive or its command path).
//!
//! The input is a sum of steps: the switch-on at t = 0 (from 0 V: the model starts from its
//! initial state, at rest by default) and each change of a held input. Delayed hard steps have
//! no derivative in τ, so each delayed step is a smooth ramp (a quintic smoothstep, C²) centred
//! on the delayed time, of width `width` (a setting, 1 ms) — or 2τ while τ < width/2, so that a
//! ramp never begins before its step: the delay stays causal, and τ = 0 is exactly the input as
//! recorded. It acts on the voltage-driven base only: on a drive base the input is a sampled
//! series integrated with steps fixed to the samples, and `position_loop` has the drive's own
//! delay in whole samples (`drive.delay_samples`).

use super::{
    InputSteps, Magnitudes, PRIOR_SHARE, PhysicsTerm, TermParam, TermSetting, positive,
    positive_setting,
};
use crate::motor::Scalar;
use crate::parameter::Prior;

#[derive(Clone, Debug, PartialEq)]
pub struct InputDelay {
    /// Width of each delayed step's ramp [s].
    pub width: f64,
}

/// One sd: a tenth of the electrical time constant L/R, the fastest response the input drives.
fn prior(m: &Magnitudes) -> Prior {
    Prior::HalfNormal {
        scale: PRIOR_SHARE * m.electrical_time,
    }
}

/// 0 at z = 0, 1 at z = 1, with zero first and second derivatives at both ends.
fn smoothstep<D: Scalar>(z: D) -> D {
    z * z * z * (z * (z * 6.0 - 15.0) + 10.0)
}

impl PhysicsTerm for InputDelay {
    const NAME: &'static str = "input_delay";
    const EQUATION: &'static str = "U(t) → U(t − τ) (each step a ramp of width `width`)";
    const NOT_ON_DRIVES: &'static str =
        "delays the supply voltage (a drive base's input is its own, sampled)";
    const PARAMS: &'static [TermParam] = &[TermParam {
        key: "tau",
        unit: "s",
        default: 0.0,
        support: positive,
        prior,
    }];
    const SETTINGS: &'static [TermSetting] = &[TermSetting {
        key: "width",
        unit: "s",
        default: 1e-3,
        speed_share: None,
        choices: &[],
    }];

    fn with_settings(s: &[f64]) -> Result<Self, String> {
        Ok(Self {
            width: positive_setting(Self::NAME, "width", s[0])?,
        })
    }

    fn settings(&self) -> Vec<f64> {
        vec![self.width]
    }

    fn input<D: Scalar>(&self, params: &[D], t: f64, input: &InputSteps<D>, u: &mut D) {
        let tau = params[0];
        if tau.re() <= 0.0 {
            return;
        }
        // Half the ramp's width: each step at c rises over [c + τ − a, c + τ + a].
        let a = if tau.re() < 0.5 * self.width {
            tau
        } else {
            D::from(0.5 * self.width)
        };
        let (begun, done) = ((-tau + a + t).re(), (-tau - a + t).re());
        // Steps whose ramp is over count in full; those within it in part.
        let mut value = input.value_at(done);
        for (c, height) in input.steps_within(done, begun) {
            value += height * smoothstep((-tau + a + (t - c)) / (a * 2.0));
        }
        *u = value;
    }
}
