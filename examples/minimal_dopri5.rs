//! A minimal, independent Dormand–Prince 5(4) for the paper's motor, timed side by side with
//! the crate's solve and log density + gradient at K = 9 in the same process: the yardstick of
//! what the integration itself should cost. Nothing of `motorcal::ode`, `forward` or `bayes` is
//! used on the minimal side; the crate only supplies the data and its own figures.
//!
//! The scheme: Hairer's coefficients and continuous extension (dopri5.f), FSAL, Hairer's initial
//! step, his PI step-size controller (β = 0.04, safety 0.9, factors 0.2–10), RMS error norm on
//! real parts, rtol = atol = 1e-8, the 501 outputs from the continuous extension; dG/dR from one
//! solve over `Dual64`.
//!
//! `cargo run --release --example minimal_dopri5`

// Index loops over parallel arrays read closer to the formulas, as in the library.
#![allow(clippy::needless_range_loop)]
use std::time::Instant;

use motorcal::bayes::ModelSettings;
use motorcal::density::LogDensity;
use motorcal::study::Problem;
use num_dual::{Dual64, DualNum};

// The right-hand side is autonomous (constant voltage): the nodes c_i are not needed.
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

/// The paper's simulation model (φ = 0.9), eqs. 3–4, constant voltage.
struct Motor<D> {
    r: D,
    c_m: f64,
    c_g: f64,
    u: f64,
    d: f64,
    l: f64,
    j: f64,
}

type Y<D> = [D; 2];

impl<D: DualNum<Primitive = f64> + Copy> Motor<D> {
    fn rhs(&self, y: &Y<D>) -> Y<D> {
        let (i, w) = (y[0], y[1]);
        [
            (-(self.r * i) - w * self.c_m + self.u) / self.l,
            (i * self.c_g - w * self.d) / self.j,
        ]
    }
}

fn axpy<D: DualNum<Primitive = f64> + Copy>(y: &Y<D>, terms: &[(f64, &Y<D>)], h: f64) -> Y<D> {
    let mut out = *y;
    for (a, k) in terms {
        for n in 0..2 {
            out[n] += k[n] * (a * h);
        }
    }
    out
}

#[derive(Default, Debug, Clone, Copy)]
struct Stats {
    accepted: usize,
    rejected: usize,
}

/// Solves from y = 0 at t = 0 and writes the state at each of `times` (increasing) into
/// `out[c * M + i]`.
fn solve<D: DualNum<Primitive = f64> + Copy>(
    motor: &Motor<D>,
    times: &[f64],
    out: &mut [D],
    tol: f64,
) -> Stats {
    let (rtol, atol) = (tol, tol);
    let m = times.len();
    let t_end = *times.last().expect("outputs");
    let mut t = 0.0;
    let mut y: Y<D> = [D::from(0.0); 2];
    let mut k1 = motor.rhs(&y);
    let sk = |y0: f64, y1: f64| atol + rtol * y0.abs().max(y1.abs());
    // Hairer's initial step (HINIT, order 5).
    let mut h = {
        let (mut dnf, mut dny) = (0.0, 0.0);
        for n in 0..2 {
            let s = sk(y[n].re(), 0.0);
            dnf += (k1[n].re() / s).powi(2);
            dny += (y[n].re() / s).powi(2);
        }
        let mut h = if dnf <= 1e-10 || dny <= 1e-10 {
            1e-6
        } else {
            (dny / dnf).sqrt() * 0.01
        };
        h = h.min(t_end);
        let y1 = axpy(&y, &[(1.0, &k1)], h);
        let f1 = motor.rhs(&y1);
        let mut der2 = 0.0;
        for n in 0..2 {
            der2 += ((f1[n].re() - k1[n].re()) / sk(y[n].re(), 0.0)).powi(2);
        }
        let der12 = (der2.sqrt() / h).max(dnf.sqrt());
        let h1 = if der12 <= 1e-15 {
            (h * 1e-3).max(1e-6)
        } else {
            (0.01 / der12).powf(0.2)
        };
        (100.0 * h).min(h1).min(t_end)
    };
    let (beta, safe, facc1, facc2) = (0.04, 0.9, 1.0 / 0.2, 1.0 / 10.0);
    let expo1 = 0.2 - beta * 0.75;
    let mut facold: f64 = 1e-4;
    let mut reject = false;
    let mut stats = Stats::default();
    let mut next = 0;
    while next < m {
        if t + 1.01 * h >= t_end {
            h = t_end - t;
        }
        let y2 = axpy(&y, &[(A21, &k1)], h);
        let k2 = motor.rhs(&y2);
        let y3 = axpy(&y, &[(A31, &k1), (A32, &k2)], h);
        let k3 = motor.rhs(&y3);
        let y4 = axpy(&y, &[(A41, &k1), (A42, &k2), (A43, &k3)], h);
        let k4 = motor.rhs(&y4);
        let y5 = axpy(&y, &[(A51, &k1), (A52, &k2), (A53, &k3), (A54, &k4)], h);
        let k5 = motor.rhs(&y5);
        let y6 = axpy(
            &y,
            &[(A61, &k1), (A62, &k2), (A63, &k3), (A64, &k4), (A65, &k5)],
            h,
        );
        let k6 = motor.rhs(&y6);
        let y_new = axpy(
            &y,
            &[(A71, &k1), (A73, &k3), (A74, &k4), (A75, &k5), (A76, &k6)],
            h,
        );
        let k7 = motor.rhs(&y_new);
        let mut err = 0.0;
        for n in 0..2 {
            let e = h
                * (E1 * k1[n].re()
                    + E3 * k3[n].re()
                    + E4 * k4[n].re()
                    + E5 * k5[n].re()
                    + E6 * k6[n].re()
                    + E7 * k7[n].re());
            err += (e / sk(y[n].re(), y_new[n].re())).powi(2);
        }
        let err = (err / 2.0).sqrt();
        let fac11 = err.powf(expo1);
        let fac = (fac11 / facold.powf(beta) / safe).clamp(facc2, facc1);
        let mut h_new = h / fac;
        if err <= 1.0 {
            stats.accepted += 1;
            facold = err.max(1e-4);
            let t_new = t + h;
            // Outputs in (t, t + h] from the continuous extension (Hairer's CONTD5).
            while next < m && times[next] <= t_new {
                let theta = (times[next] - t) / h;
                let theta1 = 1.0 - theta;
                for n in 0..2 {
                    let r2 = y_new[n] - y[n];
                    let r3 = k1[n] * h - r2;
                    let r4 = r2 - k7[n] * h - r3;
                    let r5 = (k1[n] * D1
                        + k3[n] * D3
                        + k4[n] * D4
                        + k5[n] * D5
                        + k6[n] * D6
                        + k7[n] * D7)
                        * h;
                    out[n * m + next] =
                        y[n] + (r2 + (r3 + (r4 + r5 * theta1) * theta) * theta1) * theta;
                }
                next += 1;
            }
            k1 = k7;
            y = y_new;
            t = t_new;
            if reject {
                h_new = h_new.min(h);
            }
            reject = false;
        } else {
            stats.rejected += 1;
            h_new = h / facc1.min(fac11 / safe);
            reject = true;
        }
        h = h_new;
    }
    stats
}

/// The orthonormal Legendre basis √(2j+1)·P_j(2t/T − 1) on the sample times, column-major.
fn legendre(times: &[f64], k: usize) -> Vec<f64> {
    let m = times.len();
    let t_end = *times.last().expect("times");
    let mut basis = vec![0.0; m * (k + 1)];
    for (i, &t) in times.iter().enumerate() {
        let x = 2.0 * t / t_end - 1.0;
        let (mut p0, mut p1) = (1.0, x);
        for j in 0..=k {
            let p = match j {
                0 => 1.0,
                1 => x,
                _ => {
                    let p2 = ((2 * j - 1) as f64 * x * p1 - (j - 1) as f64 * p0) / j as f64;
                    p0 = p1;
                    p1 = p2;
                    p2
                }
            };
            basis[j * m + i] = (2.0 * j as f64 + 1.0).sqrt() * p;
        }
    }
    basis
}

/// BM2(K) log likelihood at (R, σ_I, σ_ω, a_I, a_ω) and its gradient in (R, log σ, a), from one
/// dual solve: G, dG/dR, the residuals, B·a and Bᵀ·r.
struct Likelihood {
    times: Vec<f64>,
    y: Vec<f64>,
    basis: Vec<f64>,
    k: usize,
    g: Vec<Dual64>,
    residual: Vec<f64>,
}

impl Likelihood {
    fn value_and_gradient(&mut self, r: f64, sigma: [f64; 2], a: &[f64], grad: &mut [f64]) -> f64 {
        let motor = motor(Dual64::new(r, 1.0));
        solve(&motor, &self.times, &mut self.g, 1e-8);
        let (m, n) = (self.times.len(), self.k + 1);
        let mut loglik = 0.0;
        grad.fill(0.0);
        for c in 0..2 {
            let inv_var = 1.0 / (sigma[c] * sigma[c]);
            let a_c = &a[c * n..(c + 1) * n];
            for i in 0..m {
                let mut delta = 0.0;
                for j in 0..n {
                    delta += self.basis[j * m + i] * a_c[j];
                }
                self.residual[c * m + i] = self.y[c * m + i] - self.g[c * m + i].re - delta;
            }
            let rc = &self.residual[c * m..(c + 1) * m];
            let mut ss = 0.0;
            let mut dr = 0.0;
            for i in 0..m {
                ss += rc[i] * rc[i];
                dr += rc[i] * self.g[c * m + i].eps;
            }
            loglik += -(m as f64) * sigma[c].ln() - 0.5 * ss * inv_var;
            grad[0] += dr * inv_var;
            grad[1 + c] = -(m as f64) + ss * inv_var;
            for j in 0..n {
                let col = &self.basis[j * m..(j + 1) * m];
                let mut dot = 0.0;
                for i in 0..m {
                    dot += col[i] * rc[i];
                }
                grad[3 + c * n + j] = dot * inv_var;
            }
        }
        loglik
    }
}

fn motor<D>(r: D) -> Motor<D> {
    Motor {
        r,
        c_m: 0.01,
        c_g: 0.009,
        u: 24.0,
        d: 1e-6,
        l: 1e-4,
        j: 5e-5,
    }
}

/// Microseconds per call of `f`, over `n` calls.
fn per_call(n: usize, mut f: impl FnMut(usize)) -> f64 {
    let t = Instant::now();
    for i in 0..n {
        f(i);
    }
    t.elapsed().as_secs_f64() / n as f64 * 1e6
}

fn main() {
    let k = 9;
    let problem = Problem::paper(1).unwrap();
    let mut post = problem.posterior(&ModelSettings::bm2(k)).unwrap();
    let mut x = post.initial_point().unwrap();
    let forward = post.forward(0).clone();
    let times = forward.times().to_vec();
    let m = times.len();
    let mut crate_out = vec![0.0; forward.n_outputs()];
    forward.simulate(&[0.1], &mut crate_out).unwrap();

    // The minimal solver against the crate's at R = 0.1, and its dG/dR against differences.
    let mut g64 = vec![0.0; 2 * m];
    let stats = solve(&motor(0.1), &times, &mut g64, 1e-8);
    let scale = crate_out.iter().fold(0.0f64, |s, v| s.max(v.abs()));
    let gap = g64
        .iter()
        .zip(&crate_out)
        .fold(0.0f64, |s, (a, b)| s.max((a - b).abs()));
    let mut gd = vec![Dual64::from(0.0); 2 * m];
    solve(&motor(Dual64::new(0.1, 1.0)), &times, &mut gd, 1e-8);
    let (mut gp, mut gm) = (vec![0.0; 2 * m], vec![0.0; 2 * m]);
    solve(&motor(0.1 + 1e-6), &times, &mut gp, 1e-12);
    solve(&motor(0.1 - 1e-6), &times, &mut gm, 1e-12);
    let d_scale = gd.iter().fold(0.0f64, |s, v| s.max(v.eps.abs()));
    let d_gap = (0..2 * m).fold(0.0f64, |s, i| {
        s.max((gd[i].eps - (gp[i] - gm[i]) / 2e-6).abs())
    });
    println!(
        "minimal Dopri5: {} accepted, {} rejected steps, {m} outputs; max |G − crate's G| = {:.1e} \
         of max |G| {:.1e}; max |dG/dR − central difference| = {:.1e} of {:.1e}",
        stats.accepted, stats.rejected, gap, scale, d_gap, d_scale
    );

    let data: Vec<f64> = problem.recordings[0]
        .channels
        .iter()
        .flat_map(|(_, values)| values.iter().copied())
        .collect();
    let mut lik = Likelihood {
        basis: legendre(&times, k),
        times: times.clone(),
        y: data,
        k,
        g: vec![Dual64::from(0.0); 2 * m],
        residual: vec![0.0; 2 * m],
    };
    let a: Vec<f64> = (0..2 * (k + 1)).map(|j| 0.1 * (j as f64 - 9.5)).collect();
    let mut grad_min = vec![0.0; 3 + 2 * (k + 1)];
    // The likelihood's gradient in R and in a_I.1 against central differences of its value.
    let value = |lik: &mut Likelihood, r: f64, a: &[f64]| {
        let mut scratch = vec![0.0; 3 + 2 * (k + 1)];
        lik.value_and_gradient(r, [2.0, 10.0], a, &mut scratch)
    };
    lik.value_and_gradient(0.1, [2.0, 10.0], &a, &mut grad_min);
    let h = 1e-7;
    let d_r = (value(&mut lik, 0.1 + h, &a) - value(&mut lik, 0.1 - h, &a)) / (2.0 * h);
    let (mut a_plus, mut a_minus) = (a.clone(), a.clone());
    a_plus[0] += 1e-4;
    a_minus[0] -= 1e-4;
    let d_a = (value(&mut lik, 0.1, &a_plus) - value(&mut lik, 0.1, &a_minus)) / 2e-4;
    println!(
        "likelihood gradient against central differences: dR {:.6e} / {:.6e}, da_I.1 {:.6e} / {:.6e}",
        grad_min[0], d_r, grad_min[3], d_a
    );
    let mut grad = vec![0.0; x.len()];
    let n = 20_000;
    println!("K = {k}, {n} calls each, µs per call (crate / minimal):");
    for round in 1..=3 {
        let crate_solve = per_call(n, |i| {
            forward
                .simulate(&[0.1 + 1e-9 * (i % 3) as f64], &mut crate_out)
                .unwrap();
        });
        let minimal_solve = per_call(n, |i| {
            solve(&motor(0.1 + 1e-9 * (i % 3) as f64), &times, &mut g64, 1e-8);
        });
        let crate_gradient = per_call(n, |i| {
            x[0] = 0.1 + 1e-9 * (i % 3) as f64;
            post.log_density_and_gradient(&x, &mut grad).unwrap();
        });
        let crate_density = per_call(n, |i| {
            x[0] = 0.1 + 1e-9 * (i % 3) as f64;
            post.log_density(&x).unwrap();
        });
        let minimal_gradient = per_call(n, |i| {
            let r = 0.1 + 1e-9 * (i % 3) as f64;
            lik.value_and_gradient(r, [2.0, 10.0], &a, &mut grad_min);
        });
        println!(
            "round {round}: f64 solve {crate_solve:.1} / {minimal_solve:.1} ({:.2}×); \
             log density + gradient {crate_gradient:.1} / {minimal_gradient:.1} ({:.2}×)",
            crate_solve / minimal_solve,
            crate_gradient / minimal_gradient
        );
        // What `bench` counts as solve-equivalents: a plain solve 1, a gradient's dual solve
        // 1 + its directions (here one, dG/dR), i.e. 2.
        println!(
            "round {round}: gradient / plain solve: crate {:.2}× (log density + gradient {crate_gradient:.1} \
             / log density {crate_density:.1}), minimal {:.2}× (counted as 2 solve-equivalents)",
            crate_gradient / crate_density,
            minimal_gradient / minimal_solve
        );
    }
}
