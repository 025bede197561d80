//! The vector texture filter: one map's texels for a whole vector of texture coordinates, as
//! `phong_core::Texture::sample` filters one (bilinear in a level, the two levels of
//! `GL_LINEAR_MIPMAP_LINEAR` blended at `phong_core::Texture::lod`'s level of detail,
//! repeat/clamp/mirror wrap), the texels of every lane fetched by gathers, one per corner and
//! level ([`Vf32::gather_rgb8`], [`Vf32::gather_rgb16`]). Maps of other filters (a nearest
//! mipmap, nearest texels with mipmaps, magnification and minification filters that differ:
//! glTF samplers) are sampled lane by lane by `phong_core`'s sampler. The sampler
//! (`sampler.rs`) calls it for each of an object's maps.

use super::sampler::Sampling;
use super::vector::Vf32;
use phong_core::{Filter, MipFilter, TextureMap, UvTransform, Wrap};

/// The most mipmap levels (a 16384 side has 15).
const MAX_LEVELS: usize = 16;

/// One level's texels, in their storage.
#[derive(Clone, Copy)]
enum Texels<'a> {
    Eight(&'a [[u8; 4]]),
    Sixteen(&'a [[u16; 4]]),
}

/// A map in the form the vector sampler reads: its levels' sizes and texels.
#[derive(Clone, Copy)]
pub struct VectorMap<'a> {
    levels: [(u32, u32, Texels<'a>); MAX_LEVELS],
    count: usize,
    wrap: (Wrap, Wrap),
    mipmaps: bool,
    transform: UvTransform,
    /// Reads the second set of texture coordinates ([`phong_core::TextureMap::set`]).
    pub(super) second: bool,
    /// 8-bit, repeated both ways, level 0 a power of two each way (and so every level):
    /// [`Vf32::gather_quad_rgb8`] wraps and fetches.
    quad8: bool,
    /// From storage units to `[0, 1]`: `1/255` or `1/65535`.
    unit: f32,
    /// `GL_NEAREST` both ways without mipmaps: level 0's texel under the coordinates.
    nearest: bool,
    /// The coordinates come transformed already (the sampler folded `transform` into the
    /// coordinates' planes: [`VectorMap::folded`]).
    folded: bool,
    /// A map of other filters, sampled lane by lane ([`texels_per_lane`]).
    per_lane: Option<&'a TextureMap>,
}

impl<'a> VectorMap<'a> {
    /// `map` in the sampler's form: filtered by vector where linear both ways with mipmaps
    /// blended (`GL_LINEAR_MIPMAP_LINEAR`) or none (`GL_LINEAR`), or nearest both ways without
    /// mipmaps (`GL_NEAREST`); else sampled lane by lane. `None` past the levels it holds.
    pub(super) fn of(map: &'a TextureMap) -> Option<VectorMap<'a>> {
        let s = map.sampler;
        let linear = s.mag == Filter::Linear && s.min == Filter::Linear && s.mip != MipFilter::Nearest;
        let nearest = s.mag == Filter::Nearest && s.min == Filter::Nearest && s.mip == MipFilter::None;
        let t = &map.texture;
        let count = t.level_count();
        if count > MAX_LEVELS {
            return None;
        }
        let mut levels = [(1, 1, Texels::Eight(&[])); MAX_LEVELS];
        for (i, l) in levels.iter_mut().enumerate().take(count) {
            *l = match (t.level8(i), t.level16(i)) {
                (Some((w, h, texels)), _) => (w, h, Texels::Eight(texels)),
                (None, Some((w, h, texels))) => (w, h, Texels::Sixteen(texels)),
                (None, None) => return None,
            };
        }
        Some(VectorMap {
            levels,
            count,
            wrap: (s.wrap_u, s.wrap_v),
            mipmaps: s.mip == MipFilter::Linear,
            transform: map.transform,
            second: map.set >= 1,
            quad8: matches!(levels[0].2, Texels::Eight(_))
                && s.wrap_u == Wrap::Repeat
                && s.wrap_v == Wrap::Repeat
                && levels[0].0.is_power_of_two()
                && levels[0].1.is_power_of_two(),
            unit: if t.bits() == 8 { 1.0 / 255.0 } else { 1.0 / 65535.0 },
            nearest,
            folded: false,
            per_lane: (!linear && !nearest).then_some(map),
        })
    }

    /// The map's transform of texture coordinates.
    pub(super) fn transform(&self) -> UvTransform {
        self.transform
    }

    /// Whether its lanes are sampled one by one (filters the vector filter does not take).
    pub(super) fn per_lane(&self) -> bool {
        self.per_lane.is_some()
    }

    /// This map reading coordinates that its transform was applied to already.
    pub(super) fn folded(self) -> VectorMap<'a> {
        VectorMap { folded: true, ..self }
    }
}

// No closures below: a closure is not compiled with its caller's AVX2, and its intrinsics
// become calls.

/// Whole numbers `i` modulo `p` into `0..p`, `inv` about `1/p` (the quotient's rounding can
/// leave `r` one period out).
#[inline(always)]
fn modulo<V: Vf32>(i: V, p: V, inv: V) -> V {
    let zero = V::splat(0.0);
    let r = i.sub(p.mul(i.mul(inv).floor()));
    let r = V::select(r.lt(zero), r.add(p), r);
    V::select(r.ge(p), r.sub(p), r)
}

/// Mirrored repeat of whole numbers `i` into `0..n` (`inv` about `1/n`).
#[inline(always)]
fn mirror<V: Vf32>(i: V, n: V, inv: V) -> V {
    let two = n.add(n);
    let p = modulo(i, two, inv.mul(V::splat(0.5)));
    V::select(p.lt(n), p, two.sub(V::splat(1.0)).sub(p))
}

/// Whole numbers `i` wrapped into `0..n` (`n` per lane, `inv` about `1/n`), as `phong_core`'s
/// `wrap`: `(wrap(i), wrap(i + 1))`.
#[inline(always)]
fn wrap_pair<V: Vf32>(mode: Wrap, i: V, n: V, inv: V) -> (V, V) {
    let one = V::splat(1.0);
    let zero = V::splat(0.0);
    match mode {
        Wrap::Repeat => {
            let a = modulo(i, n, inv);
            let b = a.add(one);
            (a, V::select(b.ge(n), zero, b))
        }
        Wrap::Clamp => {
            let last = n.sub(one);
            (i.max(zero).min(last), i.add(one).max(zero).min(last))
        }
        Wrap::Mirror => (mirror(i, n, inv), mirror(i.add(one), n, inv)),
    }
}

/// `c·a + d·b`.
#[inline(always)]
fn linear<V: Vf32>(a: V, b: V, c: f32, d: f32) -> V {
    V::splat(c).mul(a).add(V::splat(d).mul(b))
}

/// Whether `-limit < x < limit` (false for NaN).
#[inline(always)]
fn within<V: Vf32>(x: V, limit: f32) -> V::M {
    V::and(x.lt(V::splat(limit)), x.gt(V::splat(-limit)))
}

/// `λ = ½·log2 ρ²` as `phong_core::Texture::lod` computes it (the same polynomial).
#[inline(always)]
fn half_log2<V: Vf32>(rho2: V) -> V {
    let (e, m) = rho2.frexp();
    let t = m.sub(V::splat(1.0));
    let p = t.mul_add(V::splat(0.045_268_293), V::splat(-0.193_516_53));
    let p = t.mul_add(p, V::splat(0.415_245_56));
    let p = t.mul_add(p, V::splat(-0.708_865_2));
    let p = t.mul_add(p, V::splat(1.441_879_9));
    t.mul_add(p, e).mul(V::splat(0.5))
}

/// The bilinear filter of every lane's level `level` (a whole number per lane; `None`: level 0
/// in every lane) at `(u, v)`, RGB in texel units (0 to 255): the levels present gathered one
/// by one, each lane keeping its own.
#[inline(always)]
pub(super) fn bilinear_lanes<V: Vf32>(map: &VectorMap, level: Option<V>, u: V, v: V) -> [V; 3] {
    let (zero, one, half) = (V::splat(0.0), V::splat(1.0), V::splat(0.5));
    // The lanes' levels: usually one (checked by vector), else scanned.
    let (level, lo, hi) = match level {
        None => (zero, 0, 0),
        Some(level) => {
            let l = level.to_array();
            let first = l.as_ref()[0];
            if !V::any(V::or(level.lt(V::splat(first)), level.gt(V::splat(first)))) {
                let f = (first as usize).min(map.count - 1);
                (level, f, f)
            } else {
                let (mut lo, mut hi) = (f32::INFINITY, 0.0f32);
                for &x in l.as_ref() {
                    lo = lo.min(x);
                    hi = hi.max(x);
                }
                (level, lo as usize, (hi as usize).min(map.count - 1))
            }
        }
    };
    // A level's size: the halved size rounded down, at least 1 (one level: its own).
    let (w, h, inv_w, inv_h) = if lo == hi {
        let (w, h) = (map.levels[lo].0 as f32, map.levels[lo].1 as f32);
        (V::splat(w), V::splat(h), V::splat(1.0 / w), V::splat(1.0 / h))
    } else {
        let (w0, h0) = (map.levels[0].0 as f32, map.levels[0].1 as f32);
        let scale = level.mul(V::splat(-1.0)).pow2i();
        let w = V::splat(w0).mul(scale).floor().max(one);
        let h = V::splat(h0).mul(scale).floor().max(one);
        (w, h, w.recip(), h.recip())
    };
    let (fx, fy) = (u.mul_add(w, V::splat(-0.5)), v.mul_add(h, V::splat(-0.5)));
    let (ix, iy) = (fx.floor(), fy.floor());
    let (a, b) = (fx.sub(ix), fy.sub(iy));
    let weights = [
        one.sub(a).mul(one.sub(b)),
        a.mul(one.sub(b)),
        one.sub(a).mul(b),
        a.mul(b),
    ];
    if let (true, true, Texels::Eight(t)) = (map.quad8, lo == hi, map.levels[lo].2) {
        let (lw, lh) = (map.levels[lo].0, map.levels[lo].1);
        let mut sum = [zero; 3];
        for (texel, wt) in V::gather_quad_rgb8(t, lw, lh, ix, iy).into_iter().zip(weights) {
            for c in 0..3 {
                sum[c] = texel[c].mul_add(wt, sum[c]);
            }
        }
        return sum;
    }
    let (x0, x1) = wrap_pair(map.wrap.0, ix, w, inv_w);
    let (y0, y1) = wrap_pair(map.wrap.1, iy, h, inv_h);
    let mut out = [zero; 3];
    for l in lo..=hi {
        let (lw, lh, texels) = map.levels[l];
        let corners = [(x0, y0), (x1, y0), (x0, y1), (x1, y1)];
        let mut sum = [zero; 3];
        for ((x, y), wt) in corners.into_iter().zip(weights) {
            let t = match texels {
                Texels::Eight(t) => V::gather_rgb8(t, lw, lh, x, y),
                Texels::Sixteen(t) => V::gather_rgb16(t, lw, lh, x, y),
            };
            for c in 0..3 {
                sum[c] = t[c].mul_add(wt, sum[c]);
            }
        }
        if lo == hi {
            return sum;
        }
        let mine = V::and(
            level.gt(V::splat(l as f32).sub(half)),
            level.lt(V::splat(l as f32).add(half)),
        );
        for c in 0..3 {
            out[c] = V::select(mine, sum[c], out[c]);
        }
    }
    out
}

/// `GL_NEAREST` without mipmaps: level 0's texel under `(u, v)` for every lane, RGB in texel
/// units, as `phong_core`'s nearest filter (`floor(u·w)`, wrapped).
#[inline(always)]
fn nearest_lanes<V: Vf32>(map: &VectorMap, u: V, v: V) -> [V; 3] {
    let (lw, lh, texels) = map.levels[0];
    let (w, h) = (lw as f32, lh as f32);
    let (x, _) = wrap_pair(map.wrap.0, u.mul(V::splat(w)).floor(), V::splat(w), V::splat(1.0 / w));
    let (y, _) = wrap_pair(map.wrap.1, v.mul(V::splat(h)).floor(), V::splat(h), V::splat(1.0 / h));
    match texels {
        Texels::Eight(t) => V::gather_rgb8(t, lw, lh, x, y),
        Texels::Sixteen(t) => V::gather_rgb16(t, lw, lh, x, y),
    }
}

/// The map's RGB (0 to 255) at `(u, v)` (transformed) with screen derivatives
/// `d = [∂u/∂x, ∂v/∂x, ∂u/∂y, ∂v/∂y]`: `phong_core::Texture::sample` at
/// `phong_core::Texture::lod`, for every lane.
#[inline(always)]
fn sample<V: Sampling>(map: &VectorMap, u: V, v: V, d: [V; 4]) -> [V; 3] {
    if map.nearest {
        return nearest_lanes(map, u, v);
    }
    let (zero, one) = (V::splat(0.0), V::splat(1.0));
    let (w0, h0) = (map.levels[0].0 as f32, map.levels[0].1 as f32);
    let last = (map.count - 1) as f32;
    if !map.mipmaps {
        return V::bilinear(map, None, u, v);
    }
    let (ax, bx) = (d[0].mul(V::splat(w0)), d[1].mul(V::splat(h0)));
    let (ay, by) = (d[2].mul(V::splat(w0)), d[3].mul(V::splat(h0)));
    let rho2 = ax.mul(ax).add(bx.mul(bx)).max(ay.mul(ay).add(by.mul(by)));
    // λ > 0 exactly where ρ² > 1 (and not for NaN): minified. No lane minified: level 0.
    let minify = rho2.gt(one);
    if !V::any(minify) {
        return V::bilinear(map, None, u, v);
    }
    let lod = half_log2(rho2).min(V::splat(last));
    let whole = lod.floor();
    let (level, t) = (V::select(minify, whole, zero), V::select(minify, lod.sub(whole), zero));
    let mut texel = V::bilinear(map, Some(level), u, v);
    if V::any(t.gt(zero)) {
        let b = V::bilinear(map, Some(level.add(one).min(V::splat(last))), u, v);
        for c in 0..3 {
            texel[c] = b[c].sub(texel[c]).mul_add(t, texel[c]);
        }
    }
    texel
}

/// A map's RGB (`[0, 1]`) at the mesh's coordinates and their derivatives
/// `uv = [u, v, ∂u/∂x, ∂v/∂x, ∂u/∂y, ∂v/∂y]` (through the map's transform, unless
/// [folded](VectorMap::folded)); `None` where a lane's coordinates are too large for exact
/// `f32` wrapping (beyond ±2^21 texels) or NaN.
#[inline(always)]
pub(super) fn mapped<V: Sampling>(map: &VectorMap, uv: [V; 6]) -> Option<[V; 3]> {
    if let Some(source) = map.per_lane {
        // (Never folded: `VectorMaps::derived`.)
        return Some(texels_per_lane(source, uv));
    }
    let (l, o) = (map.transform.linear, map.transform.offset);
    let (w0, h0) = (map.levels[0].0 as f32, map.levels[0].1 as f32);
    let [u, v, ux, vx, uy, vy] = uv;
    let (tu, tv, d) = if map.folded {
        (u, v, [ux, vx, uy, vy])
    } else {
        (
            linear(u, v, l.x_axis.x, l.y_axis.x).add(V::splat(o.x)),
            linear(u, v, l.x_axis.y, l.y_axis.y).add(V::splat(o.y)),
            [
                linear(ux, vx, l.x_axis.x, l.y_axis.x),
                linear(ux, vx, l.x_axis.y, l.y_axis.y),
                linear(uy, vy, l.x_axis.x, l.y_axis.x),
                linear(uy, vy, l.x_axis.y, l.y_axis.y),
            ],
        )
    };
    let limit = 2_097_152.0;
    let inside = V::and(within(tu.mul(V::splat(w0)), limit), within(tv.mul(V::splat(h0)), limit));
    if V::any(V::not(inside)) {
        return None;
    }
    let mut t = sample(map, tu, tv, d);
    for c in &mut t {
        *c = c.mul(V::splat(map.unit));
    }
    Some(t)
}

/// A map's RGB (`[0, 1]`) lane by lane by `phong_core::TextureMap::sample` at the map's set's
/// coordinates `uv` (before its transform): for maps of filters the vector filter does not
/// take, and for lanes whose coordinates its wrap cannot take (NaN, or past ±2^21 texels).
#[inline(never)]
pub(super) fn texels_per_lane<V: Vf32>(map: &TextureMap, uv: [V; 6]) -> [V; 3] {
    let a = uv.map(V::to_array);
    let mut out = [V::A::default(); 3];
    for i in 0..V::N {
        let at = |k: usize| a[k].as_ref()[i];
        let t = map.sample(
            glam::Vec2::new(at(0), at(1)),
            glam::Vec2::new(at(2), at(3)),
            glam::Vec2::new(at(4), at(5)),
        );
        for c in 0..3 {
            out[c].as_mut()[i] = t[c];
        }
    }
    out.map(V::from_array)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simd::vector::Portable;
    use phong_core::{Maps, Sampler};
    use std::sync::Arc;

    struct Lcg(u64);
    impl Lcg {
        fn next(&mut self) -> f32 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (self.0 >> 40) as f32 / (1u64 << 24) as f32
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    fn sample_avx2(map: &VectorMap, u: [f32; 8], v: [f32; 8], d: [[f32; 8]; 4]) -> [[f32; 8]; 3] {
        use crate::simd::vector::Avx2;
        let d = [0, 1, 2, 3].map(|k| Avx2::from_array(d[k]));
        let t = sample(map, Avx2::from_array(u), Avx2::from_array(v), d);
        [t[0].to_array(), t[1].to_array(), t[2].to_array()]
    }

    /// The vector sampler against `phong_core::Texture::sample` at `Texture::lod`: random 8-
    /// and 16-bit textures of odd and even sizes, every wrap (the same both ways and not),
    /// trilinear, bilinear and nearest, coordinates over several copies of the image and
    /// derivatives from magnified to the last level (now and then a ρ² past the largest float,
    /// or NaN), on both builds. Within 10⁻⁴ of the value (0.026/255; measured 3·10⁻⁶): they
    /// differ in rounding only.
    #[test]
    fn the_vector_sampler_is_texture_sample() {
        let mut r = Lcg(5);
        let mut worst = 0.0f32;
        for (w, h, bits) in [
            (1, 1, 8),
            (13, 7, 8),
            (64, 32, 8),
            (5, 40, 16),
            (128, 128, 8),
            (33, 17, 16),
        ] {
            let texels: Vec<[u16; 4]> = (0..w * h)
                .map(|_| [0, 0, 0].map(|_: u16| (r.next() * 65535.0) as u16))
                .map(|[a, b, c]| [a, b, c, 65535])
                .collect();
            let texture = Arc::new(phong_core::Texture::new(w, h, &texels, bits).unwrap());
            for wrap in [Wrap::Repeat, Wrap::Clamp, Wrap::Mirror] {
                // Each filter with one wrap both ways, and with another for v.
                let other = match wrap {
                    Wrap::Repeat => Wrap::Clamp,
                    Wrap::Clamp => Wrap::Mirror,
                    Wrap::Mirror => Wrap::Repeat,
                };
                let filters = [
                    Sampler::trilinear(wrap),
                    Sampler::bilinear(wrap),
                    Sampler::nearest(wrap),
                ];
                let mixed = filters.map(|s| Sampler { wrap_v: other, ..s });
                for sampler in filters.into_iter().chain(mixed) {
                    let maps = Maps {
                        diffuse: Some(TextureMap {
                            texture: texture.clone(),
                            sampler,
                            transform: UvTransform::default(),
                            set: 0,
                        }),
                        ..Maps::default()
                    };
                    let map = VectorMap::of(maps.diffuse.as_ref().expect("set")).expect("covered");
                    for round in 0..200 {
                        let mut u = [0f32; 8];
                        let mut v = [0f32; 8];
                        let mut d = [[0f32; 8]; 4];
                        for i in 0..8 {
                            u[i] = r.next() * 6.0 - 3.0;
                            v[i] = r.next() * 6.0 - 3.0;
                            // Texels per pixel from 1/8 to 256; every fourth vector magnified in
                            // every lane (ρ below 2^-½ texels per pixel: level 0 alone).
                            let scale = if round % 4 == 0 {
                                (r.next() * 2.5 - 3.0).exp2() / w.max(h) as f32
                            } else {
                                (r.next() * 11.0 - 3.0).exp2() / w.max(h) as f32
                            };
                            for dk in &mut d {
                                dk[i] = (r.next() * 2.0 - 1.0) * scale;
                            }
                            // Now and then a lane's ρ² past the largest float, or NaN.
                            if round % 16 == 5 && i == 2 {
                                d[0][i] = 1e30;
                            }
                            if round % 16 == 9 && i == 3 {
                                d[1][i] = f32::NAN;
                            }
                        }
                        let want: Vec<[f32; 4]> = (0..8)
                            .map(|i| {
                                let dx = glam::Vec2::new(d[0][i], d[1][i]);
                                let dy = glam::Vec2::new(d[2][i], d[3][i]);
                                texture.sample(&sampler, glam::Vec2::new(u[i], v[i]), texture.lod(dx, dy))
                            })
                            .collect();
                        let mut builds = vec![{
                            let t = sample(
                                &map,
                                Portable::from_array(u),
                                Portable::from_array(v),
                                d.map(Portable::from_array),
                            );
                            [t[0].to_array(), t[1].to_array(), t[2].to_array()]
                        }];
                        #[cfg(target_arch = "x86_64")]
                        if crate::simd::avx2_available() {
                            // SAFETY: the CPU has AVX2 and FMA (checked just above).
                            builds.push(unsafe { sample_avx2(&map, u, v, d) });
                        }
                        for got in builds {
                            for i in 0..8 {
                                for c in 0..3 {
                                    let e = (got[c][i] * map.unit - want[i][c]).abs();
                                    worst = worst.max(e);
                                    assert!(
                                        e < 1e-4,
                                        "{w}×{h} {sampler:?} uv ({}, {}) d {:?}: {} vs {}",
                                        u[i],
                                        v[i],
                                        [d[0][i], d[1][i], d[2][i], d[3][i]],
                                        got[c][i] * map.unit,
                                        want[i][c]
                                    );
                                }
                            }
                        }
                    }
                }
            }
        }
        eprintln!("largest difference {worst:e}");
    }
}
