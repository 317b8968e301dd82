//! What is read of a channel beyond the library (issue 19, session 32): a current sensor whose
//! gain drifts with the heat the winding draws, and a speed sensor clipped at the top of its
//! range. Session 31's build named the first a law in I and a fade, or `unknown`, and the
//! second a step in time of what is read of ω. Fixtures: `beyond_library_cases` of session 31's
//! generator (seeds 920007, 920010), a set made before either function was offered there, and
//! in view when they were; and a current sensor's dead band (seed 930006 of session 32's
//! sixteenth set, made blind for the first two and in view when the current's sign was offered).

mod beyond;

use beyond::{fixture, truth_value, whole_library};
use motorcal::discover::Fingerprint;

/// A Hall current sensor whose gain rises as the winding warms it: I read as I·(1 + β·E),
/// E = ∫R·I² dt (β 6.4e-5 per joule, a 158-nat miss on an input that steps down and reverses).
/// The model as given's fingerprint is a drift with the heat in what is read of I, in I·heat
/// alone, and the law discovered is that function, its coefficient within 20% of β (fitted
/// beside R, which the same heat's current also moves).
#[test]
fn a_current_sensor_s_gain_drifting_with_the_heat_is_read_as_i_times_heat() {
    let (problem, answer) = fixture("sensor_gain_heat-920007");
    let beta = truth_value(&answer, "beta");
    let d = whole_library(&problem);
    let given = d
        .unexplained_as_given
        .expect("a 158-nat miss is not nothing");
    let Fingerprint::Drift {
        variable,
        balance,
        functions,
        ..
    } = &given.fingerprint
    else {
        panic!("{:?}", given.fingerprint)
    };
    assert_eq!(
        (variable.as_str(), balance.as_str()),
        ("heat", "measurement:I")
    );
    let names: Vec<&str> = functions.iter().map(|f| f.name.as_str()).collect();
    assert_eq!(names, vec!["I*heat"]);
    let law = d.discovered.expect("the gain's law");
    assert_eq!(law.balance, "measurement:I");
    assert_eq!(law.functions.len(), 1);
    let c = law.functions[0].coefficient;
    assert!(
        (c / beta - 1.0).abs() < 0.2,
        "I·heat's coefficient {c} against the truth's β {beta}"
    );
}

/// A speed sensor at the end of its range: what is read of ω is clipped at (1 − c) of the
/// record's no-load speed (c 0.8% here, a 269-nat miss, on a constant 24 V: the speed crosses its top once, at
/// the end of the spin-up). The model as given's fingerprint is a state of what is read of ω,
/// the speed beyond a limit within 1% of the truth's top, and the law discovered takes about
/// all of the excess off (a coefficient within 20% of −1: the softened hinge acts a little
/// below its limit too).
#[test]
fn a_speed_sensor_clipped_at_its_range_reads_the_speed_beyond_a_limit() {
    let (problem, answer) = fixture("speed_clip-920010");
    let cut = truth_value(&answer, "cut");
    let top = (1.0 - cut) * 24.0 / problem.model.motor.back_emf_constant;
    let d = whole_library(&problem);
    let given = d
        .unexplained_as_given
        .expect("a 269-nat miss is not nothing");
    let Fingerprint::State {
        balance,
        functions,
        speed_limit: Some(limit),
        ..
    } = &given.fingerprint
    else {
        panic!("{:?}", given.fingerprint)
    };
    assert_eq!(balance, "measurement:omega");
    assert_eq!(functions[0].name, "sign(omega)*max(|omega|-omega_lim,0)");
    assert!(
        (limit / top - 1.0).abs() < 0.01,
        "ω_lim {limit} against the truth's top {top}"
    );
    let law = d.discovered.expect("the clip's law");
    assert_eq!(law.balance, "measurement:omega");
    let hinge = law
        .functions
        .iter()
        .find(|f| f.name == "sign(omega)*max(|omega|-omega_lim,0)")
        .expect("the hinge in the law");
    assert!(
        (hinge.coefficient + 1.0).abs() < 0.2,
        "{}",
        hinge.coefficient
    );
}

/// A Hall current sensor with a dead band: it reads sign(I)·max(|I| − I_d, 0) (I_d 2.2 A here,
/// a 300-nat miss on an input that steps down and reverses, where the band's offset changes
/// sign with the current). Session 32's build named it `unknown` beside the library's torque
/// constant and a law of the torque balance. The model as given's fingerprint is now a state
/// of what is read of I in the current's sign alone, and the law discovered is that function,
/// its coefficient within 20% of −I_d (the sign smoothed over 1 A takes a little more than the
/// band where the current is large, to make up for the samples near zero).
#[test]
fn a_current_sensor_s_dead_band_is_read_as_the_current_s_sign() {
    let (problem, answer) = fixture("current_deadband-930006");
    let i_d = truth_value(&answer, "i_d");
    let d = whole_library(&problem);
    let given = d
        .unexplained_as_given
        .expect("a 300-nat miss is not nothing");
    let Fingerprint::State {
        balance, functions, ..
    } = &given.fingerprint
    else {
        panic!("{:?}", given.fingerprint)
    };
    assert_eq!(balance, "measurement:I");
    let names: Vec<&str> = functions.iter().map(|f| f.name.as_str()).collect();
    assert_eq!(names, vec!["sign(I)"]);
    let law = d.discovered.expect("the dead band's law");
    assert_eq!(law.balance, "measurement:I");
    let sign = law
        .functions
        .iter()
        .find(|f| f.name == "sign(I)")
        .expect("the current's sign in the law");
    assert!(
        (sign.coefficient / -i_d - 1.0).abs() < 0.2,
        "sign(I)'s coefficient {} against the truth's −I_d {}",
        sign.coefficient,
        -i_d
    );
}
