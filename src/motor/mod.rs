//! The DC motor of §2 of the paper: its parameters, its input voltage, and the right-hand side of
//! equations (3)–(4) written once, generic over the number type so that the same code gives values
//! (`f64`) and forward sensitivities (num-dual numbers).
//!
//! The model is data: a parameter vector with names, a state vector, channels it measures. Physics
//! terms that the missing-physics diagnosis adds later append parameters and states to these
//! vectors instead of copying the motor.

pub mod closed_form;
mod input;
mod parameters;

pub use input::VoltageInput;
pub use parameters::{MotorParam, MotorParameters};

use num_dual::DualNum;

use crate::ode::OdeSystem;

/// The channels the motor's measurement map produces, in output order.
pub const MOTOR_CHANNELS: [&str; 2] = ["I", "omega"];

/// A motor model: nominal parameters and the input it is driven with.
#[derive(Clone, Debug)]
pub struct MotorModel {
    pub nominal: MotorParameters,
    pub input: VoltageInput,
}

impl MotorModel {
    pub fn new(nominal: MotorParameters, input: VoltageInput) -> Self {
        Self { nominal, input }
    }

    /// Names of the model's parameter vector, in the order of [`MotorModel::parameter_values`].
    pub fn parameter_names(&self) -> Vec<&'static str> {
        MotorParam::ALL.iter().map(|p| p.key()).collect()
    }

    /// The nominal values of the full parameter vector.
    pub fn parameter_values(&self) -> Vec<f64> {
        MotorParam::ALL
            .iter()
            .map(|&p| self.nominal.get(p))
            .collect()
    }

    pub fn parameter_index(&self, name: &str) -> Option<usize> {
        MotorParam::ALL.iter().position(|p| p.key() == name)
    }

    pub fn n_states(&self) -> usize {
        2
    }

    pub fn channels(&self) -> &'static [&'static str] {
        &MOTOR_CHANNELS
    }

    /// Times at which the right-hand side jumps: where a held input changes its value.
    pub fn breakpoints(&self) -> Vec<f64> {
        self.input.breakpoints()
    }

    pub fn initial_state<D: DualNum<Primitive = f64> + Copy>(&self, p: &[D], y0: &mut [D]) {
        y0[0] = p[MotorParam::InitialCurrent as usize];
        y0[1] = p[MotorParam::InitialSpeed as usize];
    }

    /// Equations (3)–(4): L dI/dt = −R I − c_m ω + U and J dω/dt = c_g I − d ω − T_L, with the load
    /// torque opposing motion (the paper writes +T_L but only ever uses T_L = 0).
    #[inline]
    pub fn rhs<D: DualNum<Primitive = f64> + Copy>(
        &self,
        voltage: D,
        y: &[D],
        c: &Coefficients<D>,
        dy: &mut [D],
    ) {
        let (current, speed) = (y[0], y[1]);
        let electrical = voltage - c.resistance * current - c.back_emf_constant * speed;
        let mechanical = c.torque_constant * current - c.viscous_friction * speed - c.load_torque;
        dy[0] = electrical * c.inverse_inductance;
        dy[1] = mechanical * c.inverse_inertia;
    }

    /// The measurement map from states to channels (identity on I and ω for the plain motor).
    pub fn measure<D: DualNum<Primitive = f64> + Copy>(&self, y: &[D], _p: &[D], out: &mut [D]) {
        out[0] = y[0];
        out[1] = y[1];
    }

    /// The ODE system at one parameter vector, ready for the integrator. `segments` is
    /// [`MotorModel::segments`], computed once per recording.
    pub fn system<'a, D: DualNum<Primitive = f64> + Copy>(
        &'a self,
        p: &'a [D],
        segments: &'a Segments,
    ) -> MotorSystem<'a, D> {
        MotorSystem {
            model: self,
            p,
            coefficients: Coefficients::new(p),
            segments,
        }
    }

    /// The breakpoints and the input held on each interval between them.
    pub fn segments(&self, t0: f64) -> Segments {
        let breakpoints = self.breakpoints();
        let voltage = match &self.input {
            VoltageInput::Constant => Vec::new(),
            held => std::iter::once(t0)
                .chain(breakpoints.iter().copied())
                .map(|start| held.value_at(start).unwrap_or(self.nominal.voltage))
                .collect(),
        };
        Segments {
            breakpoints,
            voltage,
        }
    }
}

/// The intervals between the right-hand side's discontinuities, and what is held on each.
#[derive(Clone, Debug, Default)]
pub struct Segments {
    pub breakpoints: Vec<f64>,
    /// The held voltage on each interval; empty when the voltage is the constant parameter `U`.
    pub voltage: Vec<f64>,
}

/// The parameters as the right-hand side uses them, extracted once per solve: the divisions
/// by L and J become multiplications, which matters when they run six times a step.
#[derive(Clone, Copy, Debug)]
pub struct Coefficients<D> {
    pub resistance: D,
    pub back_emf_constant: D,
    pub torque_constant: D,
    pub viscous_friction: D,
    pub load_torque: D,
    pub inverse_inductance: D,
    pub inverse_inertia: D,
}

impl<D: DualNum<Primitive = f64> + Copy> Coefficients<D> {
    pub fn new(p: &[D]) -> Self {
        use MotorParam::*;
        Self {
            resistance: p[Resistance as usize],
            back_emf_constant: p[BackEmfConstant as usize],
            torque_constant: p[TorqueConstant as usize],
            viscous_friction: p[ViscousFriction as usize],
            load_torque: p[LoadTorque as usize],
            inverse_inductance: p[Inductance as usize].recip(),
            inverse_inertia: p[Inertia as usize].recip(),
        }
    }
}

/// A motor at fixed parameters: what the integrator sees.
pub struct MotorSystem<'a, D> {
    model: &'a MotorModel,
    p: &'a [D],
    coefficients: Coefficients<D>,
    segments: &'a Segments,
}

impl<D: DualNum<Primitive = f64> + Copy> OdeSystem<D> for MotorSystem<'_, D> {
    fn n_states(&self) -> usize {
        self.model.n_states()
    }

    fn breakpoints(&self) -> &[f64] {
        &self.segments.breakpoints
    }

    #[inline]
    fn rhs(&self, _t: f64, segment: usize, y: &[D], dy: &mut [D]) {
        // The held value of the interval being integrated, not the value at t: a step that ends
        // exactly on a breakpoint must still see the old voltage in its last stage.
        let voltage = match self.segments.voltage.get(segment) {
            Some(&u) => D::from(u),
            None => self.p[MotorParam::Voltage as usize],
        };
        self.model.rhs(voltage, y, &self.coefficients, dy);
    }
}
