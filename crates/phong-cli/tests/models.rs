//! Models as a user renders them: `phong render MODEL -o out.png`, end to end.

use glam::Vec3;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn phong(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_phong"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run phong")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Decodes an 8-bit RGBA or RGB PNG: (width, height, channels, bytes).
fn read_png(p: &Path) -> (u32, u32, usize, Vec<u8>) {
    let dec = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(p).unwrap()));
    let mut r = dec.read_info().unwrap();
    let mut buf = vec![0; r.output_buffer_size().unwrap()];
    let info = r.next_frame(&mut buf).unwrap();
    buf.truncate(info.buffer_size());
    (info.width, info.height, info.color_type.samples(), buf)
}

/// `../shared/models/`, or `None` where this checkout has none (unless `PHONG_REQUIRE_MODELS`).
fn shared() -> Option<PathBuf> {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/models");
    if p.is_dir() {
        Some(p.canonicalize().unwrap())
    } else {
        assert!(
            std::env::var_os("PHONG_REQUIRE_MODELS").is_none(),
            "{} is missing",
            p.display()
        );
        eprintln!("skipped: {} is missing", p.display());
        None
    }
}

/// Whether (x, y) is inside the L of `concave_polygon_is_filled_pixel_by_pixel`: the square
/// [0, 2]² without the notch [1, 2]².
fn in_l(x: f64, y: f64) -> bool {
    (0.0..2.0).contains(&x) && (0.0..2.0).contains(&y) && !(x >= 1.0 && y >= 1.0)
}

/// An L-shaped hexagon written from its reflex corner (a fan from there fills the notch),
/// drawn emissive in an orthographic view, one sample per pixel: every pixel whose centre is
/// inside the L is the emission colour, every other is the background, with no exception.
#[test]
fn concave_polygon_is_filled_pixel_by_pixel() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(
        d.join("l.obj"),
        "v 1 1 0\nv 1 2 0\nv 0 2 0\nv 0 0 0\nv 2 0 0\nv 2 1 0\nf 1 2 3 4 5 6\n",
    )
    .unwrap();
    // 100 × 100 pixels over [-0.25, 2.25]² (0.025 per pixel): pixel centres fall a quarter of
    // a pixel from every edge, so no centre is on an edge.
    std::fs::write(
        d.join("l.toml"),
        "[image]\nwidth = 100\nheight = 100\nbackground = [0, 0, 0]\n\
         [camera]\nprojection = \"orthographic\"\nheight = 2.5\nposition = [1.0, 1.0, 5]\ntarget = [1.0, 1.0, 0]\n\
         [[object]]\nmesh = \"l.obj\"\nmaterial = { ambient = [0, 0, 0], diffuse = [0, 0, 0], specular = [0, 0, 0], emission = [1, 0.5, 0.25] }\n",
    )
    .unwrap();
    let o = phong(d, &["render", "l.toml", "-o", "l.png"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (w, h, ch, px) = read_png(&d.join("l.png"));
    let mut inside = 0;
    for j in 0..h {
        for i in 0..w {
            let x = -0.25 + (f64::from(i) + 0.5) * 0.025;
            let y = 2.25 - (f64::from(j) + 0.5) * 0.025;
            let p = &px[(j * w + i) as usize * ch..][..3];
            if in_l(x, y) {
                inside += 1;
                assert_eq!(p, [255, 128, 64], "pixel ({i}, {j}) at ({x}, {y}) is inside the L");
            } else {
                assert_eq!(p, [0, 0, 0], "pixel ({i}, {j}) at ({x}, {y}) is outside the L");
            }
        }
    }
    assert_eq!(inside, 3 * 40 * 40);
}

/// One model at the origin, 10⁻⁶ of its size, 10³⁰ times its size, and at 10⁸ from the origin
/// with its detail kept: `phong render MODEL` draws the same image for each (to within a few
/// edge pixels), where the far one was blocky, the tiny one a dot and the huge one an error.
#[test]
fn far_huge_and_tiny_models_are_framed_alike() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // A closed, irregular 12-triangle model: a box with one corner pulled out.
    let box_ = |k: f64, o: f64| {
        let mut v = Vec::new();
        for i in 0..8u32 {
            let mut p = [f64::from(i & 1), f64::from((i >> 1) & 1), f64::from((i >> 2) & 1)];
            if i == 7 {
                p = [1.6, 1.3, 1.9];
            }
            v.push(format!("v {} {} {}", p[0] * k + o, p[1] * k + o, p[2] * k + o));
        }
        v.join("\n") + "\nf 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n"
    };
    let mut images = Vec::new();
    for (name, k, o) in [
        ("unit", 1.0, 0.0),
        ("tiny", 1e-6, 0.0),
        ("huge", 1e30, 0.0),
        ("far", 1.0, 1e8),
    ] {
        std::fs::write(d.join(format!("{name}.obj")), box_(k, o)).unwrap();
        let out = format!("{name}.png");
        let o = phong(
            d,
            &["render", &format!("{name}.obj"), "-o", &out, "--antialias", "1", "-v"],
        );
        assert!(o.status.success(), "{name}: {}", stderr(&o));
        assert!(stderr(&o).contains("back faces culled"), "{name}: {}", stderr(&o));
        images.push((name, read_png(&d.join(out)).3));
    }
    let (_, unit) = &images[0];
    let bg = unit[..3].to_vec();
    let covered = unit.chunks(3).filter(|p| *p != &bg[..]).count();
    assert!(covered > 800 * 600 / 5, "the model fills the frame: {covered} pixels");
    for (name, img) in &images[1..] {
        let differ = unit
            .chunks(3)
            .zip(img.chunks(3))
            .filter(|(a, b)| a.iter().zip(b.iter()).any(|(x, y)| x.abs_diff(*y) > 2))
            .count();
        assert!(
            differ < 200,
            "{name}: {differ} pixels differ from the unit model's image"
        );
    }
    // Coordinates near f32's largest (3.4e38): framed too.
    std::fs::write(
        d.join("max.obj"),
        "v 3e38 3e38 3e38\nv -3e38 3e38 3e38\nv 3e38 -3e38 -3e38\nf 1 2 3\n",
    )
    .unwrap();
    let o = phong(d, &["render", "max.obj", "-o", "max.png", "--antialias", "1"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let px = read_png(&d.join("max.png")).3;
    let drawn = px.chunks(3).filter(|p| *p != &px[..3]).count();
    assert!(drawn > 800 * 600 / 10, "{drawn} pixels drawn");
}

/// The Cornell box (open at its front, single-sided walls): every triangle is drawn
/// (two-sided, seen from the open side), and the red and green side walls and the white
/// walls all show.
#[test]
fn cornell_box_walls_are_all_drawn() {
    let Some(shared) = shared() else { return };
    let dir = tempfile::tempdir().unwrap();
    let model = shared.join("tinyobjloader/models/cornell_box.obj");
    let o = phong(dir.path(), &["render", model.to_str().unwrap(), "-o", "cb.png", "-v"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(
        err.contains("cornell_box.obj: 36 triangles read: 36 drawn, 0 clipped then drawn, 0 culled"),
        "{err}"
    );
    let (_, _, ch, px) = read_png(&dir.path().join("cb.png"));
    let count = |f: &dyn Fn(&[u8]) -> bool| px.chunks(ch).filter(|p| f(p)).count();
    let red = count(&|p| p[0] > 30 && u16::from(p[0]) > 3 * u16::from(p[1].max(p[2])));
    let green = count(&|p| p[1] > 30 && u16::from(p[1]) > 3 * u16::from(p[0].max(p[2])));
    let white = count(&|p| p[0] > 120 && p[0].abs_diff(p[1]) < 8 && p[1].abs_diff(p[2]) < 8);
    assert!(
        red > 5000 && green > 5000 && white > 20000,
        "red {red}, green {green}, white {white}"
    );
}

/// The view flags: `--view`, `--up`, `--camera`, `--two-sided`, `--cull` change the image and
/// say so under `-v`; bad values and a scene file are refused, naming the flag.
#[test]
fn view_flags() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(
        d.join("t.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 2\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n",
    )
    .unwrap();
    let render = |out: &str, extra: &[&str]| {
        let mut args = vec!["render", "t.obj", "-o", out, "-v", "--width", "200", "--height", "150"];
        args.extend_from_slice(extra);
        let o = phong(d, &args);
        assert!(o.status.success(), "{extra:?}: {}", stderr(&o));
        (stderr(&o), read_png(&d.join(out)).3)
    };
    let (_, base) = render("a.png", &[]);
    for (i, extra) in [
        &["--view", "top"][..],
        &["--view", "back"],
        &["--up", "x"],
        &["--camera", "3,3,3,0,0,0"],
    ]
    .iter()
    .enumerate()
    {
        let (_, img) = render(&format!("v{i}.png"), extra);
        assert!(img != base, "{extra:?} changes the image");
    }
    // The closed model is culled by default; `--two-sided` draws its back faces (hidden here,
    // so only the note says it) and `--cull` keeps the default.
    let (err, _) = render("t.png", &[]);
    assert!(err.contains("back faces culled"), "{err}");
    let (err, _) = render("t2.png", &["--two-sided"]);
    assert!(!err.contains("back faces culled") && err.contains("0 culled"), "{err}");
    let (err, _) = render("c.png", &["--cull"]);
    assert!(!err.contains("two-sided") && !err.contains(" 0 culled"), "{err}");
    for (args, want) in [
        (&["render", "t.obj", "-o", "x.png", "--up", "w"][..], "--up"),
        (&["render", "t.obj", "-o", "x.png", "--view", "side"], "--view"),
        (&["render", "t.obj", "-o", "x.png", "--camera", "1,2,3"], "--camera"),
        (
            &["render", "t.obj", "-o", "x.png", "--camera", "1,1,1,1,1,1"],
            "--camera",
        ),
        (&["render", "t.obj", "-o", "x.png", "--two-sided", "--cull"], "--cull"),
    ] {
        let o = phong(d, args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(want), "{args:?}: {}", stderr(&o));
        assert!(!d.join("x.png").exists());
    }
    std::fs::write(d.join("s.toml"), "[[object]]\nshape = \"sphere\"\n").unwrap();
    let o = phong(d, &["render", "s.toml", "-o", "x.png", "--view", "top"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("apply to a model alone"), "{}", stderr(&o));
}

/// Every model of `../shared/models/` renders (exit 0, something drawn), or, for the truly
/// broken ones, exits 2 naming the file and the fault.
#[test]
fn every_shared_model_renders_or_says_why() {
    let Some(shared) = shared() else { return };
    let dir = tempfile::tempdir().unwrap();
    let broken = [
        ("invalid-relative-texture-index.obj", "out of range"),
        ("invalid-relative-vertex-index.obj", "out of range"),
        ("issue-140-zero-face-idx.obj", "vertex index 0 is out of range"),
        ("test-nan.obj", "not a finite number"),
        ("invalid-face-definition.obj", "fewer than 3 vertices"),
        ("issue-356-leading-spaces-newmtl.obj", "no faces"),
        ("line-prim.obj", "line (`l`)"),
        ("points-prim.obj", "point (`p`)"),
    ];
    let mut stack = vec![shared];
    let mut n = 0;
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
                continue;
            }
            let ext = p.extension().map(|e| e.to_string_lossy().to_ascii_lowercase());
            if !matches!(ext.as_deref(), Some("obj" | "gltf" | "glb" | "ply" | "stl")) {
                continue;
            }
            n += 1;
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            let out = dir.path().join(format!("{n}.png"));
            let o = phong(
                dir.path(),
                &[
                    "render",
                    p.to_str().unwrap(),
                    "-o",
                    out.to_str().unwrap(),
                    "--width",
                    "160",
                    "--height",
                    "120",
                ],
            );
            match broken.iter().find(|(b, _)| *b == name) {
                Some((_, why)) => {
                    assert_eq!(o.status.code(), Some(2), "{name}: {}", stderr(&o));
                    assert!(
                        stderr(&o).contains(&name) && stderr(&o).contains(why),
                        "{name}: {}",
                        stderr(&o)
                    );
                }
                None => {
                    assert!(o.status.success(), "{name}: {}", stderr(&o));
                    let (_, _, ch, px) = read_png(&out);
                    let bg = px[..3].to_vec();
                    let drawn = px.chunks(ch).filter(|p| p[..3] != bg[..]).count();
                    assert!(drawn > 50, "{name}: {drawn} pixels drawn");
                }
            }
        }
    }
    assert!(n >= 70, "{n} models");
}

/// A few real models as `phong render MODEL` draws them by default (240×180), against
/// `tests/golden/models/*.png`, within 1/255 (the AVX2 kernels' estimates differ between CPU
/// makers; see phong-raster's golden test). `PHONG_BLESS=1` rewrites them.
#[test]
fn shared_models_match_their_golden_images() {
    let Some(shared) = shared() else { return };
    let golden = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden/models");
    let bless = std::env::var_os("PHONG_BLESS").is_some();
    let dir = tempfile::tempdir().unwrap();
    for (model, name) in [
        ("spot/spot_quadrangulated.obj", "spot"),
        ("common-3d/nefertiti.obj", "nefertiti"),
        ("tinyobjloader/models/cornell_box.obj", "cornell_box"),
        ("assimp/OBJ/concave_polygon.obj", "concave_polygon"),
        ("assimp/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb", "engine"),
        // Textured: an OBJ whose MTL names JPEG maps, a glTF with an external PNG, and
        // KHR_texture_transform's test (each arrow should point at a green check).
        ("assimp/OBJ/spider.obj", "spider"),
        ("assimp/glTF2/BoxTextured-glTF/BoxTextured.gltf", "box_textured"),
        (
            "assimp/glTF2/textureTransform/TextureTransformTest.gltf",
            "texture_transform",
        ),
        // Spot with its texture, by a scene (the OBJ has no MTL): written below.
        ("spot_textured.toml", "spot_textured"),
    ] {
        let model = if model.ends_with(".toml") {
            let scene = dir.path().join(model);
            let spot = shared.join("spot");
            std::fs::write(
                &scene,
                format!(
                    "[camera]\nposition = [0.0, 0.4, 2.6]\nfov = 45.0\n\
                     [[object]]\nmesh = {:?}\nfit = true\nrotation = [0.0, 150.0, 0.0]\n\
                     material = {{ diffuse = [1.0, 1.0, 1.0], ambient = [1.0, 1.0, 1.0], diffuse_map = {:?} }}\n",
                    spot.join("spot_triangulated.obj"),
                    spot.join("spot_texture.png")
                ),
            )
            .unwrap();
            scene.to_string_lossy().into_owned()
        } else {
            shared.join(model).to_string_lossy().into_owned()
        };
        let out = dir.path().join(format!("{name}.png"));
        let o = phong(
            dir.path(),
            &[
                "render",
                &model,
                "-o",
                out.to_str().unwrap(),
                "--width",
                "240",
                "--height",
                "180",
            ],
        );
        assert!(o.status.success(), "{name}: {}", stderr(&o));
        assert!(!stderr(&o).contains("not used"), "{name}: {}", stderr(&o));
        let want = golden.join(format!("{name}.png"));
        if bless {
            std::fs::create_dir_all(&golden).unwrap();
            std::fs::copy(&out, &want).unwrap();
        }
        let (got, want) = (read_png(&out), read_png(&want));
        assert_eq!((got.0, got.1, got.2), (want.0, want.1, want.2), "{name}");
        let worst = got
            .3
            .iter()
            .zip(&want.3)
            .map(|(a, b)| a.abs_diff(*b))
            .max()
            .unwrap_or(0);
        assert!(worst <= 1, "{name}: differs from its golden image by up to {worst}/255");
    }
}

/// Writes a `w × h` RGB PNG of one colour.
fn write_png(path: &Path, (w, h): (u32, u32), rgb: [u8; 3]) {
    let f = std::fs::File::create(path).unwrap();
    let mut e = png::Encoder::new(std::io::BufWriter::new(f), w, h);
    e.set_color(png::ColorType::Rgb);
    e.set_depth(png::BitDepth::Eight);
    let data: Vec<u8> = (0..w * h).flat_map(|_| rgb).collect();
    e.write_header().unwrap().write_image_data(&data).unwrap();
}

/// Texture maps that cannot be used are warnings naming the material, the file and why, and
/// the material renders without them; a bad sampler key is an error at its line; MTL options
/// that are not used are warnings at their line; a red map makes a white material red.
#[test]
fn texture_problems_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_png(&d.join("red.png"), (4, 4), [255, 0, 0]);
    std::fs::write(d.join("bad.png"), "not an image").unwrap();
    let scene = |material: &str| {
        format!(
            "[image]\nwidth = 40\nheight = 30\n[camera]\nposition = [0.0, 0.0, 3.0]\n\
             [[object]]\nshape = \"plane\"\nrotation = [90.0, 0.0, 0.0]\nmaterial = \"m\"\n\
             [materials.m]\ndiffuse = [1.0, 1.0, 1.0]\nambient = [1.0, 1.0, 1.0]\n{material}\n"
        )
    };
    let render = |name: &str, text: &str| {
        std::fs::write(d.join(name), text).unwrap();
        let o = phong(d, &["render", name, "-o", "out.png"]);
        let centre = read_png(&d.join("out.png"));
        (o, centre)
    };
    for (file, why) in [("missing.png", "cannot read"), ("bad.png", "texture bad.png not used")] {
        let (o, _) = render("s.toml", &scene(&format!("diffuse_map = \"{file}\"")));
        assert!(o.status.success(), "{}", stderr(&o));
        let e = stderr(&o);
        assert!(e.contains("material m") && e.contains(file) && e.contains(why), "{e}");
    }
    let (o, (w, h, ch, px)) = render("s.toml", &scene("diffuse_map = \"red.png\""));
    assert!(o.status.success() && stderr(&o).is_empty(), "{}", stderr(&o));
    let c = &px[((h / 2 * w + w / 2) as usize) * ch..][..3];
    assert!(c[0] > 100 && c[1] == 0 && c[2] == 0, "{c:?}");
    std::fs::write(d.join("s.toml"), scene("diffuse_map = \"red.png\"\nwrap = \"spiral\"")).unwrap();
    let o = phong(d, &["render", "s.toml", "-o", "out.png"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("s.toml:14:8: `wrap`: unknown wrap"),
        "{}",
        stderr(&o)
    );
    // An OBJ whose MTL gives options phong does not use, and a map on a model without
    // texture coordinates.
    std::fs::write(
        d.join("q.mtl"),
        "newmtl red\nKd 1 1 1\nmap_Kd -bm 0.5 -zz red.png\nmap_Ks -s 2 2 missing.png\n",
    )
    .unwrap();
    std::fs::write(
        d.join("q.obj"),
        "mtllib q.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl red\nf 1/1 2/2 3/3 4/4\n",
    )
    .unwrap();
    let o = phong(
        d,
        &["render", "q.obj", "-o", "q.png", "--width", "40", "--height", "30"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(e.contains("q.mtl:3: map_Kd option -bm"), "{e}");
    assert!(e.contains("q.mtl:3: map_Kd option -zz (unknown option)"), "{e}");
    assert!(
        e.contains("q.mtl:4: material red: texture") && e.contains("missing.png"),
        "{e}"
    );
    let (w, h, ch, px) = read_png(&d.join("q.png"));
    let c = &px[((h / 2 * w + w / 2) as usize) * ch..][..3];
    assert!(c[0] > 50 && c[1] == 0 && c[2] == 0, "the map applies: {c:?}");
    std::fs::write(
        d.join("n.obj"),
        "mtllib q.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nusemtl red\nf 1 2 3\n",
    )
    .unwrap();
    let o = phong(
        d,
        &["render", "n.obj", "-o", "n.png", "--width", "40", "--height", "30"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("no texture coordinates"), "{}", stderr(&o));
}

/// Bump maps end to end: a height ramp rising 40/255 a texel along `+u`, times 2 (a scene's
/// `bump_scale`, an MTL's `-bm`), tilts a quad facing the camera to
/// `N' = normalize(−2·40/255, 0, 1)` in its tangent frame (`+x`, `+y`). Lit along `N'`, a
/// white diffuse material is white (`N'·L = 1`); lit along the flat normal it is
/// `255·N'·z = 243.5`. A material with both a normal map and a bump map keeps the normal map
/// and says so.
#[test]
fn bump_maps_tilt_the_normal_by_their_slope() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (w, h) = (7u32, 3u32);
    let f = std::fs::File::create(d.join("h.png")).unwrap();
    let mut e = png::Encoder::new(std::io::BufWriter::new(f), w, h);
    e.set_color(png::ColorType::Grayscale);
    e.set_depth(png::BitDepth::Eight);
    let ramp: Vec<u8> = (0..h).flat_map(|_| (0..w).map(|x| (40 * x) as u8)).collect();
    e.write_header().unwrap().write_image_data(&ramp).unwrap();
    let tilted = Vec3::new(-2.0 * 40.0 / 255.0, 0.0, 1.0).normalize();
    let centre = |png: &str| {
        let (w, h, ch, px) = read_png(&d.join(png));
        px[((h / 2 * w + w / 2) as usize) * ch] as f32
    };
    let scene = |light: Vec3, material: &str| {
        format!(
            "[image]\nwidth = 41\nheight = 31\n[camera]\nposition = [0.0, 0.0, 3.0]\n\
             [shading]\nambient = [0.0, 0.0, 0.0]\n\
             [[light]]\ntype = \"directional\"\ndirection = [{}, {}, {}]\n\
             [[object]]\nshape = \"plane\"\nrotation = [90.0, 0.0, 0.0]\nmaterial = \"m\"\n\
             [materials.m]\ndiffuse = [1.0, 1.0, 1.0]\nambient = [0.0, 0.0, 0.0]\nwrap = \"clamp\"\n{material}\n",
            -light.x, -light.y, -light.z
        )
    };
    for (light, want) in [(tilted, 255.0), (Vec3::Z, 255.0 * tilted.z)] {
        std::fs::write(d.join("s.toml"), scene(light, "bump_map = \"h.png\"\nbump_scale = 2.0")).unwrap();
        let o = phong(d, &["render", "s.toml", "-o", "s.png"]);
        assert!(o.status.success() && stderr(&o).is_empty(), "{}", stderr(&o));
        let got = centre("s.png");
        assert!((got - want).abs() <= 1.0, "scene, light {light}: {got} vs {want}");
    }
    std::fs::write(
        d.join("q.mtl"),
        "newmtl m\nKd 1 1 1\nKa 0 0 0\nbump -bm 2 -clamp on h.png\n",
    )
    .unwrap();
    std::fs::write(
        d.join("q.obj"),
        "mtllib q.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl m\nf 1/1 2/2 3/3 4/4\n",
    )
    .unwrap();
    std::fs::write(
        d.join("o.toml"),
        format!(
            "[image]\nwidth = 41\nheight = 31\n[camera]\nposition = [0.0, 0.0, 3.0]\n\
             [shading]\nambient = [0.0, 0.0, 0.0]\n\
             [[light]]\ntype = \"directional\"\ndirection = [{}, {}, {}]\n\
             [[object]]\nmesh = \"q.obj\"\n",
            -tilted.x, -tilted.y, -tilted.z
        ),
    )
    .unwrap();
    let o = phong(d, &["render", "o.toml", "-o", "o.png"]);
    assert!(o.status.success() && stderr(&o).is_empty(), "{}", stderr(&o));
    let got = centre("o.png");
    assert!((got - 255.0).abs() <= 1.0, "MTL bump -bm 2: {got}");
    std::fs::write(
        d.join("s.toml"),
        scene(tilted, "bump_map = \"h.png\"\nnormal_map = \"h.png\""),
    )
    .unwrap();
    let o = phong(d, &["render", "s.toml", "-o", "s.png"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("bump map h.png is not used (the material has a normal map)"),
        "{}",
        stderr(&o)
    );
}
