//! The scales of a model and the default priors drawn to them: what a "small" or "large" value
//! of a parameter means for this machine and this record.

use super::{MotorModel, MotorParam, VoltageInput};
use crate::parameter::{ParamId, ParameterSpec, Prior, Support};

/// The scales of a model, from its nominal values and the record's length: what a "small" or
/// "large" value of a term's parameter means for this machine. A default prior puts one
/// standard deviation at an effect of a tenth of the scale it acts on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Magnitudes {
    /// The largest supply voltage |U| [V].
    pub voltage: f64,
    /// Stall current U/R [A].
    pub current: f64,
    /// No-load speed U/c_m [rad/s].
    pub speed: f64,
    /// Stall torque c_g·U/R [N·m].
    pub torque: f64,
    /// Heat of a start-up: (U²/R) times the mechanical time constant J·R/(c_g·c_m) [J].
    pub energy: f64,
    /// Length of the recording [s].
    pub duration: f64,
    /// The electrical time constant L/R [s]: how fast the current follows the voltage.
    pub electrical_time: f64,
    /// The mechanical time constant J·R/(c_g·c_m) [s]: how fast the speed settles.
    pub mechanical_time: f64,
}

/// The share of a magnitude one prior standard deviation stands for.
pub const PRIOR_SHARE: f64 = 0.1;

impl MotorModel {
    /// The scales the default priors are drawn to, for a recording of the given length.
    pub fn magnitudes(&self, duration: f64) -> Magnitudes {
        let m = &self.nominal;
        let sane = |v: f64| if v.is_finite() && v > 0.0 { v } else { 1.0 };
        if let Some(drive) = &self.drive {
            // What the drive can deliver (c_g times its input limit) plays the stall torque's
            // part, the record's largest speed the no-load speed's.
            let current = sane(drive.input_scale());
            let torque = sane(m.torque_constant * current);
            let speed = sane(drive.speed_scale);
            // The time the drive's full torque takes to reach the record's largest speed; the
            // electrical loop is the drive's, faster than anything the record resolves.
            let mechanical_time = sane(m.inertia * speed / torque);
            return Magnitudes {
                voltage: 1.0,
                current,
                speed,
                torque,
                energy: sane(torque * speed * duration),
                duration: sane(duration),
                electrical_time: mechanical_time,
                mechanical_time,
            };
        }
        let held_max = match &self.input {
            VoltageInput::Constant => m.voltage.abs(),
            VoltageInput::Held { values, .. } => values.iter().fold(0.0f64, |a, v| a.max(v.abs())),
        };
        // A degenerate nominal model (U = 0, c_m = 0) would give zero or infinite scales; one
        // unit is then as good a scale as any, and finite.
        let voltage = sane(held_max);
        let current = sane(voltage / m.resistance);
        let speed = sane(voltage / m.back_emf_constant);
        let torque = sane(m.torque_constant * current);
        let time_constant =
            sane(m.inertia * m.resistance / (m.torque_constant * m.back_emf_constant));
        Magnitudes {
            voltage,
            current,
            speed,
            torque,
            energy: sane(voltage * voltage / m.resistance * time_constant),
            duration: sane(duration),
            electrical_time: sane(m.inductance / m.resistance),
            mechanical_time: time_constant,
        }
    }

    /// Every parameter with its unit, support and default prior (scaled by `magnitudes`).
    pub fn parameter_specs(&self, magnitudes: &Magnitudes) -> Vec<ParameterSpec> {
        let mut specs: Vec<ParameterSpec> = MotorParam::ALL
            .iter()
            .map(|&p| {
                let spec = base_spec(p, self.nominal.get(p), magnitudes);
                ParameterSpec {
                    unit: self.base.unit(spec.unit),
                    ..spec
                }
            })
            .collect();
        for t in &self.terms {
            for (decl, &value) in t.term.params().iter().zip(&t.values) {
                specs.push(ParameterSpec {
                    id: ParamId::of_term(t.term.name(), decl.key),
                    unit: self.base.unit(decl.unit),
                    nominal: value,
                    support: (decl.support)(magnitudes),
                    default_prior: (decl.prior)(magnitudes),
                });
            }
        }
        specs
    }
}

/// The base parameters' supports and default priors: R keeps the paper's N(R₀, 0.2R₀); the
/// other positive constants a log-normal of 20% around their nominal value; signed quantities
/// a normal of a tenth of the scale they act on.
fn base_spec(p: MotorParam, nominal: f64, m: &Magnitudes) -> ParameterSpec {
    use MotorParam::*;
    let normal = |sd: f64| Prior::Normal { mean: nominal, sd };
    let (support, default_prior) = match p {
        Resistance => (Support::Positive, normal(0.2 * nominal)),
        BackEmfConstant | TorqueConstant | Inductance | Inertia => (
            Support::Positive,
            Prior::LogNormal {
                median: nominal,
                sigma: 0.2,
            },
        ),
        ViscousFriction if nominal > 0.0 => (
            Support::Positive,
            Prior::LogNormal {
                median: nominal,
                sigma: 0.2,
            },
        ),
        ViscousFriction => (
            Support::Positive,
            Prior::HalfNormal {
                scale: PRIOR_SHARE * m.torque / m.speed,
            },
        ),
        Voltage => (Support::Real, normal(PRIOR_SHARE * m.voltage)),
        InitialCurrent => (Support::Real, normal(PRIOR_SHARE * m.current)),
        InitialSpeed => (Support::Real, normal(PRIOR_SHARE * m.speed)),
        // What a speed covers in a mechanical time constant: wide against a sample's noise,
        // which is all the offset is there to hold.
        InitialPositionOffset => (
            Support::Real,
            normal(PRIOR_SHARE * m.speed * m.mechanical_time),
        ),
    };
    ParameterSpec {
        id: ParamId::base(p.key()),
        unit: p.unit(),
        nominal,
        support,
        default_prior,
    }
}
