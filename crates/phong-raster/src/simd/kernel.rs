//! The 8-lane shading kernel of the fast path: [`phong_core::shade`] for 8 points at once,
//! in structure-of-arrays form (`[f32; 8]` per component) written as plain element-wise
//! loops that LLVM vectorises (SSE2 at the baseline, wider where the target allows). No
//! `unsafe` and no intrinsics.
//!
//! Per object, [`Prepared`] hoists what does not change per pixel: the light-material
//! products, the decoded options, the normalisation factors. Decisions (light type, model,
//! options) are taken once per light and batch; lanes differ only in data, with selects.
//!
//! The one approximation is `pow`: `x^s = 2^(s·log2 x)` with a 7th-order atanh series for
//! `log2` on `[√½, √2)` (truncation below 2e-8) and a degree-7 Taylor polynomial for `2^f`
//! on `[−½, ½]` (below 6e-9); the relative error of `x^s`, measured against `powf`, is at most
//! `s·3.3e-7` (mostly the f32 rounding of `s·log2 x`): 3.3e-4 at `s = 1000`, far below 1/255
//! for terms up to 1. The kernel is tested against `shade` (1e-4 absolute or relative) and the
//! fast path's images against the reference path's (within 1/255 on every pixel).

use glam::Vec3;
use phong_core::{Color, Light, Lighting, LyonLambda, Material, Normalization, ShadingOptions, SpecularModel, View};

/// Lanes per batch.
pub const LANES: usize = 8;
type F = [f32; LANES];
type M = [bool; LANES];

/// `[f(0), …, f(7)]` as a plain loop: `core::array::from_fn` is not always inlined, and its
/// calls kept the kernel from vectorising (seen in its disassembly: 12 out-of-line call sites).
#[inline(always)]
fn lanes<T: Copy + Default>(f: impl Fn(usize) -> T) -> [T; LANES] {
    let mut r = [T::default(); LANES];
    for (i, x) in r.iter_mut().enumerate() {
        *x = f(i);
    }
    r
}

#[inline(always)]
fn splat(x: f32) -> F {
    [x; LANES]
}
#[inline(always)]
fn map(a: F, f: impl Fn(f32) -> f32) -> F {
    lanes(|i| f(a[i]))
}
#[inline(always)]
fn zip(a: F, b: F, f: impl Fn(f32, f32) -> f32) -> F {
    lanes(|i| f(a[i], b[i]))
}
#[inline(always)]
fn sel(m: M, a: F, b: F) -> F {
    lanes(|i| if m[i] { a[i] } else { b[i] })
}

/// Three lanes of vectors.
#[derive(Clone, Copy)]
struct V3 {
    x: F,
    y: F,
    z: F,
}

impl V3 {
    #[inline(always)]
    fn splat(v: Vec3) -> V3 {
        V3 {
            x: splat(v.x),
            y: splat(v.y),
            z: splat(v.z),
        }
    }
    #[inline(always)]
    fn zero() -> V3 {
        V3::splat(Vec3::ZERO)
    }
    #[inline(always)]
    fn sub(self, o: V3) -> V3 {
        V3 {
            x: zip(self.x, o.x, |a, b| a - b),
            y: zip(self.y, o.y, |a, b| a - b),
            z: zip(self.z, o.z, |a, b| a - b),
        }
    }
    #[inline(always)]
    fn add(self, o: V3) -> V3 {
        V3 {
            x: zip(self.x, o.x, |a, b| a + b),
            y: zip(self.y, o.y, |a, b| a + b),
            z: zip(self.z, o.z, |a, b| a + b),
        }
    }
    #[inline(always)]
    fn scale(self, k: F) -> V3 {
        V3 {
            x: zip(self.x, k, |a, b| a * b),
            y: zip(self.y, k, |a, b| a * b),
            z: zip(self.z, k, |a, b| a * b),
        }
    }
    #[inline(always)]
    fn div(self, k: F) -> V3 {
        V3 {
            x: zip(self.x, k, |a, b| a / b),
            y: zip(self.y, k, |a, b| a / b),
            z: zip(self.z, k, |a, b| a / b),
        }
    }
    #[inline(always)]
    fn neg(self) -> V3 {
        V3 {
            x: map(self.x, |a| -a),
            y: map(self.y, |a| -a),
            z: map(self.z, |a| -a),
        }
    }
    /// `(x·x' + y·y') + z·z'`, glam's order.
    #[inline(always)]
    fn dot(self, o: V3) -> F {
        lanes(|i| self.x[i] * o.x[i] + self.y[i] * o.y[i] + self.z[i] * o.z[i])
    }
    #[inline(always)]
    fn select(m: M, a: V3, b: V3) -> V3 {
        V3 {
            x: sel(m, a.x, b.x),
            y: sel(m, a.y, b.y),
            z: sel(m, a.z, b.z),
        }
    }
    /// glam's `normalize_or_zero`: `v · (1/|v|)` when that reciprocal is finite and > 0.
    #[inline(always)]
    fn normalize_or_zero(self) -> (V3, M) {
        let rcp = map(self.dot(self), |d| 1.0 / d.sqrt());
        let ok: M = lanes(|i| rcp[i].is_finite() && rcp[i] > 0.0);
        (V3::select(ok, self.scale(rcp), V3::zero()), ok)
    }
}

/// `log2 x` for finite `x > 0` (not denormal): `x = m·2^e`, `m` in `[√½, √2)`,
/// `log2 m = 2/ln 2 · atanh(t)`, `t = (m − 1)/(m + 1)`, series to `t^7`.
#[inline(always)]
fn log2(x: f32) -> f32 {
    let bits = x.to_bits();
    let e = ((bits >> 23) & 0xff) as i32 - 127;
    let m = f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000);
    // Branch-free, so that lanes vectorise: halve m above √2.
    let big = m > core::f32::consts::SQRT_2;
    let m = if big { m * 0.5 } else { m };
    let e = e + i32::from(big);
    let t = (m - 1.0) / (m + 1.0);
    let t2 = t * t;
    let series = t * (1.0 + t2 * (1.0 / 3.0 + t2 * (1.0 / 5.0 + t2 * (1.0 / 7.0))));
    e as f32 + series * (2.0 / core::f32::consts::LN_2)
}

/// `2^y` for `y <= 0`: `y = k + f`, `f` in `[−½, ½]`, `2^f = e^(f ln 2)` to degree 7; 0 below
/// 2^−126. Branch-free: `k` by the 1.5·2^23 rounding trick (round to nearest even).
#[inline(always)]
fn exp2(y: f32) -> f32 {
    const MAGIC: f32 = 12_582_912.0;
    let yc = y.max(-126.0);
    let k = (yc + MAGIC) - MAGIC;
    let z = (yc - k) * core::f32::consts::LN_2;
    let p = 1.0
        + z * (1.0
            + z * (1.0 / 2.0
                + z * (1.0 / 6.0 + z * (1.0 / 24.0 + z * (1.0 / 120.0 + z * (1.0 / 720.0 + z * (1.0 / 5040.0)))))));
    let r = p * f32::from_bits(((k as i32 + 127) as u32) << 23);
    if y < -126.0 { 0.0 } else { r }
}

/// `(x⁺)^s` with `0^s = 0` (as `phong_core::pow_positive`), `x` clamped to 1, by `2^(s·log2 x)`
/// (`s = 0` gives `2^0 = 1` for `x > 0`).
#[inline(always)]
fn pow_positive(x: F, s: f32) -> F {
    map(x, |x| {
        let r = exp2(s * log2(x.clamp(f32::MIN_POSITIVE, 1.0)));
        if x > 0.0 { r } else { 0.0 }
    })
}

/// `(x⁺)^s` for a per-light exponent (spot falloff), `0^0 = 1` as `powf`.
#[inline(always)]
fn pow_falloff(x: F, s: f32) -> F {
    if s == 0.0 {
        return splat(1.0);
    }
    pow_positive(x, s)
}

#[derive(Clone, Copy)]
enum Kind {
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
struct PreparedLight {
    kind: Kind,
    /// `a_m ⊗ a_l`, `d_m ⊗ d_l`, `s_m ⊗ s_l`.
    amb: Color,
    dif: Color,
    spe: Color,
}

/// What [`shade8`] needs of one object, computed once per render.
pub struct Prepared {
    view: View,
    options: ShadingOptions,
    shininess: f32,
    kd: f32,
    ks: f32,
    base: Color,
    lights: Vec<PreparedLight>,
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
            lights,
        }
    }
}

/// Colours of the four terms for 8 lanes.
#[derive(Clone, Copy, Debug)]
pub struct Shaded8 {
    /// Emission and ambient terms, per channel.
    pub ambient: [F; 3],
    /// Diffuse term.
    pub diffuse: [F; 3],
    /// Specular term.
    pub specular: [F; 3],
    /// The (clamped) sum.
    pub color: [F; 3],
}

#[inline(always)]
fn acc(c: &mut [F; 3], k: Color, f: F, m: M) {
    for (ch, kc) in c.iter_mut().zip([k.r, k.g, k.b]) {
        *ch = lanes(|i| if m[i] { ch[i] + kc * f[i] } else { ch[i] });
    }
}

/// Shades 8 points (positions and normals by lane) of one object: `phong_core::shade` with
/// `pow` approximated as documented above. Inlined into each caller so that the AVX2 build
/// in [`super`] compiles it with those features.
#[inline(always)]
pub fn shade8(p: &Prepared, position: &[Vec3; LANES], normal: &[Vec3; LANES]) -> Shaded8 {
    let pos = V3 {
        x: lanes(|i| position[i].x),
        y: lanes(|i| position[i].y),
        z: lanes(|i| position[i].z),
    };
    let nrm = V3 {
        x: lanes(|i| normal[i].x),
        y: lanes(|i| normal[i].y),
        z: lanes(|i| normal[i].z),
    };
    let (v, v_ok) = match p.view {
        View::Local { eye } => V3::splat(eye).sub(pos).normalize_or_zero(),
        View::Infinite { to_viewer } => {
            let v = to_viewer.normalize_or_zero();
            (V3::splat(v), [v != Vec3::ZERO; LANES])
        }
    };
    let (n, n_ok) = nrm.normalize_or_zero();
    let o = &p.options;
    let s = p.shininess;
    let normalized = o.normalization != Normalization::None;
    let mut amb = [splat(p.base.r), splat(p.base.g), splat(p.base.b)];
    let mut dif = [splat(0.0); 3];
    let mut spe = [splat(0.0); 3];
    for light in &p.lights {
        let (l, l_ok, factor) = match light.kind {
            Kind::Directional { to_light } => (V3::splat(to_light), [true; LANES], splat(1.0)),
            Kind::Positional { position, k, spot } => {
                let dv = V3::splat(position).sub(pos);
                let d = map(dv.dot(dv), f32::sqrt);
                let pos_d: M = lanes(|i| d[i] > 0.0);
                let l = V3::select(pos_d, dv.div(d), V3::zero());
                let mut factor = map(d, |d| 1.0 / (k[0] + d * (k[1] + d * k[2])));
                if let Some((axis, cos_cutoff, exponent)) = spot {
                    let c = l.neg().dot(V3::splat(axis));
                    let fall = pow_falloff(map(c, |c| c.max(0.0)), exponent);
                    factor = lanes(|i| {
                        if pos_d[i] {
                            factor[i] * if c[i] >= cos_cutoff { fall[i] } else { 0.0 }
                        } else {
                            factor[i]
                        }
                    });
                }
                let finite_d: M = lanes(|i| d[i].is_finite());
                factor = sel(finite_d, factor, splat(0.0));
                (l, pos_d, factor)
            }
        };
        let active: M = lanes(|i| factor[i] > 0.0 && factor[i].is_finite());
        acc(&mut amb, light.amb, factor, active);
        let lit: M = lanes(|i| active[i] && l_ok[i] && n_ok[i]);
        let ndotl = n.dot(l);
        let front: M = lanes(|i| lit[i] && ndotl[i] > 0.0);
        let fd: F = lanes(|i| factor[i] * p.kd * ndotl[i]);
        acc(&mut dif, light.dif, fd, front);
        let spec_on: M = lanes(|i| lit[i] && (ndotl[i] > 0.0 || !o.gate_specular) && v_ok[i]);
        if !spec_on.iter().any(|&b| b) {
            continue;
        }
        let mut sf = match o.specular {
            SpecularModel::None => splat(0.0),
            SpecularModel::Phong => {
                let ln = l.dot(n);
                let r = n.scale(map(ln, |x| 2.0 * x)).sub(l);
                pow_positive(r.dot(v), s)
            }
            SpecularModel::BlinnPhong => {
                let (h, h_ok) = l.add(v).normalize_or_zero();
                let x = n.dot(h);
                sel(h_ok, pow_positive(x, s), splat(0.0))
            }
            SpecularModel::Lyon { squarings, lambda } => {
                let ln = l.dot(n);
                let r = n.scale(map(ln, |x| 2.0 * x)).sub(l);
                let rv = r.dot(v);
                let lam = match lambda {
                    LyonLambda::Dot => map(rv, |x| 1.0 - x),
                    LyonLambda::Difference => {
                        let d = r.sub(v);
                        map(d.dot(d), |x| 0.5 * x)
                    }
                };
                lanes(|i| {
                    if rv[i] <= 0.0 {
                        0.0
                    } else {
                        phong_core::lyon(lam[i].max(0.0), s, squarings)
                    }
                })
            }
        };
        if normalized {
            sf = zip(sf, ndotl, |a, b| a * b.max(0.0));
        }
        let fs: F = lanes(|i| factor[i] * p.ks * sf[i]);
        let on: M = lanes(|i| spec_on[i] && sf[i] > 0.0);
        acc(&mut spe, light.spe, fs, on);
    }
    // Plain loops: array `map` goes through `Drain` and was not inlined (15 call sites in the
    // disassembly before this change, none after).
    let fin = |x: f32| if x.is_nan() { 0.0 } else { x.clamp(f32::MIN, f32::MAX) };
    let mut out = Shaded8 {
        ambient: amb,
        diffuse: dif,
        specular: spe,
        color: [splat(0.0); 3],
    };
    for c in 0..3 {
        for i in 0..LANES {
            let (a, d, sp) = (fin(amb[c][i]), fin(dif[c][i]), fin(spe[c][i]));
            out.ambient[c][i] = a;
            out.diffuse[c][i] = d;
            out.specular[c][i] = sp;
            let sum = fin(a + d + sp);
            out.color[c][i] = if o.clamp { sum.clamp(0.0, 1.0) } else { sum };
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pow_approximation_bound() {
        // Relative error of 2^(s·log2 x) against powf over x in (0, 1], s in [0.5, 1000].
        let mut worst = 0.0f64;
        for i in 1..=2000 {
            let x = i as f32 / 2000.0;
            for s in [0.5f32, 1.0, 7.3, 32.0, 128.0, 500.0, 1000.0] {
                let want = x.powf(s) as f64;
                let got = pow_positive(splat(x), s)[0] as f64;
                if want > 1e-30 {
                    worst = worst.max(((got - want) / want).abs() / f64::from(s).max(1.0));
                }
            }
        }
        // Per unit of exponent: measured 3.3e-7 (mostly the f32 rounding of s·log2 x).
        assert!(worst < 5e-7, "{worst:e}");
        assert_eq!(pow_positive(splat(0.0), 0.0)[0], 0.0);
        assert_eq!(pow_positive(splat(0.3), 0.0)[0], 1.0);
    }
}
