//! Ties: a candidate that scores within the threshold of the selected one on this recording. It
//! is reported as a tie when another input would tell the two apart, with that input; when no
//! input of ours would, the pair is not identifiable from these channels and goes in the notes.
//!
//! The check is a simulated experiment: the selected model at its estimate drives the motor
//! with the other input, noise at the fitted σ is added, and both candidates are refitted to
//! it. The input separates them when the selected one then leads by more than the threshold.

use crate::error::Error;
use crate::study::{InputProfile, Problem, voltage_record};

use super::candidate::{Candidate, fit_candidate};

/// The inputs tried, in the order a user would rather run them (`design` reports its designed
/// input's gap beside theirs).
pub const TIE_EXPERIMENTS: [InputProfile; 2] = [InputProfile::Reversal, InputProfile::Step];

/// The first input on which `selected` beats `other` by more than `threshold`, if any.
pub fn separating_input(
    base: &Problem,
    selected: &Candidate,
    other: &str,
    noise_sd: &[f64],
    threshold: f64,
    seed: u64,
) -> Result<Option<InputProfile>, Error> {
    let truth = selected.fitted_problem();
    if base.model.base.is_drive() {
        return reversed_record(base, &truth, selected, other, noise_sd, threshold, seed);
    }
    for input in TIE_EXPERIMENTS {
        let times = &base.recordings[0].time;
        let voltage = input.voltage(truth.model.motor.voltage, times);
        let source = format!("simulated {input:?} input");
        let (synthetic, _) = voltage_record(&truth.model, times, voltage, noise_sd, seed, &source)?;
        if separates(base, synthetic, selected, other, threshold)? {
            return Ok(Some(input));
        }
    }
    Ok(None)
}

/// A drive base's experiment: the first record run the other way (its current negated, or its
/// reference mirrored about the start), simulated by the selected model with noise at the
/// fitted σ. Reversal is the experiment that tells a friction, which turns with the motion,
/// from a constant load, which does not.
#[allow(clippy::too_many_arguments)]
fn reversed_record(
    base: &Problem,
    truth: &Problem,
    selected: &Candidate,
    other: &str,
    noise_sd: &[f64],
    threshold: f64,
    seed: u64,
) -> Result<Option<InputProfile>, Error> {
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};

    let mut reversed = base.recordings[0].clone();
    reversed.source = "simulated reversed record".into();
    for (name, series) in reversed.inputs.iter_mut() {
        let start = series.first().copied().unwrap_or(0.0);
        for v in series.iter_mut() {
            *v = match name.as_str() {
                "q_ref" => 2.0 * start - *v,
                _ => -*v,
            };
        }
    }
    let simulated = Problem {
        label: reversed.source.clone(),
        recordings: vec![reversed],
        model: truth.model.clone(),
        reference: None,
    };
    let predicted = crate::study::predict_records(&simulated)?;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed ^ 0x7e7e_5eed);
    let mut recording = simulated.recordings[0].clone();
    for ((_, values), (c, (_, _, model))) in recording
        .channels
        .iter_mut()
        .zip(predicted[0].channels.iter().enumerate())
    {
        let noise = Normal::new(0.0, noise_sd[c].max(f64::MIN_POSITIVE))
            .map_err(|e| Error::Numerical(e.to_string()))?;
        for (v, g) in values.iter_mut().zip(model) {
            *v = g + noise.sample(&mut rng);
        }
    }
    Ok(separates(base, recording, selected, other, threshold)?.then_some(InputProfile::Reversal))
}

/// Whether the selected terms beat `other` by more than `threshold` on a simulated recording,
/// both refitted to it from the user's model.
fn separates(
    base: &Problem,
    recording: crate::io::Recording,
    selected: &Candidate,
    other: &str,
    threshold: f64,
) -> Result<bool, Error> {
    let experiment = Problem {
        label: recording.source.clone(),
        recordings: vec![recording],
        model: base.model.clone(),
        reference: None,
    };
    let a = fit_candidate(&experiment, &selected.added)?;
    let b = fit_candidate(&experiment, &[other.to_string()])?;
    Ok(a.score - b.score > threshold)
}
