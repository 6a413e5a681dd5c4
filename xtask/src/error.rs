//! The one error type of the xtask: any error, boxed, with a message helper.

/// Any error from a stage, a reader or the file system.
pub type Error = Box<dyn std::error::Error + Send + Sync>;

/// `Result` with [`Error`].
pub type Result<T> = std::result::Result<T, Error>;

/// An error carrying only a message.
pub fn msg(text: impl Into<String>) -> Error {
    text.into().into()
}
