//! The vector texture sampler: a textured object's maps sampled and applied for a whole vector
//! of pixels at once: the coordinates and their exact derivatives from the triangle's planes,
//! each map filtered by `filter.rs`, the light (or, Gouraud, the vertices' light) modulated as
//! `phong_core::Lit::modulate` does.
//!
//! It covers the common cases, decided once per draw ([`VectorMaps::new`]): diffuse, specular,
//! ambient, emission, occlusion, normal, shininess (not from the alpha channel) and glTF
//! metallic-roughness maps (bump maps are normal maps by then), 8 or 16 bits, linear filters,
//! on either set of texture coordinates, vertex colours or not (not with a second set; a
//! normal map with neither: its tangents take their planes); Gouraud-shaded objects' diffuse
//! and specular maps ([`VectorMaps::lit_per_vertex`]). A vector whose coordinates are too large
//! for exact `f32` wrapping (or NaN) is left to the caller's per-pixel sampler, lit (the texels
//! that change the light itself, normal, shininess and metallic-roughness, are sampled per
//! lane here for such a vector).

use super::filter::{VectorMap, bilinear_lanes, mapped, texels_per_lane};
use super::kernel::{
    Broadcast, MAX_LANES, Planes, Prepared, V3, centres, coefficients, interpolate, perturb, position_normal,
    shade_shininess,
};
use super::lean::Lean;
use super::vector::{Portable, Vf32};
use phong_core::{Channel, Maps, MetalRough, NormalMap, TextureMap, UvTransform};

/// The maps of an object that the vector sampler covers.
#[derive(Clone, Copy)]
pub struct VectorMaps<'a> {
    diffuse: Option<VectorMap<'a>>,
    specular: Option<VectorMap<'a>>,
    ambient: Option<VectorMap<'a>>,
    emission: Option<VectorMap<'a>>,
    /// glTF's occlusion map and its strength: the ambient terms times `1 + strength·(T.r − 1)`.
    occlusion: Option<(VectorMap<'a>, f32)>,
    /// A tangent-space normal map: its levels, and the map for lanes the vector wrap cannot
    /// take. The tangents' planes are the coordinates' planes' `attr[2..6]`.
    normal: Option<(VectorMap<'a>, &'a NormalMap)>,
    /// A shininess map (its channel red, green, blue or luminance), and the map for lanes the
    /// vector wrap cannot take.
    shininess: Option<(VectorMap<'a>, Channel, &'a TextureMap)>,
    /// glTF's metallic-roughness map (`phong_core::MetalRough`), and the same for such lanes.
    metal_rough: Option<(VectorMap<'a>, &'a MetalRough)>,
    /// Vertex colours multiply the diffuse texel (`Texels::tinted`).
    tinted: bool,
    /// A map reads the second set of coordinates (never with `tinted`: they share planes).
    second: bool,
    /// Gouraud: the light was made per vertex, its primary and specular colours are the
    /// triangle's planes (see [`VectorMaps::lit_per_vertex`]).
    per_vertex: bool,
    /// The one transform of every map, applied to the coordinates' planes once (per triangle
    /// where a triangle has every lane) instead of per map and vector: see
    /// [`VectorMaps::derived`].
    fold: Option<UvTransform>,
}

impl<'a> VectorMaps<'a> {
    /// `maps` if the sampler covers them: diffuse, specular, ambient, emission, occlusion and
    /// normal maps (at least one) and no other (each as [`VectorMap`] covers it). With ambient,
    /// emission or occlusion maps the light must be prepared with [`Prepared::emission_apart`];
    /// with a normal map the coordinates' planes carry the tangents (`setup::uv_planes`).
    pub fn new(maps: &'a Maps) -> Option<VectorMaps<'a>> {
        // Every field named: a new map must be considered here.
        let Maps {
            diffuse,
            ambient,
            specular,
            emission,
            shininess,
            // The alpha decides what is drawn (the alpha test during visibility, blended objects
            // per pixel), not the colour: the sampler does not read it.
            alpha: _,
            normal,
            metal_rough,
            occlusion,
            alpha_cutoff: _,
            blend: _,
        } = maps;
        let others = shininess.as_ref().is_some_and(|(_, c)| *c == Channel::A);
        let none = diffuse.is_none()
            && specular.is_none()
            && ambient.is_none()
            && emission.is_none()
            && occlusion.is_none()
            && normal.is_none()
            && shininess.is_none()
            && metal_rough.is_none();
        if others || none {
            return None;
        }
        let of = |m: &'a Option<TextureMap>| match m {
            Some(m) => VectorMap::of(m).map(Some),
            None => Some(None),
        };
        Some(
            VectorMaps {
                diffuse: of(diffuse)?,
                specular: of(specular)?,
                ambient: of(ambient)?,
                emission: of(emission)?,
                occlusion: match occlusion {
                    Some(o) => Some((VectorMap::of(&o.map)?, o.strength)),
                    None => None,
                },
                normal: match normal {
                    Some(n) => Some((VectorMap::of(&n.map)?, n)),
                    None => None,
                },
                shininess: match shininess {
                    Some((m, c)) => Some((VectorMap::of(m)?, *c, m)),
                    None => None,
                },
                metal_rough: match metal_rough {
                    Some(mr) => Some((VectorMap::of(&mr.map)?, mr)),
                    None => None,
                },
                tinted: false,
                second: false,
                per_vertex: false,
                fold: None,
            }
            .derived(),
        )
    }

    /// Whether the sampler's general form is needed: a split light ([`VectorMaps::split`]), a
    /// map on the second set, or a map that changes the light (normal, shininess,
    /// metallic-roughness).
    pub(crate) fn full(&self) -> bool {
        self.split() || self.second || self.changes_light()
    }

    /// These maps for a Gouraud-shaded object, whose light is made per vertex into a primary
    /// and a specular colour that its planes carry: only the diffuse and specular maps apply
    /// (the reference's `Lit::modulate` with no ambient terms apart; the others need per-pixel
    /// light). `None` with a metallic-roughness map, which changes those two texels (such an
    /// object is shaded per pixel).
    pub fn lit_per_vertex(self) -> Option<VectorMaps<'a>> {
        if self.metal_rough.is_some() {
            return None;
        }
        Some(
            VectorMaps {
                ambient: None,
                emission: None,
                occlusion: None,
                normal: None,
                shininess: None,
                per_vertex: true,
                ..self
            }
            .derived(),
        )
    }

    /// Whether the light was made per vertex (see [`VectorMaps::lit_per_vertex`]).
    pub(crate) fn per_vertex(&self) -> bool {
        self.per_vertex
    }

    /// Whether a map is sampled before the light: it tilts the normal or sets the shininess.
    fn changes_light(&self) -> bool {
        self.normal.is_some() || self.shininess.is_some() || self.metal_rough.is_some()
    }

    /// Whether the ambient or emission terms have maps of their own (see
    /// [`Prepared::emission_apart`]).
    pub fn split(&self) -> bool {
        self.ambient_apart() || self.emission.is_some()
    }

    /// The rows of the coordinates' planes read (8 floats each): the vertex colours', a
    /// second set's and the tangents' are in the third.
    fn rows(&self) -> usize {
        if self.tinted || self.second || self.normal.is_some() {
            3
        } else {
            2
        }
    }

    /// Whether the ambient terms have a factor of their own (an ambient or occlusion map).
    fn ambient_apart(&self) -> bool {
        self.ambient.is_some() || self.occlusion.is_some()
    }

    /// These maps with the fields derived from the maps themselves: `second` from their sets,
    /// and `fold`, their transform folded into the coordinates where every map has the same one
    /// and reads the first set, and no map changes the light (such maps' lanes the vector wrap
    /// cannot take are sampled per lane, from the coordinates before the transform).
    fn derived(self) -> VectorMaps<'a> {
        let maps = [self.diffuse, self.specular, self.ambient, self.emission];
        let occlusion = self.occlusion.map(|(m, _)| m);
        let normal = self.normal.map(|(m, _)| m);
        let shininess = self.shininess.map(|(m, ..)| m);
        let metal_rough = self.metal_rough.map(|(m, _)| m);
        let all = || {
            maps.iter()
                .chain([&occlusion, &normal, &shininess, &metal_rough])
                .flatten()
        };
        let second = all().any(|m| m.second);
        let first = all().next().map(VectorMap::transform);
        // (A map sampled lane by lane transforms its coordinates itself.)
        let fold = match first {
            Some(t) if !second && !self.changes_light() && all().all(|m| m.transform() == t && !m.per_lane()) => {
                Some(t)
            }
            _ => None,
        };
        let folded = |m: Option<VectorMap<'a>>| if fold.is_some() { m.map(VectorMap::folded) } else { m };
        VectorMaps {
            second,
            fold,
            diffuse: folded(self.diffuse),
            specular: folded(self.specular),
            ambient: folded(self.ambient),
            emission: folded(self.emission),
            occlusion: self.occlusion.map(|(m, s)| (folded(Some(m)).unwrap_or(m), s)),
            ..self
        }
    }

    /// These maps, the diffuse texel tinted by the mesh's vertex colours where `tinted` (their
    /// planes are the coordinates' planes' `attr[2..5]`).
    pub fn tinted(self, tinted: bool) -> VectorMaps<'a> {
        VectorMaps { tinted, ..self }
    }
}

// No closures below: a closure is not compiled with its caller's AVX2, and its intrinsics
// become calls.

/// A vector's sampled colour, or (`Err`) its light where a lane could not be sampled: the
/// primary, specular and ambient colours, finished per pixel.
pub(crate) type Lanes<V> = Result<[V; 3], [[V; 3]; 3]>;

/// A vector's texture coordinates (see [`coordinates`]): the first set and the second, each
/// `[u, v, ∂u/∂x, ∂v/∂x, ∂u/∂y, ∂v/∂y]`, and `(dx, dy, w)`.
type Coords<V> = ([V; 6], [V; 6], (V, V, V));

/// A vector's shininess from a map (or from the metallic-roughness map, with its diffuse and
/// specular factors).
type ShininessLanes<V> = (Option<V>, Option<[V; 3]>);

/// How each build calls its largest steps, [`Sampling::bilinear`] and [`Sampling::textured`]:
/// inlined where the lanes are AVX2 registers (a call is compiled without the caller's AVX2,
/// and its intrinsics become calls), called in the portable build, whose lane loops inlined
/// at every map, level and entry point took minutes to compile (BENCHMARKS.md, C10).
pub(crate) trait Sampling: Vf32 {
    /// [`bilinear_lanes`].
    fn bilinear(map: &VectorMap, level: Option<Self>, u: Self, v: Self) -> [Self; 3];
    /// [`textured_lanes`].
    fn textured<const FULL: bool, const PER_VERTEX: bool>(
        prep: (&Prepared, Option<&Lean>),
        maps: &VectorMaps,
        q: [Self; 6],
        at: (Self, Self, Self),
        k: &[Self; 24],
    ) -> Lanes<Self>;
}

/// `Sampling` for the build `$v`, its two steps with the attribute `$inline`.
macro_rules! sampling {
    ($v:ty, $inline:meta) => {
        impl Sampling for $v {
            #[$inline]
            fn bilinear(map: &VectorMap, level: Option<Self>, u: Self, v: Self) -> [Self; 3] {
                bilinear_lanes(map, level, u, v)
            }
            #[$inline]
            fn textured<const FULL: bool, const PER_VERTEX: bool>(
                prep: (&Prepared, Option<&Lean>),
                maps: &VectorMaps,
                q: [Self; 6],
                at: (Self, Self, Self),
                k: &[Self; 24],
            ) -> Lanes<Self> {
                textured_lanes::<Self, FULL, PER_VERTEX>(prep, maps, q, at, k)
            }
        }
    };
}
sampling!(Portable, inline(never));
#[cfg(target_arch = "x86_64")]
sampling!(super::vector::Avx2, inline(always));
#[cfg(target_arch = "x86_64")]
sampling!(super::vector::Avx2x2, inline(always));

/// [`mapped`] at the coordinates of the set `map` reads: `uv1` where it reads the second and
/// the sampler's general form (`FULL`) is compiled, else `uv`.
#[inline(always)]
fn mapped_set<V: Sampling, const FULL: bool>(map: &VectorMap, uv: [V; 6], uv1: [V; 6]) -> Option<[V; 3]> {
    mapped(map, if FULL && map.second { uv1 } else { uv })
}

/// The coordinates where the light's planes were evaluated, `(dx, dy, w) = (x − ox, y − oy,
/// w)` (a triangle's planes share their origin and `1/w`), from their planes `k`: the first
/// set `[u, v, ∂u/∂x, ∂v/∂x, ∂u/∂y, ∂v/∂y]`, the second (the first where no map reads it or
/// `FULL` is off), and `(dx, dy, w)`. With `q = 1/w`, `u = (u/w)·w` and `∂u/∂x = (∂(u/w)/∂x −
/// u·∂q/∂x)·w`.
#[inline(always)]
fn coordinates<V: Vf32, const FULL: bool>(maps: &VectorMaps, k: &[V; 24], (dx, dy, w): (V, V, V)) -> Coords<V> {
    let uv = coordinate_set(k, 5, (dx, dy, w));
    // The second set, where a map reads it, from the planes at 11 and 14 (in the vertex
    // colours' place: such objects have none).
    let uv1 = if FULL && maps.second {
        coordinate_set(k, 11, (dx, dy, w))
    } else {
        uv
    };
    (uv, uv1, (dx, dy, w))
}

/// One set of [`coordinates`], its planes of `u/w` and `v/w` at `a` and `a + 3`.
#[inline(always)]
fn coordinate_set<V: Vf32>(k: &[V; 24], a: usize, (dx, dy, w): (V, V, V)) -> [V; 6] {
    let zero = V::splat(0.0);
    let (nqx, nqy) = (zero.sub(k[3]), zero.sub(k[4]));
    let b = a + 3;
    let u = k[a + 2].mul_add(dy, k[a + 1].mul_add(dx, k[a])).mul(w);
    let v = k[b + 2].mul_add(dy, k[b + 1].mul_add(dx, k[b])).mul(w);
    [
        u,
        v,
        u.mul_add(nqx, k[a + 1]).mul(w),
        v.mul_add(nqx, k[b + 1]).mul(w),
        u.mul_add(nqy, k[a + 2]).mul(w),
        v.mul_add(nqy, k[b + 2]).mul(w),
    ]
}

/// The coordinates' planes `k` with the maps' one transform folded in (where
/// [`VectorMaps::derived`] found one): `u'/w = a·u/w + b·v/w + o·(1/w)` for the planes of
/// `u/w` (5), `v/w` (8) and `1/w` (2), so the coordinates come transformed.
#[inline(always)]
fn folded<V: Vf32>(maps: &VectorMaps, k: [V; 24]) -> [V; 24] {
    let Some(t) = maps.fold else {
        return k;
    };
    let (l, o) = (t.linear, t.offset);
    let mut out = k;
    for j in 0..3 {
        let (u, v, q) = (k[5 + j], k[8 + j], k[2 + j]);
        out[5 + j] = V::splat(l.x_axis.x).mul_add(u, V::splat(l.y_axis.x).mul_add(v, V::splat(o.x).mul(q)));
        out[8 + j] = V::splat(l.x_axis.y).mul_add(u, V::splat(l.y_axis.y).mul_add(v, V::splat(o.y).mul(q)));
    }
    out
}

/// The normal `nrm` tilted by the normal map of `maps` (if any) in the frame of the tangent
/// interpolated from its planes at 11, 14, 17 and 20 (over `w` as the coordinates `c`).
#[inline(always)]
fn tilted<V: Sampling, const FULL: bool>(
    maps: &VectorMaps,
    nrm: V3<V>,
    k: &[V; 24],
    (uv, uv1, (dx, dy, rq)): Coords<V>,
) -> V3<V> {
    let Some((map, source)) = &maps.normal else {
        return nrm;
    };
    let mut t = [V::splat(0.0); 4];
    for (c, t) in t.iter_mut().enumerate() {
        let i = 11 + 3 * c;
        *t = k[i].add(k[i + 1].mul(dx)).add(k[i + 2].mul(dy)).mul(rq);
    }
    let texel = texels_or_per_lane::<V, FULL>(map, &source.map, uv, uv1);
    perturb(nrm, t, tangent_space(source, texel))
}

/// `map`'s RGB (`[0, 1]`) at its set's coordinates: by the vector sampler, or for a vector it
/// cannot wrap, each lane by `phong_core::TextureMap::sample` (`source`, the same map), so that
/// the light that such a vector is handed back with is right.
#[inline(always)]
fn texels_or_per_lane<V: Sampling, const FULL: bool>(
    map: &VectorMap,
    source: &TextureMap,
    uv: [V; 6],
    uv1: [V; 6],
) -> [V; 3] {
    match mapped_set::<V, FULL>(map, uv, uv1) {
        Some(texel) => texel,
        None => texels_per_lane(source, if map.second { uv1 } else { uv }),
    }
}

/// The shininess per lane where a shininess or metallic-roughness map sets it, as
/// `phong_core::Maps::sample_sets` and `phong_core::light` take it: the material's times the
/// map's factor (at least 0), the metallic-roughness map's `MetalRough::shininess` of its
/// roughness overriding a shininess map's. With the metallic-roughness map's texel, which
/// also sets the diffuse and specular texels.
#[inline(always)]
fn shininess_lanes<V: Sampling, const FULL: bool>(
    prep: &Prepared,
    maps: &VectorMaps,
    (uv, uv1): ([V; 6], [V; 6]),
) -> ShininessLanes<V> {
    let zero = V::splat(0.0);
    if let Some((map, source)) = &maps.metal_rough {
        let t = texels_or_per_lane::<V, FULL>(map, &source.map, uv, uv1);
        let r = V::splat(source.roughness).mul(t[1]).max(zero).min(V::splat(1.0));
        let a = r.mul(r);
        let a2 = a.mul(a);
        let max = V::splat(MetalRough::MAX_SHININESS);
        // 2/α² − 2; α² this small maps past the largest shininess (and 1/α² may not be finite).
        let s = V::splat(2.0).mul(a2.recip()).sub(V::splat(2.0)).max(zero).min(max);
        let s = V::select(a2.gt(V::splat(1e-12)), s, max);
        return (Some(V::splat(prep.shininess).mul(s)), Some(t));
    }
    let Some((map, channel, source)) = &maps.shininess else {
        return (None, None);
    };
    let t = texels_or_per_lane::<V, FULL>(map, source, uv, uv1);
    let f = match channel {
        // (The alpha channel is not gathered: `VectorMaps::new` leaves such maps per pixel.)
        Channel::R | Channel::A => t[0],
        Channel::G => t[1],
        Channel::B => t[2],
        Channel::Luminance => {
            let [r, g, b] = Channel::LUMINANCE;
            V::splat(r)
                .mul(t[0])
                .add(V::splat(g).mul(t[1]))
                .add(V::splat(b).mul(t[2]))
        }
    };
    (Some(V::splat(prep.shininess).mul(f.max(zero))), None)
}

/// A normal map's tangent-space normals from its texels (`[0, 1]`), as `phong_core::Maps`
/// decodes them: `2·t − 1`, `x` and `y` times the scale, `y` negated for green down.
#[inline(always)]
fn tangent_space<V: Vf32>(map: &NormalMap, t: [V; 3]) -> [V; 3] {
    let (one, two) = (V::splat(1.0), V::splat(2.0));
    let y = if map.green_down { -map.scale } else { map.scale };
    [
        t[0].mul_add(two, V::splat(-1.0)).mul(V::splat(map.scale)),
        t[1].mul_add(two, V::splat(-1.0)).mul(V::splat(y)),
        t[2].mul(two).sub(one),
    ]
}

/// A pixel the vector sampler leaves to the caller's per-pixel sampler, with its light
/// `[primary, specular, ambient]` (`phong_core::Lit`'s: the first two clamped where the options
/// clamp; the ambient terms, emission apart, count where an ambient or occlusion map has
/// them): its
/// vector's coordinates could not be wrapped exactly (NaN, or beyond ±2^21 texels).
pub type Unsampled<I> = (I, [[f32; 3]; 3]);

/// One vector of pixels at centres `(x, y)`, with interpolated position and normal `q` (with
/// `PER_VERTEX`, Gouraud's primary and specular colours) and the coordinates' planes `k`
/// ([`coefficients`]): lit, textured and combined; `Err` with the light where the sampler
/// cannot wrap the coordinates exactly.
#[inline(always)]
fn textured_lanes<V: Sampling, const FULL: bool, const PER_VERTEX: bool>(
    (prep, lean): (&Prepared, Option<&Lean>),
    maps: &VectorMaps,
    q: [V; 6],
    at: (V, V, V),
    k: &[V; 24],
) -> Lanes<V> {
    let zero = V::splat(0.0);
    let (pos, nrm) = position_normal(q);
    // The coordinates, then the maps that change the light (a normal map tilts the normal, a
    // shininess or metallic-roughness map sets the shininess), then the colour maps, and the
    // light last: the texels wait in fewer registers than the light would (BENCHMARKS.md,
    // "The textured 100k sphere's instructions"). Gouraud's light is the planes'
    // (`PER_VERTEX` is `maps.per_vertex()`).
    let c = coordinates::<V, FULL>(maps, k, at);
    let (uv, uv1, (dx, dy, w)) = c;
    let (nrm, sv, mr) = if !PER_VERTEX && FULL && maps.changes_light() {
        let nrm = tilted::<V, FULL>(maps, nrm, k, c);
        let (sv, mr) = shininess_lanes::<V, FULL>(prep, maps, (uv, uv1));
        (nrm, sv, mr)
    } else {
        (nrm, None, None)
    };
    let texels = colour_texels::<V, FULL>(maps, uv, uv1);
    let (primary, specular, ambient) = match lean {
        // The common form lit by the lean kernel (no term kept apart, no map that changes
        // the light: `Mode::Textured`), its primary and specular colours as
        // `lit_colours` makes them.
        Some(lean) if !PER_VERTEX && !FULL => {
            let [primary, specular] = super::lean::lit_lean(prep, lean, pos, nrm);
            (primary, specular, [zero; 3])
        }
        _ => {
            let lit = if PER_VERTEX {
                None
            } else {
                Some(shade_shininess(prep, pos, nrm, sv))
            };
            lit_colours::<V, FULL>(prep, maps, q, lit)
        }
    };
    let Texels { td, ts, ta, te, ao } = texels;
    let unwrapped = matches!(td, Some(None)) || matches!(ts, Some(None));
    if unwrapped || matches!(ta, Some(None)) || matches!(te, Some(None)) || matches!(ao, Some(None)) {
        return Err([primary, specular, if FULL { ambient } else { [zero; 3] }]);
    }
    let texels = Wrapped {
        td: td.flatten(),
        ts: ts.flatten(),
        ta: ta.flatten(),
        te: te.flatten(),
        ao: ao.flatten(),
    };
    Ok(modulated::<V, FULL>(
        prep,
        maps,
        k,
        (dx, dy, w),
        [primary, specular, ambient],
        mr,
        texels,
    ))
}

/// A vector's texels of the colour maps (`None` where the object has no such map; `Some(None)`
/// where its coordinates could not be wrapped exactly): diffuse, specular, ambient, emission,
/// and the occlusion's red channel.
struct Texels<V> {
    td: Option<Option<[V; 3]>>,
    ts: Option<Option<[V; 3]>>,
    ta: Option<Option<[V; 3]>>,
    te: Option<Option<[V; 3]>>,
    ao: Option<Option<V>>,
}

/// [`Texels`] where every coordinate was wrapped: `None` only where the object has no such map.
struct Wrapped<V> {
    td: Option<[V; 3]>,
    ts: Option<[V; 3]>,
    ta: Option<[V; 3]>,
    te: Option<[V; 3]>,
    ao: Option<V>,
}

/// The texels of `maps`' colour maps at coordinates `uv` (first set) and `uv1` (second).
#[inline(always)]
fn colour_texels<V: Sampling, const FULL: bool>(maps: &VectorMaps, uv: [V; 6], uv1: [V; 6]) -> Texels<V> {
    // (Matches, not closures: see `modulo`.)
    #[allow(clippy::manual_map)]
    let td = match &maps.diffuse {
        Some(m) => Some(mapped_set::<V, FULL>(m, uv, uv1)),
        None => None,
    };
    #[allow(clippy::manual_map)]
    let ts = match &maps.specular {
        Some(m) => Some(mapped_set::<V, FULL>(m, uv, uv1)),
        None => None,
    };
    // Only the general form has ambient, emission and occlusion maps.
    let ta = match (FULL, &maps.ambient) {
        (true, Some(m)) => Some(mapped_set::<V, FULL>(m, uv, uv1)),
        _ => None,
    };
    let te = match (FULL, &maps.emission) {
        (true, Some(m)) => Some(mapped_set::<V, FULL>(m, uv, uv1)),
        _ => None,
    };
    // The occlusion's red channel (`None` inside: not wrapped).
    #[allow(clippy::manual_map)]
    let ao = match (FULL, &maps.occlusion) {
        (true, Some((m, _))) => Some(match mapped_set::<V, FULL>(m, uv, uv1) {
            Some(t) => Some(t[0]),
            None => None,
        }),
        _ => None,
    };
    Texels { td, ts, ta, te, ao }
}

/// The light's colours before the maps, `[primary, specular, ambient]` as `phong_core::light`
/// gives them: from the light `lit` per pixel, else (Gouraud) the vertices' colours in `q`.
#[inline(always)]
fn lit_colours<V: Sampling, const FULL: bool>(
    prep: &Prepared,
    maps: &VectorMaps,
    q: [V; 6],
    lit: Option<super::kernel::Terms<V>>,
) -> ([V; 3], [V; 3], [V; 3]) {
    let (zero, one) = (V::splat(0.0), V::splat(1.0));
    // `FULL` is `maps.full()`, made a constant so that the common case (diffuse and specular
    // maps on the first set) does not keep the ambient terms alive, nor choose a set per map
    // (benches/HISTORY.md, "Ambient, emission, occlusion and second-set maps").
    let split = FULL && maps.split();
    let e = [prep.emission.r, prep.emission.g, prep.emission.b];
    // Gouraud: the vertices' colours interpolated, clamped per vertex where the options clamp
    // (`phong_core::light`), as the reference interpolates them.
    let (mut primary, mut specular) = (q3(q, 0), q3(q, 3));
    let ambient = match &lit {
        Some(lit) => lit.ambient,
        None => [zero; 3],
    };
    if let Some(lit) = &lit {
        for c in 0..3 {
            // `phong_core::light`: P = D + e (no emission map) + A (no ambient map), where the
            // light keeps `e` apart (split); else `lit.ambient` holds both.
            let mut p = if split {
                let mut p = lit.diffuse[c];
                if maps.emission.is_none() {
                    p = p.add(V::splat(e[c]));
                }
                if !maps.ambient_apart() {
                    p = p.add(lit.ambient[c]);
                }
                p
            } else {
                lit.ambient[c].add(lit.diffuse[c])
            };
            let mut s = lit.specular[c];
            if prep.options.clamp {
                p = p.max(zero).min(one);
                s = s.max(zero).min(one);
            }
            primary[c] = p;
            specular[c] = s;
        }
    }
    (primary, specular, ambient)
}

/// The texels' colours `(T_Kd, T_Ks, T_Ka, T_Ke, T_AO.r)` applied to the light's colours
/// `[primary, specular, ambient]` in `Lit::modulate`'s order, tinted by the vertex colours'
/// planes in `k` (at `(dx, dy)`, over `w`) and with a metallic-roughness texel `mr`'s metalness.
#[inline(always)]
fn modulated<V: Sampling, const FULL: bool>(
    prep: &Prepared,
    maps: &VectorMaps,
    k: &[V; 24],
    (dx, dy, w): (V, V, V),
    [primary, specular, ambient]: [[V; 3]; 3],
    mr: Option<[V; 3]>,
    Wrapped { td, ts, ta, te, ao }: Wrapped<V>,
) -> [V; 3] {
    let (zero, one) = (V::splat(0.0), V::splat(1.0));
    let e = [prep.emission.r, prep.emission.g, prep.emission.b];
    // Vertex colours: their planes at 11, 14, 17, over `w` as the coordinates.
    let mut tint = [one; 3];
    if maps.tinted {
        for (c, t) in tint.iter_mut().enumerate() {
            let i = 11 + 3 * c;
            *t = k[i].add(k[i + 1].mul(dx)).add(k[i + 2].mul(dy)).mul(w);
        }
    }
    // A metallic-roughness texel's metalness `m` (its blue): `T_Kd·(1 − m)`, and the specular
    // texel `0.04·(1 − m) + base⊗T_Kd·m` in the specular map's place (`Maps::sample_sets`).
    let (td, ts) = match (FULL, mr, &maps.metal_rough) {
        (true, Some(t), Some((_, source))) => {
            let m = V::splat(source.metallic).mul(t[2]).max(zero).min(one);
            let dielectric = one.sub(m);
            let d = td.unwrap_or([one; 3]);
            let base = source.base_factor;
            let mut diffuse = [zero; 3];
            let mut specular = [zero; 3];
            for (c, b) in [base.r, base.g, base.b].into_iter().enumerate() {
                diffuse[c] = d[c].mul(dielectric);
                specular[c] = V::splat(b).mul(d[c]).mul(m).add(V::splat(0.04).mul(dielectric));
            }
            (Some(diffuse), Some(specular))
        }
        _ => (td, ts),
    };
    // The occlusion's factor `1 + strength·(T.r − 1)`.
    let ao = match (ao, &maps.occlusion) {
        (Some(r), Some((_, strength))) => Some(r.sub(one).mul_add(V::splat(*strength), one)),
        _ => None,
    };
    let mut rgb = [zero; 3];
    for c in 0..3 {
        // T_Kd, tinted.
        let kd = match td {
            Some(t) => Some(t[c].mul(tint[c])),
            None if maps.tinted => Some(tint[c]),
            None => None,
        };
        let mut x = match kd {
            Some(k) => primary[c].mul(k),
            None => primary[c],
        };
        // `Lit::modulate`'s order: P⊗T_Kd + e⊗T_Ke + A⊗T_Ka·T_AO + S⊗T_Ks (T_Ka is T_Kd
        // without an ambient map).
        if let Some(ke) = te {
            x = x.add(V::splat(e[c]).mul(ke[c]));
        }
        if FULL && maps.ambient_apart() {
            let mut ka = match (ta, kd) {
                (Some(t), _) => t[c],
                (None, Some(k)) => k,
                (None, None) => one,
            };
            if let Some(f) = ao {
                ka = ka.mul(f);
            }
            x = x.add(ambient[c].mul(ka));
        }
        let s = match ts {
            Some(t) => specular[c].mul(t[c]),
            None => specular[c],
        };
        x = x.add(s);
        x = V::select(x.finite(), x, zero);
        if prep.options.clamp {
            x = x.max(zero).min(one);
        }
        rgb[c] = x;
    }
    rgb
}

/// Lanes `k..k + 3` of `q`.
#[inline(always)]
fn q3<V: Copy>(q: [V; 6], k: usize) -> [V; 3] {
    [q[k], q[k + 1], q[k + 2]]
}

/// Hands the first `m` lanes of a [`Sampling::textured`] result to `out(lane, rgb)`, or their light to
/// `unsampled` with their index `at(lane)`.
#[inline(always)]
fn emit<V: Vf32, I>(
    r: Lanes<V>,
    m: usize,
    at: impl Fn(usize) -> I,
    mut out: impl FnMut(I, [f32; 3]),
    unsampled: &mut Vec<Unsampled<I>>,
) {
    match r {
        Ok(rgb) => {
            let rgb = rgb.map(V::to_array);
            for i in 0..m {
                out(at(i), [rgb[0].as_ref()[i], rgb[1].as_ref()[i], rgb[2].as_ref()[i]]);
            }
        }
        Err(light) => {
            let light = light.map(|t| t.map(V::to_array));
            for i in 0..m {
                unsampled.push((at(i), light.map(|t| [0, 1, 2].map(|c| t[c].as_ref()[i]))));
            }
        }
    }
}

/// [`super::kernel::shade_batch_lit`] with the diffuse and specular maps applied by the vector
/// sampler: `out(i, rgb)` takes pixel `i`'s colour, `clamp(clamp(P)⊗T_Kd + clamp(S)⊗T_Ks)`
/// (phong-core's `Lit::modulate`, clamps where the options clamp), or `unsampled` its light.
/// `lane(i)` gives pixel `i`'s centre, its triangle's planes and the planes of its texture
/// coordinates.
#[inline(always)]
pub(crate) fn shade_batch_textured<'p, V: Sampling, const FULL: bool, const PER_VERTEX: bool>(
    prep: (&Prepared, Option<&Lean>),
    maps: &VectorMaps,
    n: usize,
    lane: impl Fn(usize) -> (f32, f32, &'p Planes, &'p Planes),
    mut out: impl FnMut(usize, [f32; 3]),
    unsampled: &mut Vec<Unsampled<usize>>,
) {
    let mut start = 0;
    while start < n {
        // Each lane's centre, planes and coordinates' planes (`origin`, `1/w`, `u/w`, `v/w`
        // and, tinted, the vertex colours over `w`: the planes' first 20 floats).
        let m = (n - start).min(V::N);
        let mut xs = V::A::default();
        let mut ys = V::A::default();
        let (_, _, p0, uv0) = lane(start);
        let mut planes: [&Planes; MAX_LANES] = [p0; MAX_LANES];
        let mut uv: [&Planes; MAX_LANES] = [uv0; MAX_LANES];
        for i in 0..V::N {
            let (x, y, p, q) = lane(start + i.min(m - 1));
            xs.as_mut()[i] = x;
            ys.as_mut()[i] = y;
            planes[i] = p;
            uv[i] = q;
        }
        let (xs, ys) = (V::from_array(xs), V::from_array(ys));
        let (q, at) = interpolate::<V>(&planes[..V::N], 6, xs, ys);
        let k = folded(maps, coefficients::<V>(&uv[..V::N], maps.rows()));
        let r = V::textured::<FULL, PER_VERTEX>(prep, maps, q, at, &k);
        emit::<V, usize>(r, m, |i| start + i, &mut out, unsampled);
        start += m;
    }
}

/// [`shade_batch_textured`] for the pixels of one triangle, its `planes` and coordinates'
/// planes `uv` broadcast (as [`super::group::shade_group`]): `pixels` are `row << 16 |
/// column` from `origin`, `out(pixel, rgb)` takes each one's colour or `unsampled` its light.
/// Whole vectors only: returns how many of `pixels` (from the start) were shaded.
#[inline(always)]
pub(crate) fn shade_group_textured<V: Sampling, const FULL: bool, const PER_VERTEX: bool>(
    prep: (&Prepared, Option<&Lean>),
    maps: &VectorMaps,
    (planes, uv): (&Planes, &Planes),
    origin: (u32, u32),
    pixels: &[u32],
    mut out: impl FnMut(u32, [f32; 3]),
    unsampled: &mut Vec<Unsampled<u32>>,
) -> usize {
    let full = pixels.len() / V::N * V::N;
    if full == 0 {
        return 0;
    }
    let planes = Broadcast::<V>::new(planes, 6);
    let k = folded(maps, coefficients::<V>(&[uv], maps.rows()));
    for chunk in pixels[..full].chunks_exact(V::N) {
        let (x, y) = centres::<V>(origin, chunk);
        let (q, at) = planes.at(x, y, 6);
        let r = V::textured::<FULL, PER_VERTEX>(prep, maps, q, at, &k);
        emit::<V, u32>(r, V::N, |i| chunk[i], &mut out, unsampled);
    }
    full
}

#[cfg(test)]
mod tests {
    use super::*;
    use phong_core::{Sampler, Texture, Wrap};
    use std::sync::Arc;

    /// The maps' transform is folded into the coordinates where every map has the same one and
    /// none changes the light; else each map applies its own.
    #[test]
    fn one_transform_is_folded() {
        let texture = Arc::new(Texture::new(4, 4, &[[65535u16; 4]; 16], 8).unwrap());
        let map = |t: UvTransform| TextureMap {
            texture: texture.clone(),
            sampler: Sampler::trilinear(Wrap::Repeat),
            transform: t,
            set: 0,
        };
        let a = UvTransform::scale_offset(glam::Vec2::new(4.0, 2.0), glam::Vec2::new(0.5, 0.0));
        let b = UvTransform::scale_offset(glam::Vec2::new(4.0, 2.0), glam::Vec2::ZERO);
        let maps = |d: UvTransform, s: UvTransform| Maps {
            diffuse: Some(map(d)),
            specular: Some(map(s)),
            ..Maps::default()
        };
        let same = maps(a, a);
        let v = VectorMaps::new(&same).unwrap();
        assert_eq!(v.fold, Some(a));
        // A folded map reads its coordinates as they come; the others transform them. A 2×1
        // image, red then green, at u = 0.25: red as it comes, green past the offset of ½.
        let two = Arc::new(Texture::new(2, 1, &[[65535, 0, 0, 65535], [0, 65535, 0, 65535]], 8).unwrap());
        let nearest = TextureMap {
            texture: two,
            sampler: Sampler::nearest(Wrap::Repeat),
            transform: a,
            set: 0,
        };
        let plain = VectorMap::of(&nearest).unwrap();
        let uv = [0.25, 0.5, 0.0, 0.0, 0.0, 0.0].map(Portable::splat);
        let red = |m: VectorMap| mapped::<Portable>(&m, uv).unwrap()[0].0[0];
        assert_eq!((red(plain.folded()), red(plain)), (1.0, 0.0));
        let other = maps(a, b);
        assert_eq!(VectorMaps::new(&other).unwrap().fold, None);
        // A map sampled lane by lane (`GL_LINEAR_MIPMAP_NEAREST`) transforms its coordinates
        // itself: nothing folds.
        let mut per_lane = maps(a, a);
        per_lane.specular.as_mut().unwrap().sampler.mip = phong_core::MipFilter::Nearest;
        let v = VectorMaps::new(&per_lane).unwrap();
        assert!(v.specular.unwrap().per_lane() && !v.diffuse.unwrap().per_lane());
        assert_eq!(v.fold, None);
        // A shininess map changes the light: its lanes outside the vector wrap are sampled per
        // lane, from the coordinates before the transform.
        let mut shiny = maps(a, a);
        shiny.shininess = Some((map(a), Channel::R));
        assert_eq!(VectorMaps::new(&shiny).unwrap().fold, None);
        // Gouraud: the shininess map does not apply, so the colour maps' one transform folds.
        assert_eq!(VectorMaps::new(&shiny).unwrap().lit_per_vertex().unwrap().fold, Some(a));
    }
}
