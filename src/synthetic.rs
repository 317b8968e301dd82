//! Synthetic measurements (§2.3): the motor simulated at a tight tolerance plus seeded Gaussian
//! noise, one channel after the other.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

use crate::forward::ForwardModel;
use crate::motor::{MotorModel, MotorParameters, VoltageInput};
use crate::ode::{OdeError, SolverSettings};

/// The paper's experiment: data from φ = 1 (c_g = 0.01), noise σ_I = 2 A and σ_ω = 10 rad/s,
/// M = 501 samples at t_i = i·T/M on T = 0.5 s.
#[derive(Clone, Debug)]
pub struct PaperSetup {
    pub truth: MotorParameters,
    pub noise_sd: [f64; 2],
    pub t_end: f64,
    pub samples: usize,
}

impl Default for PaperSetup {
    fn default() -> Self {
        Self {
            truth: MotorParameters::default(),
            noise_sd: [2.0, 10.0],
            t_end: 0.5,
            samples: 501,
        }
    }
}

/// The seed of the paper's data set in `motorcal reproduce`, fixed before any run was made.
pub const DEFAULT_SEED: u64 = 20180823;

/// t_i = i·T/M, i = 1..M (no sample at t = 0).
pub fn sample_times(t_end: f64, samples: usize) -> Vec<f64> {
    (1..=samples)
        .map(|i| i as f64 * t_end / samples as f64)
        .collect()
}

/// Noise-free and measured channels of one synthetic recording.
#[derive(Clone, Debug)]
pub struct SyntheticData {
    pub times: Vec<f64>,
    pub channel_names: Vec<String>,
    pub noise_free: Vec<Vec<f64>>,
    pub measured: Vec<Vec<f64>>,
    pub seed: u64,
}

impl SyntheticData {
    /// The realised noise standard deviation of each channel (what a perfect model would fit).
    pub fn realised_noise_sd(&self) -> Vec<f64> {
        self.measured
            .iter()
            .zip(&self.noise_free)
            .map(|(y, g)| {
                let n = y.len() as f64;
                let e: Vec<f64> = y.iter().zip(g).map(|(a, b)| a - b).collect();
                let mean = e.iter().sum::<f64>() / n;
                (e.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
            })
            .collect()
    }
}

/// Simulates `model` at `times` at the data-generation tolerance and adds N(0, σ_c²) noise to
/// each channel c, drawing all of channel 0's noise first.
pub fn generate(
    model: &MotorModel,
    times: &[f64],
    noise_sd: &[f64],
    seed: u64,
) -> Result<SyntheticData, OdeError> {
    let forward = ForwardModel::new(
        model.clone(),
        times.to_vec(),
        &[] as &[&str],
        SolverSettings::for_data_generation(),
    )
    .map_err(OdeError::BadOutputTimes)?;
    let mut out = vec![0.0; forward.n_outputs()];
    forward.simulate(&[], &mut out)?;
    let m = times.len();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut noise_free = Vec::new();
    let mut measured = Vec::new();
    for (c, &sd) in noise_sd.iter().enumerate().take(forward.channels().len()) {
        let g = out[c * m..(c + 1) * m].to_vec();
        let normal = Normal::new(0.0, sd).map_err(|e| OdeError::BadOutputTimes(e.to_string()))?;
        let y = g.iter().map(|v| v + normal.sample(&mut rng)).collect();
        noise_free.push(g);
        measured.push(y);
    }
    Ok(SyntheticData {
        times: times.to_vec(),
        channel_names: forward.channels().iter().map(|s| s.to_string()).collect(),
        noise_free,
        measured,
        seed,
    })
}

/// The paper's synthetic measurements for a seed.
pub fn paper_measurements(setup: &PaperSetup, seed: u64) -> Result<SyntheticData, OdeError> {
    let model = MotorModel::new(setup.truth.clone(), VoltageInput::Constant);
    generate(
        &model,
        &sample_times(setup.t_end, setup.samples),
        &setup.noise_sd,
        seed,
    )
}
