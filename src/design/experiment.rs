//! What a design is judged on: the candidates, each at its estimate, simulated at the design's
//! sample times under any input, with the noise σ the recording showed.
//!
//! The input a design searches is the one the model is driven by ([`Commanded`]): the voltage of
//! the voltage-driven motor, or the current a `current_driven` drive is commanded (the drive
//! closes the current loop, so the current is what a recorder plays back and the model
//! measures ω alone). Either travels as a [`VoltageInput`] held between times; for a
//! current-driven candidate its values are amperes.

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
}

impl Commanded {
    /// What a model of `base` is driven by; a `position_loop` model is refused: its input is a
    /// reference position fed through a controller, which design does not search.
    pub fn of(base: Base) -> Result<Self, Error> {
        match base {
            Base::VoltageDriven => Ok(Commanded::Voltage),
            Base::CurrentDriven => Ok(Commanded::Current),
            Base::PositionLoop => Err(Error::setting(
                "model",
                "base = \"position_loop\"",
                "design searches a voltage (voltage_driven) or a current command \
                 (current_driven); a position_loop model's input is a reference position fed \
                 through its controller, which design does not search",
            )),
        }
    }

    /// The column of `input.csv` that holds the levels (`U` or `I`).
    pub fn column(&self) -> &'static str {
        match self {
            Commanded::Voltage => "U",
            Commanded::Current => "I",
        }
    }

    pub fn unit(&self) -> &'static str {
        match self {
            Commanded::Voltage => "V",
            Commanded::Current => "A",
        }
    }

    /// The bound on the levels: the voltage limit, or for a current command the current limit
    /// (U is then no input, and its limit is not used). A voltage-driven design without a
    /// voltage limit is refused.
    pub fn level_limit(&self, limits: &Limits) -> Result<f64, Error> {
        let limit = match self {
            Commanded::Voltage => limits.voltage,
            Commanded::Current => limits.current,
        };
        if !limit.is_finite() {
            return Err(Error::setting(
                "limits",
                limits,
                format!(
                    "give {}=±VALUE: the largest {} the design may command",
                    self.column(),
                    match self {
                        Commanded::Voltage => "voltage",
                        Commanded::Current => "current",
                    }
                ),
            ));
        }
        Ok(limit)
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

/// The user's model on the design's sampling: a problem whose one record is a placeholder at
/// `times` (no data of it is fitted). A current-driven model's record carries the drive's input
/// I and measures ω; the drive reads its scales from that record (the largest current it is
/// commanded, the largest speed it reaches: what a term's default smoothing speed and the
/// default priors are drawn to), so the placeholder holds the limits there, the most a designed
/// record may command and reach. A `position_loop` model is refused ([`Commanded::of`]).
pub fn design_problem(
    model: &crate::io::ModelFile,
    times: &[f64],
    limits: &Limits,
) -> Result<Problem, Error> {
    let m = times.len();
    let held = |v: f64| vec![if v.is_finite() { v } else { 0.0 }; m];
    let (channels, inputs) = match Commanded::of(model.base)? {
        Commanded::Voltage => (
            vec![("I".into(), vec![0.0; m]), ("omega".into(), vec![0.0; m])],
            Vec::new(),
        ),
        Commanded::Current => (
            vec![("omega".into(), held(limits.speed))],
            vec![("I".into(), held(limits.current))],
        ),
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
/// one for: the paper's, 2 A on I and 10 rad/s on ω.
pub fn default_noise_sd(channel: &str) -> f64 {
    let [current, speed] = crate::study::cases::NOISE_SD;
    if channel == "I" { current } else { speed }
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
    /// For a current-driven candidate `input` is the commanded current: the drive holds its
    /// value at each sample until the next (the drive's scales stay the placeholder record's,
    /// see [`design_problem`]).
    pub fn forward(&self, input: &VoltageInput, times: &[f64]) -> Result<ForwardModel, Error> {
        let model = match Commanded::of(self.problem.model.base)? {
            Commanded::Voltage => self
                .problem
                .model
                .model(input.clone())
                .map_err(Error::invalid)?,
            Commanded::Current => {
                let mut model = self.problem.model_for(self.problem.recording())?;
                let drive = model
                    .drive
                    .as_mut()
                    .ok_or_else(|| Error::invalid("a current-driven model without its drive"))?;
                drive.times = times.to_vec();
                drive.input = times
                    .iter()
                    .map(|&t| input.value_at(t))
                    .collect::<Option<Vec<f64>>>()
                    .ok_or_else(|| {
                        Error::invalid(
                            "a current-driven design needs a held current, not the constant U",
                        )
                    })?;
                drive.disturbance = vec![0.0; times.len()];
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
    pub fn commanded(&self) -> Result<Commanded, Error> {
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
