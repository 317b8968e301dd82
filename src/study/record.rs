//! A synthetic record driven by an input held between its samples: the voltage of the
//! voltage-driven motor, the current a `current_driven` drive is commanded, or the reference
//! position of a `position_loop` (what `design` writes to `input.csv` and `simulate --input
//! FILE` plays back).

use crate::error::Error;
use crate::io::{ModelFile, Recording};
use crate::motor::{Base, VoltageInput};
use crate::synthetic::{SyntheticData, generate};

use super::recording_from;

/// The record `file`'s model makes under `values` held from each of `times` on, with noise
/// σ = `noise_sd`: two numbers, the first σ_I or σ_q, the second σ_ω or σ_force, each channel
/// the model measures taking its own (a current-driven model measures ω alone, with the second;
/// its current is the input, recorded as given). The recording carries the input as its `U`
/// column, as the input `I` of a current-driven record, or as the reference `q_ref` of a
/// position loop, whose axis starts at rest at the reference's first value.
pub fn held_input_record(
    file: &ModelFile,
    times: &[f64],
    values: Vec<f64>,
    noise_sd: &[f64; 2],
    seed: u64,
    source: &str,
) -> Result<(Recording, SyntheticData), Error> {
    let numerical = |e: crate::ode::OdeError| Error::Numerical(e.to_string());
    let m = times.len();
    let (channels, inputs, sd) = match file.base {
        Base::VoltageDriven => {
            let input = VoltageInput::Held {
                times: times.to_vec(),
                values,
            };
            return voltage_record(file, times, input, noise_sd, seed, source);
        }
        Base::CurrentDriven => (
            vec![("omega".into(), vec![0.0; m])],
            vec![("I".into(), values)],
            vec![noise_sd[1]],
        ),
        Base::PositionLoop => {
            let start = values.first().copied().unwrap_or(0.0);
            (
                vec![("q".into(), vec![start; m]), ("force".into(), vec![0.0; m])],
                vec![("q_ref".into(), values)],
                noise_sd.to_vec(),
            )
        }
    };
    let input = Recording {
        source: source.into(),
        time: times.to_vec(),
        channels,
        voltage: None,
        inputs,
    };
    let model = file.model_for_recording(&input).map_err(Error::invalid)?;
    let data = generate(&model, times, &sd, seed).map_err(numerical)?;
    let recording = Recording {
        inputs: input.inputs,
        ..recording_from(&data, source, None)
    };
    Ok((recording, data))
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
