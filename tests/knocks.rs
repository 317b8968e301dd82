//! Knocks (issue 19, session 30): a torque at a few isolated instants, no function of the state,
//! named as such by the model as given's fingerprint (a law of the state stood in for the
//! clutch before). Fixtures: `beyond_library_cases` of session 30's generator (seeds 780012, 900004).

mod beyond;

use beyond::{fixture, truth_integer, truth_value};
use motorcal::discover::{Diagnosis, DiscoverSettings, Fingerprint, discover};
use motorcal::study::Problem;

/// The diagnosis with the whole library, ranked only (the model as given's fingerprint is
/// made before any fit is sampled).
fn whole_library(problem: &Problem) -> Diagnosis {
    let mut settings = DiscoverSettings {
        rank_only: true,
        candidates: None,
        ..DiscoverSettings::default()
    };
    settings.run.quiet = true;
    discover(problem, &settings).unwrap()
}

/// A clutch engaging at t_e drags a second mass up to speed through a slipping plate for about
/// ten milliseconds: a torque of the history, no function of the state. Session 29's build read
/// it as a law of the speed's reading (5.0 nats). The model as given's fingerprint now says
/// that a torque jolted the motor, and where: within 15 ms after the engagement.
#[test]
fn a_clutch_catching_is_named_a_knock_at_its_instant() {
    let (problem, answer) = fixture("clutch_engagement-780012");
    let t_e = truth_value(&answer, "t_e");
    let given = whole_library(&problem)
        .unexplained_as_given
        .expect("a 33-nat miss is not nothing");
    assert!(
        matches!(given.fingerprint, Fingerprint::Unknown { .. }),
        "{:?}",
        given.fingerprint
    );
    assert!(given.suggestion.contains("jolted"), "{}", given.suggestion);
    assert!(
        given
            .spans
            .iter()
            .any(|s| s.t_start >= t_e && s.t_start <= t_e + 0.015),
        "engaged at {t_e}; knocks at {:?}",
        given.spans
    );
}

/// The generator's knock in 40-ms window n: its instant, n·40 ms plus 90% of the window
/// times a splitmix64 draw of the salt and n (`beyond_library_cases`, `LoosePart`).
fn knock_instant(salt: u64, n: usize) -> f64 {
    let mut z = salt ^ (n as u64 + 7).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    let u = ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64;
    0.04 * n as f64 + 0.9 * 0.04 * u
}

/// A loose part strikes the shaft once in each 40-ms window, 2 ms at a time, at a random
/// instant and with a random sign: a 194-nat miss that session 29's build left as `unknown`
/// with nothing to say of it. The model as given's fingerprint now names knocks, each within
/// 5 ms of a true one.
#[test]
fn a_loose_part_s_knocks_are_found_at_their_instants() {
    let (problem, answer) = fixture("loose_part-900004");
    let salt = truth_integer(&answer, "salt");
    let truth: Vec<f64> = (0..13).map(|n| knock_instant(salt, n)).collect();
    let given = whole_library(&problem)
        .unexplained_as_given
        .expect("a 194-nat miss is not nothing");
    assert!(
        matches!(given.fingerprint, Fingerprint::Unknown { .. }),
        "{:?}",
        given.fingerprint
    );
    assert!(given.suggestion.contains("jolted"), "{}", given.suggestion);
    for s in &given.spans {
        assert!(
            truth.iter().any(|&t| (s.t_start - t).abs() <= 0.005),
            "a knock at {} s; the truth's at {truth:?}",
            s.t_start
        );
    }
}
