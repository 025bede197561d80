//! Indexed triangle meshes and their normals (seed 001: facet normals from
//! the cross product, vertex normals from the facet normals or from the
//! surface's formula).

use crate::join::Join;
use crate::{Color, Error};
use glam::{Mat3, Mat4, Vec2, Vec3, Vec4};
use rustc_hash::FxHashMap;

mod crease;
mod facets;
pub use crease::{weld_ids, weld_positions};

/// An indexed triangle mesh with one normal per vertex (or, drawn flat, one per triangle:
/// [`Mesh::face_normals`]) and, optionally, texture coordinates per vertex. Triangles are
/// counter-clockwise seen from the side their normals point to.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Mesh {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    /// Empty, or one per position.
    uvs: Vec<Vec2>,
    /// A second set of texture coordinates (glTF's `TEXCOORD_1`): empty, or one per position.
    uvs1: Vec<Vec2>,
    /// Vertex colours: empty, or one per position.
    colors: Vec<Color>,
    /// Tangents (`xyz`, and in `w` the bitangent's sign): empty, or one per position.
    tangents: Vec<Vec4>,
    /// A flat mesh's normals, one per triangle, its vertices shared ([`Mesh::flat_transformed`]);
    /// `normals` is then empty.
    face_normals: Option<Vec<Vec3>>,
    /// A flat mesh's per-vertex form, made at its first use ([`Mesh::with_vertex_normals`]).
    vertex_form: VertexForm,
}

/// [`Mesh::with_vertex_normals`]'s mesh, kept so that each frame lit per vertex does not make
/// it again. A copy of the mesh starts without it, and every change of the mesh forgets it.
#[derive(Default)]
struct VertexForm(std::sync::OnceLock<Box<Mesh>>);

impl VertexForm {
    fn forget(&mut self) {
        self.0 = std::sync::OnceLock::new();
    }
}

impl Clone for VertexForm {
    fn clone(&self) -> Self {
        VertexForm::default()
    }
}

/// Derived from the mesh: equal meshes are equal whether or not it was made.
impl PartialEq for VertexForm {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl std::fmt::Debug for VertexForm {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(if self.0.get().is_some() {
            "VertexForm(made)"
        } else {
            "VertexForm"
        })
    }
}

/// The first point with a coordinate that is not finite ([`not_finite_at`]).
pub fn first_not_finite(points: &[Vec3]) -> Option<&Vec3> {
    not_finite_at(points).map(|i| &points[i])
}

/// The index of the first point with a coordinate that is not finite. The common case,
/// none, is decided by one pass the compiler vectorises (the exponent bits of every
/// coordinate or'd together); only points that fail are searched.
pub fn not_finite_at(points: &[Vec3]) -> Option<usize> {
    const EXPONENT: u32 = 0x7f80_0000;
    let all = bytemuck::cast_slice::<Vec3, f32>(points)
        .iter()
        .fold(0u32, |acc, c| acc | u32::from(c.to_bits() & EXPONENT == EXPONENT));
    if all == 0 {
        None
    } else {
        points.iter().position(|p| !p.is_finite())
    }
}

/// The first triangle with an index at or past `n` ([`index_at_least`] over its corners).
pub fn first_out_of_range(triangles: &[[u32; 3]], n: usize) -> Option<&[u32; 3]> {
    index_at_least(triangles.as_flattened(), n).map(|k| &triangles[k / 3])
}

/// Where the first index at or past `n` is in `indices`: decided by one vectorised pass, the
/// position searched only when one is out of range.
pub fn index_at_least(indices: &[u32], n: usize) -> Option<usize> {
    let any = match n {
        0 => !indices.is_empty(),
        // As `i32` (two vector operations an index: x86-64's baseline has no unsigned 32-bit
        // max or comparison): an index of 2³¹ and more has its sign bit set, one below that
        // is out of range where it is above `n − 1`.
        1..=0x8000_0000 => {
            let last = (n - 1) as i32;
            let (bits, over) = indices
                .iter()
                .fold((0u32, 0u32), |(b, o), &i| (b | i, o | u32::from(i as i32 > last)));
            bits >> 31 != 0 || over != 0
        }
        _ => indices.iter().fold(0u32, |m, &i| m.max(i)) as usize >= n,
    };
    if any {
        indices.iter().position(|&i| i as usize >= n)
    } else {
        None
    }
}

/// The facet normal of seed 001: `normalize((p2 − p1) × (p3 − p1))`; zero for a degenerate triangle.
#[inline]
pub fn facet_normal(p1: Vec3, p2: Vec3, p3: Vec3) -> Vec3 {
    (p2 - p1).cross(p3 - p1).normalize_or_zero()
}

/// Triangles in each half of a mesh from which [`Mesh::flat_transformed`] hands its two halves
/// to its [`Join`]: a thread's start (tens of µs) is small beside the work of 10,000 triangles.
const FLAT_HALF_MIN: usize = 10_000;

/// A per-vertex attribute given to each corner of `triangles` in turn (three vertices a
/// triangle); empty for an empty one. Each array sized once and written triangle by
/// triangle, no growth check per vertex (a large glTF without normals takes this path).
fn per_corner<T: Copy + Default>(from: &[T], triangles: &[[u32; 3]]) -> Vec<T> {
    if from.is_empty() {
        return Vec::new();
    }
    let mut out = vec![T::default(); 3 * triangles.len()];
    for (o, t) in out.chunks_exact_mut(3).zip(triangles) {
        o[0] = from[t[0] as usize];
        o[1] = from[t[1] as usize];
        o[2] = from[t[2] as usize];
    }
    out
}

impl Mesh {
    /// A mesh from positions, per-vertex normals (same length) and triangles;
    /// every index must be in range and every position finite.
    pub fn new(positions: Vec<Vec3>, normals: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Result<Self, Error> {
        if normals.len() != positions.len() {
            return Err(Error::OutOfRange {
                what: "number of normals",
                range: "equal to the number of positions",
                value: normals.len() as f32,
            });
        }
        if let Some(p) = first_not_finite(&positions) {
            return Err(Error::InvalidPosition {
                what: "mesh vertex",
                value: p.to_array(),
            });
        }
        if let Some(t) = first_out_of_range(&triangles, positions.len()) {
            return Err(Error::OutOfRange {
                what: "triangle vertex index",
                range: "less than the number of vertices",
                value: t.iter().copied().max().unwrap_or(0) as f32,
            });
        }
        Ok(Mesh {
            positions,
            normals,
            triangles,
            uvs: Vec::new(),
            uvs1: Vec::new(),
            colors: Vec::new(),
            tangents: Vec::new(),
            face_normals: None,
            vertex_form: VertexForm::default(),
        })
    }

    /// The mesh with vertex colours, one per vertex (linear RGB, finite and non-negative); an
    /// empty vector removes them.
    pub fn with_colors(mut self, colors: Vec<Color>) -> Result<Self, Error> {
        self.vertex_form.forget();
        if !colors.is_empty() && colors.len() != self.positions.len() {
            return Err(Error::OutOfRange {
                what: "number of vertex colours",
                range: "0 or the number of positions",
                value: colors.len() as f32,
            });
        }
        if let Some(c) = colors.iter().find(|c| !c.is_finite_non_negative()) {
            return Err(Error::InvalidColor {
                what: "vertex colour",
                value: c.to_array(),
            });
        }
        self.colors = colors;
        Ok(self)
    }

    /// Vertex colours; empty where the mesh has none.
    pub fn colors(&self) -> &[Color] {
        &self.colors
    }

    /// Tangents per vertex (`w`: the bitangent's sign, `B = w·(N × T)`); empty where the mesh
    /// has none (see [`Mesh::with_mikktspace_tangents`]).
    pub fn tangents(&self) -> &[Vec4] {
        &self.tangents
    }

    /// The mesh with a file's tangents, one per vertex (`xyz` finite, `w` the bitangent's
    /// sign: negative or not); an empty vector removes them. Like computed ones, they are
    /// dropped by the normals' functions.
    pub fn with_tangents(mut self, tangents: Vec<Vec4>) -> Result<Self, Error> {
        self.vertex_form.forget();
        if !tangents.is_empty() && tangents.len() != self.positions.len() {
            return Err(Error::OutOfRange {
                what: "number of tangents",
                range: "0 or the number of positions",
                value: tangents.len() as f32,
            });
        }
        if let Some(t) = tangents.iter().find(|t| !t.is_finite()) {
            return Err(Error::InvalidPosition {
                what: "tangent",
                value: [t.x, t.y, t.z],
            });
        }
        self.tangents = tangents;
        Ok(self)
    }

    /// The mesh with MikkTSpace tangents (the convention of Blender, three.js and glTF's
    /// normal maps), from its normals and texture coordinates; a vertex whose corners get
    /// different tangents is split. Without texture coordinates the mesh is returned as it is.
    /// The tangents are dropped by the normals' functions (compute them after the normals).
    pub fn with_mikktspace_tangents(&self) -> Mesh {
        if self.uvs.is_empty() || self.triangles.is_empty() {
            return self.clone();
        }
        if self.face_normals.is_some() {
            return self.with_vertex_normals().with_mikktspace_tangents();
        }
        struct Corners<'a> {
            m: &'a Mesh,
            out: Vec<[f32; 4]>,
        }
        impl mikktspace::Geometry for Corners<'_> {
            fn num_faces(&self) -> usize {
                self.m.triangles.len()
            }
            fn num_vertices_of_face(&self, _: usize) -> usize {
                3
            }
            fn position(&self, f: usize, v: usize) -> [f32; 3] {
                self.m.positions[self.m.triangles[f][v] as usize].to_array()
            }
            fn normal(&self, f: usize, v: usize) -> [f32; 3] {
                self.m.corner_normal(f, v).to_array()
            }
            fn tex_coord(&self, f: usize, v: usize) -> [f32; 2] {
                self.m.uvs[self.m.triangles[f][v] as usize].to_array()
            }
            fn set_tangent_encoded(&mut self, t: [f32; 4], f: usize, v: usize) {
                self.out[3 * f + v] = t;
            }
        }
        let mut c = Corners {
            m: self,
            out: vec![[0.0; 4]; 3 * self.triangles.len()],
        };
        if !mikktspace::generate_tangents(&mut c) {
            return self.clone();
        }
        let per_corner = c.out;
        // One vertex per (vertex, tangent).
        let mut m = Mesh::default();
        let mut dedup: FxHashMap<(u32, [u32; 4]), u32> = FxHashMap::default();
        for (f, t) in self.triangles.iter().enumerate() {
            let tri = std::array::from_fn(|k| {
                let (v, tangent) = (t[k], per_corner[3 * f + k]);
                let tangent = if tangent.iter().all(|x| x.is_finite()) {
                    tangent
                } else {
                    [0.0; 4]
                };
                *dedup.entry((v, tangent.map(f32::to_bits))).or_insert_with(|| {
                    let i = v as usize;
                    m.positions.push(self.positions[i]);
                    m.normals.push(self.normals[i]);
                    m.uvs.push(self.uvs[i]);
                    if let Some(uv) = self.uvs1.get(i) {
                        m.uvs1.push(*uv);
                    }
                    if let Some(c) = self.colors.get(i) {
                        m.colors.push(*c);
                    }
                    m.tangents.push(Vec4::from_array(tangent));
                    (m.positions.len() - 1) as u32
                })
            });
            m.triangles.push(tri);
        }
        m
    }

    /// The mesh with texture coordinates, one per vertex, finite (`v = 0` is the image's
    /// bottom, as OBJ's `vt` and OpenGL); an empty vector removes them.
    pub fn with_uvs(mut self, uvs: Vec<Vec2>) -> Result<Self, Error> {
        self.vertex_form.forget();
        self.uvs = self.checked_uvs(uvs)?;
        Ok(self)
    }

    /// The mesh with its vertices moved to `positions` (one per vertex, finite), every other
    /// attribute kept.
    pub fn with_positions(mut self, positions: Vec<Vec3>) -> Result<Self, Error> {
        if positions.len() != self.positions.len() {
            return Err(Error::OutOfRange {
                what: "number of positions",
                range: "the mesh's number of vertices",
                value: positions.len() as f32,
            });
        }
        self.positions = positions;
        self.with_positions_mapped(|p| p)
    }

    /// The mesh with each vertex moved to `f` of its position (which must stay finite), in
    /// place, every other attribute kept.
    pub fn with_positions_mapped(mut self, f: impl Fn(Vec3) -> Vec3) -> Result<Self, Error> {
        self.vertex_form.forget();
        for p in &mut self.positions {
            *p = f(*p);
        }
        match first_not_finite(&self.positions) {
            Some(p) => Err(Error::InvalidPosition {
                what: "mesh vertex",
                value: p.to_array(),
            }),
            None => Ok(self),
        }
    }

    /// The mesh with a second set of texture coordinates (glTF's `TEXCOORD_1`, read by the
    /// maps whose [`crate::TextureMap::set`] is 1), as [`Mesh::with_uvs`].
    pub fn with_uvs1(mut self, uvs: Vec<Vec2>) -> Result<Self, Error> {
        self.vertex_form.forget();
        self.uvs1 = self.checked_uvs(uvs)?;
        Ok(self)
    }

    fn checked_uvs(&self, uvs: Vec<Vec2>) -> Result<Vec<Vec2>, Error> {
        if !uvs.is_empty() && uvs.len() != self.positions.len() {
            return Err(Error::OutOfRange {
                what: "number of texture coordinates",
                range: "0 or the number of positions",
                value: uvs.len() as f32,
            });
        }
        if let Some(uv) = uvs.iter().find(|uv| !uv.is_finite()) {
            return Err(Error::InvalidPosition {
                what: "texture coordinate",
                value: [uv.x, uv.y, 0.0],
            });
        }
        Ok(uvs)
    }

    /// A mesh whose normals are then computed: area-weighted smooth normals over shared vertices.
    pub fn from_triangles(positions: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Result<Self, Error> {
        let normals = vec![Vec3::ZERO; positions.len()];
        Ok(Mesh::new(positions, normals, triangles)?.with_smooth_normals())
    }

    /// Vertex positions.
    pub fn positions(&self) -> &[Vec3] {
        &self.positions
    }
    /// Vertex normals (unit, or zero where undefined); empty for a mesh of
    /// [`Mesh::face_normals`] (see [`Mesh::corner_normal`], [`Mesh::with_vertex_normals`]).
    pub fn normals(&self) -> &[Vec3] {
        &self.normals
    }
    /// Triangles as vertex indices.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }
    /// Texture coordinates per vertex; empty where the mesh has none.
    pub fn uvs(&self) -> &[Vec2] {
        &self.uvs
    }
    /// Whether the mesh has texture coordinates.
    pub fn has_uvs(&self) -> bool {
        !self.uvs.is_empty()
    }
    /// The second set of texture coordinates per vertex; empty where the mesh has none.
    pub fn uvs1(&self) -> &[Vec2] {
        &self.uvs1
    }
    /// The three corners of triangle `t`.
    pub fn corners(&self, t: usize) -> [Vec3; 3] {
        self.triangles[t].map(|i| self.positions[i as usize])
    }

    /// Appends `other`'s vertices and triangles. Where only one of the two has texture
    /// coordinates, colours or tangents, the other's vertices get `(0, 0)`, white or none.
    pub fn append(&mut self, other: &Mesh) {
        self.vertex_form.forget();
        if self.face_normals.is_some() || other.face_normals.is_some() {
            *self = self.with_vertex_normals().clone();
            return self.append(other.with_vertex_normals());
        }
        let base = self.positions.len() as u32;
        let (mine, theirs) = (self.positions.len(), other.positions.len());
        append_attribute(&mut self.uvs, &other.uvs, mine, theirs, Vec2::ZERO);
        append_attribute(&mut self.uvs1, &other.uvs1, mine, theirs, Vec2::ZERO);
        append_attribute(&mut self.tangents, &other.tangents, mine, theirs, Vec4::ZERO);
        append_attribute(&mut self.colors, &other.colors, mine, theirs, Color::WHITE);
        self.positions.extend_from_slice(&other.positions);
        self.normals.extend_from_slice(&other.normals);
        self.triangles
            .extend(other.triangles.iter().map(|t| t.map(|i| i + base)));
    }

    /// Axis-aligned bounds `(min, max)`, `None` for an empty mesh.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let first = *self.positions.first()?;
        let fold = |(lo, hi): (Vec3, Vec3), p: &Vec3| (lo.min(*p), hi.max(*p));
        let ordered = || self.positions.iter().fold((first, first), fold);
        if first.is_nan() {
            return Some(ordered());
        }
        // Four vertices at a time in 4-lane vectors: the same bounds in another order of
        // comparisons (about a fifth of the instructions), except where a bound is zero (the
        // sign of that zero may depend on the order) or a coordinate NaN (which the ordered
        // fold lets through): the ordered fold gives those.
        let blocks = self.positions.chunks_exact(4);
        let rest = blocks.remainder();
        let start: [f32; 12] = bytemuck::cast([first; 4]);
        let (mut lo, mut hi) = (start, start);
        let mut nan = [false; 12];
        for block in blocks {
            let v: &[f32; 12] = bytemuck::cast_ref(<&[Vec3; 4]>::try_from(block).expect("4 vertices"));
            for i in 0..12 {
                lo[i] = if v[i] < lo[i] { v[i] } else { lo[i] };
                hi[i] = if v[i] > hi[i] { v[i] } else { hi[i] };
                nan[i] |= v[i].is_nan();
            }
        }
        // Lane i holds coordinate i % 3.
        let (mut l, mut h) = rest.iter().fold((first, first), fold);
        for i in 0..12 {
            l[i % 3] = l[i % 3].min(lo[i]);
            h[i % 3] = h[i % 3].max(hi[i]);
        }
        let exact = !(nan.contains(&true) || rest.iter().any(|p| p.is_nan()));
        if !exact || l.cmpeq(Vec3::ZERO).any() || h.cmpeq(Vec3::ZERO).any() {
            return Some(ordered());
        }
        Some((l, h))
    }

    /// The mesh in another space: positions by `m`, normals by the inverse
    /// transpose of its upper 3×3, renormalised; a mirroring `m` (negative
    /// determinant) reverses the triangles so they stay counter-clockwise.
    pub fn transformed(&self, m: &Mat4) -> Mesh {
        self.clone().into_transformed(m)
    }

    /// [`Mesh::transformed`] in place: the same arithmetic, without a copy of the mesh (a
    /// loaded model's arrays are megabytes).
    pub fn into_transformed(mut self, m: &Mat4) -> Mesh {
        self.vertex_form.forget();
        let nm = Mat3::from_mat4(*m).inverse().transpose();
        let linear = Mat3::from_mat4(*m);
        let flip = linear.determinant() < 0.0;
        for p in &mut self.positions {
            *p = m.transform_point3(*p);
        }
        // (Four at a time: the same bits as `(nm * n).normalize_or_zero()`.)
        facets::normals_through(&mut self.normals, &nm);
        if let Some(faces) = &mut self.face_normals {
            facets::normals_through(faces, &nm);
        }
        if flip {
            for t in &mut self.triangles {
                t.swap(1, 2);
            }
        }
        // A tangent is a direction in the surface: transformed by `m` itself; a mirror flips
        // the bitangent.
        for t in &mut self.tangents {
            let d = (linear * t.truncate()).normalize_or_zero();
            *t = d.extend(if flip { -t.w } else { t.w });
        }
        self
    }

    /// Flat normals: every triangle gets its own three vertices carrying its facet normal.
    pub fn with_flat_normals(&self) -> Mesh {
        let mut normals = vec![Vec3::ZERO; 3 * self.triangles.len()];
        for (n, t) in normals.chunks_exact_mut(3).zip(&self.triangles) {
            let [a, b, c] = t.map(|i| self.positions[i as usize]);
            n.fill(facet_normal(a, b, c));
        }
        self.unshared(normals, false)
    }

    /// The mesh with three vertices of its own a triangle, each with its corner's position,
    /// coordinates and colour (and tangent, where `tangents`), carrying `normals` (three a
    /// triangle, in its corners' order).
    fn unshared(&self, normals: Vec<Vec3>, tangents: bool) -> Mesh {
        Mesh {
            positions: per_corner(&self.positions, &self.triangles),
            normals,
            triangles: (0..self.triangles.len() as u32)
                .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
                .collect(),
            uvs: per_corner(&self.uvs, &self.triangles),
            uvs1: per_corner(&self.uvs1, &self.triangles),
            colors: per_corner(&self.colors, &self.triangles),
            tangents: if tangents {
                per_corner(&self.tangents, &self.triangles)
            } else {
                Vec::new()
            },
            face_normals: None,
            vertex_form: VertexForm::default(),
        }
    }

    /// `self.with_flat_normals().into_transformed(m)` with its vertices kept shared: each
    /// position transformed once, each triangle's facet normal computed and transformed once
    /// and kept per triangle ([`Mesh::face_normals`]). Its corners are those of the two-step
    /// mesh bit for bit ([`Mesh::with_vertex_normals`] gives that mesh's form); no arrays of
    /// three vertices a triangle are made. For a model without normals (a glTF's flat ones)
    /// placed in the scene.
    pub fn flat_transformed(mut self, m: &Mat4, join: &impl Join) -> Mesh {
        self.vertex_form.forget();
        if self.triangles.is_empty() {
            return self.with_flat_normals().into_transformed(m);
        }
        let nm = Mat3::from_mat4(*m).inverse().transpose();
        let flip = Mat3::from_mat4(*m).determinant() < 0.0;
        let mut faces = vec![Vec3::ZERO; self.triangles.len()];
        let positions = &self.positions;
        let fill = |triangles: &[[u32; 3]], out: &mut [Vec3]| {
            facets::unit_normals_through(positions, triangles, &nm, out);
        };
        // A large mesh's facets in two halves, which `join` may compute side by side.
        let half = self.triangles.len() / 2;
        if half >= FLAT_HALF_MIN {
            let (t0, t1) = self.triangles.split_at(half);
            let (f0, f1) = faces.split_at_mut(half);
            join.join(|| fill(t0, f0), || fill(t1, f1));
        } else {
            fill(&self.triangles, &mut faces);
        }
        for p in &mut self.positions {
            *p = m.transform_point3(*p);
        }
        // A mirror reverses each triangle, as `into_transformed` does.
        if flip {
            for t in &mut self.triangles {
                t.swap(1, 2);
            }
        }
        Mesh {
            normals: Vec::new(),
            tangents: Vec::new(),
            face_normals: Some(faces),
            vertex_form: VertexForm::default(),
            ..self
        }
    }

    /// A flat mesh's normals, one per triangle ([`Mesh::flat_transformed`]); `None` where the
    /// normals are per vertex ([`Mesh::normals`]).
    pub fn face_normals(&self) -> Option<&[Vec3]> {
        self.face_normals.as_deref()
    }

    /// The normal at corner `k` of triangle `t`: its vertex's, or the triangle's own.
    pub fn corner_normal(&self, t: usize, k: usize) -> Vec3 {
        match &self.face_normals {
            Some(f) => f[t],
            None => self.normals[self.triangles[t][k] as usize],
        }
    }

    /// The mesh with one normal per vertex: itself, or for a mesh of [`Mesh::face_normals`]
    /// three vertices a triangle carrying its normal (as [`Mesh::with_flat_normals`] makes
    /// them), for the users of per-vertex normals (lighting per vertex, the GPU's buffers).
    pub fn with_vertex_normals(&self) -> &Mesh {
        let Some(faces) = &self.face_normals else {
            return self;
        };
        self.vertex_form.0.get_or_init(|| {
            let mut normals = vec![Vec3::ZERO; 3 * faces.len()];
            for (n, f) in normals.chunks_exact_mut(3).zip(faces) {
                n.fill(*f);
            }
            Box::new(self.unshared(normals, true))
        })
    }

    /// Vertices at the same position merged (exact match), so that normals
    /// can be averaged across faces that a file gave separate vertices. Texture coordinates
    /// are dropped (the normals' functions keep them, see [`Mesh::with_smooth_normals`]).
    pub fn welded(&self) -> Mesh {
        self.weld().0
    }

    /// [`Mesh::welded`] and, per vertex of `self`, its vertex in the welded mesh.
    fn weld(&self) -> (Mesh, Vec<u32>) {
        let (positions, remap) = weld_positions(&self.positions);
        let triangles = self.triangles.iter().map(|t| t.map(|i| remap[i as usize])).collect();
        let normals = vec![Vec3::ZERO; positions.len()];
        let mesh = Mesh {
            positions,
            normals,
            triangles,
            uvs: Vec::new(),
            uvs1: Vec::new(),
            colors: Vec::new(),
            tangents: Vec::new(),
            face_normals: None,
            vertex_form: VertexForm::default(),
        };
        (mesh, remap)
    }

    /// Smooth vertex normals (seed 001: "add the facet normals of all facets
    /// incident to a vertex, and normalize"), weighted by facet area: the sum
    /// of the unnormalised cross products `(p2 − p1) × (p3 − p1)`. Vertices
    /// at the same position are merged first; a mesh with texture coordinates keeps its own
    /// vertices (so seams keep their coordinates), each with its position's normal.
    pub fn with_smooth_normals(&self) -> Mesh {
        let (mut m, remap) = self.weld();
        let mut acc = vec![Vec3::ZERO; m.positions.len()];
        for t in &m.triangles {
            let [a, b, c] = t.map(|i| m.positions[i as usize]);
            let w = (b - a).cross(c - a);
            for &i in t {
                acc[i as usize] += w;
            }
        }
        m.normals = acc.into_iter().map(|n| n.normalize_or_zero()).collect();
        if self.uvs.is_empty() && self.uvs1.is_empty() && self.colors.is_empty() {
            return m;
        }
        Mesh {
            positions: self.positions.clone(),
            normals: remap.iter().map(|&r| m.normals[r as usize]).collect(),
            triangles: self.triangles.clone(),
            uvs: self.uvs.clone(),
            uvs1: self.uvs1.clone(),
            colors: self.colors.clone(),
            tangents: Vec::new(),
            face_normals: None,
            vertex_form: VertexForm::default(),
        }
    }

    /// Normals smoothed only across edges where the faces meet at less than
    /// `crease_deg` degrees; vertices are split at harder edges. Each corner's
    /// normal is the area-weighted sum of the facet normals of the faces
    /// around its vertex that are within the crease angle of its own face.
    ///
    /// Where a vertex has more than 64 face directions (a cone's apex, a fan), its faces are
    /// grouped instead across the edges they share at the vertex, where those faces meet within
    /// the crease angle (as Blender's auto smooth), so that the work stays linear in the faces:
    /// faces joined by a chain of soft edges share one normal there, even where the first and
    /// the last of the chain are further apart than the crease angle.
    pub fn with_crease_normals(&self, crease_deg: f32) -> Mesh {
        self.crease_normals(crease_deg).0
    }

    /// [`Mesh::with_crease_normals`] of the mesh with each vertex moved to `f` of its position
    /// (which must stay finite, as [`Mesh::with_positions_mapped`]): the positions mapped once,
    /// straight into the new mesh's, and the mesh's own normals never copied.
    pub fn crease_normals_mapped(&self, f: impl Fn(Vec3) -> Vec3, crease_deg: f32) -> Result<Mesh, Error> {
        // (Room for the vertices a crease splits to go after them, which costs nothing until
        // used: grown, the array would be copied.)
        let mut positions = Vec::with_capacity(self.positions.len() + self.positions.len() / 4);
        positions.extend(self.positions.iter().map(|&p| f(p)));
        if let Some(p) = first_not_finite(&positions) {
            return Err(Error::InvalidPosition {
                what: "mesh vertex",
                value: p.to_array(),
            });
        }
        Ok(self
            .crease_of(positions.into(), (&self.triangles[..]).into(), crease_deg)
            .0)
    }

    /// [`Mesh::with_crease_normals`] of a mesh no longer needed: where its positions are all
    /// distinct and it has no other attribute, its arrays become the new mesh's (no copy).
    pub fn into_crease_normals(mut self, crease_deg: f32) -> Mesh {
        let positions = std::mem::take(&mut self.positions);
        let triangles = std::mem::take(&mut self.triangles);
        self.crease_of(positions.into(), triangles.into(), crease_deg).0
    }
}

/// Appends a per-vertex attribute: `theirs` (for `n_theirs` vertices) after `mine` (for
/// `n_mine`), where either has it, the other's vertices given `fill`.
fn append_attribute<T: Clone>(mine: &mut Vec<T>, theirs: &[T], n_mine: usize, n_theirs: usize, fill: T) {
    if mine.is_empty() && theirs.is_empty() {
        return;
    }
    mine.resize(n_mine, fill.clone());
    if theirs.is_empty() {
        mine.resize(n_mine + n_theirs, fill);
    } else {
        mine.extend_from_slice(theirs);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    proptest::proptest! {
        /// The first index at or past `n`, as the plain search finds it, for any indices and
        /// counts (2³¹ and past included).
        #[test]
        fn index_at_least_is_the_plain_search(
            indices in proptest::collection::vec(proptest::prop_oneof![0u32..40, proptest::prelude::any::<u32>()], 0..40),
            n in proptest::prop_oneof![0usize..45, proptest::strategy::Just(0x7fff_ffff), proptest::strategy::Just(0x8000_0000), proptest::strategy::Just(0x8000_0001), proptest::strategy::Just(1usize << 33)],
        ) {
            let want = indices.iter().position(|&i| i as usize >= n);
            proptest::prop_assert_eq!(index_at_least(&indices, n), want);
        }
    }

    /// The vectorised checks find what a plain search finds: the first point with a NaN or an
    /// infinity in any coordinate (none in a finite mesh, the largest finite values included),
    /// and the first triangle with an index at or past the count.
    #[test]
    fn checks_find_the_first_bad_element() {
        let points: Vec<Vec3> = (0..100).map(|i| Vec3::new(i as f32, -(i as f32), f32::MAX)).collect();
        assert_eq!(first_not_finite(&points), None);
        for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            for (at, lane) in [(0, 0), (37, 1), (99, 2)] {
                let mut p = points.clone();
                p[at][lane] = bad;
                p[at + (99 - at) / 2][2 - lane] = bad;
                let want = p.iter().position(|q| !q.is_finite());
                assert_eq!(
                    first_not_finite(&p).map(|q| q as *const Vec3),
                    want.map(|i| &p[i] as *const Vec3)
                );
            }
        }
        let tris: Vec<[u32; 3]> = (0..50u32).map(|i| [i, i + 1, i + 2]).collect();
        assert_eq!(first_out_of_range(&tris, 52), None);
        assert_eq!(first_out_of_range(&tris, 51), Some(&[49, 50, 51]));
        assert_eq!(first_out_of_range(&tris, 10), Some(&[8, 9, 10]));
        assert_eq!(first_out_of_range(&[], 0), None);
        assert_eq!(first_out_of_range(&[[0, 0, 0]], 0), Some(&[0, 0, 0]));
    }

    /// A unit square in z = 0 as two triangles, plus a third triangle folded up by 90° along x = 1.
    fn folded() -> Mesh {
        let p = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(1.0, 0.0, -1.0),
        ];
        Mesh::from_triangles(p, vec![[0, 1, 2], [0, 2, 3], [1, 4, 2]]).unwrap()
    }

    #[test]
    fn facet_normal_is_ccw_cross_product() {
        // (1,0,0) × (0,1,0) = (0,0,1)
        assert_eq!(facet_normal(Vec3::ZERO, Vec3::X, Vec3::Y), Vec3::Z);
        assert_eq!(facet_normal(Vec3::ZERO, Vec3::Y, Vec3::X), -Vec3::Z);
        assert_eq!(facet_normal(Vec3::ZERO, Vec3::X, Vec3::X * 2.0), Vec3::ZERO);
    }

    #[test]
    fn smooth_normals_are_area_weighted() {
        let m = folded();
        // Vertex 1 touches triangle 0 (normal +z, area 1/2) and triangle 2 (1,0,0)-(1,0,-1)-(1,1,0):
        // (0,0,−1) × (0,1,0) = (1,0,0), area 1/2. Sum (1,0,1)/√2.
        let n = m.normals()[1];
        let s = core::f32::consts::FRAC_1_SQRT_2;
        assert!((n - Vec3::new(s, 0.0, s)).length() < 1e-6, "{n}");
        // Vertex 0 only touches +z faces.
        assert_eq!(m.normals()[0], Vec3::Z);
    }

    #[test]
    fn crease_splits_hard_edges() {
        let m = folded().with_crease_normals(60.0);
        // The 90° fold is harder than 60°: every corner keeps its own face's normal.
        for (t, tri) in m.triangles().iter().enumerate() {
            let [a, b, c] = m.corners(t);
            let f = facet_normal(a, b, c);
            for &i in tri {
                assert!((m.normals()[i as usize] - f).length() < 1e-6);
            }
        }
        assert_eq!(m.positions().len(), 7); // vertices 1 and 2 (on the fold) split in two
        // With a crease of 100°, it is smooth again.
        let s = folded().with_crease_normals(100.0);
        assert_eq!(s.positions().len(), 5);
    }

    /// The positions mapped then the crease normals, in one step: the two steps' mesh bit for
    /// bit (with and without texture coordinates), and a mapping to a non-finite position
    /// refused as `with_positions_mapped` refuses it.
    #[test]
    fn crease_normals_of_mapped_positions() {
        let move_it = |p: Vec3| (p - Vec3::new(0.25, -3.0, 1e-3)) * 1.7;
        let sphere = crate::primitives::sphere(12);
        let uvs: Vec<Vec2> = (0..sphere.positions().len())
            .map(|i| Vec2::new(i as f32, 0.5))
            .collect();
        for m in [folded(), sphere.clone(), sphere.with_uvs(uvs).unwrap()] {
            let two_steps = m
                .clone()
                .with_positions_mapped(move_it)
                .unwrap()
                .with_crease_normals(60.0);
            let one = m.crease_normals_mapped(move_it, 60.0).unwrap();
            assert_eq!(format!("{one:?}"), format!("{two_steps:?}"));
        }
        let far = |p: Vec3| p * f32::MAX * 4.0;
        assert_eq!(
            folded().crease_normals_mapped(far, 60.0).err(),
            folded().with_positions_mapped(far).err()
        );
    }

    #[test]
    fn flat_normals_unshare_vertices() {
        let m = folded().with_flat_normals();
        assert_eq!(m.positions().len(), 9);
        assert_eq!(m.normals()[0], Vec3::Z);
        assert_eq!(m.normals()[6], Vec3::X);
        // Each corner its vertex's position and texture coordinates, triangle t on vertices
        // 3t, 3t + 1, 3t + 2.
        let base = folded();
        let uvs: Vec<Vec2> = (0..base.positions().len()).map(|i| Vec2::new(i as f32, 0.5)).collect();
        let m = base.clone().with_uvs(uvs.clone()).unwrap().with_flat_normals();
        for (t, tri) in base.triangles().iter().enumerate() {
            let t3 = 3 * t as u32;
            assert_eq!(m.triangles()[t], [t3, t3 + 1, t3 + 2]);
            for k in 0..3 {
                assert_eq!(m.positions()[3 * t + k], base.positions()[tri[k] as usize]);
                assert_eq!(m.uvs()[3 * t + k], uvs[tri[k] as usize]);
            }
        }
        assert!(m.colors().is_empty() && m.tangents().is_empty());
    }

    /// The blocked bounds are the vertex-by-vertex fold's, bit for bit: meshes of 1 to 40
    /// vertices (every remainder of the blocks) from a small set of values, zeros of both signs
    /// among them, and meshes whose first vertex or others have a NaN or an infinity.
    #[test]
    fn bounds_are_the_ordered_folds() {
        let values = [-0.0f32, 0.0, 1.5, -2.25, 3.0e7, -1e-30, 7.0, f32::MAX, -f32::MAX];
        let mut seed = 0x2545_f491_u32;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 17;
            seed ^= seed << 5;
            values[seed as usize % values.len()]
        };
        let fold = |p: &[Vec3]| p.iter().fold((p[0], p[0]), |(lo, hi), &q| (lo.min(q), hi.max(q)));
        let bits = |(a, b): (Vec3, Vec3)| (a.to_array().map(f32::to_bits), b.to_array().map(f32::to_bits));
        let mesh = |positions: Vec<Vec3>| Mesh {
            normals: vec![Vec3::ZERO; positions.len()],
            positions,
            ..Mesh::default()
        };
        for round in 0..400 {
            let n = 1 + round % 40;
            let mut p: Vec<Vec3> = (0..n).map(|_| Vec3::new(next(), next(), next())).collect();
            if round % 7 == 0 {
                p[round % n].y = f32::NAN;
            }
            if round % 11 == 0 {
                p[(round / 11) % n].z = f32::INFINITY;
            }
            let want = fold(&p);
            assert_eq!(bits(mesh(p.clone()).bounds().unwrap()), bits(want), "{p:?}");
        }
        assert_eq!(Mesh::default().bounds(), None);
    }

    proptest::proptest! {
        /// The same on random triangles (coordinates from tiny to near f32's largest, so that
        /// some facets are zero and some lengths overflow), for a rotation with a non-uniform
        /// scale.
        #[test]
        fn flat_transformed_is_flat_then_transformed_on_any_triangles(
            points in proptest::collection::vec(
                (proptest::prop_oneof![-1e3f32..1e3, -1e-20f32..1e-20, -3e37f32..3e37], -2f32..2.0, -2f32..2.0),
                3..40,
            ),
            picks in proptest::collection::vec((0usize..40, 0usize..40, 0usize..40), 1..40),
            angle in -3f32..3.0,
        ) {
            let n = points.len();
            let p: Vec<Vec3> = points.iter().map(|&(x, y, z)| Vec3::new(x, y, z * x.abs().max(1.0))).collect();
            let t: Vec<[u32; 3]> = picks.iter().map(|&(a, b, c)| [a % n, b % n, c % n].map(|i| i as u32)).collect();
            let mesh = Mesh::from_triangles(p, t).unwrap();
            let m = Mat4::from_scale_rotation_translation(
                Vec3::new(2.0, 0.5, 1.3),
                glam::Quat::from_euler(glam::EulerRot::ZYX, angle, 0.4, -angle),
                Vec3::new(1.0, -2.0, 3.0),
            );
            let b = mesh.with_flat_normals().into_transformed(&m);
            let a = mesh.flat_transformed(&m, &crate::join::InTurn);
            proptest::prop_assert_eq!(corner_bits(&a), corner_bits(&b));
            proptest::prop_assert_eq!(corner_bits(a.with_vertex_normals()), corner_bits(&b));
        }
    }

    /// The one-pass flat placement gives the two-step one's bits: positions, normals,
    /// triangles (a mirror reversing them), texture coordinates and colours, for a rotation
    /// with a non-uniform scale and a move, a mirror, and the identity.
    #[test]
    fn flat_transformed_is_flat_then_transformed() {
        let base = folded();
        let n = base.positions().len();
        let uvs: Vec<Vec2> = (0..n).map(|i| Vec2::new(i as f32 * 0.3, 0.7)).collect();
        let colors: Vec<Color> = (0..n).map(|i| Color::new(0.1 * i as f32, 0.5, 1.0)).collect();
        // A degenerate triangle too (its normal zero either way).
        let mut p = base.positions().to_vec();
        p.push(Vec3::new(2.0, 2.0, 2.0));
        let mut t = base.triangles().to_vec();
        t.push([0, 5, 5]);
        let shapes = [
            Mesh::from_triangles(p, t).unwrap(),
            base.clone().with_uvs(uvs).unwrap().with_colors(colors).unwrap(),
        ];
        let moves = [
            Mat4::IDENTITY,
            Mat4::from_scale_rotation_translation(
                Vec3::new(2.0, 0.5, 1.3),
                glam::Quat::from_euler(glam::EulerRot::ZYX, 0.3, -1.1, 0.7),
                Vec3::new(-4.0, 1.5, 1e3),
            ),
            Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0)),
        ];
        // Large enough for two halves (at least `FLAT_HALF_MIN` triangles each), drawn in turn
        // and in the other order.
        struct Reversed;
        impl Join for Reversed {
            fn join<A, B: Send>(&self, a: impl FnOnce() -> A, b: impl FnOnce() -> B + Send) -> (A, B) {
                let b = b();
                (a(), b)
            }
        }
        let large = crate::primitives::sphere(160);
        assert!(large.triangles().len() >= 2 * FLAT_HALF_MIN);
        let shapes = [&shapes[..], &[large]].concat();
        for mesh in &shapes {
            for m in &moves {
                let b = mesh.with_flat_normals().into_transformed(m);
                let (a, reversed) = (
                    mesh.clone().flat_transformed(m, &crate::join::InTurn),
                    mesh.clone().flat_transformed(m, &Reversed),
                );
                assert_eq!(corner_bits(&a), corner_bits(&b));
                assert_eq!(corner_bits(&reversed), corner_bits(&b));
                assert_eq!(corner_bits(a.with_vertex_normals()), corner_bits(&b));
                // The vertices stay shared, the normals are the triangles'.
                assert_eq!(a.positions().len(), mesh.positions().len());
                assert!(a.normals().is_empty());
                assert_eq!(a.face_normals().map(<[Vec3]>::len), Some(mesh.triangles().len()));
                assert_eq!(a.uvs().len(), mesh.uvs().len());
                assert!(a.tangents().is_empty() && a.uvs1().is_empty());
            }
        }
    }

    /// Per corner of every triangle in turn: its position's, normal's, texture coordinates'
    /// and colour's bits (a mesh's drawing, whatever its vertices' numbering).
    fn corner_bits(m: &Mesh) -> Vec<Vec<u32>> {
        let mut out = Vec::new();
        for (t, tri) in m.triangles().iter().enumerate() {
            for (k, &i) in tri.iter().enumerate() {
                let i = i as usize;
                let mut c: Vec<f32> = m.positions()[i].to_array().to_vec();
                c.extend(m.corner_normal(t, k).to_array());
                c.extend(m.uvs().get(i).map_or([0.5; 2], |u| u.to_array()));
                c.extend(m.uvs1().get(i).map_or([0.5; 2], |u| u.to_array()));
                c.extend(m.colors().get(i).map_or([0.5; 3], |c| c.to_array()));
                out.push(c.into_iter().map(f32::to_bits).collect());
            }
        }
        out
    }

    /// A flat mesh's normals moved again are those of its vertex form moved, and an appended
    /// mesh of either form draws the same corners.
    #[test]
    fn face_normals_transform_and_append_as_vertex_normals() {
        let flat = folded().flat_transformed(&Mat4::from_rotation_x(0.3), &crate::join::InTurn);
        let m = Mat4::from_scale(Vec3::new(-2.0, 1.0, 0.5));
        assert_eq!(
            corner_bits(&flat.clone().into_transformed(&m)),
            corner_bits(&flat.with_vertex_normals().clone().into_transformed(&m))
        );
        let mut both = folded();
        both.append(&flat);
        let mut want = folded();
        want.append(flat.with_vertex_normals());
        assert_eq!(corner_bits(&both), corner_bits(&want));
        assert!(both.face_normals().is_none());
    }

    /// A flat mesh's vertex form is made once, and a changed mesh (moved, given colours,
    /// appended to) makes it again from what it now is; a copy starts without it.
    #[test]
    fn vertex_form_is_kept_until_the_mesh_changes() {
        let flat = folded().flat_transformed(&Mat4::from_rotation_x(0.3), &crate::join::InTurn);
        let first: *const Mesh = flat.with_vertex_normals();
        assert!(std::ptr::eq(first, flat.with_vertex_normals()));
        assert_eq!(corner_bits(flat.with_vertex_normals()), corner_bits(&flat));
        let copy = flat.clone();
        assert!(!std::ptr::eq(first, copy.with_vertex_normals()));
        let moved = flat.into_transformed(&Mat4::from_translation(Vec3::new(1.0, 2.0, 3.0)));
        assert_eq!(corner_bits(moved.with_vertex_normals()), corner_bits(&moved));
        let n = moved.positions().len();
        let coloured = moved.with_colors(vec![Color::new(0.25, 0.5, 1.0); n]).unwrap();
        assert_eq!(corner_bits(coloured.with_vertex_normals()), corner_bits(&coloured));
        let mut grown = copy.clone();
        let _ = grown.with_vertex_normals();
        grown.append(&folded());
        assert_eq!(corner_bits(grown.with_vertex_normals()), corner_bits(&grown));
        assert_eq!(grown.triangles().len(), 2 * copy.triangles().len());
        // Equal meshes stay equal whether or not their form was made.
        assert_eq!(copy, copy.clone());
    }

    /// New positions replace the old one for one, every other attribute kept (a flat mesh's
    /// triangle normals as they were); a wrong count or a position not finite is refused.
    #[test]
    fn with_positions_moves_vertices_and_keeps_the_rest() {
        let uvs: Vec<Vec2> = (0..5).map(|i| Vec2::new(i as f32 * 0.25, 0.5)).collect();
        let m = folded().with_uvs(uvs.clone()).unwrap();
        let moved: Vec<Vec3> = m.positions().iter().map(|p| *p * 2.0 + Vec3::X).collect();
        let got = m.clone().with_positions(moved.clone()).unwrap();
        assert_eq!(got.positions(), &moved[..]);
        assert_eq!(
            (got.normals(), got.triangles(), got.uvs()),
            (m.normals(), m.triangles(), &uvs[..])
        );
        let flat = folded().flat_transformed(&Mat4::IDENTITY, &crate::join::InTurn);
        let got = flat.clone().with_positions(moved.clone()).unwrap();
        assert_eq!(got.face_normals(), flat.face_normals());
        assert!(matches!(
            m.clone().with_positions(moved[..4].to_vec()),
            Err(Error::OutOfRange { what: "number of positions", value, .. }) if value == 4.0
        ));
        let mut bad = moved;
        bad[3].y = f32::NAN;
        assert!(matches!(
            m.with_positions(bad),
            Err(Error::InvalidPosition {
                what: "mesh vertex",
                ..
            })
        ));
    }

    #[test]
    fn transform_normals_by_inverse_transpose() {
        // Non-uniform scale (2, 1, 1) of a plane with normal (1,1,0)/√2: new normal ∝ (1/2, 1, 0).
        let s = core::f32::consts::FRAC_1_SQRT_2;
        let m = Mesh::new(vec![Vec3::ZERO], vec![Vec3::new(s, s, 0.0)], vec![]).unwrap();
        let t = m.transformed(&Mat4::from_scale(Vec3::new(2.0, 1.0, 1.0)));
        assert!((t.normals()[0] - Vec3::new(0.5, 1.0, 0.0).normalize()).length() < 1e-6);
        // A mirror keeps triangles counter-clockwise seen from the normal side.
        let f = folded().transformed(&Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0)));
        let [a, b, c] = f.corners(0);
        assert!(facet_normal(a, b, c).dot(f.normals()[0]) > 0.0);
    }

    #[test]
    fn rejects_bad_indices() {
        assert!(Mesh::new(vec![Vec3::ZERO], vec![Vec3::Z], vec![[0, 0, 1]]).is_err());
        assert!(Mesh::new(vec![Vec3::NAN], vec![Vec3::Z], vec![]).is_err());
        assert!(Mesh::new(vec![Vec3::ZERO], vec![], vec![]).is_err());
    }
}
