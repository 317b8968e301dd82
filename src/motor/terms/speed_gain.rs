//! A speed sensor with a gain error: measured ω = (1 + g)·ω.

use super::{PhysicsTerm, Sample, TermParam, relative_param};
use crate::motor::Scalar;

#[derive(Clone, Debug, PartialEq)]
pub struct SpeedGain;

impl PhysicsTerm for SpeedGain {
    const NAME: &'static str = "speed_gain";
    const EQUATION: &'static str = "measured ω = (1 + g)·ω";
    const PARAMS: &'static [TermParam] = &[relative_param("g")];

    fn with_settings(_: &[f64]) -> Result<Self, String> {
        Ok(Self)
    }

    fn measure<D: Scalar>(&self, p: &[D], _: &[D], _: Sample<D>, channels: &mut [D]) {
        channels[1] *= p[0] + 1.0;
    }
}
