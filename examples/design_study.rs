//! The measurements of papers/design.md: designed inputs against the fixed experiments, and
//! whether what they promise holds on simulated records.
//!
//! Separation, on a case folder (`motor.toml`, `diag.json` from `diagnose --rank-only --json`):
//! the 0.5-s, 8-segment design for two tied candidates, then `--records` noisy records from
//! each candidate as the truth (at the diagnosis's estimate) on the designed input, both
//! candidates refitted by `diagnose`'s scoring (`fit_candidate`), and how often the truth
//! scores higher, and higher by more than the 2-nat threshold.
//!
//! With `--diagnose N`, the first N records of each truth also go through the whole ranking
//! (`discover` with `rank_only`, every library candidate) and the selected term is counted.
//!
//! The design is checked against the rest of the library (`design::separate_checked`): rivals
//! that coincide with a candidate on the designed input join the candidates and the input is
//! designed again (at most `RIVAL_ROUNDS` times); the records are then made from every final
//! candidate as the truth. `--no-rival-check` designs for the named candidates only.
//!
//!   cargo run --release --example design_study -- separate DIR a,b [--records 20] [--diagnose N]
//!       [--no-rival-check]
//!
//! Pinning, on the paper's model (c_g = 0.009, σ = 2 A and 10 rad/s): the design for R and
//! c_g/J, then `--records` noisy records of the model on the designed and on the constant 24-V
//! input, each fitted by weighted least squares (R, c_g, J free), and the sds of the estimates
//! of R and c_g/J against the predicted ones.
//!
//!   cargo run --release --example design_study -- pin [--records 30]
//!
//! With `pin --posterior SAMPLER` instead, one noisy record of each input goes through the
//! library's Bayesian fit (`Problem::posterior` with BM1, `pipeline::run_sampler`, the path
//! `motorcal fit` takes), and the posterior sds of R and c_g/J (over the pooled draws) are
//! set against the predicted ones.
//!
//!   cargo run --release --example design_study -- pin --posterior nuts-dense

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::Instant;

use motorcal::bayes::ModelSettings;
use motorcal::design::{
    self, Candidate, DesignSettings, Experiment, Limits, RIVAL_ROUNDS, SearchSettings, Target,
    design_problem, design_times,
};
use motorcal::discover::{DiscoverSettings, EVIDENCE_THRESHOLD, discover, fit_candidate};
use motorcal::io::{ModelFile, read_model_file};
use motorcal::motor::{MotorParameters, VoltageInput};
use motorcal::pipeline::{
    MetricAdaptation, RunOutput, RunSettings, SamplerKind, default_warmup, run_sampler,
};
use motorcal::sampler::ChainSettings;
use motorcal::study::Problem;
use motorcal::synthetic::generate;

const LIMITS: &str = "U=±24,I=±300,omega=±3000";

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let option = |name: &str| {
        args.iter()
            .position(|a| a == name)
            .and_then(|i| args.get(i + 1))
            .map(|s| s.parse::<usize>())
            .transpose()
    };
    let records = option("--records")?;
    let diagnosed = option("--diagnose")?.unwrap_or(0);
    let sampler = args
        .iter()
        .position(|a| a == "--posterior")
        .and_then(|i| args.get(i + 1))
        .map(|s| s.parse::<SamplerKind>())
        .transpose()?;
    match args.first().map(String::as_str) {
        Some("separate") if args.len() >= 3 => separate(
            PathBuf::from(&args[1]),
            &args[2],
            records.unwrap_or(20),
            diagnosed,
            !args.iter().any(|a| a == "--no-rival-check"),
        ),
        Some("pin") => pin(records.unwrap_or(30), sampler),
        _ => Err(
            "usage: design_study separate DIR a,b [--records N] [--diagnose N] \
                  [--no-rival-check] | pin [--records N] [--posterior SAMPLER]"
                .into(),
        ),
    }
}

fn settings() -> Result<DesignSettings, Box<dyn std::error::Error>> {
    Ok(DesignSettings {
        search: SearchSettings::default(),
        limits: LIMITS.parse::<Limits>()?,
        draws: design::DEFAULT_DRAWS,
    })
}

/// A candidate's estimate from a `diagnose --json` ranking, keyed as the model's parameters.
fn values(diag: &serde_json::Value, name: &str) -> BTreeMap<String, f64> {
    let entry = diag["ranking"]
        .as_array()
        .into_iter()
        .flatten()
        .find(|e| e["effect"] == name)
        .cloned()
        .unwrap_or_default();
    let mut out = BTreeMap::new();
    for (k, v) in entry["params"].as_object().into_iter().flatten() {
        if let (Some(v), false) = (v.as_f64(), k == "I_sat") {
            let key = if k == "R" {
                k.clone()
            } else {
                format!("{name}.{k}")
            };
            out.insert(key, v);
        }
    }
    out
}

/// `truth > rival (gap)` for each unseparated rival, or `none`.
fn rivals(rivals: &[design::Rival]) -> String {
    if rivals.is_empty() {
        return "none".into();
    }
    rivals
        .iter()
        .map(|r| format!("{} > {} ({:.2})", r.truth, r.rival, r.expected_gap_nats))
        .collect::<Vec<_>>()
        .join(", ")
}

fn separate(
    dir: PathBuf,
    pair: &str,
    records: usize,
    diagnosed: usize,
    rival_check: bool,
) -> Result<(), Box<dyn std::error::Error>> {
    let model = read_model_file(&dir.join("motor.toml"))?;
    let diag: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("diag.json"))?)?;
    let times = design_times(0.5, 1000.0)?;
    let base = design_problem(&model, &times, &LIMITS.parse::<Limits>()?)?;
    let names: Vec<&str> = pair.split(',').collect();
    let candidates = names
        .iter()
        .map(|n| Candidate::new(&base, n, &values(&diag, n)))
        .collect::<Result<Vec<_>, _>>()?;
    let experiment = Experiment {
        candidates,
        times: times.clone(),
        noise_sd: vec![2.0, 10.0],
    };
    let started = Instant::now();
    let (d, experiment) = if rival_check {
        let checked = design::separate_checked(&base, &experiment, &settings()?, RIVAL_ROUNDS)?;
        for (i, round) in checked.rounds.iter().enumerate() {
            println!(
                "  round {}: candidates {:?}, expected gap {:.2} ± {:.2} nats; rivals within {} \
                 nats: {}",
                i + 1,
                round.candidates,
                round.expected_gap_nats,
                round.spread_nats,
                EVIDENCE_THRESHOLD,
                rivals(&round.unseparated_rivals)
            );
            if let Some(note) = &round.note {
                println!("    {note}");
            }
            if !round.not_fitted.is_empty() {
                println!("    not fitted: {:?}", round.not_fitted);
            }
        }
        (checked.design, checked.experiment)
    } else {
        (design::separate(&experiment, &settings()?)?, experiment)
    };
    println!(
        "{pair}: designed expected gap {:.2} ± {:.2} nats (worst truth), {:.1} s",
        d.expected_gap_nats,
        d.spread_nats,
        started.elapsed().as_secs_f64()
    );
    for g in &d.gaps {
        println!(
            "  {} as truth over {}: {:.2} ± {:.2}, σ estimated (at the σ given {:.2}; noise-free \
             {:.2})",
            g.truth,
            g.rival,
            g.expected_gap_nats,
            g.sd_nats,
            g.known_sigma_gap_nats,
            g.noise_free_gap_nats
        );
    }
    for f in &d.fixed_experiments {
        println!(
            "  fixed {}: {:.2} ± {:.2} nats, within limits {}",
            f.check.input, f.expected_gap_nats, f.spread_nats, f.check.within_limits
        );
    }
    let input = design::held(&times, d.values.clone());
    for (t, truth) in experiment.candidates.iter().enumerate() {
        let motor = truth.problem.model.model(input.clone())?;
        let (mut named, mut clear) = (0, 0);
        let (mut selected, mut leads) = (Vec::new(), Vec::new());
        for k in 0..records {
            let data = generate(&motor, &times, &[2.0, 10.0], 7000 + k as u64)?;
            let recording =
                motorcal::study::recording_from(&data, "designed", Some(d.values.clone()));
            let problem = Problem {
                label: "designed".into(),
                recordings: vec![recording],
                model: model.clone(),
                reference: None,
            };
            let scores = experiment
                .candidates
                .iter()
                .map(|c| fit_candidate(&problem, &c.added).map(|f| f.score))
                .collect::<Result<Vec<_>, _>>()?;
            let lead = scores
                .iter()
                .enumerate()
                .filter(|(i, _)| *i != t)
                .map(|(_, s)| scores[t] - s)
                .fold(f64::INFINITY, f64::min);
            if k < diagnosed {
                let mut settings = DiscoverSettings {
                    rank_only: true,
                    ..DiscoverSettings::default()
                };
                settings.run.quiet = true;
                selected.push(discover(&problem, &settings)?.selected);
            }
            leads.push(lead);
            named += usize::from(lead > 0.0);
            clear += usize::from(lead > EVIDENCE_THRESHOLD);
        }
        println!(
            "  {} as truth, {records} records on the designed input: scores highest in {named}, \
             by more than {EVIDENCE_THRESHOLD} nats in {clear}; its lead over the best other \
             {:.2} ± {:.2} nats",
            truth.name,
            mean(&leads),
            sd(&leads)
        );
        if diagnosed > 0 {
            let hits = selected.iter().filter(|s| **s == truth.name).count();
            println!(
                "  {} as truth, the first {} records through the whole ranking: selected {hits} \
                 times ({selected:?})",
                truth.name,
                selected.len()
            );
        }
    }
    Ok(())
}

fn pin(records: usize, sampler: Option<SamplerKind>) -> Result<(), Box<dyn std::error::Error>> {
    let model = ModelFile {
        motor: MotorParameters::paper_simulation_model(),
        ..ModelFile::default()
    };
    let times = design_times(0.5, 1000.0)?;
    let base = design_problem(&model, &times, &LIMITS.parse::<Limits>()?)?;
    let targets = [Target::parse("R"), Target::parse("c_g/J")];
    let candidate = design::pin_candidate(&base, &BTreeMap::new(), &targets)?;
    let experiment = Experiment {
        candidates: vec![candidate.clone()],
        times: times.clone(),
        noise_sd: vec![2.0, 10.0],
    };
    let started = Instant::now();
    let d = design::pin(&candidate, &experiment, &targets, &settings()?)?;
    println!("pin R, c_g/J: {:.1} s", started.elapsed().as_secs_f64());
    let designed = design::held(&times, d.values.clone());
    let constant = design::held(&times, vec![24.0; times.len()]);
    for (name, input, predicted) in [
        ("designed", &designed, &d.pinned),
        ("constant 24 V", &constant, &d.fixed_experiments[0].1),
    ] {
        if let Some(sampler) = sampler {
            let started = Instant::now();
            let (r, ratio, run) = posterior_sds(&candidate, &experiment, input, sampler)?;
            println!(
                "  {name}: predicted sd R {:.3e}, c_g/J {:.4}; {} posterior of one record \
                 (seed 9000) sd R {r:.3e}, c_g/J {ratio:.4}; posterior over predicted: R {:.3}, \
                 c_g/J {:.3} (max R-hat {:.3}, min bulk ESS {:.0}, k̂ {}, fell back {}, {:.1} s)",
                predicted.sd["R"],
                predicted.sd["c_g/J"],
                sampler.name(),
                r / predicted.sd["R"],
                ratio / predicted.sd["c_g/J"],
                run.max_rhat,
                run.min_ess_bulk,
                run.khat.map_or("—".into(), |k| format!("{k:.2}")),
                run.fell_back,
                started.elapsed().as_secs_f64()
            );
            continue;
        }
        let (r, ratio) = empirical_sds(&candidate, &experiment, input, records)?;
        println!(
            "  {name}: predicted sd R {:.3e}, c_g/J {:.4}; over {records} fitted records R {:.3e}, \
             c_g/J {:.4}",
            predicted.sd["R"], predicted.sd["c_g/J"], r, ratio
        );
    }
    let fixed = &d.fixed_experiments[0].1;
    println!(
        "  the constant 24 V's predicted sd over the designed input's: R {:.2}, c_g/J {:.2}",
        fixed.sd["R"] / d.pinned.sd["R"],
        fixed.sd["c_g/J"] / d.pinned.sd["c_g/J"]
    );
    Ok(())
}

/// The posterior sds of R and c_g/J from the library's Bayesian fit (BM1, the model file's
/// priors, σ estimated) of one noisy record of the candidate under `input`.
fn posterior_sds(
    candidate: &Candidate,
    experiment: &Experiment,
    input: &VoltageInput,
    sampler: SamplerKind,
) -> Result<(f64, f64, RunOutput), Box<dyn std::error::Error>> {
    let motor = candidate.problem.model.model(input.clone())?;
    let data = generate(&motor, &experiment.times, &experiment.noise_sd, 9000)?;
    let VoltageInput::Held { values, .. } = input else {
        return Err("the inputs here are held voltages".into());
    };
    let problem = Problem {
        label: "pin".into(),
        recordings: vec![motorcal::study::recording_from(
            &data,
            "pin",
            Some(values.clone()),
        )],
        model: candidate.problem.model.clone(),
        reference: None,
    };
    let mut posterior = problem.posterior(&ModelSettings::bm1())?;
    let settings = RunSettings {
        sampler,
        chain: ChainSettings {
            warmup: default_warmup(sampler, MetricAdaptation::default()),
            ..ChainSettings::default()
        },
        seed: 9000,
        quiet: true,
        ..RunSettings::default()
    };
    let run = run_sampler(&mut posterior, &settings, "pin")?;
    let mut r = Vec::new();
    let mut ratio = Vec::new();
    for chain in &run.chains {
        let at = |p: &str| chain.names.iter().position(|n| n == p);
        let (Some(ir), Some(ic), Some(ij)) = (at("R"), at("c_g"), at("J")) else {
            return Err(format!("the draws name {:?}, not R, c_g and J", chain.names).into());
        };
        for d in &chain.draws {
            r.push(d[ir]);
            ratio.push(d[ic] / d[ij]);
        }
    }
    Ok((sd(&r), sd(&ratio), run))
}

/// The sds of the least-squares estimates of R and c_g/J over noisy records of the candidate.
fn empirical_sds(
    candidate: &Candidate,
    experiment: &Experiment,
    input: &VoltageInput,
    records: usize,
) -> Result<(f64, f64), Box<dyn std::error::Error>> {
    let forward = candidate.forward(input, &experiment.times)?;
    let specs = forward.calibrated_specs();
    let weights = experiment.weights();
    let motor = candidate.problem.model.model(input.clone())?;
    let index = |p: &str| {
        candidate
            .calibrated
            .iter()
            .position(|c| c == p)
            .unwrap_or(0)
    };
    let (ir, ic, ij) = (index("R"), index("c_g"), index("J"));
    let mut r = Vec::new();
    let mut ratio = Vec::new();
    for k in 0..records {
        let data = generate(
            &motor,
            &experiment.times,
            &experiment.noise_sd,
            9000 + k as u64,
        )?;
        let target: Vec<f64> = data.measured.concat();
        let (_, theta) = motorcal::study::cases::oracle::levenberg_marquardt(
            &forward,
            &specs,
            &target,
            &weights,
            candidate.theta.clone(),
        )?;
        r.push(theta[ir]);
        ratio.push(theta[ic] / theta[ij]);
    }
    Ok((sd(&r), sd(&ratio)))
}

fn sd(v: &[f64]) -> f64 {
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
}

fn mean(x: &[f64]) -> f64 {
    x.iter().sum::<f64>() / x.len().max(1) as f64
}
