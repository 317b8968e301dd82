//! `simulate`, `diagnose`, `bench` and `sweep` from Python: the library's calls with the
//! command line's defaults, their reports as Python data (the same contract as each command's
//! `--json`), long work off the interpreter and stopped by Ctrl-C where the library's chains
//! run.

use std::path::PathBuf;

use motorcal::bayes::CoefficientPrior;
use motorcal::discover::{DiscoverSettings, METRIC_ADAPTATION, discover};
use motorcal::error::Error;
use motorcal::paper::bench::BenchOptions;
use motorcal::paper::sweep::SweepOptions;
use motorcal::pipeline::{MetricAdaptation, RunSettings, SamplerKind, default_warmup};
use motorcal::sampler::ChainSettings;
use motorcal::study::{InputProfile, recording_from};
use motorcal::synthetic::{DEFAULT_SEED, generate, sample_times};
use pyo3::prelude::*;

use crate::background::interruptible;
use crate::data::{Model, Recording};
use crate::posterior::{Recordings, plausible, problem};
use crate::{py_error, setting_error, to_python};

/// A synthetic recording of `model` (default: the paper's motor, c_g = 0.01) driven by
/// `input`, with Gaussian noise of `noise_sd` (I, ω) from `seed`, as `motorcal simulate`
/// makes `recording.csv`.
#[pyfunction]
#[pyo3(signature = (model=None, input="constant", seed=DEFAULT_SEED, noise_sd=(2.0, 10.0), samples=501, t_end=0.5))]
pub fn simulate(
    model: Option<Model>,
    input: &str,
    seed: u64,
    noise_sd: (f64, f64),
    samples: usize,
    t_end: f64,
) -> PyResult<Recording> {
    let profile = InputProfile::ALL
        .into_iter()
        .find(|p| p.name() == input)
        .ok_or_else(|| {
            let names: Vec<&str> = InputProfile::ALL.iter().map(|p| p.name()).collect();
            setting_error(
                "input",
                input,
                &format!("expected one of {}", names.join(", ")),
            )
        })?;
    if samples < 2 {
        return Err(setting_error("samples", samples, "need at least 2 samples"));
    }
    if !(t_end > 0.0 && t_end.is_finite()) {
        return Err(setting_error(
            "t_end",
            t_end,
            "must be a positive number of seconds",
        ));
    }
    let noise = [noise_sd.0, noise_sd.1];
    if noise.iter().any(|s| !(*s >= 0.0 && s.is_finite())) {
        return Err(setting_error(
            "noise_sd",
            format!("{noise:?}"),
            "must be non-negative numbers",
        ));
    }
    let file = model.map(|m| m.file).unwrap_or_default();
    let times = sample_times(t_end, samples);
    let voltage = profile.voltage(file.motor.voltage, &times);
    let motor = file
        .model(voltage.clone())
        .map_err(|e| py_error(Error::invalid(format!("model: {e}"))))?;
    let data = generate(&motor, &times, &noise, seed).map_err(|e| py_error(Error::numerical(e)))?;
    let held = match voltage {
        motorcal::motor::VoltageInput::Held { values, .. } => Some(values),
        motorcal::motor::VoltageInput::Constant => None,
    };
    Ok(Recording::from_library(
        recording_from(&data, "motorcal.simulate", held),
        &file,
    ))
}

/// The chains of a command that samples, as `ChainArgs` builds them.
fn chains_run(
    sampler: SamplerKind,
    chains: usize,
    warmup: Option<usize>,
    draws: usize,
    seed: u64,
    metric: MetricAdaptation,
    threads: Option<usize>,
) -> RunSettings {
    RunSettings {
        sampler,
        chains,
        chain: ChainSettings {
            warmup: warmup.unwrap_or_else(|| default_warmup(sampler, metric)),
            draws,
            keep: None,
        },
        seed,
        threads,
        quiet: true,
        metric_adaptation: metric,
        ..RunSettings::default()
    }
}

fn metric_or(name: Option<&str>, default: MetricAdaptation) -> PyResult<MetricAdaptation> {
    name.map_or(Ok(default), |m| m.parse().map_err(py_error))
}

/// `motorcal diagnose`: which physics the model left out. Returns `(report, amended)`: the
/// report as `--json` writes it (a dict), and the amended model (`None` when nothing was
/// selected or with `rank_only`). Ctrl-C stops it at its sampled fits.
#[pyfunction]
#[pyo3(signature = (recordings, model, k=None, candidates=None, rank_only=false, force=false, chains=4, seed=DEFAULT_SEED, warmup=500, draws=500, metric_adaptation=None, threads=None))]
#[allow(clippy::too_many_arguments)]
pub fn diagnose<'py>(
    py: Python<'py>,
    recordings: Recordings,
    model: Model,
    k: Option<usize>,
    candidates: Option<Vec<String>>,
    rank_only: bool,
    force: bool,
    chains: usize,
    seed: u64,
    warmup: usize,
    draws: usize,
    metric_adaptation: Option<&str>,
    threads: Option<usize>,
) -> PyResult<(Bound<'py, PyAny>, Option<Model>)> {
    let metric = metric_or(metric_adaptation, METRIC_ADAPTATION)?;
    let run = chains_run(
        SamplerKind::NutsDense,
        chains,
        Some(warmup),
        draws,
        seed,
        metric,
        threads,
    );
    let diagnosis = interruptible(py, |stop| {
        let started = std::time::Instant::now();
        let problem = problem(&recordings, &model)?;
        let implausible = plausible(&problem, force)?;
        let settings = DiscoverSettings {
            k,
            candidates,
            run: RunSettings {
                stop: Some(stop),
                ..run
            },
            rank_only,
            implausible,
        };
        let mut diagnosis = discover(&problem, &settings)?;
        diagnosis.runtime_s = started.elapsed().as_secs_f64();
        Ok::<_, Error>(diagnosis)
    })?
    .map_err(py_error)?;
    let amended = diagnosis.amended_model.clone().map(|file| Model {
        file,
        source: "diagnose".into(),
    });
    Ok((to_python(py, &diagnosis)?, amended))
}

/// `motorcal bench`: ESS per second and per gradient of each sampler at each K and thread
/// count, as a list of dicts (the records of `--json`; `pandas.DataFrame` takes it). On the
/// paper's synthetic data unless `data` and `model` (files) are given.
#[pyfunction]
#[pyo3(signature = (k=None, samplers=None, threads=None, chains=4, draws=None, warmup=None, seed=DEFAULT_SEED, data=None, model=None, prior_family="laplace", prior_decay=0.0, metric_adaptation=None))]
#[allow(clippy::too_many_arguments)]
pub fn bench<'py>(
    py: Python<'py>,
    k: Option<Vec<usize>>,
    samplers: Option<Vec<String>>,
    threads: Option<Vec<usize>>,
    chains: usize,
    draws: Option<usize>,
    warmup: Option<usize>,
    seed: u64,
    data: Option<PathBuf>,
    model: Option<PathBuf>,
    prior_family: &str,
    prior_decay: f64,
    metric_adaptation: Option<&str>,
) -> PyResult<Bound<'py, PyAny>> {
    let defaults = BenchOptions::default();
    let samplers = match samplers {
        Some(names) => names
            .iter()
            .map(|s| s.parse::<SamplerKind>())
            .collect::<Result<Vec<_>, _>>()
            .map_err(py_error)?,
        None => defaults.samplers.clone(),
    };
    let options = BenchOptions {
        ks: k.unwrap_or(defaults.ks.clone()),
        samplers,
        threads: threads.unwrap_or(defaults.threads.clone()),
        chains,
        draws,
        warmup,
        seed,
        data,
        model,
        quiet: true,
        coefficient_prior: coefficient_prior(prior_family, prior_decay)?,
        metric_adaptation: metric_or(metric_adaptation, MetricAdaptation::default())?,
        stop: None,
    };
    let records = interruptible(py, |stop| {
        motorcal::paper::bench::bench(&BenchOptions {
            stop: Some(stop),
            ..options
        })
    })?
    .map_err(py_error)?;
    to_python(py, &records)
}

fn coefficient_prior(family: &str, decay: f64) -> PyResult<CoefficientPrior> {
    Ok(CoefficientPrior {
        family: family.parse().map_err(py_error)?,
        decay_power: decay,
        ..CoefficientPrior::default()
    })
}

/// `motorcal sweep`: BM2 for each K on the paper's synthetic data (one data seed or several),
/// the error measures of §4.2 per K, as a list of dicts (the records of `--json`).
#[pyfunction]
#[pyo3(signature = (k, data_seeds=vec![DEFAULT_SEED], sampler="nuts-dense", chains=4, warmup=None, draws=1000, seed=DEFAULT_SEED, prior_family="laplace", prior_decay=0.0, metric_adaptation=None, threads=None))]
#[allow(clippy::too_many_arguments)]
pub fn sweep<'py>(
    py: Python<'py>,
    k: Vec<usize>,
    data_seeds: Vec<u64>,
    sampler: &str,
    chains: usize,
    warmup: Option<usize>,
    draws: usize,
    seed: u64,
    prior_family: &str,
    prior_decay: f64,
    metric_adaptation: Option<&str>,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyAny>> {
    let sampler: SamplerKind = sampler.parse().map_err(py_error)?;
    let metric = metric_or(metric_adaptation, MetricAdaptation::default())?;
    let run = chains_run(sampler, chains, warmup, draws, seed, metric, threads);
    let options = SweepOptions {
        ks: k,
        coefficient_prior: coefficient_prior(prior_family, prior_decay)?,
        data_seeds,
        shard: None,
        run,
        out: PathBuf::new(),
        json: None,
        figures_at: Vec::new(),
    };
    let records = interruptible(py, |stop| {
        let mut options = options;
        options.run.stop = Some(stop);
        motorcal::paper::sweep::sweep(&options)
    })?
    .map_err(py_error)?;
    to_python(py, &records)
}
