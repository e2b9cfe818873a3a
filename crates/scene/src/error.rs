//! The one error type of the scene library.
//!
//! Its kind tells a caller what went wrong in the terms a binding needs:
//! a file that cannot be read (Python's `OSError`), input that is wrong
//! (`ValueError`), or a render stopped on request. The message is what the
//! command line prints, and names the file where there is one.

use std::fmt;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ErrorKind {
    /// A file is missing, unreadable, truncated or not of its format.
    File,
    /// A value, flag, key or grid choice is wrong.
    Input,
    /// The render was cancelled through its `RenderControl`.
    Cancelled,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Error {
    pub kind: ErrorKind,
    pub message: String,
}

pub type Result<T> = std::result::Result<T, Error>;

impl Error {
    pub fn file(message: impl Into<String>) -> Self {
        Self {
            kind: ErrorKind::File,
            message: message.into(),
        }
    }

    pub fn input(message: impl Into<String>) -> Self {
        Self {
            kind: ErrorKind::Input,
            message: message.into(),
        }
    }

    pub fn cancelled() -> Self {
        Self {
            kind: ErrorKind::Cancelled,
            message: "render cancelled".into(),
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for Error {}

/// The reader's errors name the file; an unreadable file is a file error.
impl From<cirrus_vdb::Error> for Error {
    fn from(e: cirrus_vdb::Error) -> Self {
        Self::file(e.to_string())
    }
}

/// Plain messages from the renderer's validation are input errors.
impl From<String> for Error {
    fn from(message: String) -> Self {
        Self::input(message)
    }
}
