//! The problem a user poses: recordings plus the model they believe (from files, from memory
//! or from the paper's synthetic set-up) → the posterior of BM1/BM2 with the noise-prior policy
//! of its base; what a fitted model predicts; the inputs of synthetic experiments and the
//! records a held input makes; and the concealed-physics cases made to test the discovery; and
//! the check that a recording can be this motor at all (`plausibility`).

pub mod cases;
pub mod frequency_grid;
mod inputs;
pub mod plausibility;
mod predict;
pub mod predictive;
mod problem;
mod record;

pub use inputs::InputProfile;
pub use predict::{ChannelResidual, RecordPrediction, predict_records, residuals};
pub use predictive::{ChannelPredictive, Predictive, posterior_predictive, replicated_recordings};
pub use problem::{BOUNDED_STARTS, Problem, Reference, recording_from};
pub use record::{held_input_record, voltage_record};
