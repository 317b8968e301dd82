//! `motorcal simulate`: a synthetic recording, the nominal model a user would believe, and the
//! truth that made the data.

use std::path::PathBuf;

use crate::io::{ModelFile, read_model_file, write_model_file, write_recording};
use crate::motor::{MotorParameters, VoltageInput};
pub use crate::study::InputProfile;

/// The command line names the profiles as the model files and reports do.
impl clap::ValueEnum for InputProfile {
    fn value_variants<'a>() -> &'a [Self] {
        &InputProfile::ALL
    }

    fn to_possible_value(&self) -> Option<clap::builder::PossibleValue> {
        Some(clap::builder::PossibleValue::new(self.name()).help(self.help()))
    }
}
use crate::synthetic::{DEFAULT_SEED, generate, sample_times};

use super::AppError;

/// Options of `motorcal simulate`.
#[derive(Clone, Debug)]
pub struct SimulateOptions {
    /// The motor that makes the data; the paper's (φ = 1) when absent.
    pub truth: Option<PathBuf>,
    /// The model the user believes; when absent, the paper's simulation model (c_g = 0.009) for
    /// the paper's truth, or the truth itself.
    pub nominal: Option<PathBuf>,
    pub out: PathBuf,
    pub seed: u64,
    pub input: InputProfile,
    pub noise_sd: [f64; 2],
    pub samples: usize,
    pub t_end: f64,
}

impl Default for SimulateOptions {
    fn default() -> Self {
        Self {
            truth: None,
            nominal: None,
            out: PathBuf::from("simulated"),
            seed: DEFAULT_SEED,
            input: InputProfile::Constant,
            noise_sd: [2.0, 10.0],
            samples: 501,
            t_end: 0.5,
        }
    }
}

/// What `simulate` wrote.
#[derive(Clone, Debug)]
pub struct SimulateReport {
    pub recording: PathBuf,
    pub nominal: PathBuf,
    pub truth: PathBuf,
    pub realised_noise_sd: Vec<f64>,
}

pub fn simulate(options: &SimulateOptions) -> Result<SimulateReport, AppError> {
    if options.samples < 2 {
        return Err(AppError::Usage(format!(
            "--samples {} : need at least 2 samples",
            options.samples
        )));
    }
    if !(options.t_end > 0.0 && options.t_end.is_finite()) {
        return Err(AppError::Usage(format!(
            "--t-end {} : must be a positive number of seconds",
            options.t_end
        )));
    }
    if options
        .noise_sd
        .iter()
        .any(|s| !(*s >= 0.0 && s.is_finite()))
    {
        return Err(AppError::Usage(format!(
            "--noise-sd {:?} : must be non-negative numbers",
            options.noise_sd
        )));
    }
    let truth_file = match &options.truth {
        Some(path) => read_model_file(path)?,
        None => ModelFile::default(),
    };
    let nominal_file = match (&options.nominal, &options.truth) {
        (Some(path), _) => read_model_file(path)?,
        (None, Some(_)) => truth_file.clone(),
        (None, None) => ModelFile {
            motor: MotorParameters::paper_simulation_model(),
            ..ModelFile::default()
        },
    };
    let times = sample_times(options.t_end, options.samples);
    let input = options.input.voltage(truth_file.motor.voltage, &times);
    let model = truth_file
        .model(input.clone())
        .map_err(|e| AppError::Usage(format!("--truth: {e}")))?;
    let data = generate(&model, &times, &options.noise_sd, options.seed)
        .map_err(|e| AppError::Numerical(e.to_string()))?;
    let voltage = match input {
        VoltageInput::Held { values, .. } => Some(values),
        VoltageInput::Constant => None,
    };
    let recording = crate::study::recording_from(&data, "motorcal simulate", voltage);
    let report = SimulateReport {
        recording: options.out.join("recording.csv"),
        nominal: options.out.join("motor.toml"),
        truth: options.out.join("truth.toml"),
        realised_noise_sd: data.realised_noise_sd(),
    };
    write_recording(&report.recording, &recording)?;
    write_model_file(&report.nominal, &nominal_file)?;
    write_model_file(&report.truth, &truth_file)?;
    Ok(report)
}
