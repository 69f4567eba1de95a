//! The `rtid` command line. Errors print as one line on stderr with a non-zero exit.
#![forbid(unsafe_code)]

use std::process::ExitCode;

use clap::{CommandFactory, FromArgMatches};

mod cli;

fn main() -> ExitCode {
    quiet_on_broken_pipe();
    let matches = negative_numbers(cli::Cli::command()).get_matches();
    let cli = cli::Cli::from_arg_matches(&matches).unwrap_or_else(|e| e.exit());
    match cli::run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

/// Every option and subcommand, recursively, takes a negative number as its value:
/// `--preload-nm -3` means what it says, and `--amplitude-nm -1` reaches the option's
/// own check ("--amplitude-nm -1: must be positive") instead of clap's "unexpected
/// argument '-1'", which does not name the option.
fn negative_numbers(c: clap::Command) -> clap::Command {
    c.mut_args(|a| a.allow_negative_numbers(true))
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
