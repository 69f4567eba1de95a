//! The identification fixtures are what their generator writes: every line of
//! `fixtures/identification-fixtures.args` run with the real binary into a temporary
//! folder gives the shipped files byte for byte (the simulations are deterministic:
//! each frequency's lane computes what a lone run computes). A change that alters a
//! virtual experiment must regenerate the fixtures and say why.

use std::path::Path;
use std::process::Command;

#[test]
#[cfg_attr(
    not(feature = "slow-tests"),
    ignore = "slow tier: --features slow-tests"
)]
fn the_fixtures_match_their_generator() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let list = std::fs::read_to_string(root.join("fixtures/identification-fixtures.args")).unwrap();
    let tmp = tempfile::tempdir().unwrap();
    for line in list.lines().map(str::trim) {
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let mut words = line.split_whitespace();
        let dir = words.next().expect("a folder");
        let out = tmp.path().join(dir);
        let status = Command::new(env!("CARGO_BIN_EXE_rtid"))
            .arg("experiment")
            .args(words)
            .arg("--out")
            .arg(&out)
            .arg("--quiet")
            .output()
            .expect("the rtid binary runs");
        assert!(
            status.status.success(),
            "{line}: {}",
            String::from_utf8_lossy(&status.stderr)
        );
        for entry in std::fs::read_dir(&out).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "svg") {
                continue;
            }
            let name = path.file_name().unwrap();
            let shipped = root.join("fixtures").join(dir).join(name);
            assert!(
                std::fs::read(&path).unwrap() == std::fs::read(&shipped).unwrap(),
                "{} differs from what `rtid experiment {line}` writes now: regenerate with \
                 fixtures/make-identification-fixtures.sh and say why",
                shipped.display()
            );
        }
    }
}
