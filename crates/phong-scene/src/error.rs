//! The scene crate's error.

use std::path::PathBuf;
use thiserror::Error;

/// Why a scene, model or image could not be read or written.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum Error {
    /// A file could not be read.
    #[error("cannot read {}", .path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// A syntax, type or value error at a place in a file.
    #[error("{}:{line}:{col}: {}{message}", .path.display(), key_prefix(.key))]
    Parse {
        /// The file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        col: usize,
        /// The key, when known.
        key: Option<String>,
        /// What is wrong.
        message: String,
    },
    /// A model file that is not in a format phong reads, or that its format's reader refused
    /// (PLY and STL readers name no line).
    #[error("{}: {message}", .path.display())]
    Model {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// The output could not be written.
    #[error("cannot write {}", .path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
}

fn key_prefix(key: &Option<String>) -> String {
    key.as_ref().map(|k| format!("`{k}`: ")).unwrap_or_default()
}

impl Error {
    /// True when the error is in the user's input (exit code 2), false for
    /// failures of the system (exit code 1).
    pub fn is_input(&self) -> bool {
        match self {
            Error::Read { .. } => true,
            Error::Parse { .. } => true,
            Error::Model { .. } => true,
            Error::Write { .. } => false,
        }
    }

    /// A parse error at byte `offset` of `src`.
    pub(crate) fn at(path: &std::path::Path, src: &str, offset: usize, key: Option<&str>, message: String) -> Error {
        let (line, col) = line_col(src, offset);
        Error::Parse {
            path: path.to_path_buf(),
            line,
            col,
            key: key.map(str::to_string),
            message,
        }
    }
}

/// 1-based line and column (in characters) of byte `offset` in `src`.
pub(crate) fn line_col(src: &str, offset: usize) -> (usize, usize) {
    let offset = offset.min(src.len());
    let before = &src[..offset];
    let line = before.matches('\n').count() + 1;
    let start = before.rfind('\n').map_or(0, |i| i + 1);
    (line, before[start..].chars().count() + 1)
}
