//! The fast first screen: sensitivities of the nominal model's channels to R and to every
//! candidate's parameters, weighted by the noise. Two columns that point the same way (cosine
//! above [`COLLINEAR`]) are a tie waiting to happen on this recording: near the nominal model
//! the data cannot tell the two parameters apart.

use nalgebra::DMatrix;

use crate::error::Error;
use crate::ode::SolverSettings;
use crate::study::Problem;

/// |cos| above which two weighted sensitivity columns count as collinear: 0.99 leaves 1% of
/// the column's squared length to tell them apart, which a concealed effect below 1.5σ cannot
/// fill.
pub const COLLINEAR: f64 = 0.99;

/// Pairs of parameters whose weighted sensitivities are collinear, with their cosine.
pub fn collinear_pairs(
    base: &Problem,
    candidates: &[String],
    resistance: f64,
    noise_sd: &[f64],
) -> Result<Vec<(String, String, f64)>, Error> {
    // Every candidate at once: a problem no single candidate has, built for its forward
    // model alone.
    let problem = base.with_terms(candidates)?;
    let forward = problem.forward(SolverSettings::default())?;
    let names = forward.calibrated_names();
    let mut theta = forward.nominal_calibrated();
    if let Some(i) = names.iter().position(|n| n == "R") {
        theta[i] = resistance;
    }
    // A switching time at its default (the record's start) makes a step a constant; mid-record
    // is where a step is its own shape.
    for (i, spec) in forward.calibrated_specs().iter().enumerate() {
        if let crate::parameter::Support::Bounded { lower, upper } = spec.support {
            theta[i] = 0.5 * (lower + upper);
        }
    }
    let mut out = vec![0.0; forward.n_outputs()];
    let mut jacobian = DMatrix::zeros(forward.n_outputs(), names.len());
    forward
        .simulate_with_sensitivities(&theta, &mut out, &mut jacobian)
        .map_err(|e| Error::Numerical(e.to_string()))?;
    let m = forward.times().len();
    for (c, sd) in noise_sd.iter().enumerate().take(forward.channels().len()) {
        for i in 0..m {
            for j in 0..names.len() {
                jacobian[(c * m + i, j)] /= sd;
            }
        }
    }
    let norms: Vec<f64> = (0..names.len())
        .map(|j| jacobian.column(j).norm())
        .collect();
    let mut pairs = Vec::new();
    for a in 0..names.len() {
        for b in a + 1..names.len() {
            if norms[a] == 0.0 || norms[b] == 0.0 || !norms[a].is_finite() {
                continue;
            }
            let cos = jacobian.column(a).dot(&jacobian.column(b)) / (norms[a] * norms[b]);
            if cos.abs() > COLLINEAR {
                pairs.push((names[a].clone(), names[b].clone(), cos));
            }
        }
    }
    Ok(pairs)
}
