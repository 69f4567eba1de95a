//! `rtid completions SHELL` and `rtid man`: the command line described for the
//! shell's completion and for man(1), generated from the same clap tree that parses
//! it (clap_complete, clap_mangen), so they cannot drift from it.

use std::io::Write;
use std::path::PathBuf;

use anyhow::Context;
use clap::CommandFactory;

pub const COMPLETIONS_ABOUT: &str = "\
Prints the shell completion script of rtid (commands, options, their values) on stdout.

Install:
  bash  rtid completions bash > ~/.local/share/bash-completion/completions/rtid
  zsh   rtid completions zsh > ~/.zfunc/_rtid   (with fpath+=~/.zfunc before compinit)
  fish  rtid completions fish > ~/.config/fish/completions/rtid.fish";

pub const MAN_ABOUT: &str = "\
Writes rtid's man page (roff): the top-level page with every command, or with --out DIR one \
page per command as well (rtid.1, rtid-identify.1, rtid-sweep-merge.1, …).

Examples:
  rtid man | man -l -
  rtid man --out target/man && man -M target/man rtid-identify";

/// Arguments of `rtid completions`.
#[derive(Debug, clap::Args)]
pub struct CompletionArgs {
    /// The shell.
    #[arg(value_enum)]
    pub shell: clap_complete::Shell,
}

/// Arguments of `rtid man`.
#[derive(Debug, clap::Args)]
pub struct ManArgs {
    /// Write every page into this folder instead of the top-level page on stdout.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// No "wrote" lines.
    #[arg(long)]
    pub quiet: bool,
}

/// The command tree as the binary parses it.
fn command() -> clap::Command {
    super::Cli::command()
}

pub fn completions(a: CompletionArgs) -> anyhow::Result<()> {
    let mut cmd = command();
    clap_complete::generate(a.shell, &mut cmd, "rtid", &mut std::io::stdout());
    Ok(())
}

pub fn man(a: ManArgs) -> anyhow::Result<()> {
    let cmd = command();
    let Some(dir) = a.out else {
        let mut page = Vec::new();
        clap_mangen::Man::new(cmd).render(&mut page)?;
        std::io::stdout().write_all(&page)?;
        return Ok(());
    };
    std::fs::create_dir_all(&dir).with_context(|| format!("--out {}", dir.display()))?;
    for (name, page) in pages(cmd, "")? {
        let path = dir.join(format!("{name}.1"));
        rtid::io::atomic::write(&path, &page)
            .with_context(|| format!("writing {}", path.display()))?;
        if !a.quiet {
            println!("wrote {}", path.display());
        }
    }
    Ok(())
}

/// The page of `cmd` and of each of its subcommands, named rtid, rtid-identify, ….
fn pages(cmd: clap::Command, prefix: &str) -> anyhow::Result<Vec<(String, Vec<u8>)>> {
    let name = if prefix.is_empty() {
        cmd.get_name().to_string()
    } else {
        format!("{prefix}-{}", cmd.get_name())
    };
    let mut page = Vec::new();
    let cmd = cmd.name(name.clone());
    clap_mangen::Man::new(cmd.clone()).render(&mut page)?;
    let mut out = vec![(name.clone(), page)];
    for sub in cmd.get_subcommands().filter(|s| s.get_name() != "help") {
        out.extend(pages(sub.clone(), &name)?);
    }
    Ok(out)
}
