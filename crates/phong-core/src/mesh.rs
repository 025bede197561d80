//! Indexed triangle meshes and their normals (seed 001: facet normals from
//! the cross product, vertex normals from the facet normals or from the
//! surface's formula).

use crate::{Color, Error};
use glam::{Mat3, Mat4, Vec2, Vec3, Vec4};
use rustc_hash::FxHashMap;
use std::collections::HashMap;

/// An indexed triangle mesh with one normal per vertex and, optionally, texture coordinates
/// per vertex. Triangles are counter-clockwise seen from the side their normals point to.
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
}

/// The facet normal of seed 001: `normalize((p2 − p1) × (p3 − p1))`; zero for a degenerate triangle.
#[inline]
pub fn facet_normal(p1: Vec3, p2: Vec3, p3: Vec3) -> Vec3 {
    (p2 - p1).cross(p3 - p1).normalize_or_zero()
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
        if let Some(p) = positions.iter().find(|p| !p.is_finite()) {
            return Err(Error::InvalidPosition {
                what: "mesh vertex",
                value: p.to_array(),
            });
        }
        let n = positions.len() as u64;
        if let Some(t) = triangles.iter().find(|t| t.iter().any(|&i| u64::from(i) >= n)) {
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
        })
    }

    /// The mesh with vertex colours, one per vertex (linear RGB, finite and non-negative); an
    /// empty vector removes them.
    pub fn with_colors(mut self, colors: Vec<Color>) -> Result<Self, Error> {
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
                self.m.normals[self.m.triangles[f][v] as usize].to_array()
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
        self.uvs = self.checked_uvs(uvs)?;
        Ok(self)
    }

    /// The mesh with its vertices moved to `positions` (one per vertex, finite), every other
    /// attribute kept.
    pub fn with_positions(mut self, positions: Vec<Vec3>) -> Result<Self, Error> {
        let moved = Mesh::new(positions, std::mem::take(&mut self.normals), Vec::new())?;
        if moved.positions.len() != self.positions.len() {
            return Err(Error::OutOfRange {
                what: "number of positions",
                range: "the mesh's number of vertices",
                value: moved.positions.len() as f32,
            });
        }
        self.positions = moved.positions;
        self.normals = moved.normals;
        Ok(self)
    }

    /// The mesh with a second set of texture coordinates (glTF's `TEXCOORD_1`, read by the
    /// maps whose [`crate::TextureMap::set`] is 1), as [`Mesh::with_uvs`].
    pub fn with_uvs1(mut self, uvs: Vec<Vec2>) -> Result<Self, Error> {
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
    /// Vertex normals (unit, or zero where undefined).
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
        Some(
            self.positions
                .iter()
                .fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p))),
        )
    }

    /// The mesh in another space: positions by `m`, normals by the inverse
    /// transpose of its upper 3×3, renormalised; a mirroring `m` (negative
    /// determinant) reverses the triangles so they stay counter-clockwise.
    pub fn transformed(&self, m: &Mat4) -> Mesh {
        let nm = Mat3::from_mat4(*m).inverse().transpose();
        let flip = Mat3::from_mat4(*m).determinant() < 0.0;
        Mesh {
            positions: self.positions.iter().map(|&p| m.transform_point3(p)).collect(),
            normals: self.normals.iter().map(|&n| (nm * n).normalize_or_zero()).collect(),
            triangles: if flip {
                self.triangles.iter().map(|&[a, b, c]| [a, c, b]).collect()
            } else {
                self.triangles.clone()
            },
            uvs: self.uvs.clone(),
            uvs1: self.uvs1.clone(),
            colors: self.colors.clone(),
            // A tangent is a direction in the surface: transformed by `m` itself; a mirror
            // flips the bitangent.
            tangents: self
                .tangents
                .iter()
                .map(|t| {
                    let d = (Mat3::from_mat4(*m) * t.truncate()).normalize_or_zero();
                    d.extend(if flip { -t.w } else { t.w })
                })
                .collect(),
        }
    }

    /// Flat normals: every triangle gets its own three vertices carrying its facet normal.
    pub fn with_flat_normals(&self) -> Mesh {
        let mut positions = Vec::with_capacity(self.triangles.len() * 3);
        let mut normals = Vec::with_capacity(self.triangles.len() * 3);
        let mut triangles = Vec::with_capacity(self.triangles.len());
        let mut uvs = Vec::new();
        let mut uvs1 = Vec::new();
        let mut colors = Vec::new();
        for (t, corners) in self.triangles.iter().enumerate() {
            let [a, b, c] = self.corners(t);
            let n = facet_normal(a, b, c);
            let i = positions.len() as u32;
            positions.extend([a, b, c]);
            normals.extend([n; 3]);
            triangles.push([i, i + 1, i + 2]);
            if !self.uvs.is_empty() {
                uvs.extend(corners.map(|k| self.uvs[k as usize]));
            }
            if !self.uvs1.is_empty() {
                uvs1.extend(corners.map(|k| self.uvs1[k as usize]));
            }
            if !self.colors.is_empty() {
                colors.extend(corners.map(|k| self.colors[k as usize]));
            }
        }
        Mesh {
            positions,
            normals,
            triangles,
            uvs,
            uvs1,
            colors,
            tangents: Vec::new(),
        }
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

    /// [`Mesh::with_crease_normals`], and the work it did (facet comparisons), for the test
    /// that it is linear.
    fn crease_normals(&self, crease_deg: f32) -> (Mesh, u64) {
        let (positions, remap) = weld_positions(&self.positions);
        let tris: Vec<[u32; 3]> = self.triangles.iter().map(|t| t.map(|i| remap[i as usize])).collect();
        let cos_crease = crease_deg.to_radians().cos();
        let (facet, unit) = facets_of(&positions, &tris);
        // The shortcut's half angle, less 0.02° against f32's rounding of the dot products
        // (whose error in angle is under 0.001° for creases in [1°, 179°]), so that it gives
        // what the loop would.
        let cos_half = (1.0..=179.0)
            .contains(&crease_deg)
            .then(|| ((crease_deg - 0.02) * 0.5).to_radians().cos());
        // Where corners carry nothing but their normal, a vertex of one normal is one vertex.
        let plain = self.uvs.is_empty() && self.uvs1.is_empty() && self.colors.is_empty();
        let n = positions.len();
        // Most vertices take `Rule::Same`, found in two passes over the faces; the faces
        // around each vertex and the other rules only for the rest.
        let (same, count) = same_normals(n, &tris, &facet, &unit, cos_half);
        let mut work = 6 * tris.len() as u64;
        // Per vertex of the rest, its rule's index (u32::MAX: none).
        let mut slot = vec![u32::MAX; n];
        let mut rest = 0u32;
        for ((s, m), &c) in slot.iter_mut().zip(&same).zip(&count) {
            if *m == Vec3::ZERO && c > 0 {
                *s = rest;
                rest += 1;
            }
        }
        let around = (rest > 0).then(|| Around::new(&slot, &count, rest as usize, &tris));
        let mut rules = Vec::with_capacity(rest as usize);
        if let Some(around) = &around {
            let cosines = (cos_crease, cos_half);
            for v in (0..n).filter(|&v| slot[v] != u32::MAX) {
                let r = vertex_rule(around.of(slot[v]), v as u32, &tris, &facet, &unit, cosines, &mut work);
                rules.push(r);
            }
        }
        let mut others = Others {
            around,
            rules,
            slot,
            memo: FxHashMap::default(),
            facet: &facet,
            unit: &unit,
            cos_crease,
            work,
        };
        let mut out = CornerVertices::new(n);
        let triangles: Vec<[u32; 3]> = if plain {
            // Per welded vertex of one normal, its vertex (u32::MAX: not yet made).
            let mut one = vec![u32::MAX; n];
            tris.iter()
                .enumerate()
                .map(|(f, t)| {
                    let mut tri = [0u32; 3];
                    // (A loop, not `t.map`: the closure was not inlined, its array moved per
                    // corner.)
                    for corner in 0..3 {
                        let v = t[corner] as usize;
                        tri[corner] = if one[v] != u32::MAX {
                            one[v]
                        } else if same[v] != Vec3::ZERO {
                            one[v] = out.alone(positions[v], same[v]);
                            one[v]
                        } else {
                            let (normal, many) = others.normal(v as u32, f);
                            out.vertex(v as u32, positions[v], normal, self, 0, many)
                        };
                    }
                    tri
                })
                .collect()
        } else {
            tris.iter()
                .enumerate()
                .map(|(f, t)| {
                    let mut tri = [0u32; 3];
                    for corner in 0..3 {
                        let v = t[corner];
                        let (normal, many) = match same[v as usize] {
                            m if m != Vec3::ZERO => (m, false),
                            _ => others.normal(v, f),
                        };
                        // A corner keeps its own texture coordinates: vertices split where
                        // they differ.
                        let k = self.triangles[f][corner] as usize;
                        tri[corner] = out.vertex(v, positions[v as usize], normal, self, k, many);
                    }
                    tri
                })
                .collect()
        };
        (out.mesh(triangles), others.work)
    }
}

/// The vertices without `Rule::Same`: the faces around them, their rules, and what the
/// rules need.
struct Others<'a> {
    around: Option<Around>,
    rules: Vec<Rule>,
    /// Per welded vertex, its rule's index in `rules` and its slot in `around` (u32::MAX:
    /// a vertex of `Rule::Same`).
    slot: Vec<u32>,
    memo: FxHashMap<(u32, [u32; 3]), Vec3>,
    facet: &'a [Vec3],
    unit: &'a [Vec3],
    cos_crease: f32,
    /// Facet comparisons made.
    work: u64,
}

impl Others<'_> {
    /// The normal of face `f`'s corner at vertex `v`, and whether `v`'s vertices are many
    /// (looked up by hash, not by chain).
    fn normal(&mut self, v: u32, f: usize) -> (Vec3, bool) {
        let own = self.unit[f];
        let (around, rule) = match &self.around {
            Some(a) => (a, &self.rules[self.slot[v as usize] as usize]),
            None => unreachable!("a used vertex without Rule::Same has a rule"),
        };
        let (unit, facet, cos_crease, work) = (self.unit, self.facet, self.cos_crease, &mut self.work);
        let n = match rule {
            Rule::Same(n) => *n,
            Rule::Plain => around
                .of(self.slot[v as usize])
                .iter()
                .filter(|&&g| {
                    *work += 1;
                    unit[g as usize].dot(own) >= cos_crease
                })
                .fold(Vec3::ZERO, |acc, &g| acc + facet[g as usize])
                .normalize_or_zero(),
            Rule::Directions(g) => *self
                .memo
                .entry((v, own.to_array().map(f32::to_bits)))
                .or_insert_with(|| {
                    *work += g.len() as u64;
                    g.iter()
                        .filter(|(u, _)| u.dot(own) >= cos_crease)
                        .fold(Vec3::ZERO, |acc, (_, sum)| acc + *sum)
                        .normalize_or_zero()
                }),
            Rule::Edges(groups) => groups[&(f as u32)],
        };
        (n, matches!(rule, Rule::Directions(_) | Rule::Edges(_)))
    }
}

/// Positions merged where they are equal (0 and −0 alike), in the order first met, and per
/// position its merged index. An open-addressing table of indices sized for the positions
/// (at most half full): a third of the instructions of a hash map's entry per position.
pub fn weld_positions(points: &[Vec3]) -> (Vec<Vec3>, Vec<u32>) {
    let size = (points.len() * 2).next_power_of_two().max(16);
    let shift = 64 - size.trailing_zeros();
    let mut table = vec![u32::MAX; size];
    let mut keys: Vec<[u32; 3]> = Vec::with_capacity(points.len());
    let mut merged = Vec::with_capacity(points.len());
    let mut remap = Vec::with_capacity(points.len());
    for p in points {
        let k = p.to_array().map(|c| if c == 0.0 { 0 } else { c.to_bits() });
        let h = (u64::from(k[0]) | (u64::from(k[1]) << 32)).wrapping_mul(0x9E37_79B9_7F4A_7C15)
            ^ u64::from(k[2]).wrapping_mul(0xC2B2_AE3D_27D4_EB4F);
        let mut i = (h.wrapping_mul(0x2545_F491_4F6C_DD1D) >> shift) as usize;
        let index = loop {
            let e = table[i];
            if e == u32::MAX {
                let e = keys.len() as u32;
                table[i] = e;
                keys.push(k);
                merged.push(*p);
                break e;
            }
            if keys[e as usize] == k {
                break e;
            }
            i = (i + 1) & (size - 1);
        };
        remap.push(index);
    }
    (merged, remap)
}

/// Faces at a vertex up to which the mean direction may stand for all of them
/// ([`vertex_rule`]).
const MANY: usize = 32;

/// Per vertex of the welded mesh `w`, the normal of `Rule::Same` where [`vertex_rule`] would
/// give it (at most [`MANY`] faces, all within half the crease angle of their mean direction,
/// `cos_half`), else zero; and its number of corners. The facets are summed per vertex in
/// face order, as [`vertex_rule`] sums them: the same bits, without the faces-around lists.
/// Each face's facet normal `(b − a) × (c − a)` (its length twice its area) and that
/// normal's unit vector (zero for a degenerate face).
fn facets_of(positions: &[Vec3], tris: &[[u32; 3]]) -> (Vec<Vec3>, Vec<Vec3>) {
    let facet: Vec<Vec3> = tris
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| positions[i as usize]);
            (b - a).cross(c - a)
        })
        .collect();
    let unit: Vec<Vec3> = facet.iter().map(|f| f.normalize_or_zero()).collect();
    (facet, unit)
}

fn same_normals(
    n: usize,
    tris: &[[u32; 3]],
    facet: &[Vec3],
    unit: &[Vec3],
    cos_half: Option<f32>,
) -> (Vec<Vec3>, Vec<u32>) {
    let mut mean = vec![Vec3::ZERO; n];
    let mut count = vec![0u32; n];
    let Some(cos_half) = cos_half else {
        for &v in tris.iter().flatten() {
            count[v as usize] += 1;
        }
        return (mean, count);
    };
    for (t, f) in tris.iter().zip(facet) {
        for &v in t {
            mean[v as usize] += *f;
            count[v as usize] += 1;
        }
    }
    for (m, &c) in mean.iter_mut().zip(&count) {
        *m = if c as usize > MANY {
            Vec3::ZERO
        } else {
            m.normalize_or_zero()
        };
    }
    for (t, u) in tris.iter().zip(unit) {
        for &v in t {
            let m = &mut mean[v as usize];
            // (`!(a >= b)`: a NaN fails the test, as in `vertex_rule`.)
            #[allow(clippy::neg_cmp_op_on_partial_ord)]
            if *m != Vec3::ZERO && !(u.dot(*m) >= cos_half) {
                *m = Vec3::ZERO;
            }
        }
    }
    (mean, count)
}

/// The faces around some of the vertices, in face order: those of the vertex of slot `k`
/// are `faces[start[k]..start[k + 1]]` (one allocation, not one per vertex).
struct Around {
    start: Vec<u32>,
    faces: Vec<u32>,
}

impl Around {
    /// The faces around each vertex `v` with `slot[v] != u32::MAX` (`slots` of them, in the
    /// order of the vertices), each vertex with `count[v]` corners.
    fn new(slot: &[u32], count: &[u32], slots: usize, triangles: &[[u32; 3]]) -> Around {
        let mut start = Vec::with_capacity(slots + 1);
        start.push(0u32);
        for (&k, &c) in slot.iter().zip(count) {
            if k != u32::MAX {
                start.push(start[k as usize] + c);
            }
        }
        let mut faces = vec![0u32; start[slots] as usize];
        let mut fill = start.clone();
        for (f, t) in triangles.iter().enumerate() {
            for &i in t {
                let k = slot[i as usize];
                if k != u32::MAX {
                    faces[fill[k as usize] as usize] = f as u32;
                    fill[k as usize] += 1;
                }
            }
        }
        Around { start, faces }
    }

    /// The faces around the vertex of slot `k`.
    fn of(&self, k: u32) -> &[u32] {
        &self.faces[self.start[k as usize] as usize..self.start[k as usize + 1] as usize]
    }
}

/// At a vertex with many faces, faces of the same facet direction are one group (summed
/// once, in face order), so the work is faces + groups² there, not faces² (80 000 copies
/// of one triangle are one group); past MANY_GROUPS directions, the edge rule. Vertices with
/// few faces keep the plain loop, whose summation order the images were made with, or, where
/// every face lies within half the crease angle of their mean direction (so every pair is
/// within the crease), that loop's result once for all the vertex's corners.
fn vertex_rule(
    fs: &[u32],
    v: u32,
    triangles: &[[u32; 3]],
    facet: &[Vec3],
    unit: &[Vec3],
    (cos_crease, cos_half): (f32, Option<f32>),
    work: &mut u64,
) -> Rule {
    const MANY_GROUPS: usize = 64;
    if fs.len() <= MANY {
        if let Some(cos_half) = cos_half {
            *work += 2 * fs.len() as u64;
            let sum = fs.iter().fold(Vec3::ZERO, |acc, &g| acc + facet[g as usize]);
            let mean = sum.normalize_or_zero();
            if mean != Vec3::ZERO && fs.iter().all(|&g| unit[g as usize].dot(mean) >= cos_half) {
                return Rule::Same(mean);
            }
        }
        return Rule::Plain;
    }
    let mut index: FxHashMap<[u32; 3], usize> = FxHashMap::default();
    let mut g: Vec<(Vec3, Vec3)> = Vec::new();
    for &f in fs {
        *work += 1;
        let u = unit[f as usize];
        let k = *index.entry(u.to_array().map(f32::to_bits)).or_insert_with(|| {
            g.push((u, Vec3::ZERO));
            g.len() - 1
        });
        g[k].1 += facet[f as usize];
    }
    if g.len() <= MANY_GROUPS {
        Rule::Directions(g)
    } else {
        Rule::Edges(edge_groups(v, fs, triangles, facet, unit, cos_crease, work))
    }
}

/// The vertices of a mesh being split at its corners: one per position, normal, texture
/// coordinates and colour, numbered in the order they are first met. A position's vertices
/// are a chain searched in turn (a few at most where the position has few faces), those of a
/// position with many faces a hash map.
struct CornerVertices {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    uvs: Vec<Vec2>,
    uvs1: Vec<Vec2>,
    colors: Vec<Color>,
    /// The chains: per link, the vertex's key, the vertex and the next link.
    links: Vec<(CornerKey, u32, u32)>,
    /// Per welded position, its chain's first link (u32::MAX: none yet).
    head: Vec<u32>,
    many: FxHashMap<(u32, CornerKey), u32>,
}

type CornerKey = ([u32; 3], [[u32; 2]; 2], [u32; 3]);

impl CornerVertices {
    fn new(welded: usize) -> CornerVertices {
        // Room for a few split vertices without a copy.
        let room = welded + welded / 16;
        CornerVertices {
            positions: Vec::with_capacity(room),
            normals: Vec::with_capacity(room),
            uvs: Vec::new(),
            uvs1: Vec::new(),
            colors: Vec::new(),
            links: Vec::new(),
            head: vec![u32::MAX; welded],
            many: FxHashMap::default(),
        }
    }

    /// A vertex at `p` with normal `n` and no other attribute that no other corner will look
    /// up (a plain mesh's vertex of one normal).
    fn alone(&mut self, p: Vec3, n: Vec3) -> u32 {
        let i = self.positions.len() as u32;
        self.positions.push(p);
        self.normals.push(n);
        i
    }

    /// The vertex at welded position `v` (at `p`) with normal `n` and the attributes of vertex
    /// `k` of `source`.
    fn vertex(&mut self, v: u32, p: Vec3, n: Vec3, source: &Mesh, k: usize, many: bool) -> u32 {
        let uv = source.uvs.get(k).copied();
        let uv1 = source.uvs1.get(k).copied();
        let color = source.colors.get(k).copied();
        let key: CornerKey = (
            n.to_array().map(f32::to_bits),
            [uv, uv1].map(|uv| uv.unwrap_or_default().to_array().map(f32::to_bits)),
            color.unwrap_or_default().to_array().map(f32::to_bits),
        );
        if many {
            if let Some(&i) = self.many.get(&(v, key)) {
                return i;
            }
        } else {
            let mut l = self.head[v as usize];
            while l != u32::MAX {
                let (k, i, next) = &self.links[l as usize];
                if *k == key {
                    return *i;
                }
                l = *next;
            }
        }
        let i = self.positions.len() as u32;
        self.positions.push(p);
        self.normals.push(n);
        self.uvs.extend(uv);
        self.uvs1.extend(uv1);
        self.colors.extend(color);
        if many {
            self.many.insert((v, key), i);
        } else {
            self.links.push((key, i, self.head[v as usize]));
            self.head[v as usize] = (self.links.len() - 1) as u32;
        }
        i
    }

    fn mesh(self, triangles: Vec<[u32; 3]>) -> Mesh {
        Mesh {
            positions: self.positions,
            normals: self.normals,
            triangles,
            uvs: self.uvs,
            uvs1: self.uvs1,
            colors: self.colors,
            tangents: Vec::new(),
        }
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

/// How a vertex's corners get their crease normals (see [`Mesh::with_crease_normals`]).
enum Rule {
    /// Every corner's normal is this one (its faces all lie within the crease of each other).
    Same(Vec3),
    /// Every face around the vertex compared with the corner's own.
    Plain,
    /// The vertex's face directions, each with its facets' sum.
    Directions(Vec<(Vec3, Vec3)>),
    /// Each face's normal at the vertex, from the faces joined to it across shared edges.
    Edges(HashMap<u32, Vec3>),
}

/// The normal at vertex `v` of each face of `faces` (the faces around it): faces that share
/// an edge at `v` and meet within the crease angle are joined (union-find; on an edge with more
/// than two faces, each to the next), and each face gets its group's summed facets. Linear in
/// `faces` (`work` counts the comparisons).
fn edge_groups(
    v: u32,
    faces: &[u32],
    triangles: &[[u32; 3]],
    facet: &[Vec3],
    unit: &[Vec3],
    cos_crease: f32,
    work: &mut u64,
) -> HashMap<u32, Vec3> {
    fn find(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    let mut parent: Vec<usize> = (0..faces.len()).collect();
    // The last face seen on each edge (v, other vertex).
    let mut last_on_edge: HashMap<u32, usize> = HashMap::new();
    for (k, &f) in faces.iter().enumerate() {
        for &other in triangles[f as usize].iter().filter(|&&o| o != v) {
            if let Some(&j) = last_on_edge.get(&other) {
                *work += 1;
                if unit[faces[j] as usize].dot(unit[f as usize]) >= cos_crease {
                    let (a, b) = (find(&mut parent, j), find(&mut parent, k));
                    parent[a] = b;
                }
            }
            last_on_edge.insert(other, k);
        }
    }
    let mut sums = vec![Vec3::ZERO; faces.len()];
    for (k, &f) in faces.iter().enumerate() {
        let r = find(&mut parent, k);
        sums[r] += facet[f as usize];
    }
    faces
        .iter()
        .enumerate()
        .map(|(k, &f)| {
            let r = find(&mut parent, k);
            (f, sums[r].normalize_or_zero())
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

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

    #[test]
    fn flat_normals_unshare_vertices() {
        let m = folded().with_flat_normals();
        assert_eq!(m.positions().len(), 9);
        assert_eq!(m.normals()[0], Vec3::Z);
        assert_eq!(m.normals()[6], Vec3::X);
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

#[cfg(test)]
mod crease_tests {
    use super::*;

    impl Mesh {
        /// The crease normals as first written (one hash lookup a corner): the fast version must
        /// give these bits.
        pub(super) fn reference_crease_normals(&self, crease_deg: f32) -> (Mesh, u64) {
            let w = self.weld().0;
            let cos_crease = crease_deg.to_radians().cos();
            let facet: Vec<Vec3> = w
                .triangles
                .iter()
                .map(|t| {
                    let [a, b, c] = t.map(|i| w.positions[i as usize]);
                    (b - a).cross(c - a)
                })
                .collect();
            let unit: Vec<Vec3> = facet.iter().map(|f| f.normalize_or_zero()).collect();
            // The faces around each vertex, in face order: `around[v]` is
            // `faces[start[v]..start[v + 1]]` (one allocation, not one per vertex).
            let mut start = vec![0u32; w.positions.len() + 1];
            for t in &w.triangles {
                for &i in t {
                    start[i as usize + 1] += 1;
                }
            }
            for v in 0..w.positions.len() {
                start[v + 1] += start[v];
            }
            let mut faces = vec![0u32; w.triangles.len() * 3];
            let mut fill = start.clone();
            for (f, t) in w.triangles.iter().enumerate() {
                for &i in t {
                    faces[fill[i as usize] as usize] = f as u32;
                    fill[i as usize] += 1;
                }
            }
            let around = |v: usize| &faces[start[v] as usize..start[v + 1] as usize];
            let mut work = 0u64;
            // At a vertex with many faces, faces of the same facet direction are one group (summed
            // once, in face order), so the work is faces + groups² there, not faces² (80 000 copies
            // of one triangle are one group); past MANY_GROUPS directions, the edge rule above.
            // Vertices with few faces keep the plain loop, whose summation order the images were
            // made with.
            const MANY: usize = 32;
            const MANY_GROUPS: usize = 64;
            let vertex_rule: Vec<Rule> = (0..w.positions.len())
                .map(|v| {
                    let fs = around(v);
                    if fs.len() <= MANY {
                        return Rule::Plain;
                    }
                    let mut index: FxHashMap<[u32; 3], usize> = FxHashMap::default();
                    let mut g: Vec<(Vec3, Vec3)> = Vec::new();
                    for &f in fs {
                        work += 1;
                        let u = unit[f as usize];
                        let k = *index.entry(u.to_array().map(f32::to_bits)).or_insert_with(|| {
                            g.push((u, Vec3::ZERO));
                            g.len() - 1
                        });
                        g[k].1 += facet[f as usize];
                    }
                    if g.len() <= MANY_GROUPS {
                        Rule::Directions(g)
                    } else {
                        Rule::Edges(edge_groups(
                            v as u32,
                            fs,
                            &w.triangles,
                            &facet,
                            &unit,
                            cos_crease,
                            &mut work,
                        ))
                    }
                })
                .collect();
            let mut memo: FxHashMap<(u32, [u32; 3]), Vec3> = FxHashMap::default();
            let mut positions = Vec::new();
            let mut normals = Vec::new();
            let mut uvs = Vec::new();
            let mut uvs1 = Vec::new();
            let mut colors = Vec::new();
            type Key = (u32, [u32; 3], [[u32; 2]; 2], [u32; 3]);
            let mut dedup: FxHashMap<Key, u32> = FxHashMap::default();
            let mut triangles = Vec::with_capacity(w.triangles.len());
            for (f, t) in w.triangles.iter().enumerate() {
                let own = unit[f];
                let mut corner = 0;
                let tri = t.map(|v| {
                    // A corner keeps its own texture coordinates: vertices split where they differ.
                    let uv = self.uvs.get(self.triangles[f][corner] as usize).copied();
                    let uv1 = self.uvs1.get(self.triangles[f][corner] as usize).copied();
                    let color = self.colors.get(self.triangles[f][corner] as usize).copied();
                    corner += 1;
                    let n = match &vertex_rule[v as usize] {
                        Rule::Plain => around(v as usize)
                            .iter()
                            .filter(|&&g| {
                                work += 1;
                                unit[g as usize].dot(own) >= cos_crease
                            })
                            .fold(Vec3::ZERO, |acc, &g| acc + facet[g as usize])
                            .normalize_or_zero(),
                        Rule::Directions(g) => {
                            *memo.entry((v, own.to_array().map(f32::to_bits))).or_insert_with(|| {
                                work += g.len() as u64;
                                g.iter()
                                    .filter(|(u, _)| u.dot(own) >= cos_crease)
                                    .fold(Vec3::ZERO, |acc, (_, sum)| acc + *sum)
                                    .normalize_or_zero()
                            })
                        }
                        Rule::Edges(groups) => groups[&(f as u32)],
                        Rule::Same(n) => *n,
                    };
                    let key = (
                        v,
                        n.to_array().map(f32::to_bits),
                        [uv, uv1].map(|uv| uv.unwrap_or_default().to_array().map(f32::to_bits)),
                        color.unwrap_or_default().to_array().map(f32::to_bits),
                    );
                    *dedup.entry(key).or_insert_with(|| {
                        positions.push(w.positions[v as usize]);
                        normals.push(n);
                        uvs.extend(uv);
                        uvs1.extend(uv1);
                        colors.extend(color);
                        (positions.len() - 1) as u32
                    })
                });
                triangles.push(tri);
            }
            let mesh = Mesh {
                positions,
                normals,
                triangles,
                uvs,
                uvs1,
                colors,
                tangents: Vec::new(),
            };
            (mesh, work)
        }
    }

    /// A fan of 100 000 faces around one apex, every one in its own direction (a cone's tip):
    /// the work grows linearly with the faces (counted, not timed); neighbours meet at a soft
    /// edge, so the apex has one normal, the normalised sum of every facet (here +z).
    #[test]
    fn many_directions_at_a_vertex_cost_linear_work() {
        let fan = |n: usize| {
            let mut p = vec![Vec3::new(0.0, 0.0, 1.0)];
            for i in 0..n {
                let a = i as f32 / n as f32 * std::f32::consts::TAU;
                p.push(Vec3::new(a.cos(), a.sin(), 0.0));
            }
            let tris: Vec<[u32; 3]> = (0..n as u32).map(|i| [0, 1 + i, 1 + (i + 1) % n as u32]).collect();
            Mesh::from_triangles(p, tris).expect("mesh")
        };
        let (_, work_small) = fan(10_000).crease_normals(30.0);
        let (large, work_large) = fan(100_000).crease_normals(30.0);
        assert!(
            work_large < 12 * work_small,
            "work {work_small} -> {work_large} for 10x the faces"
        );
        assert!(work_large < 20 * 100_000, "{work_large}");
        let apex: Vec<Vec3> = large
            .positions()
            .iter()
            .zip(large.normals())
            .filter(|(p, _)| p.z == 1.0)
            .map(|(_, n)| *n)
            .collect();
        assert_eq!(apex.len(), 1, "one apex vertex");
        assert!((apex[0] - Vec3::Z).length() < 1e-3, "{}", apex[0]);
    }

    #[test]
    fn many_copies_of_one_triangle_are_one_group() {
        let p = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
        let tris = vec![[0, 1, 2]; 80_000];
        let m = Mesh::from_triangles(p, tris).expect("mesh").with_crease_normals(60.0);
        assert_eq!(m.positions().len(), 3);
        assert!(m.normals().iter().all(|n| (*n - Vec3::Z).length() < 1e-6));
    }

    #[test]
    fn grouped_vertices_give_the_plain_loops_normals() {
        // A fan of 40 triangles around the origin, tilted so that neighbours are within the
        // crease angle and opposite sides are not: the apex has more than MANY faces.
        let n = 40;
        let mut p = vec![Vec3::new(0.0, 0.0, 0.3)];
        for i in 0..n {
            let a = i as f32 / n as f32 * std::f32::consts::TAU;
            p.push(Vec3::new(a.cos(), a.sin(), 0.0));
        }
        let tris: Vec<[u32; 3]> = (0..n as u32).map(|i| [0, 1 + i, 1 + (i + 1) % n as u32]).collect();
        let mesh = Mesh::from_triangles(p, tris).expect("mesh");
        let m = mesh.with_crease_normals(30.0);
        // The plain loop, written out: for each face at the apex, the sum of facets within 30°.
        let facets: Vec<Vec3> = (0..n)
            .map(|f| {
                let [a, b, c] = mesh.corners(f);
                (b - a).cross(c - a)
            })
            .collect();
        for (f, t) in m.triangles().iter().enumerate() {
            let own = facets[f].normalize();
            let want = facets
                .iter()
                .filter(|g| g.normalize().dot(own) >= 30f32.to_radians().cos())
                .fold(Vec3::ZERO, |a, g| a + *g)
                .normalize();
            let got = m.normals()[t[0] as usize];
            assert!((got - want).length() < 1e-5, "face {f}: {got} vs {want}");
        }
    }
}

#[cfg(test)]
mod crease_equivalence {
    use super::*;
    use crate::primitives;
    use proptest::prelude::*;

    /// A height field of `n`×`n` cells with heights `h` (steps and slopes: creases of every
    /// angle), texture coordinates that jump on one row (seams) and, optionally, colours.
    fn field(n: usize, h: &[f32], seam: bool, colored: bool) -> Mesh {
        let mut p = Vec::new();
        let mut uv = Vec::new();
        for y in 0..=n {
            for x in 0..=n {
                p.push(Vec3::new(x as f32, y as f32, h[(y * (n + 1) + x) % h.len()]));
                let v = if seam && y == n / 2 { 0.9 } else { y as f32 / n as f32 };
                uv.push(Vec2::new(x as f32 / n as f32, v));
            }
        }
        let mut t = Vec::new();
        let at = |x: usize, y: usize| (y * (n + 1) + x) as u32;
        for y in 0..n {
            for x in 0..n {
                t.push([at(x, y), at(x + 1, y), at(x + 1, y + 1)]);
                t.push([at(x, y), at(x + 1, y + 1), at(x, y + 1)]);
            }
        }
        // A degenerate face and a repeated one.
        t.push([at(0, 0), at(0, 0), at(1, 1)]);
        t.push(t[0]);
        let colors = p
            .iter()
            .map(|q| Color::new(q.x / n as f32, q.y / n as f32, 0.5))
            .collect();
        let m = Mesh::from_triangles(p, t).expect("mesh").with_uvs(uv).expect("uvs");
        if colored {
            m.with_colors(colors).expect("colours")
        } else {
            m
        }
    }

    fn same_bits(a: &Mesh, b: &Mesh) {
        let bits = |v: &[Vec3]| v.iter().map(|x| x.to_array().map(f32::to_bits)).collect::<Vec<_>>();
        assert_eq!(a.triangles, b.triangles);
        assert_eq!(bits(&a.positions), bits(&b.positions));
        assert_eq!(bits(&a.normals), bits(&b.normals));
        assert_eq!(a.uvs, b.uvs);
        assert_eq!(a.colors, b.colors);
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(200))]
        /// The shortcut (one normal a vertex where its faces are all within half the crease of
        /// their mean) gives the plain loop's bits, vertex order and splits.
        #[test]
        fn fast_crease_normals_are_the_plain_loops(
            n in 1usize..9,
            h in proptest::collection::vec(prop_oneof![-3.0f32..3.0, Just(0.0f32), Just(1.0f32)], 1..40),
            crease in prop_oneof![0.0f32..180.0, Just(1.0f32), Just(30.0f32), Just(45.0f32), Just(90.0f32), Just(179.0f32), Just(180.0f32)],
            seam in any::<bool>(),
            colored in any::<bool>(),
        ) {
            let m = field(n, &h, seam, colored);
            same_bits(&m.crease_normals(crease).0, &m.reference_crease_normals(crease).0);
        }
    }

    #[test]
    fn fast_crease_normals_on_the_shapes() {
        for mesh in [
            primitives::sphere(24),
            primitives::cube(),
            primitives::teapot(8),
            primitives::cone(16),
            primitives::torus(16, 1.0, 0.3),
        ] {
            for crease in [1.0, 10.0, 30.0, 60.0, 89.0, 90.0, 91.0, 120.0, 179.0, 180.0] {
                same_bits(&mesh.crease_normals(crease).0, &mesh.reference_crease_normals(crease).0);
            }
        }
    }
}
