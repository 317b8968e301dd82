//! Locating the mismatch against the state, not in time (drive bases): the torque the model
//! misses at each sample, c_g·u − d·ω + Σ terms − J·ω̇ from the measured speed and input (the
//! inverse model), against the speed. Its shape names the physics: a jump at ω = 0 is Coulomb
//! friction, a slope viscous friction, a constant an offset or a load torque. The least-squares
//! fit of the missing torque on (sign ω, ω, 1) over the moving samples says it in numbers; on
//! records that never reverse, sign ω is a constant and the jump cannot be told from the
//! constant — the reason Coulomb friction and a load torque tie there.

use nalgebra::{DMatrix, DVector};
use serde::Serialize;

use crate::error::Error;
use crate::io::Recording;
use crate::motor::Base;
use crate::plot::MissingTorqueCurve;
use crate::study::Problem;

use super::candidate::Candidate;
use super::settings::SMOOTHING_S;

/// Speed bins of the figure.
const BINS: usize = 40;

/// Samples slower than this share of the record's top speed are left out of the fit: there
/// the smoothed friction of the model and the stiction of the rig differ most.
const MOVING_SHARE: f64 = 0.02;

/// The least-squares fingerprint of the missing torque over one problem's records.
#[derive(Clone, Debug, Serialize)]
pub struct StateFingerprint {
    /// Which model: `before` (as given, at its MAP) or `after` (with the selected terms).
    pub model: String,
    /// Jump across zero speed (twice the sign coefficient), slope against speed, constant.
    pub jump_at_zero: f64,
    pub slope: f64,
    pub constant: f64,
    /// RMS of the missing torque over the moving samples, and the share the three explain.
    pub rms: f64,
    pub explained: f64,
    /// Whether the records hold motion in both directions (else jump and constant are one).
    pub reverses: bool,
    pub torque_unit: String,
    pub speed_unit: String,
}

/// A centred moving average of `width` samples (shorter at the ends).
fn smooth(values: &[f64], width: usize) -> Vec<f64> {
    let half = width / 2;
    let mut prefix = vec![0.0; values.len() + 1];
    for (i, v) in values.iter().enumerate() {
        prefix[i + 1] = prefix[i] + v;
    }
    (0..values.len())
        .map(|i| {
            let (lo, hi) = (i.saturating_sub(half), (i + half + 1).min(values.len()));
            (prefix[hi] - prefix[lo]) / (hi - lo) as f64
        })
        .collect()
}

/// Central differences (one-sided at the ends).
fn derivative(values: &[f64], times: &[f64]) -> Vec<f64> {
    let m = values.len();
    (0..m)
        .map(|i| {
            let (a, b) = (i.saturating_sub(1), (i + 1).min(m - 1));
            (values[b] - values[a]) / (times[b] - times[a])
        })
        .collect()
}

/// A record's speed and drive input as measured, smoothed over [`SMOOTHING_S`]: ω and the
/// current (`current_driven`), or the derivative of q and the force over c_g
/// (`position_loop`); `None` for the voltage-driven motor.
fn measured(problem: &Problem, recording: &Recording) -> Result<Option<[Vec<f64>; 2]>, Error> {
    let times = &recording.time;
    let dt = (recording.last_time() - times[0]) / (times.len().max(2) - 1) as f64;
    let width = ((SMOOTHING_S / dt).round() as usize).max(1) | 1;
    let missing = |what: &str| Error::invalid(format!("{}: no {what}", recording.source));
    let channel = |name: &str| recording.channel(name).ok_or_else(|| missing(name));
    Ok(Some(match problem.model.base {
        Base::CurrentDriven => {
            let current = recording
                .input("I")
                .ok_or_else(|| missing("current input"))?;
            [smooth(channel("omega")?, width), smooth(current, width)]
        }
        Base::PositionLoop => {
            let gain = problem.model.motor.torque_constant;
            let controller: Vec<f64> = channel("force")?.iter().map(|f| f / gain).collect();
            let q = smooth(channel("q")?, width);
            [
                smooth(&derivative(&q, times), width),
                smooth(&controller, width),
            ]
        }
        Base::VoltageDriven => return Ok(None),
    }))
}

/// (speed, missing torque) at every sample of every record, for the model of `problem`.
fn samples(problem: &Problem) -> Result<Vec<(f64, f64)>, Error> {
    let mut out = Vec::new();
    for recording in &problem.recordings {
        let Some([speed, input]) = measured(problem, recording)? else {
            continue;
        };
        let acceleration = derivative(&speed, &recording.time);
        let model = problem.model_for(recording)?;
        let missing = model.missing_torque(&recording.time, &input, &speed, &acceleration);
        out.extend(speed.into_iter().zip(missing));
    }
    Ok(out)
}

/// Whether a drive base's records hold motion in both directions (measured speed beyond
/// [`MOVING_SHARE`] of its top on both sides of zero); `true` for the voltage-driven motor, whose
/// candidates this does not concern.
pub fn records_reverse(problem: &Problem) -> Result<bool, Error> {
    let mut speeds = Vec::new();
    for recording in &problem.recordings {
        match measured(problem, recording)? {
            Some([speed, _]) => speeds.extend(speed),
            None => return Ok(true),
        }
    }
    let top = speeds.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let moving = |sign: f64| speeds.iter().any(|v| v * sign > MOVING_SHARE * top);
    Ok(moving(1.0) && moving(-1.0))
}

/// The fingerprint and the binned curve of `fit`'s model (`none` for the model as given).
pub fn fingerprint(
    problem: &Problem,
    fit: &Candidate,
    label: &str,
) -> Result<Option<(StateFingerprint, MissingTorqueCurve)>, Error> {
    let base = problem.model.base;
    if !base.is_drive() {
        return Ok(None);
    }
    let model_problem = fit.fitted_problem();
    let points = samples(&model_problem)?;
    let top = points.iter().fold(0.0f64, |a, p| a.max(p.0.abs()));
    let moving: Vec<(f64, f64)> = points
        .iter()
        .copied()
        .filter(|p| p.0.abs() > MOVING_SHARE * top && p.1.is_finite())
        .collect();
    let reverses = moving.iter().any(|p| p.0 > 0.0) && moving.iter().any(|p| p.0 < 0.0);
    let columns = if reverses { 3 } else { 2 };
    let design = DMatrix::from_fn(moving.len(), columns, |i, j| match (j, reverses) {
        (0, true) => moving[i].0.signum(),
        (1, true) | (0, false) => moving[i].0,
        _ => 1.0,
    });
    let y = DVector::from_iterator(moving.len(), moving.iter().map(|p| p.1));
    let coefficients = design
        .clone()
        .svd(true, true)
        .solve(&y, 1e-12)
        .map_err(|e| Error::Numerical(e.to_string()))?;
    let residual = &y - &design * &coefficients;
    let n = moving.len().max(1) as f64;
    let rms = (y.norm_squared() / n).sqrt();
    let left = (residual.norm_squared() / n).sqrt();
    let (jump, slope, constant) = if reverses {
        (2.0 * coefficients[0], coefficients[1], coefficients[2])
    } else {
        (f64::NAN, coefficients[0], coefficients[1])
    };
    let (lo, hi) = moving
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
            (a.min(p.0), b.max(p.0))
        });
    let width = (hi - lo) / BINS as f64;
    let mut sums = vec![(0.0, 0.0, 0usize); BINS];
    for p in &points {
        let bin = ((p.0 - lo) / width).floor();
        if (0.0..BINS as f64).contains(&bin) && p.1.is_finite() {
            let s = &mut sums[bin as usize];
            *s = (s.0 + p.0, s.1 + p.1, s.2 + 1);
        }
    }
    let kept: Vec<(f64, f64)> = sums
        .iter()
        .filter(|s| s.2 >= 20)
        .map(|s| (s.0 / s.2 as f64, s.1 / s.2 as f64))
        .collect();
    Ok(Some((
        StateFingerprint {
            model: label.to_string(),
            jump_at_zero: jump,
            slope,
            constant,
            rms,
            explained: 1.0 - (left / rms).powi(2),
            reverses,
            torque_unit: base.unit("N·m").to_string(),
            speed_unit: base.unit("rad/s").to_string(),
        },
        MissingTorqueCurve {
            label: label.to_string(),
            speed: kept.iter().map(|k| k.0).collect(),
            torque: kept.iter().map(|k| k.1).collect(),
        },
    )))
}

/// What the fingerprint says, in words.
pub fn reading(f: &StateFingerprint) -> String {
    let unit = &f.torque_unit;
    let mut parts = Vec::new();
    if f.reverses {
        parts.push(format!(
            "a jump of {:.4} {unit} across zero speed",
            f.jump_at_zero
        ));
    }
    parts.push(format!(
        "a slope of {:.4e} {unit} per {}",
        f.slope, f.speed_unit
    ));
    parts.push(format!("a constant of {:.4} {unit}", f.constant));
    let mut text = format!(
        "missing torque against speed ({}): {} ({:.0}% of its {:.4} {unit} RMS)",
        f.model,
        parts.join(", "),
        100.0 * f.explained,
        f.rms
    );
    if !f.reverses {
        text.push_str(
            "; the records never reverse, so a jump at zero speed (Coulomb friction) and a \
             constant (a load torque) are the same torque here: a record in the other \
             direction separates them",
        );
    }
    text
}
