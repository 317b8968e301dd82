//! `simulate --input FILE`: a `t,U` file drives the motor at its own times, the recording
//! carries the U column, and a bad file gets one clear error and writes nothing.

mod cli_support;

use cli_support::{motorcal, one_error_line, scratch};

use motorcal::io::{ChannelMap, read_model_file, read_recording, read_recording_for};

#[test]
fn an_input_file_drives_the_recording_at_its_times() {
    let dir = scratch("siminput", "file");
    let input = dir.join("input.csv");
    let mut text = String::from("t,U\n");
    for i in 1..=200 {
        let t = i as f64 * 1e-3;
        let u = if i <= 120 { 12.0 } else { -6.0 };
        text.push_str(&format!("{t},{u}\n"));
    }
    std::fs::write(&input, &text).unwrap();
    let out = dir.join("sim");
    let o = motorcal(&[
        "simulate",
        "--input",
        input.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let rec = read_recording(&out.join("recording.csv"), &ChannelMap::default()).unwrap();
    assert_eq!(rec.n_samples(), 200);
    assert_eq!(rec.time[0], 1e-3);
    let u = rec.voltage.as_ref().expect("the recording carries U");
    assert_eq!((u[0], u[119], u[120]), (12.0, 12.0, -6.0));
    // After the reversal the current turns negative: the file's input drove the motor.
    let current = rec.channel("I").unwrap();
    assert!(current[60] > 20.0 && current[125] < -20.0, "{current:?}");
}

#[test]
fn a_profile_name_still_works_and_a_bad_file_writes_nothing() {
    let dir = scratch("siminput", "bad");
    let out = dir.join("sim");
    let o = motorcal(&[
        "simulate",
        "--input",
        "step",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let before = std::fs::read(out.join("recording.csv")).unwrap();

    let bad = dir.join("bad.csv");
    std::fs::write(&bad, "t,U\n0.001,24\n0.002,x\n").unwrap();
    let o = motorcal(&[
        "simulate",
        "--input",
        bad.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    one_error_line(&o, &["bad.csv:3", "U"]);

    let no_u = dir.join("no_u.csv");
    std::fs::write(&no_u, "t,V\n0.001,24\n0.002,3\n").unwrap();
    let o = motorcal(&[
        "simulate",
        "--input",
        no_u.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    one_error_line(&o, &["no_u.csv", "U"]);

    let o = motorcal(&[
        "simulate",
        "--input",
        "reversl",
        "--out",
        out.to_str().unwrap(),
    ]);
    one_error_line(&o, &["reversl"]);

    let good = dir.join("good.csv");
    std::fs::write(&good, "t,U\n0.001,24\n0.002,3\n").unwrap();
    let o = motorcal(&[
        "simulate",
        "--input",
        good.to_str().unwrap(),
        "--samples",
        "10",
        "--out",
        out.to_str().unwrap(),
    ]);
    one_error_line(&o, &["--samples"]);
    assert_eq!(std::fs::read(out.join("recording.csv")).unwrap(), before);
}

/// A drive base measures other channels than I and ω (HSM150's current-driven base measures ω
/// alone): the noise line names the model's own, where it used to index a second channel. Its
/// input is the commanded current of a `t,I` file; a profile has no current to run at.
#[test]
fn a_drive_base_truth_is_simulated_and_its_channels_named() {
    let dir = scratch("siminput", "drive-base");
    let input = dir.join("current.csv");
    std::fs::write(&input, "t,I\n0.001,1\n0.002,1\n0.003,-1\n").unwrap();
    let truth = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/hsm150/model.toml");
    let out = dir.join("sim");
    let simulate = |input: &str| {
        motorcal(&[
            "simulate",
            "--truth",
            truth,
            "--input",
            input,
            "--out",
            out.to_str().unwrap(),
        ])
    };
    let o = simulate(input.to_str().unwrap());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    let stdout = String::from_utf8_lossy(&o.stdout);
    let line = stdout
        .lines()
        .find(|l| l.starts_with("realised noise sd:"))
        .expect("the noise line");
    assert!(line.contains("omega") && !line.contains(','), "{line}");
    // Its columns are named as the model file written beside it names them (HSM150's t_s,
    // w_rad_s, I_A), so that file reads the record back.
    let model = read_model_file(&out.join("motor.toml")).unwrap();
    let rec = read_recording_for(&out.join("recording.csv"), &model.channels, model.base).unwrap();
    assert_eq!(rec.input("I").unwrap(), [1.0, 1.0, -1.0]);
    assert_eq!(rec.channel("omega").unwrap().len(), 3);
    std::fs::remove_dir_all(&out).unwrap();
    one_error_line(&simulate("constant"), &["--input constant", "t,I"]);
    assert!(!out.exists());
}
