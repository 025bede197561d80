//! A reader's memory stays within a small multiple of its input: scene files of 10 MB of
//! newlines, comments or CRLF line ends, and models of every format padded to 10 MB, are read
//! within 10 times their size (the process's peak resident memory, from /proc, in a test
//! binary of its own, one measurement at a time), and their errors still name the file's own
//! lines.

use std::path::Path;
use std::sync::Mutex;

/// One measurement at a time: the peak is the process's.
static ONE_AT_A_TIME: Mutex<()> = Mutex::new(());

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
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
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

/// Resets the peak to the current resident memory (Linux's `clear_refs` 5), so that each file
/// below is measured on its own; `false` where the kernel does not allow it.
fn reset_peak() -> bool {
    std::fs::write("/proc/self/clear_refs", "5").is_ok()
}

/// Models and scenes of every format padded with what a reader skips (blank lines, comments,
/// whitespace) to 10 MB: each is read within 10 times its size (the file's text included).
#[test]
fn every_format_padded_to_10_mb_stays_within_ten_times_its_size() {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    if peak().is_none() || !reset_peak() {
        eprintln!("skipped: no /proc/self/status or clear_refs");
        return;
    }
    let dir = std::env::temp_dir().join(format!("phong-memory-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let tri_obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    let mb = 10_000_000;
    let ply_header = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
                      element face 1\nproperty list uchar int vertex_indices\nend_header\n";
    let files: Vec<(&str, String)> = vec![
        ("blank.obj", "\n".repeat(mb) + tri_obj),
        ("comments.obj", "# c\n".repeat(mb / 4) + tri_obj),
        (
            "spaces.obj",
            format!("v 0 0 0{}\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", " ".repeat(mb)),
        ),
        ("with_mtl.obj", format!("mtllib big.mtl\nusemtl a\n{tri_obj}")),
        ("big.mtl", format!("newmtl a\n{}Kd 1 0 0\n", "# c\n".repeat(mb / 4))),
        (
            "comments.ply",
            format!(
                "ply\nformat ascii 1.0\n{}{}0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
                "comment x\n".repeat(mb / 10),
                &ply_header["ply\nformat ascii 1.0\n".len()..]
            ),
        ),
        (
            "spaces.ply",
            format!("{ply_header}0 0 0\n1 0 0\n0 1 0\n3 0 1 2{}\n", " ".repeat(mb)),
        ),
        (
            "blank.stl",
            format!(
                "solid a\n{}facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid a\n",
                "\n".repeat(mb)
            ),
        ),
        (
            "spaces.gltf",
            format!(
                "{{\"asset\": {{\"version\": \"2.0\"}},{}\"buffers\": [{{\"byteLength\": 36, \"uri\": \"data:application/octet-stream;base64,{}\"}}],\
                 \"bufferViews\": [{{\"buffer\": 0, \"byteLength\": 36}}],\
                 \"accessors\": [{{\"bufferView\": 0, \"componentType\": 5126, \"count\": 3, \"type\": \"VEC3\", \"min\": [0,0,0], \"max\": [1,1,0]}}],\
                 \"meshes\": [{{\"primitives\": [{{\"attributes\": {{\"POSITION\": 0}}}}]}}], \"nodes\": [{{\"mesh\": 0}}], \"scenes\": [{{\"nodes\": [0]}}]}}",
                " ".repeat(mb),
                "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"
            ),
        ),
    ];
    for (name, text) in &files {
        std::fs::write(dir.join(name), text).unwrap();
    }
    for (name, text) in &files {
        if name.ends_with(".mtl") {
            continue;
        }
        assert!(reset_peak());
        let before = peak().unwrap();
        let loaded = phong_scene::load(&dir.join(name));
        let grown = peak().unwrap().saturating_sub(before);
        let size = text.len() as u64 + if *name == "with_mtl.obj" { mb as u64 } else { 0 };
        let scene = loaded.unwrap_or_else(|e| panic!("{name}: {e}")).scene;
        assert_eq!(scene.triangle_count(), 1, "{name}");
        assert!(
            grown < 10 * size,
            "{name}: peak memory grew by {grown} bytes for {size} bytes of files"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
