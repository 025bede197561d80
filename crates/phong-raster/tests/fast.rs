//! The fast path (visibility first, the 8-lane kernel with an approximate `pow`) against the
//! scalar reference path and `phong_core::shade`.

mod common;
use common::Rng;

use glam::Vec3;
use phong_core::*;
use phong_raster::internals::{
    ClipVertex, Clipped, LANES, Lean, Prepared, Term, VertexTerm, clip_triangle, light_vertices, shade8, shade8_lean,
};
use phong_raster::{Kernels, RenderOptions, render};
use std::path::Path;

/// A view of round `round`: local (per-point V) on even rounds, infinite on odd ones.
fn random_view(r: &mut Rng, round: usize) -> View {
    if round.is_multiple_of(2) {
        View::Local { eye: r.v(6.0) }
    } else {
        View::Infinite { to_viewer: r.v(1.0) }
    }
}

/// A material of random colours, its shininess from 0 to 1000 by round.
fn random_material(r: &mut Rng, round: usize) -> (Material, f32) {
    let shininess = [0.0, 1.0, 10.0, 51.2, 128.0, 1000.0][round % 6];
    (
        Material::new(r.c(), r.c(), r.c(), r.c() * 0.2, shininess).unwrap(),
        shininess,
    )
}

/// Positions and normals for the lanes; every 50th round one zero normal.
fn random_points(r: &mut Rng, round: usize) -> ([Vec3; LANES], [Vec3; LANES]) {
    let pos: [Vec3; LANES] = std::array::from_fn(|_| r.v(2.0));
    let nrm: [Vec3; LANES] = std::array::from_fn(|i| {
        if round.is_multiple_of(50) && i == 3 {
            Vec3::ZERO
        } else {
            r.v(1.0)
        }
    });
    (pos, nrm)
}

/// `shade8` against `shade`, lane by lane, on 20000 random points: every model, normalization,
/// option and light type, shininess up to 1000, in the portable build and (where the CPU has
/// it) the AVX2 build. Measured: largest difference 1.5e-6 relative to max(1, |value|);
/// asserted 5e-4 (the pow approximation's bound at s = 1000 is 3.3e-4).
#[test]
fn kernel_matches_shade() {
    let mut r = Rng(3);
    let models = [
        SpecularModel::None,
        SpecularModel::Phong,
        SpecularModel::BlinnPhong,
        SpecularModel::Lyon {
            squarings: 3,
            lambda: LyonLambda::Dot,
        },
        SpecularModel::Lyon {
            squarings: 4,
            lambda: LyonLambda::Difference,
        },
    ];
    let norms = [
        Normalization::None,
        Normalization::Phong,
        Normalization::BlinnPhong,
        Normalization::BlinnPhongExact,
    ];
    let mut worst = 0.0f32;
    for round in 0..2500 {
        let mut lights = Vec::new();
        for _ in 0..(1 + round % 4) {
            let col = LightColor::new(r.c() * 0.3, r.c(), r.c()).unwrap();
            let att = Attenuation::new(r.r(0.5, 2.0), r.r(0.0, 0.5), r.r(0.0, 0.2)).unwrap();
            lights.push(match (round + lights.len()) % 3 {
                0 => Light::directional(r.v(1.0) + Vec3::splat(0.01), col).unwrap(),
                1 => Light::point(r.v(4.0), col, att).unwrap(),
                _ => Light::spot(
                    r.v(4.0),
                    r.v(1.0) + Vec3::splat(0.01),
                    r.r(5.0, 90.0),
                    r.r(0.0, 30.0),
                    col,
                    att,
                )
                .unwrap(),
            });
        }
        let lighting = Lighting::new(r.c() * 0.3, lights).unwrap();
        let (m, shininess) = random_material(&mut r, round);
        let options = ShadingOptions {
            specular: models[round % models.len()],
            gate_specular: r.f() < 0.7,
            clamp: r.f() < 0.5,
            normalization: norms[(round / 5) % norms.len()],
            two_sided: false,
        };
        let view = random_view(&mut r, round);
        let prep = Prepared::new(&lighting, &m, &options, view);
        let (pos, nrm) = random_points(&mut r, round);
        for isa in common::isas() {
            let avx2 = isa.is_avx2();
            let got = shade8(isa, &prep, &pos, &nrm);
            // Gouraud's vertex entry (16 lanes in the AVX2 build), on the same points with a
            // 5-point tail: each term it keeps exactly as `shade8` has it, flipped normals as
            // negated.
            for (term, want) in [
                (Term::Ambient, got.ambient),
                (Term::Diffuse, got.diffuse),
                (Term::Specular, got.specular),
                (Term::Color, got.color),
            ] {
                let n = 13;
                let ps: Vec<Vec3> = (0..n).map(|i| pos[i % LANES]).collect();
                let ns: Vec<Vec3> = (0..n).map(|i| -nrm[i % LANES]).collect();
                let mut out = vec![Vec3::NAN; n];
                light_vertices(isa, &prep, VertexTerm::General(term), &ps, &ns, true, &mut out);
                for (i, o) in out.iter().enumerate() {
                    let w = Vec3::new(want[0][i % LANES], want[1][i % LANES], want[2][i % LANES]);
                    // Lane-wise the same operations: the same bits.
                    assert_eq!(*o, w, "round {round} vertex {i} avx2 {avx2} {term:?}");
                }
            }
            for lane in 0..LANES {
                let want = shade(
                    &SurfacePoint {
                        position: pos[lane],
                        normal: nrm[lane],
                    },
                    &view,
                    &m,
                    &lighting,
                    &options,
                );
                for (g, w) in [
                    (got.ambient, want.ambient),
                    (got.diffuse, want.diffuse),
                    (got.specular, want.specular),
                    (got.color, want.color),
                ] {
                    for (c, wc) in w.to_array().into_iter().enumerate() {
                        let err = (g[c][lane] - wc).abs() / wc.abs().max(1.0);
                        worst = worst.max(err);
                        assert!(
                            err < 5e-4,
                            "round {round} lane {lane} avx2 {avx2}: {} vs {wc} ({options:?}, s = {shininess})",
                            g[c][lane]
                        );
                    }
                }
            }
        }
    }
    eprintln!("largest kernel vs shade difference: {worst:e}");
}

/// The lean colour kernel against `shade`'s colour on 20000 random points, in both builds:
/// Phong, Blinn-Phong and no highlight, gated or not, clamped or not, directional and point
/// lights, shininess up to 1000. Its bound: the pow approximation's (5e-4 relative, as the
/// general kernel) plus 0.05/255 a light for the highlights it skips. And the cases it leaves
/// to the general kernel: spot lights, energy normalisation, Lyon's model.
#[test]
fn lean_kernel_matches_shade() {
    let mut r = Rng(11);
    let models = [SpecularModel::Phong, SpecularModel::BlinnPhong, SpecularModel::None];
    let mut worst = 0.0f32;
    for round in 0..2500 {
        let count = 1 + round % 4;
        let mut lights = Vec::new();
        for _ in 0..count {
            let col = LightColor::new(r.c() * 0.3, r.c(), r.c()).unwrap();
            let att = Attenuation::new(r.r(0.5, 2.0), r.r(0.0, 0.5), r.r(0.0, 0.2)).unwrap();
            lights.push(match (round + lights.len()) % 3 {
                0 => Light::directional(r.v(1.0) + Vec3::splat(0.01), col).unwrap(),
                1 => Light::point(r.v(4.0), col, att).unwrap(),
                _ => Light::point(r.v(4.0), col, Attenuation::NONE).unwrap(),
            });
        }
        let lighting = Lighting::new(r.c() * 0.3, lights).unwrap();
        let (m, shininess) = random_material(&mut r, round);
        let options = ShadingOptions {
            specular: models[round % models.len()],
            gate_specular: r.f() < 0.7,
            clamp: r.f() < 0.5,
            normalization: Normalization::None,
            two_sided: false,
        };
        let view = random_view(&mut r, round);
        let prep = Prepared::new(&lighting, &m, &options, view);
        let (pos, nrm) = random_points(&mut r, round);
        let lean = Lean::of(&prep).expect("the lean kernel shades these");
        for isa in common::isas() {
            let got = shade8_lean(isa, &prep, &pos, &nrm).expect("the lean kernel shades these");
            // Gouraud's vertex entry by the lean kernel (16 lanes in the AVX2 build, so its
            // skipped highlights may differ): the same bound.
            let mut vertices = [Vec3::NAN; LANES];
            light_vertices(isa, &prep, VertexTerm::Lean(&lean), &pos, &nrm, false, &mut vertices);
            for lane in 0..LANES {
                let point = SurfacePoint {
                    position: pos[lane],
                    normal: nrm[lane],
                };
                let want = shade(&point, &view, &m, &lighting, &options).color.to_array();
                for c in 0..3 {
                    let bound = 5e-4 * want[c].abs().max(1.0) + count as f32 * 0.05 / 255.0;
                    let vertex_err = (vertices[lane][c] - want[c]).abs();
                    assert!(vertex_err <= bound, "round {round} vertex {lane} {isa:?}");
                    let err = (got[c][lane] - want[c]).abs();
                    worst = worst.max(err / bound);
                    assert!(
                        err <= bound,
                        "round {round} lane {lane} {isa:?}: {} vs {} ({options:?}, s = {shininess})",
                        got[c][lane],
                        want[c]
                    );
                }
            }
        }
    }
    eprintln!("lean kernel: worst error {worst:.3} of its bound");
    // What it leaves to the general kernel.
    let col = LightColor::new(Color::BLACK, Color::WHITE, Color::WHITE).unwrap();
    let spot = Light::spot(Vec3::Z, -Vec3::Z, 30.0, 2.0, col, Attenuation::NONE).unwrap();
    let point = Light::point(Vec3::Z, col, Attenuation::NONE).unwrap();
    let m = Material::default();
    let plain = ShadingOptions::default();
    let (p, n) = ([Vec3::ZERO; LANES], [Vec3::Z; LANES]);
    for (lights, options) in [
        (vec![spot], plain),
        (
            vec![point],
            ShadingOptions {
                normalization: Normalization::BlinnPhong,
                ..plain
            },
        ),
        (
            vec![point],
            ShadingOptions {
                specular: SpecularModel::Lyon {
                    squarings: 3,
                    lambda: LyonLambda::Dot,
                },
                ..plain
            },
        ),
    ] {
        let lighting = Lighting::new(Color::BLACK, lights).unwrap();
        let prep = Prepared::new(&lighting, &m, &options, View::Local { eye: Vec3::Z * 3.0 });
        assert!(shade8_lean(common::isas()[0], &prep, &p, &n).is_none(), "{options:?}");
    }
}

fn scenes() -> Vec<std::path::PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut v = Vec::new();
    for dir in ["examples/scenes", "benches/scenes"] {
        for e in std::fs::read_dir(root.join(dir)).unwrap() {
            let p = e.unwrap().path();
            if p.extension().is_some_and(|x| x == "toml") {
                v.push(p);
            }
        }
    }
    v.sort();
    v
}

/// Every example and benchmark scene: the fast path's image within 1/255 per channel of the
/// reference path's on every pixel, with the AVX2 build (1 and 3 threads: the same image
/// whatever the thread count) and with the portable build (they differ in rounding: fused
/// multiply-adds, reciprocal estimates). Measured: at most 17 channel values of a scene differ,
/// each by 1/255.
#[test]
fn fast_path_matches_reference_on_every_scene() {
    for path in scenes() {
        let mut scene = phong_scene::load(&path).unwrap().scene;
        scene.image.width = 240;
        scene.image.height = 160;
        let reference = render(
            &scene,
            &RenderOptions {
                reference: true,
                threads: Some(2),
                ..Default::default()
            },
        )
        .unwrap();
        let one = render(
            &scene,
            &RenderOptions {
                threads: Some(1),
                ..Default::default()
            },
        )
        .unwrap();
        let three = render(
            &scene,
            &RenderOptions {
                threads: Some(3),
                ..Default::default()
            },
        )
        .unwrap();
        assert_eq!(one, three, "{}: thread count changed the image", path.display());
        let portable = render(
            &scene,
            &RenderOptions {
                threads: Some(2),
                kernels: Kernels::Portable,
                ..Default::default()
            },
        )
        .unwrap();
        let alpha = reference.has_transparency();
        let enc = scene.image.encoding;
        let a = reference.to_bytes(enc, alpha);
        for (build, image) in [("avx2", &one), ("portable", &portable)] {
            let b = image.to_bytes(enc, alpha);
            let worst = a.iter().zip(&b).map(|(x, y)| x.abs_diff(*y)).max().unwrap();
            let differ = a.iter().zip(&b).filter(|(x, y)| x != y).count();
            eprintln!(
                "{} ({build}): {differ} channel values differ, largest {worst}/255",
                path.file_name().unwrap().to_string_lossy()
            );
            assert!(
                worst <= 1,
                "{} ({build}): a channel differs by {worst}/255",
                path.display()
            );
        }
    }
}

/// The fast path's clipped triangles: a two-sided ground plane that passes under and behind
/// the camera (its triangles cross the near plane and leave the guard band) and a torus
/// cutting the near plane, Gouraud and Phong, against the reference path, both builds. The
/// scene must make clipped triangles: more triangles are drawn than the meshes' front faces
/// could give without clipping.
#[test]
fn fast_path_matches_reference_where_triangles_are_clipped() {
    for interpolation in ["gouraud", "phong"] {
        let src = format!(
            r#"
[image]
width = 200
height = 150
[camera]
position = [0.0, 0.3, 0.0]
target = [0.0, 0.0, -2.0]
near = 0.1
[shading]
model = "blinn-phong"
interpolation = "{interpolation}"
two_sided = true
[[light]]
type = "point"
position = [0.5, 2.0, -1.0]
attenuation = [1.0, 0.1, 0.05]
[[light]]
type = "directional"
direction = [0.3, -1.0, -0.5]
[[object]]
shape = "plane"
segments = 8
material = "pewter"
position = [0.0, -0.5, 0.0]
scale = 400.0
[[object]]
shape = "torus"
segments = 24
material = "ruby"
position = [0.0, 0.3, -0.3]
rotation = [0.0, 90.0, 0.0]
"#
        );
        let mut scene = phong_scene::parse_scene(&src, Path::new("clipped.toml")).unwrap().scene;
        assert_fast_matches_reference(&scene, interpolation);
        // Textured (a 4×4 texture repeated, trilinear): the clipped triangles' texture
        // coordinates come from the clipped vertices.
        let texels: Vec<[u16; 4]> = (0..16u16)
            .map(|i| [i * 4000, 65535 - i * 3000, (i % 3) * 20000, 65535])
            .collect();
        let texture = std::sync::Arc::new(Texture::new(4, 4, &texels, 16).unwrap());
        for o in &mut scene.objects {
            let mut map = TextureMap::new(texture.clone());
            map.transform = UvTransform::scale_offset(glam::Vec2::splat(50.0), glam::Vec2::ZERO);
            o.maps.diffuse = Some(map);
        }
        assert_fast_matches_reference(&scene, &format!("{interpolation}, textured"));
        // The vector sampler's cases (`simd/sampler.rs`): above, 16 bits, trilinear; here 8
        // bits, mirrored, bilinear.
        let bytes: Vec<[u8; 4]> = texels.iter().map(|t| t.map(|c| (c / 257) as u8)).collect();
        let texture = std::sync::Arc::new(Texture::from_rgba8(4, 4, &bytes).unwrap());
        for o in &mut scene.objects {
            let map = o.maps.diffuse.as_mut().expect("set above");
            map.texture = texture.clone();
            map.sampler = Sampler::bilinear(Wrap::Mirror);
        }
        assert_fast_matches_reference(&scene, &format!("{interpolation}, textured, 8 bits"));
        // With a 16-bit specular map too (the 8-bit diffuse kept).
        let specular = std::sync::Arc::new(Texture::new(4, 4, &texels, 16).unwrap());
        for o in &mut scene.objects {
            o.maps.specular = Some(TextureMap::new(specular.clone()));
        }
        assert_fast_matches_reference(&scene, &format!("{interpolation}, diffuse and specular maps"));
        // And vertex colours tinting the diffuse texel.
        for o in &mut scene.objects {
            let colors = o
                .mesh
                .positions()
                .iter()
                .map(|p| Color::new(0.5 + 0.5 * p.x.sin(), 0.5 + 0.5 * p.z.cos(), 0.7))
                .collect();
            o.mesh = o.mesh.clone().with_colors(colors).unwrap();
        }
        assert_fast_matches_reference(&scene, &format!("{interpolation}, maps and vertex colours"));
        // Coordinates beyond the vector sampler's exact wrapping (2^21 texels): every vector
        // is left to the per-pixel sampler, with the light the vector kernel gave it.
        for o in &mut scene.objects {
            let map = o.maps.diffuse.as_mut().expect("set above");
            map.transform = UvTransform::scale_offset(glam::Vec2::splat(50.0), glam::Vec2::new(600_000.0, 0.0));
        }
        assert_fast_matches_reference(&scene, &format!("{interpolation}, coordinates past 2^21 texels"));
        // Clipping happened: some triangles are clipped into polygons.
        let aspect = scene.image.width as f32 / scene.image.height as f32;
        let clip_from_world = scene.camera.clip_from_world(aspect);
        let clipped = scene
            .objects
            .iter()
            .flat_map(|o| {
                o.mesh.triangles().iter().map(|t| {
                    t.map(|i| {
                        let p = o.mesh.positions()[i as usize];
                        ClipVertex {
                            clip: clip_from_world * p.extend(1.0),
                            world: p,
                            normal: Vec3::Z,
                            color: Vec3::ZERO,
                            color_back: Vec3::ZERO,
                            spec: [Vec3::ZERO; 2],
                            uv: glam::Vec2::ZERO,
                            uv1: glam::Vec2::ZERO,
                            rgb: Vec3::ONE,
                            tangent: glam::Vec4::ZERO,
                        }
                    })
                })
            })
            .filter(|t| matches!(clip_triangle(t), Clipped::Polygon(_)))
            .count();
        assert!(clipped > 10, "{interpolation}: only {clipped} triangles clipped");
    }
}

/// Objects of different interpolations hiding each other, in both drawing orders: Gouraud
/// pixels are coloured during visibility and Phong ones after it, so a nearer triangle of
/// either kind must win over a farther one of the other, whatever came first.
#[test]
fn fast_path_matches_reference_where_interpolations_overlap() {
    for (first, second) in [("gouraud", "phong"), ("phong", "gouraud")] {
        let src = format!(
            r#"
[image]
width = 160
height = 120
[camera]
position = [0.0, 0.0, 4.0]
[shading]
model = "blinn-phong"
[[light]]
type = "point"
position = [1.0, 2.0, 3.0]
[[object]]
shape = "sphere"
segments = 24
material = "brass"
interpolation = "{first}"
position = [-0.3, 0.0, 0.0]
[[object]]
shape = "torus"
segments = 24
material = "jade"
interpolation = "{second}"
position = [0.4, 0.1, 0.3]
rotation = [60.0, 0.0, 0.0]
"#
        );
        let scene = phong_scene::parse_scene(&src, Path::new("overlap.toml")).unwrap().scene;
        assert_fast_matches_reference(&scene, &format!("{first} then {second}"));
    }
}

/// The fast path's image, AVX2 (where the CPU has it) and portable builds, within 1/255 of the
/// reference path's on every channel of every pixel.
fn assert_fast_matches_reference(scene: &Scene, what: &str) {
    let reference = render(
        scene,
        &RenderOptions {
            reference: true,
            ..Default::default()
        },
    )
    .unwrap();
    let a = reference.to_bytes(scene.image.encoding, false);
    for kernels in [Kernels::Auto, Kernels::Portable] {
        let fast = render(
            scene,
            &RenderOptions {
                kernels,
                ..Default::default()
            },
        )
        .unwrap();
        let b = fast.to_bytes(scene.image.encoding, false);
        let worst = a.iter().zip(&b).map(|(x, y)| x.abs_diff(*y)).max().unwrap();
        assert!(worst <= 1, "{what} ({kernels:?}): a channel differs by {worst}/255");
    }
}

/// Scene TOML of `objects` in a 200×120 image, the camera at `z = 6` and one point light.
fn in_small_frame(objects: &str) -> String {
    let head = "[image]\nwidth = 200\nheight = 120\n[camera]\nposition = [0.0, 0.0, 6.0]\n";
    format!("{head}[[light]]\ntype = \"point\"\nposition = [2.0, 2.0, 4.0]\n{objects}")
}

/// A folder of the temporary directory, removed when dropped (when its test ends, failed too).
struct Dir(std::path::PathBuf);

impl Drop for Dir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// A quad with vertex colours and coordinates over twice the image, as an OBJ file in a new
/// folder `tag` of the temporary directory: the folder (removed when dropped) and the file.
fn tinted_quad(tag: &str) -> (Dir, std::path::PathBuf) {
    let dir = std::env::temp_dir().join(format!("{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let tinted = dir.join("tinted.obj");
    std::fs::write(
        &tinted,
        "v -1 -1 0 1 0.2 0.2\nv 1 -1 0 0.2 1 0.2\nv 1 1 0 0.2 0.2 1\nv -1 1 0 1 1 1\n\
         vt 0 0\nvt 2 0\nvt 2 2\nvt 0 2\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n",
    )
    .unwrap();
    (Dir(dir), tinted)
}

/// A `Renderer` kept across frames of different scenes (sizes, meshes, sample counts, both
/// paths) makes the same images as fresh renders: nothing of a previous frame leaks into the
/// next through its reused memory.
#[test]
fn renderer_reuse_matches_fresh_renders() {
    let mut renderer = phong_raster::Renderer::new();
    let paths = scenes();
    for (i, path) in paths.iter().chain(paths.iter().rev()).enumerate() {
        let mut scene = phong_scene::load(path).unwrap().scene;
        scene.image.width = [96, 160, 64][i % 3];
        scene.image.height = [64, 90, 64][i % 3];
        let options = RenderOptions {
            reference: i % 4 == 3,
            threads: Some(2),
            ..Default::default()
        };
        let fresh = render(&scene, &options).unwrap();
        let (kept, _) = renderer.render(&scene, &options).unwrap();
        assert!(
            kept == &fresh,
            "{}: a reused renderer changed the image",
            path.display()
        );
    }
}

/// Rendering straight into 8 bits gives the bytes of the `f32` image's encoding, pixel for
/// pixel: every example and benchmark scene, both encodings, the fast and the reference path,
/// the AVX2 and the portable build, 1 and 3 threads, one `Renderer` kept across all of them (its
/// 8-bit and `f32` frames alternate); and transparency is told as the `f32` image tells it, for
/// backgrounds with alpha 0, 0.5 and 1 and 1, 4 and 16 samples. A background alpha that 8 bits
/// cannot tell apart from opaque is refused (`None`).
#[test]
fn eight_bit_frames_are_the_encoded_f32_frames() {
    let mut renderer = phong_raster::Renderer::new();
    for (i, path) in scenes().iter().enumerate() {
        let mut scene = phong_scene::load(path).unwrap().scene;
        scene.image.width = [96, 150][i % 2];
        scene.image.height = [64, 100][i % 2];
        for encoding in [Encoding::Linear, Encoding::Srgb] {
            scene.image.encoding = encoding;
            for (reference, kernels, threads) in [
                (false, Kernels::Auto, 1),
                (false, Kernels::Portable, 3),
                (true, Kernels::Auto, 3),
            ] {
                let options = RenderOptions {
                    reference,
                    kernels,
                    threads: Some(threads),
                    ..Default::default()
                };
                let expected = render(&scene, &options).unwrap().to_bytes(encoding, true);
                let (image, _) = renderer
                    .render_8bit(&scene, &options)
                    .unwrap()
                    .expect("an opaque background");
                assert_eq!(image.encoding(), encoding);
                let got = image.to_bytes(true);
                let differ = expected.iter().zip(&got).filter(|(a, b)| a != b).count();
                assert_eq!(
                    differ,
                    0,
                    "{} {encoding:?} reference={reference} {kernels:?} threads={threads}",
                    path.display()
                );
            }
        }
    }
    let mut scene = phong_scene::load(&scenes()[0]).unwrap().scene;
    scene.image.width = 80;
    scene.image.height = 60;
    for alpha in [0.0, 0.5, 1.0] {
        for samples in phong_core::Samples::ALL {
            scene.image.background = [0.2, 0.4, 0.6, alpha];
            scene.image.samples = samples;
            let options = RenderOptions::default();
            let f32_image = render(&scene, &options).unwrap();
            let (image, _) = renderer.render_8bit(&scene, &options).unwrap().expect("an exact alpha");
            assert_eq!(
                image.has_transparency(),
                f32_image.has_transparency(),
                "{alpha} {samples}"
            );
            let transparent = f32_image.has_transparency();
            assert_eq!(
                image.to_bytes(transparent),
                f32_image.to_bytes(scene.image.encoding, transparent)
            );
        }
    }
    scene.image.background = [0.0, 0.0, 0.0, 0.98];
    assert!(
        renderer
            .render_8bit(&scene, &RenderOptions::default())
            .unwrap()
            .is_none()
    );
}

/// Ambient, emission and occlusion maps, which the vector sampler applies with the light's
/// emission kept apart (`Prepared::emission_apart`): each alone, beside diffuse and specular maps, with and
/// without clamping (the `opengl` model clamps), vertex colours or not, a second light with
/// an ambient colour of its own, coordinates too large for the vector sampler's wrapping (the
/// planes: their pixels are the reference's); the fast path within 1/255 of the reference.
#[test]
fn fast_path_matches_reference_with_ambient_emission_and_occlusion_maps() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenes");
    // A quad with vertex colours, which tint the diffuse texel but not the ambient map's.
    let (_dir, tinted) = tinted_quad("phong-split-maps");
    for model in ["opengl", "blinn-phong"] {
        let src = format!(
            r#"
[image]
width = 200
height = 120
[camera]
position = [0.0, 0.0, 6.0]
[shading]
model = "{model}"
ambient = [0.3, 0.25, 0.2]
[[light]]
type = "point"
position = [2.0, 2.0, 4.0]
[[light]]
type = "directional"
direction = [1.0, -0.5, -1.0]
ambient = [0.2, 0.3, 0.1]
color = [0.6, 0.6, 0.7]
[[object]]
shape = "sphere"
position = [-2.2, 0.8, 0.0]
material = {{ base = "brass", ambient = [1.5, 1.2, 1.0], ambient_map = "assets/bricks.png", uv_scale = [2.0, 1.0] }}
[[object]]
shape = "torus"
position = [0.0, 0.8, 0.0]
rotation = [60.0, 0.0, 0.0]
material = {{ base = "jade", emission = [0.4, 0.3, 0.6], emission_map = "assets/checker.png" }}
[[object]]
shape = "cube"
position = [2.2, 0.8, 0.0]
rotation = [30.0, 40.0, 0.0]
material = {{ base = "ruby", emission = [0.2, 0.5, 0.1], ambient_map = "assets/checker.png", emission_map = "assets/bricks_specular.png", diffuse_map = "assets/bricks.png", specular_map = "assets/bricks_specular.png", wrap = "mirror" }}
[[object]]
mesh = "assets/crate.obj"
position = [-1.0, -1.3, 0.0]
scale = 0.8
rotation = [20.0, 30.0, 0.0]
material = {{ base = "silver", emission = [0.3, 0.3, 0.3], emission_map = "assets/checker.png", ambient_map = "assets/bricks.png" }}
[[object]]
shape = "teapot"
position = [1.4, -1.3, 0.0]
scale = 0.6
material = {{ base = "gold", ambient_map = "assets/bricks_specular.png", specular_map = "assets/checker.png", filter = "bilinear" }}
[[object]]
mesh = "{tinted}"
position = [3.0, -1.3, 0.5]
scale = 0.6
rotation = [0.0, -30.0, 0.0]
material = {{ base = "pearl", ambient_map = "assets/bricks.png", emission = [0.1, 0.0, 0.2], emission_map = "assets/checker.png" }}
[[object]]
shape = "plane"
position = [0.0, -0.2, -2.0]
scale = 6.0
rotation = [80.0, 0.0, 0.0]
material = {{ base = "pewter", ambient_map = "assets/checker.png", uv_scale = [3.0e5, 3.0e5] }}
[[object]]
shape = "plane"
position = [-3.2, 1.5, 1.0]
scale = 0.5
rotation = [70.0, 0.0, 0.0]
material = {{ base = "chrome", emission = [0.2, 0.1, 0.3], emission_map = "assets/checker.png", uv_scale = [3.0e5, 3.0e5] }}
"#,
            tinted = tinted.display()
        );
        let mut scene = phong_scene::parse_scene(&src, &root.join("split.toml")).unwrap().scene;
        assert!(
            scene
                .objects
                .iter()
                .all(|o| o.maps.ambient.is_some() || o.maps.emission.is_some())
        );
        // glTF's occlusion map (no scene key gives one): beside an ambient map (the sphere),
        // alone on the ambient terms (the torus: `T_Kd`, here 1, times the occlusion), tinted
        // (the quad), with coordinates past the vector wrap (the planes; the second has no
        // ambient map).
        let mut r = Rng(7);
        let texels: Vec<[u16; 4]> = (0..24 * 20)
            .map(|_| [r.f(), r.f(), r.f()].map(|x| (x * 65535.0) as u16))
            .map(|[a, b, c]| [a, b, c, 65535])
            .collect();
        let occlusion = std::sync::Arc::new(Texture::new(24, 20, &texels, 8).unwrap());
        for (i, strength) in [(0, 1.0), (1, 0.6), (5, 0.8), (6, 1.0), (7, 0.9)] {
            scene.objects[i].maps.occlusion = Some(Occlusion {
                map: TextureMap::new(occlusion.clone()),
                strength,
            });
        }
        assert!(
            !scene.objects[5].mesh.colors().is_empty(),
            "the quad has vertex colours"
        );
        assert_fast_matches_reference(&scene, model);
    }
}

/// Maps on the second set of texture coordinates (glTF's `TEXCOORD_1`), beside maps on the
/// first: the vector sampler reads the set each map names (its planes in the vertex colours'
/// place). Coordinates past the vector wrap on the second set (the plane) fall back per pixel.
/// The fast path within 1/255 of the reference.
#[test]
fn fast_path_matches_reference_with_maps_on_the_second_set() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenes");
    let src = in_small_frame(
        r#"
[[object]]
shape = "sphere"
position = [-2.0, 0.6, 0.0]
material = { base = "brass", diffuse_map = "assets/bricks.png", specular_map = "assets/checker.png" }
[[object]]
shape = "torus"
position = [1.5, 0.6, 0.0]
rotation = [60.0, 0.0, 0.0]
material = { base = "jade", emission = [0.3, 0.2, 0.1], ambient_map = "assets/bricks.png", emission_map = "assets/checker.png", diffuse_map = "assets/bricks_specular.png" }
[[object]]
shape = "plane"
position = [0.0, -1.5, 0.0]
scale = 3.0
rotation = [60.0, 0.0, 0.0]
material = { base = "pewter", diffuse_map = "assets/checker.png" }
"#,
    );
    let mut scene = phong_scene::parse_scene(&src, &root.join("second.toml")).unwrap().scene;
    // The second set: the first turned a quarter and scaled (the plane's far past the wrap).
    for (i, scale) in [(0, 3.0), (1, 2.0), (2, 3.0e5)] {
        let o = &mut scene.objects[i];
        let uvs1: Vec<glam::Vec2> = o.mesh.uvs().iter().map(|t| glam::Vec2::new(t.y, t.x) * scale).collect();
        o.mesh = o.mesh.clone().with_uvs1(uvs1).unwrap();
    }
    let maps = &mut scene.objects[0].maps;
    maps.diffuse.as_mut().unwrap().set = 1;
    let maps = &mut scene.objects[1].maps;
    maps.ambient.as_mut().unwrap().set = 1;
    maps.emission.as_mut().unwrap().set = 1;
    scene.objects[2].maps.diffuse.as_mut().unwrap().set = 1;
    assert!(scene.objects.iter().all(|o| o.maps.uses_second_set()));
    assert_fast_matches_reference(&scene, "second set");
}

/// Normal maps (and bump maps, which become normal maps), which the vector sampler applies
/// before the light: the tangents' planes in the vertex colours' place. Beside diffuse,
/// specular and emission maps or alone; a normal map of random 16-bit normals with a scale and
/// with green down; back faces (a plane seen from behind, two-sided); a mesh from a file (its tangents by
/// MikkTSpace); coordinates past the vector wrap (the plane far back, whose normal map is then
/// sampled per lane); clamped and unclamped. The fast path within 1/255 of the reference
/// (`frame::tests` checks that such objects take the vector sampler).
#[test]
fn fast_path_matches_reference_with_normal_and_bump_maps() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenes");
    for model in ["opengl", "phong"] {
        let src = format!(
            r#"
[image]
width = 220
height = 130
[camera]
position = [0.0, 0.0, 6.0]
[shading]
model = "{model}"
two_sided = true
[[light]]
type = "point"
position = [2.0, 2.0, 4.0]
[[light]]
type = "directional"
direction = [1.0, -0.5, -1.0]
color = [0.5, 0.5, 0.6]
[[object]]
shape = "sphere"
position = [-2.2, 0.8, 0.0]
material = {{ base = "brass", diffuse_map = "assets/bricks.png", bump_map = "assets/bricks_height.png", bump_scale = 3.0, uv_scale = [2.0, 1.0] }}
[[object]]
shape = "torus"
position = [0.0, 0.8, 0.0]
rotation = [60.0, 0.0, 0.0]
material = {{ base = "jade", bump_map = "assets/checker.png", wrap = "mirror" }}
[[object]]
shape = "cube"
position = [2.2, 0.8, 0.0]
rotation = [30.0, 40.0, 0.0]
material = {{ base = "ruby", emission = [0.2, 0.1, 0.1], emission_map = "assets/checker.png", specular_map = "assets/bricks_specular.png", bump_map = "assets/bricks_height.png", filter = "bilinear" }}
[[object]]
mesh = "assets/crate.obj"
position = [-1.0, -1.3, 0.0]
scale = 0.8
rotation = [20.0, 30.0, 0.0]
material = {{ base = "silver", diffuse_map = "assets/bricks.png" }}
[[object]]
shape = "plane"
position = [1.6, -1.3, 0.0]
scale = 1.2
rotation = [-100.0, 20.0, 0.0]
material = {{ base = "gold", diffuse_map = "assets/checker.png" }}
[[object]]
shape = "plane"
position = [0.0, -0.2, -3.0]
scale = 6.0
rotation = [80.0, 0.0, 0.0]
material = {{ base = "pewter", bump_map = "assets/checker.png", uv_scale = [3.0e5, 3.0e5] }}
"#
        );
        let mut scene = phong_scene::parse_scene(&src, &root.join("normals.toml"))
            .unwrap()
            .scene;
        // A normal map of random normals (mostly up, tilted up to about 45°), 16-bit, on the
        // crate (scale 0.7) and the two-sided plane (green down).
        let mut r = Rng(11);
        let texels: Vec<[u16; 4]> = (0..24 * 20)
            .map(|_| {
                let n = Vec3::new(r.f() - 0.5, r.f() - 0.5, 1.0).normalize() * 0.5 + 0.5;
                [n.x, n.y, n.z].map(|x| (x * 65535.0) as u16)
            })
            .map(|[a, b, c]| [a, b, c, 65535])
            .collect();
        let texture = std::sync::Arc::new(Texture::new(24, 20, &texels, 16).unwrap());
        for (i, scale, green_down) in [(3, 0.7, false), (4, 1.0, true)] {
            scene.objects[i].maps.normal = Some(NormalMap {
                map: TextureMap::new(texture.clone()),
                scale,
                green_down,
            });
            scene.objects[i].mesh = scene.objects[i].mesh.with_mikktspace_tangents();
        }
        // The far plane's: every normal tilted the same way, so that its coordinates past the
        // wrap (which sample the last level, per lane) give the same texel on both paths; the
        // bits of such coordinates are noise to a filter, and the paths round them differently.
        let tilt = Vec3::new(0.6, -0.3, 0.75).normalize() * 0.5 + 0.5;
        let tilted = [tilt.x, tilt.y, tilt.z].map(|x| (x * 65535.0) as u16);
        let tilted = Texture::new(64, 64, &vec![[tilted[0], tilted[1], tilted[2], 65535]; 64 * 64], 8).unwrap();
        scene.objects[5].maps.normal.as_mut().unwrap().map.texture = std::sync::Arc::new(tilted);
        assert!(scene.objects.iter().all(|o| o.maps.normal.is_some()));
        assert!(scene.objects.iter().all(|o| !o.mesh.tangents().is_empty()));
        assert_fast_matches_reference(&scene, model);
    }
}

/// Shininess maps and glTF's metallic-roughness maps, which set the shininess per pixel: the
/// vector sampler samples them before the light, whose `pow` and normalisation factor then take
/// a shininess per lane. A shininess map on each channel (red, green, blue, luminance) under
/// Phong, Blinn-Phong and Lyon specular terms and each normalisation, with the `opengl` model
/// clamping; metallic-roughness maps of random texels (roughness down to 0: the largest
/// shininess), beside a diffuse map or alone, with a normal map; coordinates past the vector
/// wrap (the far plane: its maps then sampled per lane). The fast path within 1/255 of the
/// reference.
#[test]
fn fast_path_matches_reference_with_shininess_and_metallic_roughness_maps() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenes");
    let src = r#"
[image]
width = 220
height = 130
[camera]
position = [0.0, 0.0, 6.0]
[[light]]
type = "point"
position = [2.0, 2.0, 4.0]
[[light]]
type = "directional"
direction = [1.0, -0.5, -1.0]
color = [0.5, 0.5, 0.6]
[[object]]
shape = "sphere"
position = [-2.2, 0.8, 0.0]
material = { base = "brass", shininess = 80.0, diffuse_map = "assets/bricks.png", shininess_map = "assets/bricks_specular.png", uv_scale = [2.0, 1.0] }
[[object]]
shape = "torus"
position = [0.0, 0.8, 0.0]
rotation = [60.0, 0.0, 0.0]
material = { base = "jade", shininess = 40.0, shininess_map = "assets/bricks.png", wrap = "mirror" }
[[object]]
shape = "sphere"
position = [2.2, 0.8, 0.0]
material = { base = "chrome", shininess = 200.0, shininess_map = "assets/checker.png", specular_map = "assets/bricks.png", filter = "bilinear" }
[[object]]
shape = "sphere"
position = [-2.2, -1.3, 0.0]
material = { base = "gold", diffuse_map = "assets/bricks.png" }
[[object]]
shape = "cube"
position = [0.0, -1.3, 0.0]
rotation = [30.0, 40.0, 0.0]
material = { base = "silver", bump_map = "assets/bricks_height.png" }
[[object]]
shape = "torus"
position = [2.2, -1.3, 0.0]
rotation = [70.0, 0.0, 0.0]
material = { base = "ruby", shininess = 30.0, shininess_map = "assets/checker.png", emission = [0.1, 0.0, 0.1], emission_map = "assets/checker.png" }
[[object]]
shape = "plane"
position = [0.0, -0.2, -3.0]
scale = 6.0
rotation = [80.0, 0.0, 0.0]
material = { base = "pewter", shininess_map = "assets/checker.png", uv_scale = [3.0e5, 3.0e5] }
"#;
    let mut r = Rng(13);
    let random = |r: &mut Rng, w: u32, h: u32| {
        let texels: Vec<[u16; 4]> = (0..w * h)
            .map(|_| [r.f(), r.f(), r.f()].map(|x| (x * 65535.0) as u16))
            .map(|[a, b, c]| [a, b, c, 65535])
            .collect();
        std::sync::Arc::new(Texture::new(w, h, &texels, 16).unwrap())
    };
    let mr_texture = random(&mut r, 24, 20);
    // Past the wrap every lane samples the last level: one texel for the whole plane, the same
    // on both paths (such coordinates' low bits are noise to a filter).
    let flat = |t: [f32; 3]| {
        let t = t.map(|x| (x * 65535.0) as u16);
        std::sync::Arc::new(Texture::new(64, 64, &vec![[t[0], t[1], t[2], 65535]; 64 * 64], 16).unwrap())
    };
    let models = [
        SpecularModel::Phong,
        SpecularModel::BlinnPhong,
        SpecularModel::Lyon {
            squarings: 3,
            lambda: LyonLambda::Dot,
        },
    ];
    let normalizations = [
        Normalization::None,
        Normalization::Phong,
        Normalization::BlinnPhong,
        Normalization::BlinnPhongExact,
    ];
    for (round, clamp) in [(0, true), (1, false)] {
        let mut scene = phong_scene::parse_scene(src, &root.join("shininess.toml"))
            .unwrap()
            .scene;
        for (i, o) in scene.objects.iter_mut().enumerate() {
            o.shading.options.specular = models[(i + round) % 3];
            o.shading.options.normalization = normalizations[(i + round) % 4];
            o.shading.options.clamp = clamp;
        }
        for (i, channel) in [
            (0, Channel::R),
            (1, Channel::G),
            (2, Channel::B),
            (5, Channel::Luminance),
        ] {
            scene.objects[i].maps.shininess.as_mut().unwrap().1 = channel;
        }
        // Metallic-roughness: beside a diffuse map (the sphere), with a normal map (the cube),
        // over a shininess map (the torus: the roughness's shininess wins), past the wrap (the
        // plane, beside its shininess map).
        for (i, metallic, roughness) in [(3, 1.0, 1.0), (4, 0.7, 0.8), (5, 1.0, 0.5), (6, 0.8, 0.9)] {
            let o = &mut scene.objects[i];
            let mut map = TextureMap::new(mr_texture.clone());
            if i == 6 {
                map.texture = flat([0.0, 0.35, 0.6]);
                map.transform = o.maps.shininess.as_ref().unwrap().0.transform;
            }
            let mr = MetalRough {
                map,
                base_factor: Color::new(0.9, 0.7, 0.5),
                metallic,
                roughness,
            };
            o.material = mr.material(Color::BLACK, 1.0);
            o.maps.metal_rough = Some(mr);
        }
        let far = scene.objects[6].maps.shininess.as_mut().unwrap();
        far.0.texture = flat([0.2, 0.5, 0.9]);
        assert_fast_matches_reference(&scene, &format!("clamp {clamp}"));
    }
}

/// Gouraud-shaded textured objects, which the vector sampler draws from the vertices' primary
/// and specular colours in the triangles' planes: diffuse and specular maps, clamped (the
/// `opengl` model) and not; ambient, emission and normal maps, which apply with per-pixel
/// light only (ignored here, by both paths); two-sided lighting, a plane seen from behind; vertex
/// colours; a map on the second set; planes across the near plane (clipped), one seen from
/// behind; coordinates past
/// the vector wrap (their pixels finished per pixel). The fast path within 1/255 of the
/// reference (`frame::tests` checks that such objects take the vector sampler).
#[test]
fn fast_path_matches_reference_with_gouraud_textured_objects() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenes");
    let (_dir, tinted) = tinted_quad("phong-gouraud-maps");
    for model in ["opengl", "blinn-phong"] {
        let src = format!(
            r#"
[image]
width = 220
height = 130
[camera]
position = [0.0, 0.0, 6.0]
near = 0.5
[shading]
model = "{model}"
interpolation = "gouraud"
two_sided = true
ambient = [0.3, 0.25, 0.2]
[[light]]
type = "point"
position = [2.0, 2.0, 4.0]
color = [1.6, 1.5, 1.4]
[[light]]
type = "directional"
direction = [1.0, -0.5, -1.0]
color = [0.5, 0.5, 0.6]
[[light]]
type = "point"
position = [-0.6, -0.3, 5.8]
color = [0.6, 0.6, 0.4]
[[object]]
shape = "sphere"
segments = 24
position = [-2.2, 0.8, 0.0]
material = {{ base = "brass", diffuse_map = "assets/bricks.png", specular_map = "assets/bricks_specular.png", uv_scale = [2.0, 1.0] }}
[[object]]
shape = "torus"
position = [0.0, 0.8, 0.0]
rotation = [60.0, 0.0, 0.0]
material = {{ base = "jade", emission = [0.3, 0.2, 0.1], diffuse_map = "assets/checker.png", ambient_map = "assets/bricks.png", emission_map = "assets/bricks_specular.png", bump_map = "assets/bricks_height.png", wrap = "mirror" }}
[[object]]
shape = "plane"
position = [2.2, 0.8, 0.0]
scale = 0.9
rotation = [-100.0, 20.0, 0.0]
material = {{ base = "ruby", diffuse_map = "assets/bricks.png", filter = "bilinear" }}
[[object]]
mesh = "{tinted}"
position = [-2.0, -1.2, 0.5]
scale = 0.6
rotation = [0.0, 30.0, 0.0]
material = {{ base = "pearl", diffuse_map = "assets/bricks.png" }}
[[object]]
shape = "teapot"
position = [0.3, -1.5, 0.0]
scale = 0.6
material = {{ base = "gold", specular_map = "assets/checker.png" }}
[[object]]
shape = "plane"
position = [0.0, -2.2, 3.0]
scale = 4.0
rotation = [10.0, 0.0, 0.0]
material = {{ base = "pewter", diffuse_map = "assets/checker.png", uv_scale = [6.0, 6.0] }}
[[object]]
shape = "plane"
position = [0.0, 2.4, 3.0]
scale = 4.0
rotation = [-10.0, 0.0, 0.0]
segments = 8
material = {{ base = "emerald", shininess = 3.0, diffuse_map = "assets/bricks.png", specular_map = "assets/checker.png", uv_scale = [4.0, 4.0] }}
[[object]]
shape = "plane"
segments = 4
position = [0.25, -0.1, 5.2]
scale = [0.15, 1.0, 1.6]
rotation = [0.0, 0.0, -90.0]
material = {{ base = "cyan plastic", shininess = 3.0, diffuse_map = "assets/checker.png", specular_map = "assets/bricks.png" }}
[[object]]
shape = "plane"
position = [2.8, -1.0, 1.0]
scale = 0.5
rotation = [70.0, 0.0, 0.0]
material = {{ base = "chrome", emission = [0.3, 0.2, 0.1], diffuse_map = "assets/checker.png", emission_map = "assets/bricks.png", uv_scale = [3.0e5, 3.0e5] }}
"#,
            tinted = tinted.display()
        );
        let mut scene = phong_scene::parse_scene(&src, &root.join("gouraud.toml"))
            .unwrap()
            .scene;
        // A map on the second set: the torus's coordinates turned a quarter and doubled.
        let o = &mut scene.objects[1];
        let uvs1: Vec<glam::Vec2> = o.mesh.uvs().iter().map(|t| glam::Vec2::new(t.y, t.x) * 2.0).collect();
        o.mesh = o.mesh.clone().with_uvs1(uvs1).unwrap();
        o.maps.diffuse.as_mut().unwrap().set = 1;
        assert!(
            scene
                .objects
                .iter()
                .all(|o| o.textured() && o.shading.interpolation == Interpolation::Gouraud)
        );
        assert!(scene.objects[1].maps.normal.is_some() && scene.objects[1].maps.emission.is_some());
        assert!(
            !scene.objects[3].mesh.colors().is_empty(),
            "the quad has vertex colours"
        );
        assert_fast_matches_reference(&scene, model);
    }
}

/// Nearest filtering (`filter = "nearest"`: `GL_NEAREST` both ways, no mipmaps), which the
/// vector sampler reads as one gather of level 0: each wrap, magnified (the close plane) and
/// minified (the far torus), 8- and 16-bit maps, diffuse, specular, emission and bump maps,
/// Phong and Gouraud, vertex colours; coordinates past the vector wrap. The fast path within
/// 1/255 of the reference.
#[test]
fn fast_path_matches_reference_with_nearest_filtering() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenes");
    let (_dir, tinted) = tinted_quad("phong-nearest-maps");
    let src = format!(
        r#"
[image]
width = 220
height = 130
[camera]
position = [0.0, 0.0, 6.0]
[[light]]
type = "point"
position = [2.0, 2.0, 4.0]
[[object]]
shape = "sphere"
position = [-2.2, 0.8, 0.0]
material = {{ base = "brass", diffuse_map = "assets/bricks.png", specular_map = "assets/checker.png", filter = "nearest", uv_scale = [2.0, 1.0] }}
[[object]]
shape = "torus"
position = [0.0, 0.8, -8.0]
rotation = [60.0, 0.0, 0.0]
material = {{ base = "jade", emission = [0.3, 0.2, 0.1], diffuse_map = "assets/checker.png", emission_map = "assets/bricks.png", filter = "nearest", wrap = "mirror", uv_scale = [7.0, 3.0] }}
[[object]]
shape = "plane"
position = [2.2, 0.8, 3.5]
scale = 0.6
rotation = [80.0, 10.0, 0.0]
material = {{ base = "ruby", diffuse_map = "assets/bricks.png", bump_map = "assets/bricks_height.png", filter = "nearest", wrap = "clamp", uv_scale = [1.3, 1.3], uv_offset = [-0.1, -0.1] }}
[[object]]
mesh = "{tinted}"
position = [-2.0, -1.3, 0.5]
scale = 0.6
rotation = [0.0, 30.0, 0.0]
interpolation = "gouraud"
material = {{ base = "pearl", diffuse_map = "assets/bricks.png", filter = "nearest" }}
[[object]]
shape = "teapot"
position = [0.3, -1.4, 0.0]
scale = 0.6
interpolation = "gouraud"
material = {{ base = "gold", specular_map = "assets/checker.png", filter = "nearest" }}
[[object]]
shape = "plane"
position = [2.6, -1.2, 1.0]
scale = 0.5
rotation = [70.0, 0.0, 0.0]
material = {{ base = "chrome", diffuse_map = "assets/checker.png", filter = "nearest", uv_scale = [3.0e5, 3.0e5] }}
"#,
        tinted = tinted.display()
    );
    let mut scene = phong_scene::parse_scene(&src, &root.join("nearest.toml"))
        .unwrap()
        .scene;
    // A 16-bit map of random texels in the sphere's diffuse map's place.
    let mut r = Rng(11);
    let texels: Vec<[u16; 4]> = (0..37 * 23)
        .map(|_| [r.f(), r.f(), r.f()].map(|x| (x * 65535.0) as u16))
        .map(|[a, b, c]| [a, b, c, 65535])
        .collect();
    let sixteen = std::sync::Arc::new(Texture::new(37, 23, &texels, 16).unwrap());
    scene.objects[0].maps.diffuse.as_mut().unwrap().texture = sixteen;
    // Past the vector wrap, nearest filtering is aliasing: the texel is decided by the last
    // bits of the coordinates, which the reference computes in f64. A texture of one colour
    // (8×8) keeps that plane's fallback testable.
    let one = [[40u16 * 257, 160 * 257, 90 * 257, 65535]; 64];
    scene.objects[5].maps.diffuse.as_mut().unwrap().texture = std::sync::Arc::new(Texture::new(8, 8, &one, 8).unwrap());
    assert!(scene.objects.iter().all(|o| {
        let m = &o.maps;
        [&m.diffuse, &m.specular, &m.emission]
            .into_iter()
            .flatten()
            .all(|t| t.sampler == Sampler::nearest(t.sampler.wrap_u))
    }));
    assert_fast_matches_reference(&scene, "nearest");
}

/// Maps of every other combination of filters (glTF's samplers: a nearest mipmap, nearest
/// texels with mipmaps, magnification and minification filters that differ), which the vector
/// kernels sample lane by lane with `phong_core`'s sampler: magnified (the close sphere) and
/// minified (the far torus, the grazing plane), diffuse, specular and emission maps with a
/// transform, Phong and Gouraud. The fast path within 1/255 of the reference.
#[test]
fn fast_path_matches_reference_with_any_filters() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenes");
    let src = in_small_frame(
        r#"
[[object]]
shape = "sphere"
position = [-1.8, 0.6, 2.0]
material = { base = "brass", diffuse_map = "assets/bricks.png", specular_map = "assets/checker.png", uv_scale = [2.0, 1.0] }
[[object]]
shape = "torus"
position = [0.5, 0.8, -9.0]
rotation = [60.0, 0.0, 0.0]
material = { base = "jade", emission = [0.3, 0.2, 0.1], diffuse_map = "assets/checker.png", emission_map = "assets/bricks.png", wrap = "mirror", uv_scale = [7.0, 3.0] }
[[object]]
shape = "plane"
position = [1.8, -1.0, 0.0]
rotation = [82.0, 0.0, 0.0]
material = { base = "ruby", diffuse_map = "assets/bricks.png", wrap = "clamp", uv_scale = [4.0, 4.0] }
[[object]]
shape = "teapot"
position = [-1.0, -1.3, 0.0]
scale = 0.6
interpolation = "gouraud"
material = { base = "gold", diffuse_map = "assets/checker.png", uv_scale = [3.0, 3.0] }
"#,
    );
    let base = phong_scene::parse_scene(&src, &root.join("filters.toml"))
        .unwrap()
        .scene;
    for mag in [Filter::Linear, Filter::Nearest] {
        for min in [Filter::Linear, Filter::Nearest] {
            for mip in [MipFilter::Nearest, MipFilter::Linear, MipFilter::None] {
                let mut scene = base.clone();
                for o in &mut scene.objects {
                    let m = &mut o.maps;
                    for t in [&mut m.diffuse, &mut m.specular, &mut m.emission].into_iter().flatten() {
                        t.sampler = Sampler {
                            mag,
                            min,
                            mip,
                            ..t.sampler
                        };
                    }
                }
                assert_fast_matches_reference(&scene, &format!("{mag:?} {min:?} {mip:?}"));
            }
        }
    }
}

/// Alpha-tested and blended objects on the fast path (visibility with the reference's alpha
/// test, blended objects laid over the shaded image in drawing order) against the reference
/// path, both builds: a map whose alpha crosses the cutoff smoothly (magnified and minified,
/// trilinear), as the diffuse map's alpha and as an alpha map, Phong and Gouraud, vertex
/// colours; blended objects textured and not, overlapping one another and alpha-tested ones,
/// one of them alpha-tested too; one, 4 and 16 samples a pixel; and a transparent background
/// (4 samples), alpha compared.
#[test]
fn fast_path_matches_reference_with_alpha_test_and_blending() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenes");
    let (_dir, tinted) = tinted_quad("phong-alpha-maps");
    let src = format!(
        r#"
[image]
width = 240
height = 150
[camera]
position = [0.0, 0.0, 6.0]
[[light]]
type = "point"
position = [2.0, 2.0, 4.0]
[[object]]
shape = "torus"
position = [0.0, 0.3, -2.0]
material = {{ base = "jade", diffuse_map = "assets/bricks.png", uv_scale = [4.0, 2.0] }}
[[object]]
shape = "plane"
position = [-1.6, 0.6, 1.0]
rotation = [75.0, 20.0, 0.0]
material = {{ base = "brass", diffuse_map = "assets/checker.png", alpha_cutoff = 0.5 }}
[[object]]
shape = "sphere"
position = [1.8, 0.9, 0.5]
interpolation = "gouraud"
material = {{ base = "ruby", diffuse_map = "assets/bricks.png", alpha_map = "assets/leaf.png", uv_scale = [3.0, 2.0] }}
[[object]]
mesh = "{tinted}"
position = [-2.0, -1.2, 1.5]
scale = 0.7
rotation = [0.0, 30.0, 0.0]
material = {{ base = "pearl", alpha_map = "assets/leaf.png", specular_map = "assets/checker.png" }}
[[object]]
shape = "sphere"
position = [0.0, -0.2, 1.0]
scale = 0.8
material = {{ base = "gold", alpha = 0.45, blend = true }}
[[object]]
shape = "plane"
position = [0.6, -0.6, 2.0]
rotation = [80.0, -15.0, 0.0]
material = {{ base = "chrome", alpha = 0.8, blend = true, diffuse_map = "assets/checker.png", uv_scale = [2.0, 2.0] }}
[[object]]
shape = "teapot"
position = [1.7, -1.2, 2.2]
scale = 0.6
interpolation = "gouraud"
material = {{ base = "emerald", alpha = 0.3, blend = true }}
[[object]]
shape = "plane"
position = [-0.4, 1.0, 2.5]
rotation = [70.0, 0.0, 0.0]
scale = 0.8
material = {{ base = "silver", alpha = 0.9, blend = true, diffuse_map = "assets/leaf.png", alpha_map = "assets/leaf.png", alpha_cutoff = 0.4 }}
"#,
        tinted = tinted.display()
    );
    let mut scene = phong_scene::parse_scene(&src, &root.join("alpha.toml")).unwrap().scene;
    // The quad's diffuse map: random colours, an alpha that crosses 0.5 smoothly, 8-bit.
    let mut r = Rng(5);
    let (w, h) = (32u32, 16u32);
    let texels: Vec<[u16; 4]> = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f32 / w as f32, (i / w) as f32 / h as f32);
            let a = 0.5 + 0.5 * (std::f32::consts::TAU * x).sin() * (std::f32::consts::PI * y).cos();
            [r.f(), r.f(), r.f(), a].map(|c| (c * 255.0).round() as u16 * 257)
        })
        .collect();
    let map = &mut scene.objects[1].maps.diffuse.as_mut().unwrap();
    map.texture = std::sync::Arc::new(Texture::new(w, h, &texels, 8).unwrap());
    map.transform = UvTransform::scale_offset(glam::Vec2::new(3.0, 3.0), glam::Vec2::ZERO);
    assert!(scene.objects[1].maps.alpha_cutoff == Some(0.5) && !scene.objects[1].blends());
    assert!(scene.objects[2].maps.alpha_cutoff == Some(0.5));
    assert!((4..8).all(|i| scene.objects[i].blends()));
    for samples in [Samples::One, Samples::Four, Samples::Sixteen] {
        scene.image.samples = samples;
        assert_fast_matches_reference(&scene, &format!("alpha test and blending, {samples:?}"));
    }
    scene.image.samples = Samples::Four;
    // A transparent background: where blended objects lie over it, the alpha too.
    scene.image.background = [0.1, 0.2, 0.3, 0.0];
    let reference = render(
        &scene,
        &RenderOptions {
            reference: true,
            ..Default::default()
        },
    )
    .unwrap();
    let a = reference.to_bytes(scene.image.encoding, true);
    for kernels in [Kernels::Auto, Kernels::Portable] {
        let fast = render(
            &scene,
            &RenderOptions {
                kernels,
                ..Default::default()
            },
        )
        .unwrap();
        let b = fast.to_bytes(scene.image.encoding, true);
        let worst = a.iter().zip(&b).map(|(x, y)| x.abs_diff(*y)).max().unwrap();
        assert!(worst <= 1, "transparent background ({kernels:?}): {worst}/255");
    }
}

/// Textured objects with several samples a pixel (one shading per visible pixel and triangle,
/// at the pixel's centre, by the vector sampler), and flat-shaded objects (their triangles'
/// colours in planes without slope), against the reference path, both builds, 1, 4 and 16
/// samples: diffuse and specular maps, ambient and emission maps, a bump map, a shininess map,
/// Gouraud shading, vertex colours, flat shading textured and not, two-sided, edges between
/// objects and the background.
#[test]
fn fast_path_matches_reference_with_textures_and_several_samples() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenes");
    let (_dir, tinted) = tinted_quad("phong-multi-maps");
    let src = format!(
        r#"
[image]
width = 200
height = 120
[camera]
position = [0.0, 0.0, 6.0]
[[light]]
type = "point"
position = [2.0, 2.0, 4.0]
[[object]]
shape = "sphere"
position = [-2.0, 0.8, 0.0]
material = {{ base = "brass", diffuse_map = "assets/bricks.png", specular_map = "assets/bricks_specular.png", uv_scale = [2.0, 1.0] }}
[[object]]
shape = "torus"
position = [0.0, 0.8, -1.0]
rotation = [60.0, 0.0, 0.0]
material = {{ base = "jade", emission = [0.2, 0.1, 0.0], ambient_map = "assets/checker.png", emission_map = "assets/bricks.png", uv_scale = [6.0, 2.0] }}
[[object]]
shape = "plane"
position = [2.2, 0.8, 1.0]
scale = 0.8
rotation = [70.0, 10.0, 0.0]
material = {{ base = "ruby", diffuse_map = "assets/bricks.png", bump_map = "assets/bricks_height.png", shininess_map = "assets/checker.png" }}
[[object]]
mesh = "{tinted}"
position = [-2.0, -1.3, 0.5]
scale = 0.6
rotation = [0.0, 30.0, 0.0]
interpolation = "gouraud"
material = {{ base = "pearl", diffuse_map = "assets/bricks.png" }}
[[object]]
shape = "teapot"
position = [0.3, -1.3, 0.0]
scale = 0.6
interpolation = "flat"
material = {{ base = "gold", diffuse_map = "assets/checker.png" }}
[[object]]
shape = "cube"
position = [2.3, -1.2, 0.0]
scale = 0.5
rotation = [30.0, 40.0, 0.0]
interpolation = "gouraud"
material = {{ base = "chrome", specular_map = "assets/checker.png", diffuse_map = "assets/bricks.png" }}
[[object]]
shape = "torus"
position = [-0.6, -0.2, 2.5]
scale = 0.5
rotation = [75.0, 0.0, 0.0]
interpolation = "flat"
material = "ruby"
[[object]]
shape = "plane"
position = [1.0, 0.1, 2.0]
scale = 0.6
rotation = [-80.0, 20.0, 0.0]
interpolation = "flat"
material = {{ base = "silver", diffuse_map = "assets/bricks.png" }}
"#,
        tinted = tinted.display()
    );
    let mut scene = phong_scene::parse_scene(&src, &root.join("multi.toml")).unwrap().scene;
    for o in &mut scene.objects[6..] {
        o.shading.options.two_sided = true;
    }
    for samples in [Samples::One, Samples::Four, Samples::Sixteen] {
        scene.image.samples = samples;
        assert_fast_matches_reference(&scene, &format!("{samples:?}"));
    }
}

/// Visibility of triangle soups that cross one another at random depths, one emissive colour
/// per soup and nothing else lit: each pixel is the mean of its samples' triangles' colours,
/// so the images show which triangle each sample kept. With 4 and 16 samples a pixel (many
/// small triangles) and with one (fewer, larger ones, as the AVX2 kernel takes them: 8 pixels a
/// triangle in a tile or more), the AVX2 build's vector coverage must give the portable build's
/// scalar loops and the reference path exactly.
#[test]
fn visibility_is_the_scalar_loops() {
    let mut r = Rng(5);
    for (soup, grid, (w, h), samples) in [
        (300, 150, (157, 93), vec![Samples::Four, Samples::Sixteen]),
        (40, 24, (331, 203), vec![Samples::One, Samples::Four]),
    ] {
        let mut scene = soup_scene(&mut r, soup, grid, (w, h));
        for samples in samples {
            scene.image.samples = samples;
            let image = |reference, kernels| {
                let options = RenderOptions {
                    reference,
                    kernels,
                    threads: Some(2),
                    ..Default::default()
                };
                render(&scene, &options).unwrap().to_bytes(Encoding::Linear, false)
            };
            let avx2 = image(false, Kernels::Auto);
            let lit = avx2.chunks(3).filter(|p| p.iter().any(|&c| c > 0)).count();
            assert!(lit > (w * h / 3) as usize, "{samples:?}: only {lit} pixels drawn");
            assert!(
                avx2 == image(false, Kernels::Portable),
                "{w}x{h} {samples:?}: AVX2 against portable"
            );
            assert!(
                avx2 == image(true, Kernels::Auto),
                "{w}x{h} {samples:?}: AVX2 against the reference"
            );
        }
    }
}

/// Five emissive objects in a `w`×`h` image, each `soup` random triangles (a hundredth of the
/// frame's width to a third of it, some of integer coordinates) and a `grid`×`grid` grid facing
/// the camera at a random depth, shared edges on every side: its rows' and columns' edges
/// project to lines of equal y or x, some of which meet the samples' rows and columns exactly
/// (the top-left rule decides those samples).
fn soup_scene(r: &mut Rng, soup: u32, grid: u32, (w, h): (u32, u32)) -> Scene {
    let mut objects = String::new();
    for _ in 0..5 {
        let c = r.c();
        objects += &format!(
            "[[object]]\nshape = \"sphere\"\nmaterial = {{ ambient = [0.0, 0.0, 0.0], diffuse = [0.0, 0.0, 0.0], \
             emission = [{}, {}, {}] }}\n",
            c.r, c.g, c.b
        );
    }
    let src = format!(
        "[image]\nwidth = {w}\nheight = {h}\n[camera]\nposition = [0.0, 0.0, 6.0]\n[shading]\nambient = [0.0, 0.0, 0.0]\n{objects}"
    );
    let mut scene = phong_scene::parse_scene(&src, Path::new("soup.toml")).unwrap().scene;
    for o in &mut scene.objects {
        let mut positions = Vec::new();
        for k in 0..soup as usize {
            let centre = r.v(2.5);
            let size = [0.01, 0.1, 1.5][k % 3];
            for _ in 0..3 {
                let p = centre + r.v(size);
                positions.push(if k % 7 == 0 { (p * 4.0).round() / 4.0 } else { p });
            }
        }
        let mut triangles: Vec<[u32; 3]> = (0..soup).map(|k| [3 * k, 3 * k + 1, 3 * k + 2]).collect();
        let (n, at) = (grid, positions.len() as u32);
        let z = r.r(-2.0, 0.0);
        for j in 0..=n {
            for i in 0..=n {
                positions.push(Vec3::new(i as f32, j as f32, 0.0) * (7.0 / n as f32) - Vec3::new(3.5, 3.5, -z));
            }
        }
        for j in 0..n {
            for i in 0..n {
                let v = at + j * (n + 1) + i;
                if (i + j + at) % 5 != 0 {
                    triangles.extend([[v, v + 1, v + n + 2], [v, v + n + 2, v + n + 1]]);
                }
            }
        }
        let normals = vec![Vec3::Z; positions.len()];
        o.mesh = Mesh::new(positions, normals, triangles).unwrap();
    }
    scene
}
