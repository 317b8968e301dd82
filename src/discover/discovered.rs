//! The law the diagnosis discovered, as the report states it: its balance, functions, their
//! coefficients with 95% intervals, and the shapes (ω_s, k, I_lim, f, a spot's θ₀ and w) it
//! holds.

use std::collections::BTreeMap;

use serde::Serialize;

use crate::motor::Term;
use crate::motor::dictionary::{
    self, BALANCES, CURRENT_LIMIT, FADE, FUNCTIONS, N_FUNCTIONS, OMEGA_SPOT, SPEED_LIMIT, STEP,
    STRIBECK, Spot, reads_harmonic,
};

use super::candidate::Candidate;
use super::unexplained::{
    EquationTerm, equation_with, with_shapes, with_speed_limit, with_spot, with_time,
};

/// One function of a discovered law: its coefficient at the MAP and the 95% interval of the
/// Laplace approximation there (MAP ± 1.96 sd; the coefficients have real support, so the
/// approximation's coordinate is the coefficient itself).
#[derive(Clone, Debug, Serialize)]
pub struct DiscoveredFunction {
    pub name: String,
    pub coefficient: f64,
    pub q025: f64,
    pub q975: f64,
}

/// The law term the diagnosis added, as the JSON's `discovered` reports it.
#[derive(Clone, Debug, Serialize)]
pub struct Discovered {
    pub balance: String,
    pub functions: Vec<DiscoveredFunction>,
    /// What adding it gained over the model selected before it (nats, the ranking's score).
    pub score: f64,
    /// The Stribeck speed ω_s [rad/s], where the law holds the Stribeck function.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub omega_s: Option<f64>,
    /// The angle's harmonic k (periods per revolution), where the law holds sin or cos(k·θ).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub k: Option<f64>,
    /// The current limit I_lim [A], where the law holds `sign(I)*max(|I|-I_lim,0)`.
    #[serde(rename = "I_lim", skip_serializing_if = "Option::is_none")]
    pub current_limit: Option<f64>,
    /// The speed limit ω_lim [rad/s], where the law holds
    /// `sign(omega)*max(|omega|-omega_lim,0)`.
    #[serde(rename = "omega_lim", skip_serializing_if = "Option::is_none")]
    pub speed_limit: Option<f64>,
    /// The frequency f [Hz] of a periodic law, where it holds sin or cos(2πft).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub frequency_hz: Option<f64>,
    /// The spot's θ₀ and w [rad] (`theta_0`, `w`), where the law holds a spot of the angle.
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    pub spot: Option<Spot>,
    /// The fade's time constant τ [s], where the law holds `exp(-t/tau)`.
    #[serde(rename = "tau", skip_serializing_if = "Option::is_none")]
    pub fade: Option<f64>,
    /// The step's instant t_s [s], where the law holds `step(t-t_s)`.
    #[serde(rename = "t_s", skip_serializing_if = "Option::is_none")]
    pub instant: Option<f64>,
    /// The law's functions in its other balances, where it holds more than one (a law
    /// extended by a function of another balance): each balance with its functions.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub also: Vec<DiscoveredBalance>,
    /// The law as the report prints it, e.g. `J dω/dt += −0.0001·sign(ω)·|I| [95%: …]`, each
    /// further balance after a semicolon.
    pub equation: String,
}

/// A further balance of a discovered law and its functions.
#[derive(Clone, Debug, Serialize)]
pub struct DiscoveredBalance {
    pub balance: String,
    pub functions: Vec<DiscoveredFunction>,
}

/// The law `fit` holds, in the balance whose functions it lists first (the others in `also`),
/// with `gained` its score over the model before it; `None` when it holds none.
pub fn discovered(fit: &Candidate, gained: f64) -> Option<Discovered> {
    let law = fit.problem.model.terms.iter().find_map(|t| match &t.term {
        Term::Law(law) => Some(law),
        _ => None,
    })?;
    let sds = fit.map.laplace_sd();
    let mut balances: Vec<usize> = law.active.iter().map(|k| k / N_FUNCTIONS).collect();
    balances.dedup();
    let mut parts = Vec::new();
    for &balance in &balances {
        let mut functions = Vec::new();
        for &k in law.active.iter().filter(|&&k| k / N_FUNCTIONS == balance) {
            let name = format!("law.{}", dictionary::key(k));
            let i = fit
                .posterior
                .calibrated()
                .iter()
                .position(|c| c.name == name)?;
            let value = *fit.theta.get(&name)?;
            let half = 1.96 * sds[i];
            functions.push(DiscoveredFunction {
                name: FUNCTIONS[k % N_FUNCTIONS].to_string(),
                coefficient: value,
                q025: value - half,
                q975: value + half,
            });
        }
        parts.push(DiscoveredBalance {
            balance: BALANCES[balance].to_string(),
            functions,
        });
    }
    let mut parts = parts.into_iter();
    let DiscoveredBalance { balance, functions } = parts.next()?;
    let also: Vec<DiscoveredBalance> = parts.collect();
    let holds = |f: usize| {
        std::iter::once(&functions)
            .chain(also.iter().map(|b| &b.functions))
            .flatten()
            .any(|g| g.name == FUNCTIONS[f])
    };
    let omega_s = holds(STRIBECK).then_some(law.shapes.omega_s);
    let k = (0..N_FUNCTIONS)
        .any(|f| reads_harmonic(f) && holds(f))
        .then_some(law.shapes.harmonic);
    let frequency_hz = (0..N_FUNCTIONS)
        .any(|f| dictionary::reads_frequency(f) && holds(f))
        .then_some(law.shapes.frequency);
    let current_limit = holds(CURRENT_LIMIT).then_some(law.shapes.current_limit);
    let speed_limit = holds(SPEED_LIMIT).then_some(law.shapes.speed_limit);
    let spot = holds(OMEGA_SPOT).then(|| Spot::of(&law.shapes));
    let fade = holds(FADE).then_some(law.shapes.fade);
    let instant = holds(STEP).then_some(law.shapes.instant);
    let mut law = Discovered {
        equation: String::new(),
        spot,
        fade,
        instant,
        omega_s,
        k,
        current_limit,
        speed_limit,
        frequency_hz,
        balance,
        functions,
        also,
        score: gained,
    };
    law.write_equation();
    Some(law)
}

impl Discovered {
    fn write_equation(&mut self) {
        let one = |balance: &str, functions: &[DiscoveredFunction]| {
            let terms: Vec<EquationTerm> = functions
                .iter()
                .map(|f| (f.name.clone(), f.coefficient, Some((f.q025, f.q975))))
                .collect();
            with_speed_limit(
                with_time(
                    with_spot(
                        with_shapes(
                            equation_with(balance, &terms),
                            self.k,
                            self.current_limit,
                            self.frequency_hz,
                        ),
                        self.spot,
                    ),
                    self.fade,
                    self.instant,
                ),
                self.speed_limit,
            )
        };
        let mut equation = one(&self.balance, &self.functions);
        for b in &self.also {
            equation = format!("{equation}; {}", one(&b.balance, &b.functions));
        }
        self.equation = equation;
    }

    /// The sampled fit's posterior mean and 95% interval in place of the Laplace ones, where
    /// the fit holds the coefficient (`mean`, `interval` keyed `law.balance:function`).
    pub fn use_sampled(
        &mut self,
        mean: &BTreeMap<String, f64>,
        interval: &BTreeMap<String, [f64; 2]>,
    ) {
        let parts = std::iter::once((&self.balance, &mut self.functions))
            .chain(self.also.iter_mut().map(|b| (&b.balance, &mut b.functions)));
        for (balance, functions) in parts {
            for f in functions {
                let name = format!("law.{balance}:{}", f.name);
                if let (Some(&m), Some(&[lo, hi])) = (mean.get(&name), interval.get(&name)) {
                    (f.coefficient, f.q025, f.q975) = (m, lo, hi);
                }
            }
        }
        self.write_equation();
    }
}
