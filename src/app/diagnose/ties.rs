//! Ties: a candidate that scores within the threshold of the selected one on this recording. It
//! is reported as a tie when another input would tell the two apart, with that input; when no
//! input of ours would, the pair is not identifiable from these channels and goes in the notes.
//!
//! The check is a simulated experiment: the selected model at its estimate drives the motor
//! with the other input, noise at the fitted σ is added, and both candidates are refitted to
//! it. The input separates them when the selected one then leads by more than the threshold.

use crate::app::AppError;
use crate::app::problem::{Problem, recording_from};
use crate::app::simulate::InputProfile;
use crate::synthetic::generate;

use super::candidates::{CandidateFit, fit_candidate, problem_with};

/// The inputs tried, in the order a user would rather run them.
const INPUTS: [InputProfile; 2] = [InputProfile::Reversal, InputProfile::Step];

/// The first input on which `selected` beats `other` by more than `threshold`, if any.
pub fn separating_input(
    base: &Problem,
    selected: &CandidateFit,
    other: &str,
    noise_sd: &[f64],
    threshold: f64,
    seed: u64,
) -> Result<Option<InputProfile>, AppError> {
    let truth = truth_problem(base, selected)?;
    for input in INPUTS {
        let recording = &base.recordings[0];
        let model_file = &truth.model;
        let voltage = input.voltage(model_file.motor.voltage, &recording.time);
        let model = model_file.model(voltage.clone()).map_err(AppError::Usage)?;
        let data = generate(&model, &recording.time, noise_sd, seed)
            .map_err(|e| AppError::Numerical(e.to_string()))?;
        let values = match &voltage {
            crate::motor::VoltageInput::Held { values, .. } => Some(values.clone()),
            crate::motor::VoltageInput::Constant => None,
        };
        let synthetic = recording_from(&data, &format!("simulated {input:?} input"), values);
        let experiment = Problem {
            label: synthetic.source.clone(),
            recordings: vec![synthetic],
            model: base.model.clone(),
            reference: None,
        };
        let a = fit_candidate(&experiment, &selected.added)?;
        let b = fit_candidate(&experiment, &[other.to_string()])?;
        if a.score - b.score > threshold {
            return Ok(Some(input));
        }
    }
    Ok(None)
}

/// The user's model with the selected terms at their estimates and the calibrated base
/// parameters at theirs: what the recording says the motor is.
pub fn truth_problem(base: &Problem, selected: &CandidateFit) -> Result<Problem, AppError> {
    let mut problem = problem_with(base, &selected.added)?;
    for (name, &value) in &selected.theta {
        problem.model.set_value(name, value);
    }
    Ok(problem)
}
