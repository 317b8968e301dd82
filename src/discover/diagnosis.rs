//! The diagnosis as data: ties and notes, the sampled fits before and after, where the
//! discrepancy still shows, and the JSON contract (`Diagnosis` serialises to what `diagnose
//! --json` writes). The files and the human summary are the command's.

use std::collections::BTreeMap;
use std::time::Instant;

use serde::Serialize;

use crate::bayes::ModelSettings;
use crate::error::Error;
use crate::io::ModelFile;
use crate::parameter::ParamId;
use crate::plot::MissingTorqueCurve;
use crate::study::Problem;

use super::Progress;
use super::candidate::{Candidate, Confirmation, answer_params};
use super::coincide::InputCoincidence;
use super::discovered::{Discovered, discovered};
use super::fits::{self, Convergence, FitSummary, Mismatch, SampledFit};
use super::named::{Naming, fit_named_terms};
use super::overdamped::reading_in_place;
use super::prune::prune_law;
use super::screen::collinear_pairs;
use super::selection::Selection;
use super::settings::{
    DiscoverSettings, EVIDENCE_THRESHOLD, FitStage, LAPLACE_DRAWS, uses_laplace,
};
use super::state::{StateFingerprint, fingerprint, reading};
use super::ties::separating_input;
use super::unexplained::{AsGiven, Unexplained, beyond_the_library, unexplained};

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
    pub confirmation: Option<Confirmation>,
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
    /// Structure the selected model leaves that no library term holds (`unexplained`).
    pub unexplained: Option<Unexplained>,
    /// The verdict on the model as given, before any term is added: the fingerprint of the
    /// whole mismatch, reported beside what was named so that a reader can see that the two
    /// agree (a coupling named where the residual of the model as given rang, a law where it
    /// followed the state). `null` where the model as given leaves nothing the verdict finds.
    pub unexplained_as_given: Option<Unexplained>,
    /// The law term discovered from a state or drift fingerprint, when one was added.
    pub discovered: Option<Discovered>,
    /// True whenever `unexplained` is not null, or δ's band after the selected terms still
    /// excludes zero on a stretch of the record.
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
    /// What the plausibility check found (only when the caller went on regardless).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub implausible: Vec<crate::study::plausibility::Finding>,
    /// The files the command wrote (the library writes none).
    pub outputs: Vec<String>,
    /// The sampled fits, in the order they ran, for the command's figures.
    #[serde(skip)]
    pub fits: Vec<StageFit>,
    /// Drive bases: the missing torque against speed before and after, binned.
    #[serde(skip)]
    pub missing_torque: Vec<MissingTorqueCurve>,
    /// The model file with the selected terms added and the posterior means as values (after
    /// the sampled fits), calibrated with their default priors.
    #[serde(skip)]
    pub amended_model: Option<ModelFile>,
}

/// One sampled fit of a diagnosis.
#[derive(Clone, Debug)]
pub struct StageFit {
    pub stage: FitStage,
    pub fit: SampledFit,
}

fn entry(fit: &Candidate, none: &Candidate) -> RankEntry {
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

#[allow(clippy::too_many_arguments)]
pub fn assemble(
    problem: &Problem,
    settings: &DiscoverSettings,
    k: usize,
    candidates: &[String],
    ranking: Vec<Candidate>,
    selection: Selection,
    as_given: AsGiven,
    not_ranked: Vec<String>,
    started: Instant,
    [ranking_s, selection_s]: [f64; 2],
    progress: &impl Fn(Progress),
) -> Result<Diagnosis, Error> {
    let none = ranking
        .iter()
        .find(|f| f.added.is_empty())
        .expect("none is ranked")
        .clone();
    let Selection {
        terms: mut selected_set,
        fit: mut selected_fit,
        passed_over,
    } = selection;
    // The verdict after the library's selection; where its fingerprint names a dynamic term
    // that then fits better, the term joins (or replaces) the selection and the verdict is
    // asked again after it.
    let mut left = unexplained(problem, &selected_fit, &none, &as_given)?;
    let left_as_given = if selected_fit.added.is_empty() {
        left.clone()
    } else {
        unexplained(problem, &none, &none, &as_given)?
    };
    let library_best = (ranking.iter())
        .filter(|c| c.added.len() == 1)
        .max_by(|a, b| a.score.total_cmp(&b.score))
        .map(|c| (c.added[0].clone(), c.score - none.score));
    let left_after_library = left.clone();
    let mut ranking = ranking;
    let mut found = None;
    // A recording that cannot be this motor gets no physics named, by the library or the
    // fingerprint.
    let allowed: Option<&[String]> = if settings.implausible.is_empty() {
        settings.candidates.as_deref()
    } else {
        Some(&[])
    };
    // What the verdict names is fitted beside the selected terms and alone (a library term
    // selected for a delay absorbs part of it and is then dead weight beside it); a law the
    // model as given asks for, alone, in place of the terms that stand in for it.
    let mut bases = vec![&selected_fit];
    if !selected_fit.added.is_empty() {
        bases.push(&none);
    }
    let mut naming: Vec<Naming> = Vec::new();
    if let Some(verdict) = &left {
        let fingerprints = std::iter::once(&verdict.fingerprint).chain(&verdict.considered);
        naming.push((fingerprints.collect(), bases));
    }
    // Where nothing was selected the verdict holds these laws already.
    if !selected_fit.added.is_empty() {
        naming.push((as_given.fingerprints().collect(), vec![&none]));
    }
    // One call, so that a law both name is fitted once and all the fits share the cores.
    let mut best = fit_named_terms(problem, naming, &selected_fit, allowed)?;
    // An overdamped coupling's look-alike, the speed's reading of the current, in its place.
    let mut not_ranked = not_ranked;
    if let Some((fit, note)) = reading_in_place(problem, &selected_fit, allowed) {
        not_ranked.push(note);
        if let Some(fit) = fit.filter(|f| best.as_ref().is_none_or(|b| f.score > b.score)) {
            best = Some(fit);
        }
    }
    if let Some(fit) = best {
        let before = selected_fit.score;
        found = discovered(&fit, fit.score - before);
        selected_set = fit.added.clone();
        selected_fit = fit;
        left = unexplained(problem, &selected_fit, &none, &as_given)?;
        // A law taken, the verdict after it may find more in its balance (the other half of a
        // ripple's phase, which the first fit's start did not hold): one more round, which may
        // only extend the law, by the same threshold.
        let extended = match (&found, &left) {
            (Some(_), Some(verdict)) => {
                let fingerprints = std::iter::once(&verdict.fingerprint).chain(&verdict.considered);
                let naming = [(fingerprints.collect(), vec![&selected_fit])];
                fit_named_terms(problem, naming, &selected_fit, allowed)?
                    .filter(|fit| fit.added == selected_fit.added)
            }
            _ => None,
        };
        if let Some(fit) = extended {
            found = discovered(&fit, fit.score - before);
            selected_fit = fit;
            left = unexplained(problem, &selected_fit, &none, &as_given)?;
        }
        // The law's functions were chosen at first order; through the ODE each must pay.
        if let Some(fit) = prune_law(&selected_fit)? {
            found = discovered(&fit, fit.score - before);
            selected_fit = fit;
            left = unexplained(problem, &selected_fit, &none, &as_given)?;
        }
        if selected_fit.added.len() == 1 {
            ranking.push(selected_fit.clone());
            ranking.sort_by(|a, b| b.score.total_cmp(&a.score));
        }
    }
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
    let mut notes: Vec<String> = not_ranked;
    let mut ties = Vec::new();
    let mut tie_experiments = BTreeMap::new();
    // A discovered law has no rival in the library to be tied with: the ties are the
    // library's.
    if let Some(first) = ranking
        .iter()
        .find(|f| f.added.first() == Some(&selected))
        .filter(|_| selected != "law")
    {
        let noise = first.noise_sd();
        for other in &ranking {
            let Some(name) = other.added.first() else {
                continue;
            };
            // A fit confounded with an input step is no rival: it is never selected. Nor is a
            // term the selection holds, or one that alone scores well above the selected term
            // alone: the selection (a pair that beat it, found among the ranking's leaders)
            // has already been preferred to it.
            if selected_set.contains(name)
                || other.coincidence.is_some()
                || (first.score - other.score).abs() > EVIDENCE_THRESHOLD
            {
                continue;
            }
            match separating_input(
                problem,
                first,
                name,
                &noise,
                EVIDENCE_THRESHOLD,
                settings.run.seed,
            )? {
                Some(input) => {
                    ties.push(name.clone());
                    tie_experiments.insert(name.clone(), format!("{input:?}").to_lowercase());
                }
                // Say which experiment was tried: a drive's is its record run the other way,
                // which cannot part two laws that differ only within one record's reversal
                // (viscous and direction-dependent friction).
                None => notes.push(format!(
                    "{selected} and {name} fit this recording equally well and {} would not \
                     separate them either",
                    if problem.model.base.is_drive() {
                        "the record run the other way"
                    } else {
                        "a reversal or a step input"
                    }
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
    let none_noise = none.noise_sd();
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
    let mut missing_torque = Vec::new();
    for (fit, label) in [(&none, "before"), (&selected_fit, "after")] {
        if label == "after" && selected_set.is_empty() {
            continue;
        }
        if let Some((f, curve)) = fingerprint(problem, fit, label)? {
            notes.push(reading(&f));
            state.push(f);
            missing_torque.push(curve);
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
    let law_alone = (selected_fit.added == ["law"]).then_some(selected_fit.score - none.score);
    let left_as_given = beyond_the_library(
        left_as_given,
        left_after_library.as_ref(),
        library_best.as_ref().map(|(t, s)| (t.as_str(), *s)),
        law_alone,
    );
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
        residual_mismatch: left.is_some(),
        unexplained: left,
        unexplained_as_given: left_as_given,
        discovered: found,
        convergence: BTreeMap::new(),
        threshold: EVIDENCE_THRESHOLD,
        units: parameter_units(&selected_fit.problem)?,
        discrepancy_degree: k,
        seed: settings.run.seed,
        ranking_s,
        selection_s,
        runtime_s: 0.0,
        implausible: settings.implausible.clone(),
        outputs: Vec::new(),
        fits: Vec::new(),
        missing_torque,
        amended_model: None,
    };
    if !settings.rank_only {
        sampled_fits(
            problem,
            settings,
            k,
            &none,
            &selected_fit,
            &mut diagnosis,
            progress,
        )?;
    }
    diagnosis.runtime_s = started.elapsed().as_secs_f64();
    Ok(diagnosis)
}

/// BM1 before and after (noise, RMSE, whiteness, parameters), BM2 before and after (where δ
/// excludes zero), and the amended model.
fn sampled_fits(
    problem: &Problem,
    settings: &DiscoverSettings,
    k: usize,
    none: &Candidate,
    selected: &Candidate,
    diagnosis: &mut Diagnosis,
    progress: &impl Fn(Progress),
) -> Result<(), Error> {
    let before_problem = none.problem.clone();
    let after_problem = selected.fitted_problem();
    // δ after: the selected terms held at their estimates, the user's own parameters sampled.
    // Sampling the terms too would let δ and a term trade the same shape (a funnel that costs
    // NUTS divergences and most of the run) and asks nothing the BM1 fit has not answered.
    let mut held_problem = after_problem.clone();
    held_problem.model.calibrate = before_problem.model.calibrate.clone();
    let mut run = settings.run.clone();
    for (i, stage) in FitStage::ALL.into_iter().enumerate() {
        run.seed = settings.run.seed.wrapping_add(i as u64);
        if stage.is_after() && diagnosis.selected_set.is_empty() {
            continue;
        }
        // A Legendre polynomial of degree K over 20 s of back-and-forth motion is a slow trend,
        // not a locator: long records are located against the state instead.
        if stage.is_bm2() && uses_laplace(problem) {
            continue;
        }
        let (p, model) = match stage {
            FitStage::Before => (&before_problem, ModelSettings::bm1()),
            FitStage::After => (&after_problem, ModelSettings::bm1()),
            FitStage::BeforeBm2 => (&before_problem, ModelSettings::bm2(k)),
            FitStage::AfterBm2 => (&held_problem, ModelSettings::bm2(k)),
        };
        progress(Progress::Sampling(stage));
        let mut fit = fits::sample(
            p,
            &model,
            &run,
            &format!("{}: {}", stage.name(), model.label()),
        )?;
        if fit.run.fallback_stopped {
            diagnosis.notes.push(format!(
                "the {} fit's NUTS fallback spent its budget: its summary is the Laplace \
                 approximation's (k̂ {:.2}, refused for weighing)",
                stage.name(),
                fit.run.khat.unwrap_or(f64::NAN)
            ));
        }
        diagnosis
            .convergence
            .insert(stage.name().to_string(), Convergence::of(&fit.run));
        match stage {
            FitStage::Before => {
                diagnosis.fit_before = Some(fits::summarize_fit(problem, &mut fit)?)
            }
            FitStage::After => diagnosis.fit_after = Some(fits::summarize_fit(problem, &mut fit)?),
            FitStage::BeforeBm2 => {
                let (mismatch, _) = fits::mismatches(problem, &mut fit)?;
                if diagnosis.selected_set.is_empty() {
                    diagnosis.residual_mismatch |=
                        mismatch.iter().any(|m| fits::substantial(m, problem));
                }
                diagnosis.mismatch = mismatch;
            }
            FitStage::AfterBm2 => {
                let (left, _) = fits::mismatches(problem, &mut fit)?;
                let substantial: Vec<&Mismatch> = left
                    .iter()
                    .filter(|m| fits::substantial(m, problem))
                    .collect();
                diagnosis.residual_mismatch |= !substantial.is_empty();
                for m in substantial {
                    diagnosis.notes.push(format!(
                        "after the selected terms δ still excludes zero on {} from {:.4} s to \
                         {:.4} s (up to {:.2} σ): something the candidate library does not hold",
                        m.channel, m.t_start, m.t_end, m.max_over_sigma
                    ));
                }
            }
        }
        diagnosis.fits.push(StageFit { stage, fit });
    }
    if diagnosis.fit_after.is_none() {
        diagnosis.fit_after = diagnosis.fit_before.clone();
    }
    if uses_laplace(problem) {
        diagnosis.notes.push(format!(
            "{} samples: the fits before and after are Laplace approximations at the MAP \
             ({} draws from the Gaussian), not NUTS runs, and the BM2 band in time is skipped",
            problem
                .recordings
                .iter()
                .map(|r| r.n_samples())
                .sum::<usize>(),
            LAPLACE_DRAWS
        ));
    }
    if let (Some(law), Some(after)) = (&mut diagnosis.discovered, &diagnosis.fit_after) {
        law.use_sampled(&after.params_mean, &after.params_95);
    }
    // The posterior means as the model file's values.
    let mut model = after_problem.model.clone();
    for (name, &value) in diagnosis.fit_after.iter().flat_map(|f| &f.params_mean) {
        model.set_value(&ParamId::parse(name), value);
    }
    diagnosis.amended_model = Some(model);
    Ok(())
}

/// The unit of every calibrated parameter of `p`, as its base reads it.
fn parameter_units(p: &Problem) -> Result<BTreeMap<String, String>, Error> {
    let model = p.model_for(p.recording())?;
    Ok(model
        .parameter_specs(&model.magnitudes(1.0))
        .into_iter()
        .map(|spec| (spec.name(), spec.unit.to_string()))
        .collect())
}
