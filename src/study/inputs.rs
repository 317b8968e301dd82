//! The inputs a synthetic experiment drives the motor with.

use serde::{Deserialize, Serialize};

use crate::motor::VoltageInput;

/// The voltage the motor is driven with.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum InputProfile {
    /// The model's constant U (the paper's start-up).
    #[default]
    Constant,
    /// U, then U/3 from 40% of the record: the speed falls back, so friction and inertia act
    /// with the opposite sign of the current's change.
    Step,
    /// U, then U/3 from 20%, then −U from 60%: the speed changes sign, which separates Coulomb
    /// friction from a constant load.
    Reversal,
    /// U and −U by turns, each for a twentieth of the record: twenty steps, each of 2U after
    /// the first, where an effect that shows only at the input's steps (a delay) adds up.
    Square,
}

impl InputProfile {
    pub const ALL: [InputProfile; 4] = [
        InputProfile::Constant,
        InputProfile::Step,
        InputProfile::Reversal,
        InputProfile::Square,
    ];

    /// The profile's name in files and on the command line.
    pub fn name(&self) -> &'static str {
        match self {
            InputProfile::Constant => "constant",
            InputProfile::Step => "step",
            InputProfile::Reversal => "reversal",
            InputProfile::Square => "square",
        }
    }

    /// One line on what the profile does.
    pub fn help(&self) -> &'static str {
        match self {
            InputProfile::Constant => "The model's constant U (the paper's start-up)",
            InputProfile::Step => "U, then U/3 from 40% of the record",
            InputProfile::Reversal => {
                "U, then U/3 from 20%, then −U from 60%: the speed changes sign"
            }
            InputProfile::Square => "U and −U by turns, each for a twentieth of the record",
        }
    }

    pub fn voltage(&self, u: f64, times: &[f64]) -> VoltageInput {
        let t_end = times.last().copied().unwrap_or(0.0);
        let level = |t: f64| match self {
            InputProfile::Constant => u,
            InputProfile::Step => {
                if t < 0.4 * t_end {
                    u
                } else {
                    u / 3.0
                }
            }
            InputProfile::Reversal => {
                if t < 0.2 * t_end {
                    u
                } else if t < 0.6 * t_end {
                    u / 3.0
                } else {
                    -u
                }
            }
            InputProfile::Square => {
                if (20.0 * t / t_end).floor() as i64 % 2 == 0 {
                    u
                } else {
                    -u
                }
            }
        };
        match self {
            InputProfile::Constant => VoltageInput::Constant,
            _ => VoltageInput::Held {
                times: times.to_vec(),
                values: times.iter().map(|&t| level(t)).collect(),
            },
        }
    }
}
