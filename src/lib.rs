//! motorcal — Bayesian calibration of a DC-motor simulation model that learns its own
//! model discrepancy (John, Schick, Heuveline 2018), with gradient-aware MCMC.
//!
//! Data flow, one way:
//! motor model → integrator → forward model with sensitivities → Bayesian model
//! (log density + gradient) → samplers → draws → diagnostics → reports.

pub mod diagnostics;
