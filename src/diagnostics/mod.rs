//! Convergence diagnostics for MCMC draws: rank-normalised split-R̂, bulk and tail effective
//! sample size (ESS), Monte Carlo standard errors and a per-parameter summary.
//!
//! The method is that of Vehtari, Gelman, Simpson, Carpenter and Bürkner (2021),
//! "Rank-normalization, folding, and localization: An improved R̂ for assessing convergence of
//! MCMC", Bayesian Analysis 16(2), 667–718, <https://doi.org/10.1214/20-BA1221>. Every numerical
//! choice (how chains are split, the rank offset, which variance goes in the denominator of the
//! autocorrelation, Geyer's truncation, the `S·log10(S)` cap, the quantile definition) follows
//! ArviZ 0.23.4 (`arviz/stats/diagnostics.py`), so that results agree with `az.rhat`, `az.ess`
//! and `az.mcse` to rounding error and can be compared with the peers' published numbers.
//!
//! Draws are passed as one slice per chain (`&[Vec<f64>]`, `&[&[f64]]`, ...), all chains the same
//! length. Degenerate input never panics; it gives what ArviZ gives:
//! - fewer than 4 draws per chain, chains of unequal length, no chains, or any NaN: NaN;
//! - R-hat with fewer than 2 chains: NaN (ArviZ refuses single-chain R-hat);
//! - constant draws: R-hat is NaN (0/0 between and within variances), but ESS is the total
//!   number of (split) draws, because ArviZ short-circuits on a range below 1e-15.

mod ess;
mod fft;
mod normal;
mod psis;

pub use ess::{ess_bulk, ess_mean, ess_tail, mcse_mean, mcse_sd};
pub use fft::autocovariance;
pub use normal::inverse_normal_cdf;
pub use psis::{KHAT_GOOD, KHAT_UNRELIABLE, Psis, khat_threshold, psis, psis_with_reff};

use serde::Serialize;

use ess::{ess_bulk_of, ess_tail_of, mcse_mean_of};

/// ArviZ's `min_draws`, checked on the unsplit chains.
const MIN_DRAWS: usize = 4;
/// Blom's fractional offset for the rank back-transformation, (r − c)/(S − 2c + 1).
const BLOM_OFFSET: f64 = 3.0 / 8.0;
/// Chains × draws, row-major.
#[derive(Clone, Debug)]
struct Draws {
    n_chains: usize,
    n_draws: usize,
    data: Vec<f64>,
}

impl Draws {
    /// Copies the chains if ArviZ would accept them (`_not_valid`), else `None`.
    fn validated<C: AsRef<[f64]>>(chains: &[C], min_chains: usize) -> Option<Self> {
        let n_chains = chains.len();
        let n_draws = chains.first()?.as_ref().len();
        if n_chains < min_chains.max(1) || n_draws < MIN_DRAWS {
            return None;
        }
        let mut data = Vec::with_capacity(n_chains * n_draws);
        for chain in chains {
            let chain = chain.as_ref();
            if chain.len() != n_draws || chain.iter().any(|x| x.is_nan()) {
                return None;
            }
            data.extend_from_slice(chain);
        }
        Some(Self {
            n_chains,
            n_draws,
            data,
        })
    }

    fn rows(&self) -> impl Iterator<Item = &[f64]> {
        self.data.chunks_exact(self.n_draws.max(1))
    }

    fn map(&self, f: impl Fn(f64) -> f64) -> Self {
        Self {
            n_chains: self.n_chains,
            n_draws: self.n_draws,
            data: self.data.iter().map(|&x| f(x)).collect(),
        }
    }

    /// Split-chain view as ArviZ's `_split_chains`: the first halves of all chains, then the last
    /// halves. With an odd number of draws the middle draw of each chain is dropped, so both
    /// halves have `n_draws / 2` draws.
    fn split(&self) -> Self {
        let half = self.n_draws / 2;
        let mut data = Vec::with_capacity(2 * self.n_chains * half);
        for row in self.rows() {
            data.extend_from_slice(&row[..half]);
        }
        for row in self.rows() {
            data.extend_from_slice(&row[self.n_draws - half..]);
        }
        Self {
            n_chains: 2 * self.n_chains,
            n_draws: half,
            data,
        }
    }

    /// Rank normalisation (the paper's eq. 14): average ranks over all draws pooled, Blom's
    /// offset, then the normal quantile.
    fn z_scale(&self) -> Self {
        let ranks = average_ranks(&self.data);
        let denominator = self.data.len() as f64 - 2.0 * BLOM_OFFSET + 1.0;
        Self {
            n_chains: self.n_chains,
            n_draws: self.n_draws,
            data: ranks
                .into_iter()
                .map(|r| inverse_normal_cdf((r - BLOM_OFFSET) / denominator))
                .collect(),
        }
    }
}

/// Ranks 1..=n with ties given their average rank (scipy's `rankdata(method="average")`).
fn average_ranks(values: &[f64]) -> Vec<f64> {
    let mut order: Vec<usize> = (0..values.len()).collect();
    order.sort_by(|&a, &b| values[a].total_cmp(&values[b]));
    let mut ranks = vec![0.0; values.len()];
    let mut start = 0;
    while start < order.len() {
        let mut end = start + 1;
        // `==` rather than total_cmp so that −0.0 and 0.0 tie, as in scipy.
        while end < order.len() && values[order[end]] == values[order[start]] {
            end += 1;
        }
        let rank = 0.5 * ((start + 1 + end) as f64);
        for &i in &order[start..end] {
            ranks[i] = rank;
        }
        start = end;
    }
    ranks
}

fn mean(x: &[f64]) -> f64 {
    x.iter().sum::<f64>() / x.len() as f64
}

fn variance_ddof1(x: &[f64]) -> f64 {
    let m = mean(x);
    x.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / (x.len() as f64 - 1.0)
}

fn sorted(x: &[f64]) -> Vec<f64> {
    let mut s = x.to_vec();
    s.sort_by(f64::total_cmp);
    s
}

/// numpy's median: the mean of the two middle values for an even count.
fn median_sorted(s: &[f64]) -> f64 {
    let n = s.len();
    match n {
        0 => f64::NAN,
        _ if n % 2 == 1 => s[n / 2],
        _ => (s[n / 2 - 1] + s[n / 2]) / 2.0,
    }
}

/// Hyndman–Fan type 7 quantile of sorted data, written as scipy's
/// `mquantiles(alphap=1, betap=1)`, which ArviZ uses, so that a draw lying exactly on the
/// quantile is classified the same way in the tail-ESS indicator.
fn quantile_sorted(s: &[f64], p: f64) -> f64 {
    let n = s.len();
    match n {
        0 => f64::NAN,
        1 => s[0],
        _ => {
            // mquantiles' m = alphap + p·(1 − alphap − betap) with alphap = betap = 1.
            let m = 1.0 - p;
            let aleph = n as f64 * p + m;
            let k = aleph.clamp(1.0, (n - 1) as f64).floor() as usize;
            let gamma = (aleph - k as f64).clamp(0.0, 1.0);
            (1.0 - gamma) * s[k - 1] + gamma * s[k]
        }
    }
}

/// Python's `max(a, b)`: keeps `a` unless `b` is strictly larger, so a NaN in `a` survives.
fn py_max(a: f64, b: f64) -> f64 {
    if b > a { b } else { a }
}

/// Python's `min(a, b)`, with the same NaN behaviour as [`py_max`].
fn py_min(a: f64, b: f64) -> f64 {
    if b < a { b } else { a }
}

/// Classic potential scale reduction on already split (and possibly rank-normalised) chains,
/// ArviZ's `_rhat`.
fn rhat_core(draws: &Draws) -> f64 {
    let n = draws.n_draws as f64;
    let chain_means: Vec<f64> = draws.rows().map(mean).collect();
    let chain_vars: Vec<f64> = draws.rows().map(variance_ddof1).collect();
    let between = n * variance_ddof1(&chain_means);
    let within = mean(&chain_vars);
    ((between / within + n - 1.0) / n).sqrt()
}

fn rhat_of(draws: &Draws) -> f64 {
    let split = draws.split();
    let bulk = rhat_core(&split.z_scale());
    let med = median_sorted(&sorted(&split.data));
    let folded = split.map(|x| (x - med).abs());
    let tail = rhat_core(&folded.z_scale());
    py_max(bulk, tail)
}

/// Rank-normalised split-R̂: the larger of the bulk R̂ (on rank-normalised split chains) and the
/// tail R̂ (on rank-normalised split chains folded about their median), per Vehtari et al.
/// (2021), §4, exactly as ArviZ 0.23.4's `az.rhat(method="rank")`.
///
/// NaN with fewer than 2 chains, fewer than 4 draws, unequal chain lengths or any NaN draw, and
/// for constant draws.
pub fn rhat<C: AsRef<[f64]>>(chains: &[C]) -> f64 {
    Draws::validated(chains, 2).map_or(f64::NAN, |d| rhat_of(&d))
}

/// One row of a posterior summary table.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ParameterSummary {
    pub name: String,
    /// Pooled mean over all chains.
    pub mean: f64,
    /// Pooled sample sd (divisor S − 1).
    pub sd: f64,
    /// Pooled 5 %, 50 % and 95 % quantiles (type 7, linear interpolation).
    pub q05: f64,
    pub q50: f64,
    pub q95: f64,
    /// The 95% interval beside the 90% one.
    pub q025: f64,
    pub q975: f64,
    pub mcse_mean: f64,
    pub ess_bulk: f64,
    pub ess_tail: f64,
    pub rhat: f64,
}

/// Summary statistics and convergence diagnostics of one scalar parameter: [`mcse_mean`],
/// [`ess_bulk`], [`ess_tail`] and [`rhat`] as ArviZ 0.23.4 computes them (Vehtari et al. 2021).
///
/// The plain statistics (mean, sd, quantiles) are computed whenever there is at least one draw
/// and no NaN, even when the diagnostics are NaN for lack of draws or chains.
pub fn summarize<C: AsRef<[f64]>>(name: impl Into<String>, chains: &[C]) -> ParameterSummary {
    let pooled: Vec<f64> = chains
        .iter()
        .flat_map(|c| c.as_ref().iter().copied())
        .collect();
    let usable = !pooled.is_empty() && !pooled.iter().any(|x| x.is_nan());
    let s = if usable { sorted(&pooled) } else { Vec::new() };
    let (mean_value, sd) = if usable {
        (mean(&pooled), variance_ddof1(&pooled).sqrt())
    } else {
        (f64::NAN, f64::NAN)
    };
    let any = Draws::validated(chains, 1);
    let diag = |f: fn(&Draws) -> f64| any.as_ref().map_or(f64::NAN, f);
    let rhat_value = match &any {
        Some(d) if d.n_chains >= 2 => rhat_of(d),
        _ => f64::NAN,
    };
    ParameterSummary {
        name: name.into(),
        mean: mean_value,
        sd,
        q05: quantile_sorted(&s, 0.05),
        q50: quantile_sorted(&s, 0.5),
        q95: quantile_sorted(&s, 0.95),
        q025: quantile_sorted(&s, 0.025),
        q975: quantile_sorted(&s, 0.975),
        mcse_mean: diag(mcse_mean_of),
        ess_bulk: diag(ess_bulk_of),
        ess_tail: diag(ess_tail_of),
        rhat: rhat_value,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, StandardNormal};

    fn normal_chains(n_chains: usize, n_draws: usize, seed: u64) -> Vec<Vec<f64>> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        (0..n_chains)
            .map(|_| {
                (0..n_draws)
                    .map(|_| StandardNormal.sample(&mut rng))
                    .collect()
            })
            .collect()
    }

    fn ar1_chains(n_chains: usize, n_draws: usize, phi: f64, seed: u64) -> Vec<Vec<f64>> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let innovation_sd = (1.0 - phi * phi).sqrt();
        (0..n_chains)
            .map(|_| {
                // Start in the stationary distribution so no warm-up is needed.
                let mut x: f64 = StandardNormal.sample(&mut rng);
                (0..n_draws)
                    .map(|_| {
                        let e: f64 = StandardNormal.sample(&mut rng);
                        x = phi * x + innovation_sd * e;
                        x
                    })
                    .collect()
            })
            .collect()
    }

    fn within(value: f64, target: f64, rel: f64) -> bool {
        (value - target).abs() <= rel * target
    }

    #[test]
    fn iid_normal_draws() {
        let chains = normal_chains(4, 5000, 1);
        let n = 20_000.0;
        for (what, ess) in [
            ("bulk", ess_bulk(&chains)),
            ("tail", ess_tail(&chains)),
            ("mean", ess_mean(&chains)),
        ] {
            assert!(within(ess, n, 0.15), "{what} ESS {ess} vs {n}");
        }
        let r = rhat(&chains);
        assert!(r < 1.01 && r > 0.99, "rhat {r}");
        let mcse = mcse_mean(&chains);
        assert!(within(mcse, 1.0 / n.sqrt(), 0.15), "mcse_mean {mcse}");
        // sd(x)² has variance 2 for N(0, 1), so MCSE(sd) ≈ sqrt(2 / n / 4).
        let mcse_s = mcse_sd(&chains);
        assert!(within(mcse_s, (0.5 / n).sqrt(), 0.15), "mcse_sd {mcse_s}");
    }

    #[test]
    fn ar1_bulk_ess() {
        let phi = 0.9;
        let chains = ar1_chains(4, 20_000, phi, 2);
        let n = 80_000.0;
        let expected = n * (1.0 - phi) / (1.0 + phi);
        let ess = ess_bulk(&chains);
        assert!(within(ess, expected, 0.25), "bulk ESS {ess} vs {expected}");
        let ess = ess_mean(&chains);
        assert!(within(ess, expected, 0.25), "mean ESS {ess} vs {expected}");
    }

    #[test]
    fn shifted_chains_have_large_rhat() {
        let mut chains = normal_chains(4, 1000, 3);
        for (c, chain) in chains.iter_mut().enumerate() {
            chain.iter_mut().for_each(|x| *x += c as f64);
        }
        let r = rhat(&chains);
        assert!(r > 1.1, "rhat {r}");
    }

    #[test]
    fn wider_chain_is_caught_by_the_folded_rhat() {
        // Same location, different scale: invisible to the bulk R-hat, visible to the tail one.
        let mut chains = normal_chains(4, 2000, 4);
        chains[0].iter_mut().for_each(|x| *x *= 3.0);
        let split = Draws::validated(&chains, 2).unwrap().split();
        let bulk = rhat_core(&split.z_scale());
        let r = rhat(&chains);
        assert!(bulk < 1.05, "bulk {bulk}");
        assert!(r > 1.1, "rhat {r}");
    }

    #[test]
    fn odd_length_drops_the_middle_draw() {
        let chains = normal_chains(3, 101, 5);
        let trimmed: Vec<Vec<f64>> = chains
            .iter()
            .map(|c| c[..50].iter().chain(&c[51..]).copied().collect())
            .collect();
        assert_eq!(rhat(&chains), rhat(&trimmed));
        assert_eq!(ess_bulk(&chains), ess_bulk(&trimmed));
        assert_eq!(ess_mean(&chains), ess_mean(&trimmed));
    }

    #[test]
    fn ranks_average_ties() {
        assert_eq!(
            average_ranks(&[3.0, 1.0, 3.0, 2.0, -0.0, 0.0]),
            vec![5.5, 3.0, 5.5, 4.0, 1.5, 1.5]
        );
    }

    #[test]
    fn quantile_is_type_7() {
        let s = [1.0, 2.0, 3.0, 4.0, 10.0];
        assert_eq!(quantile_sorted(&s, 0.0), 1.0);
        assert_eq!(quantile_sorted(&s, 0.5), 3.0);
        assert_eq!(quantile_sorted(&s, 1.0), 10.0);
        assert!((quantile_sorted(&s, 0.9) - 7.6).abs() < 1e-12);
        assert!((quantile_sorted(&s, 0.05) - 1.2).abs() < 1e-12);
    }

    #[test]
    fn accepts_slices_of_slices() {
        let chains = normal_chains(2, 100, 6);
        let views: Vec<&[f64]> = chains.iter().map(Vec::as_slice).collect();
        assert_eq!(rhat(&chains), rhat(&views));
        assert_eq!(ess_tail(&chains), ess_tail(&views));
    }

    #[test]
    fn degenerate_input_does_not_panic() {
        let constant = vec![vec![2.5; 100]; 4];
        assert!(rhat(&constant).is_nan());
        // ArviZ short-circuits constant draws to ESS = S rather than NaN.
        assert_eq!(ess_bulk(&constant), 400.0);
        assert_eq!(ess_tail(&constant), 400.0);
        assert_eq!(mcse_mean(&constant), 0.0);
        assert!(mcse_sd(&constant).is_nan());

        let short = vec![vec![1.0, 2.0, 3.0]; 4];
        let empty: Vec<Vec<f64>> = Vec::new();
        let no_draws = vec![Vec::<f64>::new(); 3];
        let ragged = vec![vec![1.0, 2.0, 3.0, 4.0, 5.0], vec![1.0, 2.0, 3.0, 4.0]];
        let mut with_nan = normal_chains(2, 50, 7);
        with_nan[1][10] = f64::NAN;
        for chains in [&short, &empty, &no_draws, &ragged, &with_nan] {
            assert!(rhat(chains).is_nan());
            assert!(ess_bulk(chains).is_nan());
            assert!(ess_tail(chains).is_nan());
            assert!(ess_mean(chains).is_nan());
            assert!(mcse_mean(chains).is_nan());
            assert!(mcse_sd(chains).is_nan());
            let s = summarize("x", chains);
            assert!(s.rhat.is_nan() && s.ess_bulk.is_nan() && s.mcse_mean.is_nan());
        }

        let single = normal_chains(1, 400, 8);
        assert!(rhat(&single).is_nan());
        assert!(ess_bulk(&single).is_finite());
        let s = summarize("x", &single);
        assert!(s.rhat.is_nan() && s.ess_bulk.is_finite());

        let minimal = normal_chains(2, 4, 9);
        assert!(rhat(&minimal).is_finite());
        assert!(ess_bulk(&minimal).is_finite());
    }

    #[test]
    fn summary_agrees_with_the_functions() {
        let chains = ar1_chains(3, 2001, 0.5, 10);
        let s = summarize("theta", &chains);
        assert_eq!(s.name, "theta");
        assert_eq!(s.rhat, rhat(&chains));
        assert_eq!(s.ess_bulk, ess_bulk(&chains));
        assert_eq!(s.ess_tail, ess_tail(&chains));
        assert_eq!(s.mcse_mean, mcse_mean(&chains));
        assert!(s.q05 < s.q50 && s.q50 < s.q95);
        assert!(s.mean.abs() < 0.1 && (s.sd - 1.0).abs() < 0.1);
        let json = serde_json::to_value(&s).unwrap();
        assert_eq!(json["name"], "theta");
        assert!(json["ess_tail"].is_number());
    }
}
