//! The command-line conventions users know (issue 15): `--version` with the commit,
//! `NO_COLOR`, shell completions and man pages generated from the parser itself.
//! (`--shard` counting from 1 is in tests/sweep.rs; `--json` and `--quiet` on every
//! command in src/cli/mod.rs.)

use std::process::{Command, Output};

fn rtid(args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_rtid"));
    c.args(args)
        .env_remove("NO_COLOR")
        .env_remove("CLICOLOR_FORCE");
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().expect("the rtid binary runs")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8(bytes.to_vec()).expect("UTF-8")
}

#[test]
fn the_version_names_the_commit_built_from() {
    let out = rtid(&["--version"], &[]);
    assert!(out.status.success());
    let version = text(&out.stdout);
    let head = Command::new("git")
        .args(["rev-parse", "--short=12", "HEAD"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| text(&o.stdout).trim().to_string());
    let want = match head {
        Some(hash) => format!("commit {hash}"),
        None => "unknown commit".to_string(),
    };
    assert_eq!(
        version.trim(),
        format!("rtid {} ({want})", env!("CARGO_PKG_VERSION"))
    );
}

#[test]
fn no_color_takes_the_colour_out_of_help_and_errors() {
    const ESC: char = '\u{1b}';
    let forced = [("CLICOLOR_FORCE", "1")];
    for args in [
        &["identify", "--help"][..],
        &["identify", "--no-such-option"][..],
    ] {
        let out = rtid(args, &forced);
        let both = text(&out.stdout) + &text(&out.stderr);
        assert!(both.contains(ESC), "{args:?}: coloured when forced");
        let out = rtid(args, &[("CLICOLOR_FORCE", "1"), ("NO_COLOR", "1")]);
        let both = text(&out.stdout) + &text(&out.stderr);
        assert!(!both.contains(ESC), "{args:?} with NO_COLOR: {both}");
    }
}

#[test]
fn completions_cover_every_command_and_option() {
    for (shell, marker) in [
        ("bash", "complete -F"),
        ("zsh", "#compdef rtid"),
        ("fish", "complete -c rtid"),
    ] {
        let out = rtid(&["completions", shell], &[]);
        assert!(out.status.success(), "{shell}: {}", text(&out.stderr));
        let script = text(&out.stdout);
        assert!(script.contains(marker), "{shell}");
        for word in ["identify", "sweep", "merge", "resample"] {
            assert!(script.contains(word), "{shell} completion lacks {word}");
        }
    }
    let out = rtid(&["completions", "tcsh"], &[]);
    assert!(!out.status.success());
    assert!(text(&out.stderr).contains("tcsh"));
}

#[test]
fn man_pages_are_written_for_every_command() {
    let out = rtid(&["man"], &[]);
    assert!(out.status.success());
    let page = text(&out.stdout);
    assert!(
        page.starts_with(".ie") || page.contains(".TH rtid"),
        "{}",
        &page[..200.min(page.len())]
    );
    assert!(page.contains("identify"));
    let dir = tempfile::tempdir().unwrap();
    let folder = dir.path().join("man");
    let out = rtid(&["man", "--out", folder.to_str().unwrap(), "--quiet"], &[]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(text(&out.stdout).is_empty());
    for name in [
        "rtid",
        "rtid-identify",
        "rtid-sweep-merge",
        "rtid-experiment-positioning",
    ] {
        let page = std::fs::read_to_string(folder.join(format!("{name}.1"))).unwrap();
        assert!(page.contains(&format!(".TH {name}")), "{name}");
    }
    let identify = std::fs::read_to_string(folder.join("rtid-identify.1")).unwrap();
    assert!(identify.contains("resample"));
}
