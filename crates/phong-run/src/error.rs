//! The crate's error: the libraries' errors, and what is wrong in a request.

use thiserror::Error;

/// Why a render could not be made.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum Error {
    /// A scene or model file (or an image written).
    #[error(transparent)]
    Scene(#[from] phong_scene::Error),
    /// A scene document: `what` names it (a file, or `scene` for one given inline).
    #[error("{what}: {error}")]
    Json {
        /// The document's name in messages.
        what: String,
        /// The key at fault and why.
        error: phong_scene::JsonError,
    },
    /// A value of the request (a size, an override), in the caller's words.
    #[error("{0}")]
    Input(String),
    /// The CPU renderer.
    #[error(transparent)]
    Raster(#[from] phong_raster::Error),
    /// The GPU renderer.
    #[error(transparent)]
    Gpu(#[from] phong_gpu::Error),
    /// The image could not be encoded.
    #[error("encoding the PNG failed: {0}")]
    Encode(std::io::Error),
}

impl Error {
    /// Whether the error is in what was asked for (exit code 2, Python's `InputError`), not in
    /// the machine.
    pub fn is_input(&self) -> bool {
        match self {
            Error::Scene(e) => e.is_input(),
            Error::Json { .. } | Error::Input(_) => true,
            Error::Raster(e) => e.is_input(),
            Error::Gpu(e) => e.is_input(),
            Error::Encode(_) => false,
        }
    }
}

/// An error and its causes, one after the other, as the command line prints them.
pub fn message(e: &dyn std::error::Error) -> String {
    let mut s = e.to_string();
    let mut cause = e.source();
    while let Some(c) = cause {
        s.push_str(": ");
        s.push_str(&c.to_string());
        cause = c.source();
    }
    s
}
