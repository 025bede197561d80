//! The rasteriser against closed-form images and the core crate's `shade`.

mod common;

use glam::{Mat4, Vec3};
use phong_core::*;
use phong_raster::{RenderOptions, coverage_counts, sample_pattern};

fn ortho_camera(height: f32) -> Camera {
    Camera::new(
        Vec3::new(0.0, 0.0, 5.0),
        Vec3::ZERO,
        Vec3::Y,
        Projection::Orthographic { height },
        0.1,
        10.0,
    )
    .unwrap()
}

/// A scene of `objects`, each shaded with `interp` and the camera's default viewer.
fn scene(w: u32, h: u32, camera: Camera, mut objects: Vec<Object>, lighting: Lighting, interp: Interpolation) -> Scene {
    for o in &mut objects {
        o.shading.interpolation = interp;
        o.shading.viewer = camera.default_viewer();
    }
    Scene {
        image: ImageSettings {
            width: w,
            height: h,
            background: [0.0, 0.0, 0.0, 1.0],
            samples: Samples::One,
            encoding: Encoding::Linear,
        },
        camera,
        lighting,
        objects,
        labels: Vec::new(),
    }
}

fn obj(mesh: Mesh, material: Material) -> Object {
    Object {
        name: "test".into(),
        mesh,
        material,
        shading: ShadingSettings {
            options: ShadingOptions::default(),
            interpolation: Interpolation::Phong,
            viewer: Viewer::Local,
            output: Output::Color,
        },
        maps: Default::default(),
    }
}

fn render(s: &Scene, o: &RenderOptions) -> Result<Image, phong_raster::Error> {
    phong_raster::render(s, o)
}

/// Changes every object's shading settings.
fn each(s: &mut Scene, f: impl Fn(&mut ShadingSettings)) {
    for o in &mut s.objects {
        f(&mut o.shading);
    }
}

fn one_light(dir: Vec3) -> Lighting {
    Lighting::new(
        Color::splat(0.2),
        vec![Light::directional(dir, LightColor::default()).unwrap()],
    )
    .unwrap()
}

fn px(img: &Image, x: u32, y: u32) -> Vec3 {
    let p = img.get(x, y);
    Vec3::new(p[0], p[1], p[2])
}

/// World-space point at pixel centre (x, y) on the z = 0 plane, for `ortho_camera(height)` and a
/// square image of `n` pixels.
fn ortho_world(x: u32, y: u32, n: u32, height: f32) -> (f32, f32) {
    let s = height / n as f32;
    ((x as f32 + 0.5) * s - height / 2.0, height / 2.0 - (y as f32 + 0.5) * s)
}

/// An orthographic unit sphere lit by one directional light against the closed-form image:
/// at pixel centre (x, y) inside the disc the true sphere has P = N = (x, y, √(1 − x² − y²)).
/// Measured with 256 segments, Phong interpolation, 200×200: largest error 0.00041 per channel
/// over 24916 pixels (the tessellation: interpolated positions and normals are chords of the
/// sphere); asserted 0.001.
#[test]
fn orthographic_sphere_matches_closed_form() {
    let (n, height) = (200u32, 2.2f32);
    let m = Material::named("gold").unwrap();
    let light = Vec3::new(-1.0, -1.0, -2.0);
    let s = scene(
        n,
        n,
        ortho_camera(height),
        vec![obj(primitives::sphere(256), m)],
        one_light(light),
        Interpolation::Phong,
    );
    for path in common::paths() {
        let img = path.render(&s);
        eprintln!("{}", path.name);
        let view = s.camera.view(Viewer::Infinite);
        let mut worst = 0.0f32;
        let mut inside = 0;
        for y in 0..n {
            for x in 0..n {
                let (wx, wy) = ortho_world(x, y, n, height);
                let r2 = wx * wx + wy * wy;
                let got = px(&img, x, y);
                if r2 > 1.02 * 1.02 {
                    assert_eq!(got, Vec3::ZERO, "background at ({x}, {y})");
                } else if r2 < 0.98 * 0.98 {
                    let p = Vec3::new(wx, wy, (1.0 - r2).sqrt());
                    let sh = shade(
                        &SurfacePoint { position: p, normal: p },
                        &view,
                        &m,
                        &s.lighting,
                        &s.objects[0].shading.options,
                    );
                    let want = Vec3::from(sh.color.to_array());
                    worst = worst.max((got - want).abs().max_element());
                    inside += 1;
                }
            }
        }
        eprintln!("sphere: largest error {worst} over {inside} pixels");
        assert!(inside > 20000);
        assert!(worst < 0.001, "largest error {worst}");
    }
}

/// A plane facing a directional light along its normal: N·L = 1, so every pixel is exactly
/// k_a·I_a + k_d·I (no specular: shininess gives (N·H)^s, so use Lambert), in every mode.
#[test]
fn lit_plane_is_exactly_ka_ia_plus_kd_i() {
    let m = Material::new(
        Color::new(0.3, 0.2, 0.1),
        Color::new(0.5, 0.6, 0.7),
        Color::BLACK,
        Color::BLACK,
        10.0,
    )
    .unwrap();
    let plane = primitives::plane(4).transformed(&Mat4::from_rotation_x(90f32.to_radians()));
    let want = Vec3::new(0.3 * 0.2 + 0.5, 0.2 * 0.2 + 0.6, 0.1 * 0.2 + 0.7);
    for interp in [Interpolation::Flat, Interpolation::Gouraud, Interpolation::Phong] {
        let s = scene(
            64,
            64,
            ortho_camera(1.5),
            vec![obj(plane.clone(), m)],
            one_light(-Vec3::Z),
            interp,
        );
        for path in common::paths() {
            let img = path.render(&s);
            eprintln!("{}", path.name);
            for y in 0..64 {
                for x in 0..64 {
                    let d = (px(&img, x, y) - want).abs().max_element();
                    assert!(d < 1e-6, "{interp:?} ({x},{y}): {:?}", px(&img, x, y));
                }
            }
        }
    }
}

/// A grid of jittered triangles covering more than the screen, in the z = 0 plane.
fn jittered_grid(cells: u32, extent: f32, seed: u64) -> Mesh {
    grid(cells, extent, seed, 0.8)
}

/// A grid of triangles over [−extent, extent]² in the z = 0 plane, its inner vertices moved
/// by up to ±`jitter`/2 of a cell (below about 0.5 no triangle folds over another).
fn grid(cells: u32, extent: f32, seed: u64, jitter: f32) -> Mesh {
    let mut rng = common::Rng(seed);
    let mut positions = Vec::new();
    for i in 0..=cells {
        for j in 0..=cells {
            let border = i == 0 || j == 0 || i == cells || j == cells;
            let (jx, jy) = if border {
                (0.0, 0.0)
            } else {
                (rng.f() - 0.5, rng.f() - 0.5)
            };
            let step = 2.0 * extent / cells as f32;
            positions.push(Vec3::new(
                -extent + (j as f32 + jitter * jx) * step,
                -extent + (i as f32 + jitter * jy) * step,
                0.0,
            ));
        }
    }
    let k = |i: u32, j: u32| i * (cells + 1) + j;
    let mut tris = Vec::new();
    for i in 0..cells {
        for j in 0..cells {
            // Alternate the diagonal so both edge orientations occur.
            if (i + j) % 2 == 0 {
                tris.push([k(i, j), k(i, j + 1), k(i + 1, j + 1)]);
                tris.push([k(i, j), k(i + 1, j + 1), k(i + 1, j)]);
            } else {
                tris.push([k(i, j), k(i, j + 1), k(i + 1, j)]);
                tris.push([k(i, j + 1), k(i + 1, j + 1), k(i + 1, j)]);
            }
        }
    }
    Mesh::new(positions.clone(), vec![Vec3::Z; positions.len()], tris).unwrap()
}

/// The fast path's visibility is exact: a grid of 1800 small jittered triangles (about 2
/// pixels each), each its own object in a distinct emissive colour, over a background border,
/// gives on every CPU path and in every interpolation exactly the image that the triangles'
/// coverage predicts (each pixel centre's one covering triangle, by `coverage_counts` of the
/// triangle alone), with zero tolerance on the fast path.
#[test]
fn fast_path_coverage_is_exact() {
    let (w, h, cells) = (96u32, 72u32, 30u32);
    let grid = grid(cells, 1.0, 7, 0.4);
    let color = |k: usize| Color::new((k % 61) as f32 / 60.0, (k / 61 % 31) as f32 / 30.0, 0.5);
    let objects: Vec<Object> = grid
        .triangles()
        .iter()
        .enumerate()
        .map(|(k, t)| {
            let positions: Vec<Vec3> = t.iter().map(|&i| grid.positions()[i as usize]).collect();
            let mesh = Mesh::new(positions, vec![Vec3::Z; 3], vec![[0, 1, 2]]).unwrap();
            obj(mesh, emissive(color(k)))
        })
        .collect();
    let lighting = Lighting::new(Color::BLACK, Vec::new()).unwrap();
    let base = scene(w, h, ortho_camera(2.4), objects, lighting, Interpolation::Phong);
    // The expected image: each object alone, its covered pixel centres.
    let mut want = vec![None; (w * h) as usize];
    for (k, o) in base.objects.iter().enumerate() {
        let alone = Scene {
            objects: vec![o.clone()],
            ..base.clone()
        };
        for (p, &c) in coverage_counts(&alone).iter().enumerate() {
            if c > 0 {
                assert!(want[p].is_none(), "pixel {p} covered twice: {:?} and {k}", want[p]);
                want[p] = Some(k);
            }
        }
    }
    let covered = want.iter().filter(|k| k.is_some()).count();
    assert!(covered > 3000 && covered < (w * h) as usize, "{covered} pixels covered");
    for interp in [Interpolation::Phong, Interpolation::Gouraud, Interpolation::Flat] {
        let mut s = base.clone();
        each(&mut s, |sh| sh.interpolation = interp);
        for path in common::paths() {
            let img = path.render(&s);
            for (p, k) in want.iter().enumerate() {
                let (x, y) = (p as u32 % w, p as u32 / w);
                let expect = k.map_or(Vec3::ZERO, |k| Vec3::from(color(k).to_array()));
                // The reference interpolates Gouraud colours with perspective weights that sum
                // to 1 within rounding: its colour is the triangle's within 1e-6 (the palette's
                // colours are 1/60 apart, so the triangle is still unambiguous); all else exact.
                let tol = if path.options.reference && interp == Interpolation::Gouraud {
                    1e-6
                } else {
                    0.0
                };
                let d = (px(&img, x, y) - expect).abs().max_element();
                assert!(
                    d <= tol,
                    "{}, {interp:?}: pixel ({x}, {y}) {} vs {expect}",
                    path.name,
                    px(&img, x, y)
                );
            }
        }
    }
}

/// Shared edges cover each sample exactly once: no hole, no overlap (top-left rule), at every
/// sample count, for grids of 2 to 800 triangles, some vertices exactly on pixel centres.
#[test]
fn mesh_covering_the_screen_covers_each_sample_once() {
    for (cells, seed) in [(1, 1), (5, 2), (20, 3)] {
        for samples in Samples::ALL {
            let mut s = scene(
                37,
                29,
                ortho_camera(2.0),
                vec![obj(jittered_grid(cells, 2.0, seed), Material::default())],
                one_light(-Vec3::Z),
                Interpolation::Phong,
            );
            s.image.samples = samples;
            let counts = coverage_counts(&s);
            assert!(
                counts.iter().all(|&c| c == 1),
                "cells {cells} samples {samples}: {:?}",
                {
                    let bad: Vec<_> = counts.iter().enumerate().filter(|(_, c)| **c != 1).take(5).collect();
                    bad
                }
            );
        }
    }
    // Vertices on pixel centres and edges through them: a 32×32 image, a quad split along the
    // diagonal that passes exactly through pixel centres.
    let quad = rect(-1.0, -1.0, 1.0, 1.0, 0.0);
    let s = scene(
        32,
        32,
        ortho_camera(2.0),
        vec![obj(quad, Material::default())],
        one_light(-Vec3::Z),
        Interpolation::Phong,
    );
    assert!(coverage_counts(&s).iter().all(|&c| c == 1));
}

/// Two triangles sharing an edge, drawn separately, cover each pixel once; the half-open rule
/// leaves the quad's own right and bottom edges out: a quad spanning pixel centres 4.5 to 10.5
/// covers exactly columns 4..=9 (the centre at x = 10.5 on its right edge is excluded).
#[test]
fn two_triangles_share_an_edge() {
    // Ortho camera of height 16 over 16×16 pixels: 1 world unit per pixel, x = px − 8.
    let (x0, x1, y0, y1) = (4.5 - 8.0, 10.5 - 8.0, 8.0 - 3.5, 8.0 - 12.5);
    let quad = rect(x0, y1, x1, y0, 0.0);
    let s = scene(
        16,
        16,
        ortho_camera(16.0),
        vec![obj(quad, Material::default())],
        one_light(-Vec3::Z),
        Interpolation::Phong,
    );
    let counts = coverage_counts(&s);
    for y in 0..16u32 {
        for x in 0..16u32 {
            let inside = (4..10).contains(&x) && (3..12).contains(&y);
            assert_eq!(counts[(y * 16 + x) as usize], u16::from(inside), "({x},{y})");
        }
    }
}

/// Perspective-correct interpolation: a floor plane seen in perspective; the depth output is the
/// view depth of the interpolated world position, which must equal the closed-form ray–plane
/// intersection at each pixel centre (affine interpolation would be off by up to 30%).
#[test]
fn perspective_correct_interpolation_and_near_clipping() {
    let cam = Camera::new(
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(0.0, 1.0, -1.0),
        Vec3::Y,
        Projection::Perspective { fov_y_deg: 60.0 },
        0.1,
        50.0,
    )
    .unwrap();
    // A floor y = 0 from z = +10 (behind the camera: crosses the near plane) to z = −40.
    let floor = Mesh::new(
        vec![
            Vec3::new(-40.0, 0.0, 10.0),
            Vec3::new(40.0, 0.0, 10.0),
            Vec3::new(40.0, 0.0, -40.0),
            Vec3::new(-40.0, 0.0, -40.0),
        ],
        vec![Vec3::Y; 4],
        vec![[0, 1, 2], [0, 2, 3]],
    )
    .unwrap();
    let (w, h) = (64u32, 48u32);
    let mut s = scene(
        w,
        h,
        cam,
        vec![obj(floor, Material::default())],
        one_light(-Vec3::Y),
        Interpolation::Phong,
    );
    each(&mut s, |sh| sh.output = Output::Depth);
    for path in common::paths() {
        let img = path.render(&s);
        eprintln!("{}", path.name);
        let t = (30f32).to_radians().tan();
        let aspect = w as f32 / h as f32;
        let mut checked = 0;
        for y in 0..h {
            for x in 0..w {
                // Ray through the pixel centre in view space: (ndc_x·t·aspect, ndc_y·t, −1).
                let ndc_x = (x as f32 + 0.5) / w as f32 * 2.0 - 1.0;
                let ndc_y = 1.0 - (y as f32 + 0.5) / h as f32 * 2.0;
                let dir = Vec3::new(ndc_x * t * aspect, ndc_y * t, -1.0);
                let got = img.get(x, y)[0];
                if dir.y >= -1e-3 {
                    assert_eq!(got, 0.0, "above the horizon ({x},{y})"); // background
                    continue;
                }
                let depth = 1.0 / -dir.y; // camera height 1, forward component of dir is 1
                let hit = Vec3::new(0.0, 1.0, 0.0) + dir * depth;
                if hit.z < -40.0 || hit.x.abs() > 40.0 || depth > 50.0 {
                    continue;
                }
                let want = 1.0 - (depth - 0.1) / (50.0 - 0.1);
                assert!((got - want).abs() < 2e-4, "({x},{y}): {got} vs {want}");
                checked += 1;
            }
        }
        assert!(checked > 1000, "{checked}");
    }
}

/// The rectangle [x0, x1] × [y0, y1] in the plane z, two triangles counter-clockwise seen from +z.
fn rect(x0: f32, y0: f32, x1: f32, y1: f32, z: f32) -> Mesh {
    Mesh::new(
        vec![
            Vec3::new(x0, y0, z),
            Vec3::new(x1, y0, z),
            Vec3::new(x1, y1, z),
            Vec3::new(x0, y1, z),
        ],
        vec![Vec3::Z; 4],
        vec![[0, 1, 2], [0, 2, 3]],
    )
    .unwrap()
}

fn quad_at(z: f32, half: f32) -> Mesh {
    rect(-half, -half, half, half, z)
}

fn emissive(c: Color) -> Material {
    Material::new(Color::BLACK, Color::BLACK, Color::BLACK, c, 0.0).unwrap()
}

/// The nearer surface wins whatever the drawing order.
#[test]
fn depth_order() {
    let red = obj(quad_at(0.5, 0.5), emissive(Color::new(1.0, 0.0, 0.0)));
    let blue = obj(quad_at(-0.5, 1.0), emissive(Color::new(0.0, 0.0, 1.0)));
    for objects in [vec![red.clone(), blue.clone()], vec![blue, red]] {
        let s = scene(
            32,
            32,
            ortho_camera(3.0),
            objects,
            Lighting::default(),
            Interpolation::Phong,
        );
        for path in common::paths() {
            let img = path.render(&s);
            eprintln!("{}", path.name);
            assert_eq!(px(&img, 16, 16), Vec3::new(1.0, 0.0, 0.0));
            assert_eq!(px(&img, 16, 6), Vec3::new(0.0, 0.0, 1.0));
        }
    }
}

/// One triangle, orthographic: barycentrics of a pixel centre computed here independently.
fn barycentric(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> [f32; 3] {
    let area = (b - a).cross(c - a).z;
    [
        (b - p).cross(c - p).z / area,
        (c - p).cross(a - p).z / area,
        (a - p).cross(b - p).z / area,
    ]
}

/// Checks every pixel well inside triangle (a, b, c) (barycentrics all above 0.02, computed here
/// from the pixel centre) against `want(barycentrics, position)`, within `tol`; at least 300 pixels.
fn check_interior(
    img: &Image,
    n: u32,
    (a, b, c): (Vec3, Vec3, Vec3),
    tol: f32,
    label: &str,
    want: impl Fn([f32; 3], Vec3) -> Vec3,
) {
    let mut checked = 0;
    for y in 0..n {
        for x in 0..n {
            let (wx, wy) = ortho_world(x, y, n, 2.0);
            let l = barycentric(Vec3::new(wx, wy, 0.0), a, b, c);
            if l.iter().any(|&v| v < 0.02) {
                continue;
            }
            let w = want(l, a * l[0] + b * l[1] + c * l[2]);
            let got = px(img, x, y);
            assert!((got - w).abs().max_element() < tol, "{label} ({x},{y}): {got} vs {w}");
            checked += 1;
        }
    }
    assert!(checked > 300, "{label}: {checked} pixels");
}

/// Each interpolation mode and specular model against `shade`: flat is the centroid's shading
/// with the facet normal; Gouraud the barycentric blend of the vertices' shadings; Phong the
/// shading of the blended position and renormalised normal. Tolerance 2e-5: f32 rounding of the
/// blended vectors, amplified by the exponent 51.2 (with a 5e-6 bound one pixel failed at 8.8e-6;
/// the largest difference is below the asserted 2e-5 but was not recorded).
#[test]
fn interpolation_modes_against_core() {
    // Vertices on multiples of 1/8 world unit = 3 pixels, so snapping to 1/256 pixel moves nothing.
    let (a, b, c) = (
        Vec3::new(-0.875, -0.75, 0.0),
        Vec3::new(0.875, -0.625, 0.25),
        Vec3::new(0.0, 0.875, -0.25),
    );
    let na = Vec3::new(-0.5, -0.3, 1.0).normalize();
    let nb = Vec3::new(0.6, -0.2, 1.0).normalize();
    let nc = Vec3::new(0.0, 0.7, 1.0).normalize();
    let mesh = Mesh::new(vec![a, b, c], vec![na, nb, nc], vec![[0, 1, 2]]).unwrap();
    let m = Material::named("polished copper").unwrap();
    let lighting = Lighting::new(
        Color::splat(0.1),
        vec![
            Light::directional(Vec3::new(-0.3, -0.5, -1.0), LightColor::default()).unwrap(),
            Light::point(
                Vec3::new(1.0, 1.0, 2.0),
                LightColor::uniform(Color::new(0.6, 0.5, 0.4)).unwrap(),
                Attenuation::new(1.0, 0.2, 0.0).unwrap(),
            )
            .unwrap(),
        ],
    )
    .unwrap();
    let models = [
        SpecularModel::None,
        SpecularModel::Phong,
        SpecularModel::BlinnPhong,
        SpecularModel::Lyon {
            squarings: 3,
            lambda: LyonLambda::Dot,
        },
    ];
    let n = 48u32;
    for model in models {
        for interp in [Interpolation::Flat, Interpolation::Gouraud, Interpolation::Phong] {
            let mut s = scene(
                n,
                n,
                ortho_camera(2.0),
                vec![obj(mesh.clone(), m)],
                lighting.clone(),
                interp,
            );
            each(&mut s, |sh| sh.options.specular = model);
            each(&mut s, |sh| sh.viewer = Viewer::Local); // per-point V, to exercise positions too
            for path in common::paths() {
                let img = path.render(&s);
                eprintln!("{}", path.name);
                let view = s.camera.view(Viewer::Local);
                let sh = |p: Vec3, nrm: Vec3| {
                    let r = shade(
                        &SurfacePoint {
                            position: p,
                            normal: nrm,
                        },
                        &view,
                        &m,
                        &lighting,
                        &s.objects[0].shading.options,
                    );
                    Vec3::from(r.color.to_array())
                };
                let label = format!("{model:?} {interp:?}");
                // The fast paths' lean kernel may drop a highlight below 0.05/255 a light
                // (simd/lean.rs); the reference path and the general kernel stay within 2e-5.
                let tol = if path.name == "reference" {
                    2e-5
                } else {
                    2e-5 + 2.0 * 0.05 / 255.0
                };
                check_interior(&img, n, (a, b, c), tol, &label, |l, p| match interp {
                    Interpolation::Flat => sh((a + b + c) / 3.0, (b - a).cross(c - a).normalize()),
                    Interpolation::Gouraud => sh(a, na) * l[0] + sh(b, nb) * l[1] + sh(c, nc) * l[2],
                    Interpolation::Phong => sh(p, na * l[0] + nb * l[1] + nc * l[2]),
                });
            }
        }
    }
}

/// 4 samples: an edge at x = 10.5 pixels covers the 2 of the 4 standard sample positions
/// (x offsets 0.375, 0.875, 0.125, 0.625) left of it in pixel 10: half white.
#[test]
fn antialiasing_averages_samples() {
    assert_eq!(
        sample_pattern(Samples::Four).iter().filter(|(x, _)| *x < 0.5).count(),
        2
    );
    let (x0, x1) = (-8.0, 10.5 - 8.0);
    let quad = rect(x0, -8.0, x1, 8.0, 0.0);
    let mut s = scene(
        16,
        16,
        ortho_camera(16.0),
        vec![obj(quad, emissive(Color::WHITE))],
        Lighting::default(),
        Interpolation::Phong,
    );
    s.image.samples = Samples::Four;
    for path in common::paths() {
        let img = path.render(&s);
        eprintln!("{}", path.name);
        assert_eq!(px(&img, 9, 5), Vec3::ONE);
        assert!(
            (px(&img, 10, 5) - Vec3::splat(0.5)).abs().max_element() < 1e-6,
            "{}",
            px(&img, 10, 5)
        );
        assert_eq!(px(&img, 11, 5), Vec3::ZERO);
    }
    // A transparent background gives partial alpha with the covered colour (straight alpha).
    s.image.background = [0.0, 0.0, 0.0, 0.0];
    for path in common::paths() {
        let img = path.render(&s);
        eprintln!("{}", path.name);
        assert_eq!(img.get(10, 5), [1.0, 1.0, 1.0, 0.5]);
        assert_eq!(img.get(12, 5)[3], 0.0);
    }
}

/// Back faces are culled unless two-sided lighting is on.
#[test]
fn back_face_culling() {
    let back = quad_at(0.0, 1.0).transformed(&Mat4::from_rotation_y(180f32.to_radians()));
    let mut s = scene(
        8,
        8,
        ortho_camera(3.0),
        vec![obj(back, emissive(Color::WHITE))],
        Lighting::default(),
        Interpolation::Phong,
    );
    assert_eq!(px(&render(&s, &RenderOptions::default()).unwrap(), 4, 4), Vec3::ZERO);
    each(&mut s, |sh| sh.options.two_sided = true);
    assert_eq!(px(&render(&s, &RenderOptions::default()).unwrap(), 4, 4), Vec3::ONE);
}

/// The same image whatever the number of threads.
#[test]
fn deterministic_across_thread_counts() {
    let s = scene(
        150,
        110,
        ortho_camera(2.0),
        vec![obj(primitives::teapot(6), Material::named("ruby").unwrap())],
        one_light(Vec3::new(-1.0, -1.0, -1.0)),
        Interpolation::Phong,
    );
    let one = render(
        &s,
        &RenderOptions {
            threads: Some(1),
            ..Default::default()
        },
    )
    .unwrap();
    let three = render(
        &s,
        &RenderOptions {
            threads: Some(3),
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(one, three);
}

#[test]
fn rejects_bad_settings() {
    let mut s = scene(
        8,
        8,
        ortho_camera(3.0),
        vec![],
        Lighting::default(),
        Interpolation::Phong,
    );
    // Sample counts other than 1, 4 and 16 cannot be asked for (`Samples`); sizes past the
    // limits are refused, as the core crate's check says.
    assert!(Samples::from_count(3).unwrap_err().to_string().contains("1, 4 or 16"));
    for (w, h, samples) in [
        (1_000_000, 8, Samples::One),
        (0, 8, Samples::One),
        (16384, 16384, Samples::Sixteen),
    ] {
        s.image.width = w;
        s.image.height = h;
        s.image.samples = samples;
        let e = render(&s, &RenderOptions::default()).unwrap_err();
        assert!(
            e.is_input() && e.to_string().contains("cannot be rendered"),
            "{w}x{h}: {e}"
        );
    }
}

/// OpenGL's two-sided lighting decides by polygon facing, not by the sign of N·V: a back-facing
/// triangle whose vertex normals point towards the viewer is lit with those normals flipped
/// (so, lit from the front, it shows only its ambient term), in every interpolation mode.
#[test]
fn two_sided_lighting_follows_polygon_facing() {
    let (a, b, c) = (
        Vec3::new(-0.875, -0.75, 0.0),
        Vec3::new(0.875, -0.625, 0.25),
        Vec3::new(0.0, 0.875, -0.25),
    );
    let (na, nb, nc) = (
        Vec3::new(-0.2, 0.1, 1.0).normalize(),
        Vec3::new(0.3, 0.0, 1.0).normalize(),
        Vec3::new(0.0, 0.2, 1.0).normalize(),
    );
    // Wound a, c, b: clockwise on screen seen from +z, a back face.
    let mesh = Mesh::new(vec![a, b, c], vec![na, nb, nc], vec![[0, 2, 1]]).unwrap();
    let m = Material::named("red plastic").unwrap();
    let lighting = Lighting::new(
        Color::splat(0.3),
        vec![Light::directional(Vec3::new(0.2, -0.3, -1.0), LightColor::default()).unwrap()],
    )
    .unwrap();
    let n = 48u32;
    for interp in [Interpolation::Flat, Interpolation::Gouraud, Interpolation::Phong] {
        let mut s = scene(
            n,
            n,
            ortho_camera(2.0),
            vec![obj(mesh.clone(), m)],
            lighting.clone(),
            interp,
        );
        each(&mut s, |sh| sh.options.two_sided = true);
        for path in common::paths() {
            let img = path.render(&s);
            eprintln!("{}", path.name);
            let view = s.camera.view(Viewer::Infinite);
            let one_sided = ShadingOptions::default();
            let sh = |p: Vec3, nrm: Vec3| {
                let r = shade(
                    &SurfacePoint {
                        position: p,
                        normal: nrm,
                    },
                    &view,
                    &m,
                    &lighting,
                    &one_sided,
                );
                Vec3::from(r.color.to_array())
            };
            // The back face's facet normal (a, c, b winding) points away; flipped, towards +z.
            check_interior(&img, n, (a, b, c), 2e-5, &format!("{interp:?}"), |l, p| match interp {
                Interpolation::Flat => sh((a + b + c) / 3.0, (b - a).cross(c - a).normalize()),
                Interpolation::Gouraud => sh(a, -na) * l[0] + sh(b, -nb) * l[1] + sh(c, -nc) * l[2],
                Interpolation::Phong => sh(p, -(na * l[0] + nb * l[1] + nc * l[2])),
            });
            // Gouraud and Phong with flipped normals see only the ambient light: 0.3 · a_m (= 0).
            if interp != Interpolation::Flat {
                assert!(
                    px(&img, 24, 24).max_element() < 0.05,
                    "{interp:?}: {}",
                    px(&img, 24, 24)
                );
            }
        }
    }
}

/// Thread counts outside 1 to `MAX_THREADS` are an error, before anything is spawned.
#[test]
fn thread_count_out_of_range_is_an_error() {
    let scene = phong_scene::parse_scene(
        "[image]\nwidth = 8\nheight = 8\n[[object]]\nshape = \"sphere\"\nmaterial = \"gold\"\n",
        std::path::Path::new("t.toml"),
    )
    .unwrap()
    .scene;
    for n in [0, phong_core::limits::MAX_THREADS + 1, 100_000] {
        let options = RenderOptions {
            threads: Some(n),
            ..Default::default()
        };
        let e = render(&scene, &options).unwrap_err();
        assert!(matches!(e, phong_raster::Error::ThreadCount(m) if m == n), "{e}");
        assert!(e.to_string().contains("from 1 to 1024"), "{e}");
    }
    let options = RenderOptions {
        threads: Some(phong_core::limits::MAX_THREADS.min(4)),
        ..Default::default()
    };
    assert!(render(&scene, &options).is_ok());
}

/// The quad [−1, 1]² at `z`, facing +z, with texture coordinates `((x + 1)/2, (y + 1)/2)`.
fn textured_quad(z: f32) -> Mesh {
    let p = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
    Mesh::new(
        p.iter().map(|&(x, y)| Vec3::new(x, y, z)).collect(),
        vec![Vec3::Z; 4],
        vec![[0, 1, 2], [0, 2, 3]],
    )
    .unwrap()
    .with_uvs(
        p.iter()
            .map(|&(x, y)| glam::Vec2::new((x + 1.0) / 2.0, (y + 1.0) / 2.0))
            .collect(),
    )
    .unwrap()
}

/// A 4×4 texture (top row first) of distinct colours; `alpha` per texel.
fn texture_4x4(alpha: impl Fn(usize, usize) -> u16) -> (Vec<[u16; 4]>, std::sync::Arc<Texture>) {
    let texels: Vec<[u16; 4]> = (0..16)
        .map(|i| {
            let (col, row) = (i % 4, i / 4);
            [
                (col as u16 * 60 + 20) * 257,
                (row as u16 * 60 + 20) * 257,
                128 * 257,
                alpha(col, row),
            ]
        })
        .collect();
    let t = Texture::new(4, 4, &texels, 8).unwrap();
    (texels, std::sync::Arc::new(t))
}

/// On every CPU path, each pixel of `s` (the `textured_quad` filling an `n`×`n` orthographic
/// view, lit head-on, a white diffuse material) is the texel of `texture_4x4`'s `texels` that
/// the quad's mapping `((x + 1)/2, (y + 1)/2)` puts there, found by hand.
fn each_pixel_is_its_texel(s: &Scene, texels: &[[u16; 4]], what: &str) {
    let n = s.image.width;
    for path in common::paths() {
        let img = path.render(s);
        for y in 0..n {
            for x in 0..n {
                let (wx, wy) = ortho_world(x, y, n, 2.0);
                let (u, v) = ((wx + 1.0) / 2.0, (wy + 1.0) / 2.0);
                // Texel column floor(4u); row floor(4v) from the bottom, 3 − it from the top.
                let (col, row) = ((u * 4.0) as usize, 3 - (v * 4.0) as usize);
                let t = texels[row * 4 + col];
                let want = Vec3::new(t[0] as f32, t[1] as f32, t[2] as f32) / 65535.0;
                let got = px(&img, x, y);
                assert!(
                    (got - want).abs().max_element() < 1e-6,
                    "{} {what} ({x}, {y}): {got} vs {want}",
                    path.name
                );
            }
        }
    }
}

/// A diffuse map with nearest filtering on a quad lit head-on (N·L = 1, a white diffuse
/// material, no ambient): each pixel is its texel, found by hand from the quad's coordinates,
/// on every CPU path and interpolation.
#[test]
fn a_diffuse_map_is_sampled_at_each_pixel() {
    let n = 64u32;
    let m = Material::new(Color::BLACK, Color::WHITE, Color::BLACK, Color::BLACK, 1.0).unwrap();
    let (texels, texture) = texture_4x4(|_, _| 65535);
    let mut o = obj(textured_quad(0.0), m);
    let mut map = TextureMap::new(texture);
    map.sampler = Sampler::nearest(Wrap::Clamp);
    o.maps.diffuse = Some(map);
    for interp in [Interpolation::Phong, Interpolation::Gouraud, Interpolation::Flat] {
        let s = scene(n, n, ortho_camera(2.0), vec![o.clone()], one_light(-Vec3::Z), interp);
        each_pixel_is_its_texel(&s, &texels, &format!("{interp:?}"));
    }
}

/// A map on the mesh's second set of texture coordinates (glTF's `TEXCOORD_1`) reads that
/// set, not the first: the quad's first set is one point (a single texel), its second the
/// quad's mapping; each pixel is its texel by hand (`each_pixel_is_its_texel`), each
/// interpolation.
#[test]
fn a_map_on_the_second_set_reads_it() {
    let n = 32u32;
    let m = Material::new(Color::BLACK, Color::WHITE, Color::BLACK, Color::BLACK, 1.0).unwrap();
    let (texels, texture) = texture_4x4(|_, _| 65535);
    let quad = textured_quad(0.0);
    let mapping = quad.uvs().to_vec();
    let mesh = quad
        .with_uvs(vec![glam::Vec2::splat(0.9); 4])
        .unwrap()
        .with_uvs1(mapping)
        .unwrap();
    let mut o = obj(mesh, m);
    let mut map = TextureMap::new(texture);
    map.sampler = Sampler::nearest(Wrap::Clamp);
    map.set = 1;
    o.maps.diffuse = Some(map);
    for interp in [Interpolation::Phong, Interpolation::Gouraud, Interpolation::Flat] {
        let s = scene(n, n, ortho_camera(2.0), vec![o.clone()], one_light(-Vec3::Z), interp);
        each_pixel_is_its_texel(&s, &texels, &format!("{interp:?}"));
    }
}

/// The alpha test: where the diffuse map's alpha is below the cutoff, the quad is not drawn
/// (neither colour nor depth), and the red quad behind it shows.
#[test]
fn the_alpha_test_discards_colour_and_depth() {
    let n = 64u32;
    let m = Material::new(Color::BLACK, Color::WHITE, Color::BLACK, Color::BLACK, 1.0).unwrap();
    // The left half of the texture is transparent.
    let (_, texture) = texture_4x4(|col, _| if col < 2 { 0 } else { 65535 });
    let mut front = obj(textured_quad(0.0), m);
    let mut map = TextureMap::new(texture);
    map.sampler = Sampler::nearest(Wrap::Clamp);
    front.maps.diffuse = Some(map);
    front.maps.alpha_cutoff = Some(0.5);
    let red = Material::new(Color::BLACK, Color::BLACK, Color::BLACK, Color::new(1.0, 0.0, 0.0), 1.0).unwrap();
    // The front quad is drawn first: a depth write where it is discarded would hide the back one.
    let back = obj(textured_quad(-0.5), red);
    let s = scene(
        n,
        n,
        ortho_camera(2.0),
        vec![front, back],
        one_light(-Vec3::Z),
        Interpolation::Phong,
    );
    for path in common::paths() {
        let img = path.render(&s);
        for y in 0..n {
            for x in 0..n {
                let got = px(&img, x, y);
                if x < n / 2 {
                    assert_eq!(got, Vec3::new(1.0, 0.0, 0.0), "{} ({x}, {y})", path.name);
                } else {
                    assert!(got.y > 0.0 && got.z > 0.0, "{} ({x}, {y}): {got}", path.name);
                }
            }
        }
    }
}

/// A quad of `emission` with alpha `alpha` at `z`, blended where `blend`.
fn glass(z: f32, emission: Color, alpha: f32, blend: bool) -> Object {
    let m = Material::new(Color::BLACK, Color::BLACK, Color::BLACK, emission, 1.0)
        .unwrap()
        .with_alpha(alpha)
        .unwrap();
    let mut o = obj(textured_quad(z), m);
    o.maps.blend = blend;
    o
}

/// Blending by hand: a red opaque quad behind a blue one of alpha 0.25 gives `0.25·blue +
/// 0.75·red`, whatever the order the objects are listed in (opaque first, then blended back to
/// front); two blended quads compose back to front; over a transparent background the pixel's
/// alpha is `α` (straight colour: the quad's); without `blend` the alpha changes nothing.
#[test]
fn blended_objects_are_drawn_over_what_is_behind() {
    let n = 16u32;
    let lighting = Lighting::new(Color::BLACK, Vec::new()).unwrap();
    let (red, green, blue) = (
        Color::new(1.0, 0.0, 0.0),
        Color::new(0.0, 1.0, 0.0),
        Color::new(0.0, 0.0, 1.0),
    );
    let cases: Vec<(Vec<Object>, [f32; 4], [f32; 4])> = vec![
        (
            vec![glass(0.0, blue, 0.25, true), glass(-0.5, red, 1.0, false)],
            [0.0; 4],
            [0.75, 0.0, 0.25, 1.0],
        ),
        (
            vec![
                glass(0.0, green, 0.5, true),
                glass(-0.5, red, 1.0, false),
                glass(-0.25, blue, 0.5, true),
            ],
            [0.0; 4],
            [0.25, 0.5, 0.25, 1.0],
        ),
        (
            vec![glass(0.0, blue, 0.25, true)],
            [0.0, 0.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.25],
        ),
        (
            vec![glass(0.0, blue, 0.25, false), glass(-0.5, red, 1.0, false)],
            [0.0; 4],
            [0.0, 0.0, 1.0, 1.0],
        ),
    ];
    for (k, (objects, background, want)) in cases.into_iter().enumerate() {
        let mut s = scene(n, n, ortho_camera(1.0), objects, lighting.clone(), Interpolation::Phong);
        s.image.background = background;
        for path in common::paths() {
            let img = path.render(&s);
            let got = img.get(n / 2, n / 2);
            for c in 0..4 {
                assert!(
                    (got[c] - want[c]).abs() < 1e-5,
                    "case {k} {}: {got:?} vs {want:?}",
                    path.name
                );
            }
        }
    }
}

/// Vertex colours tint the diffuse texel: a white quad whose corners are red, red, blue, blue
/// (left to right, in an orthographic view, lit head-on with no ambient) shows at each pixel
/// the colour interpolated linearly across it, on every path and interpolation.
#[test]
fn vertex_colours_are_interpolated() {
    let n = 32u32;
    let m = Material::new(Color::BLACK, Color::WHITE, Color::BLACK, Color::BLACK, 1.0).unwrap();
    let (red, blue) = (Color::new(1.0, 0.0, 0.0), Color::new(0.0, 0.0, 1.0));
    // Corners of textured_quad: (−1,−1), (1,−1), (1,1), (−1,1).
    let mesh = textured_quad(0.0).with_colors(vec![red, blue, blue, red]).unwrap();
    for interp in [Interpolation::Phong, Interpolation::Gouraud] {
        let s = scene(
            n,
            n,
            ortho_camera(2.0),
            vec![obj(mesh.clone(), m)],
            one_light(-Vec3::Z),
            interp,
        );
        for path in common::paths() {
            let img = path.render(&s);
            for y in 0..n {
                for x in 0..n {
                    let (wx, _) = ortho_world(x, y, n, 2.0);
                    let t = (wx + 1.0) / 2.0;
                    let want = Vec3::new(1.0 - t, 0.0, t);
                    let got = px(&img, x, y);
                    assert!(
                        (got - want).abs().max_element() < 1e-5,
                        "{} {interp:?} ({x}, {y}): {got} vs {want}",
                        path.name
                    );
                }
            }
        }
    }
}

/// A normal map by hand: the quad facing +z (texture coordinates along +x and +y, so its
/// MikkTSpace tangent is +x and bitangent +y) with a constant tangent-space normal
/// `(0.6, 0, 0.8)`, lit from `L = (0.6, 0, 0.8)` with a white diffuse material: `N'·L = 1`
/// where the flat normal gives 0.8 (and a tangent the wrong way round 0.28). Green along +v,
/// and with `green_down` along −v. Per-pixel shading, every CPU path.
#[test]
fn a_normal_map_tilts_the_normal_in_its_tangent_frame() {
    let n = 16u32;
    let m = Material::new(Color::BLACK, Color::WHITE, Color::BLACK, Color::BLACK, 1.0).unwrap();
    let lighting = |l: Vec3| {
        Lighting::new(
            Color::BLACK,
            vec![Light::directional(-l, LightColor::uniform(Color::WHITE).unwrap()).unwrap()],
        )
        .unwrap()
    };
    let encode = |v: f32| ((v + 1.0) / 2.0 * 65535.0).round() as u16;
    for (ts, l, green_down, want) in [
        (Vec3::new(0.6, 0.0, 0.8), Vec3::new(0.6, 0.0, 0.8), false, 1.0),
        (Vec3::new(0.0, 0.6, 0.8), Vec3::new(0.0, 0.6, 0.8), false, 1.0),
        (Vec3::new(0.0, 0.6, 0.8), Vec3::new(0.0, 0.6, 0.8), true, 0.28),
    ] {
        let texel = [encode(ts.x), encode(ts.y), encode(ts.z), 65535];
        let texture = std::sync::Arc::new(Texture::new(1, 1, &[texel], 16).unwrap());
        let mut o = obj(textured_quad(0.0).with_mikktspace_tangents(), m);
        o.maps.normal = Some(NormalMap {
            map: TextureMap::new(texture),
            scale: 1.0,
            green_down,
        });
        let s = scene(n, n, ortho_camera(2.0), vec![o], lighting(l), Interpolation::Phong);
        for path in common::paths() {
            let img = path.render(&s);
            for y in 0..n {
                for x in 0..n {
                    let got = px(&img, x, y);
                    assert!(
                        (got - Vec3::splat(want)).abs().max_element() < 2e-4,
                        "{} {ts} down {green_down} ({x}, {y}): {got}",
                        path.name
                    );
                }
            }
        }
    }
}
