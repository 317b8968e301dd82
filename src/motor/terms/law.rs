//! A law of the state found beyond the library: Σ c·f(state, input) added to the torque balance
//! (J dω/dt), to the voltage balance (L dI/dt), or to what is read of a channel (measured I or
//! ω: a sensor's law, evaluated on the channels as the sensors before it read them), the
//! functions f from the fixed dictionary of `motor::dictionary`. Every (balance, function) pair
//! is a parameter (default 0: absent), but only the pairs the law lists are active: evaluated,
//! written to the model file and calibrated. Three states follow the record for the functions that need them: the charge
//! ∫|I|dt, the heat ∫R·I²dt and the angle θ = ∫ω dt, each integrated only when a listed function
//! reads it (a state left constant leaves the integrator's steps as they were).
//!
//! Not screened: the unexplained verdict's state fingerprint names the functions, and
//! `discover::named` fits the law from its estimate.

use super::{
    Balance, Magnitudes, PRIOR_SHARE, PhysicsTerm, Sample, Site, TermParam, TermSetting, TermState,
    finite_setting, positive_setting, real,
};
use crate::motor::Scalar;
use crate::motor::dictionary::{
    self, CURRENT_LIMIT, FADE, N_FUNCTIONS, ODE_BALANCES, OMEGA_SPOT, Point, SPEED_LIMIT, STEP,
    STRIBECK, Shapes,
};
use crate::parameter::Prior;

#[derive(Clone, Debug, PartialEq)]
pub struct Law {
    /// The active coefficients, indices into `PARAMS`, ascending.
    pub active: Vec<usize>,
    pub shapes: Shapes,
}

impl Law {
    /// The law with these coefficients active (indices into its parameters).
    pub fn with_active(mut self, mut active: Vec<usize>) -> Self {
        active.sort_unstable();
        active.dedup();
        self.active = active;
        self
    }

    /// Whether the law holds a function of time's frequency f (`frequency`) or of the angle's
    /// harmonic k (not).
    pub fn reads(&self, frequency: bool) -> bool {
        self.active.iter().any(|k| {
            let f = k % N_FUNCTIONS;
            if frequency {
                dictionary::reads_frequency(f)
            } else {
                dictionary::reads_harmonic(f)
            }
        })
    }

    /// Whether the law holds any of the functions `fs` (dictionary indices), in any balance.
    fn holds(&self, fs: &[usize]) -> bool {
        self.active.iter().any(|k| fs.contains(&(k % N_FUNCTIONS)))
    }

    /// The law with `more`'s functions as well; a shape (ω_s, k, f, I_lim, a spot, τ, t_s, ω_lim)
    /// that it has no function of is taken from `more` (a law has one of each).
    pub fn extended(&self, more: &Law) -> Law {
        let mut law = self
            .clone()
            .with_active(self.active.iter().chain(&more.active).copied().collect());
        let (s, m) = (&mut law.shapes, &more.shapes);
        let takes = |fs: &[usize]| !self.holds(fs) && more.holds(fs);
        if takes(&[STRIBECK]) {
            s.omega_s = m.omega_s;
        }
        if !self.reads(false) && more.reads(false) {
            s.harmonic = m.harmonic;
        }
        if !self.reads(true) && more.reads(true) {
            s.frequency = m.frequency;
        }
        if takes(&[CURRENT_LIMIT]) {
            s.current_limit = m.current_limit;
        }
        if takes(&[OMEGA_SPOT]) {
            (s.spot_angle, s.spot_width) = (m.spot_angle, m.spot_width);
        }
        if takes(&[FADE]) {
            s.fade = m.fade;
        }
        if takes(&[STEP]) {
            s.instant = m.instant;
        }
        if takes(&[SPEED_LIMIT]) {
            s.speed_limit = m.speed_limit;
        }
        law
    }

    /// Whether a function of the active set needs state `s` (0 charge, 1 heat, 2 θ).
    fn needs(&self, s: usize) -> bool {
        self.active
            .iter()
            .any(|&k| dictionary::state_of(k % N_FUNCTIONS) == Some(s))
    }
}

/// The share of the balance's scale one sd of a law's coefficient stands for: the whole of it.
/// A library term's prior (`PRIOR_SHARE`, a tenth) says how far a known effect may stray from
/// its nominal size; a law stands for what the model lacks, whose size nothing in the model
/// foretells short of the balance's own scale. At a tenth (0.02 N·m on a 2-V record of the
/// paper's motor) the slow bearing ripples of a tenth of a newton-metre came out small:
/// bearing_defect-620005's law printed 0.0507·sin + −0.111·cos against the truth's 0.116 and
/// −0.132, its intervals missing both; at the whole scale it prints 0.140 and −0.133, and they
/// hold them.
const LAW_PRIOR_SHARE: f64 = 10.0 * PRIOR_SHARE;

/// One sd: the balance's scale (stall torque, supply voltage; the current and the speed scales
/// for what is read of them) over the size the function typically takes on this machine and
/// record.
fn prior<const K: usize>(m: &Magnitudes) -> Prior {
    let scale = [m.torque, m.voltage, m.current, m.speed][K / N_FUNCTIONS];
    let size = dictionary::typical_size(K % N_FUNCTIONS, m);
    let size = if size.is_finite() && size > 0.0 {
        size
    } else {
        1.0
    };
    Prior::Normal {
        mean: 0.0,
        sd: LAW_PRIOR_SHARE * scale / size,
    }
}

/// Each function of the dictionary (in its order) with its coefficient's unit in the torque
/// balance, the voltage balance, what is read of I and of ω: the torque coefficients, then the
/// voltage ones, then the measured channels'.
macro_rules! coefficients {
    ($($k:literal $name:literal $torque:literal $voltage:literal $current:literal $speed:literal),*
     $(,)?) => {
        &[
            $(TermParam {
                key: concat!("torque:", $name),
                unit: $torque,
                default: 0.0,
                support: real,
                prior: prior::<$k>,
            },)*
            $(TermParam {
                key: concat!("voltage:", $name),
                unit: $voltage,
                default: 0.0,
                support: real,
                prior: prior::<{ $k + N_FUNCTIONS }>,
            },)*
            $(TermParam {
                key: concat!("measurement:I:", $name),
                unit: $current,
                default: 0.0,
                support: real,
                prior: prior::<{ $k + 2 * N_FUNCTIONS }>,
            },)*
            $(TermParam {
                key: concat!("measurement:omega:", $name),
                unit: $speed,
                default: 0.0,
                support: real,
                prior: prior::<{ $k + 3 * N_FUNCTIONS }>,
            },)*
        ]
    };
}

impl PhysicsTerm for Law {
    const NAME: &'static str = "law";
    const EQUATION: &'static str =
        "J dω/dt += Σ c·f(ω, I, U, t, q, E, θ) and/or L dI/dt += Σ c·f(…), f from the dictionary";
    const NOT_ON_DRIVES: &'static str =
        "is written for the voltage-driven motor's two balances (a drive base's law is not yet)";
    const PARAMS: &'static [TermParam] = coefficients!(
        0 "omega" "N·m·s/rad" "V·s/rad" "A·s/rad" "1",
        1 "omega*|omega|" "N·m·s²/rad²" "V·s²/rad²" "A·s²/rad²" "s/rad",
        2 "omega^3" "N·m·s³/rad³" "V·s³/rad³" "A·s³/rad³" "s²/rad²",
        3 "sign(omega)" "N·m" "V" "A" "rad/s",
        4 "exp(-(omega/omega_s)^2)*sign(omega)" "N·m" "V" "A" "rad/s",
        5 "I" "N·m/A" "Ω" "1" "rad/(s·A)",
        6 "|I|" "N·m/A" "Ω" "1" "rad/(s·A)",
        7 "I*|I|" "N·m/A²" "V/A²" "1/A" "rad/(s·A²)",
        8 "sign(omega)*|I|" "N·m/A" "Ω" "1" "rad/(s·A)",
        9 "U" "N·m/V" "1" "S" "rad/(s·V)",
        10 "charge" "N·m/(A·s)" "V/(A·s)" "1/s" "rad/(s²·A)",
        11 "heat" "N·m/J" "V/J" "A/J" "rad/(s·J)",
        12 "t" "N·m/s" "V/s" "A/s" "rad/s²",
        13 "sin(k*theta)" "N·m" "V" "A" "rad/s",
        14 "cos(k*theta)" "N·m" "V" "A" "rad/s",
        15 "sin(2*pi*f*t)" "N·m" "V" "A" "rad/s",
        16 "cos(2*pi*f*t)" "N·m" "V" "A" "rad/s",
        17 "U*charge" "N·m/(V·A·s)" "1/(A·s)" "1/(V·s)" "rad/(s²·V·A)",
        18 "omega*heat" "N·m·s/(rad·J)" "V·s/(rad·J)" "A·s/(rad·J)" "1/J",
        19 "I*heat" "N·m/(A·J)" "Ω/J" "1/J" "rad/(s·A·J)",
        20 "sign(I)*max(|I|-I_lim,0)" "N·m/A" "Ω" "1" "rad/(s·A)",
        21 "theta" "N·m/rad" "V/rad" "A/rad" "1/s",
        22 "1" "N·m" "V" "A" "rad/s",
        23 "I*sin(k*theta)" "N·m/A" "Ω" "1" "rad/(s·A)",
        24 "I*cos(k*theta)" "N·m/A" "Ω" "1" "rad/(s·A)",
        25 "U*sin(2*pi*f*t)" "N·m/V" "1" "S" "rad/(s·V)",
        26 "U*cos(2*pi*f*t)" "N·m/V" "1" "S" "rad/(s·V)",
        27 "omega*sin(k*theta)" "N·m·s/rad" "V·s/rad" "A·s/rad" "1",
        28 "omega*cos(k*theta)" "N·m·s/rad" "V·s/rad" "A·s/rad" "1",
        29 "omega*exp(-2*(1-cos(theta-theta_0))/w^2)" "N·m·s/rad" "V·s/rad" "A·s/rad" "1",
        30 "exp(-t/tau)" "N·m" "V" "A" "rad/s",
        31 "step(t-t_s)" "N·m" "V" "A" "rad/s",
        32 "sign(omega)*max(|omega|-omega_lim,0)" "N·m·s/rad" "V·s/rad" "A·s/rad" "1",
        33 "sign(I)" "N·m" "V" "A" "rad/s",
        34 "sign(omega)*heat" "N·m/J" "V/J" "A/J" "rad/(s·J)",
    );
    const SETTINGS: &'static [TermSetting] = &[
        TermSetting {
            key: "omega_smooth",
            unit: "rad/s",
            default: 1.0,
            speed_share: Some(0.01),
            choices: &[],
        },
        TermSetting {
            key: "omega_s",
            unit: "rad/s",
            default: 50.0,
            speed_share: None,
            choices: &[],
        },
        TermSetting {
            key: "f",
            unit: "Hz",
            default: 50.0,
            speed_share: None,
            choices: &[],
        },
        TermSetting {
            key: "k",
            unit: "1/rev",
            default: 1.0,
            speed_share: None,
            choices: &[],
        },
        TermSetting {
            key: "I_lim",
            unit: "A",
            default: 100.0,
            speed_share: None,
            choices: &[],
        },
        TermSetting {
            key: "theta_0",
            unit: "rad",
            default: 0.0,
            speed_share: None,
            choices: &[],
        },
        TermSetting {
            key: "w",
            unit: "rad",
            default: 0.5,
            speed_share: None,
            choices: &[],
        },
        TermSetting {
            key: "tau",
            unit: "s",
            default: 0.05,
            speed_share: None,
            choices: &[],
        },
        TermSetting {
            key: "t_s",
            unit: "s",
            default: 0.25,
            speed_share: None,
            choices: &[],
        },
        TermSetting {
            key: "omega_lim",
            unit: "rad/s",
            default: 2000.0,
            speed_share: None,
            choices: &[],
        },
        // As the library's voltage drop smooths the current's sign.
        TermSetting {
            key: "I_s",
            unit: "A",
            default: 1.0,
            speed_share: None,
            choices: &[],
        },
    ];
    const STATES: &'static [TermState] = &[
        TermState {
            name: "charge",
            initial: 0.0,
        },
        TermState {
            name: "heat",
            initial: 0.0,
        },
        TermState {
            name: "theta",
            initial: 0.0,
        },
    ];

    fn with_settings(s: &[f64]) -> Result<Self, String> {
        Ok(Self {
            active: Vec::new(),
            shapes: Shapes {
                omega_smooth: positive_setting(Self::NAME, "omega_smooth", s[0])?,
                omega_s: positive_setting(Self::NAME, "omega_s", s[1])?,
                frequency: positive_setting(Self::NAME, "f", s[2])?,
                harmonic: positive_setting(Self::NAME, "k", s[3])?,
                current_limit: positive_setting(Self::NAME, "I_lim", s[4])?,
                spot_angle: finite_setting(Self::NAME, "theta_0", s[5])?,
                spot_width: positive_setting(Self::NAME, "w", s[6])?,
                fade: positive_setting(Self::NAME, "tau", s[7])?,
                instant: finite_setting(Self::NAME, "t_s", s[8])?,
                speed_limit: positive_setting(Self::NAME, "omega_lim", s[9])?,
                current_smooth: positive_setting(Self::NAME, "I_s", s[10])?,
            },
        })
    }

    fn settings(&self) -> Vec<f64> {
        vec![
            self.shapes.omega_smooth,
            self.shapes.omega_s,
            self.shapes.frequency,
            self.shapes.harmonic,
            self.shapes.current_limit,
            self.shapes.spot_angle,
            self.shapes.spot_width,
            self.shapes.fade,
            self.shapes.instant,
            self.shapes.speed_limit,
            self.shapes.current_smooth,
        ]
    }

    fn check_calibrated(&self, key: &str) -> Result<(), String> {
        let k = dictionary::index_of(key)?;
        if self.active.contains(&k) {
            Ok(())
        } else {
            Err(format!(
                "law.{key} is not one of the law's functions: list it in [terms.law] to \
                 calibrate it"
            ))
        }
    }

    fn contribute<D: Scalar>(&self, site: &Site<D>, b: &mut Balance<D>) {
        let x = Point {
            t: site.t,
            current: site.current,
            speed: site.speed,
            voltage: site.voltage,
            charge: site.states[0],
            heat: site.states[1],
            theta: site.states[2],
        };
        let here = dictionary::At::new(&x, &self.shapes);
        for &k in self
            .active
            .iter()
            .filter(|&&k| k < ODE_BALANCES * N_FUNCTIONS)
        {
            let term = site.params[k] * here.value(k % N_FUNCTIONS);
            if k < N_FUNCTIONS {
                b.torque += term;
            } else {
                b.voltage += term;
            }
        }
    }

    /// What is read of I and ω, plus the law's measurement functions of the state as the
    /// sensors before it read it (the channels as they arrive), the input and the time.
    fn measure<D: Scalar>(&self, params: &[D], states: &[D], at: Sample<D>, channels: &mut [D]) {
        let first = ODE_BALANCES * N_FUNCTIONS;
        if self.active.last().is_none_or(|&k| k < first) {
            return;
        }
        let x = Point {
            t: at.t,
            current: channels[0],
            speed: channels[1],
            voltage: at.voltage,
            charge: states[0],
            heat: states[1],
            theta: states[2],
        };
        let here = dictionary::At::new(&x, &self.shapes);
        for &k in self.active.iter().filter(|&&k| k >= first) {
            let read = params[k] * here.value(k % N_FUNCTIONS);
            channels[k / N_FUNCTIONS - ODE_BALANCES] += read;
        }
    }

    fn derivatives<D: Scalar>(&self, site: &Site<D>, b: &Balance<D>, d: &mut [D]) {
        if self.needs(0) {
            d[0] = site.current.abs();
        }
        if self.needs(1) {
            d[1] = b.resistance * site.current * site.current;
        }
        if self.needs(2) {
            d[2] = site.speed;
        }
    }
}
