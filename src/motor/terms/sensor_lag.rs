//! A sensor that lags: the measured channel (I or ω, the setting `channel`) is its true value
//! through a first-order filter of time constant τ, τ·dy/dt = x − y, with y a new state that
//! starts settled on the channel (y(0) = x(0)). τ = 0 is the sensor without lag: y is then not
//! advanced and the channel is measured as it is. y feeds nothing back, so the integrator
//! advances it in closed form from the channel's dense output ([`crate::ode::ExactLag`]).

use super::{
    Balance, Magnitudes, PRIOR_SHARE, PhysicsTerm, Sample, Site, TermParam, TermSetting, TermState,
    positive,
};
use crate::motor::Scalar;
use crate::parameter::Prior;

/// The channels a lag can filter, in the order of the voltage-driven base's states.
const CHANNELS: &[&str] = &["I", "omega"];

#[derive(Clone, Debug, PartialEq)]
pub struct SensorLag {
    /// The filtered channel: 0 for I, 1 for ω.
    pub channel: usize,
}

/// One sd: a tenth of the mechanical time constant (the speed's; on I, the electrical time
/// constant L/R is the scale, which a `[calibrate]` prior can say).
fn prior(m: &Magnitudes) -> Prior {
    Prior::HalfNormal {
        scale: PRIOR_SHARE * m.mechanical_time,
    }
}

impl PhysicsTerm for SensorLag {
    const NAME: &'static str = "sensor_lag";
    const EQUATION: &'static str = "measured x = y, τ·dy/dt = x − y, y(0) = x(0) (x = I or ω)";
    const NOT_ON_DRIVES: &'static str =
        "filters faster than the steps fixed to a drive base's samples resolve";
    const PARAMS: &'static [TermParam] = &[TermParam {
        key: "tau",
        unit: "s",
        default: 0.0,
        support: positive,
        prior,
    }];
    const SETTINGS: &'static [TermSetting] = &[TermSetting {
        key: "channel",
        unit: "",
        default: 1.0,
        speed_share: None,
        choices: CHANNELS,
    }];
    const STATES: &'static [TermState] = &[TermState {
        name: "y",
        initial: 0.0,
    }];

    fn with_settings(s: &[f64]) -> Result<Self, String> {
        match s[0] {
            0.0 => Ok(Self { channel: 0 }),
            1.0 => Ok(Self { channel: 1 }),
            v => Err(format!(
                "sensor_lag.channel = {v} must name a channel: \"I\" or \"omega\""
            )),
        }
    }

    fn settings(&self) -> Vec<f64> {
        vec![self.channel as f64]
    }

    fn initial<D: Scalar>(&self, _: &[D], base: &[D], states: &mut [D]) {
        states[0] = base[self.channel];
    }

    /// y is advanced in closed form by the integrator (`exact_lag`): an explicit step would
    /// have to stay within a few τ, and a fit walking τ toward zero would take tens of
    /// thousands of steps per solve. So its derivative here stays zero.
    fn derivatives<D: Scalar>(&self, _: &Site<D>, _: &Balance<D>, d: &mut [D]) {
        d[0] = D::from(0.0);
    }

    fn exact_lag<D: Scalar>(&self, params: &[D]) -> Option<(usize, D)> {
        (params[0].re() > 0.0).then_some((self.channel, params[0]))
    }

    fn measure<D: Scalar>(&self, params: &[D], states: &[D], _: Sample<D>, channels: &mut [D]) {
        if params[0].re() > 0.0 {
            channels[self.channel] = states[0];
        }
    }
}
