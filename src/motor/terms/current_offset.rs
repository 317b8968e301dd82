//! An offset of the current sensor: measured I = I + b_I.

use super::{Magnitudes, PRIOR_SHARE, PhysicsTerm, Sample, TermParam, real};
use crate::motor::Scalar;
use crate::parameter::Prior;

#[derive(Clone, Debug, PartialEq)]
pub struct CurrentOffset;

/// Either sign; one sd is a tenth of the stall current.
fn prior(m: &Magnitudes) -> Prior {
    Prior::Normal {
        mean: 0.0,
        sd: PRIOR_SHARE * m.current,
    }
}

impl PhysicsTerm for CurrentOffset {
    const NAME: &'static str = "current_offset";
    const EQUATION: &'static str = "measured I = I + b_I";
    const PARAMS: &'static [TermParam] = &[TermParam {
        key: "b_I",
        unit: "A",
        default: 0.0,
        support: real,
        prior,
    }];

    fn with_settings(_: &[f64]) -> Result<Self, String> {
        Ok(Self)
    }

    fn measure<D: Scalar>(&self, p: &[D], _: &[D], _: Sample<D>, channels: &mut [D]) {
        channels[0] += p[0];
    }
}
