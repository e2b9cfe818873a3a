//! `cirrus`: the command-line front of the cirrus crates.
//!
//! Each subcommand in `commands/` maps its flags onto a library call and
//! prints; scene loading, rendering and benchmarks live in `cirrus-scene`,
//! `cirrus-render` and `cirrus-bench`.

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
    /// Print the grids of a .vdb, .nvdb or .cbrk file.
    Info(commands::info::InfoArgs),
    /// Convert a float grid into sparse bricks (.cbrk).
    Convert(commands::convert::ConvertArgs),
    /// Render a volume, a scene file (.toml) or a USD stage to EXR and/or PNG.
    Render(Box<commands::render::RenderArgs>),
    /// Assemble crop tiles (`render --crop`) into one full-size EXR.
    Merge(commands::merge::MergeArgs),
    /// Serve a live progressive render of a volume, scene file or USD stage
    /// in the browser.
    Preview(commands::preview::PreviewArgs),
    /// Benchmarks that print figures.
    #[command(subcommand)]
    Bench(cirrus_bench::BenchCommand),
}

fn main() -> ExitCode {
    quiet_when_stdout_closes();
    let result = match Cli::parse().command {
        Command::Info(args) => commands::info::run(&args),
        Command::Convert(args) => commands::convert::run(&args),
        Command::Bench(cmd) => cirrus_bench::run(&cmd),
        Command::Render(args) => commands::render::run(&args),
        Command::Merge(args) => commands::merge::run(&args),
        Command::Preview(args) => commands::preview::run(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("cirrus: {e}");
            ExitCode::FAILURE
        }
    }
}

/// `cirrus info FILE | head` closes stdout before cirrus is done with it:
/// Rust ignores SIGPIPE, so the next `println!` panics with "failed
/// printing to stdout: Broken pipe". The reader wanted no more output, so
/// exit as a shell tool killed by SIGPIPE does (status 128 + 13) instead of
/// printing a panic; every other panic keeps the default report.
fn quiet_when_stdout_closes() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let message = info
            .payload()
            .downcast_ref::<String>()
            .map(String::as_str)
            .unwrap_or_default();
        if message.starts_with("failed printing to stdout") && message.contains("Broken pipe") {
            std::process::exit(141);
        }
        default(info);
    }));
}
