//! `cirrus`: the command-line front of the cirrus crates.
//!
//! Each subcommand lives in `commands/` and only parses, dispatches and
//! prints; the work is in the library crates.

mod commands;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "cirrus",
    version,
    about = "Path tracer for sparse volumes (OpenVDB / NanoVDB)"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Print the grids of a .vdb or .nvdb file.
    Info(commands::info::InfoArgs),
    /// Convert a float grid into sparse bricks (.cbrk).
    Convert(commands::convert::ConvertArgs),
    /// Render a volume, or a scene file (.toml), to EXR (and PNG).
    Render(Box<commands::render::RenderArgs>),
    /// Assemble crop tiles (`render --crop`) into one full-size EXR.
    Merge(commands::merge::MergeArgs),
    /// Benchmarks that print figures.
    #[command(subcommand)]
    Bench(commands::bench::BenchCommand),
}

fn main() -> ExitCode {
    // The matches are kept so `render` can tell flags given on the command
    // line (which override a scene file) from defaults.
    let matches = <Cli as clap::CommandFactory>::command().get_matches();
    let cli = match <Cli as clap::FromArgMatches>::from_arg_matches(&matches) {
        Ok(cli) => cli,
        Err(e) => e.exit(),
    };
    let sub = matches
        .subcommand()
        .map(|(_, m)| m.clone())
        .unwrap_or_default();
    let result = match cli.command {
        Command::Info(args) => commands::info::run(&args),
        Command::Convert(args) => commands::convert::run(&args),
        Command::Bench(cmd) => commands::bench::run(&cmd),
        Command::Render(args) => commands::render::run(&args, &sub),
        Command::Merge(args) => commands::merge::run(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("cirrus: {e}");
            ExitCode::FAILURE
        }
    }
}
