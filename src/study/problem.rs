//! A calibration problem: recordings plus the nominal model the user believes, from files or
//! from the paper's synthetic set-up.

use std::path::{Path, PathBuf};

use crate::bayes::{CalibratedParameter, CalibrationPosterior, ModelSettings, Observations};
use crate::forward::ForwardModel;
use crate::io::{CalibrateEntry, ModelFile, Recording, read_model_file, read_recording_for};
use crate::motor::{ActiveTerm, MotorModel, MotorParam, MotorParameters, Term, VoltageInput};
use crate::ode::SolverSettings;
use crate::parameter::ParamId;
use crate::synthetic::{PaperSetup, SyntheticData, paper_measurements};

use crate::error::Error;

/// ε of a drive base's vague noise prior InvGamma(ε, ε²) (see [`Problem::posterior`]).
const VAGUE_NOISE_SHAPE: f64 = 1e-3;

/// Starting values tried for a parameter with a bounded support (a time in the record): the
/// likelihood is multimodal in a switching time, so one start from the prior's median can stop
/// in the wrong valley.
pub const BOUNDED_STARTS: [f64; 7] = [0.1, 0.25, 0.4, 0.5, 0.6, 0.75, 0.9];

/// What is known only in a synthetic experiment: the truth behind the data.
#[derive(Clone, Debug)]
pub struct Reference {
    pub truth: MotorParameters,
    pub noise_sd: Vec<f64>,
    pub realised_noise_sd: Vec<f64>,
    /// The reference discrepancy d0 = G(R0) − G_φ(R0) per channel (§2.4, eq. 9).
    pub discrepancy: Vec<Vec<f64>>,
}

/// Recordings and the model they are calibrated with: the physics is shared, the noise and
/// the discrepancy belong to each recording.
#[derive(Clone, Debug)]
pub struct Problem {
    pub label: String,
    pub recordings: Vec<Recording>,
    pub model: ModelFile,
    pub reference: Option<Reference>,
}

impl Problem {
    /// The paper's experiment for a noise seed: data from φ = 1, model with c_g = 0.009.
    pub fn paper(seed: u64) -> Result<Self, Error> {
        let setup = PaperSetup::default();
        let data = paper_measurements(&setup, seed).map_err(|e| Error::Numerical(e.to_string()))?;
        let model = ModelFile {
            motor: MotorParameters::paper_simulation_model(),
            ..ModelFile::default()
        };
        let reference = paper_reference(&setup, &data, &model.motor)?;
        Ok(Self {
            label: format!("paper synthetic data (seed {seed})"),
            recordings: vec![recording_from(&data, "paper synthetic data", None)],
            model,
            reference: Some(reference),
        })
    }

    /// Recordings (one or more) and a model file; every recording is read with the model
    /// file's `[channels]`.
    pub fn from_files(data: &[PathBuf], model: &Path) -> Result<Self, Error> {
        if data.is_empty() {
            return Err(Error::setting("data", "", "no recording given"));
        }
        let model_file = read_model_file(model)?;
        let recordings = data
            .iter()
            .map(|path| read_recording_for(path, &model_file.channels, model_file.base))
            .collect::<Result<Vec<_>, _>>()?;
        let label = data
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(" + ");
        Ok(Self {
            label,
            recordings,
            model: model_file,
            reference: None,
        })
    }

    /// The first (for the paper's problem, the only) recording.
    pub fn recording(&self) -> &Recording {
        &self.recordings[0]
    }

    /// The model driven by a recording's input, with the model file's terms.
    pub fn model_for(&self, recording: &Recording) -> Result<MotorModel, Error> {
        self.model
            .model_for_recording(recording)
            .map_err(Error::invalid)
    }

    /// A drive base's speed scale: the largest over its records; `None` for the voltage-driven
    /// motor.
    pub fn speed_scale(&self) -> Result<Option<f64>, Error> {
        if !self.model.base.is_drive() {
            return Ok(None);
        }
        let mut largest = 0.0f64;
        for r in &self.recordings {
            if let Some(drive) = &self.model_for(r)?.drive {
                largest = largest.max(drive.speed_scale);
            }
        }
        Ok(Some(largest))
    }

    /// What is calibrated: the `[calibrate]` table's parameters in the order of the model's
    /// parameter vector, or R alone.
    pub fn calibrated_names(&self) -> Result<Vec<String>, Error> {
        let Some(entries) = &self.model.calibrate else {
            return Ok(vec!["R".into()]);
        };
        let model = self.model_for(self.recording())?;
        let mut names: Vec<(usize, String)> = entries
            .iter()
            .map(|e| {
                model
                    .parameter_index(&e.id)
                    .map(|i| (i, e.id.to_string()))
                    .ok_or_else(|| Error::invalid(format!("unknown parameter '{}'", e.id)))
            })
            .collect::<Result<_, _>>()?;
        names.sort();
        Ok(names.into_iter().map(|(_, n)| n).collect())
    }

    /// The forward model of each recording.
    pub fn forward_models(&self, solver: SolverSettings) -> Result<Vec<ForwardModel>, Error> {
        let calibrated = self.calibrated_names()?;
        self.recordings
            .iter()
            .map(|r| {
                ForwardModel::new(self.model_for(r)?, r.time.clone(), &calibrated, solver)
                    .map_err(|e| Error::invalid(format!("{}: {e}", r.source)))
            })
            .collect()
    }

    /// The forward model of the first recording.
    pub fn forward(&self, solver: SolverSettings) -> Result<ForwardModel, Error> {
        Ok(self.forward_models(solver)?.remove(0))
    }

    /// BM1/BM2 as the model file's `[discrepancy]` says, unless the command line said otherwise
    /// (`bm`: 1 or 2, `k`: the degree).
    pub fn model_settings(&self, bm: Option<u8>, k: Option<usize>) -> ModelSettings {
        let from_file = self.model.discrepancy.as_ref();
        let mut settings = ModelSettings::default();
        if let Some(d) = from_file {
            settings.discrepancy_degree = d.basis.map(|_| d.degree);
            if let Some(basis) = d.basis {
                settings.discrepancy_basis = basis;
            }
        }
        let degree = k
            .or(from_file.map(|d| d.degree))
            .unwrap_or(ModelSettings::default().discrepancy_degree.unwrap_or(9));
        match bm {
            Some(1) => settings.discrepancy_degree = None,
            Some(_) => settings.discrepancy_degree = Some(degree),
            None if k.is_some() => settings.discrepancy_degree = Some(degree),
            None => {}
        }
        settings
    }

    /// The problem with `added` switched on (at their defaults) and calibrated with their default
    /// priors, beside what the user's model already calibrates (R when it says nothing); BM1.
    pub fn with_terms(&self, added: &[String]) -> Result<Problem, Error> {
        let base = self;
        let mut problem = base.clone();
        let mut calibrate = match &base.model.calibrate {
            Some(entries) => entries.clone(),
            None => vec![CalibrateEntry {
                id: ParamId::base(MotorParam::Resistance.key()),
                prior: None,
            }],
        };
        let speed_scale = base.speed_scale()?;
        for name in added {
            if problem.model.terms.iter().any(|t| t.term.name() == name) {
                return Err(Error::invalid(format!(
                    "the model already has the term {name}"
                )));
            }
            let term = Term::named_for(name, speed_scale).ok_or_else(|| {
                Error::invalid(format!(
                    "unknown candidate '{name}' (known: {})",
                    Term::NAMES.join(", ")
                ))
            })?;
            // Only what the term's settings let be calibrated: a law's listed coefficients.
            for p in term
                .params()
                .iter()
                .filter(|p| term.check_calibrated(p.key).is_ok())
            {
                calibrate.push(CalibrateEntry {
                    id: ParamId::of_term(name, p.key),
                    prior: None,
                });
            }
            problem.model.terms.push(ActiveTerm::with_defaults(term));
        }
        problem.model.terms.sort_by_key(|t| t.term.rank());
        problem.model.calibrate = Some(calibrate);
        problem.model.schema = 2;
        problem.model.discrepancy = None;
        Ok(problem)
    }

    /// Observed values in all recordings and channels: the N of a score's ½·d·ln N.
    pub fn n_observations(&self) -> usize {
        self.recordings
            .iter()
            .map(|r| r.n_samples() * r.channels.len())
            .sum()
    }

    pub fn posterior(&self, settings: &ModelSettings) -> Result<CalibrationPosterior, Error> {
        // The paper's InvGamma(1, 1) on σ suits its channels (A and rad/s, σ of order 1). A
        // drive base measures in whatever unit the rig has (µm of position on a ball screw,
        // where it would put −10⁵ nats on the truth), so its noise prior is the vague
        // InvGamma(ε, ε²), flat in log σ over every scale a record can have.
        let vague;
        let settings = if self.model.base.is_drive()
            && settings.noise_prior_shape == ModelSettings::default().noise_prior_shape
            && settings.noise_prior_scale == ModelSettings::default().noise_prior_scale
        {
            vague = ModelSettings {
                noise_prior_shape: VAGUE_NOISE_SHAPE,
                noise_prior_scale: VAGUE_NOISE_SHAPE * VAGUE_NOISE_SHAPE,
                ..settings.clone()
            };
            &vague
        } else {
            settings
        };
        let forwards = self.forward_models(SolverSettings::default())?;
        let mut records = Vec::new();
        for (forward, recording) in forwards.into_iter().zip(&self.recordings) {
            let channels = forward
                .channels()
                .iter()
                .map(|name| {
                    recording.channel(name).map(|v| v.to_vec()).ok_or_else(|| {
                        Error::invalid(format!("{}: no channel '{name}'", recording.source))
                    })
                })
                .collect::<Result<Vec<_>, _>>()?;
            let obs = Observations {
                label: if self.recordings.len() > 1 {
                    recording.source.clone()
                } else {
                    self.label.clone()
                },
                channels,
            };
            records.push((forward, obs));
        }
        let Some(entries) = &self.model.calibrate else {
            return CalibrationPosterior::new(records, settings).map_err(Error::invalid);
        };
        // Priors scaled to the longest recording: a load step may happen in any of them.
        let longest = records
            .iter()
            .max_by(|a, b| {
                let end = |f: &ForwardModel| f.times().last().copied().unwrap_or(0.0);
                end(&a.0).total_cmp(&end(&b.0))
            })
            .map(|(f, _)| f.calibrated_specs())
            .unwrap_or_default();
        let theta = longest
            .iter()
            .map(|spec| {
                let prior = entries
                    .iter()
                    .find(|e| e.id == spec.id)
                    .and_then(|e| e.prior);
                CalibratedParameter::new(spec, prior)
                    .map_err(|e| Error::invalid(format!("{}: {e}", self.label)))
            })
            .collect::<Result<Vec<_>, _>>()?;
        CalibrationPosterior::with_parameters(records, theta, settings).map_err(Error::invalid)
    }
}

/// A synthetic recording as the reader would return it; `voltage` is the held input's values
/// (`None` for a constant U).
pub fn recording_from(data: &SyntheticData, source: &str, voltage: Option<Vec<f64>>) -> Recording {
    Recording {
        source: source.into(),
        time: data.times.clone(),
        channels: data
            .channel_names
            .iter()
            .cloned()
            .zip(data.measured.iter().cloned())
            .collect(),
        voltage,
        inputs: Vec::new(),
    }
}

fn paper_reference(
    setup: &PaperSetup,
    data: &SyntheticData,
    model: &MotorParameters,
) -> Result<Reference, Error> {
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
    .map_err(Error::invalid)?;
    let mut g_phi = vec![0.0; forward.n_outputs()];
    forward
        .simulate(&[], &mut g_phi)
        .map_err(|e| Error::Numerical(e.to_string()))?;
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
