//! Simulation-based calibration (Talts, Betancourt, Simpson, Vehtari & Gelman 2018,
//! "Validating Bayesian inference algorithms with simulation-based calibration",
//! arXiv:1804.06788) of NUTS with a dense metric and of the two samplers that draw from the
//! Laplace approximation, on small motor posteriors: BM1, and BM2(K = 3) below.
//!
//! If θ̃ is drawn from the prior and data ỹ from the model at θ̃, then θ̃ is an exact draw from
//! the posterior p(θ | ỹ). Its rank among L independent posterior draws is therefore uniform
//! on {0, …, L} over the joint draw of (θ̃, ỹ) — if the sampler draws from that posterior. One
//! that is shifted piles the ranks up at one end, one that is too narrow at both ends, one that
//! is too wide in the middle. SBC checks the whole pipeline at once — prior, likelihood,
//! gradient, MAP warm start, warm-up, NUTS — over the range of data sets the prior makes, not
//! just the paper's one.
//!
//! Set-up: BM1 on 50 samples t_i = i·T/50, T = 0.5 s, with the data made by the same motor that
//! is fitted (c_g = 0.01), so that the model is well specified and SBC applies. θ = (R, σ_I, σ_ω)
//! with the fitted model's own priors, read from `ModelSettings::bm1()` so that the simulating
//! and the fitted prior cannot drift apart: R ~ N(0.1, 0.02) truncated to R > 0 (the posterior
//! is zero for R ≤ 0), and σ_I, σ_ω ~ InvGamma(1, 1) independently. That prior spreads σ from
//! about 0.15 to 1000 (0.1 % and 99.9 % quantiles) against signals of up to ~200 A and
//! ~2400 rad/s: data sets from nearly noise-free to nearly pure noise. All of them give smooth,
//! single-mode posteriors (50 samples pin log σ to about ±0.1 whatever σ is; 1000 replications
//! ran without a divergence), so the prior is kept as the paper states it rather than narrowed.
//!
//! Each replication runs one NUTS chain from the MAP, measures its bulk ESS, and thins it to
//! L = 99 roughly independent draws (Talts et al., §4: autocorrelated draws would bend the rank
//! histogram by themselves). The claim is a χ² test of uniform ranks per parameter, with a
//! Bonferroni correction over the 3 parameters: every p-value > 0.01/3. The same ranks against
//! deliberately wrong posteriors (the draws shifted by one posterior sd, or shrunk to a third
//! of their spread) must fail the same test, which shows that it can.
//!
//! BM2(K = 3) is the same set-up with the paper's discrepancy: δ(t) = Σ_j a_j p_j(t) on each
//! channel, four Legendre terms, added to the simulated channels before the noise. R and σ as
//! in BM1. a_j ~ Laplace(0, 10) independently, the paper's prior,
//! read from `ModelSettings::bm2(3)`. That prior has no hyper-parameters to draw (its scale is
//! fixed), so nothing in the draw can make the problem degenerate the way a drawn scale near
//! zero could; what remains is the Laplace prior's kink at a = 0, which the MAP search and the
//! Laplace approximation meet when the noise drawn is large enough to leave a coefficient to
//! its prior — where that makes the Student-t a poor proposal, the k̂ of laplace-is's weights
//! or of the independence sampler's warm-up says so and the run falls back to NUTS, which is
//! then what the ranks test. The prior is kept as stated.
//! The ranked quantities are R, σ_I and one coefficient of each channel (see [`bm2_k3`]).

mod common;

use std::time::Instant;

use common::chi_square_survival;
use motorcal::bayes::{CalibrationPosterior, DiscrepancyBasis, Legendre, ModelSettings};
use motorcal::bayes::{Observations, Prior};
use motorcal::diagnostics::ess_bulk;
use motorcal::forward::ForwardModel;
use motorcal::motor::{MotorModel, MotorParam, MotorParameters, VoltageInput};
use motorcal::ode::SolverSettings;
use motorcal::pipeline::{MetricAdaptation, RunSettings, SamplerKind, default_warmup, run_sampler};
use motorcal::sampler::ChainSettings;
use motorcal::sampler::driver::chain_rng;
use motorcal::synthetic::{generate, sample_times};
use rand::Rng;
use rand_distr::{Distribution, Exp1, Gamma, StandardNormal};
use rayon::prelude::*;

const SEED: u64 = 180_406_788;
/// Posterior draws per replication after thinning; L + 1 = 100 possible ranks.
const L: usize = 99;
const T_END: f64 = 0.5;
const SAMPLES: usize = 50;
/// Family-wise level of the uniformity test, split over the ranked quantities (Bonferroni).
const ALPHA: f64 = 0.01;
const WARMUP: usize = 300;
/// Draws of the first attempt; doubled until thinning to ESS leaves L of them.
const FIRST_DRAWS: usize = 400;

// ---------------------------------------------------------------------------------------------
// The posteriors SBC is run on.

/// A fitted model: its settings, what it calibrates, and which of its reported quantities
/// have their ranks tested.
struct Model {
    settings: ModelSettings,
    calibrated: &'static [MotorParam],
    ranked: &'static [&'static str],
}

/// BM1 calibrating R; every quantity ranked.
fn bm1() -> Model {
    Model {
        settings: ModelSettings::bm1(),
        calibrated: &[MotorParam::Resistance],
        ranked: &["R", "sigma_I", "sigma_omega"],
    }
}

/// BM2(K = 3) as the paper fits it: R calibrated, the discrepancy beside it. σ_ω is left out
/// of the ranks (σ_I stands for the noise levels; BM1 already tests both), and so are all but
/// one coefficient per channel: a_I.1, the constant term, which trades against the steady
/// current that R sets, and a_omega.4, the cubic one, the least informed by 50 samples.
///
/// Calibrating c_g and J as well (each with R's prior scaled to its nominal value) was tried
/// first. In its first six replications, independence chains needed 51 200 and 819 200 draws
/// (thinned by 425 and 4112) to give 99 independent ones, 148 s for the second; in its first
/// five, laplace-is fell back to NUTS on two, and on a third (k̂ 0.63) its weights' ESS was
/// about 115 of 12 800 proposals.
/// (Not examined further; the likely cause is that with σ drawn up to ~10³ the data pin only
/// combinations of R, c_g and J, and the posterior is a curved ridge.) It made the CI variant
/// cost many minutes, so the SBC here is of the model the paper fits.
fn bm2_k3() -> Model {
    Model {
        settings: ModelSettings::bm2(3),
        calibrated: &[MotorParam::Resistance],
        ranked: &["R", "sigma_I", "a_I.1", "a_omega.4"],
    }
}

/// The nominal (fitted) motor: the paper's true motor, c_g = 0.01.
fn nominal() -> MotorParameters {
    MotorParameters::default()
}

/// A normal draw truncated to > 0: the posterior is zero at and below 0 for these
/// untransformed parameters, so the prior it actually uses is truncated there.
fn positive_normal(rng: &mut impl Rng, mean: f64, sd: f64) -> f64 {
    loop {
        let z: f64 = StandardNormal.sample(rng);
        let x = mean + sd * z;
        if x > 0.0 {
            return x;
        }
    }
}

/// θ̃ from the fitted posterior's own prior, in its reported order: the calibrated
/// parameters, σ per channel, then each channel's coefficients. BM1 takes the random numbers
/// in the order it always has, so its replications are unchanged.
fn draw_from_prior(model: &Model, rng: &mut impl Rng) -> Vec<f64> {
    let settings = &model.settings;
    let mut truth = Vec::new();
    for &p in model.calibrated {
        let Prior::Normal { mean, sd } = settings.resistance_prior(nominal().get(p)) else {
            panic!("the paper's prior of a calibrated parameter is normal");
        };
        truth.push(positive_normal(rng, mean, sd));
    }
    // σ ~ InvGamma(α, β) ⇔ 1/σ ~ Gamma(shape α, rate β) = Gamma(α, scale 1/β).
    let precision = Gamma::new(settings.noise_prior_shape, 1.0 / settings.noise_prior_scale)
        .expect("a valid gamma");
    for _ in 0..2 {
        truth.push(1.0 / precision.sample(rng));
    }
    if let Some(k) = settings.discrepancy_degree {
        for _ in 0..2 {
            for j in 0..=k {
                let Prior::Laplace { location, scale } = settings.coefficient_prior.prior(j) else {
                    panic!("the paper's coefficient prior is Laplace");
                };
                // The difference of two unit exponentials is Laplace(0, 1).
                let e: [f64; 2] = [Exp1.sample(rng), Exp1.sample(rng)];
                truth.push(location + scale * (e[0] - e[1]));
            }
        }
    }
    truth
}

/// The posterior of one replication's data. Its ODE tolerance (10⁻⁸ relative) is the fit's
/// default, looser than the generator's 10⁻¹⁰: a model error of ~10⁻⁶ A on signals of ~10² A,
/// five orders of magnitude below the smallest noise the prior makes.
fn posterior_for(model: &Model, data: Vec<Vec<f64>>, times: &[f64]) -> CalibrationPosterior {
    let motor = MotorModel::new(nominal(), VoltageInput::Constant);
    let names: Vec<&str> = model.calibrated.iter().map(|p| p.key()).collect();
    let forward = ForwardModel::new(motor, times.to_vec(), &names, SolverSettings::default())
        .expect("a valid forward model");
    let obs = Observations {
        label: "sbc".into(),
        channels: data,
    };
    CalibrationPosterior::new(vec![(forward, obs)], &model.settings).expect("a posterior")
}

/// Data at θ̃: the motor with the drawn parameters, δ(ã) added to each channel, and noise
/// of the drawn σ̃.
fn simulate(model: &Model, truth: &[f64], times: &[f64], noise_seed: u64) -> Vec<Vec<f64>> {
    let n = model.calibrated.len();
    let mut motor = nominal();
    for (&p, &value) in model.calibrated.iter().zip(truth) {
        motor.set(p, value);
    }
    let motor = MotorModel::new(motor, VoltageInput::Constant);
    let mut data = generate(&motor, times, &truth[n..n + 2], noise_seed)
        .expect("the drawn motor simulates")
        .measured;
    if let Some(k) = model.settings.discrepancy_degree {
        // The basis the posterior builds: on [0, last sample time].
        let basis = Legendre::new(k, T_END)
            .expect("a valid basis")
            .matrix(times);
        for (c, channel) in data.iter_mut().enumerate() {
            let a = &truth[n + 2 + c * (k + 1)..n + 2 + (c + 1) * (k + 1)];
            for (i, y) in channel.iter_mut().enumerate() {
                *y += (0..=k).map(|j| basis[(i, j)] * a[j]).sum::<f64>();
            }
        }
    }
    data
}

// ---------------------------------------------------------------------------------------------
// One replication.

/// What one replication gives: ranks of θ̃ among the posterior draws, and among the same draws
/// made wrong on purpose, for each ranked quantity.
struct Replication {
    truth: Vec<f64>,
    ranks: Vec<usize>,
    /// Ranks among the draws shifted up by one posterior sd.
    shifted: Vec<usize>,
    /// Ranks among the draws shrunk to a third of their spread about their mean.
    narrowed: Vec<usize>,
    draws: usize,
    thin: usize,
    min_ess: f64,
    divergences: usize,
    /// laplace-is: its k̂, and whether it fell back to NUTS.
    khat: Option<f64>,
    fell_back: bool,
}

fn rank(truth: f64, draws: impl Iterator<Item = f64>) -> usize {
    draws.filter(|&d| d < truth).count()
}

/// Replication `r`: its prior draw, noise and chains all come from stream `r` of `SEED`, so
/// it gives the same result whichever thread runs it and however many run.
fn replicate(model: &Model, r: usize, sampler: SamplerKind) -> Replication {
    let mut rng = chain_rng(SEED, r);
    let truth = draw_from_prior(model, &mut rng);
    let noise_seed = rng.next_u64();
    let chain_seed = rng.next_u64();

    let times = sample_times(T_END, SAMPLES);
    let data = simulate(model, &truth, &times, noise_seed);
    let mut post = posterior_for(model, data, &times);
    let names = motorcal::density::LogDensity::output_names(&post);
    assert_eq!(names.len(), truth.len(), "the truth is drawn in {names:?}");
    let ranked: Vec<usize> = model
        .ranked
        .iter()
        .map(|q| {
            names
                .iter()
                .position(|n| n == q)
                .expect("a reported quantity")
        })
        .collect();

    let mut n_draws = FIRST_DRAWS;
    loop {
        let settings = RunSettings {
            sampler,
            chains: 1,
            chain: ChainSettings {
                warmup: if sampler == SamplerKind::NutsDense {
                    WARMUP
                } else {
                    default_warmup(sampler, MetricAdaptation::Laplace)
                },
                draws: n_draws,
                keep: None,
            },
            seed: chain_seed,
            quiet: true,
            ..RunSettings::default()
        };
        let run = run_sampler(&mut post, &settings, "sbc")
            .unwrap_or_else(|e| panic!("replication {r} (θ̃ = {truth:?}): {e}"));
        let chain = &run.chains[0];
        let columns: Vec<Vec<f64>> = ranked.iter().map(|&j| chain.column(j)).collect();
        // For laplace-is the run's min ESS is also capped by its weights' ESS: resampled
        // draws repeat, and thinning to the column's ESS alone would keep too many copies.
        let min_ess = columns
            .iter()
            .map(|c| ess_bulk(&[c]))
            .fold(run.min_ess_bulk, f64::min);
        // Keep every `thin`-th draw, with `thin` ≥ draws/ESS, so that the kept draws are about
        // as many as the chain's independent ones.
        let thin = (n_draws as f64 / min_ess).ceil().max(1.0) as usize;
        if n_draws / thin < L {
            n_draws *= 2;
            continue;
        }
        let kept: Vec<usize> = (0..L).map(|i| n_draws - 1 - i * thin).collect();
        let mut out = Replication {
            truth: truth.clone(),
            ranks: Vec::new(),
            shifted: Vec::new(),
            narrowed: Vec::new(),
            draws: n_draws,
            thin,
            min_ess,
            divergences: run.divergences,
            khat: run.khat,
            fell_back: run.fell_back,
        };
        for (column, &j) in columns.iter().zip(&ranked) {
            let draws: Vec<f64> = kept.iter().map(|&i| column[i]).collect();
            let mean = draws.iter().sum::<f64>() / L as f64;
            let sd =
                (draws.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / (L - 1) as f64).sqrt();
            out.ranks.push(rank(truth[j], draws.iter().copied()));
            out.shifted
                .push(rank(truth[j], draws.iter().map(|d| d + sd)));
            out.narrowed.push(rank(
                truth[j],
                draws.iter().map(|d| mean + (d - mean) / 3.0),
            ));
        }
        return out;
    }
}

// ---------------------------------------------------------------------------------------------
// The test of uniformity.

/// Counts of ranks 0..=L in `bins` equal bins.
fn histogram(ranks: impl Iterator<Item = usize>, bins: usize) -> Vec<usize> {
    assert_eq!((L + 1) % bins, 0, "bins must split the L + 1 ranks evenly");
    let mut counts = vec![0; bins];
    for rank in ranks {
        counts[rank * bins / (L + 1)] += 1;
    }
    counts
}

/// p-value of Pearson's χ² test that the counts are equally likely.
fn uniformity_p_value(counts: &[usize]) -> f64 {
    let n: usize = counts.iter().sum();
    let expected = n as f64 / counts.len() as f64;
    let statistic: f64 = counts
        .iter()
        .map(|&c| (c as f64 - expected).powi(2) / expected)
        .sum();
    chi_square_survival(statistic, counts.len() - 1)
}

/// p-values per ranked quantity of the ranks picked by `which`, with their histograms.
fn p_values(
    reps: &[Replication],
    quantities: usize,
    bins: usize,
    which: impl Fn(&Replication) -> &[usize],
) -> Vec<(f64, Vec<usize>)> {
    (0..quantities)
        .map(|j| {
            let counts = histogram(reps.iter().map(|r| which(r)[j]), bins);
            (uniformity_p_value(&counts), counts)
        })
        .collect()
}

fn calibration(model: &Model, replications: usize, bins: usize, sampler: SamplerKind) -> String {
    let started = Instant::now();
    // Ordered by r whatever the thread count: the outcome does not depend on it.
    let reps: Vec<Replication> = (0..replications)
        .into_par_iter()
        .map(|r| replicate(model, r, sampler))
        .collect();
    let seconds = started.elapsed().as_secs_f64();

    let divergences: usize = reps.iter().map(|r| r.divergences).sum();
    let mean_thin = reps.iter().map(|r| r.thin as f64).sum::<f64>() / reps.len() as f64;
    let min_ess = reps.iter().map(|r| r.min_ess).fold(f64::INFINITY, f64::min);
    let longest = reps.iter().map(|r| r.draws).max().unwrap_or(0);
    let n_theta = model.calibrated.len();
    let sigma_range = reps
        .iter()
        .flat_map(|r| r.truth[n_theta..n_theta + 2].to_vec())
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), s| {
            (lo.min(s), hi.max(s))
        });
    let mut report = format!(
        "SBC, {} on {}: {replications} replications × {L} draws, {bins} bins, {seconds:.1} s; \
         σ̃ from {:.3} to {:.1}; thinning mean {mean_thin:.2}, lowest ESS {min_ess:.0}, \
         longest chain {longest}; {divergences} divergences\n",
        sampler.name(),
        model.settings.label(),
        sigma_range.0,
        sigma_range.1
    );
    let khats: Vec<f64> = reps.iter().filter_map(|r| r.khat).collect();
    if !khats.is_empty() {
        let mut sorted = khats.clone();
        sorted.sort_by(f64::total_cmp);
        report.push_str(&format!(
            "k̂: median {:.3}, max {:.3}, {} of {} above 0.5, {} fell back to NUTS\n",
            sorted[sorted.len() / 2],
            sorted[sorted.len() - 1],
            sorted.iter().filter(|&&k| k > 0.5).count(),
            sorted.len(),
            reps.iter().filter(|r| r.fell_back).count()
        ));
    }

    let quantities = model.ranked.len();
    let threshold = ALPHA / quantities as f64;
    let sampled = p_values(&reps, quantities, bins, |r| &r.ranks);
    let shifted = p_values(&reps, quantities, bins, |r| &r.shifted);
    let narrowed = p_values(&reps, quantities, bins, |r| &r.narrowed);
    for (j, name) in model.ranked.iter().enumerate() {
        report.push_str(&format!(
            "{name:>12}: p = {:.4} {:?}; shifted by 1 sd p = {:.1e} {:?}; \
             shrunk to sd/3 p = {:.1e} {:?}\n",
            sampled[j].0, sampled[j].1, shifted[j].0, shifted[j].1, narrowed[j].0, narrowed[j].1
        ));
    }
    eprint!("{report}");
    let mut failures = Vec::new();
    for (j, name) in model.ranked.iter().enumerate() {
        // Written so that a NaN p-value fails too.
        let uniform = sampled[j].0 > threshold;
        if !uniform {
            failures.push(format!(
                "{name}: the ranks of the truth are not uniform, χ² p = {:.2e} ≤ {threshold:.4}; \
                 histogram {:?}",
                sampled[j].0, sampled[j].1
            ));
        }
        // The negative controls: posteriors off by one sd, or three times too confident, are
        // what the test exists to catch. If these passed, passing would mean nothing.
        for (control, label) in [
            (&shifted, "shifted by one sd"),
            (&narrowed, "shrunk to sd/3"),
        ] {
            let detected = control[j].0 <= threshold;
            if !detected {
                failures.push(format!(
                    "{name}: draws {label} were not detected, χ² p = {:.2e}; histogram {:?}",
                    control[j].0, control[j].1
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    report
}

/// Writes a long run's report beside the paper, its command as the first line.
fn write_report(file: &str, command: &str, report: &str) {
    let path = format!(
        "{}/papers/laplace-samplers/{file}",
        env!("CARGO_MANIFEST_DIR")
    );
    std::fs::create_dir_all(std::path::Path::new(&path).parent().unwrap()).unwrap();
    std::fs::write(path, format!("# {command}\n{report}")).unwrap();
}

/// 100 replications in 10 bins (10 expected per bin), about 15 s: coarse, but a posterior off
/// by one sd or three times too narrow fails it by orders of magnitude.
#[test]
fn nuts_ranks_the_truth_uniformly_in_100_replications() {
    calibration(&bm1(), 100, 10, SamplerKind::NutsDense);
}

/// The same 100 replications for the samplers that draw from the Laplace approximation.
#[test]
fn independence_ranks_the_truth_uniformly_in_100_replications() {
    calibration(&bm1(), 100, 10, SamplerKind::Independence);
}

#[test]
fn laplace_is_ranks_the_truth_uniformly_in_100_replications() {
    calibration(&bm1(), 100, 10, SamplerKind::LaplaceIs);
}

/// On BM1 collapsed-is proposes θ and draws each σ from its InvGamma conditional given θ.
#[test]
fn collapsed_is_ranks_the_truth_uniformly_in_100_replications() {
    calibration(&bm1(), 100, 10, SamplerKind::CollapsedIs);
}

/// Ten times Talts et al.'s 100: 1000 replications in 20 bins (50 expected per bin), which
/// also sees a bias or a width error of a fraction of a posterior sd.
#[test]
#[ignore]
fn nuts_ranks_the_truth_uniformly_in_1000_replications() {
    calibration(&bm1(), 1000, 20, SamplerKind::NutsDense);
}

/// 1000 replications of each Laplace sampler; the report is written to
/// papers/laplace-samplers/sbc_bm1.txt.
#[test]
#[ignore]
fn the_laplace_samplers_rank_the_truth_uniformly_in_1000_replications() {
    let mut report = String::new();
    for sampler in [SamplerKind::Independence, SamplerKind::LaplaceIs] {
        report.push_str(&calibration(&bm1(), 1000, 20, sampler));
    }
    write_report(
        "sbc_bm1.txt",
        "cargo test --release --test sbc -- --ignored --exact the_laplace_samplers_rank_the_truth_uniformly_in_1000_replications",
        &report,
    );
}

/// BM2(K = 3), 100 replications in 10 bins: the CI variant. When written, the two took 31 s of
/// CPU together on one thread (independence about four times laplace-is's share), all eight
/// p-values between 0.15 and 0.86, every control below 10⁻¹⁵. The threshold is BM1's, 0.01 split over the four quantities: the
/// seeds are fixed, so the test cannot flake, but a correct sampler whose draws change (a
/// changed kernel, another seed) fails it one time in a hundred; the controls show that an
/// error of one sd, or a width three times too small, fails by more than ten orders of
/// magnitude, so a stricter level would buy nothing here.
#[test]
fn independence_ranks_the_truth_uniformly_on_bm2_k3_in_100_replications() {
    calibration(&bm2_k3(), 100, 10, SamplerKind::Independence);
}

#[test]
fn laplace_is_ranks_the_truth_uniformly_on_bm2_k3_in_100_replications() {
    calibration(&bm2_k3(), 100, 10, SamplerKind::LaplaceIs);
}

/// With the coefficients drawn from their conditional given θ and σ.
#[test]
fn collapsed_is_ranks_the_truth_uniformly_on_bm2_k3_in_100_replications() {
    calibration(&bm2_k3(), 100, 10, SamplerKind::CollapsedIs);
}

/// The two replications of BM2(K = 3) whose independence chains mixed worst before the
/// sampler had a trust check: 853 drew σ_ω ≈ 1906 rad/s and 143 σ_I ≈ 650 A, far in the prior's
/// tail, which leaves that channel's coefficients to their Laplace prior, whose kink gives the
/// Hessian no curvature; the proposal was orders of magnitude too wide in them, and 853's chain
/// had a min bulk ESS of 1.4 at 819 200 draws, 143's 28 at 409 600
/// (papers/laplace-samplers/README.md). Now the k̂ of the warm-up's proposals says so and NUTS
/// draws instead, before the chain spends a draw.
#[test]
fn on_bm2_k3_the_independence_chains_that_could_not_mix_fall_back_to_nuts() {
    for r in [853, 143] {
        let rep = replicate(&bm2_k3(), r, SamplerKind::Independence);
        eprintln!(
            "replication {r}: σ̃ = {:?}, k̂ {:?}, fell back {}, {} draws, min ESS {:.0}",
            &rep.truth[1..3],
            rep.khat,
            rep.fell_back,
            rep.draws,
            rep.min_ess
        );
        let khat = rep.khat.expect("a warm-up long enough to judge");
        assert!(khat > 0.7 && rep.fell_back, "replication {r}: k̂ {khat}");
    }
}

/// 1000 replications of each Laplace sampler on BM2(K = 3) in 20 bins; the report is written
/// to papers/laplace-samplers/sbc_bm2_k3.txt. Before the independence sampler judged its
/// warm-up by k̂ this did not finish: chains like replication 853's (see above) could not mix.
/// With the check, when written: 289.6 s on one thread under a load of about 2.5 on two cores
/// (independence 215.4 s, laplace-is 74.2 s), every p-value 0.12–0.998; 7 independence
/// replications fell back to NUTS, and the longest chain had 25 600 draws. A temporary probe
/// (not kept) named them: 55, 115, 143, 375, 773, 853, 926 fell back, and the longest chain was
/// replication 118's (σ_I ≈ 223 A, k̂ 0.692, just under the line).
#[test]
#[ignore]
fn on_bm2_k3_the_laplace_samplers_rank_the_truth_uniformly_in_1000_replications() {
    let mut report = String::new();
    for sampler in [SamplerKind::Independence, SamplerKind::LaplaceIs] {
        report.push_str(&calibration(&bm2_k3(), 1000, 20, sampler));
    }
    write_report(
        "sbc_bm2_k3.txt",
        "cargo test --release --test sbc -- --ignored on_bm2_k3_the_laplace_samplers",
        &report,
    );
}

/// laplace-is alone on BM2(K = 3), 1000 replications in 20 bins, written to
/// papers/laplace-samplers/sbc_bm2_k3_laplace_is.txt (37.9 s when written), where the run of
/// both samplers above spends most of its time in the independence chains.
#[test]
#[ignore]
fn on_bm2_k3_laplace_is_ranks_the_truth_uniformly_in_1000_replications() {
    let report = calibration(&bm2_k3(), 1000, 20, SamplerKind::LaplaceIs);
    write_report(
        "sbc_bm2_k3_laplace_is.txt",
        "cargo test --release --test sbc -- --ignored on_bm2_k3_laplace_is",
        &report,
    );
}

/// collapsed-is, 1000 replications in 20 bins on BM1 and on BM2(K = 3), written to
/// papers/laplace-samplers/sbc_collapsed_is.txt.
#[test]
#[ignore]
fn collapsed_is_ranks_the_truth_uniformly_in_1000_replications() {
    let mut report = String::new();
    report.push_str(&calibration(&bm1(), 1000, 20, SamplerKind::CollapsedIs));
    report.push_str(&calibration(&bm2_k3(), 1000, 20, SamplerKind::CollapsedIs));
    write_report(
        "sbc_collapsed_is.txt",
        "cargo test --release --test sbc -- --ignored --exact collapsed_is_ranks_the_truth_uniformly_in_1000_replications",
        &report,
    );
}
