//! Triangle setup, binning, tiles: coverage, depth, shading, resolve.
//!
//! Coverage is exact: vertices are snapped to 1/256 pixel
//! ([`SUBPIXEL_BITS`]) and edge functions are evaluated in `i64`, with the
//! top-left rule deciding samples exactly on an edge, so triangles that share
//! an edge cover each sample once. The scalar reference path (`Frame::tile`) is kept
//! simple: each sample evaluates its three edge functions directly.
//!
//! The fast path (`Frame::tile_visible`) finds visibility with the same arithmetic, then
//! shades each visible pixel once; ARCHITECTURE.md describes its steps and BENCHMARKS.md their
//! measured effects. Measured dead ends are in BENCHMARKS.md ("Dead ends", R1–R14).
//!
//! The AVX2 Gouraud tile kernel's are K1–K8 there.

use crate::clip::{ClipVertex, Clipped, NOT_FINITE, OUTSIDE_CLIP, OUTSIDE_VIEW, clip_triangle, outcode};
use crate::simd::{
    Batch, GouraudTri, Planes, Prepared, Term, avx2_available, covered_span, encode_linear, gouraud_tile, group_lanes,
    light_vertices, project_vertices, shade_batch, shade_group, stream_copy, stream_fence, stream_fill,
};
use crate::{Error, RenderOptions, RenderStats};
use glam::{Vec3, Vec4};
use phong_core::limits::{SUBPIXEL_BITS, TILE_SIZE};
use phong_core::mesh::facet_normal;
use phong_core::{Color, Encoding, Interpolation, Object, Output, Scene, View, depth_color, normal_color};
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::{Duration, Instant};

const ONE: f32 = (1u32 << SUBPIXEL_BITS) as f32;
/// Triangles per parallel setup task: large enough to amortise scheduling, small enough to
/// balance 16 threads on a 100k-triangle mesh.
const SETUP_CHUNK: usize = 4096;
/// Low bits of a triangle id that index within its setup chunk (4096 · 7 < 2^15).
const ID_INDEX_BITS: u32 = 15;
const HALF: i64 = 1 << (SUBPIXEL_BITS - 1);
/// Gouraud vertices lit together: a group is lit when any of its vertices is used (the
/// kernel's 16 lanes).
const LIGHT_GROUP: usize = 16;

/// CPU time of the tiles' stages, summed over threads, in nanoseconds.
#[derive(Default)]
struct StageClock {
    raster: AtomicU64,
    shade: AtomicU64,
    resolve: AtomicU64,
}

impl StageClock {
    fn add(&self, raster: Instant, shade: Instant, resolve: Instant, end: Instant) {
        let ns = |a: Instant, b: Instant| (b - a).as_nanos() as u64;
        self.raster.fetch_add(ns(raster, shade), Ordering::Relaxed);
        self.shade.fetch_add(ns(shade, resolve), Ordering::Relaxed);
        self.resolve.fetch_add(ns(resolve, end), Ordering::Relaxed);
    }
}

/// Resolves one pixel: the straight-alpha average of its `ns` samples, in sample order
/// (both CPU paths use it, so they sum in the same order).
#[inline]
fn resolve(samples: impl Iterator<Item = [f32; 4]>, ns: usize, bg: [f32; 4]) -> [f32; 4] {
    let mut acc = [0f32; 4];
    for s in samples {
        for k in 0..3 {
            acc[k] += s[k] * s[3];
        }
        acc[3] += s[3];
    }
    if acc[3] > 0.0 {
        [acc[0] / acc[3], acc[1] / acc[3], acc[2] / acc[3], acc[3] / ns as f32]
    } else {
        [bg[0], bg[1], bg[2], 0.0]
    }
}

/// `v.round() as i64` (half away from zero) without a libm call, exact for `|v| < 2^24`
/// (the guard band keeps snapped coordinates below that): in `f64`, `|v| + ½` is exact and
/// truncation is the floor. Branch-free: a version branching on the fraction (half the
/// vertices take each way) made the projection of a 500k-vertex mesh 16 ms; `roundf` was 3% of
/// a 1M-triangle frame.
#[inline]
fn round_i64(v: f32) -> i64 {
    let r = (f64::from(v).abs() + 0.5) as i64;
    if v < 0.0 { -r } else { r }
}

/// `[f(0), f(1), f(2)]`, always inlined: in the per-pixel and per-triangle loops, `[T; 3]::map`
/// calls were not inlined (`try_map` was 5% of a 1M-triangle frame; setup 47 → 30 ms with
/// explicit arrays).
#[inline(always)]
fn each3<U>(f: impl Fn(usize) -> U) -> [U; 3] {
    [f(0), f(1), f(2)]
}

/// `a.map(f)` for three elements, always inlined (see [`each3`]).
#[inline(always)]
fn map3<T: Copy, U>(a: [T; 3], f: impl Fn(T) -> U) -> [U; 3] {
    [f(a[0]), f(a[1]), f(a[2])]
}

pub use phong_core::limits::sample_pattern;

/// The kernel's term for a lit output; `None` for the normal and depth outputs.
fn lit_term(output: Output) -> Option<Term> {
    match output {
        Output::Color => Some(Term::Color),
        Output::Ambient => Some(Term::Ambient),
        Output::Diffuse => Some(Term::Diffuse),
        Output::Specular => Some(Term::Specular),
        _ => None,
    }
}

/// A vertex in the window: snapped `x`, `y` (1/256 pixel; the guard band keeps them below
/// 2^24), depth, `1/w`.
#[derive(Clone, Copy, Debug, Default)]
struct Projected(i32, i32, f32, f32);

/// A vertex of the fast path's setup: its projection (where inside the clipping planes) and
/// outcode. 20 bytes: the fast setup reads these instead of 64-byte [`ClipVertex`] copies (a
/// 1M-triangle setup reads three per triangle).
#[derive(Clone, Copy, Default)]
struct FastVertex {
    p: Projected,
    code: u16,
}

/// A triangle ready for the tiles: what visibility reads, 80 bytes. Its object, shading planes
/// and (where kept) [`Corners`] are in its [`Chunk`].
struct Tri {
    /// Edge functions `E_i(X, Y) = a·X + b·Y + c` (edge i opposite vertex i), in 1/256 pixel;
    /// `a` and `b` are coordinate differences (below 2^25), `c` needs 64 bits.
    a: [i32; 3],
    b: [i32; 3],
    c: [i64; 3],
    /// 1 / (twice the signed area): barycentrics are `E_i · inv_area` (a multiplication,
    /// not a division, per covered sample; together with incremental edges: teapots' raster
    /// 80 → 65 ms, same run).
    inv_area: f64,
    /// Window depth in [0, 1] per vertex.
    z: [f32; 3],
    /// Pixel bounds, inclusive min, exclusive max (images are at most 16384 wide).
    bbox: [u16; 4],
    /// Bit i: edge i is not top-left, so inside is `E_i − 1 >= 0` (else `E_i >= 0`).
    bias: u8,
    /// A back face of a two-sided object: lit with flipped normals (OpenGL's two-sided lighting).
    back: bool,
}

impl Tri {
    #[inline(always)]
    fn a(&self, i: usize) -> i64 {
        i64::from(self.a[i])
    }
    #[inline(always)]
    fn b(&self, i: usize) -> i64 {
        i64::from(self.b[i])
    }
    #[inline(always)]
    fn bias(&self, i: usize) -> i64 {
        i64::from((self.bias >> i) & 1)
    }
    #[inline(always)]
    fn bbox(&self) -> [u32; 4] {
        self.bbox.map(u32::from)
    }
}

/// The edges of a set-up triangle and how its vertices were reordered (counter-clockwise on
/// screen after the swap of a front face), for the caller's attributes.
struct Setup {
    tri: Tri,
    /// Input vertex of each set-up vertex.
    order: [usize; 3],
    xy: [(i64, i64); 3],
    inv_w: [f32; 3],
    area: u64,
    front: bool,
}

/// How many of `ids` from the start equal `k`: 8 compared at a time (a branch-free mask
/// LLVM vectorises; the element-by-element `take_while` was a ninth of a 100k-triangle Gouraud
/// frame, scanning tiles whose pixels are all coloured or all background).
#[inline]
fn run_length(ids: &[u32], k: u32) -> usize {
    let mut chunks = ids.chunks_exact(8);
    let mut n = 0;
    for c in &mut chunks {
        let mut differ = 0u32;
        for (i, &id) in c.iter().enumerate() {
            differ |= u32::from(id != k) << i;
        }
        if differ != 0 {
            return n + differ.trailing_zeros() as usize;
        }
        n += 8;
    }
    n + chunks.remainder().iter().take_while(|&&id| id == k).count()
}

/// Background pixels: streamed past the caches into the image (`image`), plain stores into a
/// task's cache-resident tile buffer (see [`TileBuffers`]).
#[inline]
fn fill_background(line: &mut [[f32; 4]], value: [f32; 4], image: bool) {
    if image {
        stream_fill(line, value);
    } else {
        line.fill(value);
    }
}

/// A tile task's working memory, reused from tile to tile: its own buffer for the image's
/// pixels (see `stream_copy`), and the depth and triangle of each sample, not allocated and
/// zeroed per tile (1M Gouraud sphere, 2 threads: page faults per frame 140 → 77).
#[derive(Default)]
struct TileBuffers {
    local: Vec<[f32; 4]>,
    depth: Vec<f32>,
    ids: Vec<u32>,
}

/// The id of a pixel coloured during visibility (see [`Forward`]); bin indices stay below it.
const FORWARD: u32 = u32::MAX - 1;

/// Gouraud on the fast path with one sample: colours written into the tile's rows as pixels
/// pass the depth test, from the triangle's colour planes.
struct Forward<'r, 'i> {
    planes: ColorPlanes,
    rows: &'r mut [&'i mut [[f32; 4]]],
}

/// A triangle's Gouraud planes (see [`Planes`]) as columns of four, `[r/w, g/w, b/w, 1/w]`, so
/// that a pixel's colour is one 4-wide vector from start to store (SSE on x86-64), the layout
/// of the `[f32; 4]` pixel it is written to.
///
/// Measured (Gouraud spheres, 1080p, 1 thread): skipping the colouring altogether took the
/// 100k sphere's tiles from about 12.5 to 7.5 ms (planes read, interpolation and image writes
/// together). Against the 8-lane kernel it replaced (one call per row of a triangle; most rows
/// have 3 to 6 pixels, whose lanes went through memory to become pixels), this layout was
/// within noise on the 100k sphere and 56.8 → 54.2 ms (medians of 5) on the 1M one.
#[derive(Clone, Copy)]
struct ColorPlanes {
    c: [f32; 4],
    gx: [f32; 4],
    gy: [f32; 4],
    origin: [f32; 2],
}

impl ColorPlanes {
    #[inline(always)]
    fn new(p: &Planes) -> ColorPlanes {
        let column = |k: usize| [p.attr[0][k], p.attr[1][k], p.attr[2][k], p.inv_w[k]];
        ColorPlanes {
            c: column(0),
            gx: column(1),
            gy: column(2),
            origin: p.origin,
        }
    }

    /// The colour at the centre of pixel `(px, py)`: `q_c / q_w`, each `q = c + gx·dx + gy·dy`
    /// in `f32` (no fused multiply-adds), an exact division: the arithmetic of the reference's
    /// interpolation of Gouraud colours.
    #[inline(always)]
    fn at(&self, px: u32, py: u32) -> [f32; 4] {
        let (dx, dy) = (px as f32 + 0.5 - self.origin[0], py as f32 + 0.5 - self.origin[1]);
        let q: [f32; 4] = std::array::from_fn(|i| self.c[i] + self.gx[i] * dx + self.gy[i] * dy);
        let w = 1.0 / q[3];
        [q[0] * w, q[1] * w, q[2] * w, 1.0]
    }
}

/// How the fast path shades an object's pixels.
enum Mode {
    /// Interpolated position and normal, the 8-lane kernel; the term shown.
    Phong(Prepared, Term),
    /// Interpolated vertex colours, 8 lanes.
    Gouraud,
    /// One pixel at a time, as the reference path (flat shading, normal and depth outputs).
    Scalar,
}

impl Mode {
    /// The vector kernels' batch for this mode; `None` for scalar shading.
    fn batch(&self) -> Option<Batch<'_>> {
        match self {
            Mode::Phong(prep, term) => Some(Batch::Phong(prep, *term)),
            Mode::Gouraud => Some(Batch::Gouraud),
            Mode::Scalar => None,
        }
    }
}

/// What the scalar shading of a triangle needs besides [`Tri`]: kept only for the reference
/// path and for objects the fast path shades one pixel at a time (a 1M-triangle frame's
/// triangles were 470 bytes each with these inside).
struct Corners {
    /// 1/w per vertex.
    inv_w: [f32; 3],
    v: [ClipVertex; 3],
    /// Flat: the triangle's colour and facet normal (as seen: flipped on a two-sided back face).
    flat: Option<(Color, Vec3)>,
}

/// The triangles one setup task made, with their [`Corners`] (same index) where kept, else
/// none.
struct Chunk {
    /// The object all its triangles belong to.
    object: u32,
    tris: Vec<Tri>,
    /// The fast path's plane equations (Phong: world position and normal, flipped on a back
    /// face; Gouraud: the colour seen), same index; empty for scalar-shaded objects.
    planes: Vec<Planes>,
    corners: Vec<Corners>,
    /// Gouraud triangles whose planes wait for their vertices' colours (see [`Pending`]).
    pending: Vec<Pending>,
    /// Gouraud: the planes of clipped triangles, by slot (the others' are in `pending`
    /// until their vertices are lit).
    clipped: Vec<(u32, Planes)>,
    /// `(tile, index)` for each tile each triangle is binned into, in triangle order (see
    /// [`Frame::bin_chunks`]).
    binned: Vec<(u32, u32)>,
}

/// A Gouraud triangle set up before its vertices were lit (in the chunk's triangle `slot`),
/// its planes made once the colours exist. 16 bytes: the rest of what the planes need (vertex
/// 0's window position, `1/w`, the area, the facing) is read again from the vertex records
/// and the triangle's edges. Keeping them here (56 bytes) was within noise at one thread and
/// slower at two (the 1M-triangle sphere's setup and planes stages, 4 interleaved pairs:
/// 9.0 / 8.5 / 13.7 / 9.2 → 8.4 / 8.2 / 7.7 / 8.9 ms): a million-triangle frame's setup is
/// bound by memory traffic there.
struct Pending {
    slot: u32,
    /// Input vertices, in the set-up order.
    idx: [u32; 3],
}

/// Working memory kept between frames by a [`Renderer`](crate::Renderer): emptied, never
/// shrunk.
#[derive(Default)]
pub(crate) struct Scratch {
    /// The fast setup's per-vertex buffers (one object at a time).
    vertices: Vec<FastVertex>,
    /// Gouraud: the lit colour of each vertex seen from the front, and (two-sided) the back;
    /// kept between frames without clearing (only the vertices of drawn triangles are lit
    /// and read).
    colors: [Vec<Vec3>; 2],
    /// Gouraud: whether a vertex is used by a drawn triangle (only those are lit).
    used: Vec<AtomicBool>,
    /// Chunks of set-up triangles, emptied, for the next frame's setup tasks.
    chunks: Vec<Chunk>,
    bins: Vec<Vec<u32>>,
}

impl Chunk {
    /// An empty chunk for `object` with room for `n` triangles, from `spare` if it has one.
    fn reuse(spare: &std::sync::Mutex<Vec<Chunk>>, object: usize, n: usize) -> Chunk {
        let mut c = spare.lock().ok().and_then(|mut s| s.pop()).unwrap_or(Chunk {
            object: 0,
            tris: Vec::new(),
            planes: Vec::new(),
            corners: Vec::new(),
            pending: Vec::new(),
            clipped: Vec::new(),
            binned: Vec::new(),
        });
        c.object = object as u32;
        c.tris.reserve(n);
        c
    }
}

struct Frame<'a> {
    scene: &'a Scene,
    /// Use the AVX2 build of the kernel (decided once per frame).
    avx2: bool,
    /// Per object: how the fast path shades it (decided once per frame).
    modes: Vec<Mode>,
    /// Every object is Gouraud-shaded on the fast path (see [`Frame::tile_visible`]).
    gouraud_only: bool,
    /// Per object: its view vector rule.
    views: Vec<View>,
    w: u32,
    h: u32,
    pattern: Vec<(i64, i64)>,
    /// The pattern's bounds, for the triangles' bounding boxes (see [`SampleSpan`]).
    span: SampleSpan,
    /// Set-up triangles, in the chunks the parallel setup made them (not copied into one
    /// vector: a 1M-triangle Gouraud frame's setup went 190 → 108 ms without that copy); ids
    /// pack (chunk, index), see [`Frame::tri`].
    tris: Vec<Chunk>,
    tiles_x: u32,
    bins: Vec<Vec<u32>>,
}

impl<'a> Frame<'a> {
    /// Transforms, lights (Gouraud, flat), clips, sets up and bins every triangle, in memory
    /// taken from `scratch` (give it back with [`Frame::recycle`]).
    fn build(scene: &'a Scene, reference: bool, avx2: bool, scratch: &mut Scratch) -> Frame<'a> {
        let (w, h) = (scene.image.width, scene.image.height);
        let aspect = w as f32 / h as f32;
        let clip_from_world = scene.camera.clip_from_world(aspect);
        let views = scene
            .objects
            .iter()
            .map(|o| scene.camera.view(o.shading.viewer))
            .collect();
        let pattern = sample_pattern(scene.image.samples)
            .into_iter()
            .map(|(x, y)| ((x * ONE).round() as i64, (y * ONE).round() as i64))
            .collect::<Vec<_>>();
        let span = SampleSpan::of(&pattern);
        let modes: Vec<Mode> = scene
            .objects
            .iter()
            .map(|o| {
                let Some(term) = lit_term(o.shading.output) else {
                    return Mode::Scalar;
                };
                match o.shading.interpolation {
                    Interpolation::Phong => Mode::Phong(
                        Prepared::new(
                            &scene.lighting,
                            &o.material,
                            &o.shading.options,
                            scene.camera.view(o.shading.viewer),
                        ),
                        term,
                    ),
                    Interpolation::Gouraud => Mode::Gouraud,
                    Interpolation::Flat => Mode::Scalar,
                }
            })
            .collect();
        let gouraud_only = !reference && modes.iter().all(|m| matches!(m, Mode::Gouraud));
        let mut frame = Frame {
            scene,
            avx2,
            gouraud_only,
            modes,
            views,
            w,
            h,
            pattern,
            span,
            tris: Vec::new(),
            tiles_x: w.div_ceil(TILE_SIZE),
            bins: std::mem::take(&mut scratch.bins),
        };
        frame
            .bins
            .resize((w.div_ceil(TILE_SIZE) * h.div_ceil(TILE_SIZE)) as usize, Vec::new());
        let spare = std::sync::Mutex::new(std::mem::take(&mut scratch.chunks));
        for (oi, obj) in scene.objects.iter().enumerate() {
            let chunks = if reference || matches!(frame.modes[oi], Mode::Scalar) {
                frame.setup_object_full(oi, obj, clip_from_world)
            } else {
                frame.setup_object_fast(oi, obj, clip_from_world, scratch, &spare)
            };
            frame.bin_chunks(chunks);
        }
        scratch.chunks = spare.into_inner().unwrap_or_default();
        frame
    }

    /// Gives the frame's memory back to `scratch`, emptied, for the next frame.
    fn recycle(self, scratch: &mut Scratch) {
        for mut chunk in self.tris {
            chunk.tris.clear();
            chunk.planes.clear();
            chunk.corners.clear();
            chunk.pending.clear();
            chunk.binned.clear();
            chunk.clipped.clear();
            scratch.chunks.push(chunk);
        }
        scratch.bins = self.bins;
        for bin in &mut scratch.bins {
            bin.clear();
        }
    }

    /// The fast path's setup of a Phong- or Gouraud-interpolated object, lean in memory traffic:
    /// per vertex a 20-byte [`FastVertex`] (and for Gouraud its lit colours), per triangle its
    /// edges and plane equations; [`ClipVertex`] values are made only for the triangles that
    /// need clipping.
    fn setup_object_fast(
        &self,
        oi: usize,
        obj: &Object,
        clip_from_world: glam::Mat4,
        scratch: &mut Scratch,
        spare: &std::sync::Mutex<Vec<Chunk>>,
    ) -> Vec<Chunk> {
        let two_sided = obj.shading.options.two_sided;
        let mesh = &obj.mesh;
        let (positions, normals) = (mesh.positions(), mesh.normals());
        let mode = &self.modes[oi];
        let vertices = &mut scratch.vertices;
        // Every record is overwritten below: keep last frame's (no fill) where there are enough.
        vertices.truncate(positions.len());
        vertices.resize(positions.len(), FastVertex::default());
        vertices
            .par_chunks_mut(SETUP_CHUNK)
            .zip(positions.par_chunks(SETUP_CHUNK))
            .for_each(|(out, ps)| fast_vertices(self.avx2, clip_from_world, (self.w, self.h), ps, out));
        // Gouraud: the colour seen from the front and (two-sided) from the back, lit by the
        // kernel after the triangles are set up, and only for the vertices of drawn triangles
        // (a sphere's back half is culled). Lighting a vertex alone or among others gives the
        // same bits (the kernel's lanes are independent).
        let gouraud = matches!(mode, Mode::Gouraud);
        // Gouraud's lighting: the object's prepared constants and the term it shows (made only
        // for Gouraud objects; Phong ones have theirs in their `Mode`).
        let vertex_lighting = gouraud.then(|| {
            let prep = Prepared::new(
                &self.scene.lighting,
                &obj.material,
                &obj.shading.options,
                self.views[oi],
            );
            (
                prep,
                lit_term(obj.shading.output).expect("Gouraud mode is a lit output"),
            )
        });
        let sides = if two_sided { 2 } else { 1 };
        // The colours of vertices `ps` with normals `ns` from the front and (two-sided) the back.
        let light = |ps: &[Vec3], ns: &[Vec3], out: [&mut [Vec3]; 2]| {
            let (prep, term) = vertex_lighting.as_ref().expect("only Gouraud objects light vertices");
            for (side, o) in out.into_iter().enumerate().take(sides) {
                light_vertices(self.avx2, prep, *term, ps, ns, side == 1, o);
            }
        };
        let used = &mut scratch.used;
        if gouraud {
            used.truncate(positions.len());
            used.par_iter().for_each(|u| u.store(false, Ordering::Relaxed));
            used.resize_with(positions.len(), || AtomicBool::new(false));
        }
        let (vertices, used) = (&*vertices, &*used);
        let mark = |idx: [u32; 3]| {
            for i in idx {
                used[i as usize].store(true, Ordering::Relaxed);
            }
        };
        // The planes of a set-up triangle from its input vertices' indices (Phong).
        let phong_planes = |s: &Setup, idx: [u32; 3]| -> Planes {
            let idx = each3(|k| idx[s.order[k]] as usize);
            let sign = if s.front { 1.0 } else { -1.0 };
            let attrs = [
                [positions[idx[0]], positions[idx[1]], positions[idx[2]]],
                [normals[idx[0]] * sign, normals[idx[1]] * sign, normals[idx[2]] * sign],
            ];
            plane_equations(s.xy[0], &s.tri, s.area, s.inv_w, attrs, false)
        };
        let setup_chunk = |chunk: &[[u32; 3]]| {
            let mut out = Chunk::reuse(spare, oi, chunk.len());
            out.planes.reserve(chunk.len());
            for &tri in chunk {
                let v = [
                    vertices[tri[0] as usize],
                    vertices[tri[1] as usize],
                    vertices[tri[2] as usize],
                ];
                let c = [v[0].code, v[1].code, v[2].code];
                if c[0] & c[1] & c[2] & OUTSIDE_VIEW != 0 {
                    continue;
                }
                if (c[0] | c[1] | c[2]) & (OUTSIDE_CLIP | NOT_FINITE) == 0 {
                    if let Some(s) = self.setup_edges([v[0].p, v[1].p, v[2].p], two_sided) {
                        if gouraud {
                            mark(tri);
                            out.pending.push(Pending {
                                slot: out.tris.len() as u32,
                                idx: each3(|k| tri[s.order[k]]),
                            });
                        } else {
                            out.planes.push(phong_planes(&s, tri));
                        }
                        out.tris.push(s.tri);
                    }
                    continue;
                }
                // Rare: clip, with the vertices in full (Gouraud: lit here).
                let mut lit3 = [[Vec3::ZERO; 3]; 2];
                if gouraud {
                    let ps = tri.map(|i| positions[i as usize]);
                    let ns = tri.map(|i| normals[i as usize]);
                    let [front, back] = &mut lit3;
                    light(&ps, &ns, [front, back]);
                }
                let t = each3(|k| {
                    let i = tri[k] as usize;
                    ClipVertex {
                        clip: clip_from_world * Vec4::from((positions[i], 1.0)),
                        world: positions[i],
                        normal: normals[i],
                        color: lit3[0][k],
                        color_back: lit3[1][k],
                    }
                });
                let mut push = |t: [ClipVertex; 3]| {
                    if let Some((tri, p, _)) = self.setup(t, None, None, oi as u32, false) {
                        if gouraud {
                            out.clipped.push((out.tris.len() as u32, p));
                        } else {
                            out.planes.push(p);
                        }
                        out.tris.push(tri);
                    }
                };
                match clip_triangle(&t) {
                    Clipped::Rejected => {}
                    Clipped::Inside => push(t),
                    Clipped::Polygon(p) => {
                        for i in 1..p.len() - 1 {
                            push([p[0], p[i], p[i + 1]]);
                        }
                    }
                }
            }
            self.bin_entries(&mut out);
            out
        };
        let mut chunks: Vec<Chunk> = mesh.triangles().par_chunks(SETUP_CHUNK).map(setup_chunk).collect();
        if gouraud {
            // Lit straight into the colour arrays, which keep last frame's values (no 24 bytes a
            // vertex cleared and copied per frame): only the used vertices' colours are read.
            let [front, back] = &mut scratch.colors;
            front.resize(positions.len(), Vec3::ZERO);
            back.resize(if two_sided { positions.len() } else { 0 }, Vec3::ZERO);
            let mut backs = back.chunks_mut(SETUP_CHUNK);
            let jobs: Vec<_> = front
                .chunks_mut(SETUP_CHUNK)
                .map(|f| (f, backs.next().unwrap_or_default()))
                .enumerate()
                .collect();
            jobs.into_par_iter().for_each(|(j, (f, b))| {
                let at = j * SETUP_CHUNK;
                let range = at..at + f.len();
                let (ps, ns, us) = (&positions[range.clone()], &normals[range.clone()], &used[range]);
                // Runs of groups of 16 vertices with a used one, each lit by one kernel call.
                let group_used = |g: usize| {
                    us[g * LIGHT_GROUP..((g + 1) * LIGHT_GROUP).min(us.len())]
                        .iter()
                        .any(|u| u.load(Ordering::Relaxed))
                };
                let (groups, mut g) = (us.len().div_ceil(LIGHT_GROUP), 0);
                while g < groups {
                    if !group_used(g) {
                        g += 1;
                        continue;
                    }
                    let start = g;
                    while g < groups && group_used(g) {
                        g += 1;
                    }
                    let run = start * LIGHT_GROUP..(g * LIGHT_GROUP).min(us.len());
                    let b = if b.is_empty() { &mut [][..] } else { &mut b[run.clone()] };
                    light(&ps[run.clone()], &ns[run.clone()], [&mut f[run], b]);
                }
            });
            let colors = &scratch.colors;
            chunks.par_iter_mut().for_each(|chunk| {
                let Chunk {
                    tris,
                    planes,
                    pending,
                    clipped,
                    ..
                } = chunk;
                // In slot order: the pending triangles' planes made here, the clipped ones'
                // taken (no default planes written first: 96 bytes a triangle).
                let (mut pending, mut clipped) = (pending.iter().peekable(), clipped.iter().peekable());
                planes.extend((0..tris.len() as u32).map(|slot| {
                    if let Some(p) = pending.next_if(|p| p.slot == slot) {
                        let t = &tris[slot as usize];
                        let v = each3(|k| vertices[p.idx[k] as usize].p);
                        // Twice the area: the cross product of edges 2 (vertex 0 to 1) and 1
                        // (vertex 2 to 0), as `setup_edges` computed it up to the sign.
                        let area = (t.a(1) * t.b(2) - t.a(2) * t.b(1)).unsigned_abs();
                        let c = each3(|k| colors[usize::from(t.back)][p.idx[k] as usize]);
                        plane_equations(
                            (i64::from(v[0].0), i64::from(v[0].1)),
                            t,
                            area,
                            [v[0].3, v[1].3, v[2].3],
                            [c, [Vec3::ZERO; 3]],
                            true,
                        )
                    } else {
                        let c = clipped.next();
                        debug_assert_eq!(c.map(|c| c.0), Some(slot), "every slot is pending or clipped");
                        c.map(|c| c.1).unwrap_or_default()
                    }
                }));
            });
        }
        chunks
    }

    /// The setup of an object for the reference path, or for the fast path's scalar shading
    /// (flat, normal and depth outputs): every vertex in full, [`Corners`] kept.
    fn setup_object_full(&self, oi: usize, obj: &Object, clip_from_world: glam::Mat4) -> Vec<Chunk> {
        let scene = self.scene;
        let interpolation = obj.shading.interpolation;
        let output = obj.shading.output;
        let two_sided = obj.shading.options.two_sided;
        let view = self.views[oi];
        let mesh = &obj.mesh;
        let gouraud = interpolation == Interpolation::Gouraud;
        let verts: Vec<ClipVertex> = mesh
            .positions()
            .par_iter()
            .zip(mesh.normals().par_iter())
            .map(|(&p, &n)| ClipVertex {
                clip: clip_from_world * Vec4::from((p, 1.0)),
                world: p,
                normal: n,
                color: if gouraud {
                    let s = obj.shade(&scene.lighting, &view, p, n);
                    Vec3::from(output.term(&s).to_array())
                } else {
                    Vec3::ZERO
                },
                color_back: if gouraud && two_sided {
                    let s = obj.shade(&scene.lighting, &view, p, -n);
                    Vec3::from(output.term(&s).to_array())
                } else {
                    Vec3::ZERO
                },
            })
            .collect();
        // Per vertex, once: its outcode, and its projection where it is inside the clipping
        // planes (a vertex is shared by about six triangles; per triangle, trivial clipping
        // decisions and projections were a third of a 1M-triangle setup).
        let codes: Vec<u16> = verts.par_iter().map(|v| outcode(v.clip)).collect();
        let projected: Vec<Projected> = verts
            .par_iter()
            .zip(&codes)
            .map(|(v, &code)| {
                if code & (OUTSIDE_CLIP | NOT_FINITE) == 0 {
                    self.project(v.clip)
                } else {
                    Projected::default()
                }
            })
            .collect();
        let setup_chunk = |chunk: &[[u32; 3]]| {
            let mut out = Chunk {
                object: oi as u32,
                tris: Vec::with_capacity(chunk.len()),
                planes: Vec::new(),
                corners: Vec::new(),
                pending: Vec::new(),
                clipped: Vec::new(),
                binned: Vec::new(),
            };
            let mut push = |r: Option<(Tri, Planes, Option<Corners>)>| {
                if let Some((t, _, c)) = r {
                    out.tris.push(t);
                    out.corners.extend(c);
                }
            };
            for tri in chunk {
                let c = tri.map(|i| codes[i as usize]);
                if c[0] & c[1] & c[2] & OUTSIDE_VIEW != 0 {
                    continue;
                }
                let t = tri.map(|i| verts[i as usize]);
                // Flat: front and (two-sided) back colours, from the facet normal at the centroid.
                let flat = (interpolation == Interpolation::Flat).then(|| {
                    let fnorm = facet_normal(t[0].world, t[1].world, t[2].world);
                    let centroid = (t[0].world + t[1].world + t[2].world) / 3.0;
                    let front = output.term(&obj.shade(&scene.lighting, &view, centroid, fnorm));
                    let back = if two_sided {
                        output.term(&obj.shade(&scene.lighting, &view, centroid, -fnorm))
                    } else {
                        front
                    };
                    [(front, fnorm), (back, -fnorm)]
                });
                if (c[0] | c[1] | c[2]) & (OUTSIDE_CLIP | NOT_FINITE) == 0 {
                    let proj = tri.map(|i| projected[i as usize]);
                    push(self.setup(t, Some(proj), flat, oi as u32, true));
                    continue;
                }
                match clip_triangle(&t) {
                    Clipped::Rejected => {}
                    Clipped::Inside => push(self.setup(t, None, flat, oi as u32, true)),
                    Clipped::Polygon(p) => {
                        for i in 1..p.len() - 1 {
                            push(self.setup([p[0], p[i], p[i + 1]], None, flat, oi as u32, true));
                        }
                    }
                }
            }
            self.bin_entries(&mut out);
            out
        };
        mesh.triangles().par_chunks(SETUP_CHUNK).map(setup_chunk).collect()
    }
}

impl<'a> Frame<'a> {
    /// Evaluates triangle `t`'s three edge functions at sample `(sx, sy)` (1/256 pixel);
    /// `Some` when the sample is covered (top-left rule).
    #[inline]
    fn covers(t: &Tri, sx: i64, sy: i64) -> Option<[i64; 3]> {
        let e = each3(|i| t.a(i) * sx + t.b(i) * sy + t.c[i]);
        if (0..3).any(|i| e[i] - t.bias(i) < 0) {
            None
        } else {
            Some(e)
        }
    }
}

/// Diagnostic for coverage tests: for each sample of each pixel (row-major,
/// samples innermost), how many triangles cover it, depth ignored. Culling
/// and clipping apply as in [`render`](crate::render).
pub fn coverage_counts(scene: &Scene) -> Vec<u16> {
    let frame = Frame::build(scene, false, false, &mut Scratch::default());
    let ns = frame.pattern.len();
    let mut counts = vec![0u16; frame.w as usize * frame.h as usize * ns];
    for t in frame.tris.iter().flat_map(|c| &c.tris) {
        let bb = t.bbox();
        for py in bb[1]..bb[3] {
            for px in bb[0]..bb[2] {
                for (s, &(ox, oy)) in frame.pattern.iter().enumerate() {
                    let sx = (i64::from(px) << SUBPIXEL_BITS) + ox;
                    let sy = (i64::from(py) << SUBPIXEL_BITS) + oy;
                    if Frame::covers(t, sx, sy).is_some() {
                        counts[(py as usize * frame.w as usize + px as usize) * ns + s] += 1;
                    }
                }
            }
        }
    }
    counts
}

/// What the tiles write a frame into: linear `f32` pixels (an [`Image`]'s: tiles of one
/// triangle written straight in, the others streamed from the task's buffer), or 8-bit
/// pixels (an [`Image8`](phong_core::Image8)'s: every tile drawn in the task's buffer, then
/// encoded into the frame, a quarter of the bytes).
pub(crate) trait Pixel: Copy + Send + Sync {
    /// The frame's row as `f32` pixels, for tiles drawn straight into it (`f32` only).
    fn as_linear(row: &mut [Self]) -> Option<&mut [[f32; 4]]>;
    /// `dst` from the tile buffer's `src`.
    fn store(dst: &mut [Self], src: &[[f32; 4]], encoding: Encoding);
    /// The frame's row as 8-bit pixels that `Encoding::Linear` encodes (8-bit frames in that
    /// encoding only), for Gouraud tiles drawn straight into it ([`Frame::tile_gouraud8`]).
    fn as_linear8(row: &mut [Self], encoding: Encoding) -> Option<&mut [[u8; 4]]>;
    /// `value` as a pixel of the frame.
    fn from_linear(value: [f32; 4], encoding: Encoding) -> Self;
    /// `dst` all `value`.
    fn fill(dst: &mut [Self], value: Self);
}

impl Pixel for [f32; 4] {
    fn as_linear(row: &mut [Self]) -> Option<&mut [[f32; 4]]> {
        Some(row)
    }
    fn store(dst: &mut [Self], src: &[[f32; 4]], _: Encoding) {
        stream_copy(dst, src);
    }
    fn as_linear8(_: &mut [Self], _: Encoding) -> Option<&mut [[u8; 4]]> {
        None
    }
    fn from_linear(value: [f32; 4], _: Encoding) -> Self {
        value
    }
    fn fill(dst: &mut [Self], value: Self) {
        stream_fill(dst, value);
    }
}

/// [`Image::to_bytes`]'s encoding of one pixel: colour by `encoding`, alpha linearly.
#[inline]
fn encode(p: [f32; 4], encoding: Encoding) -> [u8; 4] {
    [
        encoding.encode(p[0]),
        encoding.encode(p[1]),
        encoding.encode(p[2]),
        Encoding::Linear.encode(p[3]),
    ]
}

impl Pixel for [u8; 4] {
    fn as_linear(_: &mut [Self]) -> Option<&mut [[f32; 4]]> {
        None
    }
    fn store(dst: &mut [Self], src: &[[f32; 4]], encoding: Encoding) {
        match encoding {
            // By SSE2 (the scalar saturating casts did not vectorise: 22% of a 100k-triangle
            // Gouraud frame).
            Encoding::Linear => encode_linear(dst, src),
            Encoding::Srgb => {
                for (d, &s) in dst.iter_mut().zip(src) {
                    *d = encode(s, encoding);
                }
            }
        }
    }
    fn as_linear8(row: &mut [Self], encoding: Encoding) -> Option<&mut [[u8; 4]]> {
        (encoding == Encoding::Linear).then_some(row)
    }
    fn from_linear(value: [f32; 4], encoding: Encoding) -> Self {
        encode(value, encoding)
    }
    fn fill(dst: &mut [Self], value: Self) {
        dst.fill(value);
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
    let (w, h) = (scene.image.width, scene.image.height);
    let frame = Frame::build(scene, options.reference, !options.no_avx2 && avx2_available(), scratch);
    let setup = t0.elapsed();

    let t1 = Instant::now();
    let tiles_y = h.div_ceil(TILE_SIZE);
    let total = u64::from(frame.tiles_x * tiles_y);
    let done = AtomicU64::new(0);
    let clock = StageClock::default();
    let shaded = AtomicU64::new(0);
    let bg = scene.image.background;
    // Tiles are written straight into the image, a strip of 64 rows per task, so that
    // nothing frame-sized exists besides the image (a collected copy did: 33 MB at 1080p).
    debug_assert_eq!(pixels.len(), w as usize * h as usize);
    let row_len = w as usize;
    let ns = frame.pattern.len();
    pixels
        .par_chunks_mut(TILE_SIZE as usize * row_len)
        .enumerate()
        .for_each(|(ty, strip)| {
            // Tiles of the strip in parallel too (tasks of one tile balance the threads), each
            // writing its rows of the image directly (disjoint slices of the strip; a copy of
            // every tile into the image was about 5% of a 100k-triangle frame).
            let mut tiles: Vec<Vec<&mut [P]>> = (0..frame.tiles_x).map(|_| Vec::new()).collect();
            for row in strip.chunks_mut(row_len) {
                for (tx, piece) in row.chunks_mut(TILE_SIZE as usize).enumerate() {
                    tiles[tx].push(piece);
                }
            }
            // A tile of several triangles is drawn into a local buffer (cache-resident, kept by
            // the task), then streamed into the image (see `stream_copy`).
            tiles
                .into_par_iter()
                .enumerate()
                .for_each_init(TileBuffers::default, |buffers, (tx, mut rows)| {
                    let tile = ty as u32 * frame.tiles_x + tx as u32;
                    let TileBuffers { local, depth, ids } = buffers;
                    let bin = frame.bins[tile as usize].len();
                    let gouraud = !options.reference && frame.gouraud_applies(tile);
                    // f32 rows for tiles drawn straight into the frame (f32 frames only).
                    let linear: Option<Vec<&mut [[f32; 4]]>> = if options.reference || bin <= 1 {
                        rows.iter_mut().map(|r| P::as_linear(r)).collect()
                    } else {
                        None
                    };
                    let n = if let Some(mut linear) = linear {
                        if options.reference {
                            frame.tile(tile, bg, &clock, &mut linear)
                        } else {
                            frame.draw_tile(tile, bg, &clock, &mut linear, true, (depth, ids), gouraud)
                        }
                    } else if bin == 0 && !options.reference {
                        // An 8-bit frame's empty tile: its background encoded once.
                        let t = Instant::now();
                        let background = P::from_linear(resolve(std::iter::repeat_n(bg, ns), ns, bg), encoding);
                        for row in rows.iter_mut() {
                            P::fill(row, background);
                        }
                        let end = Instant::now();
                        clock.add(t, end, end, end);
                        0
                    } else if gouraud
                        && frame.gouraud_kernel(tile)
                        && let Some(mut rows8) = rows
                            .iter_mut()
                            .map(|r| P::as_linear8(r, encoding))
                            .collect::<Option<Vec<_>>>()
                    {
                        frame.tile_gouraud8(tile, bg, &clock, &mut rows8, depth)
                    } else {
                        let tw = rows[0].len();
                        local.resize((TILE_SIZE * TILE_SIZE) as usize, [0.0; 4]);
                        let mut buffer: Vec<&mut [[f32; 4]]> = local.chunks_mut(tw).take(rows.len()).collect();
                        let n = if options.reference {
                            frame.tile(tile, bg, &clock, &mut buffer)
                        } else {
                            frame.draw_tile(tile, bg, &clock, &mut buffer, false, (depth, ids), gouraud)
                        };
                        for (dst, src) in rows.iter_mut().zip(&buffer) {
                            P::store(dst, src, encoding);
                        }
                        stream_fence();
                        n
                    };
                    shaded.fetch_add(n, Ordering::Relaxed);
                    let d = done.fetch_add(1, Ordering::Relaxed) + 1;
                    if let Some(p) = options.progress {
                        p(d, total);
                    }
                });
        });
    let triangles_drawn = frame.tris.iter().map(|c| c.tris.len()).sum();
    frame.recycle(scratch);
    let stats = RenderStats {
        triangles: scene.triangle_count(),
        triangles_drawn,
        pixels_shaded: shaded.into_inner(),
        setup,
        raster: t1.elapsed(),
        tile_raster: Duration::from_nanos(clock.raster.into_inner()),
        tile_shade: Duration::from_nanos(clock.shade.into_inner()),
        tile_resolve: Duration::from_nanos(clock.resolve.into_inner()),
    };
    Ok(stats)
}

/// Plane equations (see [`Planes`]) of two vector attributes (only the first with `first_only`),
/// `attrs[j][i]` at vertex `i`, for set-up triangle `t` with vertex 0 snapped at `origin` (1/256
/// pixel) and twice its area `area`: the barycentric `λ_i` is `E_i / area`, so
/// `∂q/∂x = 256 Σ a_i q_i / area` per pixel (likewise `y` with `b`), and `q = q_0` at vertex 0.
/// Computed in `f64`, stored in `f32`.
#[inline(always)]
fn plane_equations(
    origin: (i64, i64),
    t: &Tri,
    area: u64,
    inv_w: [f32; 3],
    attrs: [[Vec3; 3]; 2],
    first_only: bool,
) -> Planes {
    let k = f64::from(1u32 << SUBPIXEL_BITS) / area as f64;
    let (a, b) = (t.a.map(f64::from), t.b.map(f64::from));
    let plane = |q: [f32; 3]| {
        let qd = [f64::from(q[0]), f64::from(q[1]), f64::from(q[2])];
        let gx = (a[0] * qd[0] + a[1] * qd[1] + a[2] * qd[2]) * k;
        let gy = (b[0] * qd[0] + b[1] * qd[1] + b[2] * qd[2]) * k;
        [q[0], gx as f32, gy as f32]
    };
    let mut attr = [[0f32; 3]; 6];
    for (j, vs) in attrs.iter().enumerate().take(if first_only { 1 } else { 2 }) {
        for c in 0..3 {
            attr[j * 3 + c] = plane([vs[0][c] * inv_w[0], vs[1][c] * inv_w[1], vs[2][c] * inv_w[2]]);
        }
    }
    Planes {
        origin: [origin.0 as f32 / ONE, origin.1 as f32 / ONE],
        inv_w: plane(inv_w),
        attr,
        pad: 0.0,
    }
}

impl Frame<'_> {
    fn tile_rect(&self, tile: u32) -> (u32, u32, u32, u32) {
        let (tx, ty) = (tile % self.tiles_x, tile / self.tiles_x);
        let (x0, y0) = (tx * TILE_SIZE, ty * TILE_SIZE);
        (x0, y0, (x0 + TILE_SIZE).min(self.w), (y0 + TILE_SIZE).min(self.h))
    }

    /// Clip-space `c` (`w > 0`) to the window: snapped `x`, `y` (1/256 pixel), depth in [0, 1]
    /// and `1/w`.
    #[inline]
    fn project(&self, c: Vec4) -> Projected {
        project(c, self.w, self.h)
    }

    /// Culls and sets up the edges of a triangle from its projected vertices; `None` when it is
    /// culled (a back face of a one-sided object), degenerate or covers no pixel.
    #[inline]
    fn setup_edges(&self, proj: [Projected; 3], two_sided: bool) -> Option<Setup> {
        setup_edges(proj, two_sided, self.w, self.h, self.span)
    }
}

/// The bounds of a sample pattern's offsets within a pixel, in 1/256 pixel: `(min x, max x,
/// min y, max y)`. A triangle's bounding box holds the pixels with a sample inside its
/// vertices' bounds, not every pixel those bounds touch: a 1M-triangle sphere's triangles span
/// two or three pixels, and many cover no pixel centre at all.
#[derive(Clone, Copy, Debug)]
struct SampleSpan(i64, i64, i64, i64);

impl SampleSpan {
    fn of(pattern: &[(i64, i64)]) -> SampleSpan {
        let xs = pattern.iter().map(|p| p.0);
        let ys = pattern.iter().map(|p| p.1);
        SampleSpan(
            xs.clone().min().unwrap_or(HALF),
            xs.max().unwrap_or(HALF),
            ys.clone().min().unwrap_or(HALF),
            ys.max().unwrap_or(HALF),
        )
    }
}

/// [`Frame::project`] for an image of `w × h` pixels.
#[inline]
fn project(c: Vec4, w: u32, h: u32) -> Projected {
    let (wf, hf) = (w as f32, h as f32);
    let iw = 1.0 / c.w;
    let sx = (c.x * iw * 0.5 + 0.5) * wf;
    let sy = (0.5 - c.y * iw * 0.5) * hf;
    Projected(
        round_i64(sx * ONE) as i32,
        round_i64(sy * ONE) as i32,
        c.z * iw * 0.5 + 0.5,
        iw,
    )
}

/// The fast setup's vertex records of `positions` into `out`, for a `w × h` image: clip-space
/// transform, outcode and (inside the clip volume) window projection; by the AVX2 kernel with
/// `avx2`, the same bits (see `simd/project.rs`).
fn fast_vertices(
    avx2: bool,
    clip_from_world: glam::Mat4,
    (w, h): (u32, u32),
    positions: &[Vec3],
    out: &mut [FastVertex],
) {
    let scalar = |p: Vec3| {
        let clip = clip_from_world * Vec4::from((p, 1.0));
        let code = outcode(clip);
        let p = if code & (OUTSIDE_CLIP | NOT_FINITE) == 0 {
            project(clip, w, h)
        } else {
            Projected::default()
        };
        FastVertex { p, code }
    };
    project_vertices(
        avx2,
        &clip_from_world,
        (w as f32, h as f32, ONE),
        positions,
        out,
        |([x, y], z, inv_w, code)| FastVertex {
            p: Projected(x, y, z, inv_w),
            code,
        },
        scalar,
    );
}

/// [`Frame::setup_edges`] for an image of `w × h` pixels.
#[inline(always)]
fn setup_edges(proj: [Projected; 3], two_sided: bool, w: u32, h: u32, span: SampleSpan) -> Option<Setup> {
    {
        // Explicit arrays here and below, not `[T; 3]::map`: those calls were not inlined
        // (`try_map` was 5% of a 1M-triangle frame).
        let xy = [
            (i64::from(proj[0].0), i64::from(proj[0].1)),
            (i64::from(proj[1].0), i64::from(proj[1].1)),
            (i64::from(proj[2].0), i64::from(proj[2].1)),
        ];
        let area = (xy[1].0 - xy[0].0) * (xy[2].1 - xy[0].1) - (xy[2].0 - xy[0].0) * (xy[1].1 - xy[0].1);
        if area == 0 {
            return None;
        }
        // Counter-clockwise in NDC (y up) is clockwise on screen (y down): area < 0 is front-facing.
        let front = area < 0;
        if !front && !two_sided {
            return None;
        }
        let order = if front { [0, 2, 1] } else { [0, 1, 2] };
        let xy = [xy[order[0]], xy[order[1]], xy[order[2]]];
        let (min_x, max_x) = (xy[0].0.min(xy[1].0).min(xy[2].0), xy[0].0.max(xy[1].0).max(xy[2].0));
        let (min_y, max_y) = (xy[0].1.min(xy[1].1).min(xy[2].1), xy[0].1.max(xy[1].1).max(xy[2].1));
        // Pixel p's samples lie at p·256 + offset: the first pixel with one at or right of
        // min_x is ⌈(min_x − max offset) / 256⌉, the last at or left of max_x is
        // ⌊(max_x − min offset) / 256⌋ (shifts round down, negatives included).
        let one = (1i64 << SUBPIXEL_BITS) - 1;
        let px0 = ((min_x - span.1 + one) >> SUBPIXEL_BITS).max(0);
        let py0 = ((min_y - span.3 + one) >> SUBPIXEL_BITS).max(0);
        let px1 = (((max_x - span.0) >> SUBPIXEL_BITS) + 1).min(i64::from(w));
        let py1 = (((max_y - span.2) >> SUBPIXEL_BITS) + 1).min(i64::from(h));
        if px0 >= px1 || py0 >= py1 {
            return None;
        }
        let mut a = [0i32; 3];
        let mut b = [0i32; 3];
        let mut c = [0i64; 3];
        let mut bias = 0u8;
        for i in 0..3 {
            // Edge opposite vertex i, from vertex j to vertex k.
            let (j, k) = ((i + 1) % 3, (i + 2) % 3);
            let ((xa, ya), (xb, yb)) = (xy[j], xy[k]);
            // E(X, Y) = (xb − xa)(Y − ya) − (yb − ya)(X − xa), positive inside.
            let (ai, bi) = (-(yb - ya), xb - xa);
            a[i] = ai as i32;
            b[i] = bi as i32;
            c[i] = -(ai * xa + bi * ya);
            // Top edge: horizontal, going right; left edge: going up (y down). Both inclusive.
            let top_left = (ya == yb && xb > xa) || yb < ya;
            bias |= u8::from(!top_left) << i;
        }
        let area = area.unsigned_abs();
        Some(Setup {
            tri: Tri {
                a,
                b,
                c,
                inv_area: 1.0 / area as f64,
                z: [proj[order[0]].2, proj[order[1]].2, proj[order[2]].2],
                bbox: [px0 as u16, py0 as u16, px1 as u16, py1 as u16],
                bias,
                back: !front,
            },
            order,
            xy,
            inv_w: [proj[order[0]].3, proj[order[1]].3, proj[order[2]].3],
            area,
            front,
        })
    }
}

impl Frame<'_> {
    /// Projects (unless `proj` is given), snaps, culls and sets up one clipped triangle; with
    /// `full`, its [`Corners`] for scalar shading, else its fast-path [`Planes`].
    fn setup(
        &self,
        v: [ClipVertex; 3],
        proj: Option<[Projected; 3]>,
        flat: Option<[(Color, Vec3); 2]>,
        object: u32,
        full: bool,
    ) -> Option<(Tri, Planes, Option<Corners>)> {
        let proj = proj.unwrap_or_else(|| v.map(|v| self.project(v.clip)));
        let s = self.setup_edges(proj, self.scene.objects[object as usize].shading.options.two_sided)?;
        let v = s.order.map(|k| v[k]);
        if full {
            let corners = Corners {
                inv_w: s.inv_w,
                v,
                flat: flat.map(|f| f[usize::from(!s.front)]),
            };
            return Some((s.tri, Planes::default(), Some(corners)));
        }
        let planes = match self.modes[object as usize] {
            Mode::Scalar => Planes::default(),
            Mode::Phong(..) => {
                let sign = if s.front { 1.0 } else { -1.0 };
                let attrs = [v.map(|v| v.world), v.map(|v| v.normal * sign)];
                plane_equations(s.xy[0], &s.tri, s.area, s.inv_w, attrs, false)
            }
            Mode::Gouraud => {
                let c = v.map(|v| if s.front { v.color } else { v.color_back });
                plane_equations(s.xy[0], &s.tri, s.area, s.inv_w, [c, [Vec3::ZERO; 3]], true)
            }
        };
        Some((s.tri, planes, None))
    }

    /// The tiles each triangle of `chunk` goes into, as `(tile, index)` pairs in triangle order
    /// (in the setup's parallel tasks: binning was a sequential 1.8 ms of a 1M-triangle frame).
    fn bin_entries(&self, chunk: &mut Chunk) {
        // A setup chunk of SETUP_CHUNK input triangles makes at most 7 triangles of each.
        debug_assert!(chunk.tris.len() < 1 << ID_INDEX_BITS);
        for (i, t) in chunk.tris.iter().enumerate() {
            let [px0, py0, px1, py1] = t.bbox();
            let (tx0, tx1) = (px0 / TILE_SIZE, (px1 - 1) / TILE_SIZE);
            let (ty0, ty1) = (py0 / TILE_SIZE, (py1 - 1) / TILE_SIZE);
            let several = tx0 != tx1 || ty0 != ty1;
            for ty in ty0..=ty1 {
                for tx in tx0..=tx1 {
                    if several && Self::misses_tile(t, tx, ty) {
                        continue;
                    }
                    chunk.binned.push((ty * self.tiles_x + tx, i as u32));
                }
            }
        }
    }

    /// Keeps set-up chunks and adds their triangles to the bins, in order (chunk by chunk,
    /// triangle by triangle: the tiles draw them in the input's order). Bands of tiles are
    /// filled in parallel, each from every chunk's entries ([`Frame::bin_entries`]).
    fn bin_chunks(&mut self, chunks: Vec<Chunk>) {
        let base = self.tris.len() as u32;
        debug_assert!(base as usize + chunks.len() < 1 << (32 - ID_INDEX_BITS));
        let tiles = self.bins.len();
        let band = tiles.div_ceil(rayon::current_num_threads()).max(1);
        self.bins.par_chunks_mut(band).enumerate().for_each(|(b, bins)| {
            let first = (b * band) as u32;
            for (c, chunk) in chunks.iter().enumerate() {
                let c = (base + c as u32) << ID_INDEX_BITS;
                for &(tile, i) in &chunk.binned {
                    if let Some(bin) = bins.get_mut(tile.wrapping_sub(first) as usize) {
                        bin.push(c | i);
                    }
                }
            }
        });
        self.tris.extend(chunks);
    }

    /// Trivial reject of a tile: some edge of `t` is negative on all of tile `(tx, ty)`'s square
    /// (pixel corners, so every sample position of every pattern is inside it), tested at the
    /// square's corner where the edge is largest. Binning by bounding box alone put both
    /// triangles of a full-screen quad in every tile.
    #[inline]
    fn misses_tile(t: &Tri, tx: u32, ty: u32) -> bool {
        let (x0, y0) = (
            i64::from(tx * TILE_SIZE) << SUBPIXEL_BITS,
            i64::from(ty * TILE_SIZE) << SUBPIXEL_BITS,
        );
        let side = i64::from(TILE_SIZE) << SUBPIXEL_BITS;
        (0..3).any(|i| {
            let x = if t.a[i] >= 0 { x0 + side } else { x0 };
            let y = if t.b[i] >= 0 { y0 + side } else { y0 };
            t.a(i) * x + t.b(i) * y + t.c[i] - t.bias(i) < 0
        })
    }

    /// The triangle with packed id `id` (chunk in the high bits, index in the low ones).
    #[inline]
    fn tri(&self, id: u32) -> &Tri {
        &self.tris[(id >> ID_INDEX_BITS) as usize].tris[(id & ((1 << ID_INDEX_BITS) - 1)) as usize]
    }

    /// The object of triangle `id`.
    #[inline]
    fn object(&self, id: u32) -> usize {
        self.tris[(id >> ID_INDEX_BITS) as usize].object as usize
    }

    /// The fast path's plane equations of triangle `id`.
    #[inline]
    fn planes(&self, id: u32) -> &Planes {
        &self.tris[(id >> ID_INDEX_BITS) as usize].planes[(id & ((1 << ID_INDEX_BITS) - 1)) as usize]
    }

    /// The [`Corners`] of triangle `id` (kept for the reference path and scalar-shaded objects).
    #[inline]
    fn corners(&self, id: u32) -> &Corners {
        &self.tris[(id >> ID_INDEX_BITS) as usize].corners[(id & ((1 << ID_INDEX_BITS) - 1)) as usize]
    }

    /// Renders one tile and resolves it; returns its pixels and the number of pixel shadings.
    /// (Stages: rasterising and shading are interleaved here, so both count as `raster`.)
    fn tile(&self, tile: u32, bg: [f32; 4], clock: &StageClock, rows: &mut [&mut [[f32; 4]]]) -> u64 {
        let t_start = Instant::now();
        let (x0, y0, x1, y1) = self.tile_rect(tile);
        let (tw, th) = ((x1 - x0) as usize, (y1 - y0) as usize);
        let ns = self.pattern.len();
        let mut color = vec![bg; tw * th * ns];
        let mut depth = vec![f32::INFINITY; tw * th * ns];
        let mut shaded = 0u64;
        let mut zs = [0f32; 16];
        for &ti in &self.bins[tile as usize] {
            let t = self.tri(ti);
            let bb = t.bbox();
            let (bx0, by0, bx1, by1) = (bb[0].max(x0), bb[1].max(y0), bb[2].min(x1), bb[3].min(y1));
            for py in by0..by1 {
                for px in bx0..bx1 {
                    let base = ((py - y0) as usize * tw + (px - x0) as usize) * ns;
                    let mut mask = 0u32;
                    for (s, &(ox, oy)) in self.pattern.iter().enumerate() {
                        let sx = (i64::from(px) << SUBPIXEL_BITS) + ox;
                        let sy = (i64::from(py) << SUBPIXEL_BITS) + oy;
                        let Some(e) = Frame::covers(t, sx, sy) else {
                            continue;
                        };
                        let l = map3(e, |x| (x as f64 * t.inv_area) as f32);
                        let zz = l[0] * t.z[0] + l[1] * t.z[1] + l[2] * t.z[2];
                        if zz < depth[base + s] {
                            zs[s] = zz;
                            mask |= 1 << s;
                        }
                    }
                    if mask == 0 {
                        continue;
                    }
                    shaded += 1;
                    let c = self.shade_pixel(ti, px, py);
                    for s in 0..ns {
                        if mask & (1 << s) != 0 {
                            depth[base + s] = zs[s];
                            color[base + s] = c;
                        }
                    }
                }
            }
        }
        let t_resolve = Instant::now();
        for (px, o) in color.chunks_exact(ns).zip(rows.iter_mut().flat_map(|r| r.iter_mut())) {
            *o = resolve(px.iter().copied(), ns, bg);
        }
        clock.add(t_start, t_resolve, t_resolve, Instant::now());
        shaded
    }

    /// Perspective-correct weights of triangle `t`'s vertices at the centre of pixel
    /// `(px, py)`: `(λ_i / w_i) / Σ (λ_j / w_j)`.
    #[inline]
    fn weights(t: &Tri, corners: &Corners, px: u32, py: u32) -> [f32; 3] {
        let sx = (i64::from(px) << SUBPIXEL_BITS) + HALF;
        let sy = (i64::from(py) << SUBPIXEL_BITS) + HALF;
        let e = each3(|i| (t.a(i) * sx + t.b(i) * sy + t.c[i]) as f64 * t.inv_area);
        let q = each3(|i| e[i] as f32 * corners.inv_w[i]);
        let sum = q[0] + q[1] + q[2];
        map3(q, |x| x / sum)
    }

    /// Visibility first (the fast path): per sample the nearest triangle, with the reference's
    /// coverage and depth arithmetic; then each visible (pixel, triangle) pair is shaded once,
    /// Phong and Gouraud objects by the vector kernels. With one sample: a tile covered by its
    /// only triangle skips visibility, Gouraud pixels are coloured during it, and the rest go
    /// to [`Frame::shade_single`]; with several, one job per visible (pixel, triangle) and the
    /// reference's resolve.
    #[allow(clippy::too_many_arguments)]
    fn tile_visible(
        &self,
        tile: u32,
        bg: [f32; 4],
        clock: &StageClock,
        rows: &mut [&mut [[f32; 4]]],
        image: bool,
        (depth, ids): (&mut Vec<f32>, &mut Vec<u32>),
    ) -> u64 {
        let t_start = Instant::now();
        let (x0, y0, x1, y1) = self.tile_rect(tile);
        let (tw, th) = ((x1 - x0) as usize, (y1 - y0) as usize);
        let ns = self.pattern.len();
        let bin = &self.bins[tile as usize];
        if bin.is_empty() {
            // Background only (most tiles around a model): no depth, ids or scan; the resolve
            // of `ns` background samples, as the other paths compute it.
            let background = resolve(std::iter::repeat_n(bg, ns), ns, bg);
            for line in rows.iter_mut() {
                fill_background(line, background, image);
            }
            stream_fence();
            let t_end = Instant::now();
            clock.add(t_start, t_end, t_end, t_end);
            return 0;
        }
        if ns == 1 && bin.len() == 1 && self.covers_rect(bin[0], (x0, y0, x1, y1)) {
            // Trivial accept: the tile's only triangle covers all of it, so every pixel sees it
            // (its depth, finite inside the clipped volume, passes the test against the cleared
            // buffer): no edge, depth or sorting work. Most tiles of a large triangle.
            let t_shade = Instant::now();
            ids.clear();
            ids.resize(tw * th, 0);
            return self.shade_single(bin, ids, (x0, y0, tw, th), bg, clock, (t_start, t_shade), rows, image);
        }
        depth.clear();
        depth.resize(tw * th * ns, f32::INFINITY);
        ids.clear();
        ids.resize(tw * th * ns, u32::MAX);
        let mut offsets = [[0i64; 3]; 16];
        for (k, &ti) in bin.iter().enumerate() {
            let t = self.tri(ti);
            // Edge functions stepped incrementally (exact integer adds, so the same values as
            // the reference's direct evaluation): per sample an offset from the pixel corner,
            // per pixel a step of `a·256`.
            for (o, &(ox, oy)) in offsets.iter_mut().zip(&self.pattern) {
                *o = each3(|i| t.a(i) * ox + t.b(i) * oy - t.bias(i));
            }
            let step = each3(|i| t.a(i) << SUBPIXEL_BITS);
            let bb = t.bbox();
            let (bx0, bx1) = (bb[0].max(x0), bb[2].min(x1));
            if ns == 1 {
                // One sample: `ids` holds the index in the bin (see `shade_single`). Gouraud
                // triangles write their colour as they pass the depth test (see `Forward`).
                let tile = (x0, y0, tw, y1);
                if matches!(self.modes[self.object(ti)], Mode::Gouraud) {
                    let forward = Forward {
                        planes: ColorPlanes::new(self.planes(ti)),
                        rows: &mut *rows,
                    };
                    self.visible_single::<true>(t, k as u32, offsets[0], tile, (bx0, bx1), depth, ids, Some(forward));
                } else {
                    self.visible_single::<true>(t, k as u32, offsets[0], tile, (bx0, bx1), depth, ids, None);
                }
                continue;
            }
            for py in bb[1].max(y0)..bb[3].min(y1) {
                let (cx, cy) = (i64::from(bx0) << SUBPIXEL_BITS, i64::from(py) << SUBPIXEL_BITS);
                let mut row = each3(|i| t.a(i) * cx + t.b(i) * cy + t.c[i]);
                for px in bx0..bx1 {
                    let base = ((py - y0) as usize * tw + (px - x0) as usize) * ns;
                    for (s, o) in offsets[..ns].iter().enumerate() {
                        // e − bias >= 0 on every edge: covered (top-left rule).
                        let eb = [row[0] + o[0], row[1] + o[1], row[2] + o[2]];
                        if (eb[0] | eb[1] | eb[2]) < 0 {
                            continue;
                        }
                        let e = each3(|i| eb[i] + t.bias(i));
                        let l = map3(e, |x| (x as f64 * t.inv_area) as f32);
                        let zz = l[0] * t.z[0] + l[1] * t.z[1] + l[2] * t.z[2];
                        if zz < depth[base + s] {
                            depth[base + s] = zz;
                            ids[base + s] = ti;
                        }
                    }
                    for i in 0..3 {
                        row[i] += step[i];
                    }
                }
            }
        }
        let t_shade = Instant::now();
        if ns == 1 {
            return self.shade_single(bin, ids, (x0, y0, tw, th), bg, clock, (t_start, t_shade), rows, image);
        }
        // One job per visible (pixel, triangle), the pixel as `row << 16 | column` in the tile
        // (no division to find it again: per-lane integer divisions were 1% of fill); a
        // pixel's jobs are contiguous.
        let mut jobs: Vec<(u32, u32)> = Vec::with_capacity(tw * th);
        let mut starts = Vec::with_capacity(tw * th + 1);
        for row in 0..th {
            for col in 0..tw {
                let pixel = row * tw + col;
                let packed = (row as u32) << 16 | col as u32;
                starts.push(jobs.len());
                let first = jobs.len();
                for &id in &ids[pixel * ns..(pixel + 1) * ns] {
                    if id != u32::MAX && !jobs[first..].iter().any(|j| j.1 == id) {
                        jobs.push((packed, id));
                    }
                }
            }
        }
        starts.push(jobs.len());
        let at = |packed: u32| (x0 + (packed & 0xffff), y0 + (packed >> 16));
        let mut colors = vec![[0f32; 4]; jobs.len()];
        let mut batches: Vec<Vec<u32>> = vec![Vec::new(); self.scene.objects.len()];
        for (k, &(pixel, ti)) in jobs.iter().enumerate() {
            if matches!(self.modes[self.object(ti)], Mode::Scalar) {
                let (px, py) = at(pixel);
                colors[k] = self.shade_pixel(ti, px, py);
            } else {
                batches[self.object(ti)].push(k as u32);
            }
        }
        for (object, batch) in batches.iter().enumerate() {
            let Some(kind) = self.modes[object].batch() else {
                continue;
            };
            shade_batch(
                self.avx2,
                kind,
                batch.len(),
                |i| {
                    let (pixel, ti) = jobs[batch[i] as usize];
                    let (px, py) = at(pixel);
                    (px as f32 + 0.5, py as f32 + 0.5, self.planes(ti))
                },
                |i, rgb| colors[batch[i] as usize] = [rgb[0], rgb[1], rgb[2], 1.0],
            );
        }
        let t_resolve = Instant::now();
        // The reference's resolve, sample by sample.
        let out = rows.iter_mut().flat_map(|r| r.iter_mut());
        for (pixel, o) in out.enumerate() {
            *o = {
                let mine = &jobs[starts[pixel]..starts[pixel + 1]];
                let samples = ids[pixel * ns..(pixel + 1) * ns].iter().map(|&id| {
                    if id == u32::MAX {
                        bg
                    } else {
                        colors[starts[pixel] + mine.iter().position(|j| j.1 == id).unwrap_or(0)]
                    }
                });
                resolve(samples, ns, bg)
            };
        }
        clock.add(t_start, t_shade, t_resolve, Instant::now());
        jobs.len() as u64
    }

    /// A tile of the fast path: [`Frame::tile_gouraud`] where it applies (`gouraud`, the
    /// caller's [`Frame::gouraud_applies`], decided once per tile), else [`Frame::tile_visible`].
    #[inline]
    #[allow(clippy::too_many_arguments)]
    fn draw_tile(
        &self,
        tile: u32,
        bg: [f32; 4],
        clock: &StageClock,
        rows: &mut [&mut [[f32; 4]]],
        image: bool,
        (depth, ids): (&mut Vec<f32>, &mut Vec<u32>),
        gouraud: bool,
    ) -> u64 {
        if gouraud {
            return self.tile_gouraud(tile, bg, clock, rows, depth, self.gouraud_kernel(tile));
        }
        self.tile_visible(tile, bg, clock, rows, image, (depth, ids))
    }

    /// Whether [`Frame::tile_gouraud`] draws `tile`: an all-Gouraud frame with one sample,
    /// where `tile_visible` would reach its visibility loop (not an empty tile, not a trivial
    /// accept): the same images.
    fn gouraud_applies(&self, tile: u32) -> bool {
        let bin = &self.bins[tile as usize];
        self.gouraud_only
            && self.pattern.len() == 1
            && !bin.is_empty()
            && !(bin.len() == 1 && self.covers_rect(bin[0], self.tile_rect(tile)))
    }

    /// Whether [`Frame::tile_gouraud`] draws `tile` with the AVX2 kernel ([`gouraud_tile`]):
    /// with AVX2, where the tile has at least 8 pixels per triangle of its bin. Its cost per
    /// triangle is higher than the scalar loop's, its cost per pixel lower (1 thread, means of
    /// 2 interleaved runs: kernel everywhere, scalar everywhere, this rule: 100k sphere 12.0,
    /// 13.6, 12.1 ms; 1M 44.1, 40.5, 40.4 ms; a 300k sphere of 548 segments 21.0, 20.8, 20.2
    /// ms).
    fn gouraud_kernel(&self, tile: u32) -> bool {
        let (x0, y0, x1, y1) = self.tile_rect(tile);
        self.avx2 && ((x1 - x0) * (y1 - y0)) as usize >= 8 * self.bins[tile as usize].len()
    }

    /// [`Frame::tile_visible`] of a frame whose objects are all Gouraud-shaded, with one
    /// sample, past its empty and trivially accepted tiles: every visible pixel is coloured
    /// during visibility (see [`Forward`]), so the tile starts as background and needs no ids,
    /// no scan and no deferred shading (1 thread, 4 and 3 interleaved pairs: 100k sphere 13.7
    /// → 13.1 ms, 1M 41.2 → 39.6 ms). With `kernel`, by the AVX2 kernel [`gouraud_tile`] (see
    /// [`Frame::gouraud_kernel`]), else by the scalar loop, `visible_single`: the same bits.
    /// Chosen by the caller, not inlined: as a branch of `tile_visible`, even one calling this
    /// function, it made that function's multi-sample loop slower (teapots' tile
    /// rasterisation 25.2 → 28.2 ms of CPU time, 3 interleaved pairs).
    #[inline(never)]
    #[allow(clippy::too_many_arguments)]
    fn tile_gouraud(
        &self,
        tile: u32,
        bg: [f32; 4],
        clock: &StageClock,
        rows: &mut [&mut [[f32; 4]]],
        depth: &mut Vec<f32>,
        kernel: bool,
    ) -> u64 {
        let t_start = Instant::now();
        let ((x0, y0, x1, y1), stride) = self.gouraud_depth(tile, depth, kernel);
        let bin = &self.bins[tile as usize];
        let background = resolve(std::iter::once(bg), 1, bg);
        for line in rows.iter_mut() {
            line.fill(background);
        }
        let triangle = |k: usize| self.gouraud_tri(bin[k], (x0, y0, x1, y1));
        if let Some(covered) = gouraud_tile(kernel, (x0, y0), stride, bin.len(), triangle, depth, rows) {
            let end = Instant::now();
            clock.add(t_start, end, end, end);
            return covered;
        }
        for &ti in bin {
            let t = self.tri(ti);
            let (ox, oy) = self.pattern[0];
            let o = each3(|i| t.a(i) * ox + t.b(i) * oy - t.bias(i));
            let bb = t.bbox();
            let forward = Forward {
                planes: ColorPlanes::new(self.planes(ti)),
                rows: &mut *rows,
            };
            let tile = (x0, y0, (x1 - x0) as usize, y1);
            self.visible_single::<false>(
                t,
                0,
                o,
                tile,
                (bb[0].max(x0), bb[2].min(x1)),
                depth,
                &mut [],
                Some(forward),
            );
        }
        let end = Instant::now();
        clock.add(t_start, end, end, end);
        depth.iter().filter(|&&d| d != f32::INFINITY).count() as u64
    }

    /// [`Frame::tile_gouraud`] by the AVX2 kernel straight into the rows of an 8-bit frame that
    /// `Encoding::Linear` encodes: its pixels are encoded as they are coloured, so the tile
    /// needs no `f32` buffer (64 KB, twice L1) and no encoding pass (100k sphere, 3 and 5
    /// interleaved runs: 1 thread 11.6 → 11.2 ms, 2 threads 6.0 → 5.8 ms). The caller checked [`Frame::gouraud_applies`] and [`Frame::gouraud_kernel`].
    #[inline(never)]
    fn tile_gouraud8(
        &self,
        tile: u32,
        bg: [f32; 4],
        clock: &StageClock,
        rows: &mut [&mut [[u8; 4]]],
        depth: &mut Vec<f32>,
    ) -> u64 {
        let t_start = Instant::now();
        let ((x0, y0, x1, y1), stride) = self.gouraud_depth(tile, depth, true);
        let bin = &self.bins[tile as usize];
        let background = encode(resolve(std::iter::once(bg), 1, bg), Encoding::Linear);
        for line in rows.iter_mut() {
            line.fill(background);
        }
        let triangle = |k: usize| self.gouraud_tri(bin[k], (x0, y0, x1, y1));
        let covered = gouraud_tile(self.avx2, (x0, y0), stride, bin.len(), triangle, depth, rows)
            .expect("tile_gouraud8 without AVX2");
        let end = Instant::now();
        clock.add(t_start, end, end, end);
        covered
    }

    /// The rectangle of `tile` and its depths, all `+∞`, `stride` a row (returned): with the
    /// AVX2 kernel (`kernel`) a multiple of 4, as it tests windows of 4 pixels aligned in the
    /// tile (the extra pixels stay infinite), else the tile's width.
    fn gouraud_depth(&self, tile: u32, depth: &mut Vec<f32>, kernel: bool) -> ((u32, u32, u32, u32), usize) {
        let rect @ (x0, y0, x1, y1) = self.tile_rect(tile);
        let (tw, th) = ((x1 - x0) as usize, (y1 - y0) as usize);
        let stride = if kernel { tw.next_multiple_of(4) } else { tw };
        depth.clear();
        depth.resize(stride * th, f32::INFINITY);
        (rect, stride)
    }

    /// Triangle `ti` as the Gouraud kernel draws it into the tile `(x0, y0, x1, y1)`.
    #[inline(always)]
    fn gouraud_tri(&self, ti: u32, (x0, y0, x1, y1): (u32, u32, u32, u32)) -> GouraudTri<'_> {
        let (ox, oy) = self.pattern[0];
        let t = self.tri(ti);
        let bb = t.bbox();
        let (bx0, by0) = (bb[0].max(x0), bb[1].max(y0));
        let (cx, cy) = (i64::from(bx0) << SUBPIXEL_BITS, i64::from(by0) << SUBPIXEL_BITS);
        GouraudTri {
            start: each3(|i| t.a(i) * cx + t.b(i) * cy + t.c[i] + t.a(i) * ox + t.b(i) * oy - t.bias(i)),
            step_x: each3(|i| t.a(i) << SUBPIXEL_BITS),
            step_y: each3(|i| t.b(i) << SUBPIXEL_BITS),
            bias: each3(|i| t.bias(i)),
            inv_area: t.inv_area,
            z: t.z,
            cols: (bx0 - x0, bb[2].min(x1).max(bx0) - x0),
            rows: (by0 - y0, bb[3].min(y1).max(by0) - y0),
            planes: self.planes(ti),
        }
    }

    /// Whether triangle `id` covers the centre of every pixel of the rectangle `(x0, y0, x1, y1)`
    /// (exclusive max) by the top-left rule: the four corner pixels are covered, and the
    /// triangle is convex.
    fn covers_rect(&self, id: u32, (x0, y0, x1, y1): (u32, u32, u32, u32)) -> bool {
        let t = self.tri(id);
        let centre = |p: u32| (i64::from(p) << SUBPIXEL_BITS) + HALF;
        [(x0, y0), (x1 - 1, y0), (x0, y1 - 1), (x1 - 1, y1 - 1)]
            .iter()
            .all(|&(px, py)| Frame::covers(t, centre(px), centre(py)).is_some())
    }

    /// Visibility of triangle `t` (id `ti`) with one sample per pixel, over its rows in the tile
    /// `(x0, y0, width, y1)` and columns `bx0..bx1`: `o` is the sample's offset of the edge
    /// functions (bias subtracted). Wide rows first find their covered span exactly (per edge,
    /// the integer bound of `e − bias + k·step >= 0`), so the loop over pixels tests no edges;
    /// narrow ones (under 8 pixels, where the three divisions cost more) test each pixel. Same
    /// edge values and depth arithmetic as the reference, hence the same visibility.
    ///
    /// With `forward` (Gouraud), each pixel that passes the depth test gets its colour at once
    /// and the id [`FORWARD`]: interpolating a colour costs less than sorting the pixel for a
    /// deferred pass, and a later, nearer triangle overwrites both. Without `IDS` (see
    /// [`Frame::tile_gouraud`]) no id is written and `ids` is not read.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn visible_single<const IDS: bool>(
        &self,
        t: &Tri,
        ti: u32,
        o: [i64; 3],
        (x0, y0, tw, y1): (u32, u32, usize, u32),
        (bx0, bx1): (u32, u32),
        depth: &mut [f32],
        ids: &mut [u32],
        mut forward: Option<Forward>,
    ) {
        let step = each3(|i| t.a(i) << SUBPIXEL_BITS);
        let bb = t.bbox();
        let n = i64::from(bx1 - bx0);
        for py in bb[1].max(y0)..bb[3].min(y1) {
            let (cx, cy) = (i64::from(bx0) << SUBPIXEL_BITS, i64::from(py) << SUBPIXEL_BITS);
            // e − bias at the row's first pixel.
            let row = each3(|i| t.a(i) * cx + t.b(i) * cy + t.c[i] + o[i]);
            let (lo, hi) = covered_span(row, step, n);
            let line = (py - y0) as usize * tw + (bx0 - x0) as usize;
            let mut eb = each3(|i| row[i] + step[i] * lo);
            // Forward: the pixels of this row (at most a tile's 64) that passed.
            let mut passed = 0u64;
            for k in lo..hi {
                if (eb[0] | eb[1] | eb[2]) >= 0 {
                    let e = each3(|i| eb[i] + t.bias(i));
                    let l = map3(e, |x| (x as f64 * t.inv_area) as f32);
                    let zz = l[0] * t.z[0] + l[1] * t.z[1] + l[2] * t.z[2];
                    let at = line + k as usize;
                    if zz < depth[at] {
                        depth[at] = zz;
                        if forward.is_some() {
                            if IDS {
                                ids[at] = FORWARD;
                            }
                            passed |= 1 << k;
                        } else if IDS {
                            ids[at] = ti;
                        }
                    }
                }
                for i in 0..3 {
                    eb[i] += step[i];
                }
            }
            if let Some(f) = &mut forward
                && passed != 0
            {
                let row = &mut f.rows[(py - y0) as usize][(bx0 - x0) as usize..(bx1 - x0) as usize];
                let mut m = passed;
                while m != 0 {
                    let j = m.trailing_zeros();
                    row[j as usize] = f.planes.at(bx0 + j, py);
                    m &= m - 1;
                }
            }
        }
    }

    /// The fast path's shading with one sample per pixel: each visible pixel is shaded once and
    /// written straight into the tile (no job list; the resolve of one opaque sample is the
    /// sample itself, `x·1/1 = x`). `ids` is, per pixel of the tile `(x0, y0, width, height)`,
    /// the index in `bin` of its visible triangle. The visible pixels are sorted by triangle
    /// (a counting sort over the bin), so that each triangle's pixels are shaded together with
    /// its plane coefficients broadcast, not gathered lane by lane from neighbouring triangles.
    #[allow(clippy::too_many_arguments)]
    fn shade_single(
        &self,
        bin: &[u32],
        ids: &[u32],
        (x0, y0, tw, th): (u32, u32, usize, usize),
        bg: [f32; 4],
        clock: &StageClock,
        (t_start, t_shade): (Instant, Instant),
        out: &mut [&mut [[f32; 4]]],
        image: bool,
    ) -> u64 {
        let background = resolve(std::iter::once(bg), 1, bg);
        // starts[k + 1]: how many visible pixels triangle k of the bin has, then (prefix sums)
        // where its pixels end in `order`.
        // By runs of equal ids along rows (`(row << 16 | first column, length, k)`): a count per
        // run, not a read-modify-write of the same counter per pixel (a chain through memory).
        let mut starts = vec![0u32; bin.len() + 1];
        let mut shaded = 0u32;
        let mut runs: Vec<(u32, u32, u32)> = Vec::with_capacity(tw * th / 4);
        for (row, line) in out.iter_mut().enumerate().take(th) {
            let ids = &ids[row * tw..(row + 1) * tw];
            let mut col = 0;
            while col < tw {
                let k = ids[col];
                let len = run_length(&ids[col..], k);
                if k == u32::MAX {
                    fill_background(&mut line[col..col + len], background, image);
                } else if k == FORWARD {
                    // Coloured during visibility.
                    shaded += len as u32;
                } else {
                    starts[k as usize + 1] += len as u32;
                    runs.push(((row as u32) << 16 | col as u32, len as u32, k));
                }
                col += len;
            }
        }
        stream_fence();
        for k in 0..bin.len() {
            starts[k + 1] += starts[k];
        }
        let sorted = starts[bin.len()];
        shaded += sorted;
        let mut order = vec![0u32; sorted as usize];
        let mut next = starts.clone();
        for &(first, len, k) in &runs {
            let at = next[k as usize] as usize;
            for (i, o) in order[at..at + len as usize].iter_mut().enumerate() {
                *o = first + i as u32;
            }
            next[k as usize] += len;
        }
        // Per object, the pixels left over from whole vectors, with their triangles: shaded
        // together, each lane gathering its triangle's planes.
        let mut rest: Vec<Vec<(u32, u32)>> = vec![Vec::new(); self.scene.objects.len()];
        let at = |p: u32| ((p >> 16) as usize, (p & 0xffff) as usize);
        let group = group_lanes(self.avx2);
        for (k, &id) in bin.iter().enumerate() {
            let pixels = &order[starts[k] as usize..starts[k + 1] as usize];
            if pixels.is_empty() {
                continue;
            }
            let object = self.object(id);
            let Some(kind) = self.modes[object].batch() else {
                for &p in pixels {
                    let (r, c) = at(p);
                    let color = self.shade_pixel(id, x0 + c as u32, y0 + r as u32);
                    out[r][c] = resolve(std::iter::once(color), 1, bg);
                }
                continue;
            };
            // Fewer pixels than a vector: straight to the gathered batch (no call; a 1M-triangle
            // tile has thousands of one-pixel triangles).
            let done = if pixels.len() < group {
                0
            } else {
                shade_group(self.avx2, kind, self.planes(id), (x0, y0), pixels, |p, rgb| {
                    let (r, c) = at(p);
                    out[r][c] = [rgb[0], rgb[1], rgb[2], 1.0];
                })
            };
            rest[object].extend(pixels[done..].iter().map(|&p| (p, id)));
        }
        for (object, batch) in rest.iter().enumerate() {
            let Some(kind) = self.modes[object].batch() else {
                continue;
            };
            shade_batch(
                self.avx2,
                kind,
                batch.len(),
                |i| {
                    let (p, id) = batch[i];
                    let (r, c) = at(p);
                    (
                        (x0 + c as u32) as f32 + 0.5,
                        (y0 + r as u32) as f32 + 0.5,
                        self.planes(id),
                    )
                },
                |i, rgb| {
                    let (r, c) = at(batch[i].0);
                    out[r][c] = [rgb[0], rgb[1], rgb[2], 1.0];
                },
            );
        }
        let t_end = Instant::now();
        clock.add(t_start, t_shade, t_end, t_end);
        u64::from(shaded)
    }

    /// The colour of triangle `t` at the centre of pixel `(px, py)`, perspective-correct.
    fn shade_pixel(&self, id: u32, px: u32, py: u32) -> [f32; 4] {
        let (t, corners) = (self.tri(id), self.corners(id));
        let q = Self::weights(t, corners, px, py);
        let v = &corners.v;
        let lerp3 = |f: fn(&ClipVertex) -> Vec3| f(&v[0]) * q[0] + f(&v[1]) * q[1] + f(&v[2]) * q[2];
        let scene = self.scene;
        let obj = &scene.objects[self.object(id)];
        let output = obj.shading.output;
        let c = match output {
            Output::Normal => {
                let n = match corners.flat {
                    Some((_, n)) => n,
                    None if t.back => -lerp3(|v| v.normal).normalize_or_zero(),
                    None => lerp3(|v| v.normal).normalize_or_zero(),
                };
                normal_color(n)
            }
            Output::Depth => depth_color(&scene.camera, lerp3(|v| v.world)),
            _ => match (corners.flat, obj.shading.interpolation) {
                (Some((c, _)), _) => c,
                (None, Interpolation::Gouraud) => {
                    let c = if t.back {
                        lerp3(|v| v.color_back)
                    } else {
                        lerp3(|v| v.color)
                    };
                    Color::new(c.x, c.y, c.z)
                }
                _ => {
                    let n = lerp3(|v| v.normal);
                    let n = if t.back { -n } else { n };
                    let view = &self.views[self.object(id)];
                    output.term(&obj.shade(&scene.lighting, view, lerp3(|v| v.world), n))
                }
            },
        };
        [c.r, c.g, c.b, 1.0]
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// The record sizes the docs and BENCHMARKS.md state (per vertex and per drawn triangle).
    #[test]
    fn record_sizes() {
        use std::mem::size_of;
        assert_eq!(size_of::<FastVertex>(), 20);
        assert_eq!(size_of::<Tri>(), 80);
        assert_eq!(size_of::<Planes>(), 96);
        assert_eq!(size_of::<Pending>(), 16);
    }

    /// The AVX2 Gouraud tile kernel draws every tile of a frame bit for bit as the scalar loop
    /// (`visible_single`): each colour and depth, and the count of covered pixels; and into an
    /// 8-bit frame, the scalar loop's colours as `Encoding::Linear` encodes them. Whole frames
    /// too: `render` chooses the kernel for some tiles, and its 8-bit frames are the `f32`
    /// frames' bytes. Frames of 203 × 149 pixels (a last column of tiles 11 pixels wide, not a
    /// multiple of the kernel's 4) with a sphere, a torus and a two-sided ground plane through
    /// the near plane, and a soup of random triangles from under a pixel to wider than the
    /// frame, interpenetrating, drawn twice in two materials (equal depths: the first stays),
    /// some of them also with their vertices rotated.
    #[test]
    fn gouraud_kernel_is_the_scalar_loop() {
        if !avx2_available() {
            eprintln!("skipped: this CPU has no AVX2");
            return;
        }
        let src = r#"
[image]
width = 203
height = 149
[camera]
position = [0.0, 0.4, 0.5]
target = [0.0, 0.0, -2.0]
near = 0.1
[shading]
model = "blinn-phong"
interpolation = "gouraud"
two_sided = true
[[light]]
type = "point"
position = [0.5, 2.0, -1.0]
attenuation = [1.0, 0.1, 0.05]
[[object]]
shape = "sphere"
segments = 40
material = "gold"
position = [-0.4, 0.0, -2.0]
scale = 0.7
[[object]]
shape = "torus"
segments = 32
material = "ruby"
position = [0.5, 0.0, -1.5]
[[object]]
shape = "plane"
segments = 6
material = "pewter"
position = [0.0, -0.5, 0.0]
scale = 300.0
"#;
        let path = std::path::Path::new("gouraud-kernel.toml");
        let shapes = phong_scene::parse_scene(src, path).unwrap().scene;
        let mut soup = shapes.clone();
        soup.objects.truncate(2);
        let mut next = xorshift(0x9e37_79b9_7f4a_7c15);
        let mut unit = move || (next() >> 11) as f32 / (1u64 << 53) as f32;
        let mut positions = Vec::new();
        let mut triangles = Vec::new();
        for k in 0..400u32 {
            let centre = Vec3::new(unit() * 3.0 - 1.5, unit() * 2.0 - 1.0, -1.0 - unit() * 3.0);
            let size = [0.004, 0.05, 0.3, 2.5][k as usize % 4] * (0.5 + unit());
            for _ in 0..3 {
                positions.push(centre + (Vec3::new(unit(), unit(), unit()) - 0.5) * size);
            }
            triangles.push([3 * k, 3 * k + 1, 3 * k + 2]);
            if k % 10 == 0 {
                triangles.push([3 * k + 1, 3 * k + 2, 3 * k]);
            }
        }
        // Twice, in two materials: the same depths, other colours.
        let mesh = phong_core::Mesh::from_triangles(positions, triangles).unwrap();
        for object in &mut soup.objects {
            object.mesh = mesh.clone();
        }
        for (name, scene) in [("shapes", &shapes), ("soup", &soup)] {
            let frame = Frame::build(scene, false, true, &mut Scratch::default());
            let clock = StageClock::default();
            let bg = [0.1, 0.2, 0.3, 1.0];
            let (mut drawn, mut wide) = (0, 0);
            for tile in 0..frame.bins.len() as u32 {
                let (x0, y0, x1, y1) = frame.tile_rect(tile);
                let (tw, th) = ((x1 - x0) as usize, (y1 - y0) as usize);
                let draw = |kernel: bool| {
                    let mut pixels = vec![[f32::NAN; 4]; tw * th];
                    let mut rows: Vec<&mut [[f32; 4]]> = pixels.chunks_mut(tw).collect();
                    let mut depth = Vec::new();
                    let n = frame.tile_gouraud(tile, bg, &clock, &mut rows, &mut depth, kernel);
                    let stride = depth.len() / th;
                    let depth: Vec<f32> = depth.chunks(stride).flat_map(|r| r[..tw].to_vec()).collect();
                    let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                    (n, bits(pixels.as_flattened()), bits(&depth))
                };
                let (scalar, vector) = (draw(false), draw(true));
                assert!(scalar == vector, "{name}: tile {tile} differs");
                // Straight into 8 bits: the scalar loop's pixels encoded.
                let mut bytes = vec![[7u8; 4]; tw * th];
                let mut rows: Vec<&mut [[u8; 4]]> = bytes.chunks_mut(tw).collect();
                let n8 = frame.tile_gouraud8(tile, bg, &clock, &mut rows, &mut Vec::new());
                let encoded: Vec<[u8; 4]> = scalar
                    .1
                    .chunks(4)
                    .map(|p| encode([0, 1, 2, 3].map(|i| f32::from_bits(p[i])), Encoding::Linear))
                    .collect();
                assert_eq!(n8, scalar.0, "{name}: tile {tile}");
                assert!(bytes == encoded, "{name}: tile {tile} differs in 8 bits");
                drawn += scalar.0;
                wide += u64::from(tw % 4 != 0 && scalar.0 > 0);
            }
            assert!(drawn > 203 * 149 / 2, "{name}: only {drawn} pixels drawn");
            assert!(wide > 0, "{name}: nothing drawn in the narrow tiles");
            // Whole frames: `render` chooses the kernel for some tiles (straight into 8 bits
            // for the 8-bit frame), and the frames are the `f32` image's bytes, with 1 and 3
            // threads.
            let chosen = (0..frame.bins.len() as u32)
                .filter(|&t| frame.gouraud_applies(t) && frame.gouraud_kernel(t))
                .count();
            assert!(chosen > 0, "{name}: no tile for the kernel");
            for threads in [1, 3] {
                let options = RenderOptions {
                    threads: Some(threads),
                    ..Default::default()
                };
                let f32_bytes = crate::render(scene, &options)
                    .unwrap()
                    .to_bytes(Encoding::Linear, false);
                let mut renderer = crate::Renderer::new();
                let (image8, _) = renderer.render_8bit(scene, &options).unwrap().unwrap();
                assert!(image8.to_bytes(false) == f32_bytes, "{name}: 8-bit frame differs");
            }
        }
    }

    /// A xorshift64 generator: the tests' reproducible random numbers.
    pub(crate) fn xorshift(mut seed: u64) -> impl FnMut() -> u64 {
        move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        }
    }

    /// Binning's trivial reject never drops a tile where a sample of any pattern is covered,
    /// and does drop some (random triangles up to 2.5 tiles across, in a 4×4-tile image).
    #[test]
    fn tile_reject_is_conservative() {
        let (w, h) = (4 * TILE_SIZE, 4 * TILE_SIZE);
        let mut bits = xorshift(0x2545_f491_4f6c_dd1du64);
        let mut next = |range: i64| (bits() % range as u64) as i64;
        let patterns: Vec<Vec<(i64, i64)>> = [1, 4, 16]
            .iter()
            .map(|&n| {
                sample_pattern(n)
                    .iter()
                    .map(|&(x, y)| ((x * ONE).round() as i64, (y * ONE).round() as i64))
                    .collect()
            })
            .collect();
        let all = SampleSpan::of(&patterns.concat());
        let mut rejected = 0;
        for _ in 0..400 {
            let span = i64::from(TILE_SIZE) * 160 * 2;
            let (cx, cy) = (next(i64::from(w) * 256), next(i64::from(h) * 256));
            let proj = [0; 3].map(|_| {
                Projected(
                    (cx + next(span) - span / 2) as i32,
                    (cy + next(span) - span / 2) as i32,
                    0.5,
                    1.0,
                )
            });
            let Some(s) = setup_edges(proj, true, w, h, all) else {
                continue;
            };
            let t = &s.tri;
            for ty in 0..h / TILE_SIZE {
                for tx in 0..w / TILE_SIZE {
                    if !Frame::misses_tile(t, tx, ty) {
                        continue;
                    }
                    rejected += 1;
                    for py in ty * TILE_SIZE..(ty + 1) * TILE_SIZE {
                        for px in tx * TILE_SIZE..(tx + 1) * TILE_SIZE {
                            for &(ox, oy) in patterns.iter().flatten() {
                                let (sx, sy) = (
                                    (i64::from(px) << SUBPIXEL_BITS) + ox,
                                    (i64::from(py) << SUBPIXEL_BITS) + oy,
                                );
                                assert!(
                                    Frame::covers(t, sx, sy).is_none(),
                                    "tile ({tx}, {ty}) rejected, ({px}, {py}) covered"
                                );
                            }
                        }
                    }
                }
            }
        }
        assert!(rejected > 100, "only {rejected} tiles rejected");
    }

    /// A triangle's bounding box holds every sample it covers, for each pattern, checked pixel
    /// by pixel around its vertices (tiny triangles, most of them, and larger ones, some across
    /// the image's edges); and it is tight: exactly the pixels whose samples' span meets the
    /// vertices' bounds (with one sample, those with their sample inside), found by search.
    #[test]
    fn bounding_box_holds_every_covered_sample() {
        let (w, h) = (40u32, 30u32);
        let mut bits = xorshift(0x9e37_79b9_7f4a_7c15u64);
        let mut next = |range: i64| (bits() % range as u64) as i64;
        let (mut culled, mut tight) = (0, 0usize);
        for n in [1, 4, 16] {
            let pattern: Vec<(i64, i64)> = sample_pattern(n)
                .iter()
                .map(|&(x, y)| ((x * ONE).round() as i64, (y * ONE).round() as i64))
                .collect();
            for k in 0..3000 {
                // Half of them within about two pixels, the rest up to 12 pixels across.
                let size = if k % 2 == 0 { 2 * 256 } else { 12 * 256 };
                let (cx, cy) = (next(i64::from(w + 4) * 256) - 512, next(i64::from(h + 4) * 256) - 512);
                let proj = [0; 3].map(|_| Projected((cx + next(size)) as i32, (cy + next(size)) as i32, 0.5, 1.0));
                let covered = |px: i64, py: i64| {
                    let t = setup_edges(proj, true, w, h, SampleSpan(0, 255, 0, 255)).map(|s| s.tri);
                    pattern.iter().any(|&(ox, oy)| {
                        t.as_ref().is_some_and(|t| {
                            Frame::covers(t, (px << SUBPIXEL_BITS) + ox, (py << SUBPIXEL_BITS) + oy).is_some()
                        })
                    })
                };
                let (x0, y0) = (cx >> SUBPIXEL_BITS, cy >> SUBPIXEL_BITS);
                let mut hits = Vec::new();
                for py in (y0 - 1).max(0)..(y0 + 14).min(i64::from(h)) {
                    for px in (x0 - 1).max(0)..(x0 + 14).min(i64::from(w)) {
                        if covered(px, py) {
                            hits.push((px, py));
                        }
                    }
                }
                let Some(s) = setup_edges(proj, true, w, h, SampleSpan::of(&pattern)) else {
                    assert!(hits.is_empty(), "culled, yet covers {hits:?}");
                    culled += 1;
                    continue;
                };
                let [bx0, by0, bx1, by1] = s.tri.bbox().map(i64::from);
                for &(px, py) in &hits {
                    assert!(
                        (bx0..bx1).contains(&px) && (by0..by1).contains(&py),
                        "({px}, {py}) outside {:?}",
                        s.tri.bbox()
                    );
                }
                // Tight: exactly the pixels with a sample inside the vertices' bounds, by search.
                let bounds = |v: [i64; 3], o: &dyn Fn(&(i64, i64)) -> i64, size: u32| {
                    let (lo, hi) = (
                        v.iter().min().copied().unwrap_or(0),
                        v.iter().max().copied().unwrap_or(0),
                    );
                    // Pixel p's samples span [p·256 + min offset, p·256 + max offset] (one
                    // sample: exactly the pixels with a sample inside).
                    let (omin, omax) = (
                        pattern.iter().map(o).min().unwrap_or(0),
                        pattern.iter().map(o).max().unwrap_or(0),
                    );
                    let inside = |p: i64| (p << SUBPIXEL_BITS) + omin <= hi && (p << SUBPIXEL_BITS) + omax >= lo;
                    let mut ps = (0..i64::from(size)).filter(|&p| inside(p));
                    let first = ps.next();
                    (first, ps.next_back().or(first))
                };
                let xs = bounds(proj.map(|p| i64::from(p.0)), &|q| q.0, w);
                let ys = bounds(proj.map(|p| i64::from(p.1)), &|q| q.1, h);
                assert_eq!((xs.0, xs.1.map(|x| x + 1)), (Some(bx0), Some(bx1)), "{proj:?}");
                assert_eq!((ys.0, ys.1.map(|y| y + 1)), (Some(by0), Some(by1)), "{proj:?}");
                tight += usize::from(hits.is_empty());
            }
        }
        // Many small triangles cover no sample: most are culled, the rest have samples in
        // their bounds, outside their edges.
        assert!(
            culled > 1000 && tight > 0,
            "{culled} culled, {tight} kept with no sample"
        );
    }

    /// The AVX2 vertex stage gives the scalar one's records bit for bit: vertices in front of,
    /// across and behind a perspective camera, in and far beyond the guard band, at the eye
    /// (`w = 0`), NaN and infinite, in groups of 8 and a remainder; and through a degenerate
    /// transform whose every vertex is "inside" at `w = 0`.
    #[test]
    fn vector_vertex_stage_matches_scalar() {
        if !avx2_available() {
            eprintln!("no AVX2: the vector vertex stage is not used on this CPU");
            return;
        }
        let camera = phong_core::Camera::new(
            Vec3::new(0.3, 0.2, 3.0),
            Vec3::ZERO,
            Vec3::Y,
            phong_core::Projection::Perspective { fov_y_deg: 50.0 },
            0.1,
            50.0,
        )
        .expect("a valid camera");
        let clip_from_world = camera.clip_from_world(16.0 / 9.0);
        let mut bits = xorshift(0x0123_4567_89ab_cdef);
        let mut next = || (bits() >> 40) as f32 / (1u64 << 24) as f32;
        let mut positions: Vec<Vec3> = (0..20_000)
            .map(|i| {
                let scale = [1.5, 6.0, 400.0][i % 3];
                Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5) * scale
            })
            .collect();
        for (i, p) in [
            Vec3::new(0.3, 0.2, 3.0),
            Vec3::new(0.3, 0.2, 2.95),
            Vec3::new(f32::NAN, 0.0, 0.0),
            Vec3::new(0.0, f32::INFINITY, 0.0),
            Vec3::new(1e30, -1e30, 0.0),
        ]
        .into_iter()
        .enumerate()
        {
            positions[i * 37 + 5] = p;
        }
        positions.truncate(19_997);
        let vertex = FastVertex::default();
        let (mut fast, mut slow) = (vec![vertex; positions.len()], vec![vertex; positions.len()]);
        for (w, h) in [(1920, 1080), (333, 517)] {
            fast_vertices(true, clip_from_world, (w, h), &positions, &mut fast);
            fast_vertices(false, clip_from_world, (w, h), &positions, &mut slow);
            let bits = |v: &FastVertex| (v.p.0, v.p.1, v.p.2.to_bits(), v.p.3.to_bits(), v.code);
            let mut inside = 0;
            for (i, (a, b)) in fast.iter().zip(&slow).enumerate() {
                assert_eq!(bits(a), bits(b), "vertex {i} at {}", positions[i]);
                inside += usize::from(b.code & (OUTSIDE_CLIP | NOT_FINITE) == 0);
            }
            assert!(
                inside > 2_000 && inside < 18_000,
                "{inside} of the vertices inside the clip volume"
            );
        }
        // A degenerate transform: every vertex at clip-space (0, 0, 0, 0), inside every plane,
        // projected through 1/0 to NaN: the kernel's groups go to the scalar code's casts.
        let zero = glam::Mat4::ZERO;
        fast_vertices(true, zero, (64, 64), &positions[..20], &mut fast[..20]);
        fast_vertices(false, zero, (64, 64), &positions[..20], &mut slow[..20]);
        for (a, b) in fast[..20].iter().zip(&slow[..20]) {
            assert_eq!((a.p.0, a.p.1, a.code), (b.p.0, b.p.1, b.code));
            assert_eq!((a.p.2.is_nan(), a.p.3.to_bits()), (b.p.2.is_nan(), b.p.3.to_bits()));
        }
    }

    /// `run_length` counts the leading run exactly, at every length and position around its
    /// blocks of 8.
    #[test]
    fn run_length_counts_the_leading_run() {
        for len in 0..40 {
            for run in 0..=len {
                let mut ids = vec![7u32; len];
                if run < len {
                    ids[run] = 3;
                }
                assert_eq!(run_length(&ids, 7), run, "length {len}");
                assert_eq!(run_length(&ids, 3), usize::from(run == 0 && len > 0), "length {len}");
            }
        }
    }

    #[test]
    fn round_matches_f32_round() {
        let mut x = -17_000_000.0f32;
        while x < 17_000_000.0 {
            for v in [
                x,
                x + 0.5,
                x - 0.5,
                x + 0.49999997,
                x + 0.25,
                f32::from_bits(x.to_bits() + 1),
            ] {
                assert_eq!(round_i64(v), v.round() as i64, "{v}");
            }
            x += 9_973.37;
        }
        for v in [0.49999997f32, -0.49999997, 0.5, -0.5, 1.5, -2.5, 8388607.5, -8388607.5] {
            assert_eq!(round_i64(v), v.round() as i64, "{v}");
        }
    }
}
