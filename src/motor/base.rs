//! The physics the terms are added to: the voltage-driven motor of the paper, or a drive that
//! closes the electrical loop itself, and what each measures in which unit.

use super::Term;

/// The channels the motor's measurement map produces, in output order.
pub const MOTOR_CHANNELS: [&str; 2] = ["I", "omega"];

/// The channels of the drive bases.
pub const CURRENT_DRIVEN_CHANNELS: [&str; 1] = ["omega"];
pub const POSITION_LOOP_CHANNELS: [&str; 2] = ["q", "force"];
const DRIVE_STATES: [&str; 2] = ["q", "omega"];

/// The physics the terms are added to.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Base {
    /// L dI/dt = U − R I − c_m ω, J dω/dt = c_g I − d ω, measuring I and ω (eqs. 3–4).
    #[default]
    VoltageDriven,
    /// J dω/dt = c_g·I − d ω with the recorded current I as input (the drive closes the current
    /// loop), measuring ω.
    CurrentDriven,
    /// The same mechanics on a linear axis (J is a mass, c_g a force per volt) inside a sampled
    /// position/velocity cascade driven by a reference position; measures q and the force.
    PositionLoop,
}

impl Base {
    pub const ALL: [Base; 3] = [Base::VoltageDriven, Base::CurrentDriven, Base::PositionLoop];

    pub fn name(&self) -> &'static str {
        match self {
            Base::VoltageDriven => "voltage_driven",
            Base::CurrentDriven => "current_driven",
            Base::PositionLoop => "position_loop",
        }
    }

    /// The unit of one of the base's channels.
    pub fn channel_unit(&self, channel: &str) -> &'static str {
        match channel {
            "I" => "A",
            "omega" => self.unit("rad/s"),
            "q" => self.unit("rad"),
            "force" => self.unit("N·m"),
            _ => "",
        }
    }

    /// Whether a drive closes the electrical loop (the recorded input drives the mechanics).
    pub fn is_drive(&self) -> bool {
        *self != Base::VoltageDriven
    }

    /// Whether a term applies to this base.
    pub fn accepts(&self, term: &Term) -> bool {
        !self.is_drive() || term.mechanical()
    }

    /// A unit as this base reads it: a linear axis has N for N·m, m for rad, kg for kg·m².
    pub fn unit(&self, unit: &'static str) -> &'static str {
        if *self != Base::PositionLoop {
            return unit;
        }
        match unit {
            "kg·m²" => "kg",
            "N·m/A" => "N/V",
            "N·m" => "N",
            "N·m·s/rad" => "N·s/m",
            "N·m·s²/rad²" => "N·s²/m²",
            "rad/s" => "m/s",
            "rad" => "m",
            "A" => "V",
            other => other,
        }
    }

    pub fn from_name(name: &str) -> Option<Base> {
        Base::ALL.into_iter().find(|b| b.name() == name)
    }

    pub fn state_names(&self) -> &'static [&'static str] {
        match self {
            Base::VoltageDriven => &MOTOR_CHANNELS,
            Base::CurrentDriven | Base::PositionLoop => &DRIVE_STATES,
        }
    }

    pub fn channels(&self) -> &'static [&'static str] {
        match self {
            Base::VoltageDriven => &MOTOR_CHANNELS,
            Base::CurrentDriven => &CURRENT_DRIVEN_CHANNELS,
            Base::PositionLoop => &POSITION_LOOP_CHANNELS,
        }
    }

    /// The recorded input that drives the base: the voltage `U`, the current `I` a drive is
    /// commanded, or a position loop's reference `q_ref` (what a record carries, an input file
    /// plays back and `design` writes).
    pub fn input(&self) -> &'static str {
        match self {
            Base::VoltageDriven => "U",
            Base::CurrentDriven => "I",
            Base::PositionLoop => "q_ref",
        }
    }
}
