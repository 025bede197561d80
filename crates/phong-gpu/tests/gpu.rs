//! The GPU backend against the core crate and the CPU renderer.
//!
//! Without a GPU adapter these tests print why they were skipped and pass; with
//! `PHONG_REQUIRE_GPU=1` (CI, on Mesa's lavapipe) a missing adapter is a failure.

use glam::Vec3;
use phong_core::*;
use phong_gpu::{Gpu, GpuPath};
use std::path::Path;

fn gpu() -> Option<Gpu> {
    match Gpu::new() {
        Ok(g) => {
            eprintln!("GPU adapter: {}", g.adapter_name());
            Some(g)
        }
        Err(e) if std::env::var_os("PHONG_REQUIRE_GPU").is_some() => {
            panic!("PHONG_REQUIRE_GPU is set but: {e}")
        }
        Err(e) => {
            eprintln!("skipped: {e}");
            None
        }
    }
}

struct Rng(u64);
impl Rng {
    fn f(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
    fn range(&mut self, a: f32, b: f32) -> f32 {
        a + (b - a) * self.f()
    }
    fn vec(&mut self, r: f32) -> Vec3 {
        Vec3::new(self.range(-r, r), self.range(-r, r), self.range(-r, r))
    }
    fn color(&mut self) -> Color {
        Color::new(self.f(), self.f(), self.f())
    }
    fn pick<T: Copy>(&mut self, v: &[T]) -> T {
        v[((self.f() * v.len() as f32) as usize).min(v.len() - 1)]
    }
}

/// The WGSL port of `shade` against `phong_core::shade` on 4000 random cases: every model,
/// normalization, option and light type. Tolerance: 1e-4 absolute, or 1e-4 relative for
/// unclamped values above 1 (f32 `pow`, `sqrt` and division may differ by a few ulps on a
/// GPU; the specular power amplifies that near grazing angles).
#[test]
fn wgsl_shade_matches_core() {
    let Some(gpu) = gpu() else { return };
    let mut r = Rng(7);
    let models = [
        SpecularModel::None,
        SpecularModel::Phong,
        SpecularModel::BlinnPhong,
        SpecularModel::Lyon {
            squarings: 3,
            lambda: LyonLambda::Dot,
        },
        SpecularModel::Lyon {
            squarings: 5,
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
    for set in 0..8 {
        let mut lights = Vec::new();
        for _ in 0..(1 + set % 4) {
            let color = LightColor::new(r.color() * 0.3, r.color(), r.color()).unwrap();
            let att = Attenuation::new(r.range(0.5, 2.0), r.range(0.0, 0.5), r.range(0.0, 0.2)).unwrap();
            lights.push(match r.pick(&[0, 1, 2]) {
                0 => Light::directional(r.vec(1.0) + Vec3::splat(0.01), color).unwrap(),
                1 => Light::point(r.vec(4.0), color, att).unwrap(),
                _ => Light::spot(
                    r.vec(4.0),
                    r.vec(1.0) + Vec3::splat(0.01),
                    r.range(5.0, 90.0),
                    r.range(0.0, 20.0),
                    color,
                    att,
                )
                .unwrap(),
            });
        }
        let lighting = Lighting::new(r.color() * 0.3, lights).unwrap();
        let mut cases = Vec::new();
        for _ in 0..500 {
            let m = Material::new(r.color(), r.color(), r.color(), r.color() * 0.2, r.range(0.0, 200.0)).unwrap();
            let options = ShadingOptions {
                specular: r.pick(&models),
                gate_specular: r.f() < 0.7,
                clamp: r.f() < 0.5,
                normalization: r.pick(&norms),
                two_sided: r.f() < 0.3,
            };
            let settings = ShadingSettings {
                options,
                interpolation: Interpolation::Phong,
                viewer: Viewer::Local,
                output: Output::Color,
            };
            let view = if r.f() < 0.5 {
                View::Local { eye: r.vec(6.0) }
            } else {
                View::Infinite { to_viewer: r.vec(1.0) }
            };
            let p = SurfacePoint {
                position: r.vec(2.0),
                normal: if r.f() < 0.02 { Vec3::ZERO } else { r.vec(1.0) },
            };
            cases.push((p, m, settings, view));
        }
        let got = gpu.shade_cases(&lighting, &cases).unwrap();
        for ((p, m, s, v), g) in cases.iter().zip(&got) {
            let want = shade(p, v, m, &lighting, &s.options);
            for (a, b) in [
                (g.ambient, want.ambient),
                (g.diffuse, want.diffuse),
                (g.specular, want.specular),
                (g.color, want.color),
            ] {
                for (x, y) in a.to_array().into_iter().zip(b.to_array()) {
                    let err = (x - y).abs() / y.abs().max(1.0);
                    worst = worst.max(err);
                    assert!(err < 1e-4, "case {p:?} {m:?} {s:?} {v:?}: gpu {g:?} core {want:?}");
                }
            }
        }
    }
    eprintln!("largest WGSL vs core difference: {worst:e}");
}

fn load(name: &str) -> Scene {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/scenes")
        .join(name);
    phong_scene::load(&p).unwrap().scene
}

/// The example scenes' file names.
fn example_names() -> Vec<String> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenes");
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| {
            let n = e.unwrap().file_name().to_string_lossy().into_owned();
            n.ends_with(".toml").then_some(n)
        })
        .collect();
    names.sort();
    assert!(names.len() >= 7);
    names
}

/// Pixels of the GPU image `gimg` more than `tolerance`/255 from the CPU image of `scene`
/// in some channel (8-bit encoded), and the largest difference. Above `max_fraction` of the
/// pixels, the GPU image and a difference image are written to the temporary directory and
/// the test fails.
fn compare(name: &str, scene: &Scene, gimg: &Image, tolerance: u8, max_fraction: f64) -> (usize, u8) {
    let cpu = phong_raster::render(scene, &Default::default()).unwrap();
    let enc = scene.image.encoding;
    let alpha = cpu.has_transparency();
    let (a, b) = (cpu.to_bytes(enc, alpha), gimg.to_bytes(enc, alpha));
    let ch = if alpha { 4 } else { 3 };
    let worst = a.iter().zip(&b).map(|(p, q)| p.abs_diff(*q)).max().unwrap_or(0);
    let bad = a
        .chunks(ch)
        .zip(b.chunks(ch))
        .filter(|(x, y)| x.iter().zip(y.iter()).any(|(p, q)| p.abs_diff(*q) > tolerance))
        .count();
    let total = (scene.image.width * scene.image.height) as usize;
    let frac = bad as f64 / total as f64;
    eprintln!(
        "{name}: {bad} of {total} pixels differ by more than {tolerance}/255 ({:.3}%), at most {worst}/255",
        frac * 100.0
    );
    if frac > max_fraction {
        let out = std::env::temp_dir();
        let write = |file: &str, data: &[u8]| {
            let f = std::fs::File::create(out.join(file)).unwrap();
            let mut e = png::Encoder::new(f, scene.image.width, scene.image.height);
            e.set_color(if alpha {
                png::ColorType::Rgba
            } else {
                png::ColorType::Rgb
            });
            e.write_header().unwrap().write_image_data(data).unwrap();
        };
        write(&format!("{name}.gpu.png"), &b);
        let diff: Vec<u8> = a
            .iter()
            .zip(&b)
            .map(|(p, q)| p.abs_diff(*q).saturating_mul(32))
            .collect();
        write(&format!("{name}.diff.png"), &diff);
        panic!("{name}: {bad} pixels differ; images in {}", out.display());
    }
    (bad, worst)
}

/// Every example scene on both backends, through the render pipeline: at least 99.5% of
/// pixels within 2/255 per channel (8-bit encoded), the rest on silhouettes and edges. On
/// failure the GPU image and a difference image are written to the temporary directory.
#[test]
fn example_scenes_match_the_cpu() {
    let Some(mut gpu) = gpu() else { return };
    gpu.set_path(GpuPath::Pipeline);
    for name in example_names() {
        let mut scene = load(&name);
        scene.image.width = 320;
        scene.image.height = 200;
        let (gimg, stats) = gpu.render(&scene).unwrap();
        assert!(!stats.compute);
        compare(&name, &scene, &gimg, 2, 0.005);
    }
}

/// The compute rasterizer does the CPU's arithmetic (snapping, 64-bit edges, top-left rule,
/// depth ties to the first triangle, the CPU's sample patterns, one shading per pixel and
/// triangle at the pixel's centre, the same resolve), so it is held closer: every example
/// scene, at one sample per pixel and at its own count, at least 99.9% of pixels within 1/255
/// (lavapipe and an H100: all of them). Scenes it cannot draw are named; at least half of the
/// examples must be drawn by it.
#[test]
fn compute_rasterizer_matches_the_cpu() {
    let Some(mut gpu) = gpu() else { return };
    gpu.set_path(GpuPath::Compute);
    let names = example_names();
    let mut drawn = 0;
    for name in &names {
        let scene = load(name);
        for samples in [Samples::One, scene.image.samples, Samples::Sixteen] {
            let mut scene = scene.clone();
            scene.image.width = 320;
            scene.image.height = 200;
            scene.image.samples = samples;
            if let Some(why) = gpu.compute_reason(&scene) {
                if why.contains("64-bit atomics") {
                    eprintln!("skipped: {why}");
                    return;
                }
                eprintln!("{name}: not drawn by the compute rasterizer: {why}");
                assert!(gpu.render(&scene).unwrap_err().to_string().contains(&why));
                continue;
            }
            let (gimg, stats) = gpu.render(&scene).unwrap();
            assert!(stats.compute);
            compare(&format!("{name} ({samples} samples)"), &scene, &gimg, 1, 0.001);
            drawn += 1;
        }
    }
    assert!(2 * drawn >= 3 * names.len(), "{drawn} of {}", 3 * names.len());
}

/// The automatic path: the compute rasterizer on a GPU, the pipeline on a CPU adapter.
#[test]
fn automatic_path_follows_the_adapter() {
    let Some(gpu) = gpu() else { return };
    let mut scene = load("terms.toml");
    scene.image.width = 160;
    scene.image.height = 100;
    let (_, stats) = gpu.render(&scene).unwrap();
    let on_cpu = gpu.is_cpu_adapter();
    assert_eq!(
        stats.compute,
        !on_cpu && gpu.compute_reason(&scene).is_none(),
        "{}",
        gpu.adapter_name()
    );
}

/// A frame whose visibility buffer would exceed the adapter's storage buffers is not for the
/// compute rasterizer (the automatic paths then take the pipeline); the reason says so.
#[test]
fn compute_rasterizer_respects_buffer_limits() {
    let Some(gpu) = gpu() else { return };
    let mut scene = load("terms.toml");
    scene.image.samples = Samples::One;
    let max = gpu.max_storage_bytes();
    // The smallest square whose 8-byte-per-pixel visibility buffer exceeds the limit.
    let side = (((max / 8) as f64).sqrt() as u64 + 1) as u32;
    if side > phong_core::limits::MAX_IMAGE_DIMENSION {
        eprintln!("skipped: this adapter's storage buffers hold any image ({max} bytes)");
        return;
    }
    for (s, over) in [(side - 1, false), (side, true)] {
        scene.image.width = s;
        scene.image.height = s;
        // (At this size some objects may also reach far off screen: a later reason.)
        let why = gpu.compute_reason(&scene).unwrap_or_default();
        assert_eq!(why.contains("visibility buffer"), over, "{s}: {why}");
        assert_eq!(why.contains("storage buffer limit"), over, "{s}: {why}");
    }
}

/// A frame whose large triangles' tiles overflow the compute rasterizer's list is drawn again
/// by the pipeline (compute preferred), or is an error (compute path asked for).
#[test]
fn compute_overflow_falls_back_to_the_pipeline() {
    let Some(mut gpu) = gpu() else { return };
    gpu.set_path(GpuPath::PreferCompute);
    // A full-screen quad of two triangles, each boxing the whole image: 2 × 20 × 13 tiles of
    // 16×16 at 320×200.
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../benches/scenes/fill_4lights.toml");
    let mut scene = phong_scene::load(&p).unwrap().scene;
    scene.image.width = 320;
    scene.image.height = 200;
    scene.image.samples = Samples::One;
    if let Some(why) = gpu.compute_reason(&scene) {
        eprintln!("skipped: {why}");
        return;
    }
    // With room for every tile: drawn by the compute rasterizer.
    gpu.set_item_capacity(520);
    let (gimg, stats) = gpu.render(&scene).unwrap();
    assert!(stats.compute);
    compare("fill_4lights.toml (compute)", &scene, &gimg, 1, 0.0);
    gpu.set_item_capacity(519);
    let (gimg, stats) = gpu.render(&scene).unwrap();
    assert!(!stats.compute);
    compare("fill_4lights.toml (fallen back)", &scene, &gimg, 2, 0.005);
    gpu.set_path(GpuPath::Compute);
    let e = gpu.render(&scene).unwrap_err().to_string();
    assert!(e.contains("overflowed"), "{e}");
}

/// Where the adapter has timestamp queries, each render reports its pass's GPU time, and that
/// time lies inside the wall-clock interval from submitting the pass to its completion.
#[test]
fn pass_time_lies_within_the_render() {
    let Some(mut gpu) = gpu() else { return };
    let scene = load("terms.toml");
    let (_, stats) = gpu.render(&scene).unwrap();
    if !gpu.has_timestamps() {
        assert!(stats.gpu_pass.is_none());
        eprintln!("skipped: the adapter has no timestamp queries");
        return;
    }
    let pass = stats.gpu_pass.expect("a timed pass");
    assert!(pass > std::time::Duration::ZERO, "{pass:?}");
    // 1 ms of slack for the GPU's clock against the CPU's.
    let slack = std::time::Duration::from_millis(1);
    assert!(pass <= stats.render + slack, "{pass:?} > {:?}", stats.render);
    // The compute rasterizer's kernels, each in its own pass: all seven, in order, within the
    // frame's span on the GPU, itself within the wall-clock draw.
    let mut scene = scene;
    scene.image.samples = Samples::One;
    if gpu.compute_reason(&scene).is_none() {
        gpu.set_path(GpuPath::Compute);
        let prepared = gpu.prepare(&scene).unwrap();
        assert!(prepared.is_compute());
        assert!(gpu.draw(&prepared).unwrap().stages.is_empty());
        let drawn = gpu.draw_stages(&prepared).unwrap();
        let names: Vec<&str> = drawn.stages.iter().map(|s| s.0).collect();
        assert_eq!(
            names,
            [
                "cs_clear",
                "cs_vertex",
                "cs_raster",
                "cs_args",
                "cs_expand",
                "cs_tiles",
                "cs_shade"
            ]
        );
        let total = drawn.gpu.unwrap();
        let sum: std::time::Duration = drawn.stages.iter().map(|s| s.1).sum();
        assert!(sum <= total, "{sum:?} > {total:?}");
        assert!(total <= drawn.wall + slack, "{total:?} > {:?}", drawn.wall);
    }
}

#[test]
fn bad_requests_are_errors_not_panics() {
    let Some(gpu) = gpu() else { return };
    let mut scene = load("terms.toml");
    scene.image.width = 1_000_000;
    let e = gpu.render(&scene).unwrap_err();
    assert!(e.is_input() && e.to_string().contains("cannot be rendered"), "{e}");
    // 16384² pixels at 16 samples would need about 50 GB of attachments: refused up front, by
    // the core crate's check of the image, the CPU renderer's too.
    scene.image.width = 16384;
    scene.image.height = 16384;
    scene.image.samples = Samples::Sixteen;
    let e = gpu.render(&scene).unwrap_err();
    assert!(e.is_input() && e.to_string().contains("cannot be rendered"), "{e}");
}

/// Two-sided lighting by polygon facing on the GPU too: the example tour with two-sided
/// lighting and the camera under the floor plane (its back face in view) matches the CPU.
#[test]
fn two_sided_back_faces_match_the_cpu() {
    let Some(gpu) = gpu() else { return };
    let mut scene = load("tour.toml");
    scene.image.width = 200;
    scene.image.height = 150;
    scene.camera = Camera::new(
        Vec3::new(0.5, -3.0, 3.0),
        Vec3::ZERO,
        Vec3::Y,
        Projection::Perspective { fov_y_deg: 50.0 },
        0.1,
        50.0,
    )
    .unwrap();
    for interp in [Interpolation::Flat, Interpolation::Gouraud, Interpolation::Phong] {
        for o in &mut scene.objects {
            o.shading.options.two_sided = true;
            o.shading.interpolation = interp;
        }
        let cpu = phong_raster::render(&scene, &Default::default()).unwrap();
        let (g, _) = gpu.render(&scene).unwrap();
        let (a, b) = (
            cpu.to_bytes(Encoding::Linear, false),
            g.to_bytes(Encoding::Linear, false),
        );
        let bad = a
            .chunks(3)
            .zip(b.chunks(3))
            .filter(|(x, y)| x.iter().zip(y.iter()).any(|(p, q)| p.abs_diff(*q) > 2))
            .count();
        assert!(bad * 200 < 200 * 150, "{interp:?}: {bad} pixels differ");
    }
}

/// A smooth random 8-bit texture: `cell` texels a value.
fn random_texture(r: &mut Rng, w: u32, h: u32, cell: u32) -> std::sync::Arc<Texture> {
    let cw = w.div_ceil(cell);
    let grid: Vec<[u16; 4]> = (0..cw * h.div_ceil(cell))
        .map(|_| {
            let c = r.color();
            let [x, y, z] = [c.r, c.g, c.b].map(|v| (v * 255.0).round() as u16 * 257);
            [x, y, z, 65535]
        })
        .collect();
    let texels: Vec<[u16; 4]> = (0..w * h)
        .map(|i| grid[((i / w / cell) * cw + (i % w) / cell) as usize])
        .collect();
    std::sync::Arc::new(Texture::new(w, h, &texels, 8).unwrap())
}

/// A sphere and a floor below it, each with `material` and `maps`, shaded as `scene`'s first
/// object: the textured tests' objects.
fn sphere_and_floor(scene: &Scene, material: Material, maps: &Maps) -> Vec<Object> {
    let floor = primitives::plane(8).transformed(&glam::Mat4::from_scale_rotation_translation(
        Vec3::splat(4.0),
        glam::Quat::IDENTITY,
        Vec3::new(0.0, -1.0, 0.0),
    ));
    let shading = scene.objects[0].shading;
    [primitives::sphere(48), floor]
        .into_iter()
        .map(|mesh| Object {
            name: "textured".into(),
            mesh,
            material,
            shading,
            maps: maps.clone(),
        })
        .collect()
}

/// The textured tests' scene (the tour at 200×150) and material (grey, shininess 30).
fn textured_scene() -> (Scene, Material) {
    let mut scene = load("tour.toml");
    scene.image.width = 200;
    scene.image.height = 150;
    let material = Material::new(
        Color::splat(0.3),
        Color::splat(0.9),
        Color::splat(0.6),
        Color::BLACK,
        30.0,
    )
    .unwrap();
    (scene, material)
}

/// Textured objects on the GPU (the render pipeline, its textures, samplers and the CPU's
/// mipmaps) against the CPU: a sphere and a floor with a diffuse and a specular map, each
/// interpolation, magnified with bilinear filtering and minified with trilinear. Where the
/// level of detail agrees (bilinear: one level) the images agree within 2/255 but on
/// silhouettes; minified, the GPU's level of detail comes from differences over 2×2 pixel
/// quads, the CPU's from exact derivatives at the pixel's centre. Measured on lavapipe (200×150):
/// bilinear 0.04–0.05% of pixels beyond 2/255 (at most 24/255, on silhouettes); trilinear
/// 3.7–4.2% (at most 8/255). Asserted: 0.2% and 6%, and at most 12/255 minified.
#[test]
fn textured_objects_match_the_cpu() {
    let Some(gpu) = gpu() else { return };
    let mut r = Rng(11);
    let (mut scene, material) = textured_scene();
    for (sampler, repeat, bound, largest) in [
        (Sampler::bilinear(Wrap::Repeat), 1.0, 0.002, 255),
        (Sampler::trilinear(Wrap::Repeat), 16.0, 0.06, 12),
    ] {
        let diffuse = random_texture(&mut r, 32, 16, 2);
        let specular = random_texture(&mut r, 64, 64, 4);
        let map = |t: &std::sync::Arc<Texture>| TextureMap {
            texture: t.clone(),
            sampler,
            transform: UvTransform::scale_offset(glam::Vec2::splat(repeat), glam::Vec2::ZERO),
            set: 0,
        };
        let maps = Maps {
            diffuse: Some(map(&diffuse)),
            specular: Some(map(&specular)),
            ..Maps::default()
        };
        scene.objects = sphere_and_floor(&scene, material, &maps);
        for interp in [Interpolation::Flat, Interpolation::Gouraud, Interpolation::Phong] {
            for o in &mut scene.objects {
                o.shading.interpolation = interp;
            }
            let (g, _) = gpu.render(&scene).unwrap();
            let name = format!("textured {:?} ×{repeat} {interp:?}", sampler.mip);
            let (_, worst) = compare(&name, &scene, &g, 2, bound);
            assert!(worst <= largest, "{name}: a pixel differs by {worst}/255");
        }
    }
}

/// Maps on both sets of texture coordinates on the GPU against the CPU: the sphere and floor of
/// `textured_objects_match_the_cpu`, their second set their first scaled by (2, 3) and
/// shifted, a diffuse map on the second set and a specular map on the first, bilinear, each
/// interpolation. Measured on lavapipe (200×150): 0.043–0.053% of pixels beyond 2/255 (at
/// most 29/255, on silhouettes); with the shader reading the first set for every map, 57%.
/// Asserted as that test's bilinear case: 0.2%.
#[test]
fn maps_on_the_second_set_match_the_cpu() {
    let Some(gpu) = gpu() else { return };
    let mut r = Rng(23);
    let (mut scene, material) = textured_scene();
    let map = |t: std::sync::Arc<Texture>, set: u8| TextureMap {
        texture: t,
        sampler: Sampler::bilinear(Wrap::Repeat),
        transform: UvTransform::default(),
        set,
    };
    let maps = Maps {
        diffuse: Some(map(random_texture(&mut r, 32, 16, 2), 1)),
        specular: Some(map(random_texture(&mut r, 64, 64, 4), 0)),
        ..Maps::default()
    };
    scene.objects = sphere_and_floor(&scene, material, &maps);
    for o in &mut scene.objects {
        let second = o
            .mesh
            .uvs()
            .iter()
            .map(|uv| *uv * glam::Vec2::new(2.0, 3.0) + glam::Vec2::new(0.1, 0.3))
            .collect();
        o.mesh = std::mem::take(&mut o.mesh).with_uvs1(second).unwrap();
    }
    for interp in [Interpolation::Flat, Interpolation::Gouraud, Interpolation::Phong] {
        for o in &mut scene.objects {
            o.shading.interpolation = interp;
        }
        let (g, _) = gpu.render(&scene).unwrap();
        compare(&format!("second set {interp:?}"), &scene, &g, 2, 0.002);
    }
}

/// glTF's metallic-roughness and occlusion maps on the GPU against the CPU: the sphere and
/// floor of `textured_objects_match_the_cpu` with a base colour, a metallic-roughness and an
/// occlusion map, and an emission kept apart (the glTF loader's), bilinear, each
/// interpolation. Measured on lavapipe (200×150): 0.013–0.037% of pixels beyond 2/255 (at most
/// 6/255). Asserted: 0.3% of pixels beyond 2/255.
#[test]
fn metal_rough_and_occlusion_match_the_cpu() {
    let Some(gpu) = gpu() else { return };
    let mut r = Rng(17);
    let mut scene = load("tour.toml");
    scene.image.width = 200;
    scene.image.height = 150;
    let map = |t: std::sync::Arc<Texture>| TextureMap {
        texture: t,
        sampler: Sampler::bilinear(Wrap::Repeat),
        transform: UvTransform::default(),
        set: 0,
    };
    let mr = MetalRough {
        map: map(random_texture(&mut r, 16, 8, 2)),
        base_factor: Color::new(0.9, 0.8, 0.7),
        metallic: 0.8,
        roughness: 0.7,
    };
    let white = std::sync::Arc::new(Texture::new(1, 1, &[[65535; 4]], 8).unwrap());
    let maps = Maps {
        diffuse: Some(map(random_texture(&mut r, 32, 16, 2))),
        metal_rough: Some(mr.clone()),
        occlusion: Some(Occlusion {
            map: map(random_texture(&mut r, 8, 8, 1)),
            strength: 0.8,
        }),
        emission: Some(map(white)),
        ..Maps::default()
    };
    let material = mr.material(Color::new(0.05, 0.0, 0.0), 1.0);
    scene.objects = sphere_and_floor(&scene, material, &maps);
    for interp in [Interpolation::Flat, Interpolation::Gouraud, Interpolation::Phong] {
        for o in &mut scene.objects {
            o.shading.interpolation = interp;
        }
        let (g, _) = gpu.render(&scene).unwrap();
        compare(&format!("metal-rough {interp:?}"), &scene, &g, 2, 0.003);
    }
}

/// Blended objects on the GPU (the render pipeline's premultiplied blending, drawn in the
/// scene's draw order) against the CPU: two blended quads over an opaque one, listed out of
/// order, and one over a transparent background (the pixel's alpha), within 1/255.
#[test]
fn blended_objects_match_the_cpu() {
    let Some(gpu) = gpu() else { return };
    let quad = |z: f32, e: Color, alpha: f32, blend: bool| {
        let mut scene = load("tour.toml");
        let mut o = scene.objects.swap_remove(0);
        o.mesh = primitives::plane(1).transformed(&glam::Mat4::from_rotation_translation(
            glam::Quat::from_rotation_x(std::f32::consts::FRAC_PI_2),
            Vec3::new(0.0, 0.0, z),
        ));
        o.material = Material::new(Color::BLACK, Color::BLACK, Color::BLACK, e, 1.0)
            .unwrap()
            .with_alpha(alpha)
            .unwrap();
        o.maps = Maps {
            blend,
            ..Maps::default()
        };
        o.shading.options.two_sided = true;
        o
    };
    let (red, green, blue) = (
        Color::new(1.0, 0.0, 0.0),
        Color::new(0.0, 1.0, 0.0),
        Color::new(0.0, 0.0, 1.0),
    );
    for (objects, background) in [
        (
            vec![
                quad(0.0, green, 0.5, true),
                quad(-0.5, red, 1.0, false),
                quad(-0.25, blue, 0.5, true),
            ],
            [0.0, 0.0, 0.0, 1.0],
        ),
        (vec![quad(0.0, blue, 0.25, true)], [0.2, 0.2, 0.2, 0.0]),
    ] {
        let mut scene = load("tour.toml");
        scene.image.width = 64;
        scene.image.height = 48;
        scene.image.background = background;
        scene.objects = objects;
        let cpu = phong_raster::render(&scene, &Default::default()).unwrap();
        let (g, _) = gpu.render(&scene).unwrap();
        let (a, b) = (cpu.to_bytes(Encoding::Linear, true), g.to_bytes(Encoding::Linear, true));
        let worst = a.iter().zip(&b).map(|(x, y)| x.abs_diff(*y)).max().unwrap();
        assert!(
            worst <= 1,
            "background {background:?}: a channel differs by {worst}/255"
        );
        let c = cpu.get(32, 24);
        assert!(c[3] > 0.2, "the quads cover the centre: {c:?}");
    }
}

/// Vertex colours on the GPU against the CPU: the tour's objects with a colour per vertex
/// (from its position), each interpolation; at most 0.5% of pixels beyond 2/255 (silhouettes).
#[test]
fn vertex_colours_match_the_cpu() {
    let Some(gpu) = gpu() else { return };
    let mut scene = load("tour.toml");
    scene.image.width = 160;
    scene.image.height = 120;
    for o in &mut scene.objects {
        let colors = o
            .mesh
            .positions()
            .iter()
            .map(|p| Color::new(p.x.sin() * 0.5 + 0.5, p.y.cos() * 0.5 + 0.5, 0.5))
            .collect();
        o.mesh = o.mesh.clone().with_colors(colors).unwrap();
    }
    for interp in [Interpolation::Flat, Interpolation::Gouraud, Interpolation::Phong] {
        for o in &mut scene.objects {
            o.shading.interpolation = interp;
        }
        let (g, _) = gpu.render(&scene).unwrap();
        compare(&format!("vertex colours {interp:?}"), &scene, &g, 2, 0.005);
    }
}

/// Normal maps on the GPU against the CPU: the sphere and floor with MikkTSpace tangents and
/// a smooth random normal map, per-pixel shading, bilinear (one level, so the level of detail
/// does not enter). Measured on lavapipe: 0.31% of pixels beyond 2/255 (at most 17/255, where
/// the random map's normals turn sharply between texels). Asserted: 0.5%.
#[test]
fn normal_maps_match_the_cpu() {
    let Some(gpu) = gpu() else { return };
    let mut r = Rng(5);
    let mut scene = load("tour.toml");
    scene.image.width = 200;
    scene.image.height = 150;
    let shading = scene.objects[0].shading;
    let normals = random_texture(&mut r, 16, 16, 4);
    let material = Material::new(
        Color::splat(0.2),
        Color::splat(0.8),
        Color::splat(0.5),
        Color::BLACK,
        20.0,
    )
    .unwrap();
    let meshes = [
        primitives::sphere(48),
        primitives::plane(8).transformed(&glam::Mat4::from_scale_rotation_translation(
            Vec3::splat(4.0),
            glam::Quat::IDENTITY,
            Vec3::new(0.0, -1.0, 0.0),
        )),
    ];
    scene.objects = meshes
        .into_iter()
        .map(|mesh| Object {
            name: "normal-mapped".into(),
            mesh: mesh.with_mikktspace_tangents(),
            material,
            shading: ShadingSettings {
                interpolation: Interpolation::Phong,
                ..shading
            },
            maps: Maps {
                normal: Some(NormalMap {
                    map: TextureMap {
                        texture: normals.clone(),
                        sampler: Sampler::bilinear(Wrap::Repeat),
                        transform: UvTransform::default(),
                        set: 0,
                    },
                    scale: 1.0,
                    green_down: false,
                }),
                ..Maps::default()
            },
        })
        .collect();
    let (g, _) = gpu.render(&scene).unwrap();
    compare("normal maps", &scene, &g, 2, 0.005);
}

/// Textures are uploaded once per texture, not per frame: a second frame of the same scene is
/// the same image; a scene whose map is a new texture (the same address possible once the
/// old one is freed) draws the new one.
#[test]
fn textures_are_kept_between_frames_and_replaced_when_new() {
    let Some(gpu) = gpu() else { return };
    let mut scene = load("tour.toml");
    scene.image.width = 64;
    scene.image.height = 48;
    let one = |rgb: [u16; 3]| std::sync::Arc::new(Texture::new(1, 1, &[[rgb[0], rgb[1], rgb[2], 65535]], 8).unwrap());
    let set = |scene: &mut Scene, t: std::sync::Arc<Texture>| {
        for o in &mut scene.objects {
            o.maps.diffuse = Some(TextureMap::new(t.clone()));
        }
    };
    set(&mut scene, one([65535, 0, 0]));
    let (a, _) = gpu.render(&scene).unwrap();
    let (b, _) = gpu.render(&scene).unwrap();
    assert_eq!(a.to_bytes(Encoding::Linear, false), b.to_bytes(Encoding::Linear, false));
    set(&mut scene, one([0, 0, 65535]));
    let (c, _) = gpu.render(&scene).unwrap();
    let cpu = phong_raster::render(&scene, &Default::default()).unwrap();
    let (x, y) = (
        cpu.to_bytes(Encoding::Linear, false),
        c.to_bytes(Encoding::Linear, false),
    );
    let worst = x.iter().zip(&y).map(|(p, q)| p.abs_diff(*q)).max().unwrap();
    let red = y.chunks(3).filter(|p| p[0] > 40 && p[2] < 10).count();
    assert!(
        red == 0,
        "{red} pixels still drawn with the old texture (largest difference {worst})"
    );
    assert!(y.chunks(3).any(|p| p[2] > 40), "the new texture is drawn");
}
