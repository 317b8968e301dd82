//! Dormand–Prince 5(4) with Hairer's step-size controller and 4th-order dense output (the
//! `dopri5` of Hairer, Nørsett & Wanner, the scheme the paper used).

use num_dual::DualNum;

use super::exact_lag::{lag_at, monomials};
use super::{OdeError, OdeSystem, SolverSettings, SolverStats};

const C2: f64 = 1.0 / 5.0;
const C3: f64 = 3.0 / 10.0;
const C4: f64 = 4.0 / 5.0;
const C5: f64 = 8.0 / 9.0;
const A21: f64 = 1.0 / 5.0;
const A31: f64 = 3.0 / 40.0;
const A32: f64 = 9.0 / 40.0;
const A41: f64 = 44.0 / 45.0;
const A42: f64 = -56.0 / 15.0;
const A43: f64 = 32.0 / 9.0;
const A51: f64 = 19372.0 / 6561.0;
const A52: f64 = -25360.0 / 2187.0;
const A53: f64 = 64448.0 / 6561.0;
const A54: f64 = -212.0 / 729.0;
const A61: f64 = 9017.0 / 3168.0;
const A62: f64 = -355.0 / 33.0;
const A63: f64 = 46732.0 / 5247.0;
const A64: f64 = 49.0 / 176.0;
const A65: f64 = -5103.0 / 18656.0;
const A71: f64 = 35.0 / 384.0;
const A73: f64 = 500.0 / 1113.0;
const A74: f64 = 125.0 / 192.0;
const A75: f64 = -2187.0 / 6784.0;
const A76: f64 = 11.0 / 84.0;
const E1: f64 = 71.0 / 57600.0;
const E3: f64 = -71.0 / 16695.0;
const E4: f64 = 71.0 / 1920.0;
const E5: f64 = -17253.0 / 339200.0;
const E6: f64 = 22.0 / 525.0;
const E7: f64 = -1.0 / 40.0;
const D1: f64 = -12715105075.0 / 11282082432.0;
const D3: f64 = 87487479700.0 / 32700410799.0;
const D4: f64 = -10690763975.0 / 1880347072.0;
const D5: f64 = 701980252875.0 / 199316789632.0;
const D6: f64 = -1453857185.0 / 822651844.0;
const D7: f64 = 69997945.0 / 29380423.0;

/// Right-hand sides a trial step evaluates: the seven stages less the first, which is the last
/// step's seventh (first same as last).
pub const RHS_PER_STEP: usize = 6;

const SAFETY: f64 = 0.9;
const MAX_GROWTH: f64 = 5.0; // per accepted step
const MAX_SHRINK: f64 = 10.0;
const BETA: f64 = 0.04; // Lund stabilisation, Hairer's default
const EXPO: f64 = 0.2 - BETA * 0.75;

struct Stages<D> {
    k: [Vec<D>; 7],
    y_stage: Vec<D>,
    y_new: Vec<D>,
    cont: [Vec<D>; 5],
}

impl<D: DualNum<Primitive = f64> + Copy> Stages<D> {
    fn new(n: usize) -> Self {
        let z = || vec![D::from(0.0); n];
        Self {
            k: std::array::from_fn(|_| z()),
            y_stage: z(),
            y_new: z(),
            cont: std::array::from_fn(|_| z()),
        }
    }
}

/// Integrates `system` from `(t0, y0)` and writes the state at each of the sorted `t_out` into
/// `out` (row-major: `out[i * n + j]` is state j at `t_out[i]`).
///
/// Samples are produced by dense output, not by landing on each: on the paper's 501 samples that
/// halves the cost. The integrator lands exactly on every breakpoint of the system.
pub fn solve<D, S>(
    system: &S,
    t0: f64,
    y0: &[D],
    t_out: &[f64],
    settings: &SolverSettings,
    out: &mut [D],
) -> Result<SolverStats, OdeError>
where
    D: DualNum<Primitive = f64> + Copy,
    S: OdeSystem<D>,
{
    let n = system.n_states();
    let mut stats = SolverStats::default();
    if out.len() != n * t_out.len() {
        return Err(OdeError::BadOutputTimes(format!(
            "output buffer holds {} values, expected {}",
            out.len(),
            n * t_out.len()
        )));
    }
    if let Some(&first) = t_out.first()
        && !(first >= t0)
    {
        return Err(OdeError::BadOutputTimes(format!(
            "first output time {first} before start {t0}"
        )));
    }
    if t_out.windows(2).any(|w| !(w[1] >= w[0])) {
        return Err(OdeError::BadOutputTimes(
            "output times are not sorted".into(),
        ));
    }
    let Some(&t_end) = t_out.last() else {
        return Ok(stats);
    };

    let breakpoints = system.breakpoints();
    let lags = system.exact_lags();
    let mut lag_polys: Vec<[D; 5]> = Vec::with_capacity(lags.len());
    let mut y: Vec<D> = y0.to_vec();
    let mut s = Stages::new(n);
    let mut next_out = 0;
    // Outputs at t0 itself are the initial state.
    while next_out < t_out.len() && t_out[next_out] <= t0 {
        out[next_out * n..(next_out + 1) * n].copy_from_slice(&y);
        next_out += 1;
    }

    let mut t = t0;
    let mut segment = breakpoints.partition_point(|&b| b <= t0);
    let mut h: Option<f64> = None;
    // ln of the previous accepted step's error: the controller works in logs, since two
    // `powf` calls per step cost as much as the right-hand side evaluations.
    let mut ln_err_old = (1e-4f64).ln();
    let mut steps = 0usize;

    while next_out < t_out.len() {
        let seg_end = breakpoints
            .get(segment)
            .copied()
            .unwrap_or(f64::INFINITY)
            .min(t_end);
        // FSAL is broken at a segment start: the right-hand side has jumped.
        system.rhs(t, segment, &y, &mut s.k[0]);
        stats.rhs_evaluations += 1;
        let mut step = match h {
            Some(h) => h,
            None => initial_step(
                system,
                t,
                segment,
                &y,
                &s.k[0],
                settings,
                seg_end - t,
                &mut stats,
            ),
        };
        let mut last_rejected = false;
        while t < seg_end {
            if steps >= settings.max_steps {
                return Err(OdeError::TooManySteps {
                    t,
                    max_steps: settings.max_steps,
                });
            }
            steps += 1;
            let remaining = seg_end - t;
            let lands = step >= remaining * (1.0 - 1e-12);
            let h_step = if lands { remaining } else { step };
            if h_step <= 1e-14 * t.abs().max(1e-300) {
                return Err(OdeError::StepSizeUnderflow { t, h: h_step });
            }
            let err = try_step(system, t, segment, h_step, &y, &mut s, settings);
            stats.rhs_evaluations += RHS_PER_STEP;
            if !err.is_finite() {
                // A blown-up trial step: shrink hard and retry; a true blow-up ends in the step
                // cap or the underflow check.
                stats.rejected_steps += 1;
                step = h_step * 0.1;
                last_rejected = true;
                continue;
            }
            let ln_err = err.max(1e-300).ln();
            let fac11 = (EXPO * ln_err).exp();
            if err <= 1.0 {
                let t_new = if lands { seg_end } else { t + h_step };
                if !s.y_new.iter().all(|v| v.re().is_finite()) {
                    return Err(OdeError::NonFinite { t: t_new });
                }
                stats.accepted_steps += 1;
                dense_coefficients(n, h_step, &y, &mut s);
                // Each exact lag's source over the step, as a polynomial in θ.
                lag_polys.clear();
                lag_polys.extend(
                    (lags.iter()).map(|l| monomials(std::array::from_fn(|j| s.cont[j][l.source]))),
                );
                while next_out < t_out.len() && t_out[next_out] <= t_new {
                    let theta = ((t_out[next_out] - t) / h_step).clamp(0.0, 1.0);
                    let row = &mut out[next_out * n..(next_out + 1) * n];
                    interpolate(n, theta, &s.cont, row);
                    for (l, poly) in lags.iter().zip(&lag_polys) {
                        row[l.state] = lag_at(y[l.state], l.tau, h_step, theta, poly);
                    }
                    next_out += 1;
                }
                for (l, poly) in lags.iter().zip(&lag_polys) {
                    s.y_new[l.state] = lag_at(y[l.state], l.tau, h_step, 1.0, poly);
                }
                std::mem::swap(&mut y, &mut s.y_new);
                s.k.swap(0, 6); // first same as last
                t = t_new;
                let mut fac = ((EXPO * ln_err - BETA * ln_err_old).exp() / SAFETY)
                    .clamp(1.0 / MAX_GROWTH, MAX_SHRINK);
                if last_rejected {
                    fac = fac.max(1.0);
                }
                ln_err_old = ln_err.max((1e-4f64).ln());
                // A step clipped to land on a breakpoint says little about the next segment's
                // scale: keep the larger of the planned and the proposed size.
                step = if lands {
                    step.max(h_step / fac)
                } else {
                    h_step / fac
                };
                last_rejected = false;
            } else {
                stats.rejected_steps += 1;
                // Hairer caps the shrink after a rejection at 5×.
                step = h_step / (fac11 / SAFETY).min(5.0);
                last_rejected = true;
            }
        }
        h = Some(step);
        if next_out < t_out.len() {
            system.at_breakpoint(segment, &mut y);
            segment += 1;
        }
    }
    Ok(stats)
}

/// One Dormand–Prince step from (t, y) with size h; k[0] holds f(t, y). Returns the scaled RMS
/// error estimate (real parts only).
fn try_step<D, S>(
    system: &S,
    t: f64,
    segment: usize,
    h: f64,
    y: &[D],
    s: &mut Stages<D>,
    settings: &SolverSettings,
) -> f64
where
    D: DualNum<Primitive = f64> + Copy,
    S: OdeSystem<D>,
{
    // The system's own count, not `y.len()`: a system whose count is a constant (the plain
    // motor's two states) lets the compiler unroll every loop below.
    let n = system.n_states();
    let [k1, k2, k3, k4, k5, k6, k7] = &mut s.k;
    let ys = &mut s.y_stage;
    for i in 0..n {
        ys[i] = y[i] + k1[i] * (h * A21);
    }
    system.rhs(t + C2 * h, segment, ys, k2);
    for i in 0..n {
        ys[i] = y[i] + (k1[i] * A31 + k2[i] * A32) * h;
    }
    system.rhs(t + C3 * h, segment, ys, k3);
    for i in 0..n {
        ys[i] = y[i] + (k1[i] * A41 + k2[i] * A42 + k3[i] * A43) * h;
    }
    system.rhs(t + C4 * h, segment, ys, k4);
    for i in 0..n {
        ys[i] = y[i] + (k1[i] * A51 + k2[i] * A52 + k3[i] * A53 + k4[i] * A54) * h;
    }
    system.rhs(t + C5 * h, segment, ys, k5);
    for i in 0..n {
        ys[i] = y[i] + (k1[i] * A61 + k2[i] * A62 + k3[i] * A63 + k4[i] * A64 + k5[i] * A65) * h;
    }
    system.rhs(t + h, segment, ys, k6);
    let yn = &mut s.y_new;
    for i in 0..n {
        yn[i] = y[i] + (k1[i] * A71 + k3[i] * A73 + k4[i] * A74 + k5[i] * A75 + k6[i] * A76) * h;
    }
    system.rhs(t + h, segment, yn, k7);
    let mut sum = 0.0;
    for i in 0..n {
        let e = h
            * (E1 * k1[i].re()
                + E3 * k3[i].re()
                + E4 * k4[i].re()
                + E5 * k5[i].re()
                + E6 * k6[i].re()
                + E7 * k7[i].re());
        let scale = settings.atol + settings.rtol * y[i].re().abs().max(yn[i].re().abs());
        sum += (e / scale).powi(2);
    }
    (sum / n as f64).sqrt()
}

// Inlined by hand: once `solve` has several instantiations the compiler stops inlining these on
// its own, and the call per step and per output costs the plain solve a fifth of its time.
#[inline(always)]
fn dense_coefficients<D: DualNum<Primitive = f64> + Copy>(
    n: usize,
    h: f64,
    y: &[D],
    s: &mut Stages<D>,
) {
    let [k1, _, k3, k4, k5, k6, k7] = &s.k;
    let [c0, c1, c2, c3, c4] = &mut s.cont;
    for i in 0..n {
        let diff = s.y_new[i] - y[i];
        let bspl = k1[i] * h - diff;
        c0[i] = y[i];
        c1[i] = diff;
        c2[i] = bspl;
        c3[i] = diff - k7[i] * h - bspl;
        c4[i] = (k1[i] * D1 + k3[i] * D3 + k4[i] * D4 + k5[i] * D5 + k6[i] * D6 + k7[i] * D7) * h;
    }
}

#[inline(always)]
fn interpolate<D: DualNum<Primitive = f64> + Copy>(
    n: usize,
    theta: f64,
    c: &[Vec<D>; 5],
    out: &mut [D],
) {
    let theta1 = 1.0 - theta;
    for i in 0..n {
        out[i] =
            c[0][i] + (c[1][i] + (c[2][i] + (c[3][i] + c[4][i] * theta1) * theta) * theta1) * theta;
    }
}

/// Hairer's starting step guess from the size of y, f(y) and a trial Euler step.
#[allow(clippy::too_many_arguments)]
fn initial_step<D, S>(
    system: &S,
    t: f64,
    segment: usize,
    y: &[D],
    f0: &[D],
    settings: &SolverSettings,
    max_h: f64,
    stats: &mut SolverStats,
) -> f64
where
    D: DualNum<Primitive = f64> + Copy,
    S: OdeSystem<D>,
{
    let n = y.len();
    let scale = |v: f64| settings.atol + settings.rtol * v.abs();
    let rms =
        |f: &dyn Fn(usize) -> f64| ((0..n).map(|i| f(i).powi(2)).sum::<f64>() / n as f64).sqrt();
    let d0 = rms(&|i| y[i].re() / scale(y[i].re()));
    let d1 = rms(&|i| f0[i].re() / scale(y[i].re()));
    let h0 = if d0 < 1e-5 || d1 < 1e-5 {
        1e-6
    } else {
        0.01 * d0 / d1
    };
    let h0 = h0.min(max_h);
    let y1: Vec<D> = (0..n).map(|i| y[i] + f0[i] * h0).collect();
    let mut f1 = vec![D::from(0.0); n];
    system.rhs(t + h0, segment, &y1, &mut f1);
    stats.rhs_evaluations += 1;
    let d2 = rms(&|i| (f1[i].re() - f0[i].re()) / scale(y[i].re())) / h0;
    let h1 = if d1.max(d2) <= 1e-15 {
        (h0 * 1e-3).max(1e-6)
    } else {
        (0.01 / d1.max(d2)).powf(0.2)
    };
    (100.0 * h0).min(h1).min(max_h)
}
