//! The `caustica` command: a thin layer over the library that parses arguments, shows progress,
//! prints diagnostics and maps failures to exit codes (0 ok, 1 internal, 2 bad input, 130
//! interrupted).

mod cli;
mod commands;
mod diagnostics;
mod interrupt;
mod progress;
mod stdout;

use clap::Parser;
use std::process::ExitCode;

/// Exit code for a malformed scene, a bad option or an unreadable file.
pub const EXIT_BAD_INPUT: u8 = 2;
/// Exit code after Ctrl-C.
pub const EXIT_INTERRUPTED: u8 = 130;
/// Exit code for a failure that is caustica's fault.
pub const EXIT_INTERNAL: u8 = 1;

fn main() -> ExitCode {
    diagnostics::on_panic_exit(EXIT_INTERNAL);
    let cli = cli::Cli::parse();
    if std::env::var_os("CAUSTICA_TEST_PANIC").is_some() {
        // A deliberate bug on a worker thread, for the test of the exit codes.
        rayon::join(|| panic!("CAUSTICA_TEST_PANIC is set"), || ());
    }
    let cancel = interrupt::install();
    let json = match &cli.command {
        cli::Command::Render(args) => args.json,
        cli::Command::Info(args) => args.json,
        cli::Command::Photons(args) => args.json,
        cli::Command::Compare(args) => args.json,
        cli::Command::Bench(_) | cli::Command::Merge(_) => false,
    };
    let result = match cli.command {
        cli::Command::Render(args) => commands::render::run(*args, cancel),
        cli::Command::Info(args) => commands::info::run(args),
        cli::Command::Photons(args) => commands::photons::run(args, cancel),
        cli::Command::Bench(args) => commands::bench::run(args),
        cli::Command::Merge(args) => commands::merge::run(args),
        cli::Command::Compare(args) => commands::compare::run(args),
    };
    match result {
        Ok(code) => ExitCode::from(code),
        // The reader of our output went away (`| head`): what it wanted was printed.
        Err(error) if stdout::is_closed_pipe(&error) => ExitCode::SUCCESS,
        Err(error) => {
            diagnostics::print(&error, json);
            ExitCode::from(if error.is_bad_input() {
                EXIT_BAD_INPUT
            } else {
                EXIT_INTERNAL
            })
        }
    }
}
