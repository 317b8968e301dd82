//! What a design is judged on: the candidates, each at its estimate, simulated at the design's
//! sample times under any input, with the noise σ the recording showed.
//!
//! The input a design searches is the one the model is driven by ([`Commanded`]): the voltage of
//! the voltage-driven motor, the current a `current_driven` drive is commanded (the drive closes
//! the current loop, so the current is what a recorder plays back and the model measures ω
//! alone), or the reference position of a `position_loop` (its controller turns the reference
//! into the force; the model measures q and the force). Each travels as a [`VoltageInput`] held
//! between times; for a drive its values are amperes, or for a position loop the reference's
//! speed, which the reference integrates ([`Commanded::played`]): a piecewise-constant
//! position would be a string of steps the loop answers at its saturation, which tells little
//! and fits badly, where a move at a designed speed is what an axis is commissioned with.

use std::collections::BTreeMap;

use crate::error::Error;
use crate::forward::ForwardModel;
use crate::io::Recording;
use crate::motor::{Base, Term, VoltageInput};
use crate::ode::SolverSettings;
use crate::parameter::{ParamId, ParameterSpec};
use crate::study::Problem;

use super::limits::Limits;

/// What a design's levels are: the quantity the model is driven by.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Commanded {
    /// The voltage U of the voltage-driven motor [V].
    Voltage,
    /// The current I a `current_driven` drive is commanded [A].
    Current,
    /// The reference position q_ref of a `position_loop` [m on a linear axis], designed as its
    /// speed: the levels are the reference's speed [m/s], the reference their integral from
    /// q = 0, where the axis starts at rest.
    Position,
}

impl Commanded {
    /// What a model of `base` is driven by.
    pub fn of(base: Base) -> Self {
        match base {
            Base::VoltageDriven => Commanded::Voltage,
            Base::CurrentDriven => Commanded::Current,
            Base::PositionLoop => Commanded::Position,
        }
    }

    /// The base a model so driven has.
    fn base(&self) -> Base {
        match self {
            Commanded::Voltage => Base::VoltageDriven,
            Commanded::Current => Base::CurrentDriven,
            Commanded::Position => Base::PositionLoop,
        }
    }

    /// The column of `input.csv`, what the drive is played ([`Base::input`]).
    pub fn column(&self) -> &'static str {
        self.base().input()
    }

    pub fn unit(&self) -> &'static str {
        match self {
            Commanded::Voltage => "V",
            Commanded::Current => "A",
            Commanded::Position => "m",
        }
    }

    /// What a level is, and its unit: the input itself, or a reference's speed.
    pub fn level(&self) -> (&'static str, &'static str) {
        match self {
            Commanded::Position => ("reference speed", "m/s"),
            _ => (self.column(), self.unit()),
        }
    }

    /// What the drive is played at `times` for the levels held there: the levels themselves,
    /// or for a position loop the reference, their integral from 0 at the first sample, each
    /// level held to the next sample (what a recorder plays, and the search sees).
    pub fn played(&self, times: &[f64], levels: &[f64]) -> Vec<f64> {
        if *self != Commanded::Position {
            return levels.to_vec();
        }
        let mut at = 0.0;
        let mut out = Vec::with_capacity(times.len());
        for (k, &t) in times.iter().enumerate() {
            if k > 0 {
                at += levels[k - 1] * (t - times[k - 1]);
            }
            out.push(at);
        }
        out
    }

    /// The limits a design of this input needs: the level's own, and what the model measures
    /// or moves at. A position loop's force needs none: it defaults to under the controller's
    /// saturation ([`model_limits`]), and the speed is the axis's, from its position.
    pub fn required_limits(&self) -> &'static [&'static str] {
        match self {
            Commanded::Voltage => &["U", "I", "omega"],
            Commanded::Current => &["I", "omega"],
            Commanded::Position => &["q", "omega"],
        }
    }

    /// Refuses limits without one this input needs ([`Self::required_limits`]).
    pub fn check_limits(&self, limits: &Limits) -> Result<(), Error> {
        let why = match self {
            Commanded::Voltage => "a voltage-driven design",
            Commanded::Current => "a current_driven design (the current is what it commands)",
            Commanded::Position => {
                "a position_loop design (the reference's travel and the axis's speed)"
            }
        };
        limits
            .require(self.required_limits(), why)
            .map_err(|message| Error::setting("limits", limits, message))
    }

    /// The bound on the levels: the voltage limit, the current limit for a current command (U
    /// is then no input, and its limit is not used), or the speed limit for a reference's
    /// speed (its travel is checked on the axis's position).
    pub fn level_limit(&self, limits: &Limits) -> Result<f64, Error> {
        self.check_limits(limits)?;
        Ok(match self {
            Commanded::Voltage => limits.voltage,
            Commanded::Current => limits.current,
            Commanded::Position => limits.speed,
        })
    }

    /// Whether the drive plays the levels sample by sample (the drive bases) rather than the
    /// integrator switching exactly at the switching times (the voltage).
    pub fn is_sampled(&self) -> bool {
        self.base().is_drive()
    }
}

/// One candidate explanation at its estimate: the user's model with `added` switched on.
#[derive(Clone, Debug)]
pub struct Candidate {
    /// `none`, a term's name, or terms joined by `+`.
    pub name: String,
    pub added: Vec<String>,
    /// The user's model with the terms on, its values at the estimate.
    pub problem: Problem,
    pub calibrated: Vec<String>,
    /// The calibrated parameters' values at the estimate.
    pub theta: Vec<f64>,
}

/// The candidates and the sampling the design is for.
#[derive(Clone, Debug)]
pub struct Experiment {
    pub candidates: Vec<Candidate>,
    /// t_i = i/rate, i = 1..M.
    pub times: Vec<f64>,
    /// σ of each channel the candidates measure, in their order (I and ω; ω alone for a
    /// current-driven model).
    pub noise_sd: Vec<f64>,
}

/// The sample times of a record of `duration` s at `rate` Hz: at least ten samples.
pub fn design_times(duration: f64, rate: f64) -> Result<Vec<f64>, Error> {
    if !(duration > 0.0 && duration.is_finite()) {
        return Err(Error::setting(
            "duration",
            duration,
            "must be a positive number of seconds",
        ));
    }
    if !(rate > 0.0 && rate.is_finite()) {
        return Err(Error::setting(
            "rate",
            rate,
            "must be a positive sampling rate [Hz]",
        ));
    }
    let m = (duration * rate + 1e-9).floor() as usize;
    if m < 10 {
        return Err(Error::setting(
            "duration",
            duration,
            format!("gives {m} samples at {rate} Hz; a design needs at least ten"),
        ));
    }
    Ok((1..=m).map(|i| i as f64 / rate).collect())
}

/// The limits a design of `model` keeps: as given, and for a position loop given no force limit
/// 2% ([`super::MARGIN`]) under the force its controller saturates at (c_g times
/// `drive.input_limit`), so that neither the design nor the fixed experiments it is compared
/// with drive the loop into its saturation: there the axis's position depends on the model
/// through switching instants that the fits of `diagnose` then lose (papers/design.md: 2 and 11
/// of 20 records named so).
pub fn model_limits(model: &crate::io::ModelFile, limits: Limits) -> Limits {
    match (model.base, model.drive.input_limit) {
        (Base::PositionLoop, Some(saturation)) if !limits.force.is_finite() => Limits {
            force: super::MARGIN * model.motor.torque_constant * saturation,
            ..limits
        },
        _ => limits,
    }
}

/// The user's model on the design's sampling: a problem whose one record is a placeholder at
/// `times` (no data of it is fitted). A drive reads its scales from that record (the largest
/// input it is commanded, the largest speed it reaches: what a term's default smoothing speed
/// and the default priors are drawn to), so the placeholder holds the limits there, the most a
/// designed record may command and reach. A current-driven record carries the input I and
/// measures ω. A position loop's record carries a reference and an axis that ramp from q = 0 at
/// the speed limit (its speed scale: [`Recording::sampled_drive`]), and measures q and the
/// force; a position loop without `drive.input_limit` is refused, since its saturation
/// is what bounds the force a design may ask.
pub fn design_problem(
    model: &crate::io::ModelFile,
    times: &[f64],
    limits: &Limits,
) -> Result<Problem, Error> {
    let m = times.len();
    let held = |v: f64| vec![if v.is_finite() { v } else { 0.0 }; m];
    let commanded = Commanded::of(model.base);
    commanded.check_limits(limits)?;
    let (channels, inputs) = match commanded {
        Commanded::Voltage => (
            vec![("I".into(), vec![0.0; m]), ("omega".into(), vec![0.0; m])],
            Vec::new(),
        ),
        Commanded::Current => (
            vec![("omega".into(), held(limits.speed))],
            vec![("I".into(), held(limits.current))],
        ),
        Commanded::Position => {
            if model.drive.input_limit.is_none() {
                return Err(Error::setting(
                    "model",
                    "drive.input_limit",
                    "a position_loop design needs the controller's saturation (drive.input_limit): \
                     it bounds the force the designed reference may ask",
                ));
            }
            let t0 = times.first().copied().unwrap_or(0.0);
            let ramp: Vec<f64> = times.iter().map(|t| limits.speed * (t - t0)).collect();
            (
                vec![("q".into(), ramp.clone()), ("force".into(), vec![0.0; m])],
                vec![("q_ref".into(), ramp)],
            )
        }
    };
    Ok(Problem {
        label: "design".into(),
        recordings: vec![Recording {
            source: "design".into(),
            time: times.to_vec(),
            channels,
            voltage: None,
            inputs,
        }],
        model: model.clone(),
        reference: None,
    })
}

/// The σ a design assumes for a channel that neither the command line nor a diagnosis gives
/// one for: the paper's, 2 A on I and 10 rad/s on ω; none for a position loop's q and force,
/// whose scale is the rig's.
pub fn default_noise_sd(channel: &str) -> Option<f64> {
    let [current, speed] = crate::study::cases::NOISE_SD;
    match channel {
        "I" => Some(current),
        "omega" => Some(speed),
        _ => None,
    }
}

/// The candidate names a design can take: `none`, a library term, or terms joined by `+`.
pub fn parse_candidate(name: &str) -> Result<Vec<String>, Error> {
    if name == "none" {
        return Ok(Vec::new());
    }
    name.split('+')
        .map(|t| {
            let t = t.trim();
            if Term::ALL_NAMES.contains(&t) {
                Ok(t.to_string())
            } else {
                Err(Error::setting(
                    "separate",
                    name,
                    format!(
                        "unknown candidate '{t}' (known: none, {})",
                        Term::NAMES.join(", ")
                    ),
                ))
            }
        })
        .collect()
}

impl Candidate {
    /// The candidate `name` on `base`, at the values `values` gives (keys as a model's
    /// parameters, `R` or `coulomb_friction.T_c`); the rest at the model's values or the term's
    /// defaults.
    pub fn new(base: &Problem, name: &str, values: &BTreeMap<String, f64>) -> Result<Self, Error> {
        let added = parse_candidate(name)?;
        let mut problem = base.with_terms(&added)?;
        for (key, &v) in values {
            problem.model.set_value(&ParamId::parse(key), v);
        }
        let calibrated = problem.calibrated_names()?;
        let forward = problem.forward(SolverSettings::default())?;
        Ok(Self {
            name: name.to_string(),
            added,
            theta: forward.nominal_calibrated(),
            calibrated,
            problem,
        })
    }

    /// The candidate's forward model under `input` at `times`, its calibrated parameters free.
    /// For a drive `input` is the commanded current or the reference's speed: the drive holds
    /// its value at each sample until the next (the drive's scales stay the placeholder
    /// record's, see [`design_problem`]); a position loop's axis starts at rest where its
    /// reference starts ([`Commanded::played`]).
    pub fn forward(&self, input: &VoltageInput, times: &[f64]) -> Result<ForwardModel, Error> {
        let commanded = Commanded::of(self.problem.model.base);
        let model = match commanded {
            Commanded::Voltage => self
                .problem
                .model
                .model(input.clone())
                .map_err(Error::invalid)?,
            Commanded::Current | Commanded::Position => {
                let mut model = self.problem.model_for(self.problem.recording())?;
                let drive = model
                    .drive
                    .as_mut()
                    .ok_or_else(|| Error::invalid("a drive-base model without its drive"))?;
                drive.times = times.to_vec();
                let levels = times
                    .iter()
                    .map(|&t| input.value_at(t))
                    .collect::<Option<Vec<f64>>>()
                    .ok_or_else(|| {
                        Error::invalid(format!(
                            "a {} design needs a held {}, not the constant U",
                            self.problem.model.base.name(),
                            commanded.level().0
                        ))
                    })?;
                drive.input = commanded.played(times, &levels);
                drive.disturbance = vec![0.0; times.len()];
                if commanded == Commanded::Position {
                    drive.initial_position = drive.input.first().copied().unwrap_or(0.0);
                }
                model
            }
        };
        ForwardModel::new(
            model,
            times.to_vec(),
            &self.calibrated,
            SolverSettings::default(),
        )
        .map_err(Error::invalid)
    }

    /// The calibrated parameters' specs (supports) for the least-squares fits.
    pub fn specs(&self, input: &VoltageInput, times: &[f64]) -> Result<Vec<ParameterSpec>, Error> {
        Ok(self.forward(input, times)?.calibrated_specs())
    }
}

impl Experiment {
    /// The base the candidates share: the user's model's.
    fn base(&self) -> Base {
        self.candidates
            .first()
            .map_or(Base::VoltageDriven, |c| c.problem.model.base)
    }

    /// What the candidates are driven by.
    pub fn commanded(&self) -> Commanded {
        Commanded::of(self.base())
    }

    /// The channels the candidates measure, in the order of `noise_sd`.
    pub fn channels(&self) -> &'static [&'static str] {
        self.base().channels()
    }

    /// Observed values of one record: the N of a score's ½·d·ln N.
    pub fn n_observations(&self) -> usize {
        self.times.len() * self.noise_sd.len()
    }

    /// 1/σ for each row of a channel-major prediction.
    pub fn weights(&self) -> Vec<f64> {
        let m = self.times.len();
        (0..self.n_observations())
            .map(|row| 1.0 / self.noise_sd[row / m])
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_reference_is_the_integral_of_its_designed_speed() {
        let times = [0.001, 0.002, 0.003, 0.004];
        let speeds = [0.5, 0.5, -0.25, 9.0];
        let played = Commanded::Position.played(&times, &speeds);
        let expected = [0.0, 0.0005, 0.001, 0.00075];
        for (p, e) in played.iter().zip(expected) {
            assert!((p - e).abs() < 1e-15, "{played:?}");
        }
        // The other inputs are played as designed.
        assert_eq!(Commanded::Current.played(&times, &speeds), speeds);
        assert_eq!(Commanded::Position.level(), ("reference speed", "m/s"));
    }

    #[test]
    fn a_position_loop_s_force_is_limited_to_its_saturation_unless_told() {
        let mut model = crate::io::ModelFile {
            base: Base::PositionLoop,
            ..Default::default()
        };
        model.motor.torque_constant = 35.0;
        model.drive.input_limit = Some(10.0);
        let given: Limits = "q=±0.1,omega=±0.5".parse().unwrap();
        assert_eq!(
            model_limits(&model, given).force,
            super::super::MARGIN * 350.0
        );
        let held: Limits = "q=±0.1,omega=±0.5,force=±300".parse().unwrap();
        assert_eq!(model_limits(&model, held).force, 300.0);
        model.base = Base::CurrentDriven;
        assert_eq!(model_limits(&model, given).force, f64::INFINITY);
    }
}
