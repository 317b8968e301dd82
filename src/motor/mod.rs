//! The model a user believes: a base model (the voltage-driven DC motor of §2 of the paper) plus
//! a list of active physics terms, with the right-hand side written once, generic over the
//! number type, so that the same code gives values (`f64`) and forward sensitivities
//! (num-dual numbers).
//!
//! The model is data: a parameter vector (the base's parameters, then each term's), a state
//! vector (the base's states, then each term's), and the channels it measures. A term is an
//! addition to these vectors, never a copy of the motor.

mod balance;
pub mod closed_form;
mod drive;
mod input;
mod parameters;
pub mod terms;

pub use balance::{Balance, Coefficients, Site, torque_balance, voltage_balance};
pub use drive::{DriveSettings, SampledDrive};
pub use input::VoltageInput;
pub use parameters::{MotorParam, MotorParameters};
pub use terms::{Magnitudes, PRIOR_SHARE, Term};

use num_dual::DualNum;

use crate::ode::OdeSystem;
use crate::parameter::{ParameterSpec, Prior, Support};

/// The number types the physics is written for: `f64` and num-dual's dual numbers.
pub trait Scalar: DualNum<Primitive = f64> + Copy {}
impl<D: DualNum<Primitive = f64> + Copy> Scalar for D {}

/// The channels the motor's measurement map produces, in output order.
pub const MOTOR_CHANNELS: [&str; 2] = ["I", "omega"];

/// The channels of the drive bases.
pub const CURRENT_DRIVEN_CHANNELS: [&str; 1] = ["omega"];
pub const POSITION_LOOP_CHANNELS: [&str; 2] = ["q", "force"];
const DRIVE_STATES: [&str; 2] = ["q", "omega"];

/// The physics the terms are added to.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Base {
    /// L dI/dt = U − R I − c_m ω, J dω/dt = c_g I − d ω, measuring I and ω (eqs. 3–4).
    #[default]
    VoltageDriven,
    /// J dω/dt = c_g·I − d ω with the recorded current I as input (the drive closes the current
    /// loop), measuring ω.
    CurrentDriven,
    /// The same mechanics on a linear axis (J is a mass, c_g a force per volt) inside a sampled
    /// position/velocity cascade driven by a reference position; measures q and the force.
    PositionLoop,
}

impl Base {
    pub const ALL: [Base; 3] = [Base::VoltageDriven, Base::CurrentDriven, Base::PositionLoop];

    pub fn name(&self) -> &'static str {
        match self {
            Base::VoltageDriven => "voltage_driven",
            Base::CurrentDriven => "current_driven",
            Base::PositionLoop => "position_loop",
        }
    }

    /// The unit of one of the base's channels.
    pub fn channel_unit(&self, channel: &str) -> &'static str {
        match channel {
            "I" => "A",
            "omega" => self.unit("rad/s"),
            "q" => self.unit("rad"),
            "force" => self.unit("N·m"),
            _ => "",
        }
    }

    /// Whether a drive closes the electrical loop (the recorded input drives the mechanics).
    pub fn is_drive(&self) -> bool {
        *self != Base::VoltageDriven
    }

    /// Whether a term applies to this base.
    pub fn accepts(&self, term: &Term) -> bool {
        !self.is_drive() || term.mechanical()
    }

    /// A unit as this base reads it: a linear axis has N for N·m, m for rad, kg for kg·m².
    pub fn unit(&self, unit: &'static str) -> &'static str {
        if *self != Base::PositionLoop {
            return unit;
        }
        match unit {
            "kg·m²" => "kg",
            "N·m/A" => "N/V",
            "N·m" => "N",
            "N·m·s/rad" => "N·s/m",
            "N·m·s²/rad²" => "N·s²/m²",
            "rad/s" => "m/s",
            "rad" => "m",
            "A" => "V",
            other => other,
        }
    }

    pub fn from_name(name: &str) -> Option<Base> {
        Base::ALL.into_iter().find(|b| b.name() == name)
    }

    pub fn state_names(&self) -> &'static [&'static str] {
        match self {
            Base::VoltageDriven => &MOTOR_CHANNELS,
            Base::CurrentDriven | Base::PositionLoop => &DRIVE_STATES,
        }
    }

    pub fn channels(&self) -> &'static [&'static str] {
        match self {
            Base::VoltageDriven => &MOTOR_CHANNELS,
            Base::CurrentDriven => &CURRENT_DRIVEN_CHANNELS,
            Base::PositionLoop => &POSITION_LOOP_CHANNELS,
        }
    }
}

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
                "term {} acts on the electrical equation or the current sensor, which a {} \
                 model does not have",
                t.term.name(),
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

    /// Names of the parameter vector: the base's keys, then `term.key` for each term's.
    pub fn parameter_names(&self) -> Vec<String> {
        MotorParam::ALL
            .iter()
            .map(|p| p.key().to_string())
            .chain(self.terms.iter().flat_map(|t| {
                t.term
                    .params()
                    .iter()
                    .map(move |p| format!("{}.{}", t.term.name(), p.key))
            }))
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

    pub fn parameter_index(&self, name: &str) -> Option<usize> {
        self.parameter_names().iter().position(|n| n == name)
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

    /// The scales the default priors are drawn to, for a recording of the given length.
    pub fn magnitudes(&self, duration: f64) -> Magnitudes {
        let m = &self.nominal;
        let sane = |v: f64| if v.is_finite() && v > 0.0 { v } else { 1.0 };
        if let Some(drive) = &self.drive {
            // What the drive can deliver (c_g times its input limit) plays the stall torque's
            // part, the record's largest speed the no-load speed's.
            let current = sane(drive.input_scale());
            let torque = sane(m.torque_constant * current);
            let speed = sane(drive.speed_scale);
            return Magnitudes {
                voltage: 1.0,
                current,
                speed,
                torque,
                energy: sane(torque * speed * duration),
                duration: sane(duration),
            };
        }
        let held_max = match &self.input {
            VoltageInput::Constant => m.voltage.abs(),
            VoltageInput::Held { values, .. } => values.iter().fold(0.0f64, |a, v| a.max(v.abs())),
        };
        // A degenerate nominal model (U = 0, c_m = 0) would give zero or infinite scales; one
        // unit is then as good a scale as any, and finite.
        let voltage = sane(held_max);
        let current = sane(voltage / m.resistance);
        let speed = sane(voltage / m.back_emf_constant);
        let torque = sane(m.torque_constant * current);
        let time_constant =
            sane(m.inertia * m.resistance / (m.torque_constant * m.back_emf_constant));
        Magnitudes {
            voltage,
            current,
            speed,
            torque,
            energy: sane(voltage * voltage / m.resistance * time_constant),
            duration: sane(duration),
        }
    }

    /// Every parameter with its unit, support and default prior (scaled by `magnitudes`).
    pub fn parameter_specs(&self, magnitudes: &Magnitudes) -> Vec<ParameterSpec> {
        let mut specs: Vec<ParameterSpec> = MotorParam::ALL
            .iter()
            .map(|&p| {
                let spec = base_spec(p, self.nominal.get(p), magnitudes);
                ParameterSpec {
                    unit: self.base.unit(spec.unit),
                    ..spec
                }
            })
            .collect();
        for t in &self.terms {
            for (decl, &value) in t.term.params().iter().zip(&t.values) {
                specs.push(ParameterSpec {
                    name: format!("{}.{}", t.term.name(), decl.key),
                    unit: self.base.unit(decl.unit),
                    nominal: value,
                    support: (decl.support)(magnitudes),
                    default_prior: (decl.prior)(magnitudes),
                });
            }
        }
        specs
    }

    /// Why a parameter cannot be calibrated, if it cannot (e.g. the time of a hard step).
    pub fn check_calibrated(&self, name: &str) -> Result<(), String> {
        let Some((term_name, key)) = name.split_once('.') else {
            return Ok(());
        };
        match self.terms.iter().find(|t| t.term.name() == term_name) {
            Some(t) => t.term.check_calibrated(key),
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
        for (k, t) in self.terms.iter().enumerate() {
            for (j, s) in t.term.states().iter().enumerate() {
                y0[self.state_offsets[k] + j] = D::from(s.initial);
            }
        }
    }

    /// The measurement map over a whole solution: `states` holds `n_states()` values per sample,
    /// `out` is channel-major (`out[c * samples + i]`). I and ω as the sensor terms amend them.
    pub fn measure<D: Scalar>(&self, states: &[D], p: &[D], out: &mut [D]) {
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
        for i in 0..samples {
            for c in 0..n_channels {
                measured[c] = out[c * samples + i];
            }
            for (k, t) in self.terms.iter().enumerate() {
                t.term.measure(
                    &p[self.param_offsets[k]..self.param_offsets[k + 1]],
                    &mut measured,
                );
            }
            for c in 0..n_channels {
                out[c * samples + i] = measured[c];
            }
        }
    }

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
            breakpoints,
            voltage,
        }
    }
}

/// The base parameters' supports and default priors: R keeps the paper's N(R₀, 0.2R₀); the
/// other positive constants a log-normal of 20% around their nominal value; signed quantities
/// a normal of a tenth of the scale they act on.
fn base_spec(p: MotorParam, nominal: f64, m: &Magnitudes) -> ParameterSpec {
    use MotorParam::*;
    let normal = |sd: f64| Prior::Normal { mean: nominal, sd };
    let (support, default_prior) = match p {
        Resistance => (Support::Positive, normal(0.2 * nominal)),
        BackEmfConstant | TorqueConstant | Inductance | Inertia => (
            Support::Positive,
            Prior::LogNormal {
                median: nominal,
                sigma: 0.2,
            },
        ),
        ViscousFriction if nominal > 0.0 => (
            Support::Positive,
            Prior::LogNormal {
                median: nominal,
                sigma: 0.2,
            },
        ),
        ViscousFriction => (
            Support::Positive,
            Prior::HalfNormal {
                scale: PRIOR_SHARE * m.torque / m.speed,
            },
        ),
        Voltage => (Support::Real, normal(PRIOR_SHARE * m.voltage)),
        InitialCurrent => (Support::Real, normal(PRIOR_SHARE * m.current)),
        InitialSpeed => (Support::Real, normal(PRIOR_SHARE * m.speed)),
    };
    ParameterSpec {
        name: p.key().to_string(),
        unit: p.unit(),
        nominal,
        support,
        default_prior,
    }
}

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

/// The intervals between the right-hand side's discontinuities, and what is held on each.
#[derive(Clone, Debug, Default)]
pub struct Segments {
    /// Where the integration starts.
    pub start: f64,
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
    fn with_terms(&self, t: f64, segment: usize, voltage: D, y: &[D], dy: &mut [D]) {
        let model = self.model;
        let c = &self.coefficients;
        let (current, speed) = (y[0], y[1]);
        let segment_start = match segment {
            0 => self.segments.start,
            s => self.segments.breakpoints[s - 1],
        };
        let site = |k: usize| Site {
            t,
            segment_start,
            current,
            speed,
            params: &self.p[model.param_offsets[k]..model.param_offsets[k + 1]],
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
