//! `motorcal sweep`, `select-k` and `merge`: the K study (`paper::sweep`) and its files —
//! `sweep.csv`, `sweep.json`, Figures 8–11 and, at the degrees asked for, 13/14.

use std::path::PathBuf;

use crate::bayes::CoefficientFamily;
use crate::pipeline::{RunCost, RunOutput, SamplerKind};
use crate::plot::{self, KSeries};
use crate::study::Reference;

use super::AppError;
use super::args::{ChainArgs, coefficient_prior, parse_ks};
use super::figures::plot_discrepancy;

pub use crate::paper::sweep::*;

// The options of `motorcal sweep` and `motorcal select-k`.
#[derive(clap::Args, Clone, Debug)]
pub struct SweepArgs {
    /// Degrees: a range (0..=20) or a comma list (default 0..=20).
    #[arg(long, default_value = "0..=20")]
    pub k: String,
    /// Seeds of the synthetic noise, apart from the chains' --seed: one, a list or a range
    /// (default: the paper's data, 20180823). The grid is every (seed, K).
    #[arg(long, default_value = "20180823")]
    pub data_seed: String,
    /// Run one slice of the grid: grid points whose index is i − 1 modulo n (`--shard 3/8`);
    /// `motorcal merge` joins the slices' JSON into what one run writes.
    #[arg(long)]
    pub shard: Option<String>,
    /// Decay power p of the coefficient prior variance V0/(j+1)^p (0: the paper's prior).
    #[arg(long, default_value_t = 0.0)]
    pub prior_decay: f64,
    #[arg(long, value_enum, default_value_t = CoefficientFamily::Laplace)]
    pub prior_family: CoefficientFamily,
    #[arg(long, value_enum, default_value_t = SamplerKind::NutsDense)]
    pub sampler: SamplerKind,
    #[command(flatten)]
    pub chains: ChainArgs,
    /// Warm-up per chain (default: 100 for HMC/NUTS on the Laplace metric, which keeps R-hat
    /// and ESS at every K; else 1000; papers/john2018, "The warm-up").
    #[arg(long)]
    pub warmup: Option<usize>,
    #[arg(long, default_value_t = 1000)]
    pub draws: usize,
    #[arg(long, default_value = "out/sweep")]
    pub out: PathBuf,
    /// Write the records (or, for select-k, the choice) as JSON here.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Degrees at which to draw δ's band against d0 and the coefficients' marginals (a list).
    #[arg(long)]
    pub figures_at: Option<String>,
    /// select-k: `sigma-stabilisation` (§3.2.3) or `evidence` (the largest log marginal
    /// likelihood, by importance sampling).
    // Read as text and turned into the `ValueEnum` by `SweepArgs::rule`, so that a rule
    // mistyped stays one line naming `--rule` (tests/cli.rs), and `--help` as it was.
    #[arg(long, default_value = "sigma-stabilisation")]
    pub rule: String,
}

impl SweepArgs {
    /// The rule of `--rule`.
    pub fn rule(&self) -> Result<select::Rule, AppError> {
        <select::Rule as clap::ValueEnum>::from_str(&self.rule, false).map_err(|_| {
            AppError::Usage(format!(
                "--rule {}: known rules are sigma-stabilisation and evidence",
                self.rule
            ))
        })
    }

    /// The sweep these flags ask for (`--json` is the records' unless `select`: then the
    /// choice's).
    pub fn options(&self, select: bool) -> Result<SweepOptions, AppError> {
        let ks = parse_ks(&self.k).map_err(|e| AppError::Usage(format!("--k {e}")))?;
        self.rule()?;
        Ok(SweepOptions {
            ks,
            coefficient_prior: coefficient_prior(self.prior_family, self.prior_decay),
            data_seeds: parse_ks(&self.data_seed)
                .map_err(|e| AppError::Usage(format!("--data-seed {e}")))?
                .into_iter()
                .map(|s| s as u64)
                .collect(),
            shard: match &self.shard {
                None => None,
                Some(text) => Some(parse_shard(text)?),
            },
            run: self.chains.run(self.sampler, self.warmup, self.draws),
            out: self.out.clone(),
            json: if select { None } else { self.json.clone() },
            figures_at: match &self.figures_at {
                None => Vec::new(),
                Some(text) => {
                    parse_ks(text).map_err(|e| AppError::Usage(format!("--figures-at {e}")))?
                }
            },
        })
    }
}

fn parse_shard(text: &str) -> Result<(usize, usize), AppError> {
    let bad = || {
        AppError::Usage(format!(
            "--shard {text}: write i/n with 1 ≤ i ≤ n, e.g. 3/8"
        ))
    };
    let (i, n) = text.split_once('/').ok_or_else(bad)?;
    let (i, n): (usize, usize) = (
        i.trim().parse().map_err(|_| bad())?,
        n.trim().parse().map_err(|_| bad())?,
    );
    if !(n >= 1 && (1..=n).contains(&i)) {
        return Err(bad());
    }
    Ok((i, n))
}

/// `motorcal sweep`: the sweep, its table and the files it wrote.
pub fn run(args: &SweepArgs) -> Result<(), AppError> {
    let options = args.options(false)?;
    run_options(&options).map(|_| ())
}

/// The sweep of `options`, printed and written; its records.
pub(super) fn run_options(options: &SweepOptions) -> Result<Vec<SweepRecord>, AppError> {
    let records = sweep(options)?;
    print_and_write(&records, options)?;
    Ok(records)
}

/// The table, then the files.
pub(super) fn print_and_write(
    records: &[SweepRecord],
    options: &SweepOptions,
) -> Result<(), AppError> {
    print!("{}", format_table(records));
    for path in write_outputs(records, options)? {
        println!("wrote {}", path.display());
    }
    Ok(())
}

/// The sweep with the figures at `figures_at` drawn as each K finishes.
pub fn sweep(options: &SweepOptions) -> Result<Vec<SweepRecord>, AppError> {
    sweep_with(options, |p| {
        if options.figures_at.contains(&p.k) {
            k_figures(p.posterior, p.run, p.reference, p.k, options)?;
        }
        Ok::<_, AppError>(())
    })
}

/// δ's band with d0, and the coefficients' marginals with d0's least-squares coefficients, at K.
fn k_figures(
    posterior: &mut crate::bayes::CalibrationPosterior,
    run: &RunOutput,
    reference: &Reference,
    k: usize,
    options: &SweepOptions,
) -> Result<(), AppError> {
    std::fs::create_dir_all(&options.out)?;
    let predictive = crate::study::predictive::posterior_predictive(posterior, &run.chains, 0)?;
    plot_discrepancy(
        &options.out.join(format!("fig13-delta-k{k}.png")),
        &format!(
            "δ at K = {k} with the reference d₀ ({})",
            options.coefficient_prior.label()
        ),
        &predictive,
        Some(&reference.discrepancy),
    )?;
    let n_x = crate::density::LogDensity::dim(posterior);
    let mut channels = Vec::new();
    for (c, name) in ["I", "omega"].iter().enumerate() {
        let range = posterior
            .coefficient_range(0, c)
            .ok_or_else(|| AppError::Numerical("BM2 without coefficients".into()))?;
        // The basis columns: δ is linear in the coefficients.
        let m = reference.discrepancy[c].len();
        let mut basis = nalgebra::DMatrix::zeros(m, range.len());
        for (col, j) in range.clone().enumerate() {
            let mut x = vec![0.0; n_x];
            x[j] = 1.0;
            let column = posterior.discrepancy(&x, 0, c);
            for i in 0..m {
                basis[(i, col)] = column[i];
            }
        }
        let d0 = nalgebra::DVector::from_column_slice(&reference.discrepancy[c]);
        let least_squares = (basis.transpose() * &basis)
            .cholesky()
            .map(|ch| ch.solve(&(basis.transpose() * d0)));
        let summaries: Vec<&crate::diagnostics::ParameterSummary> = (1..=range.len())
            .map(|j| {
                run.summary(&format!("a_{name}.{j}"))
                    .ok_or_else(|| AppError::Numerical(format!("no summary of a_{name}.{j}")))
            })
            .collect::<Result<_, _>>()?;
        channels.push(plot::CoefficientMarginals {
            name: (*name).into(),
            unit: if c == 0 { "A" } else { "rad/s" }.into(),
            mean: summaries.iter().map(|s| s.mean).collect(),
            lower: summaries.iter().map(|s| s.q025).collect(),
            upper: summaries.iter().map(|s| s.q975).collect(),
            reference: least_squares.map(|v| v.iter().copied().collect()),
        });
    }
    plot::coefficient_marginals(
        &options.out.join(format!("fig14-coefficients-k{k}.png")),
        &format!(
            "Coefficients at K = {k} ({})",
            options.coefficient_prior.label()
        ),
        &channels,
    )
    .map_err(|e| AppError::Output(e.to_string()))
}

/// `sweep.csv`, `sweep.json` (or `--json`) and the figures.
pub fn write_outputs(
    records: &[SweepRecord],
    options: &SweepOptions,
) -> Result<Vec<PathBuf>, AppError> {
    std::fs::create_dir_all(&options.out)?;
    let mut written = Vec::new();
    let mut csv = String::from(
        "k,prior,data_seed,chain_seed,sampler,\
         R_mean,R_sd,R_q05,R_q95,R_q025,R_q975,R_bias,R_variance,R_mse,\
         sigma_I_mean,sigma_I_sd,sigma_I_q025,sigma_I_q975,sigma_I_bias,sigma_I_variance,sigma_I_mse,\
         sigma_omega_mean,sigma_omega_sd,sigma_omega_q025,sigma_omega_q975,sigma_omega_bias,sigma_omega_variance,sigma_omega_mse,\
         delta_I_nbias,delta_I_nv,delta_I_nmse,delta_I_nmse_bound,\
         delta_omega_nbias,delta_omega_nv,delta_omega_nmse,delta_omega_nmse_bound,\
         max_rhat,min_ess_bulk,min_ess_tail,divergences,wall_s,\
         log_evidence,log_evidence_se,log_evidence_ess,log_evidence_laplace,\
         map_cpu_s,warmup_cpu_s,sampling_cpu_s,total_cpu_s,evaluations,all_evaluations,\
         min_ess_per_s,min_ess_per_total_s,min_ess_per_eval,min_ess_per_all_evals\n",
    );
    for r in records {
        let s = |x: &ScalarStats| {
            format!(
                "{},{},{},{},{},{},{}",
                x.mean, x.sd, x.q025, x.q975, x.bias, x.variance, x.mse
            )
        };
        let d =
            |x: &DiscrepancyStats| format!("{},{},{},{}", x.n_bias, x.n_v, x.n_mse, x.n_mse_bound);
        csv.push_str(&format!(
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n",
            r.k,
            r.prior,
            r.data_seed,
            r.chain_seed,
            r.sampler,
            r.r.mean,
            r.r.sd,
            r.r.q05,
            r.r.q95,
            r.r.q025,
            r.r.q975,
            r.r.bias,
            r.r.variance,
            r.r.mse,
            s(&r.sigma_i),
            s(&r.sigma_omega),
            d(&r.delta_i),
            d(&r.delta_omega),
            r.max_rhat,
            r.min_ess_bulk,
            r.min_ess_tail,
            r.divergences,
            r.wall_s,
            r.evidence.log_evidence,
            r.evidence.standard_error,
            r.evidence.effective_draws,
            r.evidence.log_evidence_laplace,
            cost_columns(&r.cost),
        ));
    }
    let path = options.out.join("sweep.csv");
    crate::io::write_atomically(&path, csv.as_bytes())?;
    written.push(path);
    let path = options
        .json
        .clone()
        .unwrap_or_else(|| options.out.join("sweep.json"));
    let text =
        serde_json::to_string_pretty(records).map_err(|e| AppError::Output(e.to_string()))?;
    crate::io::write_atomically(&path, text.as_bytes())?;
    written.push(path);
    // Figures against K are of one data set; a grid over several seeds is for the tables.
    let one_seed = records.windows(2).all(|w| w[0].data_seed == w[1].data_seed);
    if one_seed && !records.is_empty() {
        written.extend(figures(records, options)?);
    }
    Ok(written)
}

fn cost_columns(c: &RunCost) -> String {
    format!(
        "{},{},{},{},{},{},{},{},{},{}",
        c.map.cpu_seconds,
        c.warmup.cpu_seconds,
        c.sampling.cpu_seconds,
        c.total_cpu_s,
        c.evaluations,
        c.all_evaluations,
        c.min_ess_per_s,
        c.min_ess_per_total_s,
        c.min_ess_per_eval,
        c.min_ess_per_all_evals
    )
}

fn figures(records: &[SweepRecord], options: &SweepOptions) -> Result<Vec<PathBuf>, AppError> {
    let ks: Vec<f64> = records.iter().map(|r| r.k as f64).collect();
    let series = |name: &str, unit: &str, f: &dyn Fn(&SweepRecord) -> f64, log_y: bool| KSeries {
        name: name.into(),
        unit: unit.into(),
        k: ks.clone(),
        mean: records.iter().map(f).collect(),
        log_y,
        ..KSeries::default()
    };
    let marginal = |name: &str, unit: &str, f: &dyn Fn(&SweepRecord) -> &ScalarStats| KSeries {
        name: name.into(),
        unit: unit.into(),
        k: ks.clone(),
        mean: records.iter().map(|r| f(r).mean).collect(),
        lower: Some(records.iter().map(|r| f(r).q025).collect()),
        upper: Some(records.iter().map(|r| f(r).q975).collect()),
        sd: Some(records.iter().map(|r| f(r).sd).collect()),
        reference: records.first().map(|r| f(r).reference),
        log_y: false,
    };
    let prior = records.first().map(|r| r.prior.clone()).unwrap_or_default();
    let plot_error = |e: plot::PlotError| AppError::Output(e.to_string());
    let mut written = Vec::new();
    let fig8 = options.out.join("fig8-marginals.png");
    plot::k_study(
        &fig8,
        &format!("Marginal posteriors against K ({prior})"),
        &[
            marginal("R", "Ω", &|r| &r.r),
            marginal("σ_I", "A", &|r| &r.sigma_i),
            marginal("σ_ω", "rad/s", &|r| &r.sigma_omega),
        ],
    )
    .map_err(plot_error)?;
    written.push(fig8);
    let fig9 = options.out.join("fig9-r-error.png");
    plot::k_study(
        &fig9,
        "Bias², variance and MSE of R against K",
        &[
            series("Bias(R)²", "Ω²", &|r| r.r.bias * r.r.bias, true),
            series("V(R)", "Ω²", &|r| r.r.variance, true),
            series("MSE(R)", "Ω²", &|r| r.r.mse, true),
        ],
    )
    .map_err(plot_error)?;
    written.push(fig9);
    let fig10 = options.out.join("fig10-sigma-error.png");
    plot::k_study(
        &fig10,
        "MSE of the noise standard deviations against K",
        &[
            series("MSE(σ_I)", "A²", &|r| r.sigma_i.mse, true),
            series("MSE(σ_ω)", "(rad/s)²", &|r| r.sigma_omega.mse, true),
        ],
    )
    .map_err(plot_error)?;
    written.push(fig10);
    let fig11 = options.out.join("fig11-delta-error.png");
    plot::k_study(
        &fig11,
        "nBias, nV and nMSE of δ against K",
        &[
            series("nBias(δ_I)", "A", &|r| r.delta_i.n_bias, true),
            series("nMSE(δ_I)", "A²", &|r| r.delta_i.n_mse, true),
            series("nBias(δ_ω)", "rad/s", &|r| r.delta_omega.n_bias, true),
            series("nMSE(δ_ω)", "(rad/s)²", &|r| r.delta_omega.n_mse, true),
        ],
    )
    .map_err(plot_error)?;
    written.push(fig11);
    Ok(written)
}

/// The table a user reads.
pub fn format_table(records: &[SweepRecord]) -> String {
    let mut s = format!(
        "{:>3} {:>11} {:>10} {:>10} {:>8} {:>8} {:>9} {:>9} {:>7} {:>7} {:>6}\n",
        "K", "R mean", "R sd", "MSE(R)", "σ_I", "σ_ω", "nBias δI", "nBias δω", "R-hat", "ESS", "s"
    );
    for r in records {
        s.push_str(&format!(
            "{:>3} {:>11.6} {:>10.2e} {:>10.2e} {:>8.4} {:>8.4} {:>9.3} {:>9.3} {:>7.4} {:>7.0} {:>6.1}\n",
            r.k,
            r.r.mean,
            r.r.sd,
            r.r.mse,
            r.sigma_i.mean,
            r.sigma_omega.mean,
            r.delta_i.n_bias,
            r.delta_omega.n_bias,
            r.max_rhat,
            r.min_ess_bulk,
            r.wall_s
        ));
    }
    s
}
