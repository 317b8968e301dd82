//! The discovery as a library call on data that never touches a file: a recording of a motor
//! with Coulomb friction, simulated in memory by the concealed-case generator, handed to
//! `discover` with the nominal model a user would believe.
//!
//! cargo run --release --example discover_in_memory

use motorcal::discover::{DiscoverSettings, discover};
use motorcal::study::cases::{CaseOptions, make_case};
use motorcal::study::{InputProfile, Problem};

fn main() -> Result<(), motorcal::error::Error> {
    // A friction three noise σ strong at its peak on the paper's start-up (seed fixed).
    let case = make_case(&CaseOptions {
        effects: vec!["coulomb_friction".into()],
        magnitude: Some(3.0),
        input: InputProfile::Constant,
        seed: 2026,
        conceal: false,
        tied: false,
    })?;
    let problem = Problem {
        label: "simulated in memory".into(),
        recordings: vec![case.recording],
        model: case.nominal,
        reference: None,
    };
    let mut settings = DiscoverSettings {
        rank_only: true,
        ..DiscoverSettings::default()
    };
    settings.run.quiet = true;
    let diagnosis = discover(&problem, &settings)?;
    println!(
        "truth: {} (T_c = {:.3e} N·m)",
        case.answer.effect, case.answer.params["T_c"]
    );
    println!("selected: {}", diagnosis.selected);
    Ok(())
}
