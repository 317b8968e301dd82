//! A calibration problem: recordings plus the nominal model the user believes, from files or
//! from the paper's synthetic set-up.

use std::path::Path;

use crate::bayes::{CalibrationPosterior, ModelSettings, Observations};
use crate::forward::ForwardModel;
use crate::io::{ModelFile, Recording, read_model_file, read_recording};
use crate::motor::{MOTOR_CHANNELS, MotorModel, MotorParameters, VoltageInput};
use crate::ode::SolverSettings;
use crate::synthetic::{PaperSetup, SyntheticData, paper_measurements};

use super::AppError;

/// What is known only in a synthetic experiment: the truth behind the data.
#[derive(Clone, Debug)]
pub struct Reference {
    pub truth: MotorParameters,
    pub noise_sd: Vec<f64>,
    pub realised_noise_sd: Vec<f64>,
    /// The reference discrepancy d0 = G(R0) − G_φ(R0) per channel (§2.4, eq. 9).
    pub discrepancy: Vec<Vec<f64>>,
}

/// One recording and the model it is calibrated with.
#[derive(Clone, Debug)]
pub struct Problem {
    pub label: String,
    pub recording: Recording,
    pub model: ModelFile,
    pub reference: Option<Reference>,
}

impl Problem {
    /// The paper's experiment for a noise seed: data from φ = 1, model with c_g = 0.009.
    pub fn paper(seed: u64) -> Result<Self, AppError> {
        let setup = PaperSetup::default();
        let data =
            paper_measurements(&setup, seed).map_err(|e| AppError::Numerical(e.to_string()))?;
        let model = ModelFile {
            motor: MotorParameters::paper_simulation_model(),
            ..ModelFile::default()
        };
        let reference = paper_reference(&setup, &data, &model.motor)?;
        Ok(Self {
            label: format!("paper synthetic data (seed {seed})"),
            recording: recording_from(&data, "paper synthetic data"),
            model,
            reference: Some(reference),
        })
    }

    pub fn from_files(data: &Path, model: &Path) -> Result<Self, AppError> {
        let model_file = read_model_file(model)?;
        let recording = read_recording(data, &model_file.channels)?;
        Ok(Self {
            label: data.display().to_string(),
            recording,
            model: model_file,
            reference: None,
        })
    }

    /// The forward model of the recording with R calibrated.
    pub fn forward(&self, solver: SolverSettings) -> Result<ForwardModel, AppError> {
        let motor = MotorModel::new(self.model.motor.clone(), self.recording.voltage_input());
        ForwardModel::new(motor, self.recording.time.clone(), &["R"], solver)
            .map_err(AppError::Usage)
    }

    pub fn posterior(&self, settings: &ModelSettings) -> Result<CalibrationPosterior, AppError> {
        let forward = self.forward(SolverSettings::default())?;
        let channels = MOTOR_CHANNELS
            .iter()
            .map(|name| {
                self.recording
                    .channel(name)
                    .map(|v| v.to_vec())
                    .ok_or_else(|| AppError::Usage(format!("{}: no channel '{name}'", self.label)))
            })
            .collect::<Result<Vec<_>, _>>()?;
        let obs = Observations {
            label: self.label.clone(),
            channels,
        };
        CalibrationPosterior::new(vec![(forward, obs)], settings).map_err(AppError::Usage)
    }
}

fn recording_from(data: &SyntheticData, source: &str) -> Recording {
    Recording {
        source: source.into(),
        time: data.times.clone(),
        channels: data
            .channel_names
            .iter()
            .cloned()
            .zip(data.measured.iter().cloned())
            .collect(),
        voltage: None,
    }
}

fn paper_reference(
    setup: &PaperSetup,
    data: &SyntheticData,
    model: &MotorParameters,
) -> Result<Reference, AppError> {
    let at_true_resistance = MotorParameters {
        resistance: setup.truth.resistance,
        ..model.clone()
    };
    let simulation = MotorModel::new(at_true_resistance, VoltageInput::Constant);
    let forward = ForwardModel::new(
        simulation,
        data.times.clone(),
        &[] as &[&str],
        SolverSettings::for_data_generation(),
    )
    .map_err(AppError::Usage)?;
    let mut g_phi = vec![0.0; forward.n_outputs()];
    forward
        .simulate(&[], &mut g_phi)
        .map_err(|e| AppError::Numerical(e.to_string()))?;
    let m = data.times.len();
    let discrepancy = (0..data.noise_free.len())
        .map(|c| {
            data.noise_free[c]
                .iter()
                .zip(&g_phi[c * m..(c + 1) * m])
                .map(|(a, b)| a - b)
                .collect()
        })
        .collect();
    Ok(Reference {
        truth: setup.truth.clone(),
        noise_sd: setup.noise_sd.to_vec(),
        realised_noise_sd: data.realised_noise_sd(),
        discrepancy,
    })
}
