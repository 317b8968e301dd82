//! The kinds of structure the verdict names, as the JSON contract of issue 19 spells them, and
//! the sentence each suggests.

use serde::Serialize;

use crate::motor::dictionary::{self, Spot};

/// One function of a state fingerprint: its dictionary name, the coefficient the linearised
/// regression gives (the physical unit of the law's coefficient) and its sd.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LawFunction {
    pub name: String,
    pub coefficient: f64,
    pub sd: f64,
}

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
        /// In the sensor of `channel` (a second-order filter of the measurement, fitted from
        /// the lag: `resonance`), not in the motor or its load.
        sensor: bool,
        score: f64,
        /// The frequencies its search ran over: a coupling started at its frequency pays ln of
        /// this for f_r, in place of ½·ln N (`frequency_search_cost`). Not the decay times it
        /// also tried: the coupling's damping ratio is one of its parameters, paid for by
        /// ½·ln N in its score like every other.
        #[serde(skip)]
        frequencies: usize,
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
    /// The balance (`torque`, `voltage`) misses a sum of dictionary functions of the state, or
    /// what is read of a channel does (`measurement:I`, `measurement:omega`: the law's
    /// measurement balances).
    State {
        balance: String,
        functions: Vec<LawFunction>,
        /// The Stribeck speed ω_s of `exp(-(omega/omega_s)^2)*sign(omega)`, where it is one
        /// of the functions.
        #[serde(skip_serializing_if = "Option::is_none")]
        omega_s: Option<f64>,
        /// The harmonic k of `sin(k*theta)`, `cos(k*theta)` (periods per revolution), where
        /// they are among the functions.
        #[serde(rename = "k", skip_serializing_if = "Option::is_none")]
        harmonic: Option<f64>,
        /// The current limit I_lim [A] of `sign(I)*max(|I|-I_lim,0)`, where it is one of the
        /// functions.
        #[serde(rename = "I_lim", skip_serializing_if = "Option::is_none")]
        current_limit: Option<f64>,
        /// The speed limit ω_lim [rad/s] of `sign(omega)*max(|omega|-omega_lim,0)`, where it
        /// is one of the functions.
        #[serde(rename = "omega_lim", skip_serializing_if = "Option::is_none")]
        speed_limit: Option<f64>,
        /// The spot's θ₀ and w of `omega*exp(-2*(1-cos(theta-theta_0))/w^2)`, where it is
        /// one of the functions (`theta_0`, `w` in the JSON).
        #[serde(flatten, skip_serializing_if = "Option::is_none")]
        spot: Option<Spot>,
        /// The time constant τ [s] of `exp(-t/tau)`, where it is one of the functions.
        #[serde(rename = "tau", skip_serializing_if = "Option::is_none")]
        fade: Option<f64>,
        /// The instant t_s [s] of `step(t-t_s)`, where it is one of the functions.
        #[serde(rename = "t_s", skip_serializing_if = "Option::is_none")]
        instant: Option<f64>,
        /// The step q of `sin(2*pi*<channel>/q)`, `cos(2*pi*<channel>/q)` (in the channel's
        /// unit), where what is read is rounded to steps (`quantized`).
        #[serde(rename = "q", skip_serializing_if = "Option::is_none")]
        step: Option<f64>,
        /// What its k's search cost (`order`: ln G where the order search found it, else 0):
        /// a law named at that k pays it too.
        #[serde(skip)]
        harmonic_price: f64,
        /// And the half-width of the refinement of that k through the ODE (0: none).
        #[serde(skip)]
        harmonic_width: f64,
        score: f64,
    },
    /// The balance drifts with time, the charge drawn or the heat dissipated: a state set of
    /// `t`, `charge` or `heat` alone.
    Drift {
        /// `time`, `charge` or `heat`: the first function selected.
        variable: String,
        balance: String,
        functions: Vec<LawFunction>,
        /// The time constant τ [s] of `exp(-t/tau)`, where it is one of the functions.
        #[serde(rename = "tau", skip_serializing_if = "Option::is_none")]
        fade: Option<f64>,
        /// The instant t_s [s] of `step(t-t_s)`, where it is one of the functions.
        #[serde(rename = "t_s", skip_serializing_if = "Option::is_none")]
        instant: Option<f64>,
        /// What finding its shape cost (ln G over a step's instants or a fade's time
        /// constants, else 0): a law named with it pays it too.
        #[serde(skip)]
        shape_price: f64,
        score: f64,
    },
    Unknown {
        score: f64,
    },
}

impl Fingerprint {
    /// A state fingerprint of plain functions, no shape among them (no ω_s, k, I_lim, spot or
    /// step).
    pub fn plain_state(balance: &str, functions: Vec<LawFunction>, score: f64) -> Self {
        Fingerprint::State {
            balance: balance.into(),
            functions,
            omega_s: None,
            harmonic: None,
            current_limit: None,
            speed_limit: None,
            spot: None,
            fade: None,
            instant: None,
            step: None,
            harmonic_price: 0.0,
            harmonic_width: 0.0,
            score,
        }
    }

    /// The same estimate scored `shift` nats lower (against a bar raised by `shift`).
    pub(super) fn shifted(mut self, shift: f64) -> Self {
        match &mut self {
            Fingerprint::Oscillation { score, .. }
            | Fingerprint::Delay { score, .. }
            | Fingerprint::Lag { score, .. }
            | Fingerprint::State { score, .. }
            | Fingerprint::Drift { score, .. }
            | Fingerprint::Unknown { score } => *score -= shift,
        }
        self
    }

    pub fn score(&self) -> f64 {
        match self {
            Fingerprint::Oscillation { score, .. }
            | Fingerprint::Delay { score, .. }
            | Fingerprint::Lag { score, .. }
            | Fingerprint::State { score, .. }
            | Fingerprint::Drift { score, .. }
            | Fingerprint::Unknown { score } => *score,
        }
    }

    /// The kind, with the channel and whether it rings: two fingerprints with the same
    /// identity are two estimates of one thing.
    pub(super) fn identity(&self) -> String {
        match self {
            Fingerprint::Oscillation {
                channel,
                ringing,
                sensor,
                ..
            } => format!("oscillation/{channel}/{ringing}/{sensor}"),
            Fingerprint::Delay { .. } => "delay".into(),
            Fingerprint::Lag { channel, .. } => format!("lag/{channel}"),
            // A reading in steps is not a smooth function of the state: it does not displace
            // the state fingerprint of the same reading, nor it the steps.
            Fingerprint::State {
                balance,
                step: Some(_),
                ..
            } => format!("state/{balance}/steps"),
            Fingerprint::State { balance, .. } => format!("state/{balance}"),
            Fingerprint::Drift { .. } => "drift".into(),
            Fingerprint::Unknown { .. } => "unknown".into(),
        }
    }

    /// What a user might do about it, in a sentence.
    pub fn suggestion(&self, channels: &[String]) -> String {
        let speed_limit = match self {
            Fingerprint::State { speed_limit, .. } => *speed_limit,
            _ => None,
        };
        match self {
            Fingerprint::Oscillation {
                frequency_hz,
                damping_ratio,
                channel,
                sensor: true,
                ..
            } => format!(
                "the {channel} sensor rings at {frequency_hz:.1} Hz (damping ratio {:.3}) \
                 after the input steps and the motor does not (the measured channel alone \
                 rings, as a second-order sensor does: a compliant encoder coupling, or the \
                 logger's filter), which the first-order sensor_lag does not hold; a second \
                 sensor on the same shaft would confirm it",
                damping_ratio.unwrap_or(f64::NAN)
            ),
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
            Fingerprint::State {
                balance,
                step: Some(q),
                ..
            } => format!(
                "what is read of {} follows its own value with a period of {q:.4}: the reading \
                 rounded to steps of that size (an encoder's counts per sample period, an ADC's \
                 least bit), which no law of the state holds; a finer sensor, or the step in \
                 the model, would settle it",
                balance.trim_start_matches("measurement:")
            ),
            Fingerprint::State {
                balance,
                functions,
                spot: Some(spot),
                ..
            } => format!(
                "what is read of {} is off over a span of {:.2} rad about θ = {:.2} rad, at the \
                 same angle every revolution: {} fits what is left — an encoder line damaged or \
                 missing, a worn segment of a tachogenerator's commutator (the term law, in \
                 what is read); a record turning slowly through many revolutions would map the \
                 spot's shape",
                balance.trim_start_matches("measurement:"),
                spot.w,
                spot.theta_0,
                with_spot(equation(balance, functions), Some(*spot))
            ),
            Fingerprint::State {
                balance,
                functions,
                fade,
                instant,
                ..
            }
            | Fingerprint::Drift {
                balance,
                functions,
                fade,
                instant,
                ..
            } if balance.starts_with("measurement:") => format!(
                "what is read of {} follows the state: {} fits what is left — a sensor that \
                 also reads the input (a leakage path on the supply side of a current \
                 sensor), reads nonlinearly, clips at its range or drifts (the term law, in \
                 what is read)",
                balance.trim_start_matches("measurement:"),
                with_speed_limit(
                    with_time(equation(balance, functions), *fade, *instant),
                    speed_limit
                )
            ),
            Fingerprint::State {
                balance,
                functions,
                harmonic,
                current_limit,
                fade,
                instant,
                ..
            } => format!(
                "the {balance} balance follows the state: {} fits what is left (the term \
                 law); a record with another input would confirm the law beyond this one's \
                 states",
                with_time(
                    with_shapes(
                        equation(balance, functions),
                        *harmonic,
                        *current_limit,
                        None
                    ),
                    *fade,
                    *instant
                )
            ),
            Fingerprint::Drift {
                balance,
                functions,
                fade: Some(tau),
                instant,
                ..
            } => format!(
                "the {balance} balance changes with time and settles, with a time constant of \
                 {:.1} ms: {} fits what is left (the term law): a holding brake still \
                 releasing, a supply or a zero settling after switch-on; a record started \
                 later, or twice in a row, would show whether it comes back",
                tau * 1e3,
                with_time(equation(balance, functions), Some(*tau), *instant)
            ),
            Fingerprint::Drift {
                variable,
                balance,
                functions,
                ..
            } => format!(
                "the {balance} balance drifts with the {variable}: {} fits what is left (the \
                 term law): a supply that sags with the charge drawn, a resistance or a \
                 constant that changes as the motor warms, or a slow change in time",
                equation(balance, functions)
            ),
            Fingerprint::Unknown { .. } => format!(
                "structure no library term holds remains in {}: a record with another input \
                 (a reversal, steps of several sizes) would show how it depends on the state",
                channels.join(" and ")
            ),
        }
    }
}

/// One function of a law as an equation prints it: its dictionary name, its coefficient and,
/// where given, its 95% interval.
pub type EquationTerm = (String, f64, Option<(f64, f64)>);

/// A balance's law as an equation, e.g. `J dω/dt += −0.012·sign(ω)·|I|`, each function with
/// its coefficient and, where given, an interval after it.
/// A law's shapes written into its equation: `sin(6·θ)` for `sin(k·θ)` at k = 6,
/// `max(|I|-212.4 A,0)` for I_lim = 212.4 A, `sin(2π·105.36·t)` for `sin(2πft)` at f = 105.36 Hz.
pub fn with_shapes(
    equation: String,
    harmonic: Option<f64>,
    current_limit: Option<f64>,
    frequency_hz: Option<f64>,
) -> String {
    let mut equation = equation;
    if let Some(k) = harmonic {
        // A whole k as it is (the grid's); one the order search found to three decimals,
        // finer than its refinement's error on a record of some ten revolutions.
        let k = if k.fract() == 0.0 {
            format!("{k}")
        } else {
            format!("{k:.3}")
        };
        equation = equation.replace("k·θ", &format!("{k}·θ"));
    }
    if let Some(i) = current_limit {
        equation = equation.replace("I_lim", &format!("{i:.1} A"));
    }
    if let Some(f) = frequency_hz {
        equation = equation.replace("2πft", &format!("2π·{f:.2}·t"));
    }
    equation
}

/// A speed limit written into its equation: `max(|ω|-2350.0 rad/s,0)` for ω_lim = 2350 rad/s.
pub fn with_speed_limit(equation: String, speed_limit: Option<f64>) -> String {
    match speed_limit {
        Some(w) => equation.replace("ω_lim", &format!("{w:.1} rad/s")),
        None => equation,
    }
}

/// A spot's shape written into its equation: `exp(-2·(1-cos(θ-2.356))/0.196^2)` for θ₀ =
/// 2.356 rad, w = 0.196 rad.
pub fn with_spot(equation: String, spot: Option<Spot>) -> String {
    match spot {
        Some(s) => equation
            .replace("θ-θ_0", &format!("θ-{:.3}", s.theta_0))
            .replace("/w^2", &format!("/{:.3}^2", s.w)),
        None => equation,
    }
}

/// A fade's time constant and a step's instant written into their equation: `exp(-t/35.4
/// ms)` for τ = 35.4 ms, `step(t-0.3101 s)` for t_s = 0.3101 s.
pub fn with_time(equation: String, fade: Option<f64>, instant: Option<f64>) -> String {
    let mut equation = equation;
    if let Some(tau) = fade {
        equation = equation.replace("exp(-t/τ)", &format!("exp(-t/{:.1} ms)", tau * 1e3));
    }
    if let Some(t_s) = instant {
        equation = equation.replace("step(t-t_s)", &format!("step(t-{t_s:.4} s)"));
    }
    equation
}

pub fn equation_with(balance: &str, terms: &[EquationTerm]) -> String {
    let lhs = match balance {
        "voltage" => "L dI/dt",
        "measurement:I" => "measured I",
        "measurement:omega" => "measured ω",
        _ => "J dω/dt",
    };
    let mut text = format!("{lhs} +=");
    for (i, (name, c, interval)) in terms.iter().enumerate() {
        let band = interval.map_or(String::new(), |(lo, hi)| {
            format!(" [95%: {}, {}]", signed(lo), signed(hi))
        });
        // The first coefficient carries its sign; later ones are joined by it.
        let (joint, value) = match (i, *c < 0.0) {
            (0, _) => (" ", signed(*c)),
            (_, true) => (" − ", signed(-c)),
            (_, false) => (" + ", signed(*c)),
        };
        // The constant is its coefficient alone.
        let function = match name.as_str() {
            "1" => String::new(),
            _ => format!("·{}", dictionary::pretty(name)),
        };
        text.push_str(&format!("{joint}{value}{function}{band}"));
    }
    text
}

fn equation(balance: &str, functions: &[LawFunction]) -> String {
    let terms: Vec<EquationTerm> = functions
        .iter()
        .map(|f| (f.name.clone(), f.coefficient, None))
        .collect();
    equation_with(balance, &terms)
}

/// A number to three significant digits with a true minus sign: positional from 10⁻³ to 10⁴
/// (trailing zeros dropped), else in e-notation.
fn signed(v: f64) -> String {
    let text = if v == 0.0 || !v.is_finite() {
        format!("{v}")
    } else if v.abs() < 1e-3 || v.abs() >= 1e4 {
        format!("{v:.2e}")
    } else {
        let decimals = (2 - v.abs().log10().floor() as i32).max(0) as usize;
        let fixed = format!("{v:.decimals$}");
        if fixed.contains('.') {
            fixed
                .trim_end_matches('0')
                .trim_end_matches('.')
                .to_string()
        } else {
            fixed
        }
    };
    match text.strip_prefix('-') {
        Some(magnitude) => format!("−{magnitude}"),
        None => text,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_law_reads_as_its_equation() {
        let law = [
            (
                "sign(omega)*|I|".to_string(),
                -0.012,
                Some((-0.0131, -0.0109)),
            ),
            ("omega".to_string(), -2.5e-5, None),
            ("sin(k*theta)".to_string(), 0.25, None),
        ];
        assert_eq!(
            equation_with("torque", &law),
            "J dω/dt += −0.012·sign(ω)·|I| [95%: −0.0131, −0.0109] − 2.50e-5·ω + 0.25·sin(k·θ)"
        );
        assert!(equation_with("voltage", &law[2..]).starts_with("L dI/dt += 0.25·sin(k·θ)"));
    }
}
