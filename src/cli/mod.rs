//! The command line: clap parses raw arguments here, each command's module validates
//! them into a run configuration and runs it.

pub mod common;
mod compare;
mod compensate;
mod evaluate;
mod experiment;
mod identify;
mod import;
mod model;
mod predict;
#[cfg(test)]
mod properties;
mod report;
mod shell;
mod sweep;
mod tune;
mod tune_measured;

use clap::{Parser, Subcommand};

pub use common::model_args::ModelArgs;

const ABOUT: &str = "Simulate CNC rotary tables (worm-gear and roller-gear-cam drives) and \
identify their stiffness, damping and friction from measurements.";

const LONG_ABOUT: &str = "\
rtid simulates a CNC rotary table as the 4-DOF (worm gear: motor, spur gears, worm shaft, \
table) or 3-DOF (roller gear cam: motor+cam, rollers, table) model of IMECE2008-66108: \
torsional meshes with backlash, the worm's axial bearing, Coulomb friction with true stick, \
gear fluctuation, unbalance, and the discrete P/PI servo in semi- or full-closed loop.

Every command takes a mechanism: --preset worm-gear | roller-gear-cam (the paper's Table 1), \
or --params FILE.json, and --set NAME=VALUE to change single values (SI units: rad, N·m, s, \
kg, m). `rtid params` lists every name with its unit.

Examples:
  rtid modes --preset worm-gear
  rtid simulate --preset worm-gear --input sine:freq_hz=100,amp_nm=5 --duration-s 0.5 --out run.csv
  rtid simulate --preset roller-gear-cam --input move:target_deg=30,loop=full_closed --duration-s 1 --out move.csv
  rtid params --preset worm-gear --set Kw=3.5e5 --out my-table.json
  rtid experiment positioning --preset worm-gear --out runs/worm
  rtid evaluate runs/worm/positioning.json
  rtid compensate runs/worm/positioning.json --runs 1-3 -o compensation.json
  rtid compare runs/worm runs/roller
  rtid select fit-kw-kg.json fit-kw-kg-kb.json
  rtid report fit.json runs/worm/positioning.json --tolerance-arcsec 20 --out report.html
  rtid sweep --preset worm-gear --method sobol --vary Kw=1e5..1e6:log --vary Jt=0.08..0.14 --outputs resonances --out s.csv";

/// Top-level arguments.
#[derive(Debug, Parser)]
#[command(name = "rtid", version = rtid::VERSION, about = ABOUT, long_about = LONG_ABOUT)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

/// The commands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Natural frequencies of the linearised drive, motor held and motor free.
    #[command(long_about = model::modes::LONG_ABOUT)]
    Modes(model::modes::Args),
    /// Time simulation under an open-loop torque or a closed-loop move; writes a CSV.
    #[command(long_about = model::simulate::LONG_ABOUT)]
    Simulate(model::simulate::Args),
    /// List, check or save a parameter set (names, values, units, notes).
    #[command(long_about = model::params::LONG_ABOUT)]
    Params(model::params::Args),
    /// Run one of the paper's tests on the model; writes an experiment file and a plot.
    #[command(long_about = experiment::LONG_ABOUT)]
    Experiment {
        #[command(subcommand)]
        test: experiment::Test,
    },
    /// Identify stiffness, damping and friction from experiment files.
    #[command(long_about = identify::LONG_ABOUT)]
    Identify(identify::Args),
    /// Read the files labs export (MAT, TwinCAT Scope, EPOS Studio, UFF 58, delimited
    /// text): list their channels, or write an experiment file from them.
    #[command(long_about = import::LONG_ABOUT)]
    Import(import::Args),
    /// Evaluate a measured or virtual experiment file (statistics, plot).
    #[command(long_about = evaluate::LONG_ABOUT)]
    Evaluate(evaluate::Args),
    /// Backlash and error-table compensation from a positioning record (JSON, SINUMERIK, CSV).
    #[command(long_about = compensate::LONG_ABOUT)]
    Compensate(compensate::Args),
    /// The paper's Table 3: two folders of experiment files side by side.
    #[command(long_about = compare::LONG_ABOUT)]
    Compare(compare::Args),
    /// Velocity PI, position gain and notch filters for a target phase margin, from the model.
    #[command(long_about = tune::LONG_ABOUT)]
    Tune(tune::Args),
    /// The effect of a compensation or tuning on the identified model, with the fit's uncertainty.
    #[command(long_about = predict::LONG_ABOUT)]
    Predict(predict::Args),
    /// Sensitivity sweeps: grid, local, Morris, Sobol; streamed, resumable, shardable.
    #[command(long_about = sweep::LONG_ABOUT)]
    Sweep(sweep::Args),
    /// Model selection: AIC, AICc, BIC and F-tests between identifications of the same data.
    #[command(long_about = identify::select::LONG_ABOUT)]
    Select(identify::select::Args),
    /// Experiment design: candidate tests ranked by the standard errors they would give.
    #[command(long_about = identify::design::LONG_ABOUT)]
    Design(identify::design::Args),
    /// Shell completion script (bash, zsh, fish, elvish, powershell) on stdout.
    #[command(long_about = shell::COMPLETIONS_ABOUT)]
    Completions(shell::CompletionArgs),
    /// The man page (roff), or with --out DIR one page per command.
    #[command(long_about = shell::MAN_ABOUT)]
    Man(shell::ManArgs),
    /// One self-contained HTML page of identifications, positioning tests and sweeps.
    #[command(long_about = report::LONG_ABOUT)]
    Report(report::Args),
}

/// Runs one parsed command line.
pub fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Modes(a) => model::modes::run(a),
        Command::Simulate(a) => model::simulate::run(a),
        Command::Params(a) => model::params::run(a),
        Command::Experiment { test } => experiment::run(test),
        Command::Identify(a) => identify::run(a),
        Command::Import(a) => import::run(a),
        Command::Evaluate(a) => evaluate::run(a),
        Command::Compensate(a) => compensate::run(a),
        Command::Compare(a) => compare::run(a),
        Command::Sweep(a) => sweep::run(a),
        Command::Tune(a) => tune::run(a),
        Command::Predict(a) => predict::run(a),
        Command::Select(a) => identify::select::run(a),
        Command::Design(a) => identify::design::run(a),
        Command::Completions(a) => shell::completions(a),
        Command::Man(a) => shell::man(a),
        Command::Report(a) => report::run(a),
    }
}

#[cfg(test)]
mod tests {
    use clap::CommandFactory;

    /// The commands that run something, with their path (`rtid sweep merge`).
    fn leaves(c: &clap::Command, path: String, out: &mut Vec<(String, clap::Command)>) {
        let subs: Vec<&clap::Command> = c
            .get_subcommands()
            .filter(|s| s.get_name() != "help")
            .collect();
        for s in &subs {
            leaves(s, format!("{path} {}", s.get_name()), out);
        }
        if subs.is_empty() {
            out.push((path, c.clone()));
        }
    }

    #[test]
    fn every_command_takes_json_and_quiet() {
        let mut all = Vec::new();
        leaves(&super::Cli::command(), "rtid".into(), &mut all);
        assert!(all.len() > 15, "{}", all.len());
        for (path, c) in &all {
            let has = |long: &str| c.get_arguments().any(|a| a.get_long() == Some(long));
            // What completions print is the script itself, man the page.
            if !path.ends_with("completions") {
                assert!(has("quiet"), "{path} has no --quiet");
            }
            if !path.ends_with("completions") && !path.ends_with("man") {
                assert!(has("json"), "{path} has no --json");
            }
        }
    }
}
