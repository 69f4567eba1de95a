//! Running the `rtid` binary from an integration test: the command in a folder, and its
//! output when it must succeed or fail. (Apart from `support`, which the benches share
//! and where the binary's path is not known.)
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The project's root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// `rtid ARGS…` run in `dir`.
pub fn rtid(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rtid"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("the rtid binary runs")
}

/// The standard output of a run that must succeed.
pub fn ok(out: &Output) -> String {
    assert!(
        out.status.success(),
        "rtid failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout.clone()).unwrap()
}

/// The standard error of a run that must fail.
pub fn err(out: &Output) -> String {
    assert!(!out.status.success(), "rtid succeeded where it should not");
    String::from_utf8(out.stderr.clone()).unwrap()
}
