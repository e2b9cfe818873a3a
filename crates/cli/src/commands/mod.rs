pub mod convert;
pub mod info;
pub mod merge;
pub mod preview;
pub mod render;

/// The error every subcommand returns: printed once by `main`.
pub type CliResult = Result<(), Box<dyn std::error::Error>>;
