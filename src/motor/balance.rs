//! The two balances of the motor, written once for every base and for the missing torque:
//!
//! - the voltage balance of equation (3), L dI/dt = U − R·I − c_m·ω + Σ voltage;
//! - the torque balance of equation (4), J dω/dt = c_g·I − d·ω + Σ torque, where I is the
//!   drive's input on a drive base (a recorded current or a controller output).
//!
//! Each is generic over the number type, as is everything the integrator calls. The Σ are what
//! the active terms add, with R and c_g as the terms leave them ([`Balance`]); the plain motor
//! passes `None`, not a zero sum: adding a zero costs a dual number a full addition, and the
//! plain solve is the hot path.

use super::{MotorModel, MotorParam, Scalar};

/// The parameters as the right-hand side uses them, extracted once per solve (the divisions by
/// L and J become multiplications), after the terms that rescale a constant have acted.
#[derive(Clone, Copy, Debug)]
pub struct Coefficients<D> {
    pub resistance: D,
    pub back_emf_constant: D,
    pub torque_constant: D,
    pub viscous_friction: D,
    pub inverse_inductance: D,
    pub inverse_inertia: D,
}

/// The two balances at one instant, as terms amend them: L dI/dt = U − R·I − c_m·ω + voltage
/// and J dω/dt = c_g·I − d·ω + torque.
#[derive(Clone, Copy, Debug)]
pub struct Balance<D> {
    pub resistance: D,
    pub torque_constant: D,
    pub voltage: D,
    pub torque: D,
}

/// Where a term is evaluated: the state, its own parameters and its own states.
pub struct Site<'a, D> {
    pub t: f64,
    /// Start of the interval between breakpoints being integrated: a hard step at a breakpoint
    /// is decided by it, since the step that ends on the breakpoint still sees the old side.
    pub segment_start: f64,
    pub current: D,
    pub speed: D,
    /// The supply voltage U as the terms' `input` hooks leave it (zero on a drive base, which
    /// has none).
    pub voltage: D,
    /// The constants as the terms' `adjust` left them (J is the rotor's own inertia when a
    /// term moves part of it behind a spring).
    pub coefficients: &'a Coefficients<D>,
    pub params: &'a [D],
    pub states: &'a [D],
}

/// L dI/dt = U − R·I − c_m·ω + Σ voltage (equation 3): the voltage across the inductance.
#[inline(always)]
pub fn voltage_balance<D: Scalar>(
    c: &Coefficients<D>,
    terms: Option<&Balance<D>>,
    voltage: D,
    current: D,
    speed: D,
) -> D {
    let resistance = terms.map_or(c.resistance, |b| b.resistance);
    let balance = voltage - resistance * current - c.back_emf_constant * speed;
    terms.map_or(balance, |b| balance + b.voltage)
}

/// J dω/dt = c_g·I − d·ω + Σ torque (equation 4): the torque that accelerates the rotor. The
/// load torque opposes motion (the paper writes +T_L but only ever uses T_L = 0).
#[inline(always)]
pub fn torque_balance<D: Scalar>(
    c: &Coefficients<D>,
    terms: Option<&Balance<D>>,
    current: D,
    speed: D,
) -> D {
    let torque_constant = terms.map_or(c.torque_constant, |b| b.torque_constant);
    let balance = torque_constant * current - c.viscous_friction * speed;
    terms.map_or(balance, |b| balance + b.torque)
}

impl MotorModel {
    /// The constants the right-hand side uses at a parameter vector, after the terms that
    /// rescale one (torque constant, extra viscous friction) have acted: once per solve.
    pub fn coefficients<D: Scalar>(&self, p: &[D]) -> Coefficients<D> {
        let mut coefficients = base_coefficients(p);
        for (k, t) in self.terms.iter().enumerate() {
            t.term.adjust(
                &p[self.param_offsets[k]..self.param_offsets[k + 1]],
                &mut coefficients,
            );
        }
        coefficients
    }

    /// Every term's contribution at one instant; `site(k)` is where term k is evaluated.
    #[inline]
    pub(super) fn balance<'a, D: Scalar + 'a>(
        &self,
        c: &Coefficients<D>,
        site: &impl Fn(usize) -> Site<'a, D>,
    ) -> Balance<D> {
        let mut balance = Balance {
            resistance: c.resistance,
            torque_constant: c.torque_constant,
            voltage: D::from(0.0),
            torque: D::from(0.0),
        };
        for (k, active) in self.terms.iter().enumerate() {
            active.term.contribute(&site(k), &mut balance);
        }
        balance
    }

    /// The derivatives of the terms' own states, once every term has contributed to `balance`.
    #[inline]
    pub(super) fn term_derivatives<'a, D: Scalar + 'a>(
        &self,
        site: &impl Fn(usize) -> Site<'a, D>,
        balance: &Balance<D>,
        dy: &mut [D],
    ) {
        for (k, active) in self.terms.iter().enumerate() {
            let states = self.state_offsets[k]..self.state_offsets[k + 1];
            if !states.is_empty() {
                active.term.derivatives(&site(k), balance, &mut dy[states]);
            }
        }
    }

    /// The torque balance of the mechanical equation at the model's values, from measured
    /// series: c_g·u − d·ω + Σ term torques − J·ω̇ at every sample, i.e. the torque the model
    /// misses there (the inverse-model residual; u is the current or controller output).
    pub fn missing_torque(
        &self,
        times: &[f64],
        input: &[f64],
        speed: &[f64],
        acceleration: &[f64],
    ) -> Vec<f64> {
        let p = self.parameter_values();
        let c = self.coefficients(&p);
        (0..times.len())
            .map(|i| {
                let site = |k: usize| Site {
                    t: times[i],
                    segment_start: times[i],
                    current: input[i],
                    speed: speed[i],
                    voltage: 0.0,
                    coefficients: &c,
                    params: &p[self.param_offsets[k]..self.param_offsets[k + 1]],
                    states: &[],
                };
                let balance = self.balance(&c, &site);
                torque_balance(&c, Some(&balance), input[i], speed[i])
                    - acceleration[i] / c.inverse_inertia
            })
            .collect()
    }
}

/// The base's constants as the right-hand side reads them, before a term rescales one.
fn base_coefficients<D: Scalar>(p: &[D]) -> Coefficients<D> {
    use MotorParam::*;
    Coefficients {
        resistance: p[Resistance as usize],
        back_emf_constant: p[BackEmfConstant as usize],
        torque_constant: p[TorqueConstant as usize],
        viscous_friction: p[ViscousFriction as usize],
        inverse_inductance: p[Inductance as usize].recip(),
        inverse_inertia: p[Inertia as usize].recip(),
    }
}
