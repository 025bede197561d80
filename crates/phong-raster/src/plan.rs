//! The decisions made once per frame, before any triangle is touched: which path draws it,
//! the instruction set, the sample pattern, the background, and for each object how it is set
//! up and shaded ([`ObjectPlan::decide`]). The stages after it (`setup`, `tile`) read these
//! values and decide nothing of their own about an object.

use crate::fixed::pattern;
use crate::setup::{Extra, Keep, SampleSpan};
use crate::simd::{Batch, Isa, Lean, Prepared, Term, VectorMaps};
use crate::target::resolve;
use glam::Mat4;
use phong_core::limits::TILE_SIZE;
use phong_core::{Camera, Interpolation, Lighting, Object, Output, Scene, View};

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
    /// Interpolated position and normal, the vector kernel; the term shown, and the lean
    /// kernel's data where that kernel shades the object (its colour, the common lights and
    /// models: `simd/lean.rs`).
    Phong(Prepared, Term, Option<Lean>),
    /// Interpolated vertex colours (flat: the triangle's colour).
    Gouraud,
    /// A textured object's colour, Phong-interpolated: light and maps by the vector sampler
    /// where it covers the maps ([`ObjectPlan::maps`]), else the light by the vector kernel
    /// (`shade_batch_lit`) and the maps sampled per pixel from the planes of its texture
    /// coordinates. With `per_vertex` (Gouraud and flat, always with the vector sampler), the
    /// vertices (flat: the triangle) are lit into primary and specular colours, which the
    /// triangle's planes carry instead of position and normal. `lean`: the lean kernel's
    /// data where it lights the object's pixels (per pixel, no map that changes the light or
    /// needs the light's terms apart).
    Textured {
        prep: Prepared,
        per_vertex: bool,
        lean: Option<Lean>,
    },
    /// One pixel at a time, as the reference path (textured objects the vector kernels do not
    /// cover, normal and depth outputs, blended objects).
    Scalar,
}

impl Mode {
    /// The vector kernels' batch for this mode; `None` for scalar shading.
    pub fn batch(&self) -> Option<Batch<'_>> {
        match self {
            Mode::Phong(prep, _, Some(lean)) => Some(Batch::Lean(prep, lean)),
            Mode::Phong(prep, term, None) => Some(Batch::Phong(prep, *term)),
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
    /// the reference's arithmetic (`Tiles::alpha_passes`): the object keeps its corners.
    AlphaTested,
    /// Blended over the opaque image after it is shaded, without writing depth
    /// (`Object::blends`): shaded per pixel ([`Mode::Scalar`]).
    Blended,
}

/// Which setup makes an object's triangles.
#[derive(Clone, Copy, Debug)]
pub(crate) enum SetupKind {
    /// The fast path's lean setup (`setup::fast`): 20-byte vertex records, planes only.
    Fast,
    /// Every vertex in full (`setup::full`), keeping what [`Keep`] asks for.
    Full(Keep),
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

/// Everything the stages need to know about how one object is drawn, decided once.
pub(crate) struct ObjectPlan<'a> {
    /// How its pixels are shaded on the fast path.
    pub mode: Mode,
    /// Its maps as the vector sampler reads them (a [`Mode::Textured`] object whose maps the
    /// sampler covers).
    pub maps: Option<VectorMaps<'a>>,
    /// How its points reach the image.
    pub visibility: Visibility,
    /// Whether a map reads the mesh's second set of texture coordinates.
    pub second_set: bool,
    /// What its coordinates' planes carry beside the first set.
    pub extra: Extra,
    /// Its view vector rule.
    pub view: View,
    /// Which setup makes its triangles.
    pub setup: SetupKind,
}

impl<'a> ObjectPlan<'a> {
    /// How `object` is drawn under `lighting` and `camera` on `path`. The rules, one row per
    /// case, are the table in this module's `every_case_takes_its_path` test.
    pub fn decide(object: &'a Object, lighting: &Lighting, camera: &Camera, path: Path) -> ObjectPlan<'a> {
        let view = camera.view(object.shading.viewer);
        let second_set = object.maps.uses_second_set();
        let visibility = visibility(object);
        // The vector sampler's reading of the maps, where it can read them all.
        let sampler = if object.textured() {
            VectorMaps::new(&object.maps)
        } else {
            None
        };
        let mode = mode(object, lighting, view, visibility, second_set, sampler);
        let colors = !object.mesh.colors().is_empty();
        let maps = match mode {
            Mode::Textured { per_vertex, .. } => sampler
                .and_then(|v| if per_vertex { v.lit_per_vertex() } else { Some(v) })
                .map(|v| v.tinted(colors)),
            _ => None,
        };
        let extra = match mode {
            Mode::Textured { per_vertex: false, .. } if object.maps.normal.is_some() => Extra::Tangents,
            _ if second_set => Extra::SecondSet,
            _ if colors => Extra::Colors,
            _ => Extra::Nothing,
        };
        let alpha_tested = visibility == Visibility::AlphaTested;
        let setup = if path == Path::Reference || matches!(mode, Mode::Scalar) {
            SetupKind::Full(Keep {
                corners: true,
                planes: false,
            })
        } else if alpha_tested || object.shading.interpolation == Interpolation::Flat {
            // The alpha test reads the reference's coordinates (corners), the shading the
            // planes; flat triangles are lit at their centroids by the vector kernel.
            SetupKind::Full(Keep {
                corners: alpha_tested,
                planes: true,
            })
        } else {
            SetupKind::Fast
        };
        ObjectPlan {
            mode,
            maps,
            visibility,
            second_set,
            extra,
            view,
            setup,
        }
    }
}

/// How `object`'s points reach the image.
fn visibility(object: &Object) -> Visibility {
    if object.blends() {
        Visibility::Blended
    } else if object.textured() && lit_term(object.shading.output).is_some() && object.maps.alpha_cutoff.is_some() {
        // (`Tiles::shade_pixel` applies the alpha test to these points only.)
        Visibility::AlphaTested
    } else {
        Visibility::Opaque
    }
}

/// How the fast path shades `object`'s pixels; `sampler`: its maps as the vector sampler reads
/// them, where it can.
fn mode(
    object: &Object,
    lighting: &Lighting,
    view: View,
    visibility: Visibility,
    second_set: bool,
    sampler: Option<VectorMaps>,
) -> Mode {
    let Some(term) = lit_term(object.shading.output) else {
        return Mode::Scalar;
    };
    if visibility == Visibility::Blended {
        return Mode::Scalar;
    }
    let prepared = || Prepared::new(lighting, &object.material, &object.shading.options, view);
    if !object.textured() {
        return match object.shading.interpolation {
            Interpolation::Phong => {
                let prep = prepared();
                let lean = if term == Term::Color { Lean::of(&prep) } else { None };
                Mode::Phong(prep, term, lean)
            }
            // Flat: the triangle's colour, planes without slope.
            Interpolation::Gouraud | Interpolation::Flat => Mode::Gouraud,
        };
    }
    if term != Term::Color {
        return Mode::Scalar;
    }
    let m = &object.maps;
    // Ambient, emission and occlusion maps need the light's terms apart, which only the
    // vector sampler keeps (`Prepared::emission_apart`).
    let split = m.apart() != (false, false);
    let colors = !object.mesh.colors().is_empty();
    // Normal, shininess and metallic-roughness maps change the light, which only the vector
    // sampler samples them for.
    let changes_light = m.normal.is_some() || m.shininess.is_some() || m.metal_rough.is_some();
    let per_pixel_light = ((split || changes_light) && sampler.is_none())
        // The second set takes the vertex colours' planes, the tangents both.
        || (second_set && colors)
        || (m.normal.is_some() && (second_set || colors));
    match object.shading.interpolation {
        Interpolation::Phong if !per_pixel_light => {
            let prep = if split {
                prepared().emission_apart(lighting, &object.material)
            } else {
                prepared()
            };
            let lean = if split || changes_light { None } else { Lean::of(&prep) };
            Mode::Textured {
                prep,
                per_vertex: false,
                lean,
            }
        }
        // Gouraud and flat: only the diffuse and specular maps apply, by the sampler
        // (`VectorMaps::lit_per_vertex`); the second set takes the colours' planes.
        Interpolation::Gouraud | Interpolation::Flat
            if !(second_set && colors) && sampler.and_then(VectorMaps::lit_per_vertex).is_some() =>
        {
            Mode::Textured {
                prep: prepared(),
                per_vertex: true,
                lean: None,
            }
        }
        _ => Mode::Scalar,
    }
}

/// The frame's decisions, made once and read by every stage after.
pub(crate) struct FramePlan<'a> {
    pub path: Path,
    pub isa: Isa,
    /// The image's size in pixels.
    pub w: u32,
    pub h: u32,
    /// World to clip space, at the image's aspect ratio.
    pub clip_from_world: Mat4,
    /// The sample offsets from a pixel's corner, in 1/256 pixel.
    pub pattern: Vec<(i64, i64)>,
    /// The pattern's bounds, for the triangles' bounding boxes.
    pub span: SampleSpan,
    /// The scene's background colour, for the resolve of partly covered pixels.
    pub bg: [f32; 4],
    /// An uncovered pixel: the resolve of its background samples.
    pub background: [f32; 4],
    /// Tiles in a row.
    pub tiles_x: u32,
    /// The fast path with every object Gouraud-shaded (see `tile::gouraud`).
    pub gouraud_only: bool,
    /// `gouraud_only` with one sample: the set-up keeps each triangle's
    /// [`ColourPlanes`](crate::simd::ColourPlanes) (`Chunk::colour`), not its whole
    /// [`Planes`](crate::simd::Planes), for the tiles that read only those
    /// (`tile::gouraud`, and a covered tile's 8-bit shading).
    pub colour_planes: bool,
    /// The fast path with one sample and every object opaque and shaded by the vector kernels
    /// per pixel, untextured ([`Mode::Phong`]): one-sample tiles of 8-bit frames are then
    /// shaded and encoded straight into the frame (`Tiles::tile_single8`).
    pub phong_only: bool,
    /// Every object opaque (no alpha test, no blending): a multi-sample tile's triangles then
    /// all go through one visibility kernel call (`Tiles::tile_multi`).
    pub opaque_only: bool,
    /// Per object, in the scene's order.
    pub objects: Vec<ObjectPlan<'a>>,
}

impl<'a> FramePlan<'a> {
    /// The plan of `scene` on `path` with the kernels of `isa`.
    pub fn new(scene: &'a Scene, path: Path, isa: Isa) -> FramePlan<'a> {
        let (w, h) = (scene.image.width, scene.image.height);
        let objects: Vec<ObjectPlan> = scene
            .objects
            .iter()
            .map(|o| ObjectPlan::decide(o, &scene.lighting, &scene.camera, path))
            .collect();
        let pattern = pattern(scene.image.samples);
        let bg = scene.image.background;
        let ns = pattern.len();
        let gouraud_only = path == Path::Fast && objects.iter().all(|o| matches!(o.mode, Mode::Gouraud));
        FramePlan {
            path,
            isa,
            w,
            h,
            clip_from_world: scene.camera.clip_from_world(w as f32 / h as f32),
            span: SampleSpan::of(&pattern),
            pattern,
            bg,
            background: resolve(std::iter::repeat_n(bg, ns), ns, bg),
            tiles_x: w.div_ceil(TILE_SIZE),
            gouraud_only,
            colour_planes: gouraud_only && ns == 1,
            phong_only: path == Path::Fast
                && ns == 1
                && objects
                    .iter()
                    .all(|o| matches!(o.mode, Mode::Phong(..)) && o.visibility == Visibility::Opaque),
            opaque_only: objects.iter().all(|o| o.visibility == Visibility::Opaque),
            objects,
        }
    }

    /// The number of tiles.
    pub fn tiles(&self) -> usize {
        (self.tiles_x * self.h.div_ceil(TILE_SIZE)) as usize
    }

    /// Pixel rectangle `(x0, y0, x1, y1)` of `tile` (exclusive max).
    pub fn tile_rect(&self, tile: u32) -> (u32, u32, u32, u32) {
        let (tx, ty) = (tile % self.tiles_x, tile / self.tiles_x);
        let (x0, y0) = (tx * TILE_SIZE, ty * TILE_SIZE);
        (x0, y0, (x0 + TILE_SIZE).min(self.w), (y0 + TILE_SIZE).min(self.h))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::setup::Scratch;
    use crate::simd::Planes;

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
        let frame = FramePlan::new(&scene, Path::Fast, Isa::PORTABLE);
        for i in [0, 1, 2, 3, 4] {
            assert!(matches!(frame.objects[i].mode, Mode::Textured { .. }), "object {i}");
            assert!(frame.objects[i].maps.is_some_and(|m| m.split()), "object {i}");
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
        let frame = FramePlan::new(&scene, Path::Fast, Isa::PORTABLE);
        for i in [0, 1, 2] {
            assert!(matches!(frame.objects[i].mode, Mode::Textured { .. }), "object {i}");
            assert!(frame.objects[i].maps.is_some(), "object {i}");
            assert_eq!(frame.objects[i].extra, Extra::Tangents, "object {i}");
        }
        assert!(matches!(frame.objects[3].mode, Mode::Textured { .. }));
        // No vertex colours, second set or tangents: the coordinates' planes alone.
        assert_eq!(frame.objects[3].extra, Extra::Nothing);
        assert!(matches!(frame.objects[4].mode, Mode::Scalar));
        assert_eq!(frame.objects[4].extra, Extra::SecondSet);
        assert!(matches!(frame.objects[5].mode, Mode::Textured { .. }));
        assert!(frame.objects[5].maps.is_some());
        assert!(matches!(frame.objects[6].mode, Mode::Scalar));
    }

    /// One line of an object's plan, for the table below: mode (`phong-lean`: the lean colour
    /// kernel), whether the vector sampler
    /// reads its maps, visibility, what its coordinates' planes carry, and its setup.
    fn row(plan: &ObjectPlan) -> String {
        let mode = match plan.mode {
            Mode::Phong(_, _, Some(_)) => "phong-lean",
            Mode::Phong(..) => "phong",
            Mode::Gouraud => "gouraud",
            Mode::Textured { per_vertex: false, .. } => "textured",
            Mode::Textured { per_vertex: true, .. } => "textured-per-vertex",
            Mode::Scalar => "scalar",
        };
        let maps = if plan.maps.is_some() { "sampler" } else { "-" };
        let visibility = match plan.visibility {
            Visibility::Opaque => "opaque",
            Visibility::AlphaTested => "alpha-tested",
            Visibility::Blended => "blended",
        };
        let extra = match plan.extra {
            Extra::Nothing => "-",
            Extra::Colors => "colors",
            Extra::SecondSet => "second-set",
            Extra::Tangents => "tangents",
        };
        let setup = match plan.setup {
            SetupKind::Fast => "fast",
            SetupKind::Full(Keep {
                corners: true,
                planes: true,
            }) => "full(corners+planes)",
            SetupKind::Full(Keep { corners: true, .. }) => "full(corners)",
            SetupKind::Full(Keep { planes: true, .. }) => "full(planes)",
            SetupKind::Full(_) => "full()",
        };
        format!("{mode} {maps} {visibility} {extra} {setup}")
    }

    /// How each kind of object is drawn: one row per map, interpolation and option that
    /// changes the path, with the plan [`ObjectPlan::decide`] must make for it. This table is
    /// the documentation of the rules (ARCHITECTURE.md points here).
    #[test]
    fn every_case_takes_its_path() {
        use phong_core::{Channel, Color, MetalRough};
        // (what, the object's TOML, a change made after parsing, the path, the plan's row)
        type Change = fn(&mut Object);
        let none: Change = |_| {};
        fn colours(o: &mut Object) {
            let n = o.mesh.positions().len();
            o.mesh = o.mesh.clone().with_colors(vec![Color::new(1.0, 0.5, 0.25); n]).unwrap();
        }
        fn second_set(o: &mut Object) {
            o.mesh = o.mesh.clone().with_uvs1(o.mesh.uvs().to_vec()).unwrap();
            o.maps.diffuse.as_mut().unwrap().set = 1;
        }
        fn second_set_and_colours(o: &mut Object) {
            second_set(o);
            colours(o);
        }
        let shininess_from_alpha: Change = |o| {
            let map = o.maps.diffuse.clone().unwrap();
            o.maps.shininess = Some((map, Channel::A));
        };
        let metal_rough: Change = |o| {
            let map = o.maps.diffuse.clone().unwrap();
            o.maps.metal_rough = Some(MetalRough {
                map,
                base_factor: Color::WHITE,
                metallic: 1.0,
                roughness: 0.5,
            });
        };
        let normalised: Change = |o| o.shading.options.normalization = phong_core::Normalization::BlinnPhong;
        let lyon: Change = |o| {
            o.shading.options.specular = phong_core::SpecularModel::Lyon {
                squarings: 3,
                lambda: phong_core::LyonLambda::Dot,
            }
        };
        let diffuse = r#"material = { base = "brass", diffuse_map = "assets/bricks.png" }"#;
        let bump = r#"material = { base = "brass", diffuse_map = "assets/bricks.png", bump_map = "assets/bricks_height.png" }"#;
        let emission = r#"material = { base = "brass", emission_map = "assets/checker.png" }"#;
        let rows: &[(&str, &str, Change, Path, &str)] = &[
            ("plain, per pixel", "", none, Path::Fast, "phong-lean - opaque - fast"),
            (
                "energy-normalised (the general kernel)",
                "",
                normalised,
                Path::Fast,
                "phong - opaque - fast",
            ),
            (
                "Lyon's model (the general kernel)",
                "",
                lyon,
                Path::Fast,
                "phong - opaque - fast",
            ),
            (
                "plain, diffuse term",
                r#"output = "diffuse""#,
                none,
                Path::Fast,
                "phong - opaque - fast",
            ),
            (
                "plain, per vertex",
                r#"interpolation = "gouraud""#,
                none,
                Path::Fast,
                "gouraud - opaque - fast",
            ),
            (
                "plain, flat",
                r#"interpolation = "flat""#,
                none,
                Path::Fast,
                "gouraud - opaque - full(planes)",
            ),
            (
                "vertex colours (multiply the diffuse texel)",
                "",
                colours,
                Path::Fast,
                "textured - opaque colors fast",
            ),
            (
                "vertex colours, per vertex",
                r#"interpolation = "gouraud""#,
                colours,
                Path::Fast,
                "scalar - opaque colors full(corners)",
            ),
            (
                "normal output",
                r#"output = "normal""#,
                none,
                Path::Fast,
                "scalar - opaque - full(corners)",
            ),
            (
                "reference path",
                "",
                none,
                Path::Reference,
                "phong-lean - opaque - full(corners)",
            ),
            (
                "blended",
                r#"material = { base = "brass", alpha = 0.5, blend = true }"#,
                none,
                Path::Fast,
                "scalar - blended - full(corners)",
            ),
            (
                "diffuse map",
                diffuse,
                none,
                Path::Fast,
                "textured sampler opaque - fast",
            ),
            (
                "diffuse map, reference path",
                diffuse,
                none,
                Path::Reference,
                "textured sampler opaque - full(corners)",
            ),
            (
                "diffuse map, diffuse term",
                &format!("{diffuse}\noutput = \"diffuse\""),
                none,
                Path::Fast,
                "scalar - opaque - full(corners)",
            ),
            (
                "diffuse map, per vertex",
                &format!("{diffuse}\ninterpolation = \"gouraud\""),
                none,
                Path::Fast,
                "textured-per-vertex sampler opaque - fast",
            ),
            (
                "diffuse map, flat",
                &format!("{diffuse}\ninterpolation = \"flat\""),
                none,
                Path::Fast,
                "textured-per-vertex sampler opaque - full(planes)",
            ),
            (
                "diffuse map, vertex colours",
                diffuse,
                colours,
                Path::Fast,
                "textured sampler opaque colors fast",
            ),
            (
                "diffuse map, second set",
                diffuse,
                second_set,
                Path::Fast,
                "textured sampler opaque second-set fast",
            ),
            (
                "second set and vertex colours",
                diffuse,
                second_set_and_colours,
                Path::Fast,
                "scalar - opaque second-set full(corners)",
            ),
            (
                "second set and colours, per vertex",
                &format!("{diffuse}\ninterpolation = \"gouraud\""),
                second_set_and_colours,
                Path::Fast,
                "scalar - opaque second-set full(corners)",
            ),
            (
                "bump map",
                bump,
                none,
                Path::Fast,
                "textured sampler opaque tangents fast",
            ),
            (
                "bump map, per vertex (no tangents)",
                &format!("{bump}\ninterpolation = \"gouraud\""),
                none,
                Path::Fast,
                "textured-per-vertex sampler opaque - fast",
            ),
            (
                "bump map and vertex colours",
                bump,
                colours,
                Path::Fast,
                "scalar - opaque colors full(corners)",
            ),
            (
                "emission map",
                emission,
                none,
                Path::Fast,
                "textured sampler opaque - fast",
            ),
            (
                "shininess from a map's alpha",
                diffuse,
                shininess_from_alpha,
                Path::Fast,
                "scalar - opaque - full(corners)",
            ),
            (
                "metallic-roughness map",
                diffuse,
                metal_rough,
                Path::Fast,
                "textured sampler opaque - fast",
            ),
            (
                "metallic-roughness map, per vertex",
                &format!("{diffuse}\ninterpolation = \"gouraud\""),
                metal_rough,
                Path::Fast,
                "scalar - opaque - full(corners)",
            ),
            (
                "alpha test",
                r#"material = { base = "brass", diffuse_map = "assets/leaf.png", alpha_map = "assets/leaf.png" }"#,
                none,
                Path::Fast,
                "textured sampler alpha-tested - full(corners+planes)",
            ),
            (
                "alpha test, reference path",
                r#"material = { base = "brass", diffuse_map = "assets/leaf.png", alpha_map = "assets/leaf.png" }"#,
                none,
                Path::Reference,
                "textured sampler alpha-tested - full(corners)",
            ),
        ];
        let mut wrong = Vec::new();
        for &(what, object, change, path, want) in rows {
            let src = format!(
                "[[light]]\ntype = \"point\"\nposition = [1.0, 2.0, 3.0]\n[[object]]\nshape = \"sphere\"\n{object}\n"
            );
            let mut scene = parsed(&src);
            change(&mut scene.objects[0]);
            let plan = ObjectPlan::decide(&scene.objects[0], &scene.lighting, &scene.camera, path);
            let got = row(&plan);
            if got != want {
                wrong.push(format!("{what}: {got} (want {want})"));
            }
        }
        assert!(wrong.is_empty(), "{}", wrong.join("\n"));
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
        let frame = FramePlan::new(&scene, Path::Fast, Isa::PORTABLE);
        let binned = crate::setup::run(&frame, &scene, &mut Scratch::default());
        for i in [0, 1] {
            assert!(
                matches!(frame.objects[i].mode, Mode::Textured { per_vertex: true, .. }),
                "object {i}"
            );
            let maps = frame.objects[i].maps.expect("covered");
            assert!(maps.per_vertex() && !maps.split() && !maps.full(), "object {i}");
        }
        assert_eq!(
            frame.objects[1].extra,
            Extra::Nothing,
            "no tangents: the normal map does not apply"
        );
        assert!(matches!(frame.objects[2].mode, Mode::Textured { per_vertex: true, .. }));
        assert!(matches!(frame.objects[3].mode, Mode::Scalar));
        // A flat triangle's planes give its one colour everywhere (perspective-correct: the
        // colour over `w`, divided by `1/w`), and triangles differ.
        let flat = binned.tris.iter().filter(|c| c.object == 2);
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
        let frame = FramePlan::new(&scene, Path::Fast, Isa::PORTABLE);
        assert!(matches!(
            frame.objects[0].mode,
            Mode::Textured { per_vertex: false, .. }
        ));
        assert!(matches!(frame.objects[1].mode, Mode::Textured { per_vertex: true, .. }));
        assert!(frame.objects.iter().all(|o| o.maps.is_some()));
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
        let frame = FramePlan::new(&scene, Path::Fast, Isa::PORTABLE);
        let binned = crate::setup::run(&frame, &scene, &mut Scratch::default());
        assert_eq!(
            frame.objects.iter().map(|o| o.visibility).collect::<Vec<_>>(),
            [Visibility::AlphaTested, Visibility::Blended, Visibility::Opaque]
        );
        assert!(matches!(
            frame.objects[0].mode,
            Mode::Textured { per_vertex: false, .. }
        ));
        assert!(frame.objects[0].maps.is_some());
        assert!(matches!(frame.objects[1].mode, Mode::Scalar));
        let object = |o: u32| binned.tris.iter().filter(move |c| c.object == o);
        assert!(object(0).all(|c| c.corners.len() == c.tris.len() && c.planes.len() == c.tris.len()));
        assert!(object(0).all(|c| c.uv.len() == c.tris.len()));
        assert!(object(0).any(|c| !c.tris.is_empty()));
        assert!(object(2).all(|c| c.corners.is_empty()));
    }
}
