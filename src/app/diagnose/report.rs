//! The diagnosis as a report: ties and notes, the sampled fits before and after, where the
//! discrepancy still shows, the JSON contract, the human summary, and the files in `--out`.

use std::collections::BTreeMap;
use std::fmt::Write;
use std::time::Instant;

use serde::Serialize;

use crate::app::AppError;
use crate::app::predictive::{plot_discrepancy, plot_predictive, posterior_predictive};
use crate::app::problem::Problem;
use crate::bayes::ModelSettings;
use crate::io::write_model_file;
use crate::motor::Term;

use super::candidates::{CandidateFit, answer_params};
use super::coincide::InputCoincidence;
use super::fits::{self, Convergence, FitSummary, Mismatch, SampledFit};
use super::screen::collinear_pairs;
use super::state::{StateFingerprint, fingerprint, reading};
use super::ties::{separating_input, truth_problem};
use super::{DiagnoseOptions, EVIDENCE_THRESHOLD, Selection};

#[derive(Clone, Debug, Serialize)]
pub struct RankEntry {
    pub effect: String,
    /// log L̂ − ½·d·ln N, relative to the model without terms (`none` scores 0).
    pub score: f64,
    pub log_likelihood: f64,
    /// Laplace evidence with the term's default prior, relative to `none` (reported only).
    pub log_evidence_laplace: f64,
    /// The candidate's parameters in its fitted model (MAP), keyed as the dev set's answers.
    pub params: BTreeMap<String, Option<f64>>,
    /// Parameters the data do not hold away from their bound.
    pub at_bound: Vec<String>,
    /// The importance-sampling check of the Laplace evidence, for a doubtful leader.
    pub confirmation: Option<super::confirm::Confirmation>,
    /// The input step its switching time coincides with: confounded with the input, not
    /// selected.
    pub coincides_with_input_step: Option<InputCoincidence>,
}

/// A fit the selection passed over because its switching time coincides with an input step.
#[derive(Clone, Debug, Serialize)]
pub struct PassedOver {
    /// The terms of that fit, in the order they were added.
    pub terms: Vec<String>,
    /// Its score against the model as given.
    pub score: f64,
    pub coincidence: InputCoincidence,
}

#[derive(Clone, Debug, Serialize)]
pub struct Diagnosis {
    pub selected: String,
    pub selected_set: Vec<String>,
    /// The selected model's MAP (calibrated parameters, physical values): what `--rank-only`
    /// reports of the selected set's fit.
    pub selected_params: BTreeMap<String, f64>,
    pub ranking: Vec<RankEntry>,
    pub ties: Vec<String>,
    /// Pairs of candidates that both beat the model as given but that these records cannot
    /// tell apart (Coulomb friction and a load torque on records that never reverse), with
    /// the experiment in `tie_experiments` under `a/b`.
    pub tied_pairs: Vec<[String; 2]>,
    /// Fits that would have been selected but switch at a step of a recorded input.
    pub passed_over: Vec<PassedOver>,
    /// For each tie, the input that would separate it from `selected`.
    pub tie_experiments: BTreeMap<String, String>,
    pub mismatch: Vec<Mismatch>,
    /// Drive bases: the missing torque against speed, before and after the selected terms.
    pub state: Vec<StateFingerprint>,
    pub fit_before: Option<FitSummary>,
    pub fit_after: Option<FitSummary>,
    pub notes: Vec<String>,
    pub residual_mismatch: bool,
    pub convergence: BTreeMap<String, Convergence>,
    pub threshold: f64,
    /// The unit of every parameter of the selected model, as its base reads it (N on a linear
    /// axis where the motor has N·m).
    pub units: BTreeMap<String, String>,
    pub discrepancy_degree: usize,
    pub seed: u64,
    /// Wall seconds from the start to the end of the one-at-a-time ranking, and to the end of
    /// the forward selection; `runtime_s` is the whole command.
    pub ranking_s: f64,
    pub selection_s: f64,
    pub runtime_s: f64,
    pub outputs: Vec<String>,
}

fn entry(fit: &CandidateFit, none: &CandidateFit) -> RankEntry {
    RankEntry {
        effect: fit.added.first().cloned().unwrap_or_else(|| "none".into()),
        score: fit.score - none.score,
        log_likelihood: fit.log_likelihood,
        log_evidence_laplace: fit.log_evidence_laplace - none.log_evidence_laplace,
        params: answer_params(fit),
        at_bound: fit.at_bound.clone(),
        confirmation: fit.confirmation,
        coincides_with_input_step: fit.coincidence.clone(),
    }
}

/// Why a switching time at an input step is not selected, in words.
fn passed_over_note(p: &PassedOver) -> String {
    let c = &p.coincidence;
    let step = &c.input_step;
    let (which, why) = if step.record_start {
        (
            "the record's start, where it applies the recorded input",
            "a step at the start is a constant load (load_torque, and on a record that never \
             reverses the same torque as Coulomb friction)",
        )
    } else {
        (
            "the step of the recorded input",
            "a change when the input changes cannot be told from the input acting differently \
             than modelled (a gain on the increment, a friction map not affine in speed, the \
             drive's response)",
        )
    };
    format!(
        "{} (score {:+.2}) switches at {} = {:.4} s, {:.4} s from {which} {} at {:.4} s (by \
         {:+.4}), within the time resolution {:.4} s (2 sd of the switching time, {:.4} s with \
         the residuals' autocorrelation of {:.0} samples, and of the step's time, + one \
         sample): {why}, so it is not selected",
        p.terms.join(" + "),
        p.score,
        c.parameter,
        c.switching_time,
        (c.switching_time - step.time).abs(),
        step.input,
        step.time,
        step.size,
        c.resolution,
        c.switching_time_sd,
        c.residual_autocorrelation
    )
}

/// The noise σ of each channel at the MAP of the selected model (the noise the simulated
/// experiments are given).
fn noise_at_map(problem: &Problem, fit: &CandidateFit) -> Result<Vec<f64>, AppError> {
    let p = super::problem_with(problem, &fit.added)?;
    let posterior = p.posterior(&ModelSettings::bm1())?;
    Ok((0..posterior.forward(0).channels().len())
        .map(|c| fit.x[posterior.log_sigma_index(0, c)].exp())
        .collect())
}

#[allow(clippy::too_many_arguments)]
pub fn assemble(
    problem: &Problem,
    options: &DiagnoseOptions,
    k: usize,
    candidates: &[String],
    ranking: Vec<CandidateFit>,
    selection: Selection,
    started: Instant,
    [ranking_s, selection_s]: [f64; 2],
) -> Result<Diagnosis, AppError> {
    let none = ranking
        .iter()
        .find(|f| f.added.is_empty())
        .expect("none is ranked")
        .clone();
    let Selection {
        terms: selected_set,
        fit: selected_fit,
        passed_over,
    } = selection;
    let passed_over: Vec<PassedOver> = passed_over
        .iter()
        .filter_map(|f| {
            Some(PassedOver {
                terms: f.added.clone(),
                score: f.score - none.score,
                coincidence: f.coincidence.clone()?,
            })
        })
        .collect();
    let selected = selected_set
        .first()
        .cloned()
        .unwrap_or_else(|| "none".into());
    let mut notes = Vec::new();
    let mut ties = Vec::new();
    let mut tie_experiments = BTreeMap::new();
    if let Some(first) = ranking.iter().find(|f| f.added.first() == Some(&selected)) {
        let noise = noise_at_map(problem, first)?;
        for other in &ranking {
            let Some(name) = other.added.first() else {
                continue;
            };
            // A fit confounded with an input step is no rival: it is never selected.
            if name == &selected
                || other.coincidence.is_some()
                || first.score - other.score > EVIDENCE_THRESHOLD
            {
                continue;
            }
            match separating_input(
                problem,
                first,
                name,
                &noise,
                EVIDENCE_THRESHOLD,
                options.run.seed,
            )? {
                Some(input) => {
                    ties.push(name.clone());
                    tie_experiments.insert(name.clone(), format!("{input:?}").to_lowercase());
                }
                None => notes.push(format!(
                    "{selected} and {name} fit this recording equally well and no reversal or \
                     step input would separate them either"
                )),
            }
        }
        for name in &first.at_bound {
            notes.push(format!(
                "{name} is not held away from its bound by the data: its score is a \
                 Laplace approximation at the edge of the support"
            ));
        }
    }
    notes.extend(passed_over.iter().map(passed_over_note));
    let resistance = none.theta.get("R").copied().unwrap_or(f64::NAN);
    let none_noise = noise_at_map(problem, &none)?;
    for (a, b, cos) in collinear_pairs(problem, candidates, resistance, &none_noise)? {
        notes.push(format!(
            "sensitivities of {a} and {b} are collinear on this recording (cos {cos:.4}): \
             near the nominal model the data barely tell them apart"
        ));
    }
    if selected_set.iter().any(|t| t == "torque_constant") {
        notes.push(
            "c_g and J are not separable from I and ω: only c_g/J enters the speed equation \
             given the current, so this torque-constant error can equally be an inertia error"
                .into(),
        );
    }

    let mut state = Vec::new();
    let mut curves = Vec::new();
    for (fit, label) in [(&none, "before"), (&selected_fit, "after")] {
        if label == "after" && selected_set.is_empty() {
            continue;
        }
        if let Some((f, curve)) = fingerprint(problem, fit, label)? {
            notes.push(reading(&f));
            state.push(f);
            curves.push(curve);
        }
    }
    let mut tied_pairs = Vec::new();
    if state.first().is_some_and(|f| !f.reverses) {
        let beats = |name: &str| {
            ranking.iter().any(|f| {
                f.added.first().is_some_and(|a| a == name)
                    && f.score - none.score > EVIDENCE_THRESHOLD
            })
        };
        let pair = ["coulomb_friction", "load_torque"];
        if pair.iter().all(|n| beats(n)) {
            tied_pairs.push(pair.map(String::from));
            tie_experiments.insert(pair.join("/"), "reversal".into());
        }
    }
    let mut diagnosis = Diagnosis {
        selected,
        selected_set: selected_set.clone(),
        selected_params: selected_fit.theta.clone(),
        ranking: ranking.iter().map(|f| entry(f, &none)).collect(),
        ties,
        tied_pairs,
        passed_over,
        tie_experiments,
        mismatch: Vec::new(),
        state,
        fit_before: None,
        fit_after: None,
        notes,
        residual_mismatch: false,
        convergence: BTreeMap::new(),
        threshold: EVIDENCE_THRESHOLD,
        units: parameter_units(problem, &selected_set)?,
        discrepancy_degree: k,
        seed: options.run.seed,
        ranking_s,
        selection_s,
        runtime_s: 0.0,
        outputs: Vec::new(),
    };
    if !options.rank_only {
        sampled_fits(problem, options, k, &selected_fit, &mut diagnosis)?;
    }
    if let (Some(out), false) = (&options.out, curves.is_empty()) {
        std::fs::create_dir_all(out)?;
        let path = out.join("missing-torque.png");
        let plot = crate::plot::MissingTorquePlot {
            title: "the torque the model misses, against speed".into(),
            speed_unit: problem.model.base.unit("rad/s").into(),
            torque_unit: problem.model.base.unit("N·m").into(),
            curves,
        };
        crate::plot::missing_torque(&path, &plot).map_err(|e| AppError::Output(e.to_string()))?;
        diagnosis.outputs.push(path.display().to_string());
    }
    diagnosis.runtime_s = started.elapsed().as_secs_f64();
    if let Some(path) = &options.json {
        diagnosis.outputs.push(path.display().to_string());
        let text = serde_json::to_string_pretty(&diagnosis)
            .map_err(|e| AppError::Output(e.to_string()))?;
        crate::io::write_atomically(path, text.as_bytes())?;
    }
    Ok(diagnosis)
}

/// BM1 before and after (noise, RMSE, whiteness, parameters), BM2 before and after (where δ
/// excludes zero), and the files in `--out`.
fn sampled_fits(
    problem: &Problem,
    options: &DiagnoseOptions,
    k: usize,
    selected: &CandidateFit,
    diagnosis: &mut Diagnosis,
) -> Result<(), AppError> {
    let before_problem = super::problem_with(problem, &[])?;
    let after_problem = truth_problem(problem, selected)?;
    // δ after: the selected terms held at their estimates, the user's own parameters sampled.
    // Sampling the terms too would let δ and a term trade the same shape (a funnel that costs
    // NUTS divergences and most of the run) and asks nothing the BM1 fit has not answered.
    let mut held_problem = after_problem.clone();
    held_problem.model.calibrate = before_problem.model.calibrate.clone();
    let mut run = options.run.clone();
    let stages = [
        ("before", &before_problem, ModelSettings::bm1()),
        ("after", &after_problem, ModelSettings::bm1()),
        ("before_bm2", &before_problem, ModelSettings::bm2(k)),
        ("after_bm2", &held_problem, ModelSettings::bm2(k)),
    ];
    let mut sampled: Vec<(String, SampledFit)> = Vec::new();
    for (i, (name, p, settings)) in stages.into_iter().enumerate() {
        run.seed = options.run.seed.wrapping_add(i as u64);
        if name.starts_with("after") && diagnosis.selected_set.is_empty() {
            continue;
        }
        // A Legendre polynomial of degree K over 20 s of back-and-forth motion is a slow trend,
        // not a locator: long records are located against the state instead.
        if name.ends_with("bm2") && fits::uses_laplace(problem) {
            continue;
        }
        let fit = fits::sample(p, &settings, &run, &format!("{name}: {}", settings.label()))?;
        diagnosis
            .convergence
            .insert(name.to_string(), Convergence::of(&fit.run));
        sampled.push((name.to_string(), fit));
    }
    for (name, fit) in sampled.iter_mut() {
        match name.as_str() {
            "before" => diagnosis.fit_before = Some(fits::summarize_fit(problem, fit)?),
            "after" => diagnosis.fit_after = Some(fits::summarize_fit(problem, fit)?),
            "before_bm2" => {
                let (mismatch, _) = fits::mismatches(problem, fit)?;
                if diagnosis.selected_set.is_empty() {
                    diagnosis.residual_mismatch =
                        mismatch.iter().any(|m| fits::substantial(m, problem));
                }
                diagnosis.mismatch = mismatch;
            }
            "after_bm2" => {
                let (left, _) = fits::mismatches(problem, fit)?;
                let substantial: Vec<&Mismatch> = left
                    .iter()
                    .filter(|m| fits::substantial(m, problem))
                    .collect();
                diagnosis.residual_mismatch = !substantial.is_empty();
                for m in substantial {
                    diagnosis.notes.push(format!(
                        "after the selected terms δ still excludes zero on {} from {:.4} s to \
                         {:.4} s (up to {:.2} σ): something the candidate library does not hold",
                        m.channel, m.t_start, m.t_end, m.max_over_sigma
                    ));
                }
            }
            _ => {}
        }
    }
    if diagnosis.fit_after.is_none() {
        diagnosis.fit_after = diagnosis.fit_before.clone();
    }
    if fits::uses_laplace(problem) {
        diagnosis.notes.push(format!(
            "{} samples: the fits before and after are Laplace approximations at the MAP \
             ({} draws from the Gaussian), not NUTS runs, and the BM2 band in time is skipped",
            problem
                .recordings
                .iter()
                .map(|r| r.n_samples())
                .sum::<usize>(),
            fits::LAPLACE_DRAWS
        ));
    }
    if let Some(out) = &options.out {
        std::fs::create_dir_all(out)?;
        for (name, fit) in sampled.iter_mut() {
            for r in 0..fit.posterior.n_records() {
                let p = posterior_predictive(&mut fit.posterior, &fit.run.chains, r)?;
                let suffix = if problem.recordings.len() > 1 {
                    format!("-{}", r + 1)
                } else {
                    String::new()
                };
                let path = if name.ends_with("bm2") {
                    let path = out.join(format!("discrepancy-{name}{suffix}.png"));
                    let when = name.trim_end_matches("_bm2");
                    plot_discrepancy(&path, &format!("δ {when} (BM2, K = {k})"), &p, None)?;
                    path
                } else {
                    let path = out.join(format!("fit-{name}{suffix}.png"));
                    let title = if name == "before" {
                        "the model as given (BM1)".to_string()
                    } else {
                        format!("with {} (BM1)", diagnosis.selected_set.join(" + "))
                    };
                    plot_predictive(&path, &title, &p)?;
                    path
                };
                diagnosis.outputs.push(path.display().to_string());
            }
        }
        // The posterior means as the model file's values.
        let mut model = after_problem.model.clone();
        for (name, &value) in diagnosis.fit_after.iter().flat_map(|f| &f.params_mean) {
            model.set_value(name, value);
        }
        let path = out.join("model.toml");
        write_model_file(&path, &model)?;
        diagnosis.outputs.push(path.display().to_string());
        let fits_json = serde_json::json!({
            "before": diagnosis.fit_before,
            "after": diagnosis.fit_after,
            "convergence": diagnosis.convergence,
        });
        let path = out.join("fit.json");
        crate::io::write_atomically(
            &path,
            serde_json::to_string_pretty(&fits_json)
                .map_err(|e| AppError::Output(e.to_string()))?
                .as_bytes(),
        )?;
        diagnosis.outputs.push(path.display().to_string());
    }
    Ok(())
}

fn unit_of(name: &str) -> &'static str {
    let Some((term, key)) = name.split_once('.') else {
        return if name == "R" { "Ω" } else { "" };
    };
    Term::named(term)
        .and_then(|t| t.params().iter().find(|p| p.key == key).map(|p| p.unit))
        .unwrap_or("")
}

fn parameter_units(
    problem: &Problem,
    selected: &[String],
) -> Result<BTreeMap<String, String>, AppError> {
    let p = super::problem_with(problem, selected)?;
    let model = p.model_for(p.recording())?;
    Ok(model
        .parameter_specs(&model.magnitudes(1.0))
        .into_iter()
        .map(|spec| (spec.name, spec.unit.to_string()))
        .collect())
}

/// Four significant figures, in fixed notation where that reads well.
fn sig(v: f64) -> String {
    if v == 0.0 || (1e-3..1e4).contains(&v.abs()) {
        format!("{v:.4}")
    } else {
        format!("{v:.3e}")
    }
}

/// The human summary.
pub fn format_diagnosis(d: &Diagnosis) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "ranking (score: log L − ½·d·ln N against none, nats):");
    for e in &d.ranking {
        let _ = write!(
            s,
            "  {:<20} {:>+10.2}   Laplace (default priors) {:>+10.2}",
            e.effect, e.score, e.log_evidence_laplace
        );
        match &e.coincides_with_input_step {
            Some(c) => {
                let _ = writeln!(
                    s,
                    "   at the {} step at {:.4} s: not selected",
                    c.input_step.input, c.input_step.time
                );
            }
            None => s.push('\n'),
        }
    }
    if d.selected_set.is_empty() {
        let _ = writeln!(
            s,
            "no candidate beats the model as it is by more than {} nats: nothing missing found",
            d.threshold
        );
    } else {
        let _ = writeln!(s, "the model lacks {}", d.selected_set.join(" + "));
        if d.fit_after.is_none() {
            let _ = writeln!(s, "its MAP:");
            for (name, value) in &d.selected_params {
                let unit = d
                    .units
                    .get(name)
                    .map_or_else(|| unit_of(name), String::as_str);
                let _ = writeln!(s, "  {name} = {value:.5e} {unit}");
            }
        }
        if let Some(after) = &d.fit_after {
            for (name, mean) in &after.params_mean {
                let ci = after.params_95.get(name).copied().unwrap_or([f64::NAN; 2]);
                let _ = writeln!(
                    s,
                    "  {name} = {mean:.5e} {} [95%: {:.5e}, {:.5e}]",
                    d.units
                        .get(name)
                        .map_or_else(|| unit_of(name), String::as_str),
                    ci[0],
                    ci[1]
                );
            }
        }
    }
    if let (Some(b), Some(a)) = (&d.fit_before, &d.fit_after) {
        let _ = writeln!(
            s,
            "log likelihood {:.1} → {:.1} ({:+.1} nats)",
            b.log_likelihood,
            a.log_likelihood,
            a.log_likelihood - b.log_likelihood
        );
        for (ch, sb) in &b.sigma {
            let sa = a.sigma.get(ch).copied().unwrap_or(f64::NAN);
            let wb = &b.whiteness[ch];
            let wa = &a.whiteness[ch];
            let _ = writeln!(
                s,
                "σ_{ch} {} → {}; Ljung–Box p {:.2e} → {:.2e}",
                sig(*sb),
                sig(sa),
                wb.p_value,
                wa.p_value
            );
        }
    }
    for [a, b] in &d.tied_pairs {
        let _ = writeln!(
            s,
            "{a} and {b} cannot be told apart on these records: add a {} record",
            d.tie_experiments
                .get(&format!("{a}/{b}"))
                .map(String::as_str)
                .unwrap_or("different")
        );
    }
    for t in &d.ties {
        let _ = writeln!(
            s,
            "cannot be told apart from {t} on this recording: add a {} input",
            d.tie_experiments
                .get(t)
                .map(String::as_str)
                .unwrap_or("different")
        );
    }
    for m in &d.mismatch {
        let _ = writeln!(
            s,
            "mismatch before: {} from {:.4} s to {:.4} s (|δ| up to {:.2} σ)",
            m.channel, m.t_start, m.t_end, m.max_over_sigma
        );
    }
    for n in &d.notes {
        let _ = writeln!(s, "note: {n}");
    }
    let _ = writeln!(
        s,
        "runtime {:.1} s (ranking {:.1} s, selection {:.1} s)",
        d.runtime_s, d.ranking_s, d.selection_s
    );
    s
}
