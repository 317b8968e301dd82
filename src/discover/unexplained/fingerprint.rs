//! The kinds of structure the verdict names, as the JSON contract of issue 19 spells them, and
//! the sentence each suggests.

use serde::Serialize;

/// The leading kinds of structure left, each with its own score (nats over the model).
#[derive(Clone, Debug, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Fingerprint {
    Oscillation {
        frequency_hz: f64,
        frequency_sd: f64,
        damping_ratio: Option<f64>,
        channel: String,
        ringing: bool,
        score: f64,
        /// The points its search ran over: a fit started at it pays ln of this.
        #[serde(skip)]
        grid_points: usize,
    },
    Delay {
        seconds: f64,
        sd: f64,
        score: f64,
    },
    Lag {
        channel: String,
        seconds: f64,
        sd: f64,
        score: f64,
    },
    Unknown {
        score: f64,
    },
}

impl Fingerprint {
    pub fn score(&self) -> f64 {
        match self {
            Fingerprint::Oscillation { score, .. }
            | Fingerprint::Delay { score, .. }
            | Fingerprint::Lag { score, .. }
            | Fingerprint::Unknown { score } => *score,
        }
    }

    /// The kind, with the channel and whether it rings: two fingerprints with the same
    /// identity are two estimates of one thing.
    pub(super) fn identity(&self) -> String {
        match self {
            Fingerprint::Oscillation {
                channel, ringing, ..
            } => format!("oscillation/{channel}/{ringing}"),
            Fingerprint::Delay { .. } => "delay".into(),
            Fingerprint::Lag { channel, .. } => format!("lag/{channel}"),
            Fingerprint::Unknown { .. } => "unknown".into(),
        }
    }

    /// What a user might do about it, in a sentence.
    pub fn suggestion(&self, channels: &[String]) -> String {
        match self {
            Fingerprint::Oscillation {
                frequency_hz,
                damping_ratio,
                channel,
                ringing: true,
                ..
            } => format!(
                "a resonance at {frequency_hz:.1} Hz (damping ratio {:.3}) rings on {channel} \
                 after the input steps: a compliant coupling to the load (the term \
                 compliant_coupling) or a resonant sensor; a record with sharper steps, or \
                 with the load decoupled, would tell them apart",
                damping_ratio.unwrap_or(f64::NAN)
            ),
            Fingerprint::Oscillation {
                frequency_hz,
                channel,
                ..
            } => format!(
                "a periodic disturbance at {frequency_hz:.1} Hz runs on {channel} regardless \
                 of the input: a pulsing load, an eccentric or cogging (compare it with the \
                 turning frequency ω/2π), or interference on the sensor"
            ),
            Fingerprint::Delay { seconds, .. } => format!(
                "every channel is late by {:.3} ms: the input acts later than modelled (the \
                 term input_delay)",
                seconds * 1e3
            ),
            Fingerprint::Lag {
                channel, seconds, ..
            } => format!(
                "{channel} lags the model with a time constant of {:.3} ms: a filter in its \
                 sensor or logger (the term sensor_lag on {channel})",
                seconds * 1e3
            ),
            Fingerprint::Unknown { .. } => format!(
                "structure no library term holds remains in {}: a record with another input \
                 (a reversal, steps of several sizes) would show how it depends on the state",
                channels.join(" and ")
            ),
        }
    }
}
