//! Effective sample sizes (bulk, tail, for the mean) and Monte Carlo standard errors, on the
//! split chains that [`Draws`] makes: Geyer's initial monotone sequence over FFT
//! autocovariances, as ArviZ 0.23.4 computes it.

use super::{Draws, fft, mean, py_max, py_min, quantile_sorted, sorted, variance_ddof1};

/// ArviZ's `np.finfo(float).resolution`: below this range, draws count as constant.
const CONSTANT_RANGE: f64 = 1e-15;
/// Quantiles whose indicator ESS defines the tail ESS.
const TAIL_PROBS: (f64, f64) = (0.05, 0.95);

/// ESS of already split chains by Geyer's initial monotone sequence estimator, ArviZ's `_ess`.
///
/// Autocorrelations are normalised by the pooled variance estimate `var_plus` (within plus
/// between chains, the paper's eq. 10), not by the within-chain variance alone, so that
/// disagreement between chains lowers the ESS.
fn ess_core(draws: &Draws) -> f64 {
    let (n_chain, n_draw) = (draws.n_chains, draws.n_draws);
    if n_chain == 0 || n_draw < 2 || draws.data.iter().any(|x| x.is_nan()) {
        return f64::NAN;
    }
    let size = (n_chain * n_draw) as f64;
    let (lo, hi) = draws
        .data
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| {
            (lo.min(x), hi.max(x))
        });
    if hi - lo < CONSTANT_RANGE {
        return size;
    }

    let rows: Vec<&[f64]> = draws.rows().collect();
    let acov = fft::mean_autocovariance(&rows);
    let n = n_draw as f64;
    let mean_var = acov[0] * n / (n - 1.0);
    let mut var_plus = mean_var * (n - 1.0) / n;
    if n_chain > 1 {
        let chain_means: Vec<f64> = rows.iter().map(|r| mean(r)).collect();
        var_plus += variance_ddof1(&chain_means);
    }
    let rho = |t: usize| 1.0 - (mean_var - acov[t]) / var_plus;

    let mut rho_hat = vec![0.0; n_draw];
    let mut rho_even = 1.0;
    rho_hat[0] = rho_even;
    let mut rho_odd = rho(1);
    rho_hat[1] = rho_odd;

    // Geyer's initial positive sequence: sum autocorrelation pairs while their sum is positive.
    let mut t = 1;
    while t + 3 < n_draw && rho_even + rho_odd > 0.0 {
        rho_even = rho(t + 1);
        rho_odd = rho(t + 2);
        if rho_even + rho_odd >= 0.0 {
            rho_hat[t + 1] = rho_even;
            rho_hat[t + 2] = rho_odd;
        }
        t += 2;
    }
    // `t ≥ 1`, so the last kept lag `max_t = t − 2` is ≥ −1; `first_out = max_t + 1 ≥ 0`.
    let first_out = t - 1;
    // A positive even term past the truncation point still carries information (Stan and ArviZ
    // add it with weight one).
    if rho_even > 0.0 {
        rho_hat[first_out] = rho_even;
    }

    // Geyer's initial monotone sequence: pair sums must not increase.
    let mut t = 1;
    while t + 2 < first_out {
        let previous = rho_hat[t - 1] + rho_hat[t];
        if rho_hat[t + 1] + rho_hat[t + 2] > previous {
            rho_hat[t + 1] = previous / 2.0;
            rho_hat[t + 2] = rho_hat[t + 1];
        }
        t += 2;
    }

    let kept: f64 = rho_hat[..first_out].iter().sum();
    let tail = rho_hat.get(first_out).copied().unwrap_or(0.0);
    let tau_hat = -1.0 + 2.0 * kept + tail;
    // Caps the ESS at S·log10(S): antithetic chains could otherwise report absurd values.
    let tau_hat = py_max(tau_hat, 1.0 / size.log10());
    if rho_hat.iter().any(|r| r.is_nan()) {
        return f64::NAN;
    }
    size / tau_hat
}

/// ESS of the indicator `x ≤ q_p`, with `q_p` the pooled type-7 quantile (ArviZ's
/// `_ess_quantile`).
fn ess_quantile_indicator(draws: &Draws, sorted_all: &[f64], p: f64) -> f64 {
    let q = quantile_sorted(sorted_all, p);
    let indicator = draws.map(|x| if x <= q { 1.0 } else { 0.0 });
    ess_core(&indicator.split())
}

pub(super) fn ess_bulk_of(draws: &Draws) -> f64 {
    ess_core(&draws.split().z_scale())
}

pub(super) fn ess_tail_of(draws: &Draws) -> f64 {
    let s = sorted(&draws.data);
    py_min(
        ess_quantile_indicator(draws, &s, TAIL_PROBS.0),
        ess_quantile_indicator(draws, &s, TAIL_PROBS.1),
    )
}

pub(super) fn mcse_mean_of(draws: &Draws) -> f64 {
    let ess = ess_core(&draws.split());
    variance_ddof1(&draws.data).sqrt() / ess.sqrt()
}

/// Bulk effective sample size: ESS of the rank-normalised split chains (Vehtari et al. 2021,
/// §4.2), as ArviZ 0.23.4's `az.ess(method="bulk")`. Capped at `S·log10(S)` for `S` draws.
///
/// NaN with fewer than 4 draws, unequal chain lengths or any NaN draw; `S` for constant draws.
pub fn ess_bulk<C: AsRef<[f64]>>(chains: &[C]) -> f64 {
    Draws::validated(chains, 1).map_or(f64::NAN, |d| ess_bulk_of(&d))
}

/// Tail effective sample size: the smaller ESS of the split-chain indicators `x ≤ q_0.05` and
/// `x ≤ q_0.95` (Vehtari et al. 2021, §4.3), as ArviZ 0.23.4's `az.ess(method="tail")`.
///
/// Degenerate input as [`ess_bulk`].
pub fn ess_tail<C: AsRef<[f64]>>(chains: &[C]) -> f64 {
    Draws::validated(chains, 1).map_or(f64::NAN, |d| ess_tail_of(&d))
}

/// ESS for the mean: split chains without rank normalisation (Vehtari et al. 2021, §3.2), as
/// ArviZ 0.23.4's `az.ess(method="mean")`. Only meaningful when the variance is finite.
///
/// Degenerate input as [`ess_bulk`].
pub fn ess_mean<C: AsRef<[f64]>>(chains: &[C]) -> f64 {
    Draws::validated(chains, 1).map_or(f64::NAN, |d| ess_core(&d.split()))
}

/// Monte Carlo standard error of the posterior mean, `sd / sqrt(ess_mean)` with the pooled
/// sample sd (divisor S − 1), as ArviZ 0.23.4's `az.mcse(method="mean")` (Vehtari et al. 2021).
///
/// NaN on degenerate input as [`ess_bulk`]; 0 for constant draws.
pub fn mcse_mean<C: AsRef<[f64]>>(chains: &[C]) -> f64 {
    Draws::validated(chains, 1).map_or(f64::NAN, |d| mcse_mean_of(&d))
}

/// Monte Carlo standard error of the posterior sd by the delta method on the centred squares
/// `(x − x̄)²` (Vehtari et al. 2021, as in Stan's `posterior` package and ArviZ 0.23's
/// `az.mcse(method="sd")`): `sqrt(Var̂[(x − x̄)²] / ESS / (4·E[(x − x̄)²]))`, with the ESS of the
/// split squares.
///
/// NaN on degenerate input as [`ess_bulk`], and for constant draws.
pub fn mcse_sd<C: AsRef<[f64]>>(chains: &[C]) -> f64 {
    let Some(d) = Draws::validated(chains, 1) else {
        return f64::NAN;
    };
    let centre = mean(&d.data);
    let squares = d.map(|x| (x - centre) * (x - centre));
    let ess = ess_core(&squares.split());
    let e_var = mean(&squares.data);
    let e_var2 = squares.data.iter().map(|s| s * s).sum::<f64>() / squares.data.len() as f64;
    let var_var = (e_var2 - e_var * e_var) / ess;
    (var_var / e_var / 4.0).sqrt()
}
