//! End-to-end tests of the `shadow` binary: one test binary, one module
//! per command family.

mod animate;
mod cli;
mod csg;
mod raster;
mod shadows;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The binary under test: this build's, or the one `SHADOW_BIN` names
/// (`.ci/run` runs the suite again against the release binary, the one
/// the README's first command builds).
fn shadow_bin() -> PathBuf {
    std::env::var_os("SHADOW_BIN").map_or_else(
        || PathBuf::from(env!("CARGO_BIN_EXE_shadow")),
        PathBuf::from,
    )
}

fn shadow(args: &[&str]) -> Output {
    Command::new(shadow_bin())
        .args(args)
        .output()
        .expect("the shadow binary runs")
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A fresh path in cargo's per-test scratch directory.
fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("shadow-cli-tests");
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    let _ = std::fs::remove_file(&p);
    p
}

fn assert_failed_with(o: &Output, needles: &[&str]) {
    assert_eq!(o.status.code(), Some(1), "stderr: {}", stderr(o));
    let err = stderr(o);
    assert!(err.starts_with("error: "), "{err}");
    for n in needles {
        assert!(err.contains(n), "`{n}` not in {err:?}");
    }
    assert!(!err.contains("panicked"), "{err}");
}
