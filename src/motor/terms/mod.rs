//! Physics terms: pieces a model can switch on, each adding parameters (with support and a
//! default prior scaled by the model's own magnitudes), perhaps states, and a contribution to the
//! electrical equation, the mechanical equation or the measurement map.
//!
//! Every term is one file of the same shape: a struct holding its settings and an impl of
//! [`PhysicsTerm`], overriding only the hooks it contributes to. The right-hand side is generic
//! over dual numbers, which a trait object cannot carry, so [`Term`] dispatches by `match`; the
//! `terms!` list at the end of this file names each term once (`file::Struct`), and the macro
//! writes from it the module lines, the re-exports, that enum and its dispatch.

use super::Scalar;
use crate::parameter::{Prior, Support};

pub use super::input::InputSteps;

// Where the terms' files find what they amend and what their priors are scaled by; public, as
// these paths were before the balances and magnitudes had files of their own.
pub use super::balance::{Balance, Coefficients, Site};
pub use super::magnitudes::{Magnitudes, PRIOR_SHARE};

/// A parameter a term adds.
pub struct TermParam {
    pub key: &'static str,
    pub unit: &'static str,
    /// The value when the model file does not give one (an absent effect).
    pub default: f64,
    pub support: fn(&Magnitudes) -> Support,
    pub prior: fn(&Magnitudes) -> Prior,
}

/// A fixed setting of a term (not calibrated), e.g. the smoothing speed of Coulomb friction.
pub struct TermSetting {
    pub key: &'static str,
    pub unit: &'static str,
    pub default: f64,
    /// On a drive base, the default is instead this share of the record's largest speed: a
    /// smoothing speed must be small against the speeds the rig runs at, in whatever unit
    /// (1e-3 m/s on a ball screw, not 1 rad/s).
    pub speed_share: Option<f64>,
    /// A setting that names one of these (a channel): files write the name, the term gets its
    /// index as the value. Empty for a number.
    pub choices: &'static [&'static str],
}

/// Where a measurement is read: the sample's time and the input the drive applies then (the
/// voltage held then, or the constant parameter U; before any term shifts it), for a sensor
/// that reads the input or drifts with the time besides its own channel.
#[derive(Clone, Copy, Debug)]
pub struct Sample<D> {
    pub t: f64,
    pub voltage: D,
}

/// A state a term adds to the ODE, with its initial value.
pub struct TermState {
    pub name: &'static str,
    pub initial: f64,
}

/// One physics term. Hooks left at their defaults contribute nothing.
pub trait PhysicsTerm: Sized + Clone + std::fmt::Debug + PartialEq {
    const NAME: &'static str;
    /// The equation it adds, for help texts and the README.
    const EQUATION: &'static str;
    const PARAMS: &'static [TermParam];
    const SETTINGS: &'static [TermSetting] = &[];
    const STATES: &'static [TermState] = &[];
    /// Whether the term acts on the mechanical equation alone, so that it also applies to the
    /// drive bases, where the electrical equation and the current sensor are not modelled.
    const MECHANICAL: bool = false;
    /// Why a term that is not `MECHANICAL` does not apply to the drive bases, completing "term
    /// X … which a <base> model does not have".
    const NOT_ON_DRIVES: &'static str = "acts on the electrical equation or the current sensor";
    /// Whether a parameter is a time within the record (a switching time): such a term belongs
    /// to one record, and is not a candidate for several records at once, whose clocks are
    /// not one clock.
    const RECORD_TIME: bool = false;

    /// The term with its settings (in the order of `SETTINGS`), or why they are invalid.
    fn with_settings(settings: &[f64]) -> Result<Self, String>;
    fn settings(&self) -> Vec<f64> {
        Vec::new()
    }
    /// Why a parameter cannot be calibrated with these settings, if it cannot.
    fn check_calibrated(&self, _key: &str) -> Result<(), String> {
        Ok(())
    }
    /// Once per solve: rescale a constant of the model.
    fn adjust<D: Scalar>(&self, _params: &[D], _c: &mut Coefficients<D>) {}
    /// At every evaluation of the right-hand side.
    fn contribute<D: Scalar>(&self, _site: &Site<D>, _b: &mut Balance<D>) {}
    /// Derivatives of the term's own states, after every term has contributed.
    fn derivatives<D: Scalar>(&self, _site: &Site<D>, _b: &Balance<D>, _d: &mut [D]) {}
    /// The term's states at the start where they follow the base's initial state `base` (a
    /// filter settled on its channel); otherwise `STATES`' fixed values stand.
    fn initial<D: Scalar>(&self, _params: &[D], _base: &[D], _states: &mut [D]) {}
    /// Amends the input the base is driven with at time t (the supply voltage): `u` is its value
    /// there, `input` its whole history as steps, for a term that shifts it in time.
    fn input<D: Scalar>(&self, _params: &[D], _t: f64, _input: &InputSteps<D>, _u: &mut D) {}
    /// Amends the measured channels (I, ω); `states` are the term's own at that sample.
    fn measure<D: Scalar>(
        &self,
        _params: &[D],
        _states: &[D],
        _at: Sample<D>,
        _channels: &mut [D],
    ) {
    }
    /// Times at which the term makes the right-hand side jump, at nominal parameter values.
    fn breakpoints(&self, _params: &[f64]) -> Vec<f64> {
        Vec::new()
    }
    /// For a term whose one state lags a base state and feeds nothing back: that base state's
    /// index and the time constant, which the integrator then uses to advance the state in
    /// closed form ([`crate::ode::OdeSystem::exact_lags`]); `derivatives` leaves it at zero.
    fn exact_lag<D: Scalar>(&self, _params: &[D]) -> Option<(usize, D)> {
        None
    }
}

/// tanh that stays finite for dual numbers: num-dual computes it as sinh/cosh, which is ∞/∞
/// once |x| passes ~710 — and ω/ω_s does. Written with e^(−2|x|), which only underflows.
/// The branch is on the real part, so f64 and dual runs take the same one.
pub fn tanh<D: Scalar>(x: D) -> D {
    if x.re() >= 0.0 {
        let e = exp_below_one(x * -2.0);
        (-e + 1.0) / (e + 1.0)
    } else {
        let e = exp_below_one(x * 2.0);
        (e - 1.0) / (e + 1.0)
    }
}

/// e^y for y ≤ 0, with the zero it rounds to taken without libm: below y = −746 e^y is under
/// half the smallest subnormal, so `exp` returns 0 and its derivatives ε·0, which is what y·0
/// gives too (the value's zero may carry the other sign; it is only ever added to or divided
/// into a nonzero). libm reaches that zero by its slow path, through errno below −1024, and
/// sign(ω)'s tanh and the Stribeck hump ask for it on nearly every sample at speed: 5% of a
/// law's fit, by perf, on resonant_sensor-680020.
pub fn exp_below_one<D: Scalar>(y: D) -> D {
    if y.re() < -746.0 { y * 0.0 } else { y.exp() }
}

/// The logistic 1/(1 + e^(−x)), finite with its derivatives for any x (same reason as [`tanh`]).
pub fn logistic<D: Scalar>(x: D) -> D {
    if x.re() >= 0.0 {
        (exp_below_one(-x) + 1.0).recip()
    } else {
        let e = exp_below_one(x);
        e / (e + 1.0)
    }
}

/// Settings checked for a finite positive value: a smoothing width of 0 or NaN would divide by 0.
pub(crate) fn positive_setting(term: &str, key: &str, v: f64) -> Result<f64, String> {
    if v > 0.0 && v.is_finite() {
        Ok(v)
    } else {
        Err(format!("{term}.{key} = {v} must be a positive number"))
    }
}

/// Settings checked for a finite value (an angle, of either sign).
pub(crate) fn finite_setting(term: &str, key: &str, v: f64) -> Result<f64, String> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(format!("{term}.{key} = {v} must be a finite number"))
    }
}

/// A relative change of a constant (a factor 1 + k), dimensionless and of either sign.
pub(crate) const fn relative_param(key: &'static str) -> TermParam {
    TermParam {
        key,
        unit: "1",
        default: 0.0,
        support: real,
        prior: relative_prior,
    }
}

/// The default prior of a relative change (a factor 1 + k): one sd is a tenth.
pub(crate) fn relative_prior(_: &Magnitudes) -> Prior {
    Prior::Normal {
        mean: 0.0,
        sd: PRIOR_SHARE,
    }
}

pub(crate) fn real(_: &Magnitudes) -> Support {
    Support::Real
}

pub(crate) fn positive(_: &Magnitudes) -> Support {
    Support::Positive
}

// rustfmt does not follow modules a macro declares (rust-lang/rustfmt#3253), so `cargo fmt`
// leaves the term files as they are: format them with
// `rustfmt --edition 2024 src/motor/terms/*.rs`.
macro_rules! terms {
    // The library, then the terms beyond it (`;`): every term reads and writes alike, but only
    // the library's are named in `Term::NAMES`, the list diagnose screens and the case
    // generators draw effects from.
    ($($module:ident::$variant:ident),* $(,)? ; $($beyond:ident::$bvariant:ident),* $(,)?) => {
        terms!(@all [$($module::$variant),* , $($beyond::$bvariant),*] [$($variant),*]);
    };
    (@all [$($module:ident::$variant:ident),*] [$($library:ident),*]) => {
        $(
            mod $module;
            pub use $module::$variant;
        )*

        /// An active physics term with its settings.
        #[derive(Clone, Debug, PartialEq)]
        pub enum Term {
            $($variant($variant)),*
        }

        impl Term {
            /// The library's terms, in the canonical order in which models list them: what
            /// diagnose ranks and the case generators draw effects from.
            pub const NAMES: &'static [&'static str] = &[$(<$library as PhysicsTerm>::NAME),*];

            /// Every term a model file can name, the library's first: the canonical order.
            pub const ALL_NAMES: &'static [&'static str] =
                &[$(<$variant as PhysicsTerm>::NAME),*];

            /// A term by name with its settings (`None` for an unknown name).
            pub fn from_name(name: &str, settings: &[f64]) -> Option<Result<Term, String>> {
                $(if name == <$variant as PhysicsTerm>::NAME {
                    return Some($variant::with_settings(settings).map(Term::$variant));
                })*
                None
            }

            /// The parameters and settings a term of this name declares.
            pub fn declarations(
                name: &str,
            ) -> Option<(&'static [TermParam], &'static [TermSetting])> {
                $(if name == <$variant as PhysicsTerm>::NAME {
                    return Some((
                        <$variant as PhysicsTerm>::PARAMS,
                        <$variant as PhysicsTerm>::SETTINGS,
                    ));
                })*
                None
            }

            /// Place in [`Term::ALL_NAMES`].
            pub fn rank(&self) -> usize {
                Self::ALL_NAMES.iter().position(|n| *n == self.name()).unwrap_or(usize::MAX)
            }

            pub fn name(&self) -> &'static str {
                match self { $(Term::$variant(_) => <$variant as PhysicsTerm>::NAME),* }
            }

            pub fn equation(&self) -> &'static str {
                match self { $(Term::$variant(_) => <$variant as PhysicsTerm>::EQUATION),* }
            }

            pub fn params(&self) -> &'static [TermParam] {
                match self { $(Term::$variant(_) => <$variant as PhysicsTerm>::PARAMS),* }
            }

            pub fn setting_decls(&self) -> &'static [TermSetting] {
                match self { $(Term::$variant(_) => <$variant as PhysicsTerm>::SETTINGS),* }
            }

            pub fn mechanical(&self) -> bool {
                match self { $(Term::$variant(_) => <$variant as PhysicsTerm>::MECHANICAL),* }
            }

            pub fn not_on_drives(&self) -> &'static str {
                match self { $(Term::$variant(_) => <$variant as PhysicsTerm>::NOT_ON_DRIVES),* }
            }

            pub fn record_time(&self) -> bool {
                match self { $(Term::$variant(_) => <$variant as PhysicsTerm>::RECORD_TIME),* }
            }

            pub fn states(&self) -> &'static [TermState] {
                match self { $(Term::$variant(_) => <$variant as PhysicsTerm>::STATES),* }
            }

            pub fn settings(&self) -> Vec<f64> {
                match self { $(Term::$variant(t) => t.settings()),* }
            }

            pub fn check_calibrated(&self, key: &str) -> Result<(), String> {
                match self { $(Term::$variant(t) => t.check_calibrated(key)),* }
            }

            #[inline]
            pub fn adjust<D: Scalar>(&self, params: &[D], c: &mut Coefficients<D>) {
                match self { $(Term::$variant(t) => t.adjust(params, c)),* }
            }

            #[inline]
            pub fn contribute<D: Scalar>(&self, site: &Site<D>, b: &mut Balance<D>) {
                match self { $(Term::$variant(t) => t.contribute(site, b)),* }
            }

            #[inline]
            pub fn derivatives<D: Scalar>(&self, site: &Site<D>, b: &Balance<D>, d: &mut [D]) {
                match self { $(Term::$variant(t) => t.derivatives(site, b, d)),* }
            }

            #[inline]
            pub fn initial<D: Scalar>(&self, params: &[D], base: &[D], states: &mut [D]) {
                match self { $(Term::$variant(t) => t.initial(params, base, states)),* }
            }

            #[inline]
            pub fn input<D: Scalar>(
                &self,
                params: &[D],
                t: f64,
                input: &InputSteps<D>,
                u: &mut D,
            ) {
                match self { $(Term::$variant(t_) => t_.input(params, t, input, u)),* }
            }

            #[inline]
            pub fn measure<D: Scalar>(
                &self,
                params: &[D],
                states: &[D],
                at: Sample<D>,
                channels: &mut [D],
            ) {
                match self { $(Term::$variant(t) => t.measure(params, states, at, channels)),* }
            }

            pub fn breakpoints(&self, params: &[f64]) -> Vec<f64> {
                match self { $(Term::$variant(t) => t.breakpoints(params)),* }
            }

            pub fn exact_lag<D: Scalar>(&self, params: &[D]) -> Option<(usize, D)> {
                match self { $(Term::$variant(t) => t.exact_lag(params)),* }
            }
        }
    };
}

terms!(
    torque_constant::TorqueConstant,
    back_emf_constant::BackEmfConstant,
    viscous_friction::ViscousFriction,
    coulomb_friction::CoulombFriction,
    quadratic_drag::QuadraticDrag,
    load_torque::LoadTorque,
    load_step::LoadStep,
    voltage_drop::VoltageDrop,
    resistance_heating::ResistanceHeating,
    armature_reaction::ArmatureReaction,
    input_delay::InputDelay,
    compliant_coupling::CompliantCoupling,
    // Before the sensors' offset and gain: the filter's output is what they then amend.
    sensor_lag::SensorLag,
    current_offset::CurrentOffset,
    speed_gain::SpeedGain,
    asymmetric_friction::AsymmetricFriction;
    // Beyond the library: a law of the state written from the dictionary, found by the
    // unexplained verdict's state fingerprint, never screened.
    law::Law,
);

impl Term {
    /// The term with its default settings.
    pub fn named(name: &str) -> Option<Term> {
        Term::named_for(name, None)
    }

    /// The term with its default settings for a rig whose largest speed is `speed_scale` (a
    /// drive base), or the fixed defaults (`None`).
    pub fn named_for(name: &str, speed_scale: Option<f64>) -> Option<Term> {
        let (_, settings) = Term::declarations(name)?;
        let defaults: Vec<f64> = settings
            .iter()
            .map(|s| match (s.speed_share, speed_scale) {
                (Some(share), Some(speed)) if speed > 0.0 && speed.is_finite() => share * speed,
                _ => s.default,
            })
            .collect();
        Term::from_name(name, &defaults).and_then(|t| t.ok())
    }
}

#[cfg(test)]
mod tests {
    use super::exp_below_one;
    use num_dual::{Dual64, DualNum};

    /// The shortcut is exp itself, value and derivative, bit for bit: across libm's subnormal
    /// range, through its underflow to zero and past its errno path below −1024.
    #[test]
    fn exp_below_one_is_exp_bit_for_bit_with_its_derivative() {
        let mut y = -1100.0;
        while y <= 0.0 {
            for slope in [1.0, -3.0] {
                let x = Dual64::new(y, slope);
                let (fast, libm) = (exp_below_one(x), x.exp());
                assert_eq!(fast.re, libm.re, "e^{y}");
                assert_eq!(fast.eps.to_bits(), libm.eps.to_bits(), "d e^{y}");
            }
            y += 0.37;
        }
    }
}
