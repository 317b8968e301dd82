//! The candidates of a design made without a diagnosis. With a recording, each candidate sits at
//! its MAP on it — `discover`'s fit, the one `diagnose` scores — and the noise σ is the best
//! scoring fit's; without one, at the model's values, a term's parameter whose default lies on
//! its support's bound (a friction of zero, which would make the candidate the model itself) at
//! its prior's median instead: where `diagnose`'s search would start it.

use std::collections::BTreeMap;

use crate::bayes::ModelSettings;
use crate::discover::fit_candidate;
use crate::error::Error;
use crate::study::Problem;

use super::experiment::{Candidate, parse_candidate};

/// The named candidates on the design's `base`, and the noise σ per channel of the recording
/// they were fitted to (`None` without one).
pub fn candidates_without_diagnosis(
    base: &Problem,
    names: &[String],
    recorded: Option<&Problem>,
) -> Result<(Vec<Candidate>, Option<Vec<f64>>), Error> {
    let mut candidates = Vec::new();
    let mut best: Option<(f64, Vec<f64>)> = None;
    for name in names {
        let added = parse_candidate(name)?;
        let values = match recorded {
            Some(problem) => {
                let fit = fit_candidate(problem, &added)?;
                if best.as_ref().is_none_or(|(score, _)| fit.score > *score) {
                    best = Some((fit.score, fit.noise_sd()));
                }
                fit.theta
            }
            None => starting_values(base, &added)?,
        };
        candidates.push(Candidate::new(base, name, &values)?);
    }
    Ok((candidates, best.map(|(_, sd)| sd)))
}

/// The calibrated parameters where a MAP search on `base` with `added` on starts: the model's
/// values inside their supports, the prior's median for one on a bound.
pub(super) fn starting_values(
    base: &Problem,
    added: &[String],
) -> Result<BTreeMap<String, f64>, Error> {
    let posterior = base.with_terms(added)?.posterior(&ModelSettings::bm1())?;
    Ok(posterior
        .calibrated()
        .iter()
        .map(|c| (c.name.clone(), c.start))
        .collect())
}
