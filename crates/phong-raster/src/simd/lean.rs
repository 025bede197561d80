//! The lean colour kernel: [`kernel::shade`](super::kernel)'s colour for the objects most
//! scenes have (Phong or Blinn-Phong without energy normalisation, directional and point
//! lights without spots, attenuations that never reach zero), with what the general kernel
//! decides per lane decided once per pixel or once per object:
//! - one colour accumulator, and NaN and the clamp handled once, at the end: every
//!   contribution is finite and not negative here (factors in `(0, 1/k0]`);
//! - the normal's and the view's validity folded into the vectors once per pixel (a zero
//!   normal or view gives a zero highlight), not tested per light;
//! - diffuse by `max(N·L, 0)`; a light's ambient only where it has one;
//! - the highlight's `pow` skipped for a vector whose every lane is below the light's
//!   threshold `t = (ε / (f_max·s_max))^(1/s)`: there `f·s_c·x^s < ε = 0.05/255` on every
//!   channel (`f_max` the largest attenuation factor, `1/k0`; `s_max` the largest channel of
//!   `s_m ⊗ s_l`).
//!
//! The colour differs from `shade`'s by the pow approximation (kernel.rs) and the skipped
//! highlights, at most `n·ε` for `n` lights; the tests hold it to 1/255 of the reference.

use super::kernel::{Kind, Prepared, V3, fin, pow_positive};
use super::vector::Vf32;
use phong_core::{Color, Normalization, SpecularModel, View};

/// The largest highlight a skipped vector may lose, per light and channel.
const SKIP_EPSILON: f32 = 0.05 / 255.0;

/// What the lean kernel needs beyond [`Prepared`]: per light, the highlight threshold.
#[derive(Clone, Debug)]
pub struct Lean {
    thresholds: Vec<f32>,
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
        let mut thresholds = Vec::with_capacity(p.lights.len());
        for light in &p.lights {
            let f_max = match light.kind {
                Kind::Directional { .. } => 1.0,
                Kind::Positional { spot: Some(_), .. } => return None,
                Kind::Positional { k, .. } => {
                    if !(k[0] > 0.0 && k[1] >= 0.0 && k[2] >= 0.0 && k.iter().all(|c| c.is_finite())) {
                        return None;
                    }
                    1.0 / k[0]
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
            thresholds.push(if t.is_nan() { 0.0 } else { t });
        }
        Some(Lean { thresholds })
    }
}

/// `shade`'s colour term for the lanes' positions `pos` and normals `nrm` (not normalised),
/// for an object [`Lean::of`] accepts.
#[inline(always)]
pub(super) fn shade_color_lean<V: Vf32>(p: &Prepared, lean: &Lean, pos: V3<V>, nrm: V3<V>) -> [V; 3] {
    let zero = V::splat(0.0);
    let o = &p.options;
    let (v, v_ok) = match p.view {
        View::Local { eye } => V3::splat(eye).sub(pos).normalize_or_zero(),
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
    let (n, n_ok) = nrm.normalize_or_zero();
    let none = V3 {
        x: zero,
        y: zero,
        z: zero,
    };
    // The vectors the highlight is measured with, zero where `shade` has none (an invalid
    // normal or view): R·V with V zeroed (Phong), N·H with N zeroed (Blinn-Phong).
    let blinn = o.specular == SpecularModel::BlinnPhong;
    let v_spec = V3::select(V::and(n_ok, v_ok), v, none);
    let n_spec = V3::select(v_ok, n, none);
    let mut col = [V::splat(p.base.r), V::splat(p.base.g), V::splat(p.base.b)];
    // (Functions and loops, no closures: a closure is not always inlined into the AVX2
    // builds, and its intrinsics then become calls: BENCHMARKS.md, C11.)
    for (light, &threshold) in p.lights.iter().zip(&lean.thresholds) {
        let (l, factor) = match light.kind {
            Kind::Directional { to_light } => (V3::splat(to_light), V::splat(1.0)),
            Kind::Positional { position, k, .. } => {
                let dv = V3::splat(position).sub(pos);
                // At the light itself `d² = 0`: `L = 0` and `d = 0`, as `shade` has them.
                let d2 = dv.dot(dv);
                let r = d2.max(V::splat(f32::MIN_POSITIVE)).rsqrt();
                let factor = if k == [1.0, 0.0, 0.0] {
                    V::splat(1.0)
                } else {
                    let d = d2.mul(r);
                    d.mul_add(V::splat(k[2]), V::splat(k[1]))
                        .mul_add(d, V::splat(k[0]))
                        .recip()
                };
                (dv.scale(r), factor)
            }
        };
        if light.amb != Color::BLACK {
            add(&mut col, light.amb, factor);
        }
        let ndotl = n.dot(l);
        add(&mut col, light.dif, factor.mul(ndotl.max(zero)));
        if threshold == f32::INFINITY {
            continue;
        }
        let mut x = if blinn {
            let h = l.add(v);
            n_spec.dot(h).mul(h.dot(h).max(V::splat(f32::MIN_POSITIVE)).rsqrt())
        } else {
            n.scale(ndotl.add(ndotl)).sub(l).dot(v_spec)
        };
        if o.gate_specular {
            x = V::select(ndotl.gt(zero), x, zero);
        }
        if !V::any(x.ge(V::splat(threshold))) {
            continue;
        }
        add(&mut col, light.spe, factor.mul(pow_positive(x, p.shininess)));
    }
    for c in &mut col {
        *c = fin(*c);
        if o.clamp {
            *c = c.max(zero).min(V::splat(1.0));
        }
    }
    col
}

/// `col += k·f`, per channel.
#[inline(always)]
fn add<V: Vf32>(col: &mut [V; 3], k: Color, f: V) {
    col[0] = V::splat(k.r).mul_add(f, col[0]);
    col[1] = V::splat(k.g).mul_add(f, col[1]);
    col[2] = V::splat(k.b).mul_add(f, col[2]);
}
