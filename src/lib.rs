//! motorcal — Bayesian calibration of a DC-motor simulation model that learns its own
//! model discrepancy (John, Schick, Heuveline 2018), with gradient-aware MCMC.
//!
//! Data flow, one way:
//! motor model → integrator → forward model with sensitivities → Bayesian model
//! (log density + gradient) → samplers → draws → diagnostics → reports.

// `!(a > b)` is how numeric code here says "fails, or is NaN": the negation is the point.
#![allow(clippy::neg_cmp_op_on_partial_ord)]
// Index loops over several parallel arrays read closer to the formulas than zipped iterators.
#![allow(clippy::needless_range_loop)]

pub mod app;
pub mod bayes;
pub mod density;
pub mod design;
pub mod diagnostics;
pub mod discover;
pub mod error;
pub mod evidence;
pub mod forward;
pub mod io;
pub mod motor;
pub mod ode;
pub mod optimize;
pub mod paper;
pub mod parameter;
pub mod pipeline;
pub mod plot;
pub mod sampler;
pub mod study;
pub mod synthetic;
