//! The voltage-driven motor as the integrator sees it: the intervals between the right-hand
//! side's jumps with the voltage held on each, and the system at one parameter vector.

use super::balance::{Site, torque_balance, voltage_balance};
use super::{Coefficients, InputSteps, MotorModel, MotorParam, Scalar, VoltageInput};
use crate::ode::{ExactLag, OdeSystem};

impl MotorModel {
    /// The ODE system at one parameter vector, ready for the integrator. `segments` is
    /// [`MotorModel::segments`], computed once per recording.
    pub fn system<'a, D: Scalar>(
        &'a self,
        p: &'a [D],
        segments: &'a Segments,
    ) -> MotorSystem<'a, D> {
        MotorSystem {
            model: self,
            p,
            coefficients: self.coefficients(p),
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
            start: t0,
            starts: std::iter::once(t0)
                .chain(breakpoints.iter().copied())
                .collect(),
            breakpoints,
            voltage,
        }
    }
}

/// The intervals between the right-hand side's discontinuities, and what is held on each.
#[derive(Clone, Debug, Default)]
pub struct Segments {
    /// Where the integration starts.
    pub start: f64,
    /// Where each interval starts: `start`, then the breakpoints.
    pub starts: Vec<f64>,
    pub breakpoints: Vec<f64>,
    /// The held voltage on each interval; empty when the voltage is the constant parameter `U`.
    pub voltage: Vec<f64>,
}

/// A model at fixed parameters: what the integrator sees.
pub struct MotorSystem<'a, D> {
    model: &'a MotorModel,
    p: &'a [D],
    coefficients: Coefficients<D>,
    segments: &'a Segments,
}

impl<D: Scalar> MotorSystem<'_, D> {
    /// Equations (3)–(4) with every term's contribution.
    fn with_terms(&self, t: f64, segment: usize, mut voltage: D, y: &[D], dy: &mut [D]) {
        let model = self.model;
        let c = &self.coefficients;
        let (current, speed) = (y[0], y[1]);
        let segment_start = self.segments.starts[segment];
        let params = |k: usize| &self.p[model.param_offsets[k]..model.param_offsets[k + 1]];
        let input = InputSteps {
            starts: &self.segments.starts,
            held: &self.segments.voltage,
            constant: self.p[MotorParam::Voltage as usize],
        };
        for (k, active) in model.terms.iter().enumerate() {
            active.term.input(params(k), t, &input, &mut voltage);
        }
        let site = |k: usize| Site {
            t,
            segment_start,
            current,
            speed,
            voltage,
            coefficients: c,
            params: params(k),
            states: &y[model.state_offsets[k]..model.state_offsets[k + 1]],
        };
        let balance = model.balance(c, &site);
        dy[0] = voltage_balance(c, Some(&balance), voltage, current, speed) * c.inverse_inductance;
        dy[1] = torque_balance(c, Some(&balance), current, speed) * c.inverse_inertia;
        model.term_derivatives(&site, &balance, dy);
    }
}

impl<D: Scalar> OdeSystem<D> for MotorSystem<'_, D> {
    fn n_states(&self) -> usize {
        self.model.n_states()
    }

    fn breakpoints(&self) -> &[f64] {
        &self.segments.breakpoints
    }

    #[inline]
    fn rhs(&self, t: f64, segment: usize, y: &[D], dy: &mut [D]) {
        let voltage = self.voltage(segment);
        self.with_terms(t, segment, voltage, y, dy);
    }

    fn exact_lags(&self) -> Vec<ExactLag<D>> {
        let model = self.model;
        (model.terms.iter().enumerate())
            .filter_map(|(k, active)| {
                let params = &self.p[model.param_offsets[k]..model.param_offsets[k + 1]];
                let (source, tau) = active.term.exact_lag(params)?;
                Some(ExactLag {
                    state: model.state_offsets[k],
                    source,
                    tau,
                })
            })
            .collect()
    }
}

/// The paper's motor with no term on: the same system, but with its two states known at compile
/// time, so that the integrator's loops over the state vector unroll and the right-hand side
/// inlines (a run-time state count costs the plain solve about a quarter of its time).
pub struct PlainMotorSystem<'a, D>(MotorSystem<'a, D>);

impl<'a, D: Scalar> MotorSystem<'a, D> {
    /// The system as a [`PlainMotorSystem`], if no term is on.
    pub fn plain(self) -> Result<PlainMotorSystem<'a, D>, Self> {
        if self.model.terms.is_empty() {
            Ok(PlainMotorSystem(self))
        } else {
            Err(self)
        }
    }

    /// The held value of the interval being integrated, not the value at t: a step that ends
    /// exactly on a breakpoint must still see the old voltage in its last stage.
    #[inline]
    fn voltage(&self, segment: usize) -> D {
        match self.segments.voltage.get(segment) {
            Some(&u) => D::from(u),
            None => self.p[MotorParam::Voltage as usize],
        }
    }
}

impl<D: Scalar> OdeSystem<D> for PlainMotorSystem<'_, D> {
    #[inline]
    fn n_states(&self) -> usize {
        2
    }

    fn breakpoints(&self) -> &[f64] {
        &self.0.segments.breakpoints
    }

    #[inline]
    fn rhs(&self, _t: f64, segment: usize, y: &[D], dy: &mut [D]) {
        let voltage = self.0.voltage(segment);
        let c = &self.0.coefficients;
        let (current, speed) = (y[0], y[1]);
        dy[0] = voltage_balance(c, None, voltage, current, speed) * c.inverse_inductance;
        dy[1] = torque_balance(c, None, current, speed) * c.inverse_inertia;
    }
}
