//! Errors of the reader. Every error names the file and what is wrong with it.

use std::fmt;
use std::path::{Path, PathBuf};

/// What went wrong while reading a volume file, without the file name.
#[derive(Debug, thiserror::Error)]
pub enum ErrorKind {
    #[error("I/O error: {0}")]
    Io(#[from] std::io::Error),
    #[error("not an OpenVDB or NanoVDB file (magic bytes {0:02x?})")]
    BadMagic(Vec<u8>),
    #[error("file ends early: needed {needed} bytes for {what} at offset {offset}, {available} available")]
    Truncated {
        what: &'static str,
        offset: u64,
        needed: u64,
        available: u64,
    },
    #[error("corrupt data: {0}")]
    Corrupt(String),
    #[error("unsupported {0}")]
    Unsupported(String),
    /// The grid asked for, as said (a quoted name and the file's grids,
    /// or an index and the count).
    #[error("no grid {0}")]
    NoSuchGrid(String),
}

/// A reader error: the file it came from and what went wrong.
#[derive(Debug)]
pub struct Error {
    pub path: PathBuf,
    pub kind: ErrorKind,
}

impl Error {
    pub fn new(path: impl AsRef<Path>, kind: ErrorKind) -> Self {
        Error {
            path: path.as_ref().to_path_buf(),
            kind,
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.path.display(), self.kind)
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        Some(&self.kind)
    }
}

/// Shorthand for the result of a parse step that does not know its file name yet.
pub type KindResult<T> = std::result::Result<T, ErrorKind>;
pub type Result<T> = std::result::Result<T, Error>;

pub(crate) fn corrupt(msg: impl Into<String>) -> ErrorKind {
    ErrorKind::Corrupt(msg.into())
}

pub(crate) fn unsupported(msg: impl Into<String>) -> ErrorKind {
    ErrorKind::Unsupported(msg.into())
}
