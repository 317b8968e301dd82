//! Where the dynamic terms start when they are ranked: the verdict's own estimates on the
//! residual of the model as given, whatever their evidence. A delay's τ, a lag's τ and the
//! channel it is on, a ringing resonance's frequency and damping ratio are what a MAP search
//! from the terms' defaults (τ = 0 on its bound, a resonance at 100 Hz) cannot find by itself:
//! the likelihood in a frequency has a valley per harmonic, and at τ = 0 the gradient of a lag
//! on one channel is no guide to which channel.

use crate::motor::Term;
use crate::parameter::ParamId;

use crate::study::Problem;

use std::collections::BTreeMap;

use super::super::candidate::Starts;
use super::oscillation::frequency_search_cost;
use super::{AsGiven, Fingerprint};
use crate::study::frequency_grid::{grid_over, nyquist_over};

/// The coupling's grid: frequencies a third of an octave apart (a resonance of ζ ≥ 0.05 is
/// wider than that, so a grid point lies in its valley), damping ratios over the prior's
/// range up to where it stops ringing, and shares of the inertia from barely felt to a third.
const COUPLING_PER_OCTAVE: f64 = 3.0;
const COUPLING_DAMPING: [f64; 3] = [0.05, 0.2, 0.5];
const COUPLING_SHARES: [f64; 3] = [0.03, 0.1, 0.3];

/// Points over the band a coupling's resonance can be resolved in on `problem`'s first record
/// (`lowest` Hz up to half the Nyquist frequency, four samples a period), and how many of the
/// verdict's frequencies lie in that band: what a frequency searched from them pays.
fn coupling_grid(problem: &Problem, lowest: f64) -> (Vec<BTreeMap<String, f64>>, usize) {
    let key = |p: &str| ParamId::of_term("compliant_coupling", p).to_string();
    let Some(time) = problem.recordings.first().map(|r| &r.time) else {
        return (Vec::new(), 0);
    };
    let span = time[time.len() - 1] - time[0];
    let top = 0.5 * nyquist_over(span, time.len());
    let mut points = Vec::new();
    let mut f = lowest;
    while f <= top {
        for zeta in COUPLING_DAMPING {
            for s in COUPLING_SHARES {
                points.push(BTreeMap::from([
                    (key("f_r"), f),
                    (key("zeta"), zeta),
                    (key("s"), s),
                ]));
            }
        }
        f *= 2f64.powf(1.0 / COUPLING_PER_OCTAVE);
    }
    let searched = grid_over(span, time.len())
        .0
        .iter()
        .filter(|&&g| g <= top)
        .count();
    (points, searched)
}

/// The dynamic terms the starts are for.
pub const DYNAMIC: [&str; 3] = ["input_delay", "sensor_lag", "compliant_coupling"];

/// Starts for the dynamic terms among `candidates`, estimated on the model as given's residual
/// (first record); empty when there are none to start.
pub fn dynamic_starts(problem: &Problem, as_given: &AsGiven, candidates: &[String]) -> Starts {
    let mut starts = Starts::default();
    if !candidates.iter().any(|c| DYNAMIC.contains(&c.as_str())) {
        return starts;
    }
    // The coupling's grid, whether or not the record rings: its frequency is then searched over
    // the band and pays that search, as a ringing fingerprint's start pays the verdict's grid.
    if candidates.iter().any(|c| c == "compliant_coupling") {
        let (grid, searched) = coupling_grid(problem, as_given.lowest_frequency());
        if !grid.is_empty() {
            starts.grids.insert("compliant_coupling".into(), grid);
            starts.search_penalty.insert(
                "compliant_coupling".into(),
                frequency_search_cost(searched, problem.n_observations()),
            );
        }
    }
    let Some(found) = as_given.scores(0.0).map(|s| s.fingerprints) else {
        return starts;
    };
    let best = |kind: &dyn Fn(&Fingerprint) -> bool| {
        found
            .iter()
            .map(|e| &e.fingerprint)
            .filter(|f| kind(f))
            .max_by(|a, b| a.score().total_cmp(&b.score()))
            .cloned()
    };
    let key = |term: &str, p: &str| ParamId::of_term(term, p).to_string();
    if let Some(Fingerprint::Delay { seconds, .. }) =
        best(&|f| matches!(f, Fingerprint::Delay { .. }))
    {
        starts.values.insert(key("input_delay", "tau"), seconds);
    }
    if let Some(Fingerprint::Lag {
        channel, seconds, ..
    }) = best(&|f| matches!(f, Fingerprint::Lag { .. }))
        && let Some(index) = ["I", "omega"].iter().position(|c| *c == channel)
        && let Some(Ok(term)) = Term::from_name("sensor_lag", &[index as f64])
    {
        starts.values.insert(key("sensor_lag", "tau"), seconds);
        starts.terms.push(term);
    }
    if let Some(Fingerprint::Oscillation {
        frequency_hz,
        damping_ratio,
        frequencies,
        ..
    }) = best(&|f| match f {
        Fingerprint::Oscillation {
            ringing: true,
            sensor: false,
            frequency_hz,
            ..
        } => *frequency_hz >= as_given.lowest_frequency(),
        _ => false,
    }) {
        starts
            .values
            .insert(key("compliant_coupling", "f_r"), frequency_hz);
        starts.values.insert(
            key("compliant_coupling", "zeta"),
            damping_ratio.unwrap_or(0.1).clamp(1e-3, 1.0),
        );
        starts.search_penalty.insert(
            "compliant_coupling".into(),
            frequency_search_cost(frequencies, problem.n_observations()),
        );
    }
    starts
}
