//! The search: Nelder–Mead (argmin) in the profile's free coordinates from several starts, run
//! in parallel; each start is seeded on its own and the caller chooses among the ends by cost
//! (or a finer rating) then by start index, so the result is the same whatever the thread
//! count.

use argmin::core::{CostFunction, Executor, State};
use argmin::solver::neldermead::NelderMead;
use rand::{RngExt, SeedableRng};
use rayon::prelude::*;

use super::profile::Profile;

/// How the search runs.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct SearchSettings {
    pub segments: usize,
    pub starts: usize,
    /// Nelder–Mead iterations per start.
    pub iterations: u64,
    pub seed: u64,
}

impl Default for SearchSettings {
    fn default() -> Self {
        Self {
            segments: 8,
            starts: 4,
            iterations: 400,
            seed: 2026,
        }
    }
}

/// A cost the search minimises, at free coordinates.
struct Cost<'a, F: Fn(&[f64]) -> f64 + Sync>(&'a F);

impl<F: Fn(&[f64]) -> f64 + Sync> CostFunction for Cost<'_, F> {
    type Param = Vec<f64>;
    type Output = f64;

    fn cost(&self, z: &Self::Param) -> Result<f64, argmin::core::Error> {
        Ok((self.0)(z))
    }
}

/// The starts: alternating levels at ±0.6 of the limit on equal segments, then levels drawn
/// uniformly in ±0.9 of the limit on segments of jittered lengths.
pub fn starts(settings: &SearchSettings, duration: f64, u_max: f64) -> Vec<Profile> {
    let n = settings.segments;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(settings.seed);
    let equal = |levels: Vec<f64>| Profile {
        levels,
        switches: (1..n).map(|j| duration * j as f64 / n as f64).collect(),
        duration,
    };
    let mut out = vec![equal(
        (0..n)
            .map(|j| if j % 2 == 0 { 0.6 } else { -0.6 } * u_max)
            .collect(),
    )];
    while out.len() < settings.starts.max(1) {
        let levels = (0..n)
            .map(|_| rng.random_range(-0.9..0.9) * u_max)
            .collect();
        let widths: Vec<f64> = (0..n).map(|_| rng.random_range(0.5..1.5)).collect();
        let total: f64 = widths.iter().sum();
        let mut at = 0.0;
        let switches = widths[..n - 1]
            .iter()
            .map(|w| {
                at += duration * w / total;
                at
            })
            .collect();
        out.push(Profile {
            levels,
            switches,
            duration,
        });
    }
    out
}

/// The best free coordinates found from each start and their cost, in the starts' order (the
/// caller picks among them, the first among equals: the same whatever the thread count).
pub fn minimise_each<F: Fn(&[f64]) -> f64 + Sync>(
    starts: &[Vec<f64>],
    iterations: u64,
    cost: &F,
) -> Vec<(Vec<f64>, f64)> {
    starts
        .par_iter()
        .map(|z0| {
            let mut simplex = vec![z0.clone()];
            for i in 0..z0.len() {
                let mut v = z0.clone();
                v[i] += 0.5;
                simplex.push(v);
            }
            let fallback = (z0.clone(), cost(z0));
            let solver = NelderMead::new(simplex);
            match Executor::new(Cost(cost), solver)
                .configure(|s| s.max_iters(iterations))
                .run()
            {
                Ok(result) => match result.state().get_best_param() {
                    Some(z) => (z.clone(), result.state().get_best_cost()),
                    None => fallback,
                },
                Err(_) => fallback,
            }
        })
        .collect()
}
