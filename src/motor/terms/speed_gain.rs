//! A speed sensor with a gain error: measured ω = (1 + g)·ω.

use super::{PhysicsTerm, TermParam, real, relative_prior};
use crate::motor::Scalar;

#[derive(Clone, Debug, PartialEq)]
pub struct SpeedGain;

impl PhysicsTerm for SpeedGain {
    const NAME: &'static str = "speed_gain";
    const EQUATION: &'static str = "measured ω = (1 + g)·ω";
    const PARAMS: &'static [TermParam] = &[TermParam {
        key: "g",
        unit: "1",
        default: 0.0,
        support: real,
        prior: relative_prior,
    }];

    fn with_settings(_: &[f64]) -> Result<Self, String> {
        Ok(Self)
    }

    fn measure<D: Scalar>(&self, p: &[D], channels: &mut [D]) {
        channels[1] *= p[0] + 1.0;
    }
}
