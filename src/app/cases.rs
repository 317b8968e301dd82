//! `motorcal simulate --effect`: a concealed-physics case (`study::cases`) written as the
//! development set's are: `recording.csv`, the nominal `motor.toml`, `answer.json`.

use std::path::Path;

use crate::io::{write_model_file, write_recording};
use crate::study::cases::{Answer, Case, CaseOptions, make_case};

use super::AppError;

/// Makes the case and writes it to `out`.
pub fn write_case(options: &CaseOptions, out: &Path) -> Result<Answer, AppError> {
    let Case {
        recording,
        nominal,
        answer,
    } = make_case(options)?;
    std::fs::create_dir_all(out)?;
    write_recording(&out.join("recording.csv"), &recording)?;
    write_model_file(&out.join("motor.toml"), &nominal)?;
    let text =
        serde_json::to_string_pretty(&answer).map_err(|e| AppError::Output(e.to_string()))?;
    crate::io::write_atomically(&out.join("answer.json"), text.as_bytes())?;
    Ok(answer)
}
