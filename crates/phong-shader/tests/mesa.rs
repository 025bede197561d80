//! The GLSL 1.20 and 3.30 pairs on Mesa's OpenGL (OSMesa, llvmpipe): `tests/mesa/glsl.c`,
//! compiled here with `cc` (or `$PHONG_MESA_CC`), draws scenes over every model,
//! interpolation and option with the exported shaders and uniforms, beside `phong render` at
//! one sample: at most 0.5% of the pixels past 2/255. Without OSMesa (Debian's
//! libosmesa6-dev) the test is skipped, and with `PHONG_REQUIRE_MESA=1` (CI) that is a failure.

mod common;
use common::scenes;
use phong_core::{Interpolation, Scene};
use phong_shader::Version;
use serde_json::Value;
use std::fmt::Write as _;
use std::io::Write as _;
use std::path::PathBuf;
use std::process::{Command, Stdio};

fn reference() -> Option<PathBuf> {
    let src = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/mesa/glsl.c");
    let exe = std::env::temp_dir().join(format!("phong-glsl-{}", std::process::id()));
    let cc = std::env::var("PHONG_MESA_CC").unwrap_or_else(|_| "cc".into());
    let out = Command::new(&cc)
        .args(["-O2", "-o"])
        .arg(&exe)
        .arg(&src)
        .arg("-lOSMesa")
        .output();
    match out {
        Ok(o) if o.status.success() => Some(exe),
        other => {
            let why = match other {
                Ok(o) => String::from_utf8_lossy(&o.stderr)
                    .lines()
                    .next()
                    .unwrap_or("")
                    .to_string(),
                Err(e) => e.to_string(),
            };
            if std::env::var_os("PHONG_REQUIRE_MESA").is_some() {
                panic!("PHONG_REQUIRE_MESA is set but the OSMesa program does not build: {why}");
            }
            eprintln!("skipped: the OSMesa program does not build (install libosmesa6-dev): {why}");
            None
        }
    }
}

/// The uniforms of a program's JSON in `glsl.c`'s form.
fn uniforms(out: &mut String, values: &Value) {
    let map = values.as_object().expect("an object");
    let _ = writeln!(out, "{}", map.len());
    for (name, v) in map {
        let kind = match name.as_str() {
            "uClipFromWorld" => 'm',
            "uShininess" | "uKd" | "uKs" | "uSpotCosCutoff" | "uSpotExponent" => 'f',
            _ => 'v',
        };
        let mut flat = Vec::new();
        let mut walk = vec![v];
        while let Some(x) = walk.pop() {
            match x {
                Value::Array(a) => walk.extend(a.iter().rev()),
                Value::Number(n) => flat.push(n.as_f64().expect("a number")),
                _ => panic!("{name}: {x}"),
            }
        }
        let per = match kind {
            'm' => 16,
            'v' => 3,
            _ => 1,
        };
        let _ = write!(out, "{name} {kind} {}", flat.len() / per);
        for x in flat {
            let _ = write!(out, " {x:e}");
        }
        out.push('\n');
    }
}

fn input(scene: &Scene, version: Version) -> String {
    let p = phong_shader::program(scene, version).expect("the program");
    let enc = |c: f32| f64::from(scene.image.encoding.encode(c)) / 255.0;
    let bg = scene.image.background;
    let mut s = format!(
        "{} {}\n{} {} {}\n{}\n{}{}\n{}",
        scene.image.width,
        scene.image.height,
        enc(bg[0]),
        enc(bg[1]),
        enc(bg[2]),
        p.vertex.len(),
        p.vertex,
        p.fragment.len(),
        p.fragment
    );
    s.push('\n');
    uniforms(&mut s, &p.uniforms["scene"]);
    let _ = writeln!(s, "{}", scene.objects.len());
    for (i, o) in scene.objects.iter().enumerate() {
        uniforms(&mut s, &p.uniforms["objects"][i]["uniforms"]);
        let flat = o.shading.interpolation == Interpolation::Flat;
        let arrays = phong_shader::vertex_arrays(o);
        let (pos, nor, idx) = (arrays.positions, arrays.normals, arrays.indices);
        // Centroids for flat objects only (glsl.c reads them only there).
        let cen = arrays.centroids;
        let _ = writeln!(
            s,
            "{} {} {} {}",
            u8::from(!o.shading.options.two_sided),
            u8::from(flat),
            pos.len(),
            idx.len()
        );
        for list in [&pos, &nor, &cen] {
            for v in list.iter() {
                let _ = write!(s, "{:e} {:e} {:e} ", v.x, v.y, v.z);
            }
            s.push('\n');
        }
        for i in idx {
            let _ = write!(s, "{i} ");
        }
        s.push('\n');
    }
    s
}

#[test]
fn glsl_pairs_on_mesa_draw_phongs_pixels() {
    let Some(exe) = reference() else { return };
    for (shading, scene) in scenes() {
        let mut renderer = phong_raster::Renderer::new();
        let options = phong_raster::RenderOptions::default();
        let (picture, _) =
            phong_run::draw(&scene, phong_run::Backend::Cpu(&options), &mut renderer).expect("phong's render");
        let ours = picture.rgba8();
        for version in [Version::Legacy120, Version::Core330] {
            let mut child = Command::new(&exe)
                .stdin(Stdio::piped())
                .stdout(Stdio::piped())
                .stderr(Stdio::piped())
                .spawn()
                .expect("the OSMesa program runs");
            child
                .stdin
                .take()
                .expect("stdin")
                .write_all(input(&scene, version).as_bytes())
                .expect("written");
            let out = child.wait_with_output().expect("its output");
            assert!(
                out.status.success(),
                "{shading} {version:?}: {}",
                String::from_utf8_lossy(&out.stderr)
            );
            let (w, h) = (scene.image.width as usize, scene.image.height as usize);
            // OSMesa's rows are from the bottom.
            let mesa: Vec<u8> = (0..h)
                .rev()
                .flat_map(|y| out.stdout[y * w * 4..(y + 1) * w * 4].to_vec())
                .collect();
            let off = (0..w * h)
                .filter(|&i| (0..3).any(|c| mesa[i * 4 + c].abs_diff(ours[i * 4 + c]) > 2))
                .count();
            let drawn = (0..w * h).filter(|&i| mesa[i * 4..i * 4 + 3] != mesa[..3]).count();
            eprintln!("{shading:?} {version:?}: {off} pixels past 2/255, {drawn} drawn");
            assert!(drawn * 10 >= w * h, "{shading} {version:?}: only {drawn} pixels drawn");
            assert!(
                off * 200 <= w * h,
                "{shading} {version:?}: {off} of {} pixels past 2/255",
                w * h
            );
        }
    }
    let _ = std::fs::remove_file(exe);
}
