//! The frequency grid the verdict's oscillation search runs over on a record, and what a
//! frequency started at the best of it pays. Shared by the verdict (`discover::unexplained`)
//! and the generator's oracle (`cases`), which must score a searched frequency as `diagnose`
//! does; here, below both, so that neither imports the other.

/// Frequencies searched at most (the grid's step grows beyond it on long records).
const MAX_FREQUENCIES: usize = 2048;
/// Grid points per 1/T (the Fourier spacing): four, so that a peak between two Fourier
/// frequencies loses little before refinement.
const OVERSAMPLING: f64 = 4.0;

/// The lowest frequency an oscillation is told from a trend at, on a record of `span` seconds:
/// two periods over it (below, it is the polynomial's).
pub fn lowest_frequency_over(span: f64) -> f64 {
    2.0 / span
}

/// The Nyquist frequency of `n` samples evenly over `span` seconds: above it a sampled sinusoid
/// is the alias of a slower one.
pub fn nyquist_over(span: f64, n: usize) -> f64 {
    let dt = span / (n - 1).max(1) as f64;
    0.5 / dt
}

/// What a term whose frequency started at the best of a grid of `frequencies` points pays on
/// top of its score's ½·ln N per parameter: the frequency's look-elsewhere cost, ln G, *in
/// place of* its ½·ln N, as this search's sinusoid pays it (ln G for the frequency, ½·ln N for
/// each coefficient). Charging both counted the frequency twice: under a prior uniform over the
/// searched band the frequency's Occam factor is ln(band / (√(2π)·σ_f)), and with σ_f of a
/// sinusoid gaining 15 nats on 501 samples over 0.5 s (about 0.2 Hz) that is ln 990 over the
/// 4–500 Hz band — the grid's ln G (992 points at four per Fourier spacing), not ln G + ½·ln N.
/// Never below zero: a grid coarser than √N points costs the frequency its ½·ln N still.
/// `observations`: the N of the scores.
pub fn frequency_search_cost(frequencies: usize, observations: usize) -> f64 {
    let ln_n = (observations.max(1) as f64).ln();
    ((frequencies.max(1) as f64).ln() - 0.5 * ln_n).max(0.0)
}

/// How many frequencies the search runs over on a record of `n` samples spanning `span`
/// seconds: the G whose logarithm a frequency started from it pays (`frequency_search_cost`).
pub fn searched_frequencies(span: f64, n: usize) -> usize {
    grid_over(span, n).0.len()
}

/// The frequency grid of a record of `n` samples over `span` seconds, its spacing and its
/// lowest frequency.
pub fn grid_over(span: f64, n: usize) -> (Vec<f64>, f64, f64) {
    let nyquist = nyquist_over(span, n);
    let f_min = lowest_frequency_over(span);
    let step = (1.0 / (OVERSAMPLING * span)).max((nyquist - f_min) / MAX_FREQUENCIES as f64);
    let grid = (0..)
        .map(|k| f_min + k as f64 * step)
        .take_while(|&f| f < nyquist)
        .collect();
    (grid, step, f_min)
}
