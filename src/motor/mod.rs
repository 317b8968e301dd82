//! The model a user believes: a base model (the voltage-driven DC motor of §2 of the paper) plus
//! a list of active physics terms, with the right-hand side written once, generic over the
//! number type, so that the same code gives values (`f64`) and forward sensitivities
//! (num-dual numbers).
//!
//! The model is data: a parameter vector (the base's parameters, then each term's), a state
//! vector (the base's states, then each term's), and the channels it measures. A term is an
//! addition to these vectors, never a copy of the motor.

mod balance;
mod base;
pub mod closed_form;
pub mod dictionary;
mod drive;
mod input;
mod magnitudes;
mod parameters;
mod system;
pub mod terms;

pub use balance::{Balance, Coefficients, Site, torque_balance, voltage_balance};
pub use base::{Base, CURRENT_DRIVEN_CHANNELS, MOTOR_CHANNELS, POSITION_LOOP_CHANNELS};
pub use drive::{DriveSettings, SampledDrive};
pub use input::{InputSteps, VoltageInput};
pub use magnitudes::{Magnitudes, PRIOR_SHARE};
pub use parameters::{MotorParam, MotorParameters};
pub use system::{MotorSystem, PlainMotorSystem, Segments};
pub use terms::Term;

use num_dual::DualNum;

use crate::parameter::ParamId;

/// The number types the physics is written for: `f64` and num-dual's dual numbers.
pub trait Scalar: DualNum<Primitive = f64> + Copy {}
impl<D: DualNum<Primitive = f64> + Copy> Scalar for D {}

/// A term switched on, with the nominal values of its parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct ActiveTerm {
    pub term: Term,
    pub values: Vec<f64>,
}

impl ActiveTerm {
    /// The term at its parameters' default values (absent effects).
    pub fn with_defaults(term: Term) -> Self {
        let values = term.params().iter().map(|p| p.default).collect();
        Self { term, values }
    }
}

/// A model: base, nominal values, the input it is driven with, and its active terms in
/// [`Term::NAMES`] order (so that the parameter vector does not depend on the order of a file).
#[derive(Clone, Debug, PartialEq)]
pub struct MotorModel {
    pub base: Base,
    pub nominal: MotorParameters,
    pub input: VoltageInput,
    /// The recorded input and settings of a drive base (`None` for the voltage-driven motor).
    pub drive: Option<SampledDrive>,
    terms: Vec<ActiveTerm>,
    /// Offsets of each term's parameters in the parameter vector (one more than terms).
    param_offsets: Vec<usize>,
    /// Offsets of each term's states in the state vector (one more than terms).
    state_offsets: Vec<usize>,
}

const N_BASE_PARAMS: usize = MotorParam::ALL.len();

impl MotorModel {
    /// The plain motor; a schema-1 load torque T_L ≠ 0 becomes the `load_torque` term.
    pub fn new(nominal: MotorParameters, input: VoltageInput) -> Self {
        Self::with_terms(nominal, input, Vec::new()).expect("no terms cannot collide")
    }

    pub fn with_terms(
        nominal: MotorParameters,
        input: VoltageInput,
        terms: Vec<ActiveTerm>,
    ) -> Result<Self, String> {
        Self::with_base(Base::VoltageDriven, nominal, input, terms)
    }

    /// A model of the given base with terms.
    pub fn with_base(
        base: Base,
        nominal: MotorParameters,
        input: VoltageInput,
        mut terms: Vec<ActiveTerm>,
    ) -> Result<Self, String> {
        if nominal.load_torque != 0.0 {
            if terms.iter().any(|t| matches!(t.term, Term::LoadTorque(_))) {
                return Err(
                    "the load torque is given twice: as motor.T_L and as the load_torque term"
                        .into(),
                );
            }
            terms.push(ActiveTerm {
                term: Term::LoadTorque(terms::LoadTorque),
                values: vec![nominal.load_torque],
            });
        }
        terms.sort_by_key(|t| t.term.rank());
        if let Some(t) = terms.iter().find(|t| !base.accepts(&t.term)) {
            return Err(format!(
                "term {} {}, which a {} model does not have",
                t.term.name(),
                t.term.not_on_drives(),
                base.name()
            ));
        }
        for pair in terms.windows(2) {
            if pair[0].term.name() == pair[1].term.name() {
                return Err(format!("term {} is listed twice", pair[0].term.name()));
            }
        }
        for t in &terms {
            if t.values.len() != t.term.params().len() {
                return Err(format!(
                    "term {} takes {} parameter values, got {}",
                    t.term.name(),
                    t.term.params().len(),
                    t.values.len()
                ));
            }
            if let Some(v) = t.values.iter().find(|v| !v.is_finite()) {
                return Err(format!("term {}: value {v} is not finite", t.term.name()));
            }
        }
        let mut param_offsets = vec![N_BASE_PARAMS];
        let mut state_offsets = vec![base.state_names().len()];
        for t in &terms {
            param_offsets.push(param_offsets.last().unwrap() + t.term.params().len());
            state_offsets.push(state_offsets.last().unwrap() + t.term.states().len());
        }
        Ok(Self {
            base,
            nominal: MotorParameters {
                load_torque: 0.0,
                ..nominal
            },
            input,
            drive: None,
            terms,
            param_offsets,
            state_offsets,
        })
    }

    pub fn terms(&self) -> &[ActiveTerm] {
        &self.terms
    }

    /// The parameter vector's identities: the base's, then each term's.
    pub fn parameter_ids(&self) -> Vec<ParamId> {
        MotorParam::ALL
            .iter()
            .map(|p| ParamId::base(p.key()))
            .chain(self.terms.iter().flat_map(|t| {
                t.term
                    .params()
                    .iter()
                    .map(move |p| ParamId::of_term(t.term.name(), p.key))
            }))
            .collect()
    }

    /// Names of the parameter vector: the base's keys, then `term.key` for each term's.
    pub fn parameter_names(&self) -> Vec<String> {
        self.parameter_ids()
            .iter()
            .map(ParamId::to_string)
            .collect()
    }

    /// The nominal values of the full parameter vector.
    pub fn parameter_values(&self) -> Vec<f64> {
        MotorParam::ALL
            .iter()
            .map(|&p| self.nominal.get(p))
            .chain(self.terms.iter().flat_map(|t| t.values.iter().copied()))
            .collect()
    }

    pub fn parameter_index(&self, id: &ParamId) -> Option<usize> {
        self.parameter_ids().iter().position(|p| p == id)
    }

    /// The model driven by a record's sampled input (a drive base).
    pub fn with_drive(self, drive: SampledDrive) -> Self {
        Self {
            drive: Some(drive),
            ..self
        }
    }

    /// A drive base's channels at its record's samples (channel-major), with the sampled-input
    /// integrator; the record's times are the drive's.
    pub fn simulate_drive<D: Scalar>(
        &self,
        p: &[D],
        out: &mut [D],
    ) -> Result<crate::ode::SolverStats, crate::ode::OdeError> {
        let drive = self.drive.as_ref().expect("simulate_drive needs a drive");
        drive::simulate(self, drive, p, out)
    }

    /// Why a parameter cannot be calibrated, if it cannot (e.g. the time of a hard step).
    pub fn check_calibrated(&self, id: &ParamId) -> Result<(), String> {
        let Some(term_name) = id.term() else {
            return Ok(());
        };
        match self.terms.iter().find(|t| t.term.name() == term_name) {
            Some(t) => t.term.check_calibrated(id.key()),
            None => Ok(()),
        }
    }

    pub fn n_states(&self) -> usize {
        *self.state_offsets.last().expect("offsets are never empty")
    }

    pub fn channels(&self) -> &'static [&'static str] {
        self.base.channels()
    }

    /// Times at which the right-hand side jumps: where a held input changes its value, and
    /// where a term switches hard.
    pub fn breakpoints(&self) -> Vec<f64> {
        let mut points = self.input.breakpoints();
        if !self.terms.is_empty() {
            for t in &self.terms {
                points.extend(t.term.breakpoints(&t.values));
            }
            points.sort_by(f64::total_cmp);
            points.dedup();
        }
        points
    }

    pub fn initial_state<D: Scalar>(&self, p: &[D], y0: &mut [D]) {
        y0[0] = p[MotorParam::InitialCurrent as usize];
        y0[1] = p[MotorParam::InitialSpeed as usize];
        let n_base = self.base.state_names().len();
        for (k, t) in self.terms.iter().enumerate() {
            let states = self.state_offsets[k]..self.state_offsets[k + 1];
            for (j, s) in t.term.states().iter().enumerate() {
                y0[states.start + j] = D::from(s.initial);
            }
            if !states.is_empty() {
                let (base, rest) = y0.split_at_mut(n_base);
                let params = &p[self.param_offsets[k]..self.param_offsets[k + 1]];
                t.term.initial(
                    params,
                    base,
                    &mut rest[states.start - n_base..states.end - n_base],
                );
            }
        }
    }

    /// The measurement map over a whole solution: `states` holds `n_states()` values per sample
    /// at `times`, `out` is channel-major (`out[c * samples + i]`). I and ω as the sensor terms
    /// amend them.
    pub fn measure<D: Scalar>(&self, times: &[f64], states: &[D], p: &[D], out: &mut [D]) {
        let n = self.n_states();
        let samples = states.len() / n;
        let n_channels = self.channels().len();
        // Without terms the map is the identity on the base's first states: a strided copy, not
        // a call per sample (501 of them per solve).
        for (i, y) in states.chunks_exact(n).enumerate() {
            for c in 0..n_channels {
                out[c * samples + i] = y[c];
            }
        }
        if self.terms.is_empty() {
            return;
        }
        let mut measured = vec![D::from(0.0); n_channels];
        for (i, y) in states.chunks_exact(n).enumerate() {
            for c in 0..n_channels {
                measured[c] = out[c * samples + i];
            }
            let at = terms::Sample {
                t: times[i],
                voltage: self
                    .input
                    .value_at(times[i])
                    .map_or(p[MotorParam::Voltage as usize], D::from),
            };
            for (k, t) in self.terms.iter().enumerate() {
                t.term.measure(
                    &p[self.param_offsets[k]..self.param_offsets[k + 1]],
                    &y[self.state_offsets[k]..self.state_offsets[k + 1]],
                    at,
                    &mut measured,
                );
            }
            for c in 0..n_channels {
                out[c * samples + i] = measured[c];
            }
        }
    }
}
