//! Benchmarks that print figures, reached through `cirrus bench`.
//!
//! - [`traverse`]: majorant structures (one global bound, a fixed
//!   pbrt-style grid, the brick hierarchy) side by side on the same random
//!   rays, with the ray-level measures in [`measure`] and the baselines in
//!   [`baseline`] ([`fixed_grid`] renders through the fixed grid);
//! - [`error`]: run time against error for every estimator and majorant
//!   structure, against a converged reference, plotted by [`plot`], with
//!   the ceiling any majorant structure has on the scene (`error/ceiling.rs`);
//! - [`interleave`]: free flights one at a time against two at a time on
//!   one thread, what overlapping paths' chains gains on a core;
//! - [`stress`]: extreme inputs, each checked for finite images and, where
//!   one exists, against a closed-form answer.
//!
//! Speeds are printed as ratios against a baseline measured in the same
//! run; nothing here asserts a time.

pub mod baseline;
pub mod error;
pub mod fixed_grid;
pub mod interleave;
pub mod measure;
pub mod plot;
pub mod stress;
pub mod traverse;

use std::path::Path;

/// The error every benchmark returns: printed once by the binary.
pub type BenchResult = Result<(), Box<dyn std::error::Error>>;

/// The `cirrus bench` subcommands.
#[derive(clap::Subcommand)]
pub enum BenchCommand {
    /// Segments per ray, rays/s, lookups/s and bound tightness for a global
    /// majorant, a fixed pbrt-style grid and cirrus's hierarchy.
    Traverse(traverse::TraverseArgs),
    /// Run time against error for every estimator and majorant structure,
    /// with a converged reference: results.csv, error_vs_time.png, report.md.
    Error(Box<error::ErrorArgs>),
    /// Numerical stress: extreme scales, sizes, positions, grazing rays,
    /// cameras inside volumes, bad voxels, underflowing optical depths.
    Stress(stress::StressArgs),
    /// Free flights one at a time against two at a time on one thread.
    Interleave(interleave::InterleaveArgs),
}

pub fn run(cmd: &BenchCommand) -> BenchResult {
    match cmd {
        BenchCommand::Traverse(args) => traverse::run(args),
        BenchCommand::Error(args) => error::run(args),
        BenchCommand::Stress(args) => stress::run(args),
        BenchCommand::Interleave(args) => interleave::run(args),
    }
}

/// Writes a report file whole or not at all.
fn write_whole(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    cirrus_scene::write_whole(path, bytes)
}
