//! Cubic B-splines on uniform knots over [0, T]: a discrepancy basis for long records. A
//! Legendre polynomial of degree K resolves K/2 wiggles over the whole record, which suits a
//! 0.5-s start-up and not 25 s of back-and-forth motion; a spline's functions are local (each
//! lives on four knot spans), so δ can change where the record does and stay put elsewhere, at
//! a cost that grows with the record's length instead of its degree.

use super::DiscrepancyBasis;

/// K + 1 functions (K ≥ 3) on K − 2 equal spans, clamped at both ends.
#[derive(Clone, Debug, PartialEq)]
pub struct BSpline {
    pub degree: usize,
    pub t_end: f64,
    /// 1 / RMS of each function over [0, T]: every function is scaled to unit mean square,
    /// like the orthonormal Legendre basis, so that one coefficient prior means the same
    /// amplitude in either basis.
    scale: Vec<f64>,
}

/// The fewest functions: one cubic span.
pub const MIN_BSPLINE_DEGREE: usize = 3;
/// The most: a 25-s record with spans of 0.1 s has 250.
pub const MAX_BSPLINE_DEGREE: usize = 1000;

impl BSpline {
    pub fn new(degree: usize, t_end: f64) -> Result<Self, String> {
        if !(MIN_BSPLINE_DEGREE..=MAX_BSPLINE_DEGREE).contains(&degree) {
            return Err(format!(
                "a B-spline basis takes a degree K between {MIN_BSPLINE_DEGREE} and \
                 {MAX_BSPLINE_DEGREE} (K + 1 functions), not {degree}"
            ));
        }
        if !(t_end > 0.0 && t_end.is_finite()) {
            return Err(format!(
                "the recording must end after t = 0 (last time {t_end})"
            ));
        }
        let mut basis = Self {
            degree,
            t_end,
            scale: vec![1.0; degree + 1],
        };
        // Mean squares by the midpoint rule, 64 points per span (exact to ~1e-4 for cubics).
        let points = 64 * basis.spans();
        let mut sums = vec![0.0; degree + 1];
        let mut row = vec![0.0; degree + 1];
        for i in 0..points {
            basis.evaluate((i as f64 + 0.5) * t_end / points as f64, &mut row);
            for (s, v) in sums.iter_mut().zip(&row) {
                *s += v * v;
            }
        }
        basis.scale = sums.iter().map(|s| (points as f64 / s).sqrt()).collect();
        Ok(basis)
    }

    fn spans(&self) -> usize {
        self.degree - 2
    }
}

impl DiscrepancyBasis for BSpline {
    fn describe(&self) -> String {
        format!("bspline(K={})", self.degree)
    }

    fn n_functions(&self) -> usize {
        self.degree + 1
    }

    fn evaluate(&self, t: f64, out: &mut [f64]) {
        out.iter_mut().for_each(|v| *v = 0.0);
        let spans = self.spans();
        let h = self.t_end / spans as f64;
        let x = (t / h).clamp(0.0, spans as f64);
        let span = (x.floor() as usize).min(spans - 1);
        // Knot i of the clamped vector (three repeated knots at each end), in span units.
        let knot = |i: isize| (i - 3).clamp(0, spans as isize) as f64;
        // Cox–de Boor on the four functions alive on `span` (functions span..=span+3).
        let mut n = [0.0f64; 4];
        n[0] = 1.0;
        for p in 1..=3usize {
            let mut next = [0.0f64; 4];
            for (r, slot) in next.iter_mut().enumerate().take(p + 1) {
                // Function index j = span + 3 − p + r over knots j..j+p+1.
                let j = (span + 3 - p + r) as isize;
                let left = if r > 0 {
                    let (a, b) = (knot(j), knot(j + p as isize));
                    if b > a {
                        (x - a) / (b - a) * n[r - 1]
                    } else {
                        0.0
                    }
                } else {
                    0.0
                };
                let right = if r < p {
                    let (a, b) = (knot(j + 1), knot(j + p as isize + 1));
                    if b > a { (b - x) / (b - a) * n[r] } else { 0.0 }
                } else {
                    0.0
                };
                *slot = left + right;
            }
            n = next;
        }
        for (r, v) in n.iter().enumerate() {
            out[span + r] = v * self.scale[span + r];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_unscaled_splines_are_a_partition_of_unity() {
        let basis = BSpline::new(12, 25.0).unwrap();
        let mut row = vec![0.0; 13];
        for i in 0..=1000 {
            let t = i as f64 * 0.025;
            basis.evaluate(t, &mut row);
            let sum: f64 = row.iter().zip(&basis.scale).map(|(v, s)| v / s).sum();
            assert!((sum - 1.0).abs() < 1e-12, "t = {t}: {sum}");
            assert!(row.iter().all(|v| *v >= 0.0));
        }
    }

    #[test]
    fn each_function_has_unit_mean_square_and_local_support() {
        let basis = BSpline::new(9, 2.0).unwrap();
        let n = 70_000;
        let times: Vec<f64> = (0..n).map(|i| (i as f64 + 0.5) * 2.0 / n as f64).collect();
        let b = basis.matrix(&times);
        for j in 0..10 {
            let ms = b.column(j).norm_squared() / n as f64;
            assert!((ms - 1.0).abs() < 1e-3, "function {j}: {ms}");
        }
        // Seven spans of 2/7 s: function 0 lives on the first span only.
        assert_eq!(b[(n - 1, 0)], 0.0);
        assert!(BSpline::new(2, 1.0).is_err());
    }
}
