//! The `rtid` command line. Errors print as one line on stderr with a non-zero exit.
#![forbid(unsafe_code)]

use std::process::ExitCode;

use clap::{CommandFactory, FromArgMatches};

mod cli;

fn main() -> ExitCode {
    quiet_on_broken_pipe();
    cli::common::interrupt::install();
    let matches = negative_numbers(colour(cli::Cli::command())).get_matches();
    let cli = cli::Cli::from_arg_matches(&matches).unwrap_or_else(|e| e.exit());
    match cli::run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", one_line(&e));
            ExitCode::FAILURE
        }
    }
}

/// The error and its causes on one line, each cause once: many errors already say
/// their source in their own message, and anyhow's chain would repeat it ("not a
/// regular file: not a regular file").
fn one_line(e: &anyhow::Error) -> String {
    let mut line = String::new();
    for cause in e.chain() {
        let text = cause.to_string();
        if line.contains(&text) {
            continue;
        }
        if !line.is_empty() {
            line.push_str(": ");
        }
        line.push_str(&text);
    }
    line
}

/// No colour in help and errors when `NO_COLOR` is set to anything but the empty
/// string (no-color.org). The tables and progress bars have none to begin with.
fn colour(c: clap::Command) -> clap::Command {
    if std::env::var_os("NO_COLOR").is_some_and(|v| !v.is_empty()) {
        c.color(clap::ColorChoice::Never)
    } else {
        c
    }
}

/// Every option and subcommand, recursively, takes a negative number as its value:
/// `--preload-nm -3` means what it says, and `--amplitude-nm -1` reaches the option's
/// own check ("--amplitude-nm -1: must be positive") instead of clap's "unexpected
/// argument '-1'", which does not name the option.
fn negative_numbers(c: clap::Command) -> clap::Command {
    // Only options that take values: on a flag clap's debug build refuses the setting.
    // A number option takes any hyphenated value too (clap does not read `-1e-5` as a
    // negative number): what is not a number is refused by its parser, naming it.
    c.mut_args(|a| {
        if !a.get_action().takes_values() {
            return a;
        }
        let id = |p: clap::builder::ValueParser| p.type_id();
        let numeric = [
            id(clap::value_parser!(f64).into()),
            id(clap::value_parser!(u64).into()),
            id(clap::value_parser!(u32).into()),
            id(clap::value_parser!(usize).into()),
        ]
        .contains(&a.get_value_parser().type_id());
        let a = a.allow_negative_numbers(true);
        if numeric {
            a.allow_hyphen_values(true)
        } else {
            a
        }
    })
    .mut_subcommands(negative_numbers)
}

/// `rtid … | head`: when the reader closes the pipe, `println!` panics with
/// "Broken pipe". That is the reader's choice, not an error: exit quietly with
/// success, as other command-line tools do. Every other panic keeps the default report.
fn quiet_on_broken_pipe() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let payload = info.payload();
        let message = payload
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| payload.downcast_ref::<&str>().copied())
            .unwrap_or("");
        if message.contains("Broken pipe") {
            std::process::exit(0);
        }
        default(info);
    }));
}
