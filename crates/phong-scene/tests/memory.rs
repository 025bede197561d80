//! A reader's memory stays within a small multiple of its input: scene files of 10 MB of
//! newlines, comments or CRLF line ends are parsed within 10 times their size (the process's
//! peak resident memory, from /proc, in a test binary of its own so that nothing else runs
//! beside it), and their errors still name the file's own lines.

use std::path::Path;

/// The process's peak resident memory in bytes (`VmHWM`), where /proc says it.
fn peak() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let kb: u64 = status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))?
        .trim()
        .trim_end_matches("kB")
        .trim()
        .parse()
        .ok()?;
    Some(kb * 1024)
}

#[test]
fn scene_files_of_blank_lines_stay_within_ten_times_their_size() {
    let Some(before) = peak() else {
        eprintln!("skipped: no /proc/self/status");
        return;
    };
    for (what, filler) in [("newlines", "\n"), ("comments", "#\n"), ("CRLF", "\r\n")] {
        let n = 10_000_000 / filler.len();
        let src = format!(
            "[image]\nwidth = 64\nheight = 48\n{}[[object]]\nshape = \"spher\"\n",
            filler.repeat(n)
        );
        let e = match phong_scene::parse_scene(&src, Path::new("blank.toml")) {
            Ok(_) => panic!("{what}: the misspelt shape is refused"),
            Err(e) => e.to_string(),
        };
        assert!(e.contains(&format!("blank.toml:{}:9", n + 5)), "{what}: {e}");
        let grown = peak().expect("peak") - before;
        // The text itself (10 MB) is part of what the test holds.
        assert!(
            grown < 10 * src.len() as u64,
            "{what}: peak memory grew by {grown} bytes for a {}-byte file",
            src.len()
        );
    }
}
