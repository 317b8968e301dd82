//! The designed input: a piecewise-constant voltage of N segments (levels and switching times),
//! and the smooth reparametrisation the search moves in, which keeps every level inside the
//! voltage limit and every segment of positive length.

use crate::motor::VoltageInput;

/// N levels held on N consecutive segments of a record of `duration` seconds.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Profile {
    /// The voltage of each segment [V].
    pub levels: Vec<f64>,
    /// The N − 1 times at which the next segment starts [s], increasing, inside (0, duration).
    pub switches: Vec<f64>,
    pub duration: f64,
}

impl Profile {
    /// From the search's free coordinates: `z[..n]` give the levels as `u_max·tanh(z)`,
    /// `z[n..2n]` the segments' shares of the duration as a softmax.
    pub fn from_free(z: &[f64], n: usize, duration: f64, u_max: f64) -> Self {
        let levels = z[..n].iter().map(|x| u_max * x.tanh()).collect();
        let top = z[n..2 * n]
            .iter()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max);
        let weights: Vec<f64> = z[n..2 * n].iter().map(|x| (x - top).exp()).collect();
        let total: f64 = weights.iter().sum();
        let mut switches = Vec::with_capacity(n - 1);
        let mut at = 0.0;
        for w in &weights[..n - 1] {
            at += duration * w / total;
            switches.push(at);
        }
        Self {
            levels,
            switches,
            duration,
        }
    }

    /// The free coordinates of a profile whose levels lie strictly inside ±`u_max`.
    pub fn to_free(&self, u_max: f64) -> Vec<f64> {
        let mut z: Vec<f64> = self
            .levels
            .iter()
            .map(|u| (u / u_max).clamp(-0.999, 0.999).atanh())
            .collect();
        let mut start = 0.0;
        for end in self.switches.iter().chain(std::iter::once(&self.duration)) {
            z.push((end - start).max(1e-12).ln());
            start = *end;
        }
        z
    }

    /// A held input (values at `times`) as a profile of `n` segments on `duration`: each
    /// switch halfway between the samples it falls between, the longest segments split (at
    /// equal levels) until there are `n`; `None` when the input has more than `n` levels.
    pub fn from_held(times: &[f64], values: &[f64], n: usize, duration: f64) -> Option<Self> {
        let mut levels = vec![*values.first()?];
        let mut switches = Vec::new();
        for i in 1..values.len().min(times.len()) {
            if values[i] != values[i - 1] {
                levels.push(values[i]);
                switches.push(0.5 * (times[i - 1] + times[i]));
            }
        }
        if levels.len() > n {
            return None;
        }
        while levels.len() < n {
            let bounds: Vec<f64> = std::iter::once(0.0)
                .chain(switches.iter().copied())
                .chain(std::iter::once(duration))
                .collect();
            let longest = (0..levels.len())
                .max_by(|&a, &b| {
                    (bounds[a + 1] - bounds[a]).total_cmp(&(bounds[b + 1] - bounds[b]))
                })
                .unwrap_or(0);
            levels.insert(longest, levels[longest]);
            switches.insert(longest, 0.5 * (bounds[longest] + bounds[longest + 1]));
        }
        Some(Self {
            levels,
            switches,
            duration,
        })
    }

    /// The level held at time t (the first level before the record starts).
    pub fn level_at(&self, t: f64) -> f64 {
        self.levels[self.switches.partition_point(|&s| s <= t)]
    }

    /// The input as the integrator takes it, switching exactly at the switching times.
    pub fn continuous(&self) -> VoltageInput {
        VoltageInput::Held {
            times: std::iter::once(0.0)
                .chain(self.switches.iter().copied())
                .collect(),
            values: self.levels.clone(),
        }
    }

    /// The values at the sample times: what `input.csv` holds and a recorder plays, each held
    /// until the next sample (a switch moves to the first sample at or after it).
    pub fn sampled(&self, times: &[f64]) -> Vec<f64> {
        times.iter().map(|&t| self.level_at(t)).collect()
    }
}

/// A held input at the sample times.
pub fn held(times: &[f64], values: Vec<f64>) -> VoltageInput {
    VoltageInput::Held {
        times: times.to_vec(),
        values,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn free_coordinates_keep_levels_and_segments_inside() {
        let z = [9.0, -9.0, 0.3, 0.0, 2.0, -1.0];
        let p = Profile::from_free(&z, 3, 0.5, 24.0);
        assert!(p.levels.iter().all(|u| u.abs() <= 24.0));
        assert_eq!(p.switches.len(), 2);
        assert!(0.0 < p.switches[0] && p.switches[0] < p.switches[1] && p.switches[1] < 0.5);
        let back = Profile::from_free(&p.to_free(24.0), 3, 0.5, 24.0);
        for (a, b) in back.switches.iter().zip(&p.switches) {
            assert!((a - b).abs() < 1e-12);
        }
        assert!((back.levels[2] - p.levels[2]).abs() < 1e-9);
        assert_eq!(p.level_at(0.0), p.levels[0]);
        assert_eq!(p.level_at(0.49), p.levels[2]);
    }

    #[test]
    fn a_held_input_becomes_a_profile_that_samples_back_to_it() {
        let times: Vec<f64> = (1..=10).map(|i| i as f64 * 0.1).collect();
        let values = [3.0, 3.0, 1.0, 1.0, 1.0, 1.0, -3.0, -3.0, -3.0, -3.0];
        let p = Profile::from_held(&times, &values, 5, 1.0).unwrap();
        assert_eq!((p.levels.len(), p.switches.len()), (5, 4));
        assert!(p.switches.windows(2).all(|w| w[0] < w[1]));
        assert_eq!(p.sampled(&times), values);
        assert!(Profile::from_held(&times, &values, 2, 1.0).is_none());
    }
}
