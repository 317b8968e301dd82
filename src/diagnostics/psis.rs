//! Pareto-smoothed importance sampling (PSIS): the largest importance weights replaced by the
//! expected order statistics of a generalized Pareto distribution fitted to them, the fitted
//! shape k̂ as the diagnostic of whether the importance estimate can be trusted, and the
//! effective sample size of the smoothed weights.
//!
//! The method is that of Vehtari, Simpson, Gelman, Yao and Gabry (2024), "Pareto smoothed
//! importance sampling", JMLR 25(72), with the generalized Pareto fit of Zhang and Stephens
//! (2009, Technometrics 51(3)). Every numerical choice (the tail length min(S/5, 3√(S/r_eff)),
//! the floor of the cut-off at the smallest normal double, the grid of the empirical-Bayes fit
//! and its weakly informative prior on k, the truncation of the smoothed weights at the largest
//! raw one) follows ArviZ 0.23.4's `az.psislw`, so that k̂ and the smoothed weights agree with
//! it to rounding (`tests/psis_arviz.rs`).
//!
//! Reading k̂ (Vehtari et al. 2024, §3): below 0.5 the weights have a finite variance and the
//! estimate converges at the usual rate; from 0.5 to 0.7 it is still usable but slower; above
//! 0.7 the estimate is unreliable whatever the number of draws — the proposal misses where the
//! target has mass.

/// Below this k̂ the importance estimate converges like a plain Monte Carlo one.
pub const KHAT_GOOD: f64 = 0.5;
/// Above this k̂ the importance estimate cannot be trusted.
pub const KHAT_UNRELIABLE: f64 = 0.7;

/// The k̂ below which a Pareto-smoothed estimate from `draws` weights is reliable, the
/// sample-size rule of Vehtari et al. (2024, §3.2.4, eq. 13): min(1 − 1/log₁₀ S, 0.7). Below
/// it the smoothed estimate's error is small with high probability at this S; the line rises
/// with S (0.5 at 100 draws, 0.67 at 1000) and stops at 0.7, above which the smoothing's bias
/// dominates whatever S. Fewer than ten draws can be trusted at no k̂.
pub fn khat_threshold(draws: usize) -> f64 {
    if draws < 10 {
        return f64::NEG_INFINITY;
    }
    (1.0 - 1.0 / (draws as f64).log10()).min(KHAT_UNRELIABLE)
}

/// ArviZ's fit grid is 30 + ⌊√n⌋ points; its prior on k is worth 10 observations at k = 0.5.
const GRID_BASE: usize = 30;
const PRIOR_B_SCALE: f64 = 3.0;
const PRIOR_K_WEIGHT: f64 = 10.0;

/// Smoothed log weights and the Pareto shape of their tail.
#[derive(Clone, Debug, PartialEq)]
pub struct Psis {
    /// Smoothed log weights, normalised so that their exponentials sum to one.
    pub log_weights: Vec<f64>,
    /// The fitted generalized Pareto shape k̂ of the largest weights; +∞ when the tail has
    /// too few draws to fit (then the weights are only normalised, not smoothed).
    pub khat: f64,
}

impl Psis {
    /// The normalised weights.
    pub fn weights(&self) -> Vec<f64> {
        self.log_weights.iter().map(|w| w.exp()).collect()
    }

    /// The effective sample size of the smoothed weights, 1 / Σ w̃ᵢ² (Vehtari et al. 2024,
    /// eq. 6 with r_eff = 1): how many independent draws from the target the weighted draws
    /// are worth for the mean of a bounded function.
    pub fn ess(&self) -> f64 {
        1.0 / self
            .log_weights
            .iter()
            .map(|w| (2.0 * w).exp())
            .sum::<f64>()
    }

    /// Whether k̂ says the estimate can be trusted (k̂ ≤ 0.7).
    pub fn reliable(&self) -> bool {
        self.khat <= KHAT_UNRELIABLE
    }
}

/// Pareto-smooths raw log importance weights (log p − log q up to a constant) of independent
/// draws, ArviZ's `psislw(log_weights, reff=1)`. A non-finite weight other than −∞ gives k̂ = NaN
/// and the weights unsmoothed.
pub fn psis(log_weights: &[f64]) -> Psis {
    psis_with_reff(log_weights, 1.0)
}

/// [`psis`] for draws whose relative efficiency ESS/S is `reff` (MCMC draws as proposals).
pub fn psis_with_reff(log_weights: &[f64], reff: f64) -> Psis {
    let n = log_weights.len();
    if n == 0 {
        return Psis {
            log_weights: Vec::new(),
            khat: f64::NAN,
        };
    }
    if log_weights
        .iter()
        .any(|w| w.is_nan() || *w == f64::INFINITY)
    {
        return Psis {
            log_weights: normalised(log_weights.to_vec()),
            khat: f64::NAN,
        };
    }
    let tail = (n as f64 / 5.0).min(3.0 * (n as f64 / reff).sqrt()).ceil() as usize;
    let max = log_weights
        .iter()
        .copied()
        .fold(f64::NEG_INFINITY, f64::max);
    if max == f64::NEG_INFINITY {
        return Psis {
            log_weights: log_weights.to_vec(),
            khat: f64::NAN,
        };
    }
    let mut x: Vec<f64> = log_weights.iter().map(|w| w - max).collect();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| x[a].total_cmp(&x[b]));
    // ArviZ's index −(tail + 1) counted from the end; a tail longer than the draws wraps there.
    let cut_position = (n as isize - tail as isize - 1).rem_euclid(n as isize) as usize;
    let cutoff = x[order[cut_position]].max(f64::MIN_POSITIVE.ln());
    let exp_cutoff = cutoff.exp();
    // The tail in increasing order: the sorted indices above the cut-off.
    let tail_indices: Vec<usize> = order.iter().copied().filter(|&i| x[i] > cutoff).collect();
    let khat = if tail_indices.len() <= 4 {
        f64::INFINITY
    } else {
        let exceedances: Vec<f64> = tail_indices
            .iter()
            .map(|&i| x[i].exp() - exp_cutoff)
            .collect();
        let (k, sigma) = generalized_pareto_fit(&exceedances);
        if k.is_finite() {
            let m = tail_indices.len();
            for (rank, &i) in tail_indices.iter().enumerate() {
                let p = (rank as f64 + 0.5) / m as f64;
                x[i] = (generalized_pareto_quantile(p, k, sigma) + exp_cutoff).ln();
            }
            for v in &mut x {
                if *v > 0.0 {
                    *v = 0.0;
                }
            }
        }
        k
    };
    Psis {
        log_weights: normalised(x),
        khat,
    }
}

/// Log weights shifted so that their exponentials sum to one.
fn normalised(mut x: Vec<f64>) -> Vec<f64> {
    let max = x.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let log_sum = max + x.iter().map(|v| (v - max).exp()).sum::<f64>().ln();
    for v in &mut x {
        *v -= log_sum;
    }
    x
}

/// Zhang and Stephens' empirical-Bayes fit of a generalized Pareto distribution to sorted
/// positive exceedances, with ArviZ's prior on k: (k̂, σ̂).
fn generalized_pareto_fit(sorted: &[f64]) -> (f64, f64) {
    let n = sorted.len();
    let nf = n as f64;
    let m = GRID_BASE + (nf.sqrt() as usize);
    let quartile = sorted[(nf / 4.0 + 0.5) as usize - 1];
    let largest = sorted[n - 1];
    let b: Vec<f64> = (1..=m)
        .map(|j| {
            (1.0 - (m as f64 / (j as f64 - 0.5)).sqrt()) / (PRIOR_B_SCALE * quartile)
                + 1.0 / largest
        })
        .collect();
    let mean_log1p = |bj: f64| sorted.iter().map(|&v| (-bj * v).ln_1p()).sum::<f64>() / nf;
    let profile: Vec<f64> = b
        .iter()
        .map(|&bj| {
            let k = mean_log1p(bj);
            nf * ((-(bj / k)).ln() - k - 1.0)
        })
        .collect();
    // The posterior weight of grid point i, 1 / Σⱼ exp(ℓⱼ − ℓᵢ); negligible ones dropped.
    let mut kept: Vec<(f64, f64)> = profile
        .iter()
        .zip(&b)
        .map(|(&li, &bi)| {
            let w = 1.0 / profile.iter().map(|&lj| (lj - li).exp()).sum::<f64>();
            (w, bi)
        })
        .filter(|&(w, _)| w >= 10.0 * f64::EPSILON)
        .collect();
    let total: f64 = kept.iter().map(|(w, _)| w).sum();
    for (w, _) in &mut kept {
        *w /= total;
    }
    let b_post: f64 = kept.iter().map(|(w, b)| w * b).sum();
    let k = mean_log1p(b_post);
    let sigma = -k / b_post;
    let k = (nf * k + PRIOR_K_WEIGHT * 0.5) / (nf + PRIOR_K_WEIGHT);
    (k, sigma)
}

/// The generalized Pareto quantile at p ∈ (0, 1) with shape k and scale σ (ArviZ's `_gpinv`).
fn generalized_pareto_quantile(p: f64, k: f64, sigma: f64) -> f64 {
    if sigma <= 0.0 {
        return f64::NAN;
    }
    if k.abs() < f64::EPSILON {
        -sigma * (-p).ln_1p()
    } else {
        sigma * (-k * (-p).ln_1p()).exp_m1() / k
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};

    /// log N(x; 0, 1) − log N(x; 0, s²) for n draws x ~ N(0, s²).
    fn normal_from_normal(s: f64, n: usize, seed: u64) -> Vec<f64> {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        (0..n)
            .map(|_| {
                let z: f64 = StandardNormal.sample(&mut rng);
                let x = s * z;
                -0.5 * x * x + 0.5 * z * z + s.ln()
            })
            .collect()
    }

    /// The published line at the sample sizes loo's NEWS (2.7.0) tabulates for it: 0.5, 0.6,
    /// 0.67, 0.7 and the cap 0.7 at 100, 320, 1000, 2200 and 10000 draws.
    #[test]
    fn the_trusted_khat_rises_with_the_draws_to_seven_tenths() {
        for (draws, line) in [
            (100, 0.5),
            (320, 0.6),
            (1000, 0.67),
            (2200, 0.7),
            (10_000, 0.7),
        ] {
            let threshold = khat_threshold(draws);
            assert!((threshold - line).abs() < 0.005, "{draws}: {threshold}");
        }
        assert!(khat_threshold(2000) > KHAT_GOOD && khat_threshold(2000) < KHAT_UNRELIABLE);
        assert_eq!(khat_threshold(5), f64::NEG_INFINITY);
    }

    /// For q = N(0, s²) with s < 1 the weights' tail is Pareto with shape k = 1 − s² (their
    /// survival function is t^(−1/(1 − s²))): 0.91 for s = 0.3. k̂ from 2000 draws scatters
    /// widely about it (0.55–1.1 over 20 data sets in ArviZ), so the claim is on the median.
    #[test]
    fn a_wider_proposal_gives_a_small_khat_and_a_narrower_one_a_large_khat() {
        let mut narrow_khats = Vec::new();
        for seed in 0..21 {
            let wide = psis(&normal_from_normal(1.5, 2000, seed));
            assert!(wide.khat < KHAT_GOOD, "wide: k̂ = {}", wide.khat);
            assert!(wide.ess() > 1000.0, "wide: ESS {}", wide.ess());
            let narrow = psis(&normal_from_normal(0.3, 2000, seed));
            assert!(narrow.ess() < 0.5 * 2000.0, "narrow: ESS {}", narrow.ess());
            narrow_khats.push(narrow.khat);
        }
        narrow_khats.sort_by(f64::total_cmp);
        assert!(
            narrow_khats[10] > KHAT_UNRELIABLE,
            "narrow: k̂ {narrow_khats:?}"
        );
    }

    #[test]
    fn equal_weights_are_worth_every_draw_and_sum_to_one() {
        let p = psis(&[0.3; 100]);
        assert!((p.ess() - 100.0).abs() < 1e-9, "{}", p.ess());
        let total: f64 = p.weights().iter().sum();
        assert!((total - 1.0).abs() < 1e-12);
    }

    #[test]
    fn degenerate_input_gives_nan_or_infinity_not_a_panic() {
        assert!(psis(&[]).khat.is_nan());
        assert!(psis(&[0.0, f64::NAN, 1.0]).khat.is_nan());
        // Five draws leave a one-draw tail: too short to fit.
        assert_eq!(psis(&[0.0, 1.0, 2.0, 3.0, 4.0]).khat, f64::INFINITY);
        // A zero weight (−∞) is a draw outside the target's support, not an error.
        let mut lw = normal_from_normal(1.5, 500, 9);
        lw[3] = f64::NEG_INFINITY;
        let p = psis(&lw);
        assert!(p.khat.is_finite() && p.log_weights[3] == f64::NEG_INFINITY);
    }
}
