//! A torque constant off by a factor: c_g → c_g·(1 + k) (the paper's φ = 0.9 is k = 1/9).

use super::{Coefficients, PhysicsTerm, TermParam, relative_param};
use crate::motor::Scalar;

#[derive(Clone, Debug, PartialEq)]
pub struct TorqueConstant;

impl PhysicsTerm for TorqueConstant {
    const NAME: &'static str = "torque_constant";
    const EQUATION: &'static str = "c_g → c_g·(1 + k)";
    const MECHANICAL: bool = true;
    const PARAMS: &'static [TermParam] = &[relative_param("k")];

    fn with_settings(_: &[f64]) -> Result<Self, String> {
        Ok(Self)
    }

    fn adjust<D: Scalar>(&self, p: &[D], c: &mut Coefficients<D>) {
        c.torque_constant *= p[0] + 1.0;
    }
}
