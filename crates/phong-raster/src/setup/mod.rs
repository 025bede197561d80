//! Triangle setup: snapped vertices to integer edge functions with the top-left rule, the
//! pixel bounding box, culling, and the plane equations the fast path interpolates.
//!
//! Two setups fill the same [`Chunk`]s: [`fast`] for Phong- and Gouraud-interpolated objects on
//! the fast path (20-byte vertex records, planes, no per-vertex clip records), [`full`] for the
//! reference path and the objects the fast path shades one pixel at a time (every vertex in
//! full, [`Corners`] kept).

mod fast;
mod full;

use crate::binning::{Binned, bin_entries};
use crate::clip::ClipVertex;
use crate::fixed::{HALF, ONE};
use crate::plan::{FramePlan, Mode, SetupKind};
use crate::simd::{ColourPlanes, Planes};
use crate::vertex::{FastVertex, Projected, project};
use glam::Vec3;
use phong_core::limits::SUBPIXEL_BITS;
use phong_core::{Color, Scene};
use std::sync::Mutex;
use std::sync::atomic::AtomicBool;

/// Triangles per parallel setup task: large enough to amortise scheduling, small enough to
/// balance 16 threads on a 100k-triangle mesh.
pub(crate) const SETUP_CHUNK: usize = 4096;
/// Low bits of a triangle id that index within its setup chunk (4096 · 7 < 2^15).
pub(crate) const ID_INDEX_BITS: u32 = 15;

/// A triangle ready for the tiles: what visibility reads, 64 bytes in one cache line (the
/// tiles read a fine mesh's triangles scattered through memory: BENCHMARKS.md, C15). Its
/// object, shading planes and (where kept) [`Corners`] are in its [`Chunk`].
#[repr(align(64))]
pub(crate) struct Tri {
    /// Edge functions `E_i(X, Y) = a·X + b·Y + c` (edge i opposite vertex i), in 1/256 pixel;
    /// `a` and `b` are coordinate differences (below 2^25). `E_i` is evaluated from a vertex on
    /// edge `i` ([`Tri::edges_at`]), so `c` is not kept.
    pub a: [i32; 3],
    pub b: [i32; 3],
    /// Vertex 0, snapped (1/256 pixel): on edges 1 and 2, and with edge 2's `a` and `b`, vertex 1.
    pub v0: [i32; 2],
    /// 1 / (twice the signed area): barycentrics are `E_i · inv_area`.
    pub inv_area: f64,
    /// Window depth in [0, 1] per vertex.
    pub z: [f32; 3],
    /// Pixel bounds, inclusive min, exclusive max (images are at most 16384 wide).
    pub bbox: [u16; 4],
    /// Bit i: edge i is not top-left, so inside is `E_i − 1 >= 0` (else `E_i >= 0`).
    pub bias: u8,
    /// A back face of a two-sided object: lit with flipped normals (OpenGL's two-sided lighting).
    pub back: bool,
}

impl Tri {
    /// Edge function `E_i` at `(x, y)` (1/256 pixel) as `a_i·(x − x_v) + b_i·(y − y_v)` from a
    /// vertex `v` on edge `i`: vertex 0 for edges 1 and 2, vertex 1 (`v0 + (b_2, −a_2)`, the
    /// end of edge 2) for edge 0. Exact, as `a·x + b·y + c` (below 2^51 within the guard band).
    #[inline(always)]
    pub fn edge(&self, i: usize, x: i64, y: i64) -> i64 {
        let (mut vx, mut vy) = (i64::from(self.v0[0]), i64::from(self.v0[1]));
        if i == 0 {
            (vx, vy) = (vx + self.b(2), vy - self.a(2));
        }
        self.a(i) * (x - vx) + self.b(i) * (y - vy)
    }

    /// The three edge functions at `(x, y)` ([`Tri::edge`]).
    #[inline(always)]
    pub fn edges_at(&self, x: i64, y: i64) -> [i64; 3] {
        crate::fixed::each3(|i| self.edge(i, x, y))
    }

    #[inline(always)]
    pub fn a(&self, i: usize) -> i64 {
        i64::from(self.a[i])
    }
    #[inline(always)]
    pub fn b(&self, i: usize) -> i64 {
        i64::from(self.b[i])
    }
    #[inline(always)]
    pub fn bias(&self, i: usize) -> i64 {
        i64::from((self.bias >> i) & 1)
    }
    #[inline(always)]
    pub fn bbox(&self) -> [u32; 4] {
        self.bbox.map(u32::from)
    }

    /// The three edge functions at sample `(sx, sy)` (1/256 pixel); `Some` when the sample is
    /// covered (top-left rule).
    #[inline]
    pub fn covers(&self, sx: i64, sy: i64) -> Option<[i64; 3]> {
        let e = self.edges_at(sx, sy);
        if (0..3).any(|i| e[i] - self.bias(i) < 0) {
            None
        } else {
            Some(e)
        }
    }
}

/// The edges of a set-up triangle and how its vertices were reordered (counter-clockwise on
/// screen after the swap of a front face), for the caller's attributes.
pub(crate) struct Setup {
    pub tri: Tri,
    /// Input vertex of each set-up vertex.
    pub order: [usize; 3],
    pub xy: [(i64, i64); 3],
    pub inv_w: [f32; 3],
    pub area: u64,
    pub front: bool,
}

/// A flat-shaded triangle's light as seen from one side: colour (a textured object's primary
/// colour), specular colour (textured objects only), facet normal.
pub(crate) type Flat = (Color, Color, Vec3);

/// What [`Stage::setup`] keeps of a triangle besides its [`Tri`].
#[derive(Clone, Copy, Debug)]
pub(crate) struct Keep {
    /// Its [`Corners`].
    pub corners: bool,
    /// Its fast-path [`Planes`] and coordinates' planes.
    pub planes: bool,
}

/// What the scalar shading of a triangle needs besides [`Tri`]: kept only for the reference
/// path and for objects the fast path shades one pixel at a time.
pub(crate) struct Corners {
    /// 1/w per vertex.
    pub inv_w: [f32; 3],
    pub v: [ClipVertex; 3],
    /// Flat: the triangle's colour (a textured object's primary colour), its specular colour
    /// (textured objects only) and facet normal (as seen: flipped on a two-sided back face).
    pub flat: Option<Flat>,
}

/// The triangles one setup task made, with their [`Corners`] (same index) where kept, else
/// none.
#[derive(Default)]
pub(crate) struct Chunk {
    /// The object all its triangles belong to.
    pub object: u32,
    pub tris: Vec<Tri>,
    /// The fast path's plane equations (Phong: world position and normal, flipped on a back
    /// face; Gouraud: the colour seen), same index; empty for scalar-shaded objects.
    pub planes: Vec<Planes>,
    /// Instead of `planes` in a frame whose planes are [`ColourPlanes`]
    /// ([`FramePlan::colour_planes`]), same index.
    pub colour: Vec<ColourPlanes>,
    pub corners: Vec<Corners>,
    /// Gouraud triangles whose planes wait for their vertices' colours (see [`Pending`]).
    pub pending: Vec<Pending>,
    /// Gouraud: the planes of clipped triangles, by slot (the others' are in `pending`
    /// until their vertices are lit).
    pub clipped: Vec<(u32, Planes)>,
    /// Textured objects ([`Mode::Textured`]): the planes of the texture coordinates (`u/w`,
    /// `v/w` in `attr[0]`, `attr[1]`), same index.
    pub uv: Vec<Planes>,
    /// `(tile, index)` for each tile each triangle is binned into, in triangle order (see
    /// `Binned::bin_chunks`).
    pub binned: Vec<(u32, u32)>,
}

impl Chunk {
    /// Keeps `p` as the frame's planes are kept: whole, or its colour part
    /// ([`FramePlan::colour_planes`]).
    #[inline]
    pub fn push_planes(&mut self, colour: bool, p: &Planes) {
        if colour {
            self.colour.push(ColourPlanes::from(p));
        } else {
            self.planes.push(*p);
        }
    }

    /// Room for `n` triangles' planes as the frame keeps them ([`Chunk::push_planes`]), so
    /// that a recycled chunk does not grow into fresh pages (BENCHMARKS.md, C14).
    #[inline]
    pub fn reserve_planes(&mut self, colour: bool, n: usize) {
        if colour {
            self.colour.reserve(n);
        } else {
            self.planes.reserve(n);
        }
    }

    /// An empty chunk for `object` with room for `n` triangles, from `spare` if it has one.
    pub fn reuse(spare: &Mutex<Vec<Chunk>>, object: usize, n: usize) -> Chunk {
        let mut c = spare.lock().ok().and_then(|mut s| s.pop()).unwrap_or_default();
        c.object = object as u32;
        c.tris.reserve(n);
        c
    }

    /// Empties the chunk, keeping its memory.
    pub fn clear(&mut self) {
        self.uv.clear();
        self.tris.clear();
        self.planes.clear();
        self.colour.clear();
        self.corners.clear();
        self.pending.clear();
        self.binned.clear();
        self.clipped.clear();
    }
}

/// A Gouraud triangle set up before its vertices were lit (in the chunk's triangle `slot`),
/// its planes made once the colours exist. 16 bytes: the rest of what the planes need is read
/// again from the vertex records and the triangle's edges (BENCHMARKS.md, C3).
pub(crate) struct Pending {
    pub slot: u32,
    /// Input vertices, in the set-up order.
    pub idx: [u32; 3],
}

/// A mesh's vertex attributes besides position and normal, as both set-ups read them: zero
/// texture coordinates, white and no tangent where the mesh has none.
#[derive(Clone, Copy)]
pub(crate) struct VertexAttributes<'m>(pub &'m phong_core::Mesh);

impl VertexAttributes<'_> {
    pub fn uv(self, i: u32) -> glam::Vec2 {
        self.0.uvs().get(i as usize).copied().unwrap_or_default()
    }
    pub fn uv1(self, i: u32) -> glam::Vec2 {
        self.0.uvs1().get(i as usize).copied().unwrap_or_default()
    }
    pub fn rgb(self, i: u32) -> Vec3 {
        self.0
            .colors()
            .get(i as usize)
            .map_or(Vec3::ONE, |c| Vec3::from(c.to_array()))
    }
    pub fn tangent(self, i: u32) -> glam::Vec4 {
        self.0.tangents().get(i as usize).copied().unwrap_or(glam::Vec4::ZERO)
    }
}

/// Working memory kept between frames by a [`Renderer`](crate::Renderer): emptied, never
/// shrunk.
#[derive(Default)]
pub(crate) struct Scratch {
    /// The fast setup's per-vertex records (one object at a time).
    pub vertices: Vec<FastVertex>,
    /// Gouraud: the lit colour of each vertex seen from the front, and (two-sided) the back
    /// (a textured object's primary colours, then its specular ones: see
    /// `VertexLighting::light`); kept between frames without clearing (only the vertices of
    /// drawn triangles are lit and read).
    pub colors: [Vec<Vec3>; 4],
    /// Gouraud: whether a vertex is used by a drawn triangle (only those are lit).
    pub used: Vec<AtomicBool>,
    /// Chunks of set-up triangles, emptied, for the next frame's setup tasks.
    pub chunks: Vec<Chunk>,
    pub bins: Vec<Vec<u32>>,
}

/// The bounds of a sample pattern's offsets within a pixel, in 1/256 pixel: `(min x, max x,
/// min y, max y)`. A triangle's bounding box holds the pixels with a sample inside its
/// vertices' bounds, not every pixel those bounds touch: a 1M-triangle sphere's triangles span
/// two or three pixels, and many cover no pixel centre at all.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SampleSpan(pub i64, pub i64, pub i64, pub i64);

impl SampleSpan {
    pub fn of(pattern: &[(i64, i64)]) -> SampleSpan {
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

/// Culls and sets up the edges of a triangle from its projected vertices, for a `w × h`
/// window and sample pattern bounds `span`; `None` when it is culled (a back face of a
/// one-sided object), degenerate or covers no pixel. Explicit arrays, not `[T; 3]::map` (C2).
#[inline(always)]
pub(crate) fn setup_edges(proj: [Projected; 3], two_sided: bool, w: u32, h: u32, span: SampleSpan) -> Option<Setup> {
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
    let mut bias = 0u8;
    for i in 0..3 {
        // Edge opposite vertex i, from vertex j to vertex k.
        let (j, k) = ((i + 1) % 3, (i + 2) % 3);
        let ((xa, ya), (xb, yb)) = (xy[j], xy[k]);
        // E(X, Y) = (xb − xa)(Y − ya) − (yb − ya)(X − xa), positive inside.
        let (ai, bi) = (-(yb - ya), xb - xa);
        a[i] = ai as i32;
        b[i] = bi as i32;
        // Top edge: horizontal, going right; left edge: going up (y down). Both inclusive.
        let top_left = (ya == yb && xb > xa) || yb < ya;
        bias |= u8::from(!top_left) << i;
    }
    let area = area.unsigned_abs();
    Some(Setup {
        tri: Tri {
            a,
            b,
            v0: [xy[0].0 as i32, xy[0].1 as i32],
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

/// What a textured object's coordinates' planes carry beside its first set ([`uv_planes`]'s
/// `extra`), decided per object and frame ([`crate::plan::ObjectPlan::extra`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Extra {
    /// Nothing: the first set alone (the mesh has no vertex colours, the maps read no second
    /// set and no normal map); only its planes are made.
    Nothing,
    /// The vertex colours.
    Colors,
    /// The second set of texture coordinates (the object has no vertex colours).
    SecondSet,
    /// The tangents, for a normal map (no vertex colours, no second set).
    Tangents,
}

impl Extra {
    /// A vertex's extra attributes, from its colour, second set and tangent.
    #[inline(always)]
    pub(crate) fn of(self, rgb: Vec3, uv1: glam::Vec2, tangent: glam::Vec4) -> glam::Vec4 {
        match self {
            Extra::Nothing => glam::Vec4::ZERO,
            Extra::Colors => rgb.extend(0.0),
            Extra::SecondSet => glam::Vec4::new(uv1.x, uv1.y, 0.0, 0.0),
            Extra::Tangents => tangent,
        }
    }
}

/// The planes of texture coordinates `uv` and extra attributes `extra` (per set-up vertex; see
/// [`Extra`]) of triangle `s`: `u/w`, `v/w` in `attr[0]`, `attr[1]`, the extra attributes over
/// `w` in `attr[2..6]` (not made where `what` is [`Extra::Nothing`]).
#[inline]
pub(crate) fn uv_planes(s: &Setup, uv: [glam::Vec2; 3], extra: [glam::Vec4; 3], what: Extra) -> Planes {
    let attrs = [
        crate::fixed::each3(|k| Vec3::new(uv[k].x, uv[k].y, extra[k].x)),
        crate::fixed::each3(|k| Vec3::new(extra[k].y, extra[k].z, extra[k].w)),
    ];
    plane_equations(s.xy[0], &s.tri, s.area, s.inv_w, attrs, what == Extra::Nothing)
}

/// Plane equations (see [`Planes`]) of two vector attributes (only the first with `first_only`),
/// `attrs[j][i]` at vertex `i`, for set-up triangle `t` with vertex 0 snapped at `origin` (1/256
/// pixel) and twice its area `area`: the barycentric `λ_i` is `E_i / area`, so
/// `∂q/∂x = 256 Σ a_i q_i / area` per pixel (likewise `y` with `b`), and `q = q_0` at vertex 0.
/// Computed in `f64`, stored in `f32`.
#[inline(always)]
pub(crate) fn plane_equations(
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

/// Transforms, lights (Gouraud, flat), clips, sets up and bins every triangle of `scene` as
/// `plan` says, in memory taken from `scratch` (given back by [`Binned::recycle`]).
pub(crate) fn run(plan: &FramePlan, scene: &Scene, scratch: &mut Scratch) -> Binned {
    let stage = Stage { plan, scene };
    let mut binned = Binned::new(plan.tiles(), scratch);
    let spare = Mutex::new(std::mem::take(&mut scratch.chunks));
    // Opaque objects first, then blended ones back to front (the bins keep this order).
    for oi in scene.draw_order() {
        let chunks = match plan.objects[oi].setup {
            SetupKind::Full(keep) => stage.object_full(oi, keep),
            SetupKind::Fast => stage.object_fast(oi, scratch, &spare),
        };
        binned.bin_chunks(chunks);
    }
    scratch.chunks = spare.into_inner().unwrap_or_default();
    binned
}

/// What the setup of one object reads: the frame's plan and the scene.
struct Stage<'p> {
    plan: &'p FramePlan<'p>,
    scene: &'p Scene,
}

impl Stage<'_> {
    /// Clip-space `c` (`w > 0`) to this frame's window (see [`project`]).
    #[inline]
    fn project(&self, c: glam::Vec4) -> Projected {
        project(c, self.plan.w, self.plan.h)
    }

    /// [`setup_edges`] in this frame's window and sample pattern.
    #[inline]
    fn setup_edges(&self, proj: [Projected; 3], two_sided: bool) -> Option<Setup> {
        setup_edges(proj, two_sided, self.plan.w, self.plan.h, self.plan.span)
    }

    /// Sorts a chunk's triangles into the tiles they meet ([`bin_entries`]).
    fn bin_entries(&self, chunk: &mut Chunk) {
        bin_entries(chunk, self.plan.tiles_x);
    }

    /// Projects (unless `proj` is given), snaps, culls and sets up one triangle of clip-space
    /// vertices, with what `keep` asks for: its [`Corners`] for scalar shading, its fast-path
    /// [`Planes`] (and a textured object's [`uv_planes`]). `flat`: a flat-shaded triangle's
    /// colours, front and back.
    fn setup(
        &self,
        v: [ClipVertex; 3],
        proj: Option<[Projected; 3]>,
        flat: Option<[Flat; 2]>,
        object: u32,
        keep: Keep,
    ) -> Option<(Tri, Planes, Option<Corners>, Option<Planes>)> {
        let proj = proj.unwrap_or_else(|| v.map(|v| self.project(v.clip)));
        let s = self.setup_edges(proj, self.scene.objects[object as usize].shading.options.two_sided)?;
        let v = s.order.map(|k| v[k]);
        let corners = keep.corners.then(|| Corners {
            inv_w: s.inv_w,
            v,
            flat: flat.map(|f| f[usize::from(!s.front)]),
        });
        if !keep.planes {
            return Some((s.tri, Planes::default(), corners, None));
        }
        let mode = &self.plan.objects[object as usize].mode;
        let what = self.plan.objects[object as usize].extra;
        let extra = |v: &ClipVertex| what.of(v.rgb, v.uv1, v.tangent);
        let uv = matches!(mode, Mode::Textured { .. })
            .then(|| uv_planes(&s, v.map(|v| v.uv), v.each_ref().map(extra), what));
        let planes = match mode {
            Mode::Scalar => Planes::default(),
            Mode::Phong(..) | Mode::Textured { per_vertex: false, .. } => {
                let sign = if s.front { 1.0 } else { -1.0 };
                let attrs = [v.map(|v| v.world), v.map(|v| v.normal * sign)];
                plane_equations(s.xy[0], &s.tri, s.area, s.inv_w, attrs, false)
            }
            Mode::Gouraud | Mode::Textured { per_vertex: true, .. } => {
                // The colours seen at the vertices (Gouraud), or the triangle's (flat: planes
                // with no slope, `Σ a_i = Σ b_i = 0`).
                let side = usize::from(!s.front);
                let (c, spec) = match flat {
                    Some(f) => {
                        let (c, spec, _) = f[side];
                        ([Vec3::from(c.to_array()); 3], [Vec3::from(spec.to_array()); 3])
                    }
                    None => (
                        v.map(|v| if s.front { v.color } else { v.color_back }),
                        v.map(|v| v.spec[side]),
                    ),
                };
                let colour_only = matches!(mode, Mode::Gouraud);
                plane_equations(s.xy[0], &s.tri, s.area, s.inv_w, [c, spec], colour_only)
            }
        };
        Some((s.tri, planes, corners, uv))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixed::pattern;
    use crate::testkit::xorshift;

    /// The record sizes the docs and BENCHMARKS.md state (per drawn triangle).
    #[test]
    fn record_sizes() {
        use std::mem::size_of;
        assert_eq!((size_of::<Tri>(), std::mem::align_of::<Tri>()), (64, 64));
        assert_eq!(size_of::<Planes>(), 96);
        assert_eq!(
            (size_of::<ColourPlanes>(), std::mem::align_of::<ColourPlanes>()),
            (64, 64)
        );
        assert_eq!(size_of::<Pending>(), 16);
    }

    /// A set-up triangle's edge functions ([`Tri::edge`], from vertex 0 and the edges) are
    /// those of its edges through the input vertices: `E_i = 0` at both ends of edge `i` and,
    /// at a random point, the cross product of edge `i` with the point taken from the input
    /// vertices, for random triangles of every size and place, front and back.
    #[test]
    fn edge_functions_put_each_edge_through_its_vertices() {
        let mut next = xorshift(0x5eed_c0de);
        let mut checked = 0;
        for k in 0..20_000 {
            // Snapped coordinates up to ±2^23 (32768 pixels), small triangles often.
            let scale = [1u64 << 8, 1 << 12, 1 << 18, 1 << 23][k % 4];
            let within = |v: u64, s: u64| (v % (2 * s)) as i64 - s as i64;
            let (cx, cy) = (within(next(), scale), within(next(), scale));
            let local = (scale >> 2).max(64);
            let proj: [Projected; 3] = std::array::from_fn(|_| {
                let x = (cx + within(next(), local)).clamp(-(1 << 23), 1 << 23);
                let y = (cy + within(next(), local)).clamp(-(1 << 23), 1 << 23);
                Projected(x as i32, y as i32, 0.5, 1.0)
            });
            let Some(s) = setup_edges(proj, true, 16384, 16384, SampleSpan::of(&[(128, 128)])) else {
                continue;
            };
            let t = &s.tri;
            let xy = s.order.map(|o| (i64::from(proj[o].0), i64::from(proj[o].1)));
            let (px, py) = (within(next(), scale), within(next(), scale));
            for i in 0..3 {
                for v in [(i + 1) % 3, (i + 2) % 3] {
                    assert_eq!(t.edge(i, xy[v].0, xy[v].1), 0, "edge {i}, vertex {v}");
                }
                // (xb − xa)(Y − ya) − (yb − ya)(X − xa), from vertex j to vertex k.
                let ((xa, ya), (xb, yb)) = (xy[(i + 1) % 3], xy[(i + 2) % 3]);
                assert_eq!(t.edges_at(px, py)[i], (xb - xa) * (py - ya) - (yb - ya) * (px - xa));
            }
            checked += 1;
        }
        assert!(checked > 2_000, "{checked} triangles set up");
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
        for n in phong_core::Samples::ALL {
            let pattern = pattern(n);
            for k in 0..3000 {
                // Half of them within about two pixels, the rest up to 12 pixels across.
                let size = if k % 2 == 0 { 2 * 256 } else { 12 * 256 };
                let (cx, cy) = (next(i64::from(w + 4) * 256) - 512, next(i64::from(h + 4) * 256) - 512);
                let proj = [0; 3].map(|_| Projected((cx + next(size)) as i32, (cy + next(size)) as i32, 0.5, 1.0));
                let covered = |px: i64, py: i64| {
                    let t = setup_edges(proj, true, w, h, SampleSpan(0, 255, 0, 255)).map(|s| s.tri);
                    pattern.iter().any(|&(ox, oy)| {
                        t.as_ref().is_some_and(|t| {
                            t.covers((px << SUBPIXEL_BITS) + ox, (py << SUBPIXEL_BITS) + oy)
                                .is_some()
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
}
