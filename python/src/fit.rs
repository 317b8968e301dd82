//! `fit`: the MAP and its Laplace evidence, then the library's sampler, as `motorcal fit` runs
//! them for the same options (same seed, same draws, bit for bit); the chains run with the GIL
//! released and stop on Ctrl-C. The Python side wraps the arrays into `InferenceData`.

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::AtomicUsize;

use motorcal::density::LogDensity;
use motorcal::error::Error;
use motorcal::optimize::MapEstimate;
use motorcal::pipeline::{
    MetricAdaptation, RunCost, RunOutput, RunSettings, SamplerKind, default_warmup, map_estimate,
    posterior_mean, run_sampler, write_draws,
};
use motorcal::sampler::{ChainSettings, DrawRecord};
use motorcal::study::replicated_recordings;
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::background::{Progress, interruptible_with};
use crate::data::Model;
use crate::posterior::{Calibration, Posterior, Recordings};
use crate::{py_error, to_python};

/// What the chains are asked, as `motorcal fit`'s flags give it.
#[allow(clippy::too_many_arguments)]
fn run_settings(
    sampler: &str,
    chains: usize,
    warmup: Option<usize>,
    draws: usize,
    keep: Option<usize>,
    seed: u64,
    threads: Option<usize>,
    metric_adaptation: Option<&str>,
) -> Result<RunSettings, Error> {
    let sampler: SamplerKind = sampler.parse()?;
    let metric_adaptation = match metric_adaptation {
        Some(m) => m.parse()?,
        None => MetricAdaptation::default(),
    };
    let settings = RunSettings {
        sampler,
        chains,
        chain: ChainSettings {
            warmup: warmup.unwrap_or_else(|| default_warmup(sampler, metric_adaptation)),
            draws,
            keep,
        },
        seed,
        threads,
        quiet: true,
        metric_adaptation,
        ..RunSettings::default()
    };
    settings.validate()?;
    Ok(settings)
}

/// A finished fit: the posterior it ran on, the MAP, the run, and the log likelihood at the
/// MAP and at the posterior mean.
struct Fitted {
    posterior: Posterior,
    map: MapEstimate,
    map_log_likelihood: f64,
    run: RunOutput,
    mean_log_likelihood: f64,
    outputs: Vec<String>,
}

fn fit_work(
    recordings: &Recordings,
    model: &Model,
    calibration: &Calibration,
    settings: &RunSettings,
    out: Option<&PathBuf>,
) -> Result<Fitted, Error> {
    let mut posterior = Posterior::build(recordings, model, calibration)?;
    let map = map_estimate(&mut posterior.inner)?;
    let map_log_likelihood = posterior.inner.log_likelihood(&map.x)?;
    let label = posterior.settings.label();
    let run = run_sampler(&mut posterior.inner, settings, &label)?;
    let mean = posterior_mean(&run);
    let mean_log_likelihood = posterior.inner.log_likelihood(&mean)?;
    let mut outputs = Vec::new();
    if let Some(dir) = out {
        let mut meta = motorcal::io::provenance();
        meta.push(("model_file".into(), model.source.clone()));
        meta.push(("model".into(), label));
        meta.push((
            "settings".into(),
            serde_json::to_string(settings).unwrap_or_default(),
        ));
        meta.push(("seed".into(), settings.seed.to_string()));
        std::fs::create_dir_all(dir)?;
        for path in write_draws(dir, "fit", &run, &meta)? {
            outputs.push(path.display().to_string());
        }
    }
    Ok(Fitted {
        posterior,
        map,
        map_log_likelihood,
        run,
        mean_log_likelihood,
        outputs,
    })
}

/// Values of `draws` draws of every chain, chain-major: `(chains, draws, columns)`.
fn cube<'py>(
    py: Python<'py>,
    (chains, draws): (usize, usize),
    columns: usize,
    value: impl Fn(usize, usize) -> Vec<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let mut flat = Vec::with_capacity(chains * draws * columns);
    for c in 0..chains {
        for s in 0..draws {
            flat.extend(value(c, s));
        }
    }
    Ok(PyArray1::from_vec(py, flat)
        .reshape([chains, draws, columns])?
        .into_any())
}

/// Runs the fit; returns a dict of NumPy arrays and the fit's figures (see
/// `motorcal.fit`).
#[pyfunction]
#[pyo3(signature = (recordings, model, bm=None, k=None, sampler="nuts-dense", chains=4, warmup=None, draws=1000, keep=None, seed=motorcal::synthetic::DEFAULT_SEED, threads=None, metric_adaptation=None, prior_family="laplace", prior_decay=0.0, force=false, out=None, save_warmup=true, posterior_predictive=true, show_progress=false))]
#[allow(clippy::too_many_arguments)]
pub fn fit_raw<'py>(
    py: Python<'py>,
    recordings: Recordings,
    model: Model,
    bm: Option<u8>,
    k: Option<usize>,
    sampler: &str,
    chains: usize,
    warmup: Option<usize>,
    draws: usize,
    keep: Option<usize>,
    seed: u64,
    threads: Option<usize>,
    metric_adaptation: Option<&str>,
    prior_family: &str,
    prior_decay: f64,
    force: bool,
    out: Option<PathBuf>,
    save_warmup: bool,
    posterior_predictive: bool,
    show_progress: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let calibration = Calibration {
        bm,
        k,
        prior_family: prior_family.into(),
        prior_decay,
        force,
    };
    let mut settings = run_settings(
        sampler,
        chains,
        warmup,
        draws,
        keep,
        seed,
        threads,
        metric_adaptation,
    )
    .map_err(py_error)?;
    settings.save_warmup = save_warmup;
    let transitions = Arc::new(AtomicUsize::new(0));
    settings.transitions = Some(transitions.clone());
    let progress = show_progress.then(|| Progress {
        label: format!("fit {}", settings.sampler.name()),
        done: transitions,
        total: settings.chains * (settings.chain.warmup + settings.chain.draws),
    });
    let (fitted, replicated) = interruptible_with(py, progress.as_ref(), |stop| {
        settings.stop = Some(stop);
        let fitted = fit_work(&recordings, &model, &calibration, &settings, out.as_ref())?;
        // Replicated recordings from the kept draws, while the GIL is still released.
        let replicated = if posterior_predictive {
            let mut posterior = fitted.posterior.inner.clone();
            Some(replicated_recordings(
                &mut posterior,
                &fitted.run.chains,
                seed,
            )?)
        } else {
            None
        };
        Ok::<_, Error>((fitted, replicated))
    })?
    .map_err(py_error)?;
    let dict = report(py, &fitted)?;
    if let Some(replicated) = replicated {
        let posterior = &fitted.posterior.inner;
        let predictive = PyDict::new(py);
        let several = posterior.n_records() > 1;
        for (r, per_record) in replicated.iter().enumerate() {
            let suffix = if several {
                format!("_r{}", r + 1)
            } else {
                String::new()
            };
            for (name, per_channel) in posterior.channel_names(r).into_iter().zip(per_record) {
                let shape = (per_channel.len(), per_channel.first().map_or(0, Vec::len));
                let n = posterior.observed(r, 0).len();
                let cube = cube(py, shape, n, |c, s| per_channel[c][s].clone())?;
                predictive.set_item(format!("{name}{suffix}"), cube)?;
            }
        }
        dict.set_item("posterior_predictive", predictive)?;
    }
    Ok(dict)
}

fn report<'py>(py: Python<'py>, f: &Fitted) -> PyResult<Bound<'py, PyDict>> {
    let run = &f.run;
    let posterior = &f.posterior.inner;
    let dict = PyDict::new(py);
    let names = posterior.output_names();
    let coordinates = posterior.parameter_names();
    let chains = run.chains.len();
    let kept = (chains, run.chains.first().map_or(0, |c| c.draws.len()));
    let warmup = (
        chains,
        run.chains.first().map_or(0, |c| c.warmup_draws.len()),
    );
    dict.set_item("names", &names)?;
    dict.set_item(
        "draws",
        cube(py, kept, names.len(), |c, s| run.chains[c].draws[s].clone())?,
    )?;
    dict.set_item("unconstrained_names", &coordinates)?;
    dict.set_item(
        "unconstrained",
        cube(py, kept, coordinates.len(), |c, s| {
            run.chains[c].unconstrained[s].clone()
        })?,
    )?;
    dict.set_item(
        "sample_stats",
        stats(py, kept, |c, s| &run.chains[c].records[s])?,
    )?;
    if warmup.1 > 0 {
        dict.set_item(
            "warmup_draws",
            cube(py, warmup, names.len(), |c, s| {
                run.chains[c].warmup_draws[s].clone()
            })?,
        )?;
        dict.set_item(
            "warmup_sample_stats",
            stats(py, warmup, |c, s| &run.chains[c].warmup_records[s])?,
        )?;
    }
    let observed = PyDict::new(py);
    let several = posterior.n_records() > 1;
    for r in 0..posterior.n_records() {
        let suffix = if several {
            format!("_r{}", r + 1)
        } else {
            String::new()
        };
        for (c, name) in posterior.channel_names(r).into_iter().enumerate() {
            let values = posterior.observed(r, c);
            observed.set_item(format!("{name}{suffix}"), PyArray1::from_slice(py, values))?;
        }
    }
    dict.set_item("observed_data", observed)?;
    let map = PyDict::new(py);
    for ((name, x), sd) in coordinates.iter().zip(&f.map.x).zip(f.map.laplace_sd()) {
        map.set_item(name, (*x, sd))?;
    }
    dict.set_item("map", map)?;
    dict.set_item("map_log_density", f.map.log_density)?;
    dict.set_item("map_log_likelihood", f.map_log_likelihood)?;
    dict.set_item("log_evidence_laplace", f.map.log_evidence_laplace)?;
    dict.set_item("posterior_mean_log_likelihood", f.mean_log_likelihood)?;
    dict.set_item("model", f.posterior.settings.label())?;
    dict.set_item("sampler", &run.sampler)?;
    let uses_gradient = run.chains.first().is_some_and(|c| c.uses_gradient);
    dict.set_item("cost", to_python(py, &RunCost::of(run, uses_gradient))?)?;
    dict.set_item("summaries", to_python(py, &run.summaries)?)?;
    dict.set_item("max_rhat", run.max_rhat)?;
    dict.set_item("min_ess_bulk", run.min_ess_bulk)?;
    dict.set_item("divergences", run.divergences)?;
    dict.set_item("wall_seconds", run.wall_seconds)?;
    dict.set_item("outputs", &f.outputs)?;
    Ok(dict)
}

/// CmdStan's seven sampler columns of `shape` draws, `(chains, draws)` arrays by column name.
fn stats<'py, 'a>(
    py: Python<'py>,
    shape: (usize, usize),
    record: impl Fn(usize, usize) -> &'a DrawRecord,
) -> PyResult<Bound<'py, PyDict>> {
    type Stat = fn(&DrawRecord) -> f64;
    let columns: [(&str, Stat); 7] = [
        ("lp__", |r| r.lp),
        ("accept_stat__", |r| r.accept_stat),
        ("stepsize__", |r| r.step_size),
        ("treedepth__", |r| r.tree_depth as f64),
        ("n_leapfrog__", |r| r.n_steps as f64),
        ("divergent__", |r| r.divergent as u8 as f64),
        ("energy__", |r| r.energy),
    ];
    let stats = PyDict::new(py);
    for (name, value) in columns {
        let array = cube(py, shape, 1, |c, s| vec![value(record(c, s))])?;
        stats.set_item(name, array.call_method1("squeeze", (2,))?)?;
    }
    Ok(stats)
}
