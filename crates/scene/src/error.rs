//! The one error type of the scene library.
//!
//! Its kind tells a caller what went wrong in the terms a binding needs:
//! a file that cannot be read (Python's `OSError`), input that is wrong
//! (`ValueError`), or a render stopped on request. The kind is decided
//! where the error arises: the reader's errors are the file's, the
//! renderer's say themselves which they are ([`cirrus_render::Error`]),
//! and the library's own checks name theirs. The message is what the
//! command line prints, and names the file where there is one; the error
//! it came from stays reachable as its `source`.

/// What a caller does about an [`Error`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ErrorKind {
    /// A file is missing, unreadable, truncated or not of its format.
    File,
    /// A value, flag, key or grid choice is wrong.
    Input,
    /// The render was cancelled through its `RenderControl`.
    Cancelled,
}

/// The error an error came from.
pub type Source = Box<dyn std::error::Error + Send + Sync + 'static>;

#[derive(Debug, thiserror::Error)]
pub enum Error {
    #[error("{message}")]
    File {
        message: String,
        #[source]
        source: Option<Source>,
    },
    #[error("{message}")]
    Input {
        message: String,
        #[source]
        source: Option<Source>,
    },
    #[error("render cancelled")]
    Cancelled,
}

pub type Result<T> = std::result::Result<T, Error>;

impl Error {
    pub fn file(message: impl Into<String>) -> Self {
        Self::File {
            message: message.into(),
            source: None,
        }
    }

    pub fn input(message: impl Into<String>) -> Self {
        Self::Input {
            message: message.into(),
            source: None,
        }
    }

    pub fn cancelled() -> Self {
        Self::Cancelled
    }

    pub fn kind(&self) -> ErrorKind {
        match self {
            Self::File { .. } => ErrorKind::File,
            Self::Input { .. } => ErrorKind::Input,
            Self::Cancelled => ErrorKind::Cancelled,
        }
    }

    /// The same error with `context` (a scene file's name, say) before its
    /// message.
    pub fn within(self, context: impl std::fmt::Display) -> Self {
        match self {
            Self::File { message, source } => Self::File {
                message: format!("{context}: {message}"),
                source,
            },
            Self::Input { message, source } => Self::Input {
                message: format!("{context}: {message}"),
                source,
            },
            Self::Cancelled => Self::Cancelled,
        }
    }
}

/// The reader's errors name the file; an unreadable file is a file error.
impl From<cirrus_vdb::Error> for Error {
    fn from(e: cirrus_vdb::Error) -> Self {
        Self::File {
            message: e.to_string(),
            source: Some(Box::new(e)),
        }
    }
}

/// The renderer's errors say whether a file or a value is at fault.
impl From<cirrus_render::Error> for Error {
    fn from(e: cirrus_render::Error) -> Self {
        let (message, file) = (e.to_string(), e.is_file());
        let source = Some(Box::new(e) as Source);
        match file {
            true => Self::File { message, source },
            false => Self::Input { message, source },
        }
    }
}

impl From<cirrus_render::MediumError> for Error {
    fn from(e: cirrus_render::MediumError) -> Self {
        cirrus_render::Error::from(e).into()
    }
}
