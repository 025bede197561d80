//! The shading kernels of the fast path, written once over the 8-lane vector of
//! `super::vector`: [`phong_core::shade`] for 8 points at once in structure-of-arrays form,
//! fed by the perspective-correct interpolation of a triangle's attributes (`planes.rs`).
//!
//! Per object, [`Prepared`] hoists what does not change per pixel: the light-material
//! products, the decoded options, the normalisation factors. Decisions (light type, model,
//! options, whether a light is attenuated) are taken once per light and batch; lanes differ
//! only in data, with selects.
//!
//! Approximations, all far below 1/255 on terms up to 1: `pow` is `x^s = 2^(s·log2 x)` with a
//! 7th-order atanh series for `log2` on `[√½, √2)` (truncation below 2e-8) and a degree-7
//! Taylor polynomial for `2^f` on `[−½, ½]` (below 6e-9); the relative error of `x^s`,
//! measured against `powf`, is at most `s·3.3e-7` (mostly the f32 rounding of `s·log2 x`):
//! 3.3e-4 at `s = 1000`. The AVX2 build also uses fused multiply-adds and refined estimates of
//! `1/x` and `1/√x` (relative error about 2^−22). The kernel is tested against `shade` (5e-4
//! relative, both builds) and the fast path's images against the reference path's (within
//! 1/255 on every pixel).

pub(super) use super::planes::{Broadcast, centres, coefficients, interpolate};
pub use super::planes::{Planes, pixel_centre};
use super::vector::Vf32;
use glam::Vec3;
use phong_core::{Color, Light, Lighting, LyonLambda, Material, Normalization, ShadingOptions, SpecularModel, View};

/// Lanes of `shade8`.
pub const LANES: usize = 8;
/// The most lanes of any `Vf32` implementation.
pub(super) const MAX_LANES: usize = 16;

/// Three lanes of vectors.
#[derive(Clone, Copy)]
pub(super) struct V3<V> {
    pub(super) x: V,
    pub(super) y: V,
    pub(super) z: V,
}

impl<V: Vf32> V3<V> {
    #[inline(always)]
    pub(super) fn splat(v: Vec3) -> Self {
        V3 {
            x: V::splat(v.x),
            y: V::splat(v.y),
            z: V::splat(v.z),
        }
    }
    #[inline(always)]
    pub(super) fn sub(self, o: Self) -> Self {
        V3 {
            x: self.x.sub(o.x),
            y: self.y.sub(o.y),
            z: self.z.sub(o.z),
        }
    }
    #[inline(always)]
    pub(super) fn add(self, o: Self) -> Self {
        V3 {
            x: self.x.add(o.x),
            y: self.y.add(o.y),
            z: self.z.add(o.z),
        }
    }
    #[inline(always)]
    pub(super) fn scale(self, k: V) -> Self {
        V3 {
            x: self.x.mul(k),
            y: self.y.mul(k),
            z: self.z.mul(k),
        }
    }
    #[inline(always)]
    pub(super) fn dot(self, o: Self) -> V {
        self.z.mul_add(o.z, self.x.mul_add(o.x, self.y.mul(o.y)))
    }
    #[inline(always)]
    pub(super) fn select(m: V::M, a: Self, b: Self) -> Self {
        V3 {
            x: V::select(m, a.x, b.x),
            y: V::select(m, a.y, b.y),
            z: V::select(m, a.z, b.z),
        }
    }
    #[inline(always)]
    fn cross(self, o: Self) -> Self {
        V3 {
            x: self.y.mul(o.z).sub(self.z.mul(o.y)),
            y: self.z.mul(o.x).sub(self.x.mul(o.z)),
            z: self.x.mul(o.y).sub(self.y.mul(o.x)),
        }
    }
    /// glam's `normalize_or_zero`: `v · (1/|v|)` when that reciprocal is finite and > 0.
    #[inline(always)]
    pub(super) fn normalize_or_zero(self) -> (Self, V::M) {
        let rcp = self.dot(self).rsqrt();
        let ok = V::and(rcp.finite(), rcp.gt(V::splat(0.0)));
        let zero = V::splat(0.0);
        (
            V3::select(
                ok,
                self.scale(rcp),
                V3 {
                    x: zero,
                    y: zero,
                    z: zero,
                },
            ),
            ok,
        )
    }
}

/// `phong_core::perturb` for every lane: the normal `n` tilted by the tangent-space normal
/// `ts` in the frame of the tangent `t` (`t[3]`: the bitangent's sign); `n` itself where the
/// frame degenerates (a zero normal, or a tangent zero or along the normal).
#[inline(always)]
pub(super) fn perturb<V: Vf32>(n: V3<V>, t: [V; 4], ts: [V; 3]) -> V3<V> {
    let (nn, n_ok) = n.normalize_or_zero();
    let t3 = V3 {
        x: t[0],
        y: t[1],
        z: t[2],
    };
    let (tt, t_ok) = t3.sub(nn.scale(nn.dot(t3))).normalize_or_zero();
    let b = nn.cross(tt);
    let sign = V::select(t[3].lt(V::splat(0.0)), V::splat(-1.0), V::splat(1.0));
    let tilted = tt.scale(ts[0]).add(b.scale(sign.mul(ts[1]))).add(nn.scale(ts[2]));
    V3::select(V::and(n_ok, t_ok), tilted, n)
}

/// `log2 x` for finite `x > 0` (not denormal): `x = m·2^e`, `m` in `[√½, √2)`,
/// `log2 m = 2/ln 2 · atanh(t)`, `t = (m − 1)/(m + 1)`, series to `t^7`.
#[inline(always)]
fn log2<V: Vf32>(x: V) -> V {
    let (e, m) = x.frexp();
    let one = V::splat(1.0);
    let big = m.gt(V::splat(core::f32::consts::SQRT_2));
    let m = V::select(big, m.mul(V::splat(0.5)), m);
    let e = V::select(big, e.add(one), e);
    let t = m.sub(one).mul(m.add(one).recip());
    let t2 = t.mul(t);
    let poly = t2.mul_add(V::splat(1.0 / 7.0), V::splat(1.0 / 5.0));
    let poly = t2.mul_add(poly, V::splat(1.0 / 3.0));
    let poly = t2.mul_add(poly, one);
    t.mul(poly).mul_add(V::splat(2.0 / core::f32::consts::LN_2), e)
}

/// `2^y` for `y <= 0`: `y = k + f`, `f` in `[−½, ½]`, `2^f = e^(f ln 2)` to degree 7; 0 below
/// 2^−126.
#[inline(always)]
fn exp2<V: Vf32>(y: V) -> V {
    let yc = y.max(V::splat(-126.0));
    let k = yc.round();
    let z = yc.sub(k).mul(V::splat(core::f32::consts::LN_2));
    let mut p = V::splat(1.0 / 5040.0);
    for c in [1.0 / 720.0, 1.0 / 120.0, 1.0 / 24.0, 1.0 / 6.0, 1.0 / 2.0, 1.0, 1.0] {
        p = z.mul_add(p, V::splat(c));
    }
    let r = p.mul(k.pow2i());
    V::select(y.lt(V::splat(-126.0)), V::splat(0.0), r)
}

/// `(x⁺)^s` with `0^s = 0` (as `phong_core::pow_positive`), `x` clamped to 1, by `2^(s·log2 x)`
/// (`s = 0` gives `2^0 = 1` for `x > 0`).
#[inline(always)]
pub(super) fn pow_positive<V: Vf32>(x: V, s: f32) -> V {
    let xc = x.max(V::splat(f32::MIN_POSITIVE)).min(V::splat(1.0));
    let r = exp2(V::splat(s).mul(log2(xc)));
    V::select(x.gt(V::splat(0.0)), r, V::splat(0.0))
}

/// [`pow_positive`] with the exponent `sv` per lane where given, else `s`.
#[inline(always)]
fn pow_lanes<V: Vf32>(x: V, s: f32, sv: Option<V>) -> V {
    match sv {
        None => pow_positive(x, s),
        Some(sv) => {
            let xc = x.max(V::splat(f32::MIN_POSITIVE)).min(V::splat(1.0));
            let r = exp2(sv.mul(log2(xc)));
            V::select(x.gt(V::splat(0.0)), r, V::splat(0.0))
        }
    }
}

/// The specular normalisation factor `Normalization::factors(s).1` for shininess `s` per lane
/// (`s >= 0`).
#[inline(always)]
fn specular_factor<V: Vf32>(normalization: Normalization, s: V) -> V {
    use core::f32::consts::PI;
    match normalization {
        Normalization::None => V::splat(1.0),
        Normalization::Phong => s.add(V::splat(2.0)).mul(V::splat(1.0 / (2.0 * PI))),
        Normalization::BlinnPhong => s.add(V::splat(8.0)).mul(V::splat(1.0 / (8.0 * PI))),
        Normalization::BlinnPhongExact => {
            let num = s.add(V::splat(2.0)).mul(s.add(V::splat(4.0)));
            let den = exp2(s.mul(V::splat(-0.5))).add(s).mul(V::splat(8.0 * PI));
            num.mul(den.recip())
        }
    }
}

/// `(x⁺)^s` for a per-light exponent (spot falloff), `0^0 = 1` as `powf`.
#[inline(always)]
fn pow_falloff<V: Vf32>(x: V, s: f32) -> V {
    if s == 0.0 {
        return V::splat(1.0);
    }
    pow_positive(x, s)
}

#[derive(Clone, Copy)]
pub(super) enum Kind {
    Directional {
        to_light: Vec3,
    },
    Positional {
        position: Vec3,
        k: [f32; 3],
        spot: Option<(Vec3, f32, f32)>,
    },
}

#[derive(Clone, Copy)]
pub(super) struct PreparedLight {
    pub(super) kind: Kind,
    /// `a_m ⊗ a_l`, `d_m ⊗ d_l`, `s_m ⊗ s_l`.
    pub(super) amb: Color,
    pub(super) dif: Color,
    pub(super) spe: Color,
}

/// What `shade8` needs of one object, computed once per render.
pub struct Prepared {
    pub(super) view: View,
    pub(super) options: ShadingOptions,
    /// The material's shininess.
    pub(super) shininess: f32,
    kd: f32,
    ks: f32,
    pub(super) base: Color,
    /// The emission where it is kept apart from `base` ([`Prepared::emission_apart`]), else 0.
    pub(super) emission: Color,
    pub(super) lights: Vec<PreparedLight>,
}

impl Prepared {
    /// Hoists the constants of `material` under `lighting` with `options` (two-sided off:
    /// the renderer flips back faces' normals itself).
    pub fn new(lighting: &Lighting, material: &Material, options: &ShadingOptions, view: View) -> Prepared {
        let s = material.shininess();
        let (kd, ks) = options.normalization.factors(s);
        let lights = lighting
            .lights()
            .iter()
            .map(|l| {
                let c = l.color();
                let kind = match l {
                    Light::Directional(_) => Kind::Directional {
                        to_light: l.to_light().unwrap_or_default(),
                    },
                    _ => Kind::Positional {
                        position: l.position().unwrap_or_default(),
                        k: l.attenuation().map_or([1.0, 0.0, 0.0], |a| a.coefficients()),
                        spot: l
                            .spot_cone()
                            .filter(|c| c.1 != 180.0)
                            .map(|(axis, _, cos, e)| (axis, cos, e)),
                    },
                };
                PreparedLight {
                    kind,
                    amb: material.ambient() * c.ambient(),
                    dif: material.diffuse() * c.diffuse(),
                    spe: material.specular() * c.specular(),
                }
            })
            .collect();
        Prepared {
            view,
            options: ShadingOptions {
                two_sided: false,
                ..*options
            },
            shininess: s,
            kd,
            ks,
            base: material.emission() + material.ambient() * lighting.ambient(),
            emission: Color::BLACK,
            lights,
        }
    }

    /// This preparation with the material's emission kept apart from the ambient terms (for
    /// ambient and emission maps, which modulate them apart: `phong_core::light`'s split).
    pub fn emission_apart(self, lighting: &Lighting, material: &Material) -> Prepared {
        Prepared {
            base: material.ambient() * lighting.ambient(),
            emission: material.emission(),
            ..self
        }
    }
}

/// Colours of the four terms for 8 lanes.
#[derive(Clone, Copy, Debug)]
pub struct Shaded8 {
    /// Emission and ambient terms, per channel.
    pub ambient: [[f32; LANES]; 3],
    /// Diffuse term.
    pub diffuse: [[f32; LANES]; 3],
    /// Specular term.
    pub specular: [[f32; LANES]; 3],
    /// The (clamped) sum.
    pub color: [[f32; LANES]; 3],
}

/// The four terms, per channel, in vectors.
#[derive(Clone, Copy)]
pub(crate) struct Terms<V> {
    pub(super) ambient: [V; 3],
    pub(super) diffuse: [V; 3],
    pub(super) specular: [V; 3],
    color: [V; 3],
}

/// Which term of the shading an object shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Term {
    /// Emission and ambient.
    Ambient,
    /// Diffuse.
    Diffuse,
    /// Specular.
    Specular,
    /// The sum.
    Color,
}

impl<V: Vf32> Terms<V> {
    #[inline(always)]
    fn get(&self, term: Term) -> [V; 3] {
        match term {
            Term::Ambient => self.ambient,
            Term::Diffuse => self.diffuse,
            Term::Specular => self.specular,
            Term::Color => self.color,
        }
    }
}

/// `c += k·f` on the lanes of `m` (`k` is finite: `f` is zeroed elsewhere, one select instead
/// of one per channel).
#[inline(always)]
fn acc<V: Vf32>(c: &mut [V; 3], k: Color, f: V, m: V::M) {
    let f = V::select(m, f, V::splat(0.0));
    for (ch, kc) in c.iter_mut().zip([k.r, k.g, k.b]) {
        *ch = V::splat(kc).mul_add(f, *ch);
    }
}

/// NaN → 0, overflow → ±f32::MAX, as `shade` (a function, not a closure: a closure is not
/// always inlined into the AVX2 kernels, and its intrinsics then become calls).
#[inline(always)]
pub(super) fn fin<V: Vf32>(x: V) -> V {
    V::select(
        x.nan(),
        V::splat(0.0),
        x.max(V::splat(f32::MIN)).min(V::splat(f32::MAX)),
    )
}

/// Shades 8 points (positions and unnormalised normals by lane) of one object:
/// `phong_core::shade` with `pow` approximated as documented above.
#[inline(always)]
pub(super) fn shade<V: Vf32>(p: &Prepared, pos: V3<V>, nrm: V3<V>) -> Terms<V> {
    shade_shininess(p, pos, nrm, None)
}

/// [`shade`] with the shininess per lane where `sv` is given (a shininess or
/// metallic-roughness map's, as `phong_core::light` takes it), else the material's.
#[inline(always)]
pub(super) fn shade_shininess<V: Vf32>(p: &Prepared, pos: V3<V>, nrm: V3<V>, sv: Option<V>) -> Terms<V> {
    let zero = V::splat(0.0);
    let (v, v_ok) = match p.view {
        View::Local { eye } => V3::splat(eye).sub(pos).normalize_or_zero(),
        View::Infinite { to_viewer } => {
            let v = to_viewer.normalize_or_zero();
            let ok = if v != Vec3::ZERO {
                V::all_true()
            } else {
                V::not(V::all_true())
            };
            (V3::splat(v), ok)
        }
    };
    let (n, n_ok) = nrm.normalize_or_zero();
    let o = &p.options;
    let s = p.shininess;
    let normalized = o.normalization != Normalization::None;
    let ks = match sv {
        Some(sv) => specular_factor(o.normalization, sv),
        None => V::splat(p.ks),
    };
    let mut amb = [V::splat(p.base.r), V::splat(p.base.g), V::splat(p.base.b)];
    let mut dif = [zero; 3];
    let mut spe = [zero; 3];
    for light in &p.lights {
        let (l, l_ok, factor) = match light.kind {
            Kind::Directional { to_light } => (V3::splat(to_light), V::all_true(), V::splat(1.0)),
            Kind::Positional { position, k, spot } => {
                let dv = V3::splat(position).sub(pos);
                let d2 = dv.dot(dv);
                let pos_d = d2.gt(zero);
                let r = d2.rsqrt();
                // d = √d² (NaN where d² = ∞, as the scalar 1/(k0 + ∞) ends at factor 0 too).
                let d = V::select(pos_d, d2.mul(r), zero);
                let l = V3::select(pos_d, dv.scale(r), V3::splat(Vec3::ZERO));
                let mut factor = if k == [1.0, 0.0, 0.0] {
                    V::splat(1.0)
                } else {
                    d.mul_add(V::splat(k[2]), V::splat(k[1]))
                        .mul_add(d, V::splat(k[0]))
                        .recip()
                };
                if let Some((axis, cos_cutoff, exponent)) = spot {
                    let c = zero.sub(l.dot(V3::splat(axis)));
                    let fall = pow_falloff(c.max(zero), exponent);
                    let inside = V::select(c.ge(V::splat(cos_cutoff)), fall, zero);
                    factor = V::select(pos_d, factor.mul(inside), factor);
                }
                factor = V::select(d.finite(), factor, zero);
                (l, pos_d, factor)
            }
        };
        let active = V::and(factor.gt(zero), factor.finite());
        acc(&mut amb, light.amb, factor, active);
        let lit = V::and(V::and(active, l_ok), n_ok);
        let ndotl = n.dot(l);
        let ndotl_pos = ndotl.gt(zero);
        let front = V::and(lit, ndotl_pos);
        let fd = factor.mul(V::splat(p.kd)).mul(ndotl);
        acc(&mut dif, light.dif, fd, front);
        let gate = if o.gate_specular { ndotl_pos } else { V::all_true() };
        let spec_on = V::and(V::and(lit, gate), v_ok);
        if !V::any(spec_on) {
            continue;
        }
        let mut sf = match o.specular {
            SpecularModel::None => zero,
            SpecularModel::Phong => {
                let r = n.scale(ndotl.add(ndotl)).sub(l);
                pow_lanes(r.dot(v), s, sv)
            }
            SpecularModel::BlinnPhong => {
                let (h, h_ok) = l.add(v).normalize_or_zero();
                V::select(h_ok, pow_lanes(n.dot(h), s, sv), zero)
            }
            SpecularModel::Lyon { squarings, lambda } => {
                let r = n.scale(ndotl.add(ndotl)).sub(l);
                let rv = r.dot(v);
                let lam = match lambda {
                    LyonLambda::Dot => V::splat(1.0).sub(rv),
                    LyonLambda::Difference => {
                        let d = r.sub(v);
                        d.dot(d).mul(V::splat(0.5))
                    }
                };
                // Lyon's squarings per lane (a rarely used model: not worth a vector form).
                let (rv, lam) = (rv.to_array(), lam.to_array());
                let ss = sv.unwrap_or(V::splat(s)).to_array();
                let mut out = V::A::default();
                for (i, o) in out.as_mut().iter_mut().enumerate() {
                    if rv.as_ref()[i] > 0.0 {
                        *o = phong_core::lyon(lam.as_ref()[i].max(0.0), ss.as_ref()[i], squarings);
                    }
                }
                V::from_array(out)
            }
        };
        if normalized {
            sf = sf.mul(ndotl.max(zero));
        }
        let fs = factor.mul(ks).mul(sf);
        let on = V::and(spec_on, sf.gt(zero));
        acc(&mut spe, light.spe, fs, on);
    }
    let mut t = Terms {
        ambient: amb,
        diffuse: dif,
        specular: spe,
        color: [zero; 3],
    };
    for c in 0..3 {
        t.ambient[c] = fin(amb[c]);
        t.diffuse[c] = fin(dif[c]);
        t.specular[c] = fin(spe[c]);
        let sum = fin(t.ambient[c].add(t.diffuse[c]).add(t.specular[c]));
        t.color[c] = if o.clamp { sum.max(zero).min(V::splat(1.0)) } else { sum };
    }
    t
}

/// [`shade`] on arrays of positions and normals.
#[inline(always)]
pub(crate) fn shade_points<V: Vf32<A = [f32; LANES]>>(
    p: &Prepared,
    position: &[Vec3; LANES],
    normal: &[Vec3; LANES],
) -> Shaded8 {
    let col = |a: &[Vec3; LANES], f: fn(Vec3) -> f32| V::from_array(std::array::from_fn(|i| f(a[i])));
    let pos = V3 {
        x: col(position, |v| v.x),
        y: col(position, |v| v.y),
        z: col(position, |v| v.z),
    };
    let nrm = V3 {
        x: col(normal, |v| v.x),
        y: col(normal, |v| v.y),
        z: col(normal, |v| v.z),
    };
    let t = shade(p, pos, nrm);
    let arr = |c: [V; 3]| c.map(V::to_array);
    Shaded8 {
        ambient: arr(t.ambient),
        diffuse: arr(t.diffuse),
        specular: arr(t.specular),
        color: arr(t.color),
    }
}

/// The lean kernel's colour (`lean.rs`) on arrays of positions and normals.
#[inline(always)]
pub(crate) fn lean_points<V: Vf32<A = [f32; LANES]>>(
    p: &Prepared,
    lean: &super::Lean,
    position: &[Vec3; LANES],
    normal: &[Vec3; LANES],
) -> [[f32; LANES]; 3] {
    let col = |a: &[Vec3; LANES], f: fn(Vec3) -> f32| V::from_array(std::array::from_fn(|i| f(a[i])));
    let v3 = |a: &[Vec3; LANES]| V3 {
        x: col(a, |v| v.x),
        y: col(a, |v| v.y),
        z: col(a, |v| v.z),
    };
    super::lean::shade_color_lean::<V, false>(p, lean, v3(position), v3(normal)).map(V::to_array)
}

/// What Gouraud's vertex lighting computes: a term by the general kernel, or the colour by
/// the lean kernel (`lean.rs`).
#[derive(Clone, Copy)]
pub enum VertexTerm<'a> {
    /// The term, by the general kernel (`shade` here).
    General(Term),
    /// The colour, by the lean kernel.
    Lean(&'a super::Lean),
}

/// Lights vertices for Gouraud, [`V::N`](Vf32::N) at a time: `out[i]` becomes `term` of the
/// shading at `positions[i]` with normal `normals[i]` (negated with `flip`). The same
/// arithmetic per lane as [`shade_points`], only the term asked for kept.
#[inline(always)]
pub(crate) fn light_vertices<V: Vf32>(
    p: &Prepared,
    term: VertexTerm,
    positions: &[Vec3],
    normals: &[Vec3],
    flip: bool,
    out: &mut [Vec3],
) {
    for ((ps, ns), os) in positions
        .chunks(V::N)
        .zip(normals.chunks(V::N))
        .zip(out.chunks_mut(V::N))
    {
        let (pos, nrm) = vertex_lanes::<V>(ps, ns, flip);
        let colour = match term {
            VertexTerm::Lean(lean) => super::lean::shade_color_lean::<V, false>(p, lean, pos, nrm),
            VertexTerm::General(term) => shade(p, pos, nrm).get(term),
        };
        store_lanes(colour, os);
    }
}

/// Vertices `ps` with normals `ns` (negated with `flip`) as lanes, the last repeated past
/// `ps.len()`.
#[inline(always)]
fn vertex_lanes<V: Vf32>(ps: &[Vec3], ns: &[Vec3], flip: bool) -> (V3<V>, V3<V>) {
    let m = ps.len();
    let mut c = [V::A::default(); 6];
    for i in 0..V::N {
        let (pp, mut nn) = (ps[i.min(m - 1)], ns[i.min(m - 1)]);
        if flip {
            nn = -nn;
        }
        for (k, v) in [pp.x, pp.y, pp.z, nn.x, nn.y, nn.z].into_iter().enumerate() {
            c[k].as_mut()[i] = v;
        }
    }
    let [px, py, pz, nx, ny, nz] = c.map(V::from_array);
    (V3 { x: px, y: py, z: pz }, V3 { x: nx, y: ny, z: nz })
}

/// The first `out.len()` lanes of `rgb` into `out`.
#[inline(always)]
fn store_lanes<V: Vf32>(rgb: [V; 3], out: &mut [Vec3]) {
    let rgb = rgb.map(V::to_array);
    for (i, o) in out.iter_mut().enumerate() {
        *o = Vec3::new(rgb[0].as_ref()[i], rgb[1].as_ref()[i], rgb[2].as_ref()[i]);
    }
}

/// Gouraud's vertex lighting of a textured object: `primary[i]` and `specular[i]`, the
/// [`phong_core::Lit`] at `positions[i]` with `normals[i]` (negated with `flip`): emission,
/// ambient and diffuse, and the specular term, each clamped where the options clamp.
#[inline(always)]
pub(crate) fn light_vertices_lit<V: Vf32>(
    p: &Prepared,
    positions: &[Vec3],
    normals: &[Vec3],
    flip: bool,
    [primary, specular]: [&mut [Vec3]; 2],
) {
    let (zero, one) = (V::splat(0.0), V::splat(1.0));
    for (((ps, ns), po), so) in positions
        .chunks(V::N)
        .zip(normals.chunks(V::N))
        .zip(primary.chunks_mut(V::N))
        .zip(specular.chunks_mut(V::N))
    {
        let (pos, nrm) = vertex_lanes::<V>(ps, ns, flip);
        let t = shade(p, pos, nrm);
        let mut lit = [[zero; 3]; 2];
        for ch in 0..3 {
            lit[0][ch] = t.ambient[ch].add(t.diffuse[ch]);
            lit[1][ch] = t.specular[ch];
            if p.options.clamp {
                for l in &mut lit {
                    l[ch] = l[ch].max(zero).min(one);
                }
            }
        }
        store_lanes(lit[0], po);
        store_lanes(lit[1], so);
    }
}

/// `shade8` in the portable build (the AVX2 build is [`super::shade8`]).
pub fn shade8(p: &Prepared, position: &[Vec3; LANES], normal: &[Vec3; LANES]) -> Shaded8 {
    shade_points::<super::vector::Portable>(p, position, normal)
}

/// What a batch interpolates and how it colours the result.
#[derive(Clone, Copy)]
pub enum Batch<'a> {
    /// Interpolated position and normal, shaded by the kernel; the given term.
    Phong(&'a Prepared, Term),
    /// Interpolated position and normal, the colour term by the lean kernel (`lean.rs`).
    Lean(&'a Prepared, &'a super::Lean),
    /// Interpolated colour (Gouraud).
    Gouraud,
}

/// Interpolated attributes `q` as a position (`q[0..3]`) and a normal (`q[3..6]`).
#[inline(always)]
pub(super) fn position_normal<V: Vf32>(q: [V; 6]) -> (V3<V>, V3<V>) {
    let v3 = |k: usize| V3 {
        x: q[k],
        y: q[k + 1],
        z: q[k + 2],
    };
    (v3(0), v3(3))
}

/// The colour of a batch's interpolated attributes `q`: Phong shades position `q[0..3]` and
/// normal `q[3..6]` and keeps its term; Gouraud's colour is `q[0..3]`. With `RAW`, the lean
/// kernel's colour is left unclamped, NaN included, for an 8-bit encoding that clamps it.
#[inline(always)]
pub(super) fn batch_color<V: Vf32, const RAW: bool>(batch: Batch, q: [V; 6]) -> [V; 3] {
    match batch {
        Batch::Phong(prep, term) => {
            let (pos, nrm) = position_normal(q);
            shade(prep, pos, nrm).get(term)
        }
        Batch::Lean(prep, lean) => {
            let (pos, nrm) = position_normal(q);
            super::lean::shade_color_lean::<V, RAW>(prep, lean, pos, nrm)
        }
        Batch::Gouraud => [q[0], q[1], q[2]],
    }
}

/// Where [`shade_batch_into`] puts a vector's colours: as RGB floats, or encoded to 8 bits in
/// the registers.
trait BatchSink<V: Vf32> {
    /// The sink encodes to 8 bits, which clamps: [`batch_color`]'s `RAW` (as the group
    /// kernel's sink says it).
    const ENCODES: bool;
    /// The colours `rgb` of pixels `start..start + m`.
    fn put(&mut self, start: usize, m: usize, rgb: [V; 3]);
}

/// RGB floats: `out(i, rgb)`.
struct RgbSink<F>(F);

impl<V: Vf32, F: FnMut(usize, [f32; 3])> BatchSink<V> for RgbSink<F> {
    const ENCODES: bool = false;
    #[inline(always)]
    fn put(&mut self, start: usize, m: usize, rgb: [V; 3]) {
        let rgb = rgb.map(V::to_array);
        for i in 0..m {
            (self.0)(start + i, [rgb[0].as_ref()[i], rgb[1].as_ref()[i], rgb[2].as_ref()[i]]);
        }
    }
}

/// 8-bit RGBA as `Encoding::Linear` encodes the colours (alpha 255): `out(i, pixel)`.
struct Rgba8Sink<F>(F);

impl<V: Vf32, F: FnMut(usize, [u8; 4])> BatchSink<V> for Rgba8Sink<F> {
    const ENCODES: bool = true;
    #[inline(always)]
    fn put(&mut self, start: usize, m: usize, rgb: [V; 3]) {
        let px = V::encode_rgba8(rgb);
        for (i, &p) in px.as_ref()[..m].iter().enumerate() {
            (self.0)(start + i, p);
        }
    }
}

/// Shades `n` pixels a vector at a time: `lane(i)` gives pixel `i`'s centre `(x, y)` in pixels
/// and its triangle's planes; `sink` takes their colours.
#[inline(always)]
fn shade_batch_into<'p, V: Vf32, S: BatchSink<V>>(
    batch: Batch,
    n: usize,
    lane: impl Fn(usize) -> (f32, f32, &'p Planes),
    mut sink: S,
) {
    let attrs = match batch {
        Batch::Phong(..) | Batch::Lean(..) => 6,
        Batch::Gouraud => 3,
    };
    let mut start = 0;
    while start < n {
        let (m, q) = lanes::<V>(&lane, start, n, attrs);
        let rgb = if S::ENCODES {
            batch_color::<V, true>(batch, q)
        } else {
            batch_color::<V, false>(batch, q)
        };
        sink.put(start, m, rgb);
        start += m;
    }
}

/// [`shade_batch_into`] RGB floats: `out(i, rgb)` receives pixel `i`'s colour.
#[inline(always)]
pub(crate) fn shade_batch<'p, V: Vf32>(
    batch: Batch,
    n: usize,
    lane: impl Fn(usize) -> (f32, f32, &'p Planes),
    out: impl FnMut(usize, [f32; 3]),
) {
    shade_batch_into::<V, _>(batch, n, lane, RgbSink(out));
}

/// [`shade_batch`] with the colours encoded to 8-bit RGBA in the vector registers, as
/// `Encoding::Linear` encodes them (alpha 255): `out(i, pixel)`.
#[inline(always)]
pub(crate) fn shade_batch8<'p, V: Vf32>(
    batch: Batch,
    n: usize,
    lane: impl Fn(usize) -> (f32, f32, &'p Planes),
    out: impl FnMut(usize, [u8; 4]),
) {
    shade_batch_into::<V, _>(batch, n, lane, Rgba8Sink(out));
}

/// Pixels `start..` (at most [`V::N`](Vf32::N), `m` of them; the last repeated to fill the
/// vector) gathered by `lane`, and their first `attrs` attributes interpolated.
#[inline(always)]
pub(super) fn lanes<'p, V: Vf32>(
    lane: &impl Fn(usize) -> (f32, f32, &'p Planes),
    start: usize,
    n: usize,
    attrs: usize,
) -> (usize, [V; 6]) {
    let m = (n - start).min(V::N);
    let mut xs = V::A::default();
    let mut ys = V::A::default();
    let mut planes: [&Planes; MAX_LANES] = [lane(start).2; MAX_LANES];
    for (i, plane) in planes.iter_mut().enumerate().take(V::N) {
        let (x, y, p) = lane(start + i.min(m - 1));
        xs.as_mut()[i] = x;
        ys.as_mut()[i] = y;
        *plane = p;
    }
    (
        m,
        interpolate::<V>(&planes[..V::N], attrs, V::from_array(xs), V::from_array(ys)).0,
    )
}

/// [`shade_batch`] for a textured object (Phong, its colour): `out(i, primary, specular)`
/// takes phong-core's `Lit` of each pixel with every term in the primary colour: emission,
/// ambient and diffuse summed, and the specular apart, each clamped where the options clamp;
/// the caller applies the texels.
#[inline(always)]
pub(crate) fn shade_batch_lit<'p, V: Vf32>(
    prep: &Prepared,
    n: usize,
    lane: impl Fn(usize) -> (f32, f32, &'p Planes),
    mut out: impl FnMut(usize, [f32; 3], [f32; 3]),
) {
    let mut start = 0;
    while start < n {
        let (m, q) = lanes::<V>(&lane, start, n, 6);
        let (pos, nrm) = position_normal(q);
        let t = shade(prep, pos, nrm);
        let (zero, one) = (V::splat(0.0), V::splat(1.0));
        // Plain loops, not closures: a closure is not compiled with the caller's AVX2.
        let mut primary = [V::A::default(); 3];
        let mut specular = [V::A::default(); 3];
        for c in 0..3 {
            let (mut p, mut s) = (t.ambient[c].add(t.diffuse[c]), t.specular[c]);
            if prep.options.clamp {
                p = p.max(zero).min(one);
                s = s.max(zero).min(one);
            }
            primary[c] = p.to_array();
            specular[c] = s.to_array();
        }
        for i in 0..m {
            out(
                start + i,
                [0, 1, 2].map(|c| primary[c].as_ref()[i]),
                [0, 1, 2].map(|c| specular[c].as_ref()[i]),
            );
        }
        start += m;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simd::vector::Portable;

    #[test]
    fn pow_approximation_bound() {
        // Relative error of 2^(s·log2 x) against powf over x in (0, 1], s in [0.5, 1000].
        let mut worst = 0.0f64;
        for i in 1..=2000 {
            let x = i as f32 / 2000.0;
            for s in [0.5f32, 1.0, 7.3, 32.0, 128.0, 500.0, 1000.0] {
                let want = x.powf(s) as f64;
                let got = pow_positive(Portable::splat(x), s).0[0] as f64;
                if want > 1e-30 {
                    worst = worst.max(((got - want) / want).abs() / f64::from(s).max(1.0));
                }
            }
        }
        // Per unit of exponent: measured 3.3e-7 (mostly the f32 rounding of s·log2 x).
        assert!(worst < 5e-7, "{worst:e}");
        assert_eq!(pow_positive(Portable::splat(0.0), 0.0).0[0], 0.0);
        assert_eq!(pow_positive(Portable::splat(0.3), 0.0).0[0], 1.0);
    }
}
