//! Property tests of the option parsing (issue 13): any value given to any option of
//! any command, and any text given to the hand-written value parsers (`--set`,
//! `--bound`, `--input`), either parses to finite numbers or is refused naming the
//! option — never a panic. (The library's file parsers: `tests/properties.rs`.)

use clap::{CommandFactory, FromArgMatches};
use proptest::prelude::*;

use super::Cli;
use crate::cli::common::model_args::parse_assignment;
use crate::cli::identify::parse_bound;
use rtid::input_spec::InputSpec;

/// Every (subcommand path, long option taking a value) of the command line.
fn options() -> Vec<(Vec<String>, String)> {
    fn walk(c: &clap::Command, path: &[String], out: &mut Vec<(Vec<String>, String)>) {
        for a in c.get_arguments() {
            if let (Some(long), true) = (a.get_long(), a.get_action().takes_values()) {
                out.push((path.to_vec(), long.to_string()));
            }
        }
        for sub in c.get_subcommands() {
            let mut p = path.to_vec();
            p.push(sub.get_name().to_string());
            walk(sub, &p, out);
        }
    }
    let mut out = Vec::new();
    walk(&Cli::command(), &[], &mut out);
    out
}

/// A value a user might give an option.
fn value() -> impl Strategy<Value = String> {
    prop_oneof![
        any::<f64>().prop_map(|v| v.to_string()),
        any::<i64>().prop_map(|v| v.to_string()),
        Just("NaN".to_string()),
        Just("-inf".to_string()),
        Just("1e400".to_string()),
        Just("-1".to_string()),
        Just(String::new()),
        "[ -~]{0,16}",
        ".{0,8}",
    ]
}

/// Whether a debug print holds a non-finite number outside quoted text.
fn non_finite(debug: &str) -> bool {
    debug
        .split(|c: char| !(c.is_alphanumeric() || c == '-'))
        .any(|t| matches!(t, "NaN" | "inf" | "-inf"))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    /// Any value of any option parses or gets clap's error naming the option.
    #[test]
    fn any_value_of_any_option_parses_or_names_the_option(
        pick in any::<prop::sample::Index>(),
        v in value(),
    ) {
        let all = options();
        let (path, long) = &all[pick.index(all.len())];
        let mut args = vec!["rtid".to_string()];
        args.extend(path.iter().cloned());
        args.push(format!("--{long}"));
        args.push(v.clone());
        match crate::negative_numbers(Cli::command()).try_get_matches_from(&args) {
            Ok(m) => {
                let _ = Cli::from_arg_matches(&m);
            }
            Err(e) => {
                use clap::error::ErrorKind;
                if matches!(e.kind(), ErrorKind::InvalidValue | ErrorKind::ValueValidation) {
                    prop_assert!(e.to_string().contains(&format!("--{long}")), "{args:?}: {e}");
                }
            }
        }
    }

    /// `--set NAME=VALUE` gives a finite value, printed back as given, or a refusal
    /// quoting the text.
    #[test]
    fn assignments_parse_finite_or_are_refused(text in ".{0,24}", v in any::<f64>()) {
        match parse_assignment(&text) {
            Ok((_, x)) => prop_assert!(x.is_finite(), "{text}"),
            Err(e) => prop_assert!(e.to_string().contains("--set"), "{e}"),
        }
        let given = format!("Kw={v}");
        match parse_assignment(&given) {
            Ok(parsed) => prop_assert_eq!(parsed, ("Kw", v)),
            Err(_) => prop_assert!(!v.is_finite()),
        }
    }

    /// `--bound NAME=LO..HI` gives finite bounds or a refusal naming `--bound`.
    #[test]
    fn bounds_parse_finite_or_are_refused(
        name in "[A-Za-z_]{0,4}",
        lo in value(),
        hi in value(),
        junk in ".{0,16}",
    ) {
        for text in [format!("{name}={lo}..{hi}"), junk] {
            match parse_bound(&text) {
                Ok((_, b)) => prop_assert!(b.lo.is_finite() && b.hi.is_finite(), "{text}"),
                Err(e) => prop_assert!(e.to_string().contains("--bound"), "{e}"),
            }
        }
    }

    /// `--input` specifications parse to finite numbers or are refused.
    #[test]
    fn input_specifications_parse_finite_or_are_refused(
        kind in prop_oneof![
            Just("sine".to_string()),
            Just("step".to_string()),
            Just("move".to_string()),
            Just("none".to_string()),
            Just("file".to_string()),
            "[a-z]{0,5}",
        ],
        key in prop_oneof![
            Just("freq_hz".to_string()),
            Just("amp_nm".to_string()),
            Just("torque_nm".to_string()),
            Just("target_deg".to_string()),
            Just("loop".to_string()),
            "[a-z_]{0,8}",
        ],
        v in value(),
        more in ".{0,12}",
    ) {
        for text in [format!("{kind}:{key}={v}"), format!("{kind}:{key}={v},{more}")] {
            if let Ok(spec) = text.parse::<InputSpec>() {
                prop_assert!(!non_finite(&format!("{spec:?}")) || kind == "file", "{text}: {spec:?}");
            }
        }
    }
}

#[test]
fn the_walk_finds_the_options() {
    let all = options();
    for (path, long) in [
        ("simulate", "duration-s"),
        ("identify", "bound"),
        ("sweep", "vary"),
    ] {
        assert!(
            all.iter()
                .any(|(p, l)| p.first().map(String::as_str) == Some(path) && l == long),
            "{path} --{long}"
        );
    }
    assert!(all.len() > 100, "{} options", all.len());
}
