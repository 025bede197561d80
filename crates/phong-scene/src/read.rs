//! Reading input files safely: only regular files (a FIFO would block, a device never ends),
//! each within a size limit checked before reading and again while reading, and text that is
//! not UTF-8 named by its first bad line.

use crate::Error;
use std::io::Read;
use std::path::{Path, PathBuf};

/// The bytes of `path`, a regular file of at most `limit` bytes (`what` names the kind and its
/// limit's constant in messages).
pub fn read_bounded(path: &Path, limit: u64, what: &str) -> Result<Vec<u8>, Error> {
    crate::timing::timed(|t| &mut t.read, || read_bounded_untimed(path, limit, what))
}

fn read_bounded_untimed(path: &Path, limit: u64, what: &str) -> Result<Vec<u8>, Error> {
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

/// Where a file that a model names is, looked up from the model's folder `dir`: the name as
/// written (`\\` read as `/`); else, for a name written on another machine (an absolute
/// Windows path, another letter case, the images moved into a subfolder), the file it means:
/// the path with each folder and file matched regardless of case, then a file of its name
/// (regardless of case) in `dir` or in its subfolders two deep, as Blender's OBJ importer
/// searches (where `by_name`). The second value is true where the file was found elsewhere than written (the
/// caller warns). Nothing found: the path as written, for the caller's error to name.
pub(crate) fn locate(dir: &Path, name: &str, by_name: bool) -> (PathBuf, bool) {
    let written = name.replace('\\', "/");
    let as_written = dir.join(&written);
    if as_written.exists() {
        return (as_written, false);
    }
    // A model named without a folder is in the working one.
    let dir = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    let found = matched_case(dir, &written).or_else(|| {
        if !by_name {
            return None;
        }
        let base = Path::new(&written).file_name()?.to_str()?;
        by_file_name(dir, base)
    });
    match found {
        Some(p) => (p, true),
        None => (as_written, false),
    }
}

/// The file a model at `model` names `name` (relative to the model's folder `dir`): as
/// written, else where [`locate`] finds it (by its file name where `by_name`),
/// with a warning in `moved`.
pub(crate) fn found(
    dir: &Path,
    name: &str,
    by_name: bool,
    model: &Path,
    moved: &std::cell::RefCell<Vec<String>>,
) -> PathBuf {
    let (p, elsewhere) = crate::read::locate(dir, name, by_name);
    if elsewhere {
        let msg = format!(
            "{}: `{name}` is not there as written; reading {} (found by its name)",
            model.display(),
            p.display()
        );
        let mut moved = moved.borrow_mut();
        if !moved.contains(&msg) {
            moved.push(msg);
        }
    }
    p
}

/// The entries of `dir` in name order (none where it cannot be read), each with whether it
/// is a folder; at most `budget` entries read, `budget` reduced by those read.
fn entries(dir: &Path, budget: &mut usize) -> Vec<(String, PathBuf, bool)> {
    let Ok(read) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for e in read.flatten() {
        if *budget == 0 {
            break;
        }
        *budget -= 1;
        let Ok(name) = e.file_name().into_string() else {
            continue;
        };
        // `metadata` follows links: a link to a folder is searched as one.
        let dir = std::fs::metadata(e.path()).is_ok_and(|m| m.is_dir());
        out.push((name, e.path(), dir));
    }
    out.sort();
    out
}

/// Entries read at most while looking for a file: a model in a large folder (a home folder)
/// costs a bounded look, not a walk of the disk.
const SEARCH_BUDGET: usize = 4096;

/// `relative` (`/`-separated) from `dir` with each component matched regardless of ASCII
/// case (`.` and `..` as they are); `None` for an absolute path or where a component has no
/// match.
fn matched_case(dir: &Path, relative: &str) -> Option<PathBuf> {
    if relative.starts_with('/') {
        return None;
    }
    let mut budget = SEARCH_BUDGET;
    let mut at = dir.to_path_buf();
    let parts: Vec<&str> = relative.split('/').filter(|c| !c.is_empty() && *c != ".").collect();
    for (i, part) in parts.iter().enumerate() {
        let last = i + 1 == parts.len();
        if *part == ".." {
            at.push("..");
            continue;
        }
        if at.join(part).exists() {
            at.push(part);
            continue;
        }
        let (_, path, _) = entries(&at, &mut budget)
            .into_iter()
            .find(|(n, _, is_dir)| n.eq_ignore_ascii_case(part) && (*is_dir != last))?;
        at = path;
    }
    at.is_file().then_some(at)
}

/// A file named `base` regardless of ASCII case in `dir` or its subfolders up to two deep:
/// the shallowest, one of exactly that name first, then in name order.
fn by_file_name(dir: &Path, base: &str) -> Option<PathBuf> {
    let mut budget = SEARCH_BUDGET;
    let mut level = vec![dir.to_path_buf()];
    for _depth in 0..3 {
        let mut next = Vec::new();
        let mut found: Vec<(bool, PathBuf)> = Vec::new();
        for d in &level {
            for (name, path, is_dir) in entries(d, &mut budget) {
                if is_dir {
                    next.push(path);
                } else if name.eq_ignore_ascii_case(base) {
                    found.push((name != base, path));
                }
            }
        }
        if let Some((_, p)) = found.into_iter().min() {
            return Some(p);
        }
        level = next;
    }
    None
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

    /// Names written on another machine find their file; the name as written wins where it
    /// is there; nothing found gives the name as written back.
    #[test]
    fn locate_finds_files_named_from_another_machine() {
        let dir = std::env::temp_dir().join(format!("phong-locate-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        for f in [
            "Textures/Skin.PNG",
            "a/b/deep.png",
            "a/b/c/deeper.png",
            "x.png",
            "sub/X.png",
            "sub/x.png",
        ] {
            let p = dir.join(f);
            std::fs::create_dir_all(p.parent().unwrap()).unwrap();
            std::fs::write(&p, f).unwrap();
        }
        let at = |name: &str| locate(&dir, name, true);
        let rel = |p: PathBuf| p.strip_prefix(&dir).unwrap().to_string_lossy().replace('\\', "/");
        // As written (backslashes are separators): not moved.
        assert_eq!(at("Textures\\Skin.PNG"), (dir.join("Textures/Skin.PNG"), false));
        assert_eq!(at("x.png"), (dir.join("x.png"), false));
        // Another letter case, folder and file.
        let (p, moved) = at("textures/skin.png");
        assert_eq!((rel(p), moved), ("Textures/Skin.PNG".to_string(), true));
        // An absolute Windows path, or a folder that is not there: the file name, searched.
        let (p, moved) = at("C:\\Users\\bob\\Desktop\\SKIN.png");
        assert_eq!((rel(p), moved), ("Textures/Skin.PNG".to_string(), true));
        let (p, moved) = at("/home/bob/model/maps/deep.png");
        assert_eq!((rel(p), moved), ("a/b/deep.png".to_string(), true));
        // Two deep at most.
        assert_eq!(at("deeper.png"), (dir.join("deeper.png"), false));
        // The shallowest, then the exact name: `x.png` beside the model, `sub/x.png` below it.
        let (p, _) = at("elsewhere/x.png");
        assert_eq!(rel(p), "x.png");
        std::fs::remove_file(dir.join("x.png")).unwrap();
        let (p, _) = at("elsewhere/x.png");
        assert_eq!(rel(p), "sub/x.png");
        let (p, _) = at("elsewhere/X.png");
        assert_eq!(rel(p), "sub/X.png");
        // Not searched by name where the caller says so (another case still found).
        assert!(at("x/deep.png").1);
        assert_eq!(locate(&dir, "x/deep.png", false), (dir.join("x/deep.png"), false));
        assert!(locate(&dir, "a/B/DEEP.png", false).1);
        // Nothing of that name.
        assert_eq!(at("maps/none.png"), (dir.join("maps/none.png"), false));
        // A model given without a folder looks in the working one.
        assert_eq!(
            locate(Path::new(""), "no-such-file.png", true),
            (PathBuf::from("no-such-file.png"), false)
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
