//! A winding that heats: R → R·(1 + α·E), with the dissipated energy E a new state,
//! dE/dt = R(1 + αE)·I², E(0) = 0.

use super::{Balance, Magnitudes, PRIOR_SHARE, PhysicsTerm, Site, TermParam, TermState, positive};
use crate::motor::Scalar;
use crate::parameter::Prior;

#[derive(Clone, Debug, PartialEq)]
pub struct ResistanceHeating;

/// One sd: R up by a tenth after the heat of one start-up.
fn prior(m: &Magnitudes) -> Prior {
    Prior::HalfNormal {
        scale: PRIOR_SHARE / m.energy,
    }
}

impl PhysicsTerm for ResistanceHeating {
    const NAME: &'static str = "resistance_heating";
    const EQUATION: &'static str = "R → R·(1 + α·E), dE/dt = R(1 + αE)·I², E(0) = 0";
    const PARAMS: &'static [TermParam] = &[TermParam {
        key: "alpha",
        unit: "1/J",
        default: 0.0,
        support: positive,
        prior,
    }];
    const STATES: &'static [TermState] = &[TermState {
        name: "E",
        initial: 0.0,
    }];

    fn with_settings(_: &[f64]) -> Result<Self, String> {
        Ok(Self)
    }

    fn contribute<D: Scalar>(&self, site: &Site<D>, b: &mut Balance<D>) {
        b.resistance *= site.params[0] * site.states[0] + 1.0;
    }

    fn derivatives<D: Scalar>(&self, site: &Site<D>, b: &Balance<D>, d: &mut [D]) {
        d[0] = b.resistance * site.current * site.current;
    }
}
