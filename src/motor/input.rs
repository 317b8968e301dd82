//! The voltage that drives the motor.

use serde::{Deserialize, Serialize};

use super::Scalar;

/// The input voltage: the model's constant `U`, or a recorded series held between samples.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, Default)]
pub enum VoltageInput {
    /// The model parameter `U` throughout.
    #[default]
    Constant,
    /// Zero-order hold: the value at `times[i]` holds on `[times[i], times[i+1])`, and the first
    /// value also before `times[0]`.
    Held { times: Vec<f64>, values: Vec<f64> },
}

impl VoltageInput {
    /// The held value at time `t`, or `None` for a constant input.
    pub fn value_at(&self, t: f64) -> Option<f64> {
        match self {
            VoltageInput::Constant => None,
            VoltageInput::Held { times, values } => {
                let after = times.partition_point(|&ti| ti <= t);
                Some(values[after.saturating_sub(1)])
            }
        }
    }

    /// The held series, or `None` for a constant input: what a record carries as its `U`.
    pub fn held_values(&self) -> Option<&[f64]> {
        match self {
            VoltageInput::Constant => None,
            VoltageInput::Held { values, .. } => Some(values),
        }
    }

    /// Times at which the held value actually changes (not every sample: stopping the
    /// integrator there would cost a restart for nothing).
    pub fn breakpoints(&self) -> Vec<f64> {
        match self {
            VoltageInput::Constant => Vec::new(),
            VoltageInput::Held { times, values } => (1..times.len())
                .filter(|&i| values[i] != values[i - 1])
                .map(|i| times[i])
                .collect(),
        }
    }
}

/// The input of one solve as a sum of steps, for a term that evaluates it at other times than
/// the integrator's (a delay): 0 before the first start (the switch-on), then `value(j)` from
/// `starts[j]` on. The starts are the intervals between the right-hand side's breakpoints, so
/// some steps may be of zero height.
pub struct InputSteps<'a, D> {
    pub starts: &'a [f64],
    /// The held value on each interval; empty when the input is the constant parameter.
    pub held: &'a [f64],
    pub constant: D,
}

impl<D: Scalar> InputSteps<'_, D> {
    /// The value held from `starts[j]` on.
    pub fn value(&self, j: usize) -> D {
        self.held.get(j).map_or(self.constant, |&u| D::from(u))
    }

    /// The value held at time t (the value of the interval that begins at or before t), 0
    /// before the switch-on.
    pub fn value_at(&self, t: f64) -> D {
        match self.starts.partition_point(|&s| s <= t) {
            0 => D::from(0.0),
            j => self.value(j - 1),
        }
    }

    /// The steps strictly after `after` and up to `until`: (time, height).
    pub fn steps_within(&self, after: f64, until: f64) -> impl Iterator<Item = (f64, D)> + '_ {
        let first = self.starts.partition_point(|&s| s <= after);
        let last = self.starts.partition_point(|&s| s <= until);
        (first..last).map(move |j| {
            let before = if j == 0 {
                D::from(0.0)
            } else {
                self.value(j - 1)
            };
            (self.starts[j], self.value(j) - before)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn held_voltage_changes_only_at_its_breakpoints() {
        let input = VoltageInput::Held {
            times: vec![0.1, 0.2, 0.3, 0.4],
            values: vec![24.0, 24.0, 8.0, -24.0],
        };
        assert_eq!(input.breakpoints(), vec![0.3, 0.4]);
        assert_eq!(input.value_at(0.0), Some(24.0));
        assert_eq!(input.value_at(0.3), Some(8.0));
        assert_eq!(input.value_at(0.35), Some(8.0));
        assert_eq!(input.value_at(0.5), Some(-24.0));
        assert_eq!(VoltageInput::Constant.value_at(0.2), None);
    }
}
