//! The motor's physical parameters (§2.1 of the paper) and their file keys.

use serde::{Deserialize, Serialize};

use super::Base;

/// One physical parameter of the motor; the discriminant is its place in the parameter vector.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MotorParam {
    Resistance = 0,
    BackEmfConstant,
    TorqueConstant,
    Voltage,
    ViscousFriction,
    Inductance,
    Inertia,
    InitialCurrent,
    InitialSpeed,
    /// A position loop's initial position, as an offset from the record's first measured q
    /// (which carries that sample's noise): 0 takes the sample as it is.
    InitialPositionOffset,
}

impl MotorParam {
    pub const ALL: [MotorParam; 10] = [
        MotorParam::Resistance,
        MotorParam::BackEmfConstant,
        MotorParam::TorqueConstant,
        MotorParam::Voltage,
        MotorParam::ViscousFriction,
        MotorParam::Inductance,
        MotorParam::Inertia,
        MotorParam::InitialCurrent,
        MotorParam::InitialSpeed,
        MotorParam::InitialPositionOffset,
    ];

    /// The key in model files and in output column names (the paper's symbols).
    pub fn key(self) -> &'static str {
        match self {
            MotorParam::Resistance => "R",
            MotorParam::BackEmfConstant => "c_m",
            MotorParam::TorqueConstant => "c_g",
            MotorParam::Voltage => "U",
            MotorParam::ViscousFriction => "d",
            MotorParam::Inductance => "L",
            MotorParam::Inertia => "J",
            MotorParam::InitialCurrent => "I0",
            MotorParam::InitialSpeed => "omega0",
            MotorParam::InitialPositionOffset => "q0_offset",
        }
    }

    pub fn unit(self) -> &'static str {
        match self {
            MotorParam::Resistance => "Ω",
            MotorParam::BackEmfConstant => "V·s/rad",
            MotorParam::TorqueConstant => "N·m/A",
            MotorParam::Voltage => "V",
            MotorParam::ViscousFriction => "N·m·s/rad",
            MotorParam::Inductance => "H",
            MotorParam::Inertia => "kg·m²",
            MotorParam::InitialCurrent => "A",
            MotorParam::InitialSpeed => "rad/s",
            MotorParam::InitialPositionOffset => "m",
        }
    }

    pub fn from_key(key: &str) -> Option<MotorParam> {
        MotorParam::ALL.into_iter().find(|p| p.key() == key)
    }

    /// The one base a parameter belongs to (`None`: every base's): a position loop's initial
    /// offset, which no other base has a measured position for.
    pub fn only_on(self) -> Option<Base> {
        match self {
            MotorParam::InitialPositionOffset => Some(Base::PositionLoop),
            _ => None,
        }
    }

    /// Parameters that divide the right-hand side or are physically positive.
    pub fn must_be_positive(self) -> bool {
        matches!(
            self,
            MotorParam::Resistance | MotorParam::Inductance | MotorParam::Inertia
        )
    }
}

/// The nominal motor: what the user believes. Missing keys in a model file take §2.1's values.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MotorParameters {
    /// Armature (cable harness) resistance R [Ω].
    #[serde(rename = "R")]
    pub resistance: f64,
    /// Back-EMF constant c_m [V·s/rad].
    #[serde(rename = "c_m")]
    pub back_emf_constant: f64,
    /// Torque constant c_g [N·m/A].
    #[serde(rename = "c_g")]
    pub torque_constant: f64,
    /// Supply voltage U [V] when no voltage series is recorded.
    #[serde(rename = "U")]
    pub voltage: f64,
    /// Viscous friction d [N·m·s/rad].
    #[serde(rename = "d")]
    pub viscous_friction: f64,
    /// Inductance L [H].
    #[serde(rename = "L")]
    pub inductance: f64,
    /// Rotor inertia J [kg·m²].
    #[serde(rename = "J")]
    pub inertia: f64,
    /// Constant load torque T_L [N·m], opposing motion: the key of schema-1 files, read as the
    /// `load_torque` term's T_0 (not a parameter of the base model).
    #[serde(rename = "T_L")]
    pub load_torque: f64,
    /// Initial current I(0) [A].
    #[serde(rename = "I0")]
    pub initial_current: f64,
    /// Initial speed ω(0) [rad/s].
    #[serde(rename = "omega0")]
    pub initial_speed: f64,
    /// A position loop's initial position less the record's first measured q [m].
    #[serde(rename = "q0_offset")]
    pub initial_position_offset: f64,
}

impl Default for MotorParameters {
    /// §2.1: R₀ = 0.1, c_m = c_g = 0.01, U = 24, d = 1e-6, L = 1e-4, J = 5e-5, started from rest
    /// without load.
    fn default() -> Self {
        Self {
            resistance: 0.1,
            back_emf_constant: 0.01,
            torque_constant: 0.01,
            voltage: 24.0,
            viscous_friction: 1e-6,
            inductance: 1e-4,
            inertia: 5e-5,
            load_torque: 0.0,
            initial_current: 0.0,
            initial_speed: 0.0,
            initial_position_offset: 0.0,
        }
    }
}

impl MotorParameters {
    /// The paper's simulation model G_φ with φ = 0.9 (§2.4): the torque constant is 10% low.
    pub fn paper_simulation_model() -> Self {
        Self {
            torque_constant: 0.009,
            ..Self::default()
        }
    }

    pub fn get(&self, p: MotorParam) -> f64 {
        match p {
            MotorParam::Resistance => self.resistance,
            MotorParam::BackEmfConstant => self.back_emf_constant,
            MotorParam::TorqueConstant => self.torque_constant,
            MotorParam::Voltage => self.voltage,
            MotorParam::ViscousFriction => self.viscous_friction,
            MotorParam::Inductance => self.inductance,
            MotorParam::Inertia => self.inertia,
            MotorParam::InitialCurrent => self.initial_current,
            MotorParam::InitialSpeed => self.initial_speed,
            MotorParam::InitialPositionOffset => self.initial_position_offset,
        }
    }

    pub fn set(&mut self, p: MotorParam, value: f64) {
        let slot = match p {
            MotorParam::Resistance => &mut self.resistance,
            MotorParam::BackEmfConstant => &mut self.back_emf_constant,
            MotorParam::TorqueConstant => &mut self.torque_constant,
            MotorParam::Voltage => &mut self.voltage,
            MotorParam::ViscousFriction => &mut self.viscous_friction,
            MotorParam::Inductance => &mut self.inductance,
            MotorParam::Inertia => &mut self.inertia,
            MotorParam::InitialCurrent => &mut self.initial_current,
            MotorParam::InitialSpeed => &mut self.initial_speed,
            MotorParam::InitialPositionOffset => &mut self.initial_position_offset,
        };
        *slot = value;
    }

    /// Physical plausibility: every value finite, R, L and J positive.
    pub fn validate(&self) -> Result<(), String> {
        if !self.load_torque.is_finite() {
            return Err(format!("T_L = {} is not a finite number", self.load_torque));
        }
        for p in MotorParam::ALL {
            let v = self.get(p);
            if !v.is_finite() {
                return Err(format!("{} = {v} is not a finite number", p.key()));
            }
            if p.must_be_positive() && v <= 0.0 {
                return Err(format!("{} = {v} must be positive", p.key()));
            }
        }
        Ok(())
    }
}
