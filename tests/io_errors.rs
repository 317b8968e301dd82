//! Every file the tool reads: good files round-trip, bad files give one error that names the file,
//! the line and the field, and no input makes a reader panic.

use std::io::Write;
use std::path::{Path, PathBuf};

use motorcal::io::{
    AtomicFile, ChannelMap, CmdStanWriter, InputError, ModelFile, Recording, SAMPLER_COLUMNS,
    SamplerColumns, read_draws, read_model_file, read_recording, write_atomically,
    write_model_file, write_recording,
};
use motorcal::motor::VoltageInput;

const SHARED: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../shared");

/// A fresh directory for one test, under the system's temp directory.
fn scratch(test: &str) -> PathBuf {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("motorcal-io-errors-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn put(dir: &Path, name: &str, contents: impl AsRef<[u8]>) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, contents).unwrap();
    path
}

/// The error's one line names the file, the line and (when given) the field.
fn check(err: &InputError, file: &str, line: usize, field: Option<&str>) {
    let shown = err.to_string();
    assert!(!shown.contains('\n'), "{shown}");
    assert!(shown.contains(file), "file {file} missing from: {shown}");
    assert!(
        shown.contains(&format!(":{line}: ")),
        "line {line} missing from: {shown}"
    );
    assert_eq!(err.line, Some(line), "{shown}");
    if let Some(field) = field {
        assert!(
            shown.contains(&format!("field '{field}'")),
            "field {field} missing from: {shown}"
        );
    }
}

fn shared(rel: &str) -> Option<PathBuf> {
    let path = Path::new(SHARED).join(rel);
    if path.exists() {
        Some(path)
    } else {
        eprintln!("skipped: {} is absent", path.display());
        None
    }
}

#[test]
fn bad_recordings_are_located() {
    let dir = scratch("recordings");
    let map = ChannelMap::default();
    // (file name, contents, line, field)
    let cases: &[(&str, &[u8], usize, Option<&str>)] = &[
        (
            "missing_column.csv",
            b"t,I,speed\n0.1,1,2\n0.2,1,2\n",
            1,
            Some("omega"),
        ),
        (
            "non_numeric.csv",
            b"t,I,omega\n0.1,1,2\n0.2,abc,2\n",
            3,
            Some("I"),
        ),
        (
            "empty_cell.csv",
            b"t,I,omega\n0.1,1,2\n0.2,,2\n",
            3,
            Some("I"),
        ),
        (
            "nan.csv",
            b"# comment\nt,I,omega\n0.1,1,NaN\n0.2,1,2\n",
            3,
            Some("omega"),
        ),
        (
            "inf.csv",
            b"t,I,omega\n0.1,1,2\n\n0.2,inf,2\n",
            4,
            Some("I"),
        ),
        (
            "huge.csv",
            b"t,I,omega\n0.1,1,2\n0.2,1,1e999\n",
            3,
            Some("omega"),
        ),
        (
            "not_increasing.csv",
            b"t,I,omega\n0.1,1,2\n0.3,1,2\n0.2,1,2\n",
            4,
            Some("t"),
        ),
        (
            "repeated_t.csv",
            b"t,I,omega\n0.1,1,2\n0.1,1,2\n",
            3,
            Some("t"),
        ),
        (
            "negative_t.csv",
            b"t,I,omega\n-0.1,1,2\n0.1,1,2\n",
            2,
            Some("t"),
        ),
        ("one_row.csv", b"t,I,omega\n0.1,1,2\n", 2, Some("t")),
        ("header_only.csv", b"t,I,omega\n", 1, Some("t")),
        (
            "short_row.csv",
            b"t,I,omega,U\n0.1,1,2,24\n0.2,1,2\n",
            3,
            Some("U"),
        ),
        ("long_row.csv", b"t,I,omega\n0.1,1,2\n0.2,1,2,3\n", 3, None),
        (
            "latin1_cell.csv",
            b"t,I,omega\n0.1,1,2\n0.2,1,\xB02\n",
            3,
            Some("omega"),
        ),
        ("latin1_header.csv", b"t,I,\xF6mega\n0.1,1,2\n", 1, None),
        ("nul.csv", b"t,I,omega\n0.1,1\x00,2\n", 2, None),
        (
            "duplicate.csv",
            b"t,I,omega,t\n0.1,1,2,3\n0.2,1,2,3\n",
            1,
            Some("t"),
        ),
    ];
    for &(name, contents, line, field) in cases {
        let path = put(&dir, name, contents);
        let err = read_recording(&path, &map).expect_err(name);
        check(&err, name, line, field);
    }

    let empty = put(&dir, "empty.csv", b"");
    let err = read_recording(&empty, &map).unwrap_err();
    assert!(
        err.to_string().starts_with(&empty.display().to_string()),
        "{err}"
    );
    let missing = dir.join("does_not_exist.csv");
    let err = read_recording(&missing, &map).unwrap_err();
    assert!(err.to_string().contains("does_not_exist.csv"), "{err}");

    // The missing-column message lists what the file has, so the user can fix the mapping.
    let err = read_recording(&dir.join("missing_column.csv"), &map).unwrap_err();
    assert!(err.message.contains("'speed'"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_model_files_are_located() {
    let dir = scratch("models");
    let cases: &[(&str, &str, usize, &str)] = &[
        ("syntax.toml", "[motor]\nR = 0.1\nL = = 2\n", 3, "motor.L"),
        (
            "unknown_key.toml",
            "schema = 1\n[motor]\nR = 0.1\nr = 0.2\n",
            4,
            "motor.r",
        ),
        ("unknown_table.toml", "[motors]\nR = 0.1\n", 1, "motors"),
        (
            "unknown_channel.toml",
            "[channels]\nI = \"amps\"\nspeed = \"w\"\n",
            3,
            "channels.speed",
        ),
        ("wrong_type.toml", "[motor]\nJ = \"5e-5\"\n", 2, "motor.J"),
        (
            "wrong_channel_type.toml",
            "[channels]\nt = 3\n",
            2,
            "channels.t",
        ),
        ("schema.toml", "schema = 7\n[motor]\n", 1, "schema"),
        (
            "negative_r.toml",
            "[motor]\nc_m = 0.01\nR = -0.1\n",
            3,
            "motor.R",
        ),
        ("zero_l.toml", "[motor]\nL = 0\n", 2, "motor.L"),
        ("nan.toml", "[motor]\nU = nan\n", 2, "motor.U"),
        ("inf.toml", "[motor]\nd = -inf\n", 2, "motor.d"),
        ("huge.toml", "[motor]\nJ = 1e999\n", 2, "motor.J"),
        ("dotted.toml", "motor.J = -1.0\n", 1, "motor.J"),
        (
            "duplicate.toml",
            "[motor]\nR = 0.1\nR = 0.2\n",
            3,
            "motor.R",
        ),
        // Only a position loop has an initial position to offset.
        (
            "q0_offset_voltage.toml",
            "[motor]\nR = 0.1\nq0_offset = 1e-6\n",
            3,
            "motor.q0_offset",
        ),
        (
            "q0_offset_calibrated_current.toml",
            "schema = 2\nbase = \"current_driven\"\n[motor]\nJ = 1e-4\n[calibrate]\nJ = {}\nq0_offset = {}\n",
            7,
            "calibrate.q0_offset",
        ),
    ];
    for &(name, contents, line, field) in cases {
        let path = put(&dir, name, contents);
        let err = read_model_file(&path).expect_err(name);
        check(&err, name, line, Some(field));
    }
    let err =
        read_model_file(&put(&dir, "bad_utf8.toml", b"[motor]\nR = 0.1 # \xFF\n")).unwrap_err();
    check(&err, "bad_utf8.toml", 2, Some("motor.R"));
    let err = read_model_file(&put(&dir, "binary.toml", b"\x00\x01\x02")).unwrap_err();
    check(&err, "binary.toml", 1, None);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_draws_are_located() {
    let dir = scratch("draws");
    let cmdstan = |name: &str, rows: &[&str]| {
        let mut text = format!("# seed = 1\n{},a,b\n", SAMPLER_COLUMNS.join(","));
        for row in rows {
            text.push_str(&format!("-1,0.9,0.1,3,7,0,2,{row}\n"));
        }
        put(&dir, name, text)
    };
    let a = cmdstan("a.csv", &["1,2", "3,4", "5,6"]);
    let short = cmdstan("short.csv", &["1,2", "3,4"]);
    let err = read_draws(&[a.clone(), short]).unwrap_err();
    check(&err, "short.csv", 4, None);

    let other = put(
        &dir,
        "other.csv",
        format!(
            "{},a,c\n-1,0.9,0.1,3,7,0,2,1,2\n",
            SAMPLER_COLUMNS.join(",")
        ),
    );
    check(
        &read_draws(&[a.clone(), other]).unwrap_err(),
        "other.csv",
        1,
        Some("b"),
    );

    let bad_cell = cmdstan("bad_cell.csv", &["1,2", "3,x"]);
    check(
        &read_draws(&[bad_cell]).unwrap_err(),
        "bad_cell.csv",
        4,
        Some("b"),
    );
    let nan = cmdstan("nan.csv", &["1,nan"]);
    check(&read_draws(&[nan]).unwrap_err(), "nan.csv", 3, Some("b"));
    let ragged = cmdstan("ragged.csv", &["1,2", "3"]);
    check(
        &read_draws(&[ragged]).unwrap_err(),
        "ragged.csv",
        4,
        Some("b"),
    );
    let none = cmdstan("none.csv", &[]);
    check(&read_draws(&[none]).unwrap_err(), "none.csv", 2, None);

    let long = put(
        &dir,
        "long.csv",
        "chain,draw,a,b\n0,0,1,2\n0,1,1,2\n1,0,1,2\n",
    );
    check(
        &read_draws(&[long]).unwrap_err(),
        "long.csv",
        4,
        Some("chain"),
    );
    let label = put(&dir, "label.csv", "chain,draw,a\n0,0,1\nzero,1,1\n");
    check(
        &read_draws(&[label]).unwrap_err(),
        "label.csv",
        3,
        Some("chain"),
    );
    let utf8 = put(&dir, "utf8.csv", b"chain,draw,a\n0,0,1\n0,1,\xE91\n");
    check(&read_draws(&[utf8]).unwrap_err(), "utf8.csv", 3, Some("a"));

    assert!(read_draws(&[]).is_err());
    assert!(read_draws(&[put(&dir, "empty.csv", "")]).is_err());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Deterministic pseudo-random bytes (an LCG): garbage, truncated and binary files must give
/// errors, never panics.
#[test]
fn garbage_never_panics() {
    let dir = scratch("garbage");
    let mut state: u64 = 0x2545_F491_4F6C_DD1D;
    let mut next = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 33) as u8
    };
    let alphabet = b"t,I,omega,U\n#0123456789.eE+-naif \r\"=[]motor";
    for case in 0..300 {
        let len = usize::from(next()) * 4;
        let bytes: Vec<u8> = (0..len)
            .map(|_| {
                let b = next();
                // Mostly plausible characters, so parsing gets past the first line sometimes.
                if case % 3 == 0 {
                    b
                } else {
                    alphabet[usize::from(b) % alphabet.len()]
                }
            })
            .collect();
        let path = put(&dir, "garbage", &bytes);
        let _ = read_recording(&path, &ChannelMap::default());
        let _ = read_model_file(&path);
        let _ = read_draws(&[path]);
    }
    // Truncations of a good file at every byte.
    let good = b"# c\nt,I,omega,U\n0.001,1.5,2e1,24\n0.002,1.25,3,24.0\n";
    for cut in 0..=good.len() {
        let path = put(&dir, "cut.csv", &good[..cut]);
        if let Err(e) = read_recording(&path, &ChannelMap::default()) {
            assert!(e.to_string().contains("cut.csv"));
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn recordings_round_trip_exactly() {
    let dir = scratch("recording_round_trip");
    let time: Vec<f64> = (1..=50).map(|i| f64::from(i) * 0.5 / 501.0).collect();
    let current: Vec<f64> = time
        .iter()
        .map(|t| (t * 1e3).sin() * 1e-7 + 1.0 / 3.0)
        .collect();
    let speed: Vec<f64> = time.iter().map(|t| t.exp() * 1e300).collect();
    let voltage: Vec<f64> = time
        .iter()
        .map(|&t| if t < 0.02 { 24.0 } else { -8.0 })
        .collect();
    for with_voltage in [false, true] {
        let rec = Recording {
            source: String::new(),
            time: time.clone(),
            channels: vec![
                ("I".into(), current.clone()),
                ("omega".into(), speed.clone()),
            ],
            voltage: with_voltage.then(|| voltage.clone()),
            inputs: Vec::new(),
        };
        let path = dir.join(format!("sub/rec_{with_voltage}.csv"));
        write_recording(&path, &rec).unwrap();
        let header = std::fs::read_to_string(&path).unwrap();
        let header = header.lines().next().unwrap();
        assert_eq!(
            header,
            if with_voltage {
                "t,I,omega,U"
            } else {
                "t,I,omega"
            }
        );
        let back = read_recording(&path, &ChannelMap::default()).unwrap();
        assert_eq!(back.source, path.display().to_string());
        assert_eq!(
            Recording {
                source: String::new(),
                ..back.clone()
            },
            rec
        );
        assert_eq!(back.n_samples(), 50);
        assert_eq!(back.last_time(), time[49]);
        match back.voltage_input() {
            VoltageInput::Held { times, values } => {
                assert!(with_voltage);
                assert_eq!((times, values), (time.clone(), voltage.clone()));
            }
            VoltageInput::Constant => assert!(!with_voltage),
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn model_files_round_trip_exactly() {
    let dir = scratch("model_round_trip");
    let mut model = ModelFile::default();
    model.motor.torque_constant = 0.009;
    model.motor.inertia = 4.999_999_999_999_9e-5;
    model.motor.initial_speed = -1.0 / 7.0;
    model.channels = ChannelMap {
        t: "t_s".into(),
        current: "I_A".into(),
        speed: "w_rad_s".into(),
        voltage: "U".into(),
        ..ChannelMap::default()
    };
    let path = dir.join("models/m.toml");
    write_model_file(&path, &model).unwrap();
    assert_eq!(read_model_file(&path).unwrap(), model);
    // A drive base with its [drive] table and the channels only it uses.
    model.schema = 2;
    model.base = motorcal::motor::Base::PositionLoop;
    model.drive = motorcal::motor::DriveSettings {
        input_limit: Some(10.0),
        position_gain: 160.18,
        velocity_gain: 243.45,
        delay_samples: 1,
        substeps: 2,
    };
    model.channels.q = "qm_m".into();
    model.channels.q_ref = "qg_m".into();
    model.channels.force = "force_N".into();
    model.channels.disturbance = "pulses_raw".into();
    write_model_file(&path, &model).unwrap();
    assert_eq!(read_model_file(&path).unwrap(), model);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn draws_round_trip_exactly_through_cmdstan_files() {
    let dir = scratch("draws_round_trip");
    let names: Vec<String> = ["R", "sigma_I", "a.1"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    let metadata = vec![
        ("seed".to_string(), "42".to_string()),
        (
            "motorcal_version".to_string(),
            env!("CARGO_PKG_VERSION").to_string(),
        ),
    ];
    let mut paths = Vec::new();
    let mut expected = Vec::new();
    for chain in 0..3 {
        let path = dir.join(format!("out/chain_{chain}.csv"));
        let mut writer = CmdStanWriter::create(&path, &metadata, &names).unwrap();
        let mut columns = vec![Vec::new(); names.len()];
        // A warm-up draw, then CmdStan's marker: readers keep only what follows.
        writer
            .write_draw(&SamplerColumns::default(), &[9.0, 9.0, 9.0])
            .unwrap();
        writer
            .write_comment("Adaptation terminated\nStep size = 0.1")
            .unwrap();
        for draw in 0..20 {
            let values = [
                0.1 + f64::from(draw) * 1e-17,
                1.0 / f64::from(chain * 20 + draw + 1),
                -1e-300 * f64::from(draw),
            ];
            for (c, v) in columns.iter_mut().zip(values) {
                c.push(v);
            }
            let sampler = SamplerColumns {
                lp: -1234.5,
                accept_stat: 0.93,
                stepsize: 0.0123,
                treedepth: 4,
                n_leapfrog: 15,
                divergent: draw == 3,
                energy: 1240.25,
                weight: None,
            };
            writer.write_draw(&sampler, &values).unwrap();
        }
        assert!(!path.exists(), "the file appears only on finish");
        writer.finish().unwrap();
        paths.push(path);
        expected.push(columns);
    }
    let text = std::fs::read_to_string(&paths[0]).unwrap();
    assert!(
        text.starts_with("# seed = 42\n# motorcal_version = "),
        "{text}"
    );
    assert!(text.contains(&format!("\n{},R,sigma_I,a.1\n", SAMPLER_COLUMNS.join(","))));
    assert!(text.contains("-1234.5,0.93,0.0123,4,15,1,1240.25,"));

    let set = read_draws(&paths).unwrap();
    assert_eq!(set.names, names);
    assert_eq!(set.chains, expected);
    assert_eq!((set.n_chains(), set.n_draws(), set.n_params()), (3, 20, 3));
    assert_eq!(
        set.parameter("sigma_I").unwrap()[1],
        expected[1][1].as_slice()
    );

    // A write with the wrong number of values is refused, and the writer dropped unfinished
    // leaves nothing.
    let path = dir.join("out/abandoned.csv");
    let mut writer = CmdStanWriter::create(&path, &[], &names).unwrap();
    assert!(
        writer
            .write_draw(&SamplerColumns::default(), &[1.0])
            .is_err()
    );
    drop(writer);
    assert!(!path.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn long_draws_split_by_chain_and_reorder_columns() {
    let dir = scratch("long_draws");
    let long = put(
        &dir,
        "long.csv",
        "chain,draw,a,b\n1,0,10,20\n0,0,1,2\n1,1,11,21\n0,1,3,4\n",
    );
    let cmdstan = put(
        &dir,
        "c.csv",
        format!(
            "# x\n{},b,a\n0,0,0,0,0,0,0,5,6\n0,0,0,0,0,0,0,7,8\n",
            SAMPLER_COLUMNS.join(",")
        ),
    );
    let set = read_draws(&[long, cmdstan]).unwrap();
    assert_eq!(set.names, ["a", "b"]);
    assert_eq!(
        set.chains,
        [
            vec![vec![1.0, 3.0], vec![2.0, 4.0]],
            vec![vec![10.0, 11.0], vec![20.0, 21.0]],
            vec![vec![6.0, 8.0], vec![5.0, 7.0]],
        ]
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn an_uncommitted_atomic_file_leaves_the_old_file() {
    let dir = scratch("atomic");
    let path = dir.join("report.json");
    write_atomically(&path, b"{\"good\": true}").unwrap();
    {
        let mut file = AtomicFile::create(&path).unwrap();
        file.write_all(b"{\"half\": ").unwrap();
        // Dropped here, as when a run fails before committing.
    }
    assert_eq!(std::fs::read(&path).unwrap(), b"{\"good\": true}");
    assert_eq!(
        std::fs::read_dir(&dir).unwrap().count(),
        1,
        "no temporary file left behind"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn concealed_dev_cases_parse() {
    let Some(root) = shared("data/concealed-dev") else {
        return;
    };
    for case in 1..=14 {
        let dir = root.join(format!("case{case:02}"));
        let model = read_model_file(&dir.join("motor.toml")).unwrap();
        let rec = read_recording(&dir.join("recording.csv"), &model.channels).unwrap();
        assert_eq!(rec.n_samples(), 501, "case {case}");
        assert_eq!(rec.channels.len(), 2);
        assert!((rec.last_time() - 0.5).abs() < 1e-12);
    }
    // case01 is type B (a U column), case03 type A.
    let model = read_model_file(&root.join("case01/motor.toml")).unwrap();
    assert_eq!(model.motor, motorcal::motor::MotorParameters::default());
    let rec = read_recording(&root.join("case01/recording.csv"), &model.channels).unwrap();
    assert_eq!(rec.time[0], 0.000998003992015968);
    assert_eq!(rec.channel("I").unwrap()[0], 153.6416506410527);
    assert_eq!(rec.channel("omega").unwrap()[0], 18.49820337803056);
    let voltage = rec.voltage.as_ref().expect("case01 records U");
    assert_eq!(voltage[0], 24.0);
    assert!(
        voltage.iter().any(|&u| u < 0.0),
        "the type-B profile reverses"
    );
    let rec = read_recording(&root.join("case03/recording.csv"), &ChannelMap::default()).unwrap();
    assert_eq!(rec.voltage_input(), VoltageInput::Constant);
}

#[test]
fn real_recordings_parse_with_a_channel_map() {
    let Some(path) = shared("data/real/hsm150/idf_pos_0.06_1.csv") else {
        return;
    };
    let map = ChannelMap {
        t: "t_s".into(),
        current: "I_A".into(),
        speed: "w_rad_s".into(),
        ..ChannelMap::default()
    };
    let rec = read_recording(&path, &map).unwrap();
    assert_eq!(rec.time[0], 0.0);
    assert!(rec.n_samples() > 100);
    assert!(rec.voltage.is_none());
}

#[test]
fn the_peers_long_draws_parse() {
    let Some(path) = shared("peers/data/numpyro_k9_draws.csv") else {
        return;
    };
    let set = read_draws(&[path]).unwrap();
    assert_eq!(
        (set.n_chains(), set.n_draws(), set.n_params()),
        (4, 1000, 23)
    );
    assert_eq!(set.names[..3], ["R", "sigma_I", "sigma_w"]);
    // The file's text has more digits than an f64 holds; it must parse to the nearest f64.
    let first: f64 = "0.097905486642797246".parse().unwrap();
    assert_eq!(set.chains[0][0][0], first);
    assert!(set.chains.iter().all(|c| c.iter().all(|p| p.len() == 1000)));
}
