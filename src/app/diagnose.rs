//! `motorcal diagnose`: reads the recordings and the model, calls [`crate::discover`], and
//! writes what it found — the JSON report, the figures (fits before and after, δ before and
//! after, the missing torque), both fits' `fit.json`, the amended `model.toml` — and prints the
//! human summary.

use std::fmt::Write;
use std::path::PathBuf;

use crate::discover::{Diagnosis, DiscoverSettings, FitStage, discover};
use crate::io::write_model_file;
use crate::motor::Term;
use crate::pipeline::{RunSettings, SamplerKind};
use crate::study::{Problem, posterior_predictive};

use super::AppError;
use super::args::ChainArgs;
use super::figures::{plot_discrepancy, plot_predictive};

pub use crate::discover::METRIC_ADAPTATION;

/// Options of `motorcal diagnose`.
#[derive(Clone, Debug)]
pub struct DiagnoseOptions {
    pub data: Vec<PathBuf>,
    pub model: PathBuf,
    pub k: Option<usize>,
    /// Term names to consider; `None`: every term the model lacks that applies to its base.
    pub candidates: Option<Vec<String>>,
    pub run: RunSettings,
    pub out: Option<PathBuf>,
    pub json: Option<PathBuf>,
    /// Skip the sampled fits (ranking, selection and ties only).
    pub rank_only: bool,
    /// Go on when the recordings cannot be this motor (the report carries the findings and
    /// selects nothing).
    pub force: bool,
}

#[derive(clap::Args, Clone, Debug)]
pub struct DiagnoseArgs {
    /// A recording; repeat for several (shared physics, noise per recording).
    #[arg(long, required = true)]
    pub data: Vec<PathBuf>,
    /// The nominal model (TOML, schema 1 or 2).
    #[arg(long)]
    pub model: PathBuf,
    /// Degree K of the discrepancy that locates the mismatch (default 9).
    #[arg(long)]
    pub k: Option<usize>,
    /// Candidate terms, comma separated (default: every term the model lacks).
    #[arg(long, value_delimiter = ',')]
    pub candidates: Option<Vec<String>>,
    /// Write the report as JSON here.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Write figures, fit.json and the amended model.toml here.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Rank and select only: no sampled fits before and after.
    #[arg(long)]
    pub rank_only: bool,
    /// Go on when a recording cannot be this motor as set up (a dead channel, a unit, sign or
    /// swap, time in ms): the report lists the findings and selects no physics.
    #[arg(long)]
    pub force: bool,
    #[command(flatten)]
    pub chains: ChainArgs,
    #[arg(long, default_value_t = 500)]
    pub warmup: usize,
    #[arg(long, default_value_t = 500)]
    pub draws: usize,
}

impl DiagnoseArgs {
    /// The diagnosis these flags ask for: NUTS (dense), with the diagnosis's own metric
    /// adaptation unless told.
    pub fn options(&self) -> DiagnoseOptions {
        DiagnoseOptions {
            data: self.data.clone(),
            model: self.model.clone(),
            k: self.k,
            candidates: self.candidates.clone(),
            run: self.chains.run_adapting(
                SamplerKind::NutsDense,
                Some(self.warmup),
                self.draws,
                METRIC_ADAPTATION,
            ),
            out: self.out.clone(),
            json: self.json.clone(),
            rank_only: self.rank_only,
            force: self.force,
        }
    }
}

/// `motorcal diagnose`: the diagnosis, its report and the files it wrote.
pub fn run(args: &DiagnoseArgs) -> Result<(), AppError> {
    let diagnosis = diagnose(&args.options())?;
    print!("{}", format_diagnosis(&diagnosis));
    for path in &diagnosis.outputs {
        println!("wrote {path}");
    }
    Ok(())
}

/// The whole command: read, discover, write; returns the report with the files it wrote.
pub fn diagnose(options: &DiagnoseOptions) -> Result<Diagnosis, AppError> {
    let started = std::time::Instant::now();
    let problem = Problem::from_files(&options.data, &options.model)?;
    let implausible = super::plausible(&problem, options.force)?;
    let settings = DiscoverSettings {
        k: options.k,
        candidates: options.candidates.clone(),
        run: options.run.clone(),
        rank_only: options.rank_only,
        implausible,
    };
    let mut diagnosis = discover(&problem, &settings)?;
    if let Some(out) = &options.out {
        write_figures(&problem, &mut diagnosis, out)?;
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

/// The figures of the sampled fits, `model.toml`, `fit.json` and the missing torque in `out`.
fn write_figures(
    problem: &Problem,
    diagnosis: &mut Diagnosis,
    out: &std::path::Path,
) -> Result<(), AppError> {
    std::fs::create_dir_all(out)?;
    let k = diagnosis.discrepancy_degree;
    let mut outputs = Vec::new();
    if !diagnosis.fits.is_empty() {
        let selected = diagnosis.selected_set.join(" + ");
        for stage_fit in diagnosis.fits.iter_mut() {
            let (stage, fit) = (stage_fit.stage, &mut stage_fit.fit);
            for r in 0..fit.posterior.n_records() {
                let p = posterior_predictive(&mut fit.posterior, &fit.run.chains, r)?;
                let suffix = if problem.recordings.len() > 1 {
                    format!("-{}", r + 1)
                } else {
                    String::new()
                };
                let path = if stage.is_bm2() {
                    let path = out.join(format!("discrepancy-{}{suffix}.png", stage.name()));
                    let when = if stage.is_after() { "after" } else { "before" };
                    plot_discrepancy(&path, &format!("δ {when} (BM2, K = {k})"), &p, None)?;
                    path
                } else {
                    let path = out.join(format!("fit-{}{suffix}.png", stage.name()));
                    let title = if stage == FitStage::Before {
                        "the model as given (BM1)".to_string()
                    } else {
                        format!("with {selected} (BM1)")
                    };
                    plot_predictive(&path, &title, &p)?;
                    path
                };
                outputs.push(path.display().to_string());
            }
        }
        if let Some(model) = &diagnosis.amended_model {
            let path = out.join("model.toml");
            write_model_file(&path, model)?;
            outputs.push(path.display().to_string());
        }
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
        outputs.push(path.display().to_string());
    }
    if !diagnosis.missing_torque.is_empty() {
        let path = out.join("missing-torque.png");
        let plot = crate::plot::MissingTorquePlot {
            title: "the torque the model misses, against speed".into(),
            speed_unit: problem.model.base.unit("rad/s").into(),
            torque_unit: problem.model.base.unit("N·m").into(),
            curves: diagnosis.missing_torque.clone(),
        };
        crate::plot::missing_torque(&path, &plot).map_err(|e| AppError::Output(e.to_string()))?;
        outputs.push(path.display().to_string());
    }
    // The verdict after the selection, and on the model as given: the evidence behind the
    // fingerprint of what is left, and of the whole mismatch that the named terms took up.
    for (verdict, name, model) in [
        (
            &diagnosis.unexplained,
            "unexplained.png",
            "the selected model",
        ),
        (
            &diagnosis.unexplained_as_given,
            "unexplained_as_given.png",
            "the model as given",
        ),
    ] {
        if let Some(u) = verdict {
            let path = out.join(name);
            crate::plot::unexplained(&path, &unexplained_plot(u, model))
                .map_err(|e| AppError::Output(e.to_string()))?;
            outputs.push(path.display().to_string());
        }
    }
    diagnosis.outputs.extend(outputs);
    Ok(())
}

/// The verdict's evidence as figure rows: each channel's residual with what the leading
/// fingerprint explains of it, then each channel's spectrum of gains.
/// The figure of a verdict on `model` ("the selected model", "the model as given").
fn unexplained_plot(u: &crate::discover::Unexplained, model: &str) -> crate::plot::UnexplainedPlot {
    let f = &u.figure;
    let n = f.times.len();
    let lead = serde_json::to_value(&u.fingerprint)
        .ok()
        .and_then(|v| v["kind"].as_str().map(String::from))
        .unwrap_or_default();
    let mut rows = Vec::new();
    for (c, name) in f.channels.iter().enumerate() {
        rows.push(crate::plot::UnexplainedRow {
            x_desc: "t [s]".into(),
            y_desc: format!("{name} residual [σ]"),
            x: f.times.clone(),
            points: f.residual[c * n..(c + 1) * n].to_vec(),
            points_label: format!("residual of {model}"),
            curve: f.explained[c * n..(c + 1) * n].to_vec(),
            curve_label: format!("what the fingerprint ({lead}) explains"),
        });
    }
    for (name, (freq, gain)) in f.channels.iter().zip(&f.spectrum) {
        rows.push(crate::plot::UnexplainedRow {
            x_desc: "frequency [Hz]".into(),
            y_desc: format!("{name}: gain [nats]"),
            x: freq.clone(),
            points: Vec::new(),
            points_label: String::new(),
            curve: gain.clone(),
            curve_label: "a sinusoid through the record".into(),
        });
    }
    if let Some(folded) = &f.folded {
        rows.push(crate::plot::UnexplainedRow {
            x_desc: format!("{}, fraction of a period", folded.variable),
            y_desc: format!("{} residual [σ]", folded.channel),
            x: folded.phase.clone(),
            points: folded.residual.clone(),
            points_label: format!("residual of {model}, folded"),
            curve: folded.binned.clone(),
            curve_label: format!(
                "its mean over 1/{} of a period",
                crate::discover::FOLDED_BINS
            ),
        });
    }
    crate::plot::UnexplainedPlot {
        title: format!(
            "left unexplained: {lead} ({:+.1} nats over {model})",
            u.evidence
        ),
        rows,
    }
}

fn unit_of(name: &str) -> &'static str {
    let Some((term, key)) = name.split_once('.') else {
        return if name == "R" { "Ω" } else { "" };
    };
    Term::named(term)
        .and_then(|t| t.params().iter().find(|p| p.key == key).map(|p| p.unit))
        .unwrap_or("")
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
    if !d.implausible.is_empty() {
        for finding in &d.implausible {
            let _ = writeln!(s, "implausible (went on with --force): {finding}");
        }
        let _ = writeln!(
            s,
            "no physics is named on top of a recording that cannot be this motor as set up"
        );
        return s;
    }
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
    if d.selected_set.is_empty() && d.unexplained.is_some() {
        let _ = writeln!(
            s,
            "no library term beats the model as it is by more than {} nats, but something is \
             missing that the library does not hold:",
            d.threshold
        );
    } else if d.selected_set.is_empty() {
        let _ = writeln!(
            s,
            "no candidate beats the model as it is by more than {} nats: nothing missing found",
            d.threshold
        );
    } else {
        let _ = writeln!(s, "the model lacks {}", d.selected_set.join(" + "));
        if let Some(law) = &d.discovered {
            let _ = writeln!(
                s,
                "discovered law ({:+.1} nats): {}",
                law.score, law.equation
            );
        }
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
    if let Some(u) = &d.unexplained {
        let _ = writeln!(
            s,
            "unexplained: {:+.1} nats left on {} that no library term holds; {}",
            u.evidence,
            u.channels.join(" and "),
            u.suggestion
        );
        for f in std::iter::once(&u.fingerprint).chain(&u.alternatives) {
            let _ = writeln!(
                s,
                "  fingerprint: {}",
                serde_json::to_string(f).unwrap_or_default()
            );
        }
        for w in &u.spans {
            let _ = writeln!(
                s,
                "  where: {} from {:.4} s to {:.4} s",
                w.channel, w.t_start, w.t_end
            );
        }
    }
    if let Some(g) = &d.unexplained_as_given {
        let _ = writeln!(
            s,
            "the model as given: {:+.1} nats on {}, fingerprint {}",
            g.evidence,
            g.channels.join(" and "),
            serde_json::to_string(&g.fingerprint).unwrap_or_default()
        );
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
