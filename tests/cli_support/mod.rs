//! What the tests that run the `motorcal` binary share: running it, a scratch folder of their
//! own, and the claim that a refused command says so in one line.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The binary run with `args`.
pub fn motorcal(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_motorcal"))
        .args(args)
        .output()
        .expect("the binary runs")
}

/// An empty folder `motorcal-{suite}-{pid}-{name}` under the target's scratch space.
pub fn scratch(suite: &str, name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("motorcal-{suite}-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `o` failed with one line on stderr, no panic, naming each of `needles`.
pub fn one_error_line(o: &Output, needles: &[&str]) {
    assert!(!o.status.success(), "expected a failure");
    let err = String::from_utf8_lossy(&o.stderr);
    let lines: Vec<&str> = err.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "expected one error line, got: {err}");
    assert!(!err.contains("panicked"), "{err}");
    for n in needles {
        assert!(err.contains(n), "'{err}' does not mention '{n}'");
    }
}
