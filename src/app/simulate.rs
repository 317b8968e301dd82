//! `motorcal simulate`: a synthetic recording, the nominal model a user would believe, and the
//! truth that made the data.

use std::path::PathBuf;

use crate::io::{
    ModelFile, read_input_profile, read_model_file, write_model_file, write_recording_as,
};
use crate::motor::MotorParameters;
pub use crate::study::InputProfile;

/// The command line names the profiles as the model files and reports do.
impl clap::ValueEnum for InputProfile {
    fn value_variants<'a>() -> &'a [Self] {
        &InputProfile::ALL
    }

    fn to_possible_value(&self) -> Option<clap::builder::PossibleValue> {
        Some(clap::builder::PossibleValue::new(self.name()).help(self.help()))
    }
}
use crate::synthetic::{DEFAULT_SEED, sample_times};

use super::AppError;

/// Samples and length of a record driven by a profile, unless the command line says otherwise.
pub const DEFAULT_SAMPLES: usize = 501;
pub const DEFAULT_T_END: f64 = 0.5;

/// What drives the simulated motor: a named profile or a `t,U` file.
#[derive(Clone, Debug, PartialEq)]
pub enum InputSource {
    Profile(InputProfile),
    File(PathBuf),
}

impl InputSource {
    /// A profile's name, or else the path of a file (read, and refused with its error, later).
    pub fn parse(text: &str) -> Result<Self, String> {
        if text.is_empty() {
            return Err(format!(
                "empty; give a profile ({}) or the path of a t,U file",
                InputProfile::ALL.map(|p| p.name()).join(", ")
            ));
        }
        Ok(InputProfile::ALL
            .into_iter()
            .find(|p| p.name() == text)
            .map_or_else(
                || InputSource::File(PathBuf::from(text)),
                InputSource::Profile,
            ))
    }
}

// The options of `motorcal simulate`, as the command line and the tests give them.
#[derive(clap::Args, Clone, Debug)]
pub struct SimulateOptions {
    /// Model file of the motor that makes the data (default: the paper's, c_g = 0.01).
    #[arg(long)]
    pub truth: Option<PathBuf>,
    /// Model file the user believes (default: the paper's c_g = 0.009, or the truth).
    #[arg(long)]
    pub nominal: Option<PathBuf>,
    /// Output folder for recording.csv, motor.toml and truth.toml.
    #[arg(long, default_value = "simulated")]
    pub out: PathBuf,
    #[arg(long, default_value_t = DEFAULT_SEED)]
    pub seed: u64,
    /// The input: a profile (constant, step, reversal, square) or the path of a `t,U` file
    /// (a designed or recorded input; `t,I` for a current_driven truth, the commanded
    /// current; `t,q_ref` for a position_loop truth, the reference position), whose times the
    /// recording then takes.
    #[arg(long, default_value = "constant", value_parser = InputSource::parse)]
    pub input: InputSource,
    /// Noise standard deviations of I [A] and ω [rad/s] (a current_driven truth measures ω
    /// alone and takes SD_OMEGA; a position_loop truth takes them for q and the force).
    #[arg(long, num_args = 2, value_names = ["SD_I", "SD_OMEGA"], default_values_t = [2.0, 10.0])]
    pub noise_sd: Vec<f64>,
    /// Samples of the record (default 501; an input file's rows otherwise).
    #[arg(long)]
    pub samples: Option<usize>,
    /// Length of the record [s] (default 0.5; an input file's last time otherwise).
    #[arg(long)]
    pub t_end: Option<f64>,
    /// A concealed-physics case instead: the hidden effect(s) (a term name, two comma
    /// separated, or `none`); writes recording.csv, motor.toml and answer.json.
    #[arg(long, value_delimiter = ',', conflicts_with_all = ["truth", "nominal"])]
    pub effect: Option<Vec<String>>,
    /// With --effect: the peak effect over the noise σ (default: drawn in 0.6..1.5).
    #[arg(long, requires = "effect", allow_negative_numbers = true)]
    pub magnitude: Option<f64>,
    /// With --effect: keep the effect below 1.5σ and redraw until it is identifiable.
    #[arg(long, requires = "effect")]
    pub conceal: bool,
    /// With --conceal: a tie instead — the effect stands out from no effect but not from its
    /// look-alike (the runner-up) on the input asked, which is kept: a case to practise
    /// `motorcal design` on. The answer names the runner-up.
    #[arg(long)]
    pub tied: bool,
}

impl Default for SimulateOptions {
    fn default() -> Self {
        Self {
            truth: None,
            nominal: None,
            out: PathBuf::from("simulated"),
            seed: DEFAULT_SEED,
            input: InputSource::Profile(InputProfile::Constant),
            noise_sd: vec![2.0, 10.0],
            samples: None,
            t_end: None,
            effect: None,
            magnitude: None,
            conceal: false,
            tied: false,
        }
    }
}

/// `motorcal simulate`: a recording with its nominal model and truth, or with `--effect` a
/// concealed-physics case; says what it wrote.
pub fn run(options: &SimulateOptions) -> Result<(), AppError> {
    let out = &options.out;
    if options.tied && !options.conceal {
        return Err(AppError::Usage(
            "--tied needs --effect and --conceal: a tie is a concealed effect's".into(),
        ));
    }
    if let Some(effects) = &options.effect {
        let InputSource::Profile(input) = options.input else {
            return Err(AppError::Usage(
                "--input FILE cannot be combined with --effect: a concealed case draws its input \
                 from the profiles"
                    .into(),
            ));
        };
        let answer = super::cases::write_case(
            &crate::study::cases::CaseOptions {
                effects: effects.clone(),
                magnitude: options.magnitude,
                input,
                seed: options.seed,
                conceal: options.conceal,
                tied: options.tied,
            },
            out,
        )?;
        if let (true, Some(rival), Some(lead)) =
            (options.tied, &answer.oracle_runner_up, answer.oracle_margin)
        {
            println!("tied with {rival} (the truth leads it by {lead:.2} nats)");
        }
        println!(
            "wrote {} (effect {}, peak {:.2}/{:.2} σ on I/ω, input {:?}{})",
            out.display(),
            answer.effect,
            answer.max_abs_effect_over_sigma["I"],
            answer.max_abs_effect_over_sigma["omega"],
            answer.input,
            if answer.input_fallback {
                ", after falling back"
            } else {
                ""
            }
        );
        return Ok(());
    }
    let report = simulate(options)?;
    println!("wrote {}", report.recording.display());
    println!(
        "wrote {} (the model a user would believe)",
        report.nominal.display()
    );
    println!(
        "wrote {} (the truth that made the data)",
        report.truth.display()
    );
    // One entry per measured channel: a drive base measures other channels than I and ω.
    let sds: Vec<String> = report
        .channels
        .iter()
        .zip(&report.realised_noise_sd)
        .map(|(name, sd)| format!("{name} {sd:.4}"))
        .collect();
    println!(
        "realised noise sd: {} (seed {})",
        sds.join(", "),
        options.seed
    );
    Ok(())
}

/// What `simulate` wrote.
#[derive(Clone, Debug)]
pub struct SimulateReport {
    pub recording: PathBuf,
    pub nominal: PathBuf,
    pub truth: PathBuf,
    pub realised_noise_sd: Vec<f64>,
    /// The measured channels, in the order of `realised_noise_sd`.
    pub channels: Vec<String>,
}

pub fn simulate(options: &SimulateOptions) -> Result<SimulateReport, AppError> {
    let truth_file = match &options.truth {
        Some(path) => read_model_file(path)?,
        None => ModelFile::default(),
    };
    let nominal_file = match (&options.nominal, &options.truth) {
        (Some(path), _) => read_model_file(path)?,
        (None, Some(_)) => truth_file.clone(),
        (None, None) => ModelFile {
            motor: MotorParameters::paper_simulation_model(),
            ..ModelFile::default()
        },
    };
    if options.noise_sd.len() != 2
        || options
            .noise_sd
            .iter()
            .any(|s| !(*s >= 0.0 && s.is_finite()))
    {
        return Err(AppError::Usage(format!(
            "--noise-sd {:?} : must be non-negative numbers",
            options.noise_sd
        )));
    }
    let noise_sd = [options.noise_sd[0], options.noise_sd[1]];
    let truth_error = |e: crate::error::Error| match e {
        crate::error::Error::Settings(s) => AppError::Usage(format!("--truth: {}", s.message)),
        e => AppError::from(e),
    };
    let (recording, data) = match &options.input {
        InputSource::File(path) => {
            if options.samples.is_some() || options.t_end.is_some() {
                return Err(AppError::Usage(format!(
                    "--samples and --t-end cannot be given with --input {}: the file's times are \
                     the record's",
                    path.display()
                )));
            }
            let profile = read_input_profile(path, truth_file.base.input())?;
            crate::study::held_input_record(
                &truth_file,
                &profile.times,
                profile.values,
                &noise_sd,
                options.seed,
                "motorcal simulate",
            )
            .map_err(truth_error)?
        }
        InputSource::Profile(profile) => {
            if truth_file.base.is_drive() {
                return Err(AppError::Usage(format!(
                    "--input {}: a {} truth is driven by a recorded input; give the path of a \
                     t,{} file",
                    profile.name(),
                    truth_file.base.name(),
                    truth_file.base.input()
                )));
            }
            let samples = options.samples.unwrap_or(DEFAULT_SAMPLES);
            let t_end = options.t_end.unwrap_or(DEFAULT_T_END);
            if samples < 2 {
                return Err(AppError::Usage(format!(
                    "--samples {samples} : need at least 2 samples"
                )));
            }
            if !(t_end > 0.0 && t_end.is_finite()) {
                return Err(AppError::Usage(format!(
                    "--t-end {t_end} : must be a positive number of seconds"
                )));
            }
            let times = sample_times(t_end, samples);
            let input = profile.voltage(truth_file.motor.voltage, &times);
            crate::study::voltage_record(
                &truth_file,
                &times,
                input,
                &noise_sd,
                options.seed,
                "motorcal simulate",
            )
            .map_err(truth_error)?
        }
    };
    let report = SimulateReport {
        recording: options.out.join("recording.csv"),
        nominal: options.out.join("motor.toml"),
        truth: options.out.join("truth.toml"),
        realised_noise_sd: data.realised_noise_sd(),
        channels: data.channel_names.clone(),
    };
    // Named as the model file written beside it names them, so that it reads the record back.
    write_recording_as(&report.recording, &recording, &nominal_file.channels)?;
    write_model_file(&report.nominal, &nominal_file)?;
    write_model_file(&report.truth, &truth_file)?;
    Ok(report)
}
