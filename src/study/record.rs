//! A synthetic record driven by an input held between its samples: the voltage of the
//! voltage-driven motor, or the current a `current_driven` drive is commanded (what `design`
//! writes to `input.csv` and `simulate --input FILE` plays back).

use crate::error::Error;
use crate::io::{ModelFile, Recording};
use crate::motor::{Base, VoltageInput};
use crate::synthetic::{SyntheticData, generate};

use super::recording_from;

/// The column of an input file that drives a model of `base`: `U`, or `I` for a current-driven
/// model. A `position_loop` model is refused: its input is a reference position fed through its
/// controller, not a series to play back.
pub fn input_column(base: Base) -> Result<&'static str, Error> {
    match base {
        Base::VoltageDriven => Ok("U"),
        Base::CurrentDriven => Ok("I"),
        Base::PositionLoop => Err(Error::invalid(
            "a position_loop model is driven by a reference position through its controller; \
             only a voltage (t,U) or a current command (t,I, current_driven) can be played back",
        )),
    }
}

/// The record `file`'s model makes under `values` held from each of `times` on, with noise
/// σ = `noise_sd` — given as (σ_I, σ_ω), each channel the model measures taking its own (a
/// current-driven model measures ω alone: its current is the input, recorded as given). The
/// recording carries the input as its `U` column, or as the input `I` of a current-driven
/// record.
pub fn held_input_record(
    file: &ModelFile,
    times: &[f64],
    values: Vec<f64>,
    noise_sd: &[f64; 2],
    seed: u64,
    source: &str,
) -> Result<(Recording, SyntheticData), Error> {
    let numerical = |e: crate::ode::OdeError| Error::Numerical(e.to_string());
    input_column(file.base)?;
    match file.base {
        Base::CurrentDriven => {
            let input = Recording {
                source: source.into(),
                time: times.to_vec(),
                channels: vec![("omega".into(), vec![0.0; times.len()])],
                voltage: None,
                inputs: vec![("I".into(), values)],
            };
            let model = file.model_for_recording(&input).map_err(Error::invalid)?;
            let data = generate(&model, times, &[noise_sd[1]], seed).map_err(numerical)?;
            let recording = Recording {
                inputs: input.inputs,
                ..recording_from(&data, source, None)
            };
            Ok((recording, data))
        }
        _ => {
            let input = VoltageInput::Held {
                times: times.to_vec(),
                values,
            };
            voltage_record(file, times, input, noise_sd, seed, source)
        }
    }
}

/// The record `file`'s voltage-driven model makes under `input` (a held voltage, or constant at
/// the model's U) at `times`, with noise σ = `noise_sd` (σ_I, σ_ω); a held voltage is recorded
/// as the `U` column. What `simulate` writes, and the experiment a tie is checked on.
pub fn voltage_record(
    file: &ModelFile,
    times: &[f64],
    input: VoltageInput,
    noise_sd: &[f64],
    seed: u64,
    source: &str,
) -> Result<(Recording, SyntheticData), Error> {
    let voltage = input.held_values().map(<[f64]>::to_vec);
    let model = file.model(input).map_err(Error::invalid)?;
    let data =
        generate(&model, times, noise_sd, seed).map_err(|e| Error::Numerical(e.to_string()))?;
    Ok((recording_from(&data, source, voltage), data))
}
