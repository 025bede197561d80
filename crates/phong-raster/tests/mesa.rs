//! phong's `opengl` model against Mesa's OpenGL fixed-function lighting (OSMesa, llvmpipe):
//! the same scene (matrices, lights, material, mesh) rendered by both with Gouraud shading,
//! compared pixel by pixel. The reference is `tests/mesa/ffp.c`, compiled here with `cc` (or
//! `$PHONG_MESA_CC`);
//! without OSMesa (Debian's libosmesa6-dev) the test reports that it was skipped, and with
//! `PHONG_REQUIRE_MESA=1` (CI) that is a failure.

mod common;
use common::Rng;

use glam::{Mat4, Vec3};
use phong_core::*;
use phong_raster::{RenderOptions, render};
use std::fmt::Write as _;
use std::io::Write as _;
use std::path::PathBuf;
use std::process::{Command, Stdio};

fn reference() -> Option<PathBuf> {
    let src = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/mesa/ffp.c");
    // One executable per test: tests run in parallel, and a file being written cannot be run.
    static BUILDS: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);
    let k = BUILDS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let exe = std::env::temp_dir().join(format!("phong-ffp-{}-{k}", std::process::id()));
    let cc = std::env::var("PHONG_MESA_CC").unwrap_or_else(|_| "cc".into());
    let out = Command::new(&cc)
        .args(["-O2", "-o"])
        .arg(&exe)
        .arg(&src)
        .args(["-lOSMesa"])
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
                panic!("PHONG_REQUIRE_MESA is set but the OSMesa reference does not build: {why}");
            }
            eprintln!("skipped: the OSMesa reference does not build (install libosmesa6-dev): {why}");
            None
        }
    }
}

fn push(s: &mut String, v: &[f32]) {
    for x in v {
        write!(s, "{x:e} ").unwrap();
    }
    s.push('\n');
}

/// Renders `scene` (one object, the OpenGL model) with Mesa: Gouraud by the fixed function,
/// Phong interpolation by `ffp.c`'s GLSL program (the same equation per fragment).
fn mesa(exe: &PathBuf, scene: &Scene) -> Vec<u8> {
    let (w, h) = (scene.image.width, scene.image.height);
    let o = &scene.objects[0];
    let mut s = String::new();
    let local = u8::from(o.shading.viewer == Viewer::Local);
    let per_fragment = u8::from(o.shading.interpolation == Interpolation::Phong);
    writeln!(
        s,
        "{w} {h} {local} {} {per_fragment}",
        u8::from(o.shading.options.two_sided)
    )
    .unwrap();
    push(
        &mut s,
        &scene.camera.clip_from_view(w as f32 / h as f32).to_cols_array(),
    );
    push(&mut s, &scene.camera.view_from_world().to_cols_array());
    push(&mut s, &scene.lighting.ambient().to_array());
    let m = &o.material;
    for c in [m.ambient(), m.diffuse(), m.specular(), m.emission()] {
        push(&mut s, &c.to_array());
    }
    push(&mut s, &[m.shininess()]);
    writeln!(s, "{}", scene.lighting.lights().len()).unwrap();
    for l in scene.lighting.lights() {
        let pos = match l.position() {
            Some(p) => [p.x, p.y, p.z, 1.0],
            None => {
                let d = l.to_light().unwrap();
                [d.x, d.y, d.z, 0.0]
            }
        };
        push(&mut s, &pos);
        let c = l.color();
        for k in [c.ambient(), c.diffuse(), c.specular()] {
            push(&mut s, &k.to_array());
        }
        push(&mut s, &l.attenuation().map_or([1.0, 0.0, 0.0], |a| a.coefficients()));
        let (dir, cutoff, _, exponent) = l.spot_cone().unwrap_or((Vec3::new(0.0, 0.0, -1.0), 180.0, -1.0, 0.0));
        push(&mut s, &[dir.x, dir.y, dir.z, cutoff, exponent]);
    }
    let mesh = &o.mesh;
    writeln!(s, "{}", mesh.positions().len()).unwrap();
    for (i, (p, n)) in mesh.positions().iter().zip(mesh.normals()).enumerate() {
        let uv = mesh.uvs().get(i).copied().unwrap_or_default();
        push(&mut s, &[p.x, p.y, p.z, n.x, n.y, n.z, uv.x, uv.y]);
    }
    writeln!(s, "{}", mesh.triangles().len()).unwrap();
    for t in mesh.triangles() {
        writeln!(s, "{} {} {}", t[0], t[1], t[2]).unwrap();
    }
    match &o.maps.diffuse {
        None => writeln!(s, "0 0").unwrap(),
        Some(map) => {
            let (tw, th, texels) = map.texture.level8(0).expect("an 8-bit texture");
            writeln!(s, "{tw} {th}").unwrap();
            for t in texels {
                writeln!(s, "{} {} {} {}", t[0], t[1], t[2], t[3]).unwrap();
            }
            let wrap = match map.sampler.wrap_u {
                Wrap::Repeat => 0,
                Wrap::Clamp => 1,
                Wrap::Mirror => 2,
            };
            let filter = match (map.sampler.min, map.sampler.mip) {
                (_, MipFilter::Linear) => 0,
                (Filter::Linear, _) => 1,
                _ => 2,
            };
            writeln!(s, "{wrap} {filter}").unwrap();
        }
    }
    let mut child = Command::new(exe)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    child.stdin.take().unwrap().write_all(s.as_bytes()).unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success());
    assert_eq!(out.stdout.len(), (w * h * 3) as usize);
    out.stdout
}

/// Per pixel, the largest channel difference between phong's image of `scene` and Mesa's.
fn differences(exe: &PathBuf, scene: &Scene) -> Vec<u8> {
    let ours = render(scene, &RenderOptions::default())
        .unwrap()
        .to_bytes(Encoding::Linear, false);
    let theirs = mesa(exe, scene);
    ours.chunks(3)
        .zip(theirs.chunks(3))
        .map(|(a, b)| a.iter().zip(b).map(|(x, y)| x.abs_diff(*y)).max().unwrap_or(0))
        .collect()
}

fn scene_with(
    mesh: Mesh,
    m: Material,
    lights: Vec<Light>,
    ambient: Color,
    eye: Vec3,
    viewer: Viewer,
    two_sided: bool,
) -> Scene {
    let camera = Camera::new(
        eye,
        Vec3::ZERO,
        Vec3::Y,
        Projection::Perspective { fov_y_deg: 40.0 },
        0.5,
        20.0,
    )
    .unwrap();
    let shading = ShadingSettings {
        options: ShadingOptions::opengl(two_sided),
        interpolation: Interpolation::Gouraud,
        viewer,
        output: Output::Color,
    };
    Scene {
        image: ImageSettings {
            width: 160,
            height: 120,
            background: [0.0, 0.0, 0.0, 1.0],
            samples: phong_core::Samples::One,
            encoding: Encoding::Linear,
        },
        camera,
        lighting: Lighting::new(ambient, lights).unwrap(),
        objects: vec![Object {
            name: "test".into(),
            mesh,
            material: m,
            shading,
            maps: Default::default(),
        }],
        labels: Vec::new(),
    }
}

/// Sphere plus floor as one mesh.
fn geometry() -> Mesh {
    let mut m = primitives::sphere(48).transformed(&Mat4::from_translation(Vec3::new(0.0, 0.3, 0.0)));
    m.append(
        &primitives::plane(24).transformed(&Mat4::from_scale_rotation_translation(
            Vec3::splat(2.5),
            glam::Quat::IDENTITY,
            Vec3::new(0.0, -0.8, 0.0),
        )),
    );
    m
}

/// Random scenes of every light type and option the OpenGL model has: directional, point and
/// spot lights with attenuation, per-light ambient, emission, global ambient, local and
/// infinite viewer, shininess from 1 to 128, two-sided lighting seen from below the floor; and
/// shininess 0 under unattenuated lights (case 12). Measured on Mesa 22.3 (llvmpipe): every
/// pixel of every case within 1/255 of Mesa's. Asserted: 99.5% of pixels within 1/255 (edges
/// may rasterise differently), all within 8/255.
///
/// Shininess 0 under an attenuated or spot light is left out on purpose: there Mesa's
/// fixed-function program overwrites the shininess with N·L before its LIT instruction
/// (`ffvertex_prog.c`, `material_shininess_is_zero`), giving a specular factor of
/// `(N·L)^(N·L)`, between 0.69 and 1, where OpenGL 2.1's equation gives `(N·H)^0 = 1`. phong
/// follows the specification; the difference reaches 20/255 with a specular term of 0.25.
#[test]
fn opengl_model_matches_mesa_fixed_function() {
    lighting_cases(Interpolation::Gouraud, 0.005, 8);
}

/// The cases of `opengl_model_matches_mesa_fixed_function` shaded per pixel, against the same
/// equation per fragment in GLSL on llvmpipe (`ffp.c`'s program). Measured on Mesa 22.3: every
/// pixel of every case within 1/255 but one (case 2, 25/255), where a spot light's cone
/// boundary passes within rounding of the pixel's centre: with the cone 0.5° wider, both give
/// the same bytes. Asserted: at most 0.03% of pixels (5) beyond 1/255 a case; a pixel on a cone's
/// hard edge may differ by that light's whole contribution, so the largest is not bounded.
#[test]
fn opengl_model_per_pixel_matches_mesa_glsl() {
    lighting_cases(Interpolation::Phong, 0.0003, 255);
}

/// Random lighting cases rendered by phong and Mesa with `interpolation`; at most `share` of
/// the pixels beyond 1/255 and none beyond `largest`.
fn lighting_cases(interpolation: Interpolation, share: f64, largest: u8) {
    let Some(exe) = reference() else { return };
    let mut r = Rng(42);
    let mut worst_frac = 0.0f64;
    for case in 0..13 {
        let mut lights = Vec::new();
        if case == 12 {
            let col = LightColor::new(Color::splat(0.1), Color::splat(0.6), Color::splat(0.4)).unwrap();
            lights.push(Light::directional(Vec3::new(-1.0, -2.0, -1.5), col).unwrap());
            lights.push(Light::point(Vec3::new(2.0, 2.0, 2.0), col, Attenuation::NONE).unwrap());
        }
        for _ in 0..(if case == 12 { 0 } else { 1 + case % 4 }) {
            let col = LightColor::new(r.c() * 0.3, r.c(), r.c()).unwrap();
            let att = Attenuation::new(r.r(0.5, 1.5), r.r(0.0, 0.3), r.r(0.0, 0.1)).unwrap();
            let pos = Vec3::new(r.r(-3.0, 3.0), r.r(1.0, 4.0), r.r(-1.0, 4.0));
            lights.push(match (case + lights.len()) % 3 {
                0 => Light::directional(-pos, col).unwrap(),
                1 => Light::point(pos, col, att).unwrap(),
                _ => Light::spot(
                    pos,
                    -pos + Vec3::new(r.r(-0.5, 0.5), 0.0, r.r(-0.5, 0.5)),
                    r.r(15.0, 60.0),
                    r.r(0.0, 30.0),
                    col,
                    att,
                )
                .unwrap(),
            });
        }
        let shininess = if case == 12 {
            0.0
        } else {
            [1.0, 12.8, 51.2, 100.0, 128.0][case % 5]
        };
        let m = Material::new(r.c(), r.c(), r.c(), r.c() * 0.2, shininess).unwrap();
        let two_sided = case % 4 == 3;
        let eye = if two_sided {
            Vec3::new(0.5, -3.5, 3.0) // below the floor: its back face is in view
        } else {
            Vec3::new(r.r(-2.0, 2.0), r.r(1.0, 3.0), 4.0)
        };
        if two_sided {
            // Light the floor's underside too.
            lights.push(Light::point(Vec3::new(0.0, -2.5, 1.0), LightColor::default(), Attenuation::NONE).unwrap());
        }
        let viewer = if case % 2 == 0 { Viewer::Local } else { Viewer::Infinite };
        let mut scene = scene_with(geometry(), m, lights, r.c() * 0.3, eye, viewer, two_sided);
        scene.objects[0].shading.interpolation = interpolation;
        let diffs = differences(&exe, &scene);
        let n = diffs.len();
        let max = diffs.iter().copied().max().unwrap_or(0);
        let off = diffs.iter().filter(|&&d| d > 1).count();
        let frac = off as f64 / n as f64;
        worst_frac = worst_frac.max(frac);
        eprintln!("{interpolation:?} case {case}: {off} of {n} pixels differ by more than 1/255 (largest {max}/255)");
        assert!(frac < share, "case {case}: {off} pixels differ");
        assert!(max <= largest, "case {case}: a pixel differs by {max}/255");
    }
    eprintln!("worst case: {:.3}% of pixels beyond 1/255", worst_frac * 100.0);
    let _ = std::fs::remove_file(&exe);
}

/// A random 8-bit RGBA texture (alpha 255), smooth at `cell` texels a random value (so that
/// magnification differences stay about sampling, not about noise).
fn texture(r: &mut Rng, w: u32, h: u32, cell: u32) -> std::sync::Arc<Texture> {
    let cw = w.div_ceil(cell) as usize + 1;
    let ch = h.div_ceil(cell) as usize + 1;
    let grid: Vec<[f32; 3]> = (0..cw * ch)
        .map(|_| [r.r(0.0, 1.0), r.r(0.0, 1.0), r.r(0.0, 1.0)])
        .collect();
    let texels: Vec<[u16; 4]> = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| {
            let (gx, gy) = ((x / cell) as usize, (y / cell) as usize);
            let c = grid[gy * cw + gx];
            let [r, g, b] = c.map(|v| (v * 255.0).round() as u16 * 257);
            [r, g, b, 65535]
        })
        .collect();
    std::sync::Arc::new(Texture::new(w, h, &texels, 8).unwrap())
}

/// Textured scenes against Mesa's fixed function with `GL_MODULATE`,
/// `GL_SEPARATE_SPECULAR_COLOR` and the driver's mipmaps (`glGenerateMipmap`): the sphere and
/// floor of the lighting test with a diffuse map, magnified (a 16×8 texture on the sphere),
/// minified (the floor's coordinates repeated 12 times over a 128×128 texture, seen at a
/// grazing angle), under each filter (trilinear, bilinear, nearest) and wrap mode; Gouraud
/// against the fixed function, per-pixel shading against `ffp.c`'s GLSL program (the texel
/// from `texture2D`, applied as `GL_MODULATE` with the separate specular colour).
///
/// Where the level of detail agrees (magnification; the filters without mipmaps), Mesa's
/// pixels and ours differ by the rounding of their texture coordinates: bilinear is within
/// 1/255 everywhere. Minified with mipmaps, llvmpipe takes the level of detail from
/// differences over 2×2 pixel quads (and an approximate `log2`), where phong takes the exact
/// derivatives at the pixel's centre: a different blend of two levels, 2 to 8/255 on a few
/// percent of the pixels. (The driver's mipmaps are rounded means: with truncated means, 37%
/// of case 1's pixels differ by more than 2/255.)
#[test]
fn textured_opengl_model_matches_mesa() {
    let Some(exe) = reference() else { return };
    let mut r = Rng(7);
    // (filter, wrap; uv repeat on the floor, texture size, cell; bounds on the share of pixels
    // beyond 2/255 and on the largest difference). Measured on Mesa 22.3 (llvmpipe), in case
    // order, Gouraud: 0.05% (15/255: the sphere's poles and rim, where it is minified), 1.56%
    // (8/255), none beyond 1/255, 0.03% (nearest: a texel boundary falls on the other side of 5
    // pixel centres), 1.32% (7/255); per pixel: 0.05%, 1.51%, none, 0.03%, 1.30%, the same
    // largest differences.
    let cases: [(Sampler, u32, u32, u32, f64, u8); 5] = [
        (Sampler::trilinear(Wrap::Repeat), 1, 16, 2, 0.002, 24),
        (Sampler::trilinear(Wrap::Repeat), 12, 128, 1, 0.025, 16),
        (Sampler::bilinear(Wrap::Clamp), 1, 16, 2, 0.0, 1),
        (Sampler::nearest(Wrap::Mirror), 3, 32, 4, 0.001, 255),
        (Sampler::trilinear(Wrap::Mirror), 5, 64, 2, 0.025, 16),
    ];
    for (case, &(sampler, repeat, size, cell, share, largest)) in cases.iter().enumerate() {
        let sphere = primitives::sphere(48).transformed(&Mat4::from_translation(Vec3::new(0.0, 0.3, 0.0)));
        let floor = primitives::plane(24).transformed(&Mat4::from_scale_rotation_translation(
            Vec3::splat(2.5),
            glam::Quat::IDENTITY,
            Vec3::new(0.0, -0.8, 0.0),
        ));
        let uvs = floor.uvs().iter().map(|&uv| uv * repeat as f32).collect();
        let mut mesh = sphere;
        mesh.append(&floor.with_uvs(uvs).unwrap());
        let col = LightColor::new(Color::splat(0.1), Color::splat(0.8), Color::splat(0.6)).unwrap();
        let lights = vec![
            Light::directional(Vec3::new(-1.0, -2.0, -1.5), col).unwrap(),
            Light::point(
                Vec3::new(2.0, 2.0, 2.0),
                col,
                Attenuation::new(1.0, 0.05, 0.01).unwrap(),
            )
            .unwrap(),
        ];
        let m = Material::new(r.c(), r.c(), r.c(), r.c() * 0.1, 40.0).unwrap();
        let eye = Vec3::new(r.r(-1.0, 1.0), r.r(0.4, 1.2), 4.0);
        let mut scene = scene_with(mesh, m, lights, Color::splat(0.2), eye, Viewer::Local, false);
        let mut map = TextureMap::new(texture(&mut r, size, size / 2 + size / 4, cell));
        map.sampler = sampler;
        scene.objects[0].maps.diffuse = Some(map);
        for interpolation in [Interpolation::Gouraud, Interpolation::Phong] {
            scene.objects[0].shading.interpolation = interpolation;
            let diffs = differences(&exe, &scene);
            let n = diffs.len();
            let (mut off, mut max) = (0usize, 0u8);
            let mut hist = [0usize; 4];
            for &d in &diffs {
                max = max.max(d);
                off += usize::from(d > 2);
                hist[match d {
                    0..=1 => 0,
                    2..=4 => 1,
                    5..=16 => 2,
                    _ => 3,
                }] += 1;
            }
            let frac = off as f64 / n as f64;
            eprintln!(
                "textured case {case} {interpolation:?}: {:.2}% of pixels beyond 2/255, largest {max}/255; \
             ≤1: {}, 2–4: {}, 5–16: {}, >16: {}",
                frac * 100.0,
                hist[0],
                hist[1],
                hist[2],
                hist[3]
            );
            assert!(frac <= share, "case {case}: {off} pixels beyond 2/255");
            assert!(max <= largest, "case {case}: a pixel differs by {max}/255");
        }
    }
    let _ = std::fs::remove_file(&exe);
}
