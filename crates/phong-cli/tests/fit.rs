//! `phong fit` from the command line: a fit written as a scene file's material that renders
//! the target back, the report, and bad input refused with exit 2 and nothing written.

use std::path::Path;
use std::process::Command;

fn phong() -> Command {
    Command::new(env!("CARGO_BIN_EXE_phong"))
}

const SCENE: &str = r#"
[image]
width = 200
height = 150
[camera]
position = [0, 0.5, 4]
[[light]]
type = "point"
position = [2, 2, 3]
[[object]]
shape = "sphere"
material = MATERIAL
[[object]]
shape = "plane"
position = [0, -1, 0]
scale = 3
material = "white_rubber"
"#;

fn setup(dir: &Path) {
    let truth = SCENE.replace(
        "MATERIAL",
        "{ ambient = [0.1, 0.1, 0.3], diffuse = [0.2, 0.3, 0.6], specular = [0.6, 0.6, 0.6], shininess = 75 }",
    );
    std::fs::write(dir.join("truth.toml"), truth).expect("write");
    std::fs::write(dir.join("start.toml"), SCENE.replace("MATERIAL", "\"jade\"")).expect("write");
    let st = phong()
        .arg("render")
        .arg(dir.join("truth.toml"))
        .arg("-o")
        .arg(dir.join("target.png"))
        .output()
        .expect("render");
    assert!(st.status.success());
}

#[test]
fn a_fit_renders_the_target_back() {
    let dir = tempfile::tempdir().expect("tmp");
    setup(dir.path());
    let out = phong()
        .current_dir(dir.path())
        .args([
            "fit",
            "start.toml",
            "--target",
            "target.png",
            "--object",
            "sphere",
            "-o",
            "fitted.toml",
            "--mtl",
            "fitted.mtl",
            "--report",
            "report",
        ])
        .output()
        .expect("fit");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}{}", String::from_utf8_lossy(&out.stderr));
    assert!(
        stdout.contains("psnr") && stdout.contains("nearest classic material"),
        "{stdout}"
    );
    for f in ["fitted.toml", "fitted.mtl", "report/comparison.png", "report/error.png"] {
        assert!(dir.path().join(f).is_file(), "{f}");
    }
    // The block drops into the scene: the sphere takes the fitted material.
    let block = std::fs::read_to_string(dir.path().join("fitted.toml")).expect("read");
    let scene = format!("{block}\n{}", SCENE.replace("MATERIAL", "\"fitted\""));
    std::fs::write(dir.path().join("refit.toml"), scene).expect("write");
    let st = phong()
        .current_dir(dir.path())
        .args(["render", "refit.toml", "-o", "refit.png"])
        .output()
        .expect("render");
    assert!(st.status.success(), "{}", String::from_utf8_lossy(&st.stderr));
    let a = decode(&dir.path().join("target.png"));
    let b = decode(&dir.path().join("refit.png"));
    let worst = a.iter().zip(&b).map(|(x, y)| x.abs_diff(*y)).max().unwrap_or(255);
    assert!(
        worst <= 3,
        "the fitted material's render differs from the target by {worst}/255"
    );
    let mtl = std::fs::read_to_string(dir.path().join("fitted.mtl")).expect("read");
    assert!(mtl.starts_with("newmtl fitted\nKa "), "{mtl}");
}

fn decode(p: &Path) -> Vec<u8> {
    let mut r = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(p).expect("open")))
        .read_info()
        .expect("png");
    let mut buf = vec![0; r.output_buffer_size().expect("size")];
    let info = r.next_frame(&mut buf).expect("frame");
    buf.truncate(info.buffer_size());
    buf
}

#[test]
fn bad_input_is_exit_2_and_writes_nothing() {
    let dir = tempfile::tempdir().expect("tmp");
    setup(dir.path());
    std::fs::write(
        dir.path().join("small.toml"),
        SCENE
            .replace("width = 200", "width = 100")
            .replace("MATERIAL", "\"jade\""),
    )
    .expect("w");
    std::fs::write(dir.path().join("text.png"), "not an image").expect("w");
    std::fs::write(
        dir.path().join("short.binary"),
        [90u8, 0, 0, 0, 90, 0, 0, 0, 180, 0, 0, 0, 1, 2],
    )
    .expect("w");
    let cases: &[(&[&str], &str)] = &[
        (
            &["fit", "small.toml", "--target", "target.png", "--object", "0"],
            "the target is 200x150 but the scene's image is 100x150",
        ),
        (
            &["fit", "start.toml", "--target", "text.png", "--object", "0"],
            "not a PNG",
        ),
        (
            &["fit", "start.toml", "--target", "missing.png", "--object", "0"],
            "cannot read",
        ),
        (
            &["fit", "start.toml", "--target", "target.png"],
            "choose one with --object",
        ),
        (
            &["fit", "start.toml", "--target", "target.png", "--object", "teapot"],
            "no such object",
        ),
        (
            &[
                "fit",
                "start.toml",
                "--target",
                "target.png",
                "--object",
                "0",
                "--free",
                "",
            ],
            "nothing to fit",
        ),
        (
            &[
                "fit",
                "start.toml",
                "--target",
                "target.png",
                "--object",
                "0",
                "--model",
                "fong",
            ],
            "unknown --model",
        ),
        (&["fit", "--brdf", "merl:short.binary"], "truncated"),
        (&["fit", "--brdf", "ggx:alpha=-1"], "alpha"),
        (&["fit"], "needs SCENE.toml --target"),
    ];
    for (args, msg) in cases {
        let out = phong()
            .current_dir(dir.path())
            .args(*args)
            .args(["-o", "out.toml"])
            .output()
            .expect("runs");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(msg), "{args:?}: {err}");
        assert!(!dir.path().join("out.toml").exists(), "{args:?} wrote its output");
    }
}

#[test]
fn a_brdf_fit_from_the_command_line() {
    let dir = tempfile::tempdir().expect("tmp");
    let out = phong()
        .current_dir(dir.path())
        .args([
            "fit",
            "--brdf",
            "ggx:alpha=0.2,f0=0.04,kd=0.5/0.3/0.2",
            "--report",
            "r",
            "-o",
            "ggx.toml",
        ])
        .output()
        .expect("runs");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let toml = std::fs::read_to_string(dir.path().join("ggx.toml")).expect("read");
    assert!(
        toml.contains("normalization = \\\"blinn-phong\\\"") || toml.contains("normalization = \"blinn-phong\""),
        "{toml}"
    );
    assert!(dir.path().join("r/lobes.png").is_file());
}
