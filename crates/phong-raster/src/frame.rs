//! A frame: the decisions made once per render (path, instruction set, how each object is
//! shaded, the sample pattern, the background), the set-up and binned triangles, and the
//! render itself (setup, then the tiles).

use crate::fixed::pattern;
use crate::setup::{Chunk, Corners, Extra, ID_INDEX_BITS, Keep, SampleSpan, Scratch, Tri};
use crate::simd::{Batch, Isa, Planes, Prepared, Term, VectorMaps};
use crate::stats::{RenderStats, StageClock};
use crate::target::{Pixel, resolve};
use crate::{Error, RenderOptions};
use phong_core::limits::{SUBPIXEL_BITS, TILE_SIZE};
use phong_core::{Encoding, Interpolation, Output, Scene, View};
use std::sync::Mutex;
use std::time::Instant;

/// Which CPU path draws the frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Path {
    /// One `shade` per pixel and covering triangle, in drawing order.
    Reference,
    /// Visibility first, then each visible pixel shaded once, by the vector kernels.
    Fast,
}

/// How the fast path shades an object's pixels.
pub(crate) enum Mode {
    /// Interpolated position and normal, the vector kernel; the term shown.
    Phong(Prepared, Term),
    /// Interpolated vertex colours (flat: the triangle's colour).
    Gouraud,
    /// A textured object's colour, Phong-interpolated: light and maps
    /// by the vector sampler where it covers the maps ([`Frame::vector_maps`]), else the light
    /// by the vector kernel (`shade_batch_lit`) and the maps sampled per pixel from the planes
    /// of its texture coordinates (maps that change the light, normal, shininess and
    /// metallic-roughness maps, need the vector sampler: without it they are [`Mode::Scalar`]'s).
    /// With `per_vertex` (Gouraud and flat, always with the vector sampler), the vertices (flat:
    /// the triangle) are lit into primary and specular colours, which the triangle's planes
    /// carry instead of position and normal.
    Textured { prep: Prepared, per_vertex: bool },
    /// One pixel at a time, as the reference path (textured objects the vector kernels do not
    /// cover, normal and depth outputs, blended objects).
    Scalar,
}

impl Mode {
    /// The vector kernels' batch for this mode; `None` for scalar shading.
    pub fn batch(&self) -> Option<Batch<'_>> {
        match self {
            Mode::Phong(prep, term) => Some(Batch::Phong(prep, *term)),
            Mode::Gouraud => Some(Batch::Gouraud),
            Mode::Textured { .. } | Mode::Scalar => None,
        }
    }
}

/// How an object's points reach the image (the fast path decides visibility before shading).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Visibility {
    /// Drawn where nearest.
    Opaque,
    /// Drawn where nearest and its alpha passes the alpha test, decided during visibility with
    /// the reference's arithmetic ([`Frame::alpha_passes`]): the object keeps [`Corners`].
    AlphaTested,
    /// Blended over the opaque image after it is shaded, without writing depth
    /// (`Object::blends`): shaded per pixel ([`Mode::Scalar`]).
    Blended,
}

/// The kernel's term for a lit output; `None` for the normal and depth outputs.
pub(crate) fn lit_term(output: Output) -> Option<Term> {
    match output {
        Output::Color => Some(Term::Color),
        Output::Ambient => Some(Term::Ambient),
        Output::Diffuse => Some(Term::Diffuse),
        Output::Specular => Some(Term::Specular),
        _ => None,
    }
}

pub(crate) struct Frame<'a> {
    pub scene: &'a Scene,
    pub path: Path,
    pub isa: Isa,
    /// Per object: how the fast path shades it.
    pub modes: Vec<Mode>,
    /// Per object: its maps as the vector sampler reads them, for a [`Mode::Textured`] object
    /// whose maps it covers (decided once per frame).
    pub vector_maps: Vec<Option<VectorMaps<'a>>>,
    /// Per object: how its points reach the image.
    pub visibility: Vec<Visibility>,
    /// Per object: whether a map reads the mesh's second set of texture coordinates.
    pub second_sets: Vec<bool>,
    /// Per object: what its coordinates' planes carry beside the first set.
    pub extras: Vec<Extra>,
    /// The fast path with every object Gouraud-shaded (see `tile::gouraud`).
    pub gouraud_only: bool,
    /// Per object: its view vector rule.
    pub views: Vec<View>,
    pub w: u32,
    pub h: u32,
    /// The sample offsets from a pixel's corner, in 1/256 pixel.
    pub pattern: Vec<(i64, i64)>,
    /// The pattern's bounds, for the triangles' bounding boxes.
    pub span: SampleSpan,
    /// The scene's background colour, for the resolve of partly covered pixels.
    pub bg: [f32; 4],
    /// An uncovered pixel: the resolve of its background samples.
    pub background: [f32; 4],
    /// Set-up triangles, in the chunks the parallel setup made them (not copied into one
    /// vector); ids pack (chunk, index), see [`Frame::tri`].
    pub tris: Vec<Chunk>,
    pub tiles_x: u32,
    pub bins: Vec<Vec<u32>>,
}

impl<'a> Frame<'a> {
    /// Decides the frame's constants, then transforms, lights (Gouraud, flat), clips, sets up and
    /// bins every triangle, in memory taken from `scratch` (given back by [`Frame::recycle`]).
    pub fn build(scene: &'a Scene, path: Path, isa: Isa, scratch: &mut Scratch) -> Frame<'a> {
        let (w, h) = (scene.image.width, scene.image.height);
        let clip_from_world = scene.camera.clip_from_world(w as f32 / h as f32);
        let views: Vec<View> = scene
            .objects
            .iter()
            .map(|o| scene.camera.view(o.shading.viewer))
            .collect();
        let pattern = pattern(scene.image.samples);
        let second_sets: Vec<bool> = scene.objects.iter().map(|o| o.maps.uses_second_set()).collect();
        let visibility: Vec<Visibility> = scene
            .objects
            .iter()
            .map(|o| {
                if o.blends() {
                    Visibility::Blended
                } else if o.textured() && lit_term(o.shading.output).is_some() && o.maps.alpha_cutoff.is_some() {
                    // (`Frame::shade_pixel` applies the alpha test to these points only.)
                    Visibility::AlphaTested
                } else {
                    Visibility::Opaque
                }
            })
            .collect();
        let modes: Vec<Mode> = scene
            .objects
            .iter()
            .zip(&views)
            .zip(&second_sets)
            .zip(&visibility)
            .map(|(((o, &view), &second_set), &visibility)| {
                let Some(term) = lit_term(o.shading.output) else {
                    return Mode::Scalar;
                };
                if visibility == Visibility::Blended {
                    return Mode::Scalar;
                }
                if o.textured() {
                    let m = &o.maps;
                    // Ambient, emission and occlusion maps need the light's terms apart, which
                    // only the vector sampler keeps (`Prepared::emission_apart`).
                    let split = m.apart() != (false, false);
                    let colors = !o.mesh.colors().is_empty();
                    // Normal, shininess and metallic-roughness maps change the light, which
                    // only the vector sampler samples them for.
                    let changes_light = m.normal.is_some() || m.shininess.is_some() || m.metal_rough.is_some();
                    let per_pixel_light = ((split || changes_light) && VectorMaps::new(m).is_none())
                        // The second set takes the vertex colours' planes, the tangents both.
                        || (second_set && colors)
                        || (m.normal.is_some() && (second_set || colors));
                    if term != Term::Color {
                        return Mode::Scalar;
                    }
                    let prep = Prepared::new(&scene.lighting, &o.material, &o.shading.options, view);
                    return match o.shading.interpolation {
                        Interpolation::Phong if !per_pixel_light => Mode::Textured {
                            prep: if split {
                                prep.emission_apart(&scene.lighting, &o.material)
                            } else {
                                prep
                            },
                            per_vertex: false,
                        },
                        // Gouraud and flat: only the diffuse and specular maps apply, by the
                        // sampler (`VectorMaps::lit_per_vertex`); the second set takes the
                        // colours' planes.
                        Interpolation::Gouraud | Interpolation::Flat
                            if !(second_set && colors)
                                && VectorMaps::new(m).and_then(VectorMaps::lit_per_vertex).is_some() =>
                        {
                            Mode::Textured { prep, per_vertex: true }
                        }
                        _ => Mode::Scalar,
                    };
                }
                match o.shading.interpolation {
                    Interpolation::Phong => Mode::Phong(
                        Prepared::new(&scene.lighting, &o.material, &o.shading.options, view),
                        term,
                    ),
                    // Flat: the triangle's colour, planes without slope.
                    Interpolation::Gouraud | Interpolation::Flat => Mode::Gouraud,
                }
            })
            .collect();
        let bg = scene.image.background;
        let ns = pattern.len();
        let tiles = (w.div_ceil(TILE_SIZE) * h.div_ceil(TILE_SIZE)) as usize;
        let mut frame = Frame {
            scene,
            path,
            isa,
            gouraud_only: path == Path::Fast && modes.iter().all(|m| matches!(m, Mode::Gouraud)),
            vector_maps: scene
                .objects
                .iter()
                .zip(&modes)
                .map(|(o, m)| match m {
                    Mode::Textured { per_vertex, .. } => VectorMaps::new(&o.maps)
                        .and_then(|v| if *per_vertex { v.lit_per_vertex() } else { Some(v) })
                        .map(|v| v.tinted(!o.mesh.colors().is_empty())),
                    _ => None,
                })
                .collect(),
            extras: scene
                .objects
                .iter()
                .zip(&modes)
                .zip(&second_sets)
                .map(|((o, mode), &second)| match mode {
                    Mode::Textured { per_vertex: false, .. } if o.maps.normal.is_some() => Extra::Tangents,
                    _ if second => Extra::SecondSet,
                    _ if o.mesh.colors().is_empty() => Extra::Nothing,
                    _ => Extra::Colors,
                })
                .collect(),
            modes,
            visibility,
            second_sets,
            views,
            w,
            h,
            span: SampleSpan::of(&pattern),
            pattern,
            bg,
            background: resolve(std::iter::repeat_n(bg, ns), ns, bg),
            tris: Vec::new(),
            tiles_x: w.div_ceil(TILE_SIZE),
            bins: std::mem::take(&mut scratch.bins),
        };
        frame.bins.resize(tiles, Vec::new());
        let spare = Mutex::new(std::mem::take(&mut scratch.chunks));
        // Opaque objects first, then blended ones back to front (the bins keep this order).
        for oi in scene.draw_order() {
            let obj = &scene.objects[oi];
            let alpha_tested = frame.visibility[oi] == Visibility::AlphaTested;
            let chunks = if path == Path::Reference || matches!(frame.modes[oi], Mode::Scalar) {
                let keep = Keep {
                    corners: true,
                    planes: false,
                };
                frame.setup_object_full(oi, obj, clip_from_world, keep)
            } else if alpha_tested || obj.shading.interpolation == Interpolation::Flat {
                // The alpha test reads the reference's coordinates (`Corners`), the shading the
                // planes; flat triangles are lit at their centroids by the vector kernel.
                let keep = Keep {
                    corners: alpha_tested,
                    planes: true,
                };
                frame.setup_object_full(oi, obj, clip_from_world, keep)
            } else {
                frame.setup_object_fast(oi, obj, clip_from_world, scratch, &spare)
            };
            frame.bin_chunks(chunks);
        }
        scratch.chunks = spare.into_inner().unwrap_or_default();
        frame
    }

    /// Gives the frame's memory back to `scratch`, emptied, for the next frame. Spare chunks are kept up to the number this frame used: the full set-up makes chunks
    /// of its own rather than taking spare ones, and keeping all of them grew the memory of
    /// every repeated frame that has such objects.
    pub fn recycle(self, scratch: &mut Scratch) {
        let keep = self.tris.len();
        for mut chunk in self.tris {
            if scratch.chunks.len() >= keep {
                break;
            }
            chunk.clear();
            scratch.chunks.push(chunk);
        }
        scratch.bins = self.bins;
        for bin in &mut scratch.bins {
            bin.clear();
        }
    }

    /// The triangle with packed id `id` (chunk in the high bits, index in the low ones).
    #[inline]
    pub fn tri(&self, id: u32) -> &Tri {
        &self.tris[(id >> ID_INDEX_BITS) as usize].tris[(id & ((1 << ID_INDEX_BITS) - 1)) as usize]
    }

    /// The object of triangle `id`.
    #[inline]
    pub fn object(&self, id: u32) -> usize {
        self.tris[(id >> ID_INDEX_BITS) as usize].object as usize
    }

    /// The fast path's plane equations of triangle `id`.
    #[inline]
    pub fn planes(&self, id: u32) -> &Planes {
        &self.tris[(id >> ID_INDEX_BITS) as usize].planes[(id & ((1 << ID_INDEX_BITS) - 1)) as usize]
    }

    /// The planes of a textured triangle's texture coordinates ([`Mode::Textured`]).
    #[inline]
    pub fn uv_planes(&self, id: u32) -> &Planes {
        &self.tris[(id >> ID_INDEX_BITS) as usize].uv[(id & ((1 << ID_INDEX_BITS) - 1)) as usize]
    }

    /// The [`Corners`] of triangle `id` (kept for the reference path and scalar-shaded objects).
    #[inline]
    pub fn corners(&self, id: u32) -> &Corners {
        &self.tris[(id >> ID_INDEX_BITS) as usize].corners[(id & ((1 << ID_INDEX_BITS) - 1)) as usize]
    }

    /// Pixel rectangle `(x0, y0, x1, y1)` of `tile` (exclusive max).
    pub fn tile_rect(&self, tile: u32) -> (u32, u32, u32, u32) {
        let (tx, ty) = (tile % self.tiles_x, tile / self.tiles_x);
        let (x0, y0) = (tx * TILE_SIZE, ty * TILE_SIZE);
        (x0, y0, (x0 + TILE_SIZE).min(self.w), (y0 + TILE_SIZE).min(self.h))
    }
}

/// Renders into `pixels`, the scene's size row-major (8-bit pixels encoded by `encoding`);
/// every pixel is written.
pub(crate) fn render<P: Pixel>(
    scene: &Scene,
    options: &RenderOptions,
    pixels: &mut [P],
    encoding: Encoding,
    scratch: &mut Scratch,
) -> Result<RenderStats, Error> {
    let t0 = Instant::now();
    let path = if options.reference { Path::Reference } else { Path::Fast };
    let frame = Frame::build(scene, path, Isa::detect(!options.no_avx2, !options.no_avx512), scratch);
    let setup = t0.elapsed();
    let t1 = Instant::now();
    let clock = StageClock::default();
    let shaded = frame.draw_tiles(pixels, encoding, &clock, options.progress);
    let triangles_drawn = frame.tris.iter().map(|c| c.tris.len()).sum();
    frame.recycle(scratch);
    let raster = t1.elapsed();
    let (tile_raster, tile_shade, tile_resolve) = clock.into_durations();
    Ok(RenderStats {
        triangles: scene.triangle_count(),
        triangles_drawn,
        pixels_shaded: shaded,
        setup,
        raster,
        tile_raster,
        tile_shade,
        tile_resolve,
    })
}

/// Diagnostic for coverage tests: for each sample of each pixel (row-major,
/// samples innermost), how many triangles cover it, depth ignored. Culling
/// and clipping apply as in [`render`](crate::render).
pub fn coverage_counts(scene: &Scene) -> Vec<u16> {
    let frame = Frame::build(scene, Path::Fast, Isa::PORTABLE, &mut Scratch::default());
    let ns = frame.pattern.len();
    let mut counts = vec![0u16; frame.w as usize * frame.h as usize * ns];
    for t in frame.tris.iter().flat_map(|c| &c.tris) {
        let bb = t.bbox();
        for py in bb[1]..bb[3] {
            for px in bb[0]..bb[2] {
                for (s, &(ox, oy)) in frame.pattern.iter().enumerate() {
                    let sx = (i64::from(px) << SUBPIXEL_BITS) + ox;
                    let sy = (i64::from(py) << SUBPIXEL_BITS) + oy;
                    if t.covers(sx, sy).is_some() {
                        counts[(py as usize * frame.w as usize + px as usize) * ns + s] += 1;
                    }
                }
            }
        }
    }
    counts
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Ambient, emission and occlusion maps, and maps on the second set of coordinates, are
    /// drawn by the vector sampler (the fast path's textured mode), not per pixel; so is one of
    /// filters it samples lane by lane (`GL_LINEAR_MIPMAP_NEAREST`).
    #[test]
    fn ambient_emission_occlusion_and_second_set_maps_take_the_vector_sampler() {
        let src = r#"
[[light]]
type = "point"
position = [1.0, 2.0, 3.0]
[[object]]
shape = "sphere"
material = { base = "brass", ambient_map = "assets/bricks.png", emission_map = "assets/checker.png" }
[[object]]
shape = "sphere"
material = { base = "brass", emission_map = "assets/checker.png" }
[[object]]
shape = "sphere"
material = { base = "brass", ambient_map = "assets/checker.png" }
"#;
        let mut scene = parsed(src);
        scene.objects[2].maps.ambient.as_mut().unwrap().sampler = linear_mipmap_nearest();
        // glTF's occlusion map, alone, on a copy of the second sphere.
        let mut o = scene.objects[1].clone();
        o.maps.emission = None;
        let map = scene.objects[1].maps.emission.clone().unwrap();
        o.maps.occlusion = Some(phong_core::Occlusion { map, strength: 1.0 });
        scene.objects.push(o);
        // A map on the second set of coordinates.
        let mut o = scene.objects[0].clone();
        o.mesh = o.mesh.clone().with_uvs1(o.mesh.uvs().to_vec()).unwrap();
        o.maps.ambient.as_mut().unwrap().set = 1;
        scene.objects.push(o);
        let frame = Frame::build(&scene, Path::Fast, Isa::PORTABLE, &mut Scratch::default());
        for i in [0, 1, 2, 3, 4] {
            assert!(matches!(frame.modes[i], Mode::Textured { .. }), "object {i}");
            assert!(frame.vector_maps[i].is_some_and(|m| m.split()), "object {i}");
        }
    }

    /// An object with a normal (or bump) map is drawn by the vector sampler, its tangents in
    /// its coordinates' planes, whatever the map's filters; with a second set of coordinates it
    /// is shaded per pixel. So is one with a shininess map, unless the map reads its alpha (not
    /// gathered).
    #[test]
    fn normal_and_shininess_maps_take_the_vector_sampler() {
        let src = r#"
[[light]]
type = "point"
position = [1.0, 2.0, 3.0]
[[object]]
shape = "sphere"
material = { base = "brass", bump_map = "assets/bricks_height.png" }
[[object]]
shape = "torus"
material = { base = "brass", diffuse_map = "assets/bricks.png", emission_map = "assets/checker.png", bump_map = "assets/bricks_height.png" }
[[object]]
shape = "sphere"
material = { base = "brass", bump_map = "assets/checker.png" }
[[object]]
shape = "sphere"
material = { base = "brass", diffuse_map = "assets/bricks.png" }
"#;
        let mut scene = parsed(src);
        scene.objects[2].maps.normal.as_mut().unwrap().map.sampler = linear_mipmap_nearest();
        // A normal map beside a map on the second set.
        let mut o = scene.objects[1].clone();
        o.mesh = o.mesh.clone().with_uvs1(o.mesh.uvs().to_vec()).unwrap();
        o.maps.emission.as_mut().unwrap().set = 1;
        scene.objects.push(o);
        // A shininess map (the diffuse map's image), then the same on its alpha channel.
        let mut o = scene.objects[3].clone();
        let map = o.maps.diffuse.clone().unwrap();
        o.maps.shininess = Some((map, phong_core::Channel::Luminance));
        scene.objects.push(o.clone());
        o.maps.shininess.as_mut().unwrap().1 = phong_core::Channel::A;
        scene.objects.push(o);
        let frame = Frame::build(&scene, Path::Fast, Isa::PORTABLE, &mut Scratch::default());
        for i in [0, 1, 2] {
            assert!(matches!(frame.modes[i], Mode::Textured { .. }), "object {i}");
            assert!(frame.vector_maps[i].is_some(), "object {i}");
            assert_eq!(frame.extras[i], Extra::Tangents, "object {i}");
        }
        assert!(matches!(frame.modes[3], Mode::Textured { .. }));
        // No vertex colours, second set or tangents: the coordinates' planes alone.
        assert_eq!(frame.extras[3], Extra::Nothing);
        assert!(matches!(frame.modes[4], Mode::Scalar));
        assert_eq!(frame.extras[4], Extra::SecondSet);
        assert!(matches!(frame.modes[5], Mode::Textured { .. }));
        assert!(frame.vector_maps[5].is_some());
        assert!(matches!(frame.modes[6], Mode::Scalar));
    }

    /// The scene of TOML `src`, its files relative to `examples/scenes` (its `assets`).
    fn parsed(src: &str) -> Scene {
        let at = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenes/test.toml");
        phong_scene::parse_scene(src, &at).unwrap().scene
    }

    /// `GL_LINEAR_MIPMAP_NEAREST` (glTF can ask for it), which the vector sampler samples lane by
    /// lane.
    fn linear_mipmap_nearest() -> phong_core::Sampler {
        phong_core::Sampler {
            mip: phong_core::MipFilter::Nearest,
            ..phong_core::Sampler::trilinear(phong_core::Wrap::Repeat)
        }
    }

    /// A Gouraud-shaded textured object is drawn by the vector sampler from its vertices'
    /// primary and specular colours (only its diffuse and specular maps apply, so its other
    /// maps do not matter, nor does their filter), a flat-shaded one from its triangles'; with
    /// a metallic-roughness map, or vertex colours beside a second set, it is shaded per pixel.
    #[test]
    fn gouraud_textured_objects_take_the_vector_sampler() {
        let src = r#"
[shading]
interpolation = "gouraud"
[[light]]
type = "point"
position = [1.0, 2.0, 3.0]
[[object]]
shape = "sphere"
material = { base = "brass", diffuse_map = "assets/bricks.png", specular_map = "assets/checker.png" }
[[object]]
shape = "torus"
material = { base = "brass", diffuse_map = "assets/bricks.png", emission_map = "assets/checker.png", bump_map = "assets/bricks_height.png" }
[[object]]
shape = "sphere"
interpolation = "flat"
material = { base = "brass", diffuse_map = "assets/bricks.png" }
"#;
        let mut scene = parsed(src);
        // glTF's metallic-roughness map on a copy of the first sphere.
        let mut o = scene.objects[0].clone();
        let map = o.maps.diffuse.clone().unwrap();
        o.maps.metal_rough = Some(phong_core::MetalRough {
            map,
            base_factor: phong_core::Color::WHITE,
            metallic: 1.0,
            roughness: 0.5,
        });
        scene.objects.push(o);
        let frame = Frame::build(&scene, Path::Fast, Isa::PORTABLE, &mut Scratch::default());
        for i in [0, 1] {
            assert!(
                matches!(frame.modes[i], Mode::Textured { per_vertex: true, .. }),
                "object {i}"
            );
            let maps = frame.vector_maps[i].expect("covered");
            assert!(maps.per_vertex() && !maps.split() && !maps.full(), "object {i}");
        }
        assert_eq!(
            frame.extras[1],
            Extra::Nothing,
            "no tangents: the normal map does not apply"
        );
        assert!(matches!(frame.modes[2], Mode::Textured { per_vertex: true, .. }));
        assert!(matches!(frame.modes[3], Mode::Scalar));
        // A flat triangle's planes give its one colour everywhere (perspective-correct: the
        // colour over `w`, divided by `1/w`), and triangles differ.
        let flat = frame.tris.iter().filter(|c| c.object == 2);
        let planes: Vec<&Planes> = flat.flat_map(|c| &c.planes).collect();
        assert!(!planes.is_empty());
        let at = |k: [f32; 3], (dx, dy): (f32, f32)| k[0] + k[1] * dx + k[2] * dy;
        let colour = |p: &Planes, d| at(p.attr[0], d) / at(p.inv_w, d);
        for p in &planes {
            let c = colour(p, (0.0, 0.0));
            for d in [(3.0, 0.0), (0.0, -5.0), (7.5, 2.5)] {
                assert!((colour(p, d) - c).abs() <= 1e-4, "{c} vs {}", colour(p, d));
            }
        }
        assert!(
            planes
                .iter()
                .any(|p| colour(p, (0.0, 0.0)) != colour(planes[0], (0.0, 0.0)))
        );
    }

    /// Nearest filtering (`GL_NEAREST`, no mipmaps) is one gather of level 0: such maps take
    /// the vector sampler, Phong- or Gouraud-shaded, bump maps included.
    #[test]
    fn nearest_filtering_takes_the_vector_sampler() {
        let src = r#"
[[light]]
type = "point"
position = [1.0, 2.0, 3.0]
[[object]]
shape = "sphere"
material = { base = "brass", diffuse_map = "assets/bricks.png", bump_map = "assets/bricks_height.png", filter = "nearest" }
[[object]]
shape = "sphere"
interpolation = "gouraud"
material = { base = "brass", specular_map = "assets/checker.png", filter = "nearest" }
"#;
        let scene = parsed(src);
        let frame = Frame::build(&scene, Path::Fast, Isa::PORTABLE, &mut Scratch::default());
        assert!(matches!(frame.modes[0], Mode::Textured { per_vertex: false, .. }));
        assert!(matches!(frame.modes[1], Mode::Textured { per_vertex: true, .. }));
        assert!(frame.vector_maps.iter().all(Option::is_some));
    }

    /// Alpha-tested and blended objects on the fast path: an alpha-tested textured object keeps
    /// its mode (the vector sampler, which does not read the alpha map) and both its corners
    /// (for the alpha test) and its planes; a blended one is shaded per pixel.
    #[test]
    fn alpha_tested_and_blended_objects_take_the_fast_path() {
        let src = r#"
[[light]]
type = "point"
position = [1.0, 2.0, 3.0]
[[object]]
shape = "sphere"
material = { base = "brass", diffuse_map = "assets/leaf.png", alpha_map = "assets/leaf.png" }
[[object]]
shape = "sphere"
material = { base = "brass", alpha = 0.5, blend = true }
[[object]]
shape = "sphere"
material = { base = "brass", diffuse_map = "assets/bricks.png" }
"#;
        let scene = parsed(src);
        let frame = Frame::build(&scene, Path::Fast, Isa::PORTABLE, &mut Scratch::default());
        assert_eq!(
            frame.visibility,
            [Visibility::AlphaTested, Visibility::Blended, Visibility::Opaque]
        );
        assert!(matches!(frame.modes[0], Mode::Textured { per_vertex: false, .. }));
        assert!(frame.vector_maps[0].is_some());
        assert!(matches!(frame.modes[1], Mode::Scalar));
        let object = |o: u32| frame.tris.iter().filter(move |c| c.object == o);
        assert!(object(0).all(|c| c.corners.len() == c.tris.len() && c.planes.len() == c.tris.len()));
        assert!(object(0).all(|c| c.uv.len() == c.tris.len()));
        assert!(object(0).any(|c| !c.tris.is_empty()));
        assert!(object(2).all(|c| c.corners.is_empty()));
    }
}
