//! Autocovariance by FFT.
//!
//! ESS needs the autocovariance at every lag of every (split) chain; chains can be 40 000 draws
//! long, so the direct O(n²) sum is out of the question. A radix-2 transform zero-padded to at
//! least 2n gives the linear (not circular) autocovariance, as ArviZ's `autocov` does with
//! `next_fast_len(2n)`; only rounding differs. The transform is rustfft's.

use rustfft::FftPlanner;
use rustfft::num_complex::Complex;

/// Biased (divisor n) autocovariance at lags 0..n of each row, averaged over rows.
///
/// All rows must have the same length. Rows are transformed two at a time, one as the real and
/// one as the imaginary part, which halves the work: split chains always come in pairs.
pub(super) fn mean_autocovariance(rows: &[&[f64]]) -> Vec<f64> {
    let Some(n) = rows.first().map(|r| r.len()) else {
        return Vec::new();
    };
    if n == 0 {
        return Vec::new();
    }
    let m = (2 * n).next_power_of_two();
    let mut planner = FftPlanner::<f64>::new();
    let forward = planner.plan_fft_forward(m);
    let inverse = planner.plan_fft_inverse(m);
    let mut sum = vec![0.0; n];
    let mut buf = vec![Complex::default(); m];
    let mut power = vec![Complex::default(); m];

    for pair in rows.chunks(2) {
        let a = pair[0];
        let b = pair.get(1).copied();
        let mean_a = mean(a);
        let mean_b = b.map_or(0.0, mean);
        buf.fill(Complex::default());
        for (i, slot) in buf.iter_mut().take(n).enumerate() {
            slot.re = a[i] - mean_a;
            slot.im = b.map_or(0.0, |b| b[i] - mean_b);
        }
        forward.process(&mut buf);
        // Untangle the two real spectra, A_k = (Z_k + conj Z_{m-k})/2 and
        // B_k = (Z_k − conj Z_{m-k})/(2i); |A|² and |B|² are even and real, so a single inverse
        // transform of |A|² + i|B|² returns both autocovariances, one per component.
        for k in 0..m {
            let z = buf[k];
            let zc = buf[(m - k) % m].conj();
            let spec_a = Complex::new(0.5 * (z.re + zc.re), 0.5 * (z.im + zc.im));
            let spec_b = Complex::new(0.5 * (z.im - zc.im), -0.5 * (z.re - zc.re));
            power[k] = Complex::new(spec_a.norm_sqr(), spec_b.norm_sqr());
        }
        inverse.process(&mut power);
        let scale = 1.0 / (m as f64 * n as f64);
        for (t, s) in sum.iter_mut().enumerate() {
            *s += power[t].re * scale;
            if b.is_some() {
                *s += power[t].im * scale;
            }
        }
    }
    let rows_f = rows.len() as f64;
    sum.iter_mut().for_each(|s| *s /= rows_f);
    sum
}

/// Biased autocovariance estimate `γ̂_t = (1/n) Σ_{i<n−t} (x_i − x̄)(x_{i+t} − x̄)` at every lag
/// `t = 0..n`, as ArviZ's `autocov`, computed by FFT in O(n log n).
pub fn autocovariance(series: &[f64]) -> Vec<f64> {
    mean_autocovariance(&[series])
}

fn mean(x: &[f64]) -> f64 {
    x.iter().sum::<f64>() / x.len() as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    fn direct(x: &[f64]) -> Vec<f64> {
        let n = x.len();
        let m = mean(x);
        (0..n)
            .map(|t| (0..n - t).map(|i| (x[i] - m) * (x[i + t] - m)).sum::<f64>() / n as f64)
            .collect()
    }

    fn series(n: usize, seed: u64) -> Vec<f64> {
        let mut state = seed;
        let mut value = 0.0;
        (0..n)
            .map(|_| {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                let u = (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
                value = 0.7 * value + u + 3.0;
                value
            })
            .collect()
    }

    #[test]
    fn matches_direct_sum() {
        for n in [1, 2, 3, 5, 8, 37, 64, 101] {
            let x = series(n, 0x9e37_79b9_7f4a_7c15 + n as u64);
            let fast = autocovariance(&x);
            let slow = direct(&x);
            assert_eq!(fast.len(), n);
            for (f, s) in fast.iter().zip(&slow) {
                assert!((f - s).abs() <= 1e-10, "n = {n}: {f} vs {s}");
            }
        }
    }

    #[test]
    fn paired_rows_match_single_rows() {
        let rows: Vec<Vec<f64>> = (0..5).map(|c| series(53, 17 + c)).collect();
        let refs: Vec<&[f64]> = rows.iter().map(Vec::as_slice).collect();
        let mean_fast = mean_autocovariance(&refs);
        let direct_rows: Vec<Vec<f64>> = rows.iter().map(|r| direct(r)).collect();
        for (t, fast) in mean_fast.iter().enumerate() {
            let expected = direct_rows.iter().map(|d| d[t]).sum::<f64>() / 5.0;
            assert!((fast - expected).abs() <= 1e-10);
        }
    }

    #[test]
    fn empty_input() {
        assert!(autocovariance(&[]).is_empty());
        assert!(mean_autocovariance(&[]).is_empty());
    }
}
