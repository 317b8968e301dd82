//! Knocks (issue 19, session 30): a torque at a few isolated instants, no function of the state,
//! named as such by the model as given's fingerprint (a law of the state stood in for the
//! clutch before). Fixtures: `beyond_library_cases` of session 30's generator (seeds 780012, 900004);
//! and knocks of the supply (session 32), brush_bounce-3200001 of session 31's generator at
//! `--seed-base 3200000 --min-nats 300 --max-nats 600`.

mod beyond;

use beyond::{fixture, truth_integer, truth_value, whole_library};
use motorcal::discover::{Fingerprint, Span};

/// The knocks the model as given's fingerprint names on case `name` (their `where`), after
/// asserting that it names them: `unknown`, its sentence a jolt. The case's answer beside.
fn knocks_named(name: &str, miss: &str) -> (Vec<Span>, serde_json::Value) {
    knocks_said(name, miss, "jolted")
}

/// The same, its sentence holding `said`.
fn knocks_said(name: &str, miss: &str, said: &str) -> (Vec<Span>, serde_json::Value) {
    let (problem, answer) = fixture(name);
    let given = whole_library(&problem)
        .unexplained_as_given
        .unwrap_or_else(|| panic!("a {miss} miss is not nothing"));
    assert!(
        matches!(given.fingerprint, Fingerprint::Unknown { .. }),
        "{:?}",
        given.fingerprint
    );
    assert!(given.suggestion.contains(said), "{}", given.suggestion);
    (given.spans, answer)
}

/// A clutch engaging at t_e drags a second mass up to speed through a slipping plate for about
/// ten milliseconds: a torque of the history, no function of the state. Session 29's build read
/// it as a law of the speed's reading (5.0 nats). The model as given's fingerprint now says
/// that a torque jolted the motor, and where: within 15 ms after the engagement.
#[test]
fn a_clutch_catching_is_named_a_knock_at_its_instant() {
    let (knocks, answer) = knocks_named("clutch_engagement-780012", "33-nat");
    let t_e = truth_value(&answer, "t_e");
    assert!(
        knocks
            .iter()
            .any(|s| s.t_start >= t_e && s.t_start <= t_e + 0.015),
        "engaged at {t_e}; knocks at {knocks:?}"
    );
}

/// splitmix64's finalizer, as the generator draws a case's instants with it.
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// The generator's instant in a window of `window` seconds, n-th: n windows plus 90% of one
/// times a splitmix64 draw of the salt and n (`beyond_library_cases`, `LoosePart`,
/// `BrushBounce`).
fn instant_in(salt: u64, n: usize, window: f64) -> f64 {
    let u = (mix(salt ^ (n as u64 + 7).wrapping_mul(0x9E37_79B9_7F4A_7C15)) >> 11) as f64
        / (1u64 << 53) as f64;
    window * n as f64 + 0.9 * window * u
}

/// The generator's knock in 40-ms window n.
fn knock_instant(salt: u64, n: usize) -> f64 {
    instant_in(salt, n, 0.04)
}

/// A loose part strikes the shaft once in each 40-ms window, 2 ms at a time, at a random
/// instant and with a random sign: a 194-nat miss that session 29's build left as `unknown`
/// with nothing to say of it. The model as given's fingerprint now names knocks, each within
/// 5 ms of a true one.
#[test]
fn a_loose_part_s_knocks_are_found_at_their_instants() {
    let (knocks, answer) = knocks_named("loose_part-900004", "194-nat");
    let salt = truth_integer(&answer, "salt");
    let truth: Vec<f64> = (0..13).map(|n| knock_instant(salt, n)).collect();
    for s in &knocks {
        assert!(
            truth.iter().any(|&t| (s.t_start - t).abs() <= 0.005),
            "a knock at {} s; the truth's at {truth:?}",
            s.t_start
        );
    }
}

/// Brushes bouncing on the commutator: in each 25-ms window, with probability one half, the
/// winding sees (1 − d)·U for 1 ms (d 0.096 here, a 325-nat miss). Each loss is a voltage, not a
/// torque: the current dips at once and the speed barely follows. Session 31's build named a
/// law of what is read of ω, or nothing, on such records. The model as given's fingerprint now
/// says the winding lost its supply for a moment, each instant within 2 ms of a true bounce.
#[test]
fn brushes_bouncing_are_knocks_of_the_supply_at_their_instants() {
    let (knocks, answer) = knocks_said(
        "brush_bounce-3200001",
        "325-nat",
        "loses part of its supply",
    );
    assert!(!knocks.is_empty());
    let salt = truth_integer(&answer, "salt");
    // The generator's sign draw of window n, positive where the window bounces.
    let bounces = |n: usize| {
        mix(salt.wrapping_add((n as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15))) >> 63 == 1
    };
    let truth: Vec<f64> = (0..20)
        .filter(|&n| bounces(n))
        .map(|n| instant_in(salt, n, 0.025))
        .collect();
    for s in &knocks {
        assert_eq!(s.channel, "I");
        assert!(
            truth.iter().any(|&t| (s.t_start - t).abs() <= 0.002),
            "a loss at {} s; the truth's at {truth:?}",
            s.t_start
        );
    }
}
