//! The renderer's one error type: what went wrong, decided where it
//! went wrong, so a caller can tell bad input from a bad file without
//! reading the message.

use std::path::{Path, PathBuf};

/// An error of the renderer's inputs or files.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A setting or parameter out of range, or input that cannot be used
    /// (a crop outside the image, tiles that do not fit together).
    #[error("{0}")]
    Invalid(String),
    /// A file that could not be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// A file whose contents are not what they must be (a broken EXR, a
    /// phase table with a bad row, at `line` where there is one).
    #[error("{}{}: {message}", path.display(), line.map_or(String::new(), |l| format!(":{l}")))]
    Format {
        path: PathBuf,
        line: Option<usize>,
        message: String,
    },
}

pub type Result<T> = std::result::Result<T, Error>;

impl Error {
    pub fn invalid(message: impl Into<String>) -> Self {
        Self::Invalid(message.into())
    }

    pub fn io(path: &Path, source: std::io::Error) -> Self {
        Self::Io {
            path: path.to_path_buf(),
            source,
        }
    }

    pub fn format(path: &Path, message: impl std::fmt::Display) -> Self {
        Self::Format {
            path: path.to_path_buf(),
            line: None,
            message: message.to_string(),
        }
    }

    /// [`Error::format`] at a line of a text file.
    pub fn format_at(path: &Path, line: usize, message: impl std::fmt::Display) -> Self {
        Self::Format {
            path: path.to_path_buf(),
            line: Some(line),
            message: message.to_string(),
        }
    }

    /// Whether a file is at fault (rather than a value).
    pub fn is_file(&self) -> bool {
        !matches!(self, Self::Invalid(_))
    }
}
