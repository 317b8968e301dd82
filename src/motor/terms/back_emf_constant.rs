//! A back-EMF constant off by a factor: c_m → c_m·(1 + k).

use super::{Coefficients, PhysicsTerm, TermParam, relative_param};
use crate::motor::Scalar;

#[derive(Clone, Debug, PartialEq)]
pub struct BackEmfConstant;

impl PhysicsTerm for BackEmfConstant {
    const NAME: &'static str = "back_emf_constant";
    const EQUATION: &'static str = "c_m → c_m·(1 + k)";
    const PARAMS: &'static [TermParam] = &[relative_param("k")];

    fn with_settings(_: &[f64]) -> Result<Self, String> {
        Ok(Self)
    }

    fn adjust<D: Scalar>(&self, p: &[D], c: &mut Coefficients<D>) {
        c.back_emf_constant *= p[0] + 1.0;
    }
}
