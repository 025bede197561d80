//! Normals by crease angle ([`Mesh::with_crease_normals`]): the positions welded, each
//! vertex's rule (one normal for all its corners, or its faces compared), and the mesh split at
//! its corners where their normals differ.

use super::Mesh;
use crate::Color;
use glam::{Vec2, Vec3, Vec3A};
use rustc_hash::FxHashMap;
use std::borrow::Cow;
use std::collections::HashMap;

impl Mesh {
    /// [`Mesh::with_crease_normals`], and the work it did (facet comparisons), for the test
    /// that it is linear.
    pub(super) fn crease_normals(&self, crease_deg: f32) -> (Mesh, u64) {
        self.crease_of(
            Cow::Borrowed(&self.positions),
            Cow::Borrowed(&self.triangles),
            crease_deg,
        )
    }

    /// [`Mesh::crease_normals`] of the mesh of `original` positions and triangles (borrowed
    /// from `self` or taken from it) and `self`'s other attributes.
    pub(super) fn crease_of(
        &self,
        original: Cow<[Vec3]>,
        original_tris: Cow<[[u32; 3]]>,
        crease_deg: f32,
    ) -> (Mesh, u64) {
        // Where no two positions are equal (most files), the mesh's own arrays stand for the
        // welded ones: no copies.
        let (distinct, remap) = weld_ids(&original);
        // (`unwelded`: the original triangles, where they are not `tris`.)
        let (positions, tris, unwelded): (Cow<[Vec3]>, Cow<[[u32; 3]]>, _) = if distinct == original.len() {
            (original, original_tris, None)
        } else {
            (
                Cow::Owned(merged(&original, &remap, distinct)),
                Cow::Owned(original_tris.iter().map(|t| t.map(|i| remap[i as usize])).collect()),
                Some(original_tris),
            )
        };
        let cos_crease = crease_deg.to_radians().cos();
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
        let Facets {
            facet,
            unit,
            sum,
            count,
        } = facets_of(&positions, &tris, cos_half.is_some());
        let mut same = same_normals(sum, &count, &tris, &unit, cos_half);
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
                // One normal for all its corners: the corner loop's shortcut.
                if let Rule::Same(m) = r {
                    same[v] = m;
                }
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
        // A plain mesh whose welded vertices are all used keeps them in place: a vertex of one
        // normal is its welded vertex, the first normal of any other takes its place and the
        // rest follow (each corner's attributes as below, the vertices numbered otherwise).
        if plain && count.iter().all(|&c| c > 0) {
            let triangles = tris.into_owned();
            let out = CornerVertices::in_place(positions.into_owned(), same, rest as usize);
            return (out.split_in_place(triangles, &mut others), others.work);
        }
        // A plain mesh makes at most one vertex for a vertex of one normal and one a corner for
        // the others: room for all of them at once (a vector grown past its room is copied).
        let room = if plain {
            same.iter()
                .zip(&count)
                .map(|(m, &c)| if *m != Vec3::ZERO { 1 } else { c as usize })
                .sum()
        } else {
            n + n / 16
        };
        let mut out = CornerVertices::new(n, room);
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
            let original = unwelded.as_deref().unwrap_or(&tris);
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
                        let k = original[f][corner] as usize;
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
/// position its merged index.
pub fn weld_positions(points: &[Vec3]) -> (Vec<Vec3>, Vec<u32>) {
    let (distinct, ids) = weld_ids(points);
    (merged(points, &ids, distinct), ids)
}

/// The `distinct` positions of `points` in the order first met, from their ids
/// ([`weld_ids`]).
fn merged(points: &[Vec3], ids: &[u32], distinct: usize) -> Vec<Vec3> {
    let mut out = Vec::with_capacity(distinct);
    for (p, &id) in points.iter().zip(ids) {
        if id as usize == out.len() {
            out.push(*p);
        }
    }
    out
}

/// How many distinct positions `points` has (equal positions, 0 and −0 alike, are one), and
/// per point the index of its position in the order first met: point `i`'s is `i` for every
/// `i` exactly where the count is `points.len()`.
///
/// The points are first sorted into buckets by their hash's top bits (a counting sort, in
/// point order within a bucket), then each bucket is welded in an open-addressing table sized
/// for it (at most half full, 16 to 32 KiB: in the L1 cache), whose entries hold a tag of the
/// position's hash and the first point at that position. One table for all the points missed
/// the caches at nearly every probe (BENCHMARKS.md, "Loading against trimesh").
pub fn weld_ids(points: &[Vec3]) -> (usize, Vec<u32>) {
    // Buckets of 1,024 to 2,047 points on average (one for fewer points), at most 4,096 of them.
    let bits = (points.len() / 1024).max(1).ilog2().min(12);
    weld_ids_in(points, bits)
}

/// A position's key: its bits, 0 for both zeros.
#[inline(always)]
fn weld_key(p: &Vec3) -> [u32; 3] {
    let bits = |c: f32| {
        let b = c.to_bits();
        if b << 1 == 0 { 0 } else { b }
    };
    [bits(p.x), bits(p.y), bits(p.z)]
}

/// A key's 32-bit hash: its top `bits` bits choose the bucket, the bits below them the slot
/// in the bucket's table; all of it is the tag an entry keeps.
#[inline(always)]
fn weld_hash(k: [u32; 3]) -> u32 {
    (((u64::from(k[0]) | (u64::from(k[1]) << 32)).wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ u64::from(k[2]).wrapping_mul(0xC2B2_AE3D_27D4_EB4F))
    .wrapping_mul(0x2545_F491_4F6C_DD1D)
        >> 32) as u32
}

/// [`weld_ids`] with `2^bits` buckets.
fn weld_ids_in(points: &[Vec3], bits: u32) -> (usize, Vec<u32>) {
    let n = points.len();
    let buckets = 1usize << bits;
    let bucket = |h: u32| (h.checked_shr(32 - bits).unwrap_or(0)) as usize;
    // Per point its hash (kept in `first` until the tables replace it), per bucket its size.
    let mut first: Vec<u32> = points.iter().map(|p| weld_hash(weld_key(p))).collect();
    let mut start = vec![0u32; buckets + 1];
    for &h in &first {
        start[bucket(h) + 1] += 1;
    }
    for b in 0..buckets {
        start[b + 1] += start[b];
    }
    // Per bucket, its points as `hash << 32 | point`, in point order.
    let mut sorted = vec![0u64; n];
    let mut fill = start[..buckets].to_vec();
    for (i, &h) in first.iter().enumerate() {
        let f = &mut fill[bucket(h)];
        sorted[*f as usize] = u64::from(h) << 32 | i as u64;
        *f += 1;
    }
    // Per point, the first point at its position (so that `first[i] <= i`).
    let largest = start.windows(2).map(|w| w[1] - w[0]).max().unwrap_or(0) as usize;
    // (An entry's point is never u32::MAX: a mesh's vertices are indexed by u32.)
    let mut table = vec![u64::MAX; (largest * 2).next_power_of_two().max(16)];
    for w in start.windows(2) {
        let list = &sorted[w[0] as usize..w[1] as usize];
        let size = (list.len() * 2).next_power_of_two().max(16);
        let table = &mut table[..size];
        table.fill(u64::MAX);
        // The slot from the hash's bits below the bucket's (equal positions start alike).
        let slot_bits = size.trailing_zeros().min(32 - bits);
        for &e in list {
            let i = (e & 0xFFFF_FFFF) as usize;
            let tag = e >> 32;
            let mut slot = (((tag << bits) & 0xFFFF_FFFF) >> (32 - slot_bits)) as usize;
            first[i] = loop {
                let t = table[slot];
                if t == u64::MAX {
                    table[slot] = e;
                    break i as u32;
                }
                if t >> 32 == tag {
                    let f = (t & 0xFFFF_FFFF) as u32;
                    if weld_key(&points[f as usize]) == weld_key(&points[i]) {
                        break f;
                    }
                }
                slot = (slot + 1) & (size - 1);
            };
        }
    }
    // Ids in the order first met, in place: `first[i] < i` is already an id.
    let mut distinct = 0u32;
    for i in 0..n {
        let f = first[i] as usize;
        first[i] = if f == i {
            distinct += 1;
            distinct - 1
        } else {
            first[f]
        };
    }
    (distinct as usize, first)
}

/// Faces at a vertex up to which the mean direction may stand for all of them
/// ([`vertex_rule`]).
const MANY: usize = 32;

/// Each face's facet normal `(b − a) × (c − a)` (its length twice its area) and that
/// normal's unit vector (zero for a degenerate face); per vertex, its number of corners and
/// (where asked) its faces' facets summed in face order.
struct Facets {
    facet: Vec<Vec3>,
    unit: Vec<Vec3>,
    /// Empty where not asked.
    sum: Vec<Vec3>,
    count: Vec<u32>,
}

/// [`Facets`] of a welded mesh, in one pass over its faces.
fn facets_of(positions: &[Vec3], tris: &[[u32; 3]], sums: bool) -> Facets {
    if sums {
        facets_summed::<true>(positions, tris)
    } else {
        facets_summed::<false>(positions, tris)
    }
}

#[inline(always)]
fn facets_summed<const SUMS: bool>(positions: &[Vec3], tris: &[[u32; 3]]) -> Facets {
    let n = positions.len();
    // (Sized at once and written in place: a push per face checked its room.)
    let mut facet = vec![Vec3::ZERO; tris.len()];
    let mut unit = vec![Vec3::ZERO; tris.len()];
    // (The sums become the normals of a plain mesh split in place, whose new vertices go
    // after them: room for a quarter more, which costs nothing until used.)
    let mut sum = Vec::with_capacity(if SUMS { n + n / 4 } else { 0 });
    sum.resize(if SUMS { n } else { 0 }, Vec3::ZERO);
    let mut count = vec![0u32; n];
    for ((t, f_out), u_out) in tris.iter().zip(&mut facet).zip(&mut unit) {
        // (In `Vec3A`, glam's SSE form of the same operations in the same order: the same
        // bits in fewer instructions. Four at a time in `Vec4` lanes, as the flat normals
        // are, was no fewer: BENCHMARKS.md, L10.)
        let [a, b, c] = [t[0], t[1], t[2]].map(|i| Vec3A::from(positions[i as usize]));
        let fa = (b - a).cross(c - a);
        let f = Vec3::from(fa);
        *f_out = f;
        *u_out = fa.normalize_or_zero().into();
        for &v in t {
            count[v as usize] += 1;
            if SUMS {
                sum[v as usize] += f;
            }
        }
    }
    Facets {
        facet,
        unit,
        sum,
        count,
    }
}

/// Per vertex of the welded mesh, the normal of `Rule::Same` where [`vertex_rule`] would give
/// it (at most [`MANY`] faces, all within half the crease angle of their mean direction,
/// `cos_half`), else zero, from its facets' sum in face order (`sum`, as [`vertex_rule`] sums
/// them: the same bits, without the faces-around lists) and its number of corners.
fn same_normals(
    mut mean: Vec<Vec3>,
    count: &[u32],
    tris: &[[u32; 3]],
    unit: &[Vec3],
    cos_half: Option<f32>,
) -> Vec<Vec3> {
    let Some(cos_half) = cos_half else {
        return vec![Vec3::ZERO; count.len()];
    };
    for (m, &c) in mean.iter_mut().zip(count) {
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
    mean
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
/// every pair of faces is within the crease (found at once where every face lies within half
/// the crease angle of their mean direction, else pair by pair), that loop's result once for
/// all the vertex's corners.
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
        *work += fs.len() as u64;
        let sum = fs.iter().fold(Vec3::ZERO, |acc, &g| acc + facet[g as usize]);
        let mean = sum.normalize_or_zero();
        if let Some(cos_half) = cos_half {
            *work += fs.len() as u64;
            if mean != Vec3::ZERO && fs.iter().all(|&g| unit[g as usize].dot(mean) >= cos_half) {
                return Rule::Same(mean);
            }
        }
        // Every pair of faces within the crease (each face with itself too: at a crease of
        // 0° a unit vector's square may fall short of 1): each corner's loop would keep every
        // face, in face order, so its sum is `sum` (dot products are symmetric in f32).
        *work += (fs.len() * (fs.len() + 1) / 2) as u64;
        let all = fs.iter().enumerate().all(|(i, &f)| {
            let u = unit[f as usize];
            fs[i..].iter().all(|&g| unit[g as usize].dot(u) >= cos_crease)
        });
        return if all { Rule::Same(mean) } else { Rule::Plain };
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
    /// For `welded` positions, with room for `room` vertices.
    fn new(welded: usize, room: usize) -> CornerVertices {
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

    /// The welded `positions` kept in place with their normals `same` (zero where a vertex
    /// has several, `several` of them: [`CornerVertices::split_in_place`] fills them).
    fn in_place(positions: Vec<Vec3>, same: Vec<Vec3>, several: usize) -> CornerVertices {
        let n = positions.len();
        CornerVertices {
            positions,
            normals: same,
            uvs: Vec::new(),
            uvs1: Vec::new(),
            colors: Vec::new(),
            // (A link each at least, more where a vertex splits: room at once, not grown by
            // copies.)
            links: Vec::with_capacity(several + several / 2),
            head: vec![u32::MAX; n],
            many: FxHashMap::default(),
        }
    }

    /// The mesh of welded `triangles` whose every vertex is used, each keeping its index where
    /// its normal is one (non-zero in `normals`); a vertex of several normals gives its index to
    /// the first met and the others new vertices after all of them. Without texture
    /// coordinates or colours.
    fn split_in_place(mut self, mut triangles: Vec<[u32; 3]>, others: &mut Others) -> Mesh {
        // Per vertex: 0 one normal (kept), 1 several and its index free, 2 its index taken.
        let mut state: Vec<u8> = self.normals.iter().map(|n| u8::from(*n == Vec3::ZERO)).collect();
        for (f, t) in triangles.iter_mut().enumerate() {
            for v in t.iter_mut() {
                let i = *v as usize;
                if state[i] == 0 {
                    continue;
                }
                let (n, many) = others.normal(*v, f);
                let key: CornerKey = (n.to_array().map(f32::to_bits), [[0; 2]; 2], [0; 3]);
                if state[i] == 1 {
                    state[i] = 2;
                    self.normals[i] = n;
                    self.remember(*v, key, *v, many);
                    continue;
                }
                *v = match self.find(*v, &key, many) {
                    Some(k) => k,
                    None => {
                        let k = self.positions.len() as u32;
                        self.positions.push(self.positions[i]);
                        self.normals.push(n);
                        self.remember(*v, key, k, many);
                        k
                    }
                };
            }
        }
        self.mesh(triangles)
    }

    /// The vertex made at welded position `v` for `key`, if any.
    fn find(&self, v: u32, key: &CornerKey, many: bool) -> Option<u32> {
        if many {
            return self.many.get(&(v, *key)).copied();
        }
        let mut l = self.head[v as usize];
        while l != u32::MAX {
            let (k, i, next) = &self.links[l as usize];
            if k == key {
                return Some(*i);
            }
            l = *next;
        }
        None
    }

    /// Records vertex `i` as welded position `v`'s for `key`.
    fn remember(&mut self, v: u32, key: CornerKey, i: u32, many: bool) {
        if many {
            self.many.insert((v, key), i);
        } else {
            self.links.push((key, i, self.head[v as usize]));
            self.head[v as usize] = (self.links.len() - 1) as u32;
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
        if let Some(i) = self.find(v, &key, many) {
            return i;
        }
        let i = self.positions.len() as u32;
        self.positions.push(p);
        self.normals.push(n);
        self.uvs.extend(uv);
        self.uvs1.extend(uv1);
        self.colors.extend(color);
        self.remember(v, key, i, many);
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
            face_normals: None,
            vertex_form: Default::default(),
        }
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
mod crease_tests {
    use super::*;

    /// Welded ids: equal positions (0 and −0 alike) share an id and only they do, ids are
    /// numbered as first met, the count is the number of distinct positions, and all-distinct
    /// points get their own indices; `weld_positions` lists each distinct position once.
    #[test]
    fn welded_ids_number_positions_as_first_met() {
        let p = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
        let points = [
            p(1.0, 2.0, 3.0),
            p(0.0, 1.0, 0.0),
            p(1.0, 2.0, 3.0),
            p(-0.0, 1.0, -0.0),
            p(4.0, 5.0, 6.0),
        ];
        let (count, ids) = weld_ids(&points);
        assert_eq!((count, ids.clone()), (3, vec![0, 1, 0, 1, 2]));
        let (merged, same) = weld_positions(&points);
        assert_eq!((merged, same), (vec![points[0], points[1], points[4]], ids));
        let distinct: Vec<Vec3> = (0..1000).map(|i| p(i as f32 * 0.5, (i % 7) as f32, 1.0)).collect();
        assert_eq!(weld_ids(&distinct), (1000, (0..1000).collect()));
    }

    proptest::proptest! {
        /// Points drawn from a few values (many equal, zeros of both signs, tags colliding in a
        /// full table): the ids a plain map numbers in the order first met.
        #[test]
        fn welded_ids_are_a_maps(
            picks in proptest::collection::vec((0usize..6, 0usize..6, 0usize..3), 0..300),
        ) {
            let values = [0.0f32, -0.0, 1.0, -1.5, 1e-30, f32::MAX];
            let points: Vec<Vec3> = picks.iter().map(|&(x, y, z)| Vec3::new(values[x], values[y], values[z])).collect();
            let mut first: HashMap<[u32; 3], u32> = HashMap::new();
            let want: Vec<u32> = points
                .iter()
                .map(|p| {
                    let k = p.to_array().map(|c| if c == 0.0 { 0 } else { c.to_bits() });
                    let next = first.len() as u32;
                    *first.entry(k).or_insert(next)
                })
                .collect();
            proptest::prop_assert_eq!(weld_ids(&points), (first.len(), want.clone()));
            // Several buckets (a few points each, some empty), as large inputs have them.
            for bits in [1, 3, 6] {
                proptest::prop_assert_eq!(weld_ids_in(&points, bits), (first.len(), want.clone()));
            }
        }
    }

    impl Mesh {
        /// The crease normals from their definition alone, for meshes whose vertices have at
        /// most [`MANY`] faces (where the fast version keeps the plain rule's bits): positions
        /// equal (0 and −0 alike) are one vertex; each corner's normal is the normalised sum,
        /// in face order, of the facet normals of the faces around its vertex whose unit
        /// normals are within the crease of its own face's; a vertex is made per distinct
        /// (position, normal, texture coordinates, colour), numbered as first met, face by
        /// face and corner by corner.
        pub(super) fn reference_crease_normals(&self, crease_deg: f32) -> Mesh {
            let mut ids: HashMap<[u32; 3], u32> = HashMap::new();
            let mut welded: Vec<Vec3> = Vec::new();
            let id: Vec<u32> = self
                .positions
                .iter()
                .map(|p| {
                    let key = p.to_array().map(|c| if c == 0.0 { 0 } else { c.to_bits() });
                    *ids.entry(key).or_insert_with(|| {
                        welded.push(*p);
                        welded.len() as u32 - 1
                    })
                })
                .collect();
            let faces: Vec<[usize; 3]> = self
                .triangles
                .iter()
                .map(|t| t.map(|i| id[i as usize] as usize))
                .collect();
            let facet: Vec<Vec3> = faces
                .iter()
                .map(|&[a, b, c]| (welded[b] - welded[a]).cross(welded[c] - welded[a]))
                .collect();
            let unit: Vec<Vec3> = facet.iter().map(|f| f.normalize_or_zero()).collect();
            let mut around: Vec<Vec<usize>> = vec![Vec::new(); welded.len()];
            for (f, t) in faces.iter().enumerate() {
                for &v in t {
                    around[v].push(f);
                }
            }
            assert!(
                around.iter().all(|fs| fs.len() <= MANY),
                "the reference is for vertices of at most {MANY} faces"
            );
            let cos_crease = crease_deg.to_radians().cos();
            let mut out = Mesh::default();
            type Key = (usize, [u32; 3], [[u32; 2]; 2], [u32; 3]);
            let mut made: HashMap<Key, u32> = HashMap::new();
            for (f, t) in faces.iter().enumerate() {
                let mut tri = [0u32; 3];
                for (corner, &v) in t.iter().enumerate() {
                    let k = self.triangles[f][corner] as usize;
                    let n = around[v]
                        .iter()
                        .filter(|&&g| unit[g].dot(unit[f]) >= cos_crease)
                        .fold(Vec3::ZERO, |sum, &g| sum + facet[g])
                        .normalize_or_zero();
                    let (uv, uv1, color) = (self.uvs.get(k), self.uvs1.get(k), self.colors.get(k));
                    let key = (
                        v,
                        n.to_array().map(f32::to_bits),
                        [uv, uv1].map(|uv| uv.copied().unwrap_or_default().to_array().map(f32::to_bits)),
                        color.copied().unwrap_or_default().to_array().map(f32::to_bits),
                    );
                    tri[corner] = *made.entry(key).or_insert_with(|| {
                        out.positions.push(welded[v]);
                        out.normals.push(n);
                        out.uvs.extend(uv);
                        out.uvs1.extend(uv1);
                        out.colors.extend(color);
                        out.positions.len() as u32 - 1
                    });
                }
                out.triangles.push(tri);
            }
            out
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
    /// angle), texture coordinates that jump on one row (seams) and, optionally, colours; or
    /// (`plain`) positions alone.
    fn field(n: usize, h: &[f32], seam: bool, colored: bool, plain: bool) -> Mesh {
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
        let m = Mesh::from_triangles(p, t).expect("mesh");
        if plain {
            return m;
        }
        let m = m.with_uvs(uv).expect("uvs");
        if colored {
            m.with_colors(colors).expect("colours")
        } else {
            m
        }
    }

    /// `a` and `b` are the same mesh up to the numbering of their vertices: as many vertices,
    /// and each corner of each triangle the same bits of position, normal, texture coordinates
    /// and colour; no two vertices of `a` alike (the definition's vertices are distinct).
    fn same_bits(a: &Mesh, b: &Mesh) {
        type Key = ([u32; 3], [u32; 3], Option<[u32; 2]>, Option<[u32; 3]>);
        let key = |m: &Mesh, i: u32| -> Key {
            let i = i as usize;
            (
                m.positions[i].to_array().map(f32::to_bits),
                m.normals[i].to_array().map(f32::to_bits),
                m.uvs.get(i).map(|u| u.to_array().map(f32::to_bits)),
                m.colors.get(i).map(|c| c.to_array().map(f32::to_bits)),
            )
        };
        assert_eq!(a.positions.len(), b.positions.len(), "vertices");
        assert_eq!(a.normals.len(), a.positions.len());
        assert_eq!((a.uvs.len(), a.colors.len()), (b.uvs.len(), b.colors.len()));
        assert_eq!(a.triangles.len(), b.triangles.len(), "triangles");
        for (ta, tb) in a.triangles.iter().zip(&b.triangles) {
            for (&i, &j) in ta.iter().zip(tb) {
                assert_eq!(key(a, i), key(b, j));
            }
        }
        let distinct: std::collections::HashSet<Key> = (0..a.positions.len() as u32).map(|i| key(a, i)).collect();
        assert_eq!(distinct.len(), a.positions.len(), "vertices alike");
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(200))]
        /// The fast version (the shortcut of one normal a vertex where its faces are all within
        /// half the crease of their mean, the corner loop, the splits) gives the definition's
        /// bits and vertices ([`Mesh::reference_crease_normals`]).
        #[test]
        fn fast_crease_normals_are_the_plain_loops(
            n in 1usize..9,
            h in proptest::collection::vec(prop_oneof![-3.0f32..3.0, Just(0.0f32), Just(1.0f32)], 1..40),
            crease in prop_oneof![0.0f32..180.0, Just(1.0f32), Just(30.0f32), Just(45.0f32), Just(90.0f32), Just(179.0f32), Just(180.0f32)],
            seam in any::<bool>(),
            colored in any::<bool>(),
            plain in any::<bool>(),
        ) {
            let m = field(n, &h, seam, colored, plain);
            same_bits(&m.crease_normals(crease).0, &m.reference_crease_normals(crease));
        }
    }

    /// The same on the primitives (their vertices of at most [`MANY`] faces: the teapot of 4
    /// segments a patch; of 8, its lid's tip has 36, where the grouped rule holds and
    /// `grouped_vertices_give_the_plain_loops_normals` compares within 1e-5).
    #[test]
    fn fast_crease_normals_on_the_shapes() {
        for mesh in [
            primitives::sphere(24),
            primitives::cube(),
            primitives::teapot(4),
            primitives::cone(16),
            primitives::torus(16, 1.0, 0.3),
        ] {
            // Positions alone (kept in place), and with a vertex no face uses (numbered anew).
            let plain = Mesh::from_triangles(mesh.positions.clone(), mesh.triangles.clone()).expect("mesh");
            let mut unused = mesh.positions.clone();
            unused.push(Vec3::splat(7.0));
            let unused = Mesh::from_triangles(unused, mesh.triangles.clone()).expect("mesh");
            for crease in [1.0, 10.0, 30.0, 60.0, 89.0, 90.0, 91.0, 120.0, 179.0, 180.0] {
                for m in [&mesh, &plain, &unused] {
                    let fast = m.crease_normals(crease).0;
                    same_bits(&fast, &m.reference_crease_normals(crease));
                    // Taking the mesh's arrays changes nothing.
                    assert_eq!(m.clone().into_crease_normals(crease), fast);
                }
            }
        }
    }
}
