//! Every figure renders to a PNG and refuses bad input without leaving a file.

use std::fs;
use std::path::{Path, PathBuf};

use super::frame::*;
use super::*;

const PNG_SIGNATURE: [u8; 8] = [0x89, b'P', b'N', b'G', 0x0d, 0x0a, 0x1a, 0x0a];

fn out(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("motorcal_plot_{name}.png"))
}

fn assert_png(path: &Path) {
    let bytes = fs::read(path).expect("png written");
    assert_eq!(&bytes[..8], &PNG_SIGNATURE, "{}", path.display());
    assert!(
        bytes.len() > 10_000,
        "{} is only {} bytes",
        path.display(),
        bytes.len()
    );
    // No temporary file left next to it.
    let dir = path.parent().unwrap();
    let stem = format!(".{}.", path.file_name().unwrap().to_string_lossy());
    let leftovers = fs::read_dir(dir)
        .unwrap()
        .filter_map(Result::ok)
        .filter(|e| e.file_name().to_string_lossy().starts_with(&stem))
        .count();
    assert_eq!(leftovers, 0, "temporary files left for {}", path.display());
}

fn assert_err_no_file(path: &Path, r: Result<(), PlotError>) {
    let _ = fs::remove_file(path);
    assert!(r.is_err());
    assert!(!path.exists());
}

/// Small deterministic normal generator (xorshift + Box–Muller).
struct Rng(u64);
impl Rng {
    fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        ((self.0 >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
    fn normal(&mut self) -> f64 {
        let (u, v) = (self.uniform(), self.uniform());
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }
}

fn predictive_example() -> PredictivePlot {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let times: Vec<f64> = (0..400).map(|i| i as f64 * 0.005).collect();
    let mut channels = Vec::new();
    for (name, unit, sigma) in [("I", "A", 0.04), ("ω", "rad/s", 0.8)] {
        let truth = |t: f64| {
            if name == "I" {
                2.0 * (-t / 0.15).exp() + 0.3 + 0.08 * (9.0 * t).sin()
            } else {
                40.0 * (1.0 - (-t / 0.3).exp()) - 1.5 * (4.0 * t).sin()
            }
        };
        let model = |t: f64| {
            if name == "I" {
                2.0 * (-t / 0.16).exp() + 0.3
            } else {
                40.0 * (1.0 - (-t / 0.3).exp())
            }
        };
        let mean: Vec<f64> = times.iter().map(|&t| truth(t) + 0.01).collect();
        let half: Vec<f64> = times
            .iter()
            .map(|&t| 2.0 * sigma * (0.4 + 0.3 * (3.0 * t).cos().abs()))
            .collect();
        let mut measured: Vec<f64> = times
            .iter()
            .map(|&t| truth(t) + sigma * rng.normal())
            .collect();
        measured[17] = f64::NAN; // a missing sample
        channels.push(ChannelPrediction {
            name: name.into(),
            unit: unit.into(),
            model: times.iter().map(|&t| model(t)).collect(),
            lower: mean.iter().zip(&half).map(|(m, h)| m - h).collect(),
            upper: mean.iter().zip(&half).map(|(m, h)| m + h).collect(),
            mean,
            measured,
            sigma,
        });
    }
    PredictivePlot {
        title: "Posterior predictive check — recording 1".into(),
        times,
        channels,
    }
}

#[test]
fn posterior_predictive_writes_png() {
    let p = out("predictive");
    posterior_predictive(&p, &predictive_example()).unwrap();
    assert_png(&p);
}

#[test]
fn posterior_predictive_rejects_empty_and_inconsistent_input() {
    let p = out("predictive_empty");
    assert_err_no_file(&p, posterior_predictive(&p, &PredictivePlot::default()));
    let mut ex = predictive_example();
    ex.channels.clear();
    assert_err_no_file(&p, posterior_predictive(&p, &ex));
    let mut ex = predictive_example();
    ex.channels[1].upper.pop();
    let err = posterior_predictive(&p, &ex).unwrap_err();
    assert!(err.message().contains("upper"), "{err}");
    assert!(!p.exists());
    let mut ex = predictive_example();
    for ch in &mut ex.channels {
        for v in [
            &mut ch.measured,
            &mut ch.model,
            &mut ch.mean,
            &mut ch.lower,
            &mut ch.upper,
        ] {
            v.iter_mut().for_each(|x| *x = f64::NAN);
        }
    }
    assert_err_no_file(&p, posterior_predictive(&p, &ex));
}

#[test]
fn posterior_predictive_survives_degenerate_data() {
    let p = out("predictive_degenerate");
    let mut ex = predictive_example();
    // Constant channel, infinities, a channel without any finite value, zero sigma.
    let n = ex.times.len();
    ex.channels[0] = ChannelPrediction {
        name: "I".into(),
        unit: "A".into(),
        measured: vec![1.0; n],
        model: vec![1.0; n],
        mean: vec![1.0; n],
        lower: vec![1.0; n],
        upper: vec![f64::INFINITY; n],
        sigma: 0.0,
    };
    ex.channels[1].measured = vec![f64::NAN; n];
    ex.channels[1].model = vec![f64::NEG_INFINITY; n];
    ex.channels[1].mean = vec![f64::NAN; n];
    ex.channels[1].lower = vec![f64::NAN; n];
    ex.channels[1].upper = vec![f64::NAN; n];
    posterior_predictive(&p, &ex).unwrap();
    assert_png(&p);
}

fn discrepancy_example() -> (Vec<f64>, Vec<DiscrepancyBand>) {
    let times: Vec<f64> = (0..300).map(|i| i as f64 * 0.01).collect();
    let chans = [("I", "A", 0.05), ("ω", "rad/s", 1.2)]
        .into_iter()
        .map(|(name, unit, a)| {
            let d0: Vec<f64> = times
                .iter()
                .map(|&t| a * ((2.1 * t).sin() + 0.3 * (5.0 * t).cos()))
                .collect();
            let mean: Vec<f64> = d0
                .iter()
                .zip(&times)
                .map(|(d, &t)| d + 0.15 * a * (1.3 * t).cos())
                .collect();
            let half: Vec<f64> = times.iter().map(|&t| a * (0.25 + 0.1 * t)).collect();
            DiscrepancyBand {
                name: name.into(),
                unit: unit.into(),
                lower: mean.iter().zip(&half).map(|(m, h)| m - h).collect(),
                upper: mean.iter().zip(&half).map(|(m, h)| m + h).collect(),
                mean,
                reference: Some(d0),
            }
        })
        .collect();
    (times, chans)
}

#[test]
fn discrepancy_band_writes_png() {
    let p = out("discrepancy");
    let (t, ch) = discrepancy_example();
    discrepancy_band(&p, "Discrepancy δ, K = 6 (BM2)", &t, &ch).unwrap();
    assert_png(&p);
}

#[test]
fn discrepancy_band_rejects_empty_input() {
    let p = out("discrepancy_empty");
    let (t, mut ch) = discrepancy_example();
    assert_err_no_file(&p, discrepancy_band(&p, "x", &t, &[]));
    assert_err_no_file(&p, discrepancy_band(&p, "x", &[], &ch));
    ch[0].reference.as_mut().unwrap().push(0.0);
    assert_err_no_file(&p, discrepancy_band(&p, "x", &t, &ch));
}

fn trace_example(n: usize) -> Vec<TraceSeries> {
    let mut rng = Rng(42);
    [
        ("R [Ω]", 1.2, 0.05, 0.9),
        ("k_e [V·s/rad]", 0.05, 0.002, 0.97),
        ("σ_I [A]", 0.04, 0.003, 0.5),
    ]
    .into_iter()
    .map(|(name, mu, sd, rho)| {
        let chains = (0..4)
            .map(|c| {
                let mut x = mu + sd * (c as f64 - 1.5);
                (0..n)
                    .map(|_| {
                        x = mu + rho * (x - mu) + sd * (1.0 - rho * rho).sqrt() * rng.normal();
                        x
                    })
                    .collect()
            })
            .collect();
        TraceSeries {
            name: name.into(),
            chains,
            reference: Some(mu),
        }
    })
    .collect()
}

#[test]
fn traces_writes_png() {
    let p = out("traces");
    traces(&p, "Trace plots, BM1, NUTS", &trace_example(2000)).unwrap();
    assert_png(&p);
    // Long chains are decimated; a constant parameter and NaNs do not break it.
    let mut ex = trace_example(50_000);
    ex[2].chains = vec![vec![0.5; 1000], vec![0.5; 1000]];
    ex[2].reference = None;
    ex[0].chains[1][10] = f64::NAN;
    let p = out("traces_long");
    traces(&p, "Trace plots, long chains", &ex).unwrap();
    assert_png(&p);
}

#[test]
fn traces_rejects_empty_input() {
    let p = out("traces_empty");
    assert_err_no_file(&p, traces(&p, "x", &[]));
    let ex = vec![TraceSeries {
        name: "a".into(),
        chains: vec![vec![]],
        reference: None,
    }];
    assert_err_no_file(&p, traces(&p, "x", &ex));
    let ex = vec![TraceSeries {
        name: "a".into(),
        chains: vec![vec![f64::NAN; 10]],
        reference: None,
    }];
    assert_err_no_file(&p, traces(&p, "x", &ex));
}

fn ess_example() -> Vec<SamplerCurve> {
    let ks: Vec<f64> = (0..=10).map(f64::from).collect();
    [
        ("random-walk MH", 40.0, 0.55),
        ("MALA", 90.0, 0.4),
        ("HMC", 150.0, 0.3),
        ("NUTS", 120.0, 0.18),
    ]
    .into_iter()
    .map(|(name, a, decay)| SamplerCurve {
        sampler: name.into(),
        points: ks
            .iter()
            .map(|&k| {
                let v = a * f64::exp(-decay * k);
                (k, v, v < 1.0)
            })
            .collect(),
    })
    .collect()
}

#[test]
fn ess_per_second_writes_png() {
    let p = out("ess");
    ess_per_second(
        &p,
        "Sampling efficiency, BM2",
        "min ESS per second [1/s]",
        &ess_example(),
    )
    .unwrap();
    assert_png(&p);
    // Non-positive and non-finite values are skipped on the log axis.
    let mut ex = ess_example();
    ex[0].points[3].1 = 0.0;
    ex[1].points[4].1 = -2.0;
    ex[2].points[5].1 = f64::NAN;
    ex[3].points = vec![(2.0, 5.0, false)];
    let p = out("ess_gradient");
    ess_per_second(&p, "Efficiency per gradient", "min ESS per gradient", &ex).unwrap();
    assert_png(&p);
}

#[test]
fn ess_per_second_rejects_empty_input() {
    let p = out("ess_empty");
    assert_err_no_file(&p, ess_per_second(&p, "x", "y", &[]));
    let ex = vec![SamplerCurve {
        sampler: "MH".into(),
        points: vec![(1.0, 0.0, false), (2.0, -1.0, true)],
    }];
    assert_err_no_file(&p, ess_per_second(&p, "x", "y", &ex));
}

fn k_example() -> Vec<KSeries> {
    let k: Vec<f64> = (0..=10).map(f64::from).collect();
    let mean: Vec<f64> = k.iter().map(|&k| 1.2 + 0.1 * (-k).exp()).collect();
    let sd: Vec<f64> = k.iter().map(|&k| 0.01 + 0.004 * k).collect();
    let sig: Vec<f64> = k.iter().map(|&k| 0.3 * (-0.6 * k).exp() + 0.04).collect();
    vec![
        KSeries {
            name: "R".into(),
            unit: "Ω".into(),
            lower: Some(mean.iter().zip(&sd).map(|(m, s)| m - 1.96 * s).collect()),
            upper: Some(mean.iter().zip(&sd).map(|(m, s)| m + 1.96 * s).collect()),
            sd: Some(sd),
            mean,
            k: k.clone(),
            reference: Some(1.2),
            log_y: false,
        },
        KSeries {
            name: "σ_I".into(),
            unit: "A".into(),
            lower: Some(sig.iter().map(|s| s * 0.8).collect()),
            upper: Some(sig.iter().map(|s| s * 1.25).collect()),
            sd: None,
            mean: sig,
            k,
            reference: Some(0.04),
            log_y: true,
        },
    ]
}

#[test]
fn k_study_writes_png() {
    let p = out("kstudy");
    k_study(
        &p,
        "Posterior against the discrepancy degree K",
        &k_example(),
    )
    .unwrap();
    assert_png(&p);
    // All-equal values, NaNs, non-positive values on a log axis.
    let mut ex = k_example();
    ex[0].mean = vec![2.0; 11];
    ex[0].sd = None;
    ex[0].lower = None;
    ex[0].upper = None;
    ex[1].mean[3] = -1.0;
    ex[1].mean[4] = f64::NAN;
    ex[1].lower.as_mut().unwrap()[0] = 0.0;
    let p = out("kstudy_degenerate");
    k_study(&p, "Degenerate", &ex).unwrap();
    assert_png(&p);
}

#[test]
fn k_study_rejects_empty_input() {
    let p = out("kstudy_empty");
    assert_err_no_file(&p, k_study(&p, "x", &[]));
    let mut ex = k_example();
    ex[1].k.clear();
    ex[1].mean.clear();
    assert_err_no_file(&p, k_study(&p, "x", &ex));
    let mut ex = k_example();
    ex[0].sd.as_mut().unwrap().pop();
    assert_err_no_file(&p, k_study(&p, "x", &ex));
}

#[test]
fn failed_plot_leaves_no_file() {
    let dir = std::env::temp_dir().join("motorcal_plot_no_such_dir_x");
    let _ = fs::remove_dir_all(&dir);
    let p = dir.join("f.png");
    let r = ess_per_second(&p, "x", "y", &ess_example());
    assert!(r.is_err());
    assert!(!dir.exists());
}

#[test]
fn plots_from_many_threads() {
    let handles: Vec<_> = (0..4)
        .map(|i| {
            std::thread::spawn(move || {
                let p = out(&format!("thread_{i}"));
                ess_per_second(&p, &format!("thread {i}"), "y", &ess_example()).unwrap();
                assert_png(&p);
                fs::remove_file(&p).unwrap();
            })
        })
        .collect();
    for h in handles {
        h.join().unwrap();
    }
}

#[test]
fn axes_are_sane() {
    let a = linear_axis([0.0, 1.0], 0.0, 0.0, false, 6).unwrap();
    assert_eq!(a.ticks.first(), Some(&0.0));
    assert_eq!(a.ticks.last(), Some(&1.0));
    assert_eq!(a.label(0.2), "0.2");
    let a = linear_axis([3.0, 3.0], 0.05, 0.0, false, 6).unwrap();
    assert!(a.lo < 3.0 && a.hi > 3.0);
    let a = linear_axis([0.0, 0.0], 0.05, 0.0, false, 6).unwrap();
    assert!(a.lo < 0.0 && a.hi > 0.0);
    assert!(linear_axis([f64::NAN, f64::INFINITY], 0.05, 0.0, false, 6).is_none());
    let a = linear_axis([0.0, 10.0], 0.0, 0.5, true, 12).unwrap();
    assert!(a.ticks.iter().all(|t| t.fract() == 0.0));
    let l = log_axis([0.5, 200.0, -1.0, 0.0], 0.05, 8).unwrap();
    assert!(l.ticks.len() >= 3);
    assert!(l.ticks.iter().any(|&t| l.label(t) == "10"));
    let l = log_axis([300.0, 320.0], 0.05, 8).unwrap();
    assert!(l.ticks.len() >= 2, "{l:?}");
    assert!(log_axis([0.0, -3.0], 0.05, 8).is_none());
    assert_eq!(fmt_sig(1e-5), "1e-5");
    assert_eq!(fmt_sig(0.30000000000000004), "0.3");
}

#[test]
fn coefficient_marginals_write_png_and_refuse_mismatched_lengths() {
    let path = out("coefficients");
    let channel = |name: &str, scale: f64| CoefficientMarginals {
        name: name.into(),
        unit: "A".into(),
        mean: (0..10).map(|j| scale / (j as f64 + 1.0)).collect(),
        lower: (0..10)
            .map(|j| scale / (j as f64 + 1.0) - 0.3 * scale)
            .collect(),
        upper: (0..10)
            .map(|j| scale / (j as f64 + 1.0) + 0.3 * scale)
            .collect(),
        reference: Some((0..10).map(|j| scale * 0.9 / (j as f64 + 1.0)).collect()),
    };
    coefficient_marginals(
        &path,
        "coefficients",
        &[channel("I", 1.0), channel("omega", 40.0)],
    )
    .unwrap();
    assert_png(&path);
    let bad = out("coefficients_bad");
    let mut broken = channel("I", 1.0);
    broken.upper.pop();
    assert!(coefficient_marginals(&bad, "bad", &[broken]).is_err());
    assert!(!bad.exists());
}

fn missing_torque_example() -> MissingTorquePlot {
    let speed: Vec<f64> = (0..40).map(|i| -0.12 + 0.006 * i as f64).collect();
    let before = speed
        .iter()
        .map(|v| 20.0 * v.signum() - 200.0 * v)
        .collect();
    let after = speed.iter().map(|v| 0.5 * (30.0 * v).sin()).collect();
    MissingTorquePlot {
        title: "the torque the model misses, against speed".into(),
        speed_unit: "m/s".into(),
        torque_unit: "N".into(),
        curves: vec![
            MissingTorqueCurve {
                label: "before".into(),
                speed: speed.clone(),
                torque: before,
            },
            MissingTorqueCurve {
                label: "after".into(),
                speed,
                torque: after,
            },
        ],
    }
}

#[test]
fn missing_torque_writes_png() {
    let p = out("missing_torque");
    missing_torque(&p, &missing_torque_example()).unwrap();
    assert_png(&p);
}

#[test]
fn missing_torque_rejects_empty_and_inconsistent_input() {
    let p = out("missing_torque_bad");
    let mut plot = missing_torque_example();
    plot.curves[0].torque.pop();
    assert_err_no_file(&p, missing_torque(&p, &plot));
    plot.curves.clear();
    assert_err_no_file(&p, missing_torque(&p, &plot));
}

fn design_example(rival: bool) -> DesignPlot {
    let times: Vec<f64> = (1..=200).map(|i| f64::from(i) / 400.0).collect();
    let input = times
        .iter()
        .map(|t| if *t < 0.25 { 24.0 } else { -12.0 })
        .collect();
    let channel = |name: &str, unit: &str, scale: f64, sigma: f64| DesignChannel {
        name: name.into(),
        unit: unit.into(),
        truth: times
            .iter()
            .map(|t| scale * (1.0 - (-t / 0.05).exp()))
            .collect(),
        rival: if rival {
            times
                .iter()
                .map(|t| scale * (1.0 - (-t / 0.06).exp()))
                .collect()
        } else {
            Vec::new()
        },
        sigma,
    };
    DesignPlot {
        title: "design".into(),
        times: times.clone(),
        input,
        input_label: "U [V]".into(),
        truth: "coulomb_friction".into(),
        rival: rival.then(|| "load_torque".into()),
        channels: vec![
            channel("I", "A", 100.0, 2.0),
            channel("ω", "rad/s", 1500.0, 10.0),
        ],
    }
}

#[test]
fn the_design_figure_draws_a_separating_and_a_pinning_design() {
    for rival in [true, false] {
        let p = out(&format!("design_{rival}"));
        design_figure(&p, &design_example(rival)).unwrap();
        assert_png(&p);
    }
}

#[test]
fn the_design_figure_refuses_a_rival_fit_of_the_wrong_length() {
    let p = out("design_bad");
    let mut ex = design_example(true);
    ex.channels[0].rival.pop();
    let err = design_figure(&p, &ex).unwrap_err();
    assert!(err.message().contains("rival"), "{err}");
    assert!(!p.exists());
    assert_err_no_file(&p, design_figure(&p, &DesignPlot::default()));
}
