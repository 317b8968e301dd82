//! Every file the tool reads or writes.
//!
//! Reading: recordings (CSV), model files (TOML) and draws (CmdStan CSV or a long
//! `chain,draw,...` table). Any input the tool cannot use gives one [`InputError`] that names the
//! file, the line and the field, so the user can fix it without reading code; nothing here panics
//! on malformed input.
//!
//! Writing: every output goes through [`AtomicFile`], so a failed or interrupted run never leaves
//! a half-written file nor destroys the previous good one.

mod atomic;
mod draws;
mod error;
mod input_file;
mod model_file;
mod model_tables;
mod recording;
mod table;
mod toml_lines;

pub use atomic::{AtomicFile, write_atomically};
pub use draws::{CmdStanWriter, DrawSet, SAMPLER_COLUMNS, SamplerColumns, read_draws};
pub use error::InputError;
pub use input_file::{
    VoltageProfile, read_input_profile, read_voltage_profile, write_input_profile,
    write_voltage_profile,
};
pub use model_file::{
    MODEL_FILE_SCHEMA, ModelFile, parse_model_file, read_model_file, to_toml_string,
    write_model_file,
};
pub use model_tables::{CalibrateEntry, DiscrepancyChoice};
pub use recording::{
    ChannelMap, Recording, read_recording, read_recording_for, write_recording, write_recording_as,
};

/// Provenance written into every output: crate version and the commit it was built from.
pub fn provenance() -> Vec<(String, String)> {
    vec![
        ("motorcal_version".into(), env!("CARGO_PKG_VERSION").into()),
        ("git_commit".into(), env!("MOTORCAL_GIT_COMMIT").into()),
    ]
}
