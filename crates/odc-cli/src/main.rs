//! `odc`: the object-dictionary compiler's command line.
//!
//! Exit codes: 0 when no diagnostic is at error level, 1 when one is, 2 for usage and I/O errors.

mod commands;
mod input;

use std::process::ExitCode;

use clap::{CommandFactory, Parser, Subcommand};

/// The exit codes, shown by `odc --help` (README.md says the same).
const EXIT_STATUS: &str = "\
Exit status:
  0  no diagnostic at error level (warnings allowed)
  1  at least one error-level diagnostic (check), or a file with errors where a command needs a
     usable model (dump, convert, info, generate); a failed check (conformance)
  2  usage error (bad arguments, unknown device or rule) or I/O error (unreadable input,
     unwritable output); nothing is written

Output files (-o) are written to a temporary file beside the target and renamed into place:
a failed run leaves the previous file untouched.";

/// Object-dictionary compiler for CANopen EDS/DCF and EtherCAT ESI device files.
///
/// Reads a vendor's device file, checks it against CiA 306/301/402 and ETG rules with
/// compiler-style diagnostics, converts between formats, and dumps the object dictionary.
#[derive(Parser)]
#[command(
    name = "odc",
    version,
    propagate_version = true,
    max_term_width = 100,
    after_help = EXIT_STATUS
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    Check(commands::check::Args),
    Dump(commands::dump::Args),
    Convert(commands::convert::Args),
    Doc(commands::doc::Args),
    Diff(commands::diff::Args),
    Generate(commands::generate::Args),
    Info(commands::info::Args),
    Sii(commands::sii::Args),
    Simulate(commands::simulate::Args),
    Sdo(commands::sdo::Args),
    Conformance(commands::conformance::Args),
    Nmt(commands::nmt::Args),
    Lss(commands::lss::Args),
    Monitor(commands::monitor::Args),
    Explain(commands::explain::Args),
    Lints(commands::explain::LintsArgs),
    Completions(Completions),
    /// Print the manual page (roff, every subcommand listed): `odc man > odc.1; man ./odc.1`.
    Man,
}

/// Print a shell completion script (bash, zsh, fish, elvish, powershell).
///
/// `odc completions bash > /etc/bash_completion.d/odc`, `odc completions zsh > ~/.zfunc/_odc`,
/// `odc completions fish > ~/.config/fish/completions/odc.fish`.
#[derive(clap::Args)]
struct Completions {
    /// The shell.
    shell: clap_complete::Shell,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Check(args) => commands::check::run(args),
        Command::Dump(args) => commands::dump::run(args),
        Command::Convert(args) => commands::convert::run(args),
        Command::Doc(args) => commands::doc::run(args),
        Command::Diff(args) => commands::diff::run(args),
        Command::Generate(args) => commands::generate::run(args),
        Command::Info(args) => commands::info::run(args),
        Command::Sii(args) => commands::sii::run(args),
        Command::Simulate(args) => commands::simulate::run(args),
        Command::Sdo(args) => commands::sdo::run(args),
        Command::Conformance(args) => commands::conformance::run(args),
        Command::Nmt(args) => commands::nmt::run(args),
        Command::Lss(args) => commands::lss::run(args),
        Command::Monitor(args) => commands::monitor::run(args),
        Command::Explain(args) => commands::explain::run(args),
        Command::Lints(args) => commands::explain::lints(args),
        Command::Completions(args) => completions(args.shell),
        Command::Man => man(),
    };
    match result {
        Ok(code) => code,
        Err(err) => {
            commands::err(&format!("error: {}\n", message(&err)));
            if err.downcast_ref::<commands::HasErrors>().is_some() {
                ExitCode::from(1)
            } else {
                ExitCode::from(2)
            }
        }
    }
}

/// `odc completions SHELL`.
fn completions(shell: clap_complete::Shell) -> anyhow::Result<ExitCode> {
    let mut script = Vec::new();
    clap_complete::generate(shell, &mut Cli::command(), "odc", &mut script);
    commands::out(&String::from_utf8_lossy(&script))?;
    Ok(ExitCode::SUCCESS)
}

/// `odc man`.
fn man() -> anyhow::Result<ExitCode> {
    let mut page = Vec::new();
    clap_mangen::Man::new(Cli::command()).render(&mut page)?;
    commands::out(&String::from_utf8_lossy(&page))?;
    Ok(ExitCode::SUCCESS)
}

/// The error and its causes, `: `-separated, each cause once: an error whose text already
/// includes its cause's (`cannot read x.eds: No such file or directory (os error 2)`) does not
/// repeat it.
fn message(err: &anyhow::Error) -> String {
    let mut text = String::new();
    for cause in err.chain() {
        let part = cause.to_string();
        if text.contains(&part) {
            continue;
        }
        if !text.is_empty() {
            text.push_str(": ");
        }
        text.push_str(&part);
    }
    text
}
