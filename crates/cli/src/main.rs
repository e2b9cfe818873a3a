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
    /// Render a volume to EXR (and PNG).
    Render(Box<commands::render::RenderArgs>),
    /// Benchmarks that print figures.
    #[command(subcommand)]
    Bench(commands::bench::BenchCommand),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Info(args) => commands::info::run(&args),
        Command::Convert(args) => commands::convert::run(&args),
        Command::Bench(cmd) => commands::bench::run(&cmd),
        Command::Render(args) => commands::render::run(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("cirrus: {e}");
            ExitCode::FAILURE
        }
    }
}
