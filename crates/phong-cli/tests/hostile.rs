//! Hostile input through the binary: the output is never an input, only regular files within
//! their limits are read, a scene's size is bounded as a whole, inputs that made tobj panic.

use std::path::Path;
use std::process::{Command, Output};
use std::time::{Duration, Instant};

fn phong(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_phong"))
        .current_dir(dir)
        .args(args)
        .output()
        .expect("runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

const SCENE: &str = "[image]\nwidth = 32\nheight = 24\n[[object]]\nshape = \"sphere\"\n";

#[test]
fn the_output_is_never_an_input() {
    let dir = tempfile::tempdir().expect("tmp");
    let d = dir.path();
    // A scene file named like an image, rendered onto itself.
    std::fs::write(d.join("s.png"), SCENE).expect("w");
    std::fs::write(d.join("s.toml"), SCENE).expect("w");
    std::os::unix::fs::symlink(d.join("s.toml"), d.join("link.png")).expect("symlink");
    std::fs::hard_link(d.join("s.toml"), d.join("hard.png")).expect("hard link");
    for (scene, out) in [
        ("s.png", "s.png"),
        ("s.toml", "link.png"),
        ("s.toml", "hard.png"),
        ("./s.png", "../{}/s.png"),
    ] {
        let out = out.replace("{}", &d.file_name().expect("name").to_string_lossy());
        let o = phong(d, &["render", scene, "-o", &out]);
        assert_eq!(o.status.code(), Some(2), "{scene} -o {out}: {}", stderr(&o));
        assert!(stderr(&o).contains("refusing to overwrite"), "{}", stderr(&o));
    }
    assert_eq!(std::fs::read_to_string(d.join("s.png")).expect("r"), SCENE);
    assert_eq!(std::fs::read_to_string(d.join("s.toml")).expect("r"), SCENE);
    // A model's MTL as the output.
    std::fs::write(
        d.join("m.obj"),
        "mtllib m.mtl\nusemtl a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    )
    .expect("w");
    std::fs::write(d.join("m.mtl"), "newmtl a\nKd 1 0 0\n").expect("w");
    std::os::unix::fs::symlink(d.join("m.mtl"), d.join("mtl.png")).expect("symlink");
    let o = phong(d, &["render", "m.obj", "-o", "mtl.png"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert_eq!(
        std::fs::read_to_string(d.join("m.mtl")).expect("r"),
        "newmtl a\nKd 1 0 0\n"
    );
    // And phong fit's outputs.
    let o = phong(d, &["fit", "s.toml", "--target", "s.png", "-o", "hard.png"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}

#[test]
fn only_regular_files_are_read_and_quickly() {
    let dir = tempfile::tempdir().expect("tmp");
    let d = dir.path();
    let fifo = d.join("fifo.toml");
    if !Command::new("mkfifo").arg(&fifo).status().is_ok_and(|s| s.success()) {
        eprintln!("skipped the FIFO cases: mkfifo failed");
        return;
    }
    std::fs::write(d.join("fifo-mesh.toml"), "[[object]]\nmesh = \"fifo.obj\"\n").expect("w");
    Command::new("mkfifo").arg(d.join("fifo.obj")).status().expect("mkfifo");
    std::fs::write(d.join("m.obj"), "mtllib fifo.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").expect("w");
    Command::new("mkfifo").arg(d.join("fifo.mtl")).status().expect("mkfifo");
    std::os::unix::fs::symlink("/dev/zero", d.join("zero.obj")).expect("symlink");
    for args in [
        &["render", "fifo.toml", "-o", "x.png"][..],
        &["render", "fifo-mesh.toml", "-o", "x.png"],
        &["render", "m.obj", "-o", "x.png"],
        &["render", "/dev/zero", "-o", "x.png"],
        &["render", "zero.obj", "-o", "x.png"],
        &["render", ".", "-o", "x.png"],
    ] {
        let t = Instant::now();
        let o = phong(d, args);
        assert!(t.elapsed() < Duration::from_secs(10), "{args:?} took {:?}", t.elapsed());
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        let e = stderr(&o);
        assert!(e.contains("regular file") || e.contains("a directory"), "{args:?}: {e}");
        assert!(!d.join("x.png").exists());
    }
}

#[test]
fn a_scene_is_bounded_as_a_whole() {
    let dir = tempfile::tempdir().expect("tmp");
    // Each sphere is under the per-primitive limit; three are past the scene's.
    let mut scene = String::new();
    for _ in 0..3 {
        scene.push_str("[[object]]\nshape = \"sphere\"\nsegments = 3000\n");
    }
    std::fs::write(dir.path().join("big.toml"), &scene).expect("w");
    let o = phong(dir.path(), &["render", "big.toml", "-o", "x.png"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("MAX_SCENE_TRIANGLES") && stderr(&o).contains("big.toml:"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn inputs_that_made_tobj_panic_render() {
    let dir = tempfile::tempdir().expect("tmp");
    let d = dir.path();
    // `Kd 0.5` (one value: grey) made tobj 4.0.5 unwrap an error.
    std::fs::write(
        d.join("k.obj"),
        "mtllib k.mtl\nusemtl a\nv -1 -1 0\nv 1 -1 0\nv 0 1 0\nf 1 2 3\n",
    )
    .expect("w");
    std::fs::write(d.join("k.mtl"), "newmtl a\nKa 0\nKd 0.5 # grey\nKs 0\n").expect("w");
    let o = phong(d, &["render", "k.obj", "-o", "k.png"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    // Non-UTF-8 text names its line.
    std::fs::write(d.join("latin.toml"), b"[image]\n# caf\xe9\nwidth = 4\n").expect("w");
    let o = phong(d, &["render", "latin.toml", "-o", "l.png"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("latin.toml:2:6: not UTF-8"), "{}", stderr(&o));
}
