//! Reading input files safely: only regular files (a FIFO would block, a device never ends),
//! each within a size limit checked before reading and again while reading, and text that is
//! not UTF-8 named by its first bad line.

use crate::Error;
use std::io::Read;
use std::path::Path;

/// The bytes of `path`, a regular file of at most `limit` bytes (`what` names the kind and its
/// limit's constant in messages).
pub fn read_bounded(path: &Path, limit: u64, what: &str) -> Result<Vec<u8>, Error> {
    let fail = |m: String| Error::Read {
        path: path.to_path_buf(),
        source: std::io::Error::other(m),
    };
    let io = |source: std::io::Error| Error::Read {
        path: path.to_path_buf(),
        source,
    };
    // metadata follows symlinks: a link to /dev/zero is a device.
    let meta = std::fs::metadata(path).map_err(io)?;
    if !meta.is_file() {
        let kind = if meta.is_dir() {
            "a directory"
        } else {
            "not a regular file (a FIFO, socket or device)"
        };
        return Err(fail(format!("{kind}: a {what} must be a regular file")));
    }
    if meta.len() > limit {
        return Err(fail(format!("{} bytes: a {what} may have at most {limit}", meta.len())));
    }
    let mut buf = Vec::with_capacity(meta.len() as usize);
    std::fs::File::open(path)
        .map_err(io)?
        .take(limit + 1)
        .read_to_end(&mut buf)
        .map_err(io)?;
    if buf.len() as u64 > limit {
        return Err(fail(format!(
            "more than {limit} bytes: a {what} may have at most {limit}"
        )));
    }
    Ok(buf)
}

/// [`read_bounded`] as UTF-8 text; the error names the first line that is not.
pub fn read_text(path: &Path, limit: u64, what: &str) -> Result<String, Error> {
    text_of(path, read_bounded(path, limit, what)?, what)
}

/// `bytes` (of `path`) as UTF-8 text; the error names the first line that is not.
pub(crate) fn text_of(path: &Path, bytes: Vec<u8>, what: &str) -> Result<String, Error> {
    String::from_utf8(bytes).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        let bytes = e.as_bytes();
        let line = bytes[..at].iter().filter(|&&b| b == b'\n').count() + 1;
        let col = at - bytes[..at].iter().rposition(|&b| b == b'\n').map_or(0, |p| p + 1) + 1;
        Error::Parse {
            path: path.to_path_buf(),
            line,
            col,
            key: None,
            message: format!("not UTF-8 text (byte 0x{:02x}); save the {what} as UTF-8", bytes[at]),
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refuses_devices_directories_fifos_and_large_files() {
        let e = read_text(Path::new("/dev/zero"), 1024, "scene")
            .unwrap_err()
            .to_string();
        assert!(e.contains("/dev/zero"), "{e}");
        let e = format!("{:?}", read_text(Path::new("/dev/zero"), 1024, "scene").unwrap_err());
        assert!(e.contains("not a regular file"), "{e}");
        let dir = std::env::temp_dir().join(format!("phong-read-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        assert!(format!("{:?}", read_text(&dir, 1024, "scene").unwrap_err()).contains("a directory"));
        let fifo = dir.join("fifo");
        let made = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .is_ok_and(|s| s.success());
        if made {
            // Refused at once: nothing opens it (opening a FIFO would block).
            assert!(format!("{:?}", read_text(&fifo, 1024, "scene").unwrap_err()).contains("not a regular file"));
        }
        let big = dir.join("big.toml");
        std::fs::write(&big, vec![b'#'; 2000]).unwrap();
        assert!(format!("{:?}", read_text(&big, 1024, "scene").unwrap_err()).contains("at most 1024"));
        std::fs::write(&big, b"a = 1\nb = \"\xff\"\n").unwrap();
        let e = read_text(&big, 1024, "scene").unwrap_err().to_string();
        assert!(e.contains(":2:6:") && e.contains("not UTF-8"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
