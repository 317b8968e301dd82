//! `motorcal design`: the input to record next, within the drive's limits, that tells the
//! candidates of a diagnosis apart or pins named parameters; writes input.csv, design.json and
//! design.png. The science is `crate::design`'s.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

use serde_json::{Value, json};

use crate::design::{
    self, Candidate, DesignSettings, Experiment, Limits, SearchSettings, Target, design_problem,
    design_times,
};
use crate::io::{VoltageProfile, read_model_file, write_atomically, write_input_profile};
use crate::motor::VoltageInput;
use crate::plot::{DesignChannel, DesignPlot, design_figure};
use crate::study::Problem;

use super::AppError;

mod diagnosis;
mod print;
use diagnosis::{candidate_values, default_candidates, read_diagnosis, selected_model};
use print::print_summary;

// The options of `motorcal design`, as the command line and the tests give them.
#[derive(clap::Args, Clone, Debug)]
pub struct DesignArgs {
    /// The user's model file (not the amended one).
    #[arg(long)]
    pub model: PathBuf,
    /// A `diagnose --json` report: the candidates' fits and the noise σ (with --pin, the
    /// selected model at its MAP, whose terms' parameters then can be pinned).
    #[arg(long)]
    pub diagnosis: Option<PathBuf>,
    /// Without --diagnosis: a recording to fit the --separate candidates to, or with --pin the
    /// model as given (repeat for several); without either they sit at the model's values.
    #[arg(long, conflicts_with = "diagnosis")]
    pub data: Vec<PathBuf>,
    /// Candidates to tell apart (default: the diagnosis's selected term and its ties).
    #[arg(long, value_delimiter = ',')]
    pub separate: Option<Vec<String>>,
    /// Parameters to pin (`R`, `coulomb_friction.T_c`, or a ratio `c_g/J`).
    #[arg(long, value_delimiter = ',', conflicts_with = "separate")]
    pub pin: Option<Vec<String>>,
    /// Length of the record [s].
    #[arg(long)]
    pub duration: f64,
    /// Sampling rate [Hz].
    #[arg(long)]
    pub rate: f64,
    /// The drive's limits, e.g. U=±24,I=±300,omega=±3000 (a current_driven model: I=±6,omega=±500,
    /// the current being what it commands; a position_loop: q=±0.1,omega=±0.5, the reference's
    /// travel about q = 0 and the axis's speed, and force=±F, by default 2% under the
    /// controller's saturation).
    #[arg(long, allow_hyphen_values = true)]
    pub limits: String,
    /// Segments of the designed input (a voltage, a current_driven model's current command, or
    /// a position_loop's reference position).
    #[arg(long, default_value_t = 8)]
    pub segments: usize,
    #[arg(long, default_value_t = 2026)]
    pub seed: u64,
    /// Noise σ of each channel the model measures: I [A] and ω [rad/s], ω alone for a
    /// current_driven model, q and the force for a position_loop (default: the diagnosis's or
    /// the fitted recording's, else the paper's 2 and 10; a position_loop has no default).
    #[arg(long, num_args = 1..=2, value_names = ["SD_1", "SD_2"])]
    pub noise_sd: Option<Vec<f64>>,
    /// Seeded search starts (run in parallel; a drive's design also starts from its fixed
    /// experiments).
    #[arg(long, default_value_t = 4)]
    pub starts: usize,
    /// Noisy records per candidate for the reported gap and its spread.
    #[arg(long, default_value_t = design::DEFAULT_DRAWS)]
    pub draws: usize,
    /// Separate the named candidates only: skip the check of the rest of the library on the
    /// designed input (by default a library term that comes within the ranking's tie threshold
    /// of a candidate there joins the candidates and the input is designed again, at most
    /// twice).
    #[arg(long, conflicts_with = "pin")]
    pub no_rival_check: bool,
    /// Output folder for input.csv, design.json and design.png.
    #[arg(long)]
    pub out: PathBuf,
}

/// `motorcal design`: search, write, say what it wrote.
pub fn run(args: &DesignArgs) -> Result<(), AppError> {
    let started = Instant::now();
    let limits: Limits = args
        .limits
        .parse()
        .map_err(|e| AppError::Usage(format!("--limits {}: {e}", args.limits)))?;
    let model = read_model_file(&args.model)?;
    // As the design keeps them (it applies the same default): what design.json reports.
    let limits = design::model_limits(&model, limits);
    let times = design_times(args.duration, args.rate)?;
    let base = design_problem(&model, &times, &limits)?;
    let commanded = design::Commanded::of(model.base);
    let channels = model.base.channels();
    let diagnosis = args.diagnosis.as_deref().map(read_diagnosis).transpose()?;
    let mut noise_sd = noise_sd(args, diagnosis.as_ref(), channels)?;
    let settings = DesignSettings {
        search: SearchSettings {
            segments: args.segments,
            starts: args.starts.max(1),
            seed: args.seed,
            ..SearchSettings::default()
        },
        limits,
        draws: args.draws.max(2),
    };
    if args.segments == 0 {
        return Err(AppError::Usage(
            "--segments 0 : a design needs at least one".into(),
        ));
    }
    let (report, values, fixed, figure): (_, _, Vec<design::InputCheck>, _) = if let Some(pins) =
        &args.pin
    {
        let targets: Vec<Target> = pins.iter().map(|p| Target::parse(p)).collect();
        // Where the design sits: the diagnosis's selected model at its MAP (its terms' own
        // parameters then can be pinned), the model as given fitted to --data, or the file.
        let (pinned_model, values, source) = match (&diagnosis, args.data.is_empty()) {
            (Some(diagnosis), _) => {
                let (terms, values) = selected_model(diagnosis)?;
                (
                    base.with_terms(&terms)?,
                    values,
                    "the diagnosis's selected model at its MAP",
                )
            }
            (None, true) => (base.clone(), BTreeMap::new(), "the model's values"),
            (None, false) => {
                let recorded = Problem::from_files(&args.data, &args.model)?;
                let (values, sd) = design::pin_values_from(&recorded, &targets)?;
                if args.noise_sd.is_none() {
                    noise_sd = sd;
                }
                (base.clone(), values, "the model's MAP on the recordings")
            }
        };
        let candidate = design::pin_candidate(&pinned_model, &values, &targets)?;
        let experiment = Experiment {
            candidates: vec![candidate.clone()],
            times: times.clone(),
            noise_sd: noise_sd.clone(),
        };
        let d = design::pin(&candidate, &experiment, &targets, &settings)?;
        let input = design::held(&d.times, d.values.clone());
        let (_, y, _) = prediction(&experiment, 0, &input)?;
        let report = json!({
            "objective": "pin",
            "targets": targets.iter().map(Target::name).collect::<Vec<_>>(),
            "expected_sd": d.pinned.sd,
            "expected_relative_sd": d.pinned.relative_sd,
            "log_det_covariance": d.pinned.log_det,
            "fixed_experiments": d.fixed_experiments.iter().map(|(c, p)| json!({
                "input": c.input, "file": fixed_file(&c.input), "within_limits": c.within_limits,
                "peaks": c.peaks, "expected_sd": p.sd, "expected_relative_sd": p.relative_sd,
            })).collect::<Vec<_>>(),
            "profile": d.profile, "peaks": d.check.peaks,
            "pinned_at": {"source": source, "values": candidate.calibrated.iter()
                .zip(&candidate.theta).collect::<BTreeMap<_, _>>()},
        });
        let figure = Figure {
            title: format!("design: pin {}", pins.join(", ")),
            truth_name: "model".into(),
            truth: y,
            rival: None,
        };
        let fixed = d.fixed_experiments.into_iter().map(|(c, _)| c).collect();
        (report, d.values, fixed, figure)
    } else {
        let names = match (&args.separate, &diagnosis) {
            (Some(names), _) => names.clone(),
            (None, Some(diagnosis)) => default_candidates(diagnosis)?,
            (None, None) => {
                return Err(AppError::Usage(
                    "name the candidates to tell apart with --separate (or give --diagnosis, \
                     whose selected term and ties they default to), or give --pin"
                        .into(),
                ));
            }
        };
        if names.len() < 2 {
            return Err(AppError::Usage(format!(
                "--separate {}: name at least two candidates",
                names.join(",")
            )));
        }
        let (candidates, source) = match &diagnosis {
            Some(diagnosis) => {
                let candidates = names
                    .iter()
                    .map(|name| {
                        design::parse_candidate(name)?;
                        let values = candidate_values(diagnosis, name)?;
                        Ok(Candidate::new(&base, name, &values)?)
                    })
                    .collect::<Result<Vec<_>, AppError>>()?;
                (candidates, "the diagnosis's estimates")
            }
            None => {
                for name in &names {
                    design::parse_candidate(name)?;
                }
                let recorded = if args.data.is_empty() {
                    None
                } else {
                    Some(Problem::from_files(&args.data, &args.model)?)
                };
                let (candidates, sd) =
                    design::candidates_without_diagnosis(&base, &names, recorded.as_ref())?;
                if args.noise_sd.is_none()
                    && let Some(sd) = sd
                {
                    noise_sd = sd;
                }
                let source = if recorded.is_some() {
                    "their MAP on the recordings"
                } else {
                    "the model's values"
                };
                (candidates, source)
            }
        };
        let experiment = Experiment {
            candidates,
            times: times.clone(),
            noise_sd: noise_sd.clone(),
        };
        let (d, experiment, checked) = if args.no_rival_check {
            (design::separate(&experiment, &settings)?, experiment, None)
        } else {
            let c = design::separate_checked(&base, &experiment, &settings, design::RIVAL_ROUNDS)?;
            let check = json!({
                "threshold_nats": crate::discover::EVIDENCE_THRESHOLD,
                "library": c.library,
                "added": c.added(),
                "rounds": c.rounds,
            });
            let rivals = json!(c.unseparated_rivals());
            (c.design, c.experiment, Some((rivals, check)))
        };
        let at: BTreeMap<&str, BTreeMap<&str, f64>> = experiment
            .candidates
            .iter()
            .map(|c| {
                let values = c
                    .calibrated
                    .iter()
                    .map(String::as_str)
                    .zip(c.theta.iter().copied())
                    .collect();
                (c.name.as_str(), values)
            })
            .collect();
        let mut at = json!({"source": source, "values": at});
        if experiment.candidates.len() > names.len() {
            at["added_source"] =
                json!("each added rival at its fit to the truth it came closest to");
        }
        let input = design::held(&d.times, d.values.clone());
        let curves = design::lead_curves(&experiment, &input)?;
        let mut report = json!({
            "objective": "separate",
            "candidates": names,
            "candidates_at": at,
            "expected_gap_nats": d.expected_gap_nats,
            "expected_gap_sd_nats": d.spread_nats,
            "gaps": d.gaps,
            "fixed_experiments": d.fixed_experiments.iter().map(|f| json!({
                "input": f.check.input, "file": fixed_file(&f.check.input),
                "expected_gap_nats": f.expected_gap_nats,
                "expected_gap_sd_nats": f.spread_nats, "within_limits": f.check.within_limits,
                "peaks": f.check.peaks, "gaps": f.gaps,
            })).collect::<Vec<_>>(),
            "profile": d.profile, "peaks": d.check.peaks,
        });
        // Null where the check was skipped: not checked, which an empty list would not say.
        let (rivals, check) = checked.unwrap_or((Value::Null, Value::Null));
        report["unseparated_rivals"] = rivals;
        report["rival_check"] = check;
        let (truth, rival) = (
            &experiment.candidates[curves.lead.truth].name,
            &experiment.candidates[curves.lead.rival].name,
        );
        let figure = Figure {
            title: format!(
                "design: {truth} as truth, {rival} fitted to it (noise-free lead {:.0} nats)",
                curves.lead.gap
            ),
            truth_name: truth.clone(),
            truth: curves.truth,
            rival: Some((rival.clone(), curves.rival_fit)),
        };
        let fixed = d.fixed_experiments.into_iter().map(|f| f.check).collect();
        (report, d.values, fixed, figure)
    };
    let mut report = report;
    report["limits"] = json!(limits);
    report["seed"] = json!(args.seed);
    report["duration_s"] = json!(args.duration);
    report["rate_hz"] = json!(args.rate);
    report["segments"] = json!(args.segments);
    report["noise_sd"] = json!(channels.iter().zip(&noise_sd).collect::<BTreeMap<_, _>>());
    let (level, level_unit) = commanded.level();
    report["input"] = json!({
        "quantity": commanded.column(), "unit": commanded.unit(),
        "levels": {"quantity": level, "unit": level_unit},
    });
    report["search"] = json!(settings.search);
    report["draws"] = json!(settings.draws);
    report["runtime_s"] = json!(started.elapsed().as_secs_f64());
    report["provenance"] = json!(
        crate::io::provenance()
            .into_iter()
            .collect::<BTreeMap<_, _>>()
    );
    let input = (commanded.column(), commanded.unit());
    let channels = channels
        .iter()
        .map(|&c| (c, model.base.channel_unit(c)))
        .collect::<Vec<_>>();
    // What the drive is played: the levels, or a position loop's reference, their integral.
    let values = commanded.played(&times, &values);
    let fixed: Vec<(String, Vec<f64>)> = fixed
        .into_iter()
        .map(|c| (fixed_file(&c.input), commanded.played(&times, &c.levels)))
        .collect();
    let written = Written {
        times: &times,
        values: &values,
        fixed: &fixed,
        input,
        channels: &channels,
        noise_sd: &noise_sd,
    };
    write_outputs(&args.out, &written, &report, &figure)?;
    print_summary(&report, &args.out);
    Ok(())
}

/// The noise-free prediction of candidate `c` under `input`, with its channels' names.
fn prediction(
    experiment: &Experiment,
    c: usize,
    input: &VoltageInput,
) -> Result<(Vec<String>, Vec<f64>, usize), AppError> {
    let forward = experiment.candidates[c].forward(input, &experiment.times)?;
    let mut y = vec![0.0; forward.n_outputs()];
    forward
        .simulate(&experiment.candidates[c].theta, &mut y)
        .map_err(|e| AppError::Numerical(e.to_string()))?;
    let names = forward.channels().iter().map(|s| s.to_string()).collect();
    Ok((names, y, experiment.times.len()))
}

/// What design.png draws: the truth's noise-free prediction and, when separating, the name of
/// its best-fitting rival and that fit (both channel-major).
struct Figure {
    title: String,
    truth_name: String,
    truth: Vec<f64>,
    rival: Option<(String, Vec<f64>)>,
}

/// σ of each of `channels`: the command line's, else the diagnosis's fit's, else the paper's.
fn noise_sd(
    args: &DesignArgs,
    diagnosis: Option<&Value>,
    channels: &[&str],
) -> Result<Vec<f64>, AppError> {
    if let Some(sd) = &args.noise_sd {
        if sd.len() != channels.len() || sd.iter().any(|s| !(*s > 0.0 && s.is_finite())) {
            return Err(AppError::Usage(format!(
                "--noise-sd {sd:?} : give one positive σ per channel the model measures ({})",
                channels.join(", ")
            )));
        }
        return Ok(sd.clone());
    }
    for fit in ["fit_after", "fit_before"] {
        let sigma = diagnosis.map(|d| &d[fit]["sigma"]);
        if let Some(s) = sigma
            && let Some(sd) = channels.iter().map(|c| s[*c].as_f64()).collect()
        {
            return Ok(sd);
        }
    }
    // Candidates (or with --pin, the model) fitted to --data take σ from their best fit
    // (`run`), before anything uses it: a channel without a default needs none then.
    let fitted_later = args.diagnosis.is_none() && !args.data.is_empty();
    channels
        .iter()
        .map(|c| {
            design::default_noise_sd(c)
                .or(fitted_later.then_some(1.0))
                .ok_or_else(|| {
                    AppError::Usage(format!(
                        "--noise-sd: no σ for the channel '{c}' (the model measures {}): give \
                     --noise-sd, or --diagnosis or --data to take it from",
                        channels.join(", ")
                    ))
                })
        })
        .collect()
}

/// The file a fixed experiment's input is written to in `--out`, beside the design's
/// `input.csv`: the same columns, so that `simulate --input` and a rig take it alike.
fn fixed_file(input: &str) -> String {
    format!("fixed-{input}.csv")
}

/// What input.csv and design.png show: the sample times, the designed levels, the input's
/// column and unit, the measured channels with their units and σ.
struct Written<'a> {
    times: &'a [f64],
    values: &'a [f64],
    /// Each fixed experiment's file name and what it plays, as `values` is the design's.
    fixed: &'a [(String, Vec<f64>)],
    input: (&'a str, &'a str),
    channels: &'a [(&'a str, &'a str)],
    noise_sd: &'a [f64],
}

fn write_outputs(
    out: &Path,
    written: &Written,
    report: &Value,
    figure: &Figure,
) -> Result<(), AppError> {
    let Written {
        times,
        values,
        input,
        ..
    } = *written;
    std::fs::create_dir_all(out)?;
    let files = std::iter::once(("input.csv", values)).chain(
        written
            .fixed
            .iter()
            .map(|(name, played)| (name.as_str(), played.as_slice())),
    );
    for (name, played) in files {
        write_input_profile(
            &out.join(name),
            input.0,
            &VoltageProfile {
                times: times.to_vec(),
                values: played.to_vec(),
            },
        )?;
    }
    let text = serde_json::to_string_pretty(report).map_err(|e| AppError::Output(e.to_string()))?;
    write_atomically(&out.join("design.json"), text.as_bytes())?;
    let m = times.len();
    let channels = written
        .channels
        .iter()
        .enumerate()
        .map(|(c, (name, unit))| DesignChannel {
            name: if *name == "omega" { "ω" } else { name }.into(),
            unit: unit.to_string(),
            truth: figure.truth[c * m..(c + 1) * m].to_vec(),
            rival: figure
                .rival
                .as_ref()
                .map_or(Vec::new(), |(_, y)| y[c * m..(c + 1) * m].to_vec()),
            sigma: written.noise_sd[c],
        })
        .collect();
    design_figure(
        &out.join("design.png"),
        &DesignPlot {
            title: figure.title.clone(),
            times: times.to_vec(),
            input: values.to_vec(),
            input_label: format!("{} [{}]", input.0, input.1),
            truth: figure.truth_name.clone(),
            rival: figure.rival.as_ref().map(|(name, _)| name.clone()),
            channels,
        },
    )
    .map_err(|e| AppError::Output(e.to_string()))?;
    Ok(())
}
