//! The real `phong` binary, as a user runs it.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn phong(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_phong"))
        .args(args)
        .current_dir(root())
        .output()
        .expect("run phong")
}

/// A path named `name` in a fresh temporary directory, removed (with what the test wrote
/// there) when this is dropped.
struct TmpPath {
    /// Held for its `Drop`, which removes the directory.
    _dir: tempfile::TempDir,
    path: PathBuf,
}

impl std::ops::Deref for TmpPath {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.path
    }
}

impl AsRef<Path> for TmpPath {
    fn as_ref(&self) -> &Path {
        &self.path
    }
}

fn tmp(name: &str) -> TmpPath {
    let dir = tempfile::Builder::new().prefix("phong-cli-").tempdir().unwrap();
    let path = dir.path().join(name);
    TmpPath { _dir: dir, path }
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Decodes a PNG: (width, height, channels, bytes).
fn read_png(p: &Path) -> (u32, u32, usize, Vec<u8>) {
    let dec = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(p).unwrap()));
    let mut r = dec.read_info().unwrap();
    let mut buf = vec![0; r.output_buffer_size().unwrap()];
    let info = r.next_frame(&mut buf).unwrap();
    buf.truncate(info.buffer_size());
    (info.width, info.height, info.color_type.samples(), buf)
}

fn examples() -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(root().join("examples/scenes"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    v.sort();
    v
}

#[test]
fn every_example_scene_renders() {
    let scenes = examples();
    assert!(scenes.len() >= 7, "{scenes:?}");
    for s in scenes {
        let out = tmp(&format!("{}.png", s.file_stem().unwrap().to_string_lossy()));
        let o = phong(&[
            "render",
            s.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--width",
            "240",
            "--height",
            "160",
        ]);
        assert!(o.status.success(), "{}: {}", s.display(), stderr(&o));
        let (w, h, _, bytes) = read_png(&out);
        assert_eq!((w, h), (240, 160));
        // Something was drawn: not a single colour.
        assert!(bytes.chunks(3).any(|p| p != &bytes[..3]), "{} is blank", s.display());
    }
}

/// The README's quick-start render command, exactly as written there.
#[test]
fn readme_render_command_works() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let line = readme
        .lines()
        .find(|l| l.starts_with("cargo run --release -- render "))
        .expect("README has a render command");
    let args: Vec<&str> = line
        .trim_start_matches("cargo run --release -- ")
        .split_whitespace()
        .collect();
    let out_pos = args.iter().position(|a| *a == "-o").unwrap() + 1;
    let out = tmp("readme.png");
    let mut args = args.clone();
    args[out_pos] = out.to_str().unwrap();
    let o = phong(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(out.is_file());
    assert!(readme.contains("cargo test --workspace"));
}

#[test]
fn obj_model_renders_alone() {
    let out = tmp("knot.png");
    let o = phong(&[
        "render",
        "examples/scenes/assets/knot.obj",
        "-o",
        out.to_str().unwrap(),
        "--width",
        "200",
        "--height",
        "150",
        "-v",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(e.contains("triangles=5120") && e.contains("png="), "{e}");
    assert_eq!(read_png(&out).0, 200);
}

#[test]
fn bad_input_exits_2_with_location() {
    let scene = tmp("bad.toml");
    std::fs::write(
        &scene,
        "[image]\nwidth = 800\n\n[[object]]\nshape = \"sphere\"\nmaterial = \"emrald\"\n",
    )
    .unwrap();
    let out = tmp("bad.png");
    std::fs::write(&out, b"previous").unwrap();
    let o = phong(&["render", scene.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    let e = stderr(&o);
    assert!(
        e.contains("bad.toml:6:12: `material`: unknown material \"emrald\"; did you mean emerald?"),
        "{e}"
    );
    assert!(!e.contains("panicked"));
    // The previous file is untouched: never a partial output.
    assert_eq!(std::fs::read(&out).unwrap(), b"previous");

    let o = phong(&["render", "does/not/exist.toml", "-o", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("cannot read does/not/exist.toml"), "{}", stderr(&o));

    let o = phong(&["render", "examples/scenes/tour.toml", "-o", "x.jpg"]);
    assert_eq!(o.status.code(), Some(2));
    let o = phong(&[
        "render",
        "examples/scenes/tour.toml",
        "-o",
        out.to_str().unwrap(),
        "--width",
        "1000000",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("--width must be from 1 to 16384"));
    // Thread counts: none, and more than any machine has (100 000 used to exhaust memory
    // spawning them, then abort).
    for (cmd, t) in [("render", "0"), ("bench", "100000")] {
        let mut args = vec![cmd, "examples/scenes/tour.toml", "--threads", t];
        if cmd == "render" {
            args.extend(["-o", out.to_str().unwrap()]);
        }
        let o = phong(&args);
        assert_eq!(o.status.code(), Some(2), "{cmd} --threads {t}");
        assert!(
            stderr(&o).contains(&format!("--threads must be from 1 to 1024, got {t}")),
            "{}",
            stderr(&o)
        );
    }
    let o = phong(&[
        "render",
        "examples/scenes/tour.toml",
        "-o",
        out.to_str().unwrap(),
        "--model",
        "blin",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("did you mean \"blinn-phong\""), "{}", stderr(&o));
    let o = phong(&[
        "render",
        "examples/scenes/tour.toml",
        "-o",
        out.to_str().unwrap(),
        "--antialias",
        "8",
    ]);
    assert_eq!(o.status.code(), Some(2));
    // Each flag within its range, together past the core's limit of pixels × samples: refused
    // before rendering, naming the flags, and the previous file left as it was.
    let o = phong(&[
        "render",
        "examples/scenes/tour.toml",
        "-o",
        out.to_str().unwrap(),
        "--width",
        "16384",
        "--height",
        "16384",
        "--antialias",
        "16",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("--antialias") && stderr(&o).contains("cannot be rendered"),
        "{}",
        stderr(&o)
    );
    assert_eq!(std::fs::read(&out).unwrap(), b"previous");
}

#[test]
fn unwritable_output_exits_1_and_leaves_nothing() {
    let dir = tmp("no-such-dir");
    let out = dir.join("x.png");
    let o = phong(&[
        "render",
        "examples/scenes/terms.toml",
        "-o",
        out.to_str().unwrap(),
        "--width",
        "64",
        "--height",
        "32",
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("cannot write"), "{}", stderr(&o));
    assert!(!dir.exists());
}

/// `--model lambert --output specular`: no specular anywhere, so the objects are black.
#[test]
fn flags_override_the_file() {
    let out = tmp("spec.png");
    let args = [
        "render",
        "examples/scenes/tour.toml",
        "-o",
        out.to_str().unwrap(),
        "--width",
        "80",
        "--height",
        "60",
    ];
    let mut with = args.to_vec();
    with.extend(["--model", "lambert", "--output", "specular", "--antialias", "1"]);
    assert!(phong(&with).status.success());
    let (_, _, _, bytes) = read_png(&out);
    let bg = [13u8, 13, 20]; // [0.05, 0.05, 0.08] · 255, rounded
    assert!(
        bytes.chunks(3).all(|p| p == bg || p == [0, 0, 0]),
        "specular without a specular term"
    );
    assert!(bytes.chunks(3).any(|p| p == [0, 0, 0]));
    // `--output normal`: each object pixel is a unit normal, `(n + 1)/2`; `--interpolation
    // flat` makes it the facet's, so a sphere of 8 segments shows at most its 64 triangles'
    // normals where per-pixel interpolation shows hundreds.
    let sphere = tmp("sphere.toml");
    std::fs::write(
        &sphere,
        "[image]\nwidth = 96\nheight = 96\nbackground = [0.0, 0.0, 0.0]\n[[object]]\nshape = \"sphere\"\nsegments = 8\n",
    )
    .unwrap();
    let normals = |interpolation: &str| {
        let out = tmp("normal.png");
        let o = phong(&[
            "render",
            sphere.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--output",
            "normal",
            "--interpolation",
            interpolation,
            "--antialias",
            "1",
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let (_, _, n, bytes) = read_png(&out);
        let object: Vec<&[u8]> = bytes.chunks(n).filter(|p| p[..3] != [0, 0, 0]).collect();
        assert!(
            object.len() > 1000,
            "{interpolation}: the sphere covers {} pixels",
            object.len()
        );
        for p in &object {
            let n: f32 = p[..3].iter().map(|&c| (f32::from(c) / 255.0 * 2.0 - 1.0).powi(2)).sum();
            assert!(
                (n.sqrt() - 1.0).abs() < 0.02,
                "{interpolation}: |n| = {} at {p:?}",
                n.sqrt()
            );
        }
        object
            .iter()
            .map(|p| p[..3].to_vec())
            .collect::<std::collections::BTreeSet<_>>()
            .len()
    };
    let (flat, smooth) = (normals("flat"), normals("phong"));
    assert!(flat <= 64 && smooth > 300, "{flat} flat normals, {smooth} interpolated");
}

/// `--kernels`: the AVX2 builds (with and without AVX-512's registers) draw the same bytes; the
/// portable build (exact reciprocals and square roots, where AVX2 refines the hardware's
/// estimates) draws within 1/255 of them on every pixel.
#[test]
fn every_kernel_build_draws_the_same_image() {
    let image = |kernels: &str| {
        let out = tmp("k.png");
        let o = phong(&[
            "render",
            "examples/scenes/textures.toml",
            "-o",
            out.to_str().unwrap(),
            "--width",
            "160",
            "--height",
            "120",
            "--kernels",
            kernels,
            "-v",
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        (stderr(&o), read_png(&out).3)
    };
    let (auto, avx2, portable) = (image("auto"), image("avx2"), image("portable"));
    assert!(portable.0.contains("portable kernels"), "{}", portable.0);
    assert!(auto.1 == avx2.1, "the AVX2 builds' images differ");
    assert_eq!(avx2.1.len(), portable.1.len());
    let worst = avx2.1.iter().zip(&portable.1).map(|(a, b)| a.abs_diff(*b)).max();
    assert!(
        worst <= Some(1),
        "the portable build is {worst:?}/255 from the AVX2 build"
    );
    let o = phong(&["render", "examples/scenes/tour.toml", "-o", "x.png", "--kernels", "sse"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}

#[test]
fn materials_lists_29_and_shows_one() {
    let o = phong(&["materials"]);
    assert!(o.status.success());
    let s = String::from_utf8_lossy(&o.stdout);
    assert_eq!(s.lines().count(), 30, "{s}");
    assert!(s.contains("polished_bronze"));
    let o = phong(&["materials", "Polished Bronze"]);
    let s = String::from_utf8_lossy(&o.stdout);
    assert!(
        s.contains("shininess 76.8") && s.contains("0.774597 0.458561 0.200621"),
        "{s}"
    );
    let o = phong(&["materials", "bronz"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("did you mean bronze"));
}

/// Golden images: small renders compared with tests/golden/*.png within 1/255 (float
/// differences across compilers); on failure the actual image and a difference image are
/// written beside them. Re-bless with `PHONG_BLESS=1 cargo test -p phong-cli --test cli golden`.
#[test]
fn golden_images() {
    let golden = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden");
    let bless = std::env::var_os("PHONG_BLESS").is_some();
    let mut failures = Vec::new();
    for name in ["terms", "gouraud_vs_phong", "teapots", "tour"] {
        let scene = format!("examples/scenes/{name}.toml");
        let out = tmp(&format!("golden-{name}.png"));
        let o = phong(&[
            "render",
            &scene,
            "-o",
            out.to_str().unwrap(),
            "--width",
            "300",
            "--height",
            "150",
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let want_path = golden.join(format!("{name}.png"));
        if bless {
            std::fs::copy(&out, &want_path).unwrap();
            continue;
        }
        let (_, _, ch, got) = read_png(&out);
        let (_, _, ch2, want) = read_png(&want_path);
        assert_eq!((ch, got.len()), (ch2, want.len()), "{name}: size");
        let worst = got.iter().zip(&want).map(|(a, b)| a.abs_diff(*b)).max().unwrap_or(0);
        if worst > 1 {
            std::fs::copy(&out, golden.join(format!("{name}.actual.png"))).unwrap();
            let diff: Vec<u8> = got
                .iter()
                .zip(&want)
                .map(|(a, b)| a.abs_diff(*b).saturating_mul(16))
                .collect();
            let f = std::fs::File::create(golden.join(format!("{name}.diff.png"))).unwrap();
            let mut enc = png::Encoder::new(f, 300, 150);
            enc.set_color(if ch == 4 {
                png::ColorType::Rgba
            } else {
                png::ColorType::Rgb
            });
            enc.write_header().unwrap().write_image_data(&diff).unwrap();
            failures.push(format!("{name}: largest difference {worst}/255"));
        }
    }
    assert!(failures.is_empty(), "{failures:?}");
}

/// `--backend gpu` with no Vulkan driver: a clear error and exit code 1; `auto` falls back to
/// the CPU. With a driver (lavapipe in CI), `--backend gpu` renders, by the path asked for.
#[test]
fn gpu_backend_selection() {
    let out = tmp("gpu.png");
    let args = [
        "render",
        "examples/scenes/terms.toml",
        "-o",
        out.to_str().unwrap(),
        "--width",
        "120",
        "--height",
        "40",
        "-v",
    ];
    let no_driver = |backend: &str| {
        let mut a = args.to_vec();
        a.extend(["--backend", backend]);
        Command::new(env!("CARGO_BIN_EXE_phong"))
            .args(&a)
            .current_dir(root())
            .env("VK_DRIVER_FILES", "/nonexistent")
            .env("VK_ICD_FILENAMES", "/nonexistent")
            .output()
            .unwrap()
    };
    let o = no_driver("gpu");
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("no GPU adapter found"), "{}", stderr(&o));
    let o = no_driver("auto");
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("backend cpu"), "{}", stderr(&o));

    let mut a = args.to_vec();
    a.extend(["--backend", "gpu"]);
    let o = phong(&a);
    if o.status.success() {
        assert!(stderr(&o).contains("backend gpu"), "{}", stderr(&o));
        assert_eq!(read_png(&out).0, 120);
        // How the GPU drew it, as asked.
        for (path, said) in [("pipeline", "render pipeline"), ("compute", "compute rasterizer")] {
            let mut a = a.clone();
            a.extend(["--gpu-path", path]);
            let o = phong(&a);
            assert!(o.status.success(), "{}", stderr(&o));
            assert!(stderr(&o).contains(said), "{path}: {}", stderr(&o));
        }
        // `bench --backend gpu -v`: the line, the path, and the kernels' times where the
        // adapter has timestamps.
        let o = phong(&[
            "bench",
            "benches/scenes/fill_4lights.toml",
            "--backend",
            "gpu",
            "--gpu-path",
            "compute",
            "--frames",
            "2",
            "--width",
            "64",
            "--height",
            "32",
            "-v",
        ]);
        assert_bench_line(&o, "64x32", 2, 2);
        let e = stderr(&o);
        assert!(e.contains("compute rasterizer") && e.contains("readback="), "{e}");
        if !e.contains("no timestamps") {
            assert!(e.contains("gpu kernels per frame") && e.contains("shade="), "{e}");
        }
        // A camera inside the scene's sphere: a triangle to clip, which the compute rasterizer
        // does not do (exit 2: an input error naming why).
        let scene = tmp("inside.toml");
        std::fs::write(
            &scene,
            "[camera]\nposition = [0.0, 0.0, 0.0]\ntarget = [0.0, 0.0, -1.0]\n\n[shading]\ntwo_sided = true\n\n\
             [[light]]\ntype = \"directional\"\ndirection = [0.0, 0.0, 1.0]\n\n[[object]]\nshape = \"sphere\"\nscale = 2.0\n",
        )
        .unwrap();
        let o = phong(&[
            "render",
            scene.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--backend",
            "gpu",
            "--gpu-path",
            "compute",
        ]);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        assert!(
            stderr(&o).contains("cannot draw this frame") && stderr(&o).contains("near or far plane"),
            "{}",
            stderr(&o)
        );
    } else if std::env::var_os("PHONG_REQUIRE_GPU").is_some() {
        panic!("PHONG_REQUIRE_GPU is set but: {}", stderr(&o));
    } else {
        eprintln!("skipped --backend gpu render: {}", stderr(&o));
    }
}

/// `phong bench`'s output `o`: success and exactly one line in the documented format, of
/// `size`, at least `min_tris` triangles and `frames` frames, with positive times and rates.
fn assert_bench_line(o: &std::process::Output, size: &str, min_tris: u64, frames: u32) {
    assert!(o.status.success(), "{}", stderr(o));
    let out = String::from_utf8_lossy(&o.stdout);
    let line = out.trim();
    assert_eq!(out.lines().count(), 1, "{out}");
    let fields: Vec<&str> = line.split(' ').collect();
    assert_eq!(fields.len(), 6, "{line}");
    assert_eq!(fields[0], "phong:");
    assert_eq!(fields[1], size);
    assert!(
        fields[2].strip_prefix("tris=").unwrap().parse::<u64>().unwrap() >= min_tris,
        "{line}"
    );
    assert_eq!(fields[3], format!("frames={frames}"));
    assert!(
        fields[4].strip_prefix("ms_per_frame=").unwrap().parse::<f64>().unwrap() > 0.0,
        "{line}"
    );
    assert!(
        fields[5].strip_prefix("mpix_per_s=").unwrap().parse::<f64>().unwrap() > 0.0,
        "{line}"
    );
}

/// `phong bench` prints exactly one line in the documented format, and -v the stages.
#[test]
fn bench_line_format() {
    let o = phong(&[
        "bench",
        "examples/scenes/terms.toml",
        "--frames",
        "2",
        "--width",
        "64",
        "--height",
        "32",
        "-v",
    ]);
    assert_bench_line(&o, "64x32", 1001, 2);
    let e = stderr(&o);
    assert!(
        e.contains("setup+binning=")
            && e.contains("rasterisation=")
            && e.contains("shading=")
            && e.contains("resolve="),
        "{e}"
    );
}

/// A PLY model renders from the command line as an OBJ does (framed, lit), a binary STL named
/// in a scene's `mesh` too; a file of no format phong reads is exit 2 naming the formats.
#[test]
fn ply_and_stl_models_render() {
    let ply = tmp("tetra.ply");
    std::fs::write(
        &ply,
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n\
         element face 4\nproperty list uchar int vertex_indices\nend_header\n\
         0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n",
    )
    .unwrap();
    let out = tmp("tetra.png");
    let o = phong(&[
        "render",
        ply.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--width",
        "64",
        "--height",
        "48",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let (w, h, _, px) = read_png(&out);
    assert_eq!((w, h), (64, 48));
    assert!(px.iter().any(|&b| b > 40), "the model is drawn");
    // A binary STL of one triangle in a scene, beside it.
    let stl = tmp("tri.stl");
    let mut b = b"binary".to_vec();
    b.resize(80, 0);
    b.extend(1u32.to_le_bytes());
    for c in [0f32, 0.0, 1.0, -1.0, -1.0, 0.0, 1.0, -1.0, 0.0, 0.0, 1.0, 0.0] {
        b.extend(c.to_le_bytes());
    }
    b.extend([0, 0]);
    std::fs::write(&stl, &b).unwrap();
    let scene = tmp("s.toml");
    std::fs::write(
        &scene,
        format!(
            "[image]\nwidth = 32\nheight = 32\n[[object]]\nmesh = \"{}\"\nmaterial = \"gold\"\n",
            stl.display()
        ),
    )
    .unwrap();
    let out2 = tmp("s.png");
    let o = phong(&["render", scene.to_str().unwrap(), "-o", out2.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let other = tmp("cloud.xyz");
    std::fs::write(&other, "ply\nnot really\n").unwrap();
    let o = phong(&["render", other.to_str().unwrap(), "-o", out2.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("cloud.xyz"), "{}", stderr(&o));
}

/// `-v`'s count of images read back from the texture cache.
fn from_cache(o: &Output) -> usize {
    let e = stderr(o);
    let line = e
        .lines()
        .find(|l| l.contains("phong: textures:"))
        .expect("a textures line");
    let n = line.split(" images (").nth(1).and_then(|r| r.split(' ').next());
    n.and_then(|n| n.parse().ok()).unwrap_or_else(|| panic!("{line}"))
}

#[test]
fn a_large_texture_is_read_back_from_the_texture_cache() {
    // A 2048² RGB image (21 MiB with its mipmaps: above the cache's 16 MiB) on a quad.
    let out = tmp("scene.toml");
    let dir = out.parent().unwrap();
    let (w, h) = (2048u32, 2048u32);
    let mut rgb = Vec::with_capacity((w * h * 3) as usize);
    for y in 0..h {
        for x in 0..w {
            rgb.extend_from_slice(&[((x * 7) ^ y) as u8, (y * 3) as u8, ((x + y) / 5) as u8]);
        }
    }
    let mut enc = png::Encoder::new(std::fs::File::create(dir.join("big.png")).unwrap(), w, h);
    enc.set_color(png::ColorType::Rgb);
    enc.set_compression(png::Compression::Fast);
    enc.write_header().unwrap().write_image_data(&rgb).unwrap();
    std::fs::write(
        &*out,
        "[image]\nwidth = 96\nheight = 64\n[camera]\nposition = [0, 0, 3]\n[[light]]\ntype = \"directional\"\ndirection = [0, 0, -1]\n\
         [[object]]\nshape = \"plane\"\nrotation = [90, 0, 0]\nmaterial = { diffuse = [1, 1, 1], diffuse_map = \"big.png\", uv_scale = [3, 3] }\n",
    )
    .unwrap();
    let cache = dir.join("cache");
    let render = |png: &str, cache_arg: &str| {
        let o = phong(&[
            "render",
            out.to_str().unwrap(),
            "-o",
            dir.join(png).to_str().unwrap(),
            "-v",
            "--texture-cache",
            cache_arg,
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        o
    };
    let ptx = || -> Vec<PathBuf> {
        std::fs::read_dir(&cache).map_or(Vec::new(), |d| d.flatten().map(|e| e.path()).collect())
    };
    // Off: decoded, nothing kept.
    let off = render("off.png", "off");
    assert_eq!(from_cache(&off), 0);
    assert!(ptx().is_empty());
    // First load decodes and keeps one file; the second reads it back, the same image.
    let first = render("first.png", cache.to_str().unwrap());
    assert_eq!(from_cache(&first), 0);
    let files = ptx();
    assert_eq!(files.len(), 1, "{files:?}");
    let second = render("second.png", cache.to_str().unwrap());
    assert_eq!(from_cache(&second), 1, "{}", stderr(&second));
    let image = |p: &str| read_png(&dir.join(p)).3;
    let lit = image("off.png");
    let distinct: std::collections::HashSet<&[u8]> = lit.chunks(3).collect();
    assert!(
        distinct.len() > 100,
        "the textured quad fills the view: {} colours",
        distinct.len()
    );
    assert_eq!(image("first.png"), lit);
    assert_eq!(image("second.png"), image("first.png"));
    // A damaged file is not used: decoded again (and written anew), the same image.
    let bytes = std::fs::read(&files[0]).unwrap();
    std::fs::write(&files[0], &bytes[..bytes.len() / 2]).unwrap();
    let third = render("third.png", cache.to_str().unwrap());
    assert_eq!(from_cache(&third), 0);
    assert_eq!(image("third.png"), image("first.png"));
    assert_eq!(std::fs::read(&files[0]).unwrap(), bytes, "rewritten whole");
    // The environment variable names it too.
    let o = Command::new(env!("CARGO_BIN_EXE_phong"))
        .args([
            "render",
            out.to_str().unwrap(),
            "-o",
            dir.join("env.png").to_str().unwrap(),
            "-v",
        ])
        .env("PHONG_TEXTURE_CACHE", &cache)
        .output()
        .unwrap();
    assert_eq!(from_cache(&o), 1, "{}", stderr(&o));
}

/// `phong shader`: the GLSL targets write the pair and its uniforms (the JSON's values are the
/// scene's: the sphere's shininess, the light's direction); what a shader cannot express is
/// exit 2 naming what, and no file is written.
#[test]
fn shader_exports_glsl_and_refuses_what_it_cannot_express() {
    let stem = tmp("s");
    let s = stem.to_str().unwrap();
    let o = phong(&["shader", "examples/scenes/shininess.toml", "--target", "glsl", "-o", s]);
    assert!(o.status.success(), "{}", stderr(&o));
    let vert = std::fs::read_to_string(stem.with_extension("vert")).unwrap();
    let frag = std::fs::read_to_string(stem.with_extension("frag")).unwrap();
    assert!(
        vert.starts_with("#version 120\n") && vert.contains("attribute vec3 normal;"),
        "{vert}"
    );
    assert!(frag.contains("vec3 R = 2.0 * dot(L, N) * N - L;"), "{frag}");
    assert!(frag.contains("gl_FragColor") && !frag.contains("out vec4"), "{frag}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(stem.with_extension("json")).unwrap()).unwrap();
    let shininess: Vec<f64> = json["objects"]
        .as_array()
        .unwrap()
        .iter()
        .map(|o| o["uniforms"]["uShininess"].as_f64().unwrap())
        .collect();
    assert_eq!(shininess, [1.0, 10.0, 100.0, 1000.0]);
    // Directional: the direction to the light, -direction normalised.
    let l = &json["scene"]["uLightPosition"][0];
    let n = (1.0f64 + 1.0 + 2.25).sqrt();
    for (k, want) in [1.0 / n, 1.0 / n, 1.5 / n].into_iter().enumerate() {
        assert!((l[k].as_f64().unwrap() - want).abs() < 1e-6, "{l}");
    }
    let o = phong(&["shader", "examples/scenes/shininess.toml", "--target", "glsl330"]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("#version 330 core") && text.contains("out vec4 fragColor;"),
        "{text}"
    );
    for (scene, target, says) in [
        (
            "examples/scenes/textures.toml",
            "html",
            "has normal or bump maps: the shader export draws diffuse and specular maps only",
        ),
        ("examples/scenes/gouraud_vs_phong.toml", "glsl", "shaded differently"),
        (
            "examples/scenes/gouraud_vs_phong.toml",
            "glsl --object nothing",
            "--object nothing: no such object",
        ),
    ] {
        let page = tmp("p.out");
        let mut args = vec!["shader", scene, "--target"];
        args.extend(target.split(' '));
        args.extend(["-o", page.to_str().unwrap()]);
        let o = phong(&args);
        assert_eq!(o.status.code(), Some(2), "{scene} {target}");
        assert!(stderr(&o).contains(says), "{scene}: {}", stderr(&o));
        assert!(!page.exists() && !page.with_extension("vert").exists());
    }
    // An output that is a folder: exit 2, saying so.
    let folder = tempfile::tempdir().unwrap();
    let o = phong(&[
        "shader",
        "examples/scenes/shininess.toml",
        "--target",
        "html",
        "-o",
        folder.path().to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("is a folder"), "{}", stderr(&o));
    // A scene of objects shaded differently: the page draws each with its own program; the
    // GLSL pair is one object's (flat: lit at the triangle's centroid).
    let page = tmp("g.html");
    let o = phong(&[
        "shader",
        "examples/scenes/gouraud_vs_phong.toml",
        "--target",
        "html",
        "-o",
        page.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let html = std::fs::read_to_string(&*page).unwrap();
    assert!(
        html.contains("triangleCentroid") && html.contains("vFront"),
        "flat and Gouraud programs"
    );
    let o = phong(&[
        "shader",
        "examples/scenes/gouraud_vs_phong.toml",
        "--target",
        "glsl330",
        "--object",
        "1",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        String::from_utf8_lossy(&o.stdout).matches("#version 330 core").count(),
        2
    );
}
