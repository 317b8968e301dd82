//! The dictionary's functions at points where their values are known.

use super::*;

/// The law's default shapes (its settings' defaults), each test changing the ones it reads.
fn shapes() -> Shapes {
    Shapes {
        omega_smooth: 1.0,
        omega_s: 50.0,
        frequency: 50.0,
        harmonic: 1.0,
        current_limit: 100.0,
        spot_angle: 0.0,
        spot_width: 0.5,
        fade: 0.05,
        instant: 0.25,
        speed_limit: 2000.0,
        current_smooth: 1.0,
    }
}

/// k periods per revolution: sin(k·θ) and cos(k·θ) at the harmonic the shapes hold.
#[test]
fn the_angle_functions_turn_k_times_per_revolution() {
    let x = Point {
        t: 0.0,
        current: 1.0,
        speed: 1.0,
        voltage: 1.0,
        charge: 0.0,
        heat: 0.0,
        theta: 0.3,
    };
    let shapes = |harmonic| Shapes {
        harmonic,
        ..shapes()
    };
    assert_eq!(value(SIN_THETA, &x, &shapes(1.0)), 0.3f64.sin());
    // 6·0.3 is 1.8 to the last bit or two.
    assert!((value(SIN_THETA, &x, &shapes(6.0)) - 1.8f64.sin()).abs() < 1e-12);
    assert!((value(COS_THETA, &x, &shapes(6.0)) - 1.8f64.cos()).abs() < 1e-12);
    assert_eq!(FUNCTIONS[SIN_THETA], "sin(k*theta)");
    assert_eq!(FUNCTIONS[COS_THETA], "cos(k*theta)");
}

/// The current's ripple is the current times the angle's, at the same harmonic, and a torque's
/// alone: a torque constant that varies over a turn.
#[test]
fn the_current_s_ripple_is_the_current_times_the_angle_s_in_the_torque_balance() {
    let x = Point {
        t: 0.0,
        current: -12.5,
        speed: 1.0,
        voltage: 1.0,
        charge: 0.0,
        heat: 0.0,
        theta: 0.7,
    };
    let shapes = Shapes {
        harmonic: 3.0,
        ..shapes()
    };
    for (ripple, angle) in [(I_SIN_THETA, SIN_THETA), (I_COS_THETA, COS_THETA)] {
        assert_eq!(
            value(ripple, &x, &shapes),
            -12.5 * value(angle, &x, &shapes)
        );
        assert_eq!(state_of(ripple), Some(2), "it needs θ integrated");
        let offered: Vec<bool> = (0..BALANCES.len()).map(|b| offered_in(ripple, b)).collect();
        assert_eq!(offered, [true, false, false, false]);
    }
    assert_eq!(FUNCTIONS[I_SIN_THETA], "I*sin(k*theta)");
    assert_eq!(index_of("torque:I*cos(k*theta)"), Ok(I_COS_THETA));
}

/// The supply's ripple is the input times the periodic functions of time, at the same
/// frequency, and a voltage's alone: a share of what the drive applies.
#[test]
fn the_supply_s_ripple_is_the_input_times_the_periodic_functions_in_the_voltage_balance() {
    let x = Point {
        t: 0.0123,
        current: 3.0,
        speed: 1.0,
        voltage: -8.0,
        charge: 0.0,
        heat: 0.0,
        theta: 0.0,
    };
    let shapes = Shapes {
        frequency: 74.8,
        ..shapes()
    };
    for (ripple, plain) in SUPPLY_RIPPLE.into_iter().zip(PERIODIC) {
        assert_eq!(value(ripple, &x, &shapes), -8.0 * value(plain, &x, &shapes));
        assert_eq!(state_of(ripple), None);
        let offered: Vec<bool> = (0..BALANCES.len()).map(|b| offered_in(ripple, b)).collect();
        assert_eq!(offered, [false, true, false, false]);
    }
    assert_eq!(FUNCTIONS[U_SIN_FT], "U*sin(2*pi*f*t)");
    assert_eq!(
        index_of("voltage:U*cos(2*pi*f*t)"),
        Ok(N_FUNCTIONS + U_COS_FT)
    );
}

/// The speed's ripple is the speed times the angle's, at the same harmonic, and what is
/// read of ω alone: a tachometer's ripple.
#[test]
fn the_speed_s_ripple_is_the_speed_times_the_angle_s_in_what_is_read_of_omega() {
    let x = Point {
        t: 0.0,
        current: 3.0,
        speed: 180.0,
        voltage: 2.0,
        charge: 0.0,
        heat: 0.0,
        theta: 40.3,
    };
    let shapes = Shapes {
        harmonic: 2.0,
        ..shapes()
    };
    for (ripple, angle) in READING_RIPPLE.into_iter().zip([SIN_THETA, COS_THETA]) {
        assert_eq!(
            value(ripple, &x, &shapes),
            180.0 * value(angle, &x, &shapes)
        );
        assert_eq!(state_of(ripple), Some(2), "it needs θ integrated");
        assert!(reads_harmonic(ripple) && ripple_of(ripple).is_none());
        let offered: Vec<bool> = (0..BALANCES.len()).map(|b| offered_in(ripple, b)).collect();
        assert_eq!(offered, [false, false, false, true]);
    }
    assert_eq!(
        index_of("measurement:omega:omega*sin(k*theta)"),
        Ok(3 * N_FUNCTIONS + OMEGA_SIN_THETA)
    );
}

/// Where each function may enter a fingerprint: the angle in the torque balance (a spring's)
/// and in what is read of ω (a coupling capacitor's loss), the constant in what is read only
/// (in a balance it is a library term's).
#[test]
fn the_angle_winds_up_a_torque_or_a_speed_s_reading_and_the_constant_offsets_a_reading() {
    assert_eq!(FUNCTIONS[THETA], "theta");
    assert_eq!(FUNCTIONS[CONSTANT], "1");
    let offered = |f| -> Vec<bool> { (0..BALANCES.len()).map(|b| offered_in(f, b)).collect() };
    assert_eq!(offered(THETA), [true, false, false, true]);
    assert_eq!(offered(CONSTANT), [false, false, true, true]);
    assert_eq!(
        index_of("measurement:omega:1"),
        Ok(3 * N_FUNCTIONS + CONSTANT)
    );
    assert_eq!(key(2 * N_FUNCTIONS + THETA), "measurement:I:theta");
}

/// The current beyond a limit: nothing below it, the excess with the current's sign above
/// it, and its derivative in the current (what the law's sensitivities carry) the sign of
/// I there and zero below — to the softplus's rounding, e^(−23) or less 23 widths (3% of
/// the limit each) away from the bend.
#[test]
fn the_current_beyond_a_limit_is_zero_below_it_and_the_signed_excess_above() {
    use num_dual::Dual64;
    let shapes = Shapes {
        current_limit: 200.0,
        ..shapes()
    };
    let at = |current: f64| {
        let x = Point {
            t: 0.0,
            current: Dual64::new(current, 1.0),
            speed: Dual64::from(100.0),
            voltage: Dual64::from(24.0),
            charge: Dual64::from(0.0),
            heat: Dual64::from(0.0),
            theta: Dual64::from(0.0),
        };
        let v = value(CURRENT_LIMIT, &x, &shapes);
        (v.re, v.eps)
    };
    let near = |(v, d): (f64, f64), (value, slope): (f64, f64)| {
        (v - value).abs() < 1e-5 && (d - slope).abs() < 1e-5
    };
    assert!(near(at(50.0), (0.0, 0.0)), "{:?}", at(50.0));
    assert!(near(at(-60.0), (0.0, 0.0)), "{:?}", at(-60.0));
    assert!(near(at(400.0), (200.0, 1.0)), "{:?}", at(400.0));
    assert!(near(at(-450.0), (-250.0, 1.0)), "{:?}", at(-450.0));
    assert_eq!(FUNCTIONS[CURRENT_LIMIT], "sign(I)*max(|I|-I_lim,0)");
}

/// The speed beyond a limit, the current's hinge's twin in what is read of ω: zero below
/// ω_lim either way round, the signed excess above it (a clip at ω_lim is −1 times it), and its
/// derivative in the speed 0 below and 1 above — to the softplus's rounding, e^(−16) or less
/// 16 widths (0.3% of the limit each) away from the bend.
#[test]
fn the_speed_beyond_a_limit_is_zero_below_it_and_the_signed_excess_above() {
    use num_dual::Dual64;
    let shapes = Shapes {
        speed_limit: 2000.0,
        ..shapes()
    };
    let at = |speed: f64| {
        let x = Point {
            t: 0.0,
            current: Dual64::from(50.0),
            speed: Dual64::new(speed, 1.0),
            voltage: Dual64::from(24.0),
            charge: Dual64::from(0.0),
            heat: Dual64::from(0.0),
            theta: Dual64::from(0.0),
        };
        let v = value(SPEED_LIMIT, &x, &shapes);
        (v.re, v.eps)
    };
    let near = |(v, d): (f64, f64), (value, slope): (f64, f64)| {
        (v - value).abs() < 1e-5 && (d - slope).abs() < 1e-5
    };
    assert!(near(at(1900.0), (0.0, 0.0)), "{:?}", at(1900.0));
    assert!(near(at(-1880.0), (0.0, 0.0)), "{:?}", at(-1880.0));
    assert!(near(at(2100.0), (100.0, 1.0)), "{:?}", at(2100.0));
    assert!(near(at(-2300.0), (-300.0, 1.0)), "{:?}", at(-2300.0));
    assert_eq!(
        FUNCTIONS[SPEED_LIMIT],
        "sign(omega)*max(|omega|-omega_lim,0)"
    );
    assert_eq!(pretty(FUNCTIONS[SPEED_LIMIT]), "sign(ω)·max(|ω|-ω_lim,0)");
    // What is read of ω only.
    let offered: Vec<bool> = (0..BALANCES.len())
        .map(|b| offered_in(SPEED_LIMIT, b))
        .collect();
    assert_eq!(offered, vec![false, false, false, true]);
}

/// A spot of the angle: the speed itself at θ₀, the same a turn later, about the Gaussian
/// exp(−(δ/w)²) a little way off, and small half a turn away.
#[test]
fn a_spot_of_the_angle_reads_the_speed_at_its_centre_once_per_revolution() {
    let shapes = Shapes {
        spot_angle: 2.0,
        spot_width: 0.2,
        ..shapes()
    };
    let at = |theta: f64| Point {
        t: 0.0,
        current: 0.0,
        speed: 7.0,
        voltage: 0.0,
        charge: 0.0,
        heat: 0.0,
        theta,
    };
    let spot = |theta: f64| value(OMEGA_SPOT, &at(theta), &shapes);
    assert_eq!(spot(2.0), 7.0);
    assert!((spot(2.0 + 3.0 * TAU + 0.05) - spot(2.05)).abs() < 1e-12);
    let gaussian = 7.0 * (-(0.05f64 / 0.2).powi(2)).exp();
    assert!((spot(2.05) / gaussian - 1.0).abs() < 1e-3);
    assert!(spot(2.0 + std::f64::consts::PI) < 1e-40);
}

/// The fade: one at the record's start, 1/e after τ, the same whatever the state.
#[test]
fn a_fade_is_one_at_the_start_and_one_over_e_after_its_time_constant() {
    let shapes = Shapes {
        fade: 0.02,
        ..shapes()
    };
    let at = |t: f64, speed: f64| Point {
        t,
        current: 3.0,
        speed,
        voltage: 24.0,
        charge: 0.0,
        heat: 0.0,
        theta: 1.0,
    };
    assert_eq!(value(FADE, &at(0.0, 5.0), &shapes), 1.0);
    let e = value(FADE, &at(0.02, 5.0), &shapes);
    assert!((e - (-1.0f64).exp()).abs() < 1e-15);
    assert_eq!(e, value(FADE, &at(0.02, -900.0), &shapes));
    assert_eq!(FUNCTIONS[FADE], "exp(-t/tau)");
    assert_eq!(pretty(FUNCTIONS[FADE]), "exp(-t/τ)");
}

/// The current's sign, smoothed over I_s as the library's voltage drop smooths it (tanh), read
/// of I only; the speed's sign times the heat, a drag of the torque balance only, reading the
/// law's heat state.
#[test]
fn the_current_s_sign_is_read_of_i_and_the_speed_s_sign_times_the_heat_drags_the_torque() {
    let at = |current: f64, speed: f64| Point {
        t: 0.0,
        current,
        speed,
        voltage: 0.0,
        charge: 0.0,
        heat: 40.0,
        theta: 0.0,
    };
    let s = Shapes {
        current_smooth: 2.0,
        ..shapes()
    };
    assert!((value(SIGN_I, &at(3.0, 0.0), &s) - 1.5f64.tanh()).abs() < 1e-15);
    assert_eq!(value(SIGN_I, &at(-300.0, 0.0), &s), -1.0);
    assert_eq!(value(SIGN_OMEGA_HEAT, &at(0.0, -500.0), &s), -40.0);
    assert_eq!(value(SIGN_OMEGA_HEAT, &at(0.0, 0.0), &s), 0.0);
    assert_eq!(state_of(SIGN_OMEGA_HEAT), Some(1));
    assert_eq!(state_of(SIGN_I), None);
    let offered =
        |f: usize| -> Vec<bool> { (0..BALANCES.len()).map(|b| offered_in(f, b)).collect() };
    assert_eq!(offered(SIGN_I), vec![false, false, true, false]);
    assert_eq!(offered(SIGN_OMEGA_HEAT), vec![true, false, false, false]);
    assert_eq!(
        index_of("measurement:I:sign(I)"),
        Ok(2 * N_FUNCTIONS + SIGN_I)
    );
    assert_eq!(index_of("torque:sign(omega)*heat"), Ok(SIGN_OMEGA_HEAT));
}
