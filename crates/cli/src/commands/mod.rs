pub mod bench;
pub mod convert;
pub mod info;

/// The error every subcommand returns: printed once by `main`.
pub type CliResult = Result<(), Box<dyn std::error::Error>>;
