//! The lean colour kernel: [`kernel::shade`](super::kernel)'s colour for the objects most
//! scenes have (Phong or Blinn-Phong without energy normalisation, directional and point
//! lights without spots, attenuations that never reach zero), with what the general kernel
//! decides per lane decided once per pixel or once per object:
//! - a variant of the code per highlight model and gate, and the lights ordered by kind (one
//!   loop per kind), so that no light tests what it is;
//! - the lights' constants stored as whole vectors ([`Splat`]), read as memory operands;
//! - one colour accumulator, and NaN and the clamp handled once, at the end (or left to the
//!   8-bit encoding, which does both): every contribution is finite and not negative here
//!   (factors in `(0, 1/k0]`);
//! - the normal's and the view's validity folded into the vectors once per pixel (a zero
//!   normal or view gives a zero highlight), not tested per light;
//! - diffuse by `max(N·L, 0)`; a light's ambient only where it has one; the highlight from
//!   the dot products the diffuse term takes (see [`lean_variant`]);
//! - the highlight's `pow` by shorter polynomials ([`pow_lean`]), and skipped for a vector
//!   whose every lane is below the light's threshold `t = (ε / (f_max·s_max))^(1/s)`: there
//!   `f·s_c·x^s < ε = 0.05/255` on every channel (`f_max` the largest attenuation factor,
//!   `1/k0`; `s_max` the largest channel of `s_m ⊗ s_l`).
//!
//! The colour differs from `shade`'s by `pow_lean`'s error (below 1e-4 of a highlight), the
//! skipped highlights (at most `n·ε` for `n` lights) and the rounding of the sums in another
//! order; the tests hold it to 1/255 of the reference.

use super::kernel::{Kind, Prepared, V3, fin};
use super::vector::{Splat, Vf32};
use phong_core::{Color, Normalization, SpecularModel, View};

/// The largest highlight a skipped vector may lose, per light and channel.
const SKIP_EPSILON: f32 = 0.05 / 255.0;

/// One light as the lean kernel reads it: its constants in whole vectors ([`Splat`]: memory
/// operands, not broadcasts) and what it decides once per object.
#[derive(Clone, Debug)]
struct LeanLight {
    /// A point light (else directional).
    point: bool,
    /// A point light whose factor is not 1 (`k ≠ (1, 0, 0)`).
    attenuated: bool,
    /// `a_m ⊗ a_l ≠ 0`.
    ambient: bool,
    /// No highlight can pass `threshold` (no specular colour, or no specular model).
    dark: bool,
    /// The position, or the unit direction to the light.
    at: [Splat; 3],
    /// The attenuation's `k0, k1, k2`.
    k: [Splat; 3],
    /// Directional: `|L|² + 1` (the Blinn half vector's `|L + V|² = |L|² + 2 L·V + 1`).
    ll1: Splat,
    amb: [Splat; 3],
    dif: [Splat; 3],
    spe: [Splat; 3],
    threshold: Splat,
}

/// What the lean kernel needs beyond [`Prepared`]: per light, its constants and the highlight
/// threshold, the lights ordered by kind (attenuated point lights, then point lights of factor
/// 1, then directional ones: one loop of code without a test of kind per kind); and the
/// highlight's model and gate, which choose the kernel's variant.
#[derive(Clone, Debug)]
pub struct Lean {
    lights: Vec<LeanLight>,
    /// Where the point lights of factor 1 and the directional lights start in `lights`.
    plain: usize,
    directional: usize,
    /// (Boxed: a plan's modes stay small.)
    base: Box<[Splat; 3]>,
    blinn: bool,
    gate: bool,
}

/// Three channels or coordinates as [`Splat`]s.
fn splat3(c: [f32; 3]) -> [Splat; 3] {
    c.map(Splat::new)
}

impl Lean {
    /// The lean kernel's data for `p`, where it shades `p`'s objects (see the module); `None`
    /// where the general kernel must.
    pub fn of(p: &Prepared) -> Option<Lean> {
        let o = &p.options;
        let model_ok = matches!(
            o.specular,
            SpecularModel::Phong | SpecularModel::BlinnPhong | SpecularModel::None
        );
        if !model_ok || o.normalization != Normalization::None || p.shininess.is_nan() {
            return None;
        }
        let mut lights = Vec::with_capacity(p.lights.len());
        for light in &p.lights {
            let (f_max, point, at, k) = match light.kind {
                Kind::Directional { to_light } => (1.0, false, to_light, [1.0, 0.0, 0.0]),
                Kind::Positional { spot: Some(_), .. } => return None,
                Kind::Positional { position, k, .. } => {
                    if !(k[0] > 0.0 && k[1] >= 0.0 && k[2] >= 0.0 && k.iter().all(|c| c.is_finite())) {
                        return None;
                    }
                    (1.0 / k[0], true, position, k)
                }
            };
            let s_max = light.spe.r.max(light.spe.g).max(light.spe.b);
            let t = if s_max <= 0.0 || o.specular == SpecularModel::None {
                f32::INFINITY
            } else if p.shininess > 0.0 {
                (SKIP_EPSILON / (f_max * s_max)).powf(1.0 / p.shininess)
            } else {
                0.0
            };
            let t = if t.is_nan() { 0.0 } else { t };
            lights.push(LeanLight {
                point,
                attenuated: point && k != [1.0, 0.0, 0.0],
                ambient: light.amb != Color::BLACK,
                dark: t == f32::INFINITY,
                at: splat3(at.to_array()),
                k: splat3(k),
                ll1: Splat::new(at.length_squared() + 1.0),
                amb: splat3(light.amb.to_array()),
                dif: splat3(light.dif.to_array()),
                spe: splat3(light.spe.to_array()),
                threshold: Splat::new(t),
            });
        }
        // (A stable sort: within a kind, the scene's order.)
        lights.sort_by_key(|l| match (l.point, l.attenuated) {
            (true, true) => 0,
            (true, false) => 1,
            (false, _) => 2,
        });
        let plain = lights.iter().take_while(|l| l.attenuated).count();
        let directional = lights.iter().take_while(|l| l.point).count();
        Some(Lean {
            lights,
            plain,
            directional,
            base: Box::new(splat3(p.base.to_array())),
            blinn: o.specular == SpecularModel::BlinnPhong,
            gate: o.gate_specular,
        })
    }
}

/// `s` as a vector of every lane.
#[inline(always)]
fn ld<V: Vf32>(s: &Splat) -> V {
    V::load_splat(s)
}

/// `s` as three vectors.
#[inline(always)]
fn ld3<V: Vf32>(s: &[Splat; 3]) -> V3<V> {
    V3 {
        x: ld(&s[0]),
        y: ld(&s[1]),
        z: ld(&s[2]),
    }
}

/// `shade`'s colour term for the lanes' positions `pos` and normals `nrm` (not normalised),
/// for an object [`Lean::of`] accepts; with `RAW`, before the NaN step and the clamp (for an
/// 8-bit encoding, which does both). One variant of the code per highlight model and gate.
#[inline(always)]
pub(super) fn shade_color_lean<V: Vf32, const RAW: bool>(p: &Prepared, lean: &Lean, pos: V3<V>, nrm: V3<V>) -> [V; 3] {
    let base = [ld(&lean.base[0]), ld(&lean.base[1]), ld(&lean.base[2])];
    match (lean.blinn, lean.gate) {
        (true, true) => lean_variant::<V, _, RAW, true, true>(p, lean, pos, nrm, base),
        (true, false) => lean_variant::<V, _, RAW, true, false>(p, lean, pos, nrm, base),
        (false, true) => lean_variant::<V, _, RAW, false, true>(p, lean, pos, nrm, base),
        (false, false) => lean_variant::<V, _, RAW, false, false>(p, lean, pos, nrm, base),
    }
}

/// The light of `shade` before a texture modulates it, `[primary, specular]` as
/// `phong_core::light` gives them where the emission is not apart (primary: emission, ambient
/// and diffuse), each clamped where the options clamp: [`shade_color_lean`]'s two sums kept
/// apart. For the textured kernels' common form (diffuse and specular maps).
#[inline(always)]
pub(super) fn lit_lean<V: Vf32>(p: &Prepared, lean: &Lean, pos: V3<V>, nrm: V3<V>) -> [[V; 3]; 2] {
    let zero = V::splat(0.0);
    let two = [[ld(&lean.base[0]), ld(&lean.base[1]), ld(&lean.base[2])], [zero; 3]];
    match (lean.blinn, lean.gate) {
        (true, true) => lean_variant::<V, _, false, true, true>(p, lean, pos, nrm, two),
        (true, false) => lean_variant::<V, _, false, true, false>(p, lean, pos, nrm, two),
        (false, true) => lean_variant::<V, _, false, false, true>(p, lean, pos, nrm, two),
        (false, false) => lean_variant::<V, _, false, false, false>(p, lean, pos, nrm, two),
    }
}

/// Where the lean kernel adds a light's terms: one colour (`[V; 3]`: every term in it), or
/// two (`[[V; 3]; 2]`: the highlights in the second).
trait Sums<V: Vf32> {
    /// The colour the ambient and diffuse terms go to.
    fn lit(&mut self) -> &mut [V; 3];
    /// The colour the highlights go to.
    fn highlight(&mut self) -> &mut [V; 3];
    /// NaN to 0 and, where `clamp`, each channel into `[0, 1]`.
    fn finish(&mut self, clamp: bool);
}

impl<V: Vf32> Sums<V> for [V; 3] {
    #[inline(always)]
    fn lit(&mut self) -> &mut [V; 3] {
        self
    }
    #[inline(always)]
    fn highlight(&mut self) -> &mut [V; 3] {
        self
    }
    #[inline(always)]
    fn finish(&mut self, clamp: bool) {
        for c in self {
            *c = fin(*c);
            if clamp {
                *c = c.max(V::splat(0.0)).min(V::splat(1.0));
            }
        }
    }
}

impl<V: Vf32> Sums<V> for [[V; 3]; 2] {
    #[inline(always)]
    fn lit(&mut self) -> &mut [V; 3] {
        &mut self[0]
    }
    #[inline(always)]
    fn highlight(&mut self) -> &mut [V; 3] {
        &mut self[1]
    }
    #[inline(always)]
    fn finish(&mut self, clamp: bool) {
        self[0].finish(clamp);
        self[1].finish(clamp);
    }
}

/// What every light of a pixel reads: its position, unit normal and view vector, the view
/// vector the highlight uses, and `N·V` as the highlight uses it.
#[derive(Clone, Copy)]
struct Point<V> {
    pos: V3<V>,
    n: V3<V>,
    v: V3<V>,
    v_spec: V3<V>,
    nv: V,
}

/// [`shade_color_lean`] for Blinn-Phong (`BLINN`) or Phong, the highlight gated by `N·L > 0`
/// where `GATE`, added to `sums` (which start with the emission and global ambient).
///
/// The highlight's vectors come from dot products the diffuse term has already taken: with
/// `D` the vector to a point light and `r = 1/|D|`, `N·L = r·(N·D)`; Blinn-Phong's
/// `N·H = (N·L + N·V)/|L + V|` with `|L + V|² = |L|² + 2 L·V + 1`, Phong's
/// `R·V = 2 (N·L)(N·V) − L·V`.
///
/// A normal or view vector is valid where its squared length is above 0 (`shade`'s
/// `normalize_or_zero`, for the finite vectors interpolation gives; the squared length is
/// raised to `f32::MIN_POSITIVE` before its inverse square root, so a zero vector stays zero).
#[inline(always)]
fn lean_variant<V: Vf32, S: Sums<V>, const RAW: bool, const BLINN: bool, const GATE: bool>(
    p: &Prepared,
    lean: &Lean,
    pos: V3<V>,
    nrm: V3<V>,
    mut sums: S,
) -> S {
    let zero = V::splat(0.0);
    let tiny = V::splat(f32::MIN_POSITIVE);
    let (v, v_ok) = match p.view {
        View::Local { eye } => {
            let e = V3::splat(eye).sub(pos);
            let ee = e.dot(e);
            (e.scale(ee.max(tiny).rsqrt_positive()), ee.gt(zero))
        }
        View::Infinite { to_viewer } => {
            let v = to_viewer.normalize_or_zero();
            let ok = if v != glam::Vec3::ZERO {
                V::all_true()
            } else {
                V::not(V::all_true())
            };
            (V3::splat(v), ok)
        }
    };
    // Zero where the normal is not valid: no diffuse, and below no highlight.
    let nn = nrm.dot(nrm);
    let n = nrm.scale(nn.max(tiny).rsqrt_positive());
    // `shade` has no highlight where the normal or the view is not valid. Blinn-Phong: N·V
    // there is −MAX, which makes N·H negative (a zero normal's N·L and N·V are 0 already);
    // Phong: V zero there, so R·V is 0.
    let (v_spec, nv) = if BLINN {
        (v, V::select(v_ok, n.dot(v), V::splat(-f32::MAX)))
    } else {
        let none = V3 {
            x: zero,
            y: zero,
            z: zero,
        };
        let v_spec = V3::select(V::and(nn.gt(zero), v_ok), v, none);
        let nv = n.dot(v_spec);
        (v_spec, nv.add(nv))
    };
    let at = Point { pos, n, v, v_spec, nv };
    // (Functions and loops, no closures: a closure is not always inlined into the AVX2
    // builds, and its intrinsics then become calls: BENCHMARKS.md, C11.)
    let s = p.shininess;
    for light in &lean.lights[..lean.plain] {
        light_term::<V, S, BLINN, GATE, true, true>(light, &at, s, &mut sums);
    }
    for light in &lean.lights[lean.plain..lean.directional] {
        light_term::<V, S, BLINN, GATE, true, false>(light, &at, s, &mut sums);
    }
    for light in &lean.lights[lean.directional..] {
        light_term::<V, S, BLINN, GATE, false, false>(light, &at, s, &mut sums);
    }
    if !RAW {
        sums.finish(p.options.clamp);
    }
    sums
}

/// Adds one light's terms at `at` to `sums`: a point light (`POINT`) whose factor is not 1
/// (`ATTENUATED`), or a directional light.
#[inline(always)]
fn light_term<V: Vf32, S: Sums<V>, const BLINN: bool, const GATE: bool, const POINT: bool, const ATTENUATED: bool>(
    light: &LeanLight,
    at: &Point<V>,
    shininess: f32,
    sums: &mut S,
) {
    let zero = V::splat(0.0);
    let tiny = V::splat(f32::MIN_POSITIVE);
    let to = ld3::<V>(&light.at);
    // `N·L`, and Phong's `V·L` or Blinn-Phong's `|L + V|²`.
    let (ndotl, vl, hh, factor) = if POINT {
        let dv = to.sub(at.pos);
        // At the light itself `d² = 0`: `L = 0` and `d = 0`, as `shade` has them.
        let d2 = dv.dot(dv);
        let r = d2.max(tiny).rsqrt_positive();
        let d = d2.mul(r);
        let factor = if ATTENUATED {
            d.mul_add(ld(&light.k[2]), ld(&light.k[1]))
                .mul_add(d, ld(&light.k[0]))
                .recip()
        } else {
            V::splat(1.0)
        };
        let (vl, hh) = if BLINN {
            // |L|² + 2 L·V + 1 = r·(d + 2 V·D) + 1.
            let vdv = at.v.dot(dv);
            (zero, vdv.add(vdv).add(d).mul_add(r, V::splat(1.0)))
        } else {
            (at.v_spec.dot(dv).mul(r), zero)
        };
        (at.n.dot(dv).mul(r), vl, hh, factor)
    } else {
        let ndotl = at.n.dot(to);
        if BLINN {
            let vl = at.v.dot(to);
            (ndotl, zero, vl.add(vl).add(ld(&light.ll1)), V::splat(1.0))
        } else {
            (ndotl, at.v_spec.dot(to), zero, V::splat(1.0))
        }
    };
    if light.ambient {
        add(sums.lit(), &light.amb, factor);
    }
    add(sums.lit(), &light.dif, factor.mul(ndotl.max(zero)));
    if light.dark {
        return;
    }
    let mut x = if BLINN {
        ndotl.add(at.nv).mul(hh.max(tiny).rsqrt_positive())
    } else {
        ndotl.mul(at.nv).sub(vl)
    };
    if GATE {
        x = V::select(ndotl.gt(zero), x, zero);
    }
    if !V::any(x.ge(ld(&light.threshold))) {
        return;
    }
    add(sums.highlight(), &light.spe, factor.mul(pow_lean(x, shininess)));
}

/// `log2(1 + u)/u` on `[√½ − 1, √2 − 1)`, degree 5, fitted for relative error (7.5e-6
/// measured in `f32` with fused multiply-adds): coefficients from `u^0`.
static LOG2_Q: [Splat; 6] = [
    Splat::new(1.442_701_6),
    Splat::new(-0.721_206_4),
    Splat::new(0.479_811_85),
    Splat::new(-0.366_491_7),
    Splat::new(0.318_199_87),
    Splat::new(-0.206_190_96),
];

/// `2^f` on `[−½, ½]`, degree 4, fitted for relative error (2.7e-6 measured in `f32` with
/// fused multiply-adds): coefficients from `f^0`.
static EXP2_P: [Splat; 5] = [
    Splat::new(0.999_999_3),
    Splat::new(0.693_121_8),
    Splat::new(0.240_247_46),
    Splat::new(0.055_917_89),
    Splat::new(0.009_570_092),
];

/// The lean kernel's `(x⁺)^s` (`0^s = 0`, `x` clamped to 1) as `2^(s·log2 x)`, with the
/// shorter polynomials above. Its relative error where a highlight can be seen is below 1e-4:
/// `log2 x = e + u·q(u)` with `|u·q(u)| ≤ |log2 x|`, so the error of `s·log2 x` is at most
/// `s·|log2 x|·7.5e-6`; where `x^s` is above `2^−16` (below that a highlight of factor ≤ 2
/// and colour ≤ 1 is under 0.01/255) that is 16·7.5e-6, and `2^y` adds `ln 2` times it plus
/// the exponential's 2.7e-6 and the rounding of `y` (test `lean_pow_bound`).
#[inline(always)]
fn pow_lean<V: Vf32>(x: V, s: f32) -> V {
    let zero = V::splat(0.0);
    let xc = x.max(V::splat(f32::MIN_POSITIVE)).min(V::splat(1.0));
    let (e, m) = xc.frexp_folded();
    let u = m.sub(V::splat(1.0));
    let mut q = ld::<V>(&LOG2_Q[5]);
    for c in LOG2_Q[..5].iter().rev() {
        q = q.mul_add(u, ld(c));
    }
    let sv = V::splat(s);
    // Below 2^−125 the result is taken as it comes (still normal, and far below ε).
    let y = u.mul(q).mul_add(sv, e.mul(sv)).max(V::splat(-125.0));
    let k = y.round();
    let f = y.sub(k);
    let mut p = ld::<V>(&EXP2_P[4]);
    for c in EXP2_P[..4].iter().rev() {
        p = p.mul_add(f, ld(c));
    }
    V::select(x.gt(zero), p.scale_pow2(k), zero)
}

/// `col += k·f`, per channel.
#[inline(always)]
fn add<V: Vf32>(col: &mut [V; 3], k: &[Splat; 3], f: V) {
    col[0] = ld::<V>(&k[0]).mul_add(f, col[0]);
    col[1] = ld::<V>(&k[1]).mul_add(f, col[1]);
    col[2] = ld::<V>(&k[2]).mul_add(f, col[2]);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simd::vector::Portable;

    /// [`pow_lean`] against `powf` in `f64` over `x` in `(0, 1]` (a fine grid, denser near 1)
    /// and shininess from 0.5 to 1000, in `V`'s build: the worst relative error where
    /// `x^s ≥ 2^−16` (asserted below 1e-4), and below `2^−16·1e-4` in absolute terms elsewhere.
    fn pow_errors<V: Vf32>() -> f64 {
        let mut worst = 0.0f64;
        let mut xs: Vec<f32> = (1..=20_000).map(|i| i as f32 / 20_000.0).collect();
        xs.extend((0..20_000).map(|i| 1.0 - i as f32 * 1e-6));
        for s in [0.5f32, 1.0, 2.0, 7.3, 10.0, 32.0, 51.2, 89.6, 128.0, 500.0, 1000.0] {
            for chunk in xs.chunks(V::N) {
                let mut a = V::A::default();
                for (i, l) in a.as_mut().iter_mut().enumerate() {
                    *l = chunk[i.min(chunk.len() - 1)];
                }
                let got = pow_lean(V::from_array(a), s).to_array();
                for (&x, &g) in a.as_ref().iter().zip(got.as_ref()) {
                    let want = f64::from(x).powf(f64::from(s));
                    let err = (f64::from(g) - want).abs();
                    if want >= 2f64.powi(-16) {
                        worst = worst.max(err / want);
                        assert!(err <= 1e-4 * want, "x = {x}, s = {s}: {g} vs {want}");
                    } else {
                        assert!(err <= 2f64.powi(-16) * 1e-4, "x = {x}, s = {s}: {g} vs {want}");
                    }
                }
            }
        }
        let at = |x: f32, s: f32| pow_lean(V::splat(x), s).to_array().as_ref()[0];
        assert_eq!(at(0.0, 0.0), 0.0);
        assert_eq!(at(0.0, 10.0), 0.0);
        assert_eq!(at(-0.5, 10.0), 0.0);
        assert!((at(1.5, 10.0) - 1.0).abs() < 1e-5);
        assert!((at(0.3, 0.0) - 1.0).abs() < 1e-5);
        worst
    }

    /// The bound of [`pow_lean`]'s documentation, in both builds (measured: 8.2e-5 in each).
    #[test]
    fn lean_pow_bound() {
        eprintln!(
            "lean pow, portable: worst relative error {:e}",
            pow_errors::<Portable>()
        );
        #[cfg(target_arch = "x86_64")]
        if crate::simd::avx2_available() {
            #[target_feature(enable = "avx2,fma")]
            fn avx2() -> f64 {
                pow_errors::<crate::simd::vector::Avx2x2>()
            }
            // SAFETY: the CPU has AVX2 and FMA (checked above).
            eprintln!("lean pow, AVX2: worst relative error {:e}", unsafe { avx2() });
        }
    }
}
