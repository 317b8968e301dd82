//! The load on a torsion spring: a share s of the inertia J sits behind a spring and damper,
//! and the speed is measured on the motor's side. With the twist φ and the load's speed ω_l as
//! new states, the reduced inertia μ = s(1 − s)·J, the resonance ω_r = 2π·f_r (= √(k/μ)) and
//! the damping ratio ζ (= c/(2μω_r)):
//!
//! (1 − s)·J dω/dt = [the torque balance] − μ·(ω_r²·φ + 2ζω_r·(ω − ω_l)),
//! dφ/dt = ω − ω_l,   dω_l/dt = (1 − s)·(ω_r²·φ + 2ζω_r·(ω − ω_l)).
//!
//! s = 0 is the rigid motor exactly (the spring then carries no inertia and exerts no torque,
//! while ω_l follows ω without acting back), and the equations stay regular there, so the
//! derivative in s is finite at the absent value. Every other torque (friction, a load) acts on
//! the motor's side. The voltage-driven base only: a resonance near the sampling rate is not
//! resolved by a drive base's steps fixed to the samples.

use super::{Balance, Coefficients, Magnitudes, PhysicsTerm, Site, TermParam, TermState, positive};
use crate::motor::Scalar;
use crate::parameter::{Prior, Support};

#[derive(Clone, Debug, PartialEq)]
pub struct CompliantCoupling;

fn share_support(_: &Magnitudes) -> Support {
    Support::Bounded {
        lower: 0.0,
        upper: 1.0,
    }
}

/// Any share of the inertia alike.
fn share_prior(_: &Magnitudes) -> Prior {
    Prior::Uniform {
        lower: 0.0,
        upper: 1.0,
    }
}

/// Centred on the electrical corner frequency R/(2πL), the fastest the motor itself responds,
/// a factor e either way per sd.
fn frequency_prior(m: &Magnitudes) -> Prior {
    Prior::LogNormal {
        median: 1.0 / (2.0 * std::f64::consts::PI * m.electrical_time),
        sigma: 1.0,
    }
}

/// A lightly damped coupling (ζ around 0.1), a factor e either way per sd.
fn damping_prior(_: &Magnitudes) -> Prior {
    Prior::LogNormal {
        median: 0.1,
        sigma: 1.0,
    }
}

/// The spring's and damper's torque per unit reduced inertia: ω_r²·φ + 2ζω_r·(ω − ω_l).
fn spring<D: Scalar>(params: &[D], states: &[D], speed: D) -> D {
    let omega_r = params[1] * (2.0 * std::f64::consts::PI);
    omega_r * omega_r * states[0] + omega_r * params[2] * 2.0 * (speed - states[1])
}

impl PhysicsTerm for CompliantCoupling {
    const NAME: &'static str = "compliant_coupling";
    const EQUATION: &'static str = "(1 − s)J dω/dt = … − s(1 − s)J·(ω_r²φ + 2ζω_r(ω − ω_l)), \
                                    dφ/dt = ω − ω_l, dω_l/dt = (1 − s)(ω_r²φ + 2ζω_r(ω − ω_l))";
    const NOT_ON_DRIVES: &'static str =
        "rings faster than the steps fixed to a drive base's samples resolve";
    const PARAMS: &'static [TermParam] = &[
        TermParam {
            key: "s",
            unit: "1",
            default: 0.0,
            support: share_support,
            prior: share_prior,
        },
        TermParam {
            key: "f_r",
            unit: "Hz",
            default: 100.0,
            support: positive,
            prior: frequency_prior,
        },
        TermParam {
            key: "zeta",
            unit: "1",
            default: 0.1,
            support: positive,
            prior: damping_prior,
        },
    ];
    const STATES: &'static [TermState] = &[
        TermState {
            name: "phi",
            initial: 0.0,
        },
        TermState {
            name: "omega_l",
            initial: 0.0,
        },
    ];

    fn with_settings(_: &[f64]) -> Result<Self, String> {
        Ok(Self)
    }

    /// J → (1 − s)·J: the motor's side accelerates alone (a division by 1, exact, at s = 0).
    fn adjust<D: Scalar>(&self, params: &[D], c: &mut Coefficients<D>) {
        c.inverse_inertia /= -params[0] + 1.0;
    }

    /// Untwisted, the load turning with the motor.
    fn initial<D: Scalar>(&self, _: &[D], base: &[D], states: &mut [D]) {
        states[1] = base[1];
    }

    fn contribute<D: Scalar>(&self, site: &Site<D>, b: &mut Balance<D>) {
        let share = site.params[0];
        // μ = s·(1 − s)·J = s times the motor's side's own inertia, as `adjust` left it.
        let mu = share / site.coefficients.inverse_inertia;
        b.torque -= mu * spring(site.params, site.states, site.speed);
    }

    fn derivatives<D: Scalar>(&self, site: &Site<D>, _: &Balance<D>, d: &mut [D]) {
        let share = site.params[0];
        d[0] = site.speed - site.states[1];
        d[1] = (-share + 1.0) * spring(site.params, site.states, site.speed);
    }
}
