//! What a design is judged on: the candidates, each at its estimate, simulated at the design's
//! sample times under any input, with the noise σ the recording showed.

use std::collections::BTreeMap;

use crate::error::Error;
use crate::forward::ForwardModel;
use crate::io::Recording;
use crate::motor::{Term, VoltageInput};
use crate::ode::SolverSettings;
use crate::parameter::{ParamId, ParameterSpec};
use crate::study::Problem;

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
    /// σ of each channel (I, ω).
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

/// The user's model (any recording) as a problem whose record is the design's sampling.
pub fn design_problem(model: &crate::io::ModelFile, times: &[f64]) -> Result<Problem, Error> {
    if model.base.is_drive() {
        return Err(Error::invalid(format!(
            "design drives the voltage-driven motor; a {} model's input is a reference, which \
             design does not search yet",
            model.base.name()
        )));
    }
    Ok(Problem {
        label: "design".into(),
        recordings: vec![Recording {
            source: "design".into(),
            time: times.to_vec(),
            channels: vec![
                ("I".into(), vec![0.0; times.len()]),
                ("omega".into(), vec![0.0; times.len()]),
            ],
            voltage: None,
            inputs: Vec::new(),
        }],
        model: model.clone(),
        reference: None,
    })
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
    pub fn forward(&self, input: &VoltageInput, times: &[f64]) -> Result<ForwardModel, Error> {
        let model = self
            .problem
            .model
            .model(input.clone())
            .map_err(Error::invalid)?;
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
