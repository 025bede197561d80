//! The illumination model: [`shade`], the scalar specification of phong.
//!
//! ```text
//! c = e_m + a_m⊗a_g + Σ_lights att·spot·[ a_m⊗a_l + k_d·(N·L)⁺ d_m⊗d_l + k_s·f·spec·s_m⊗s_l ]
//! ```
//!
//! with `(x)⁺ = max(x, 0)`, and, by [`SpecularModel`]:
//!
//! | model        | `spec`                                      | source |
//! |--------------|---------------------------------------------|--------|
//! | `None`       | 0 (Lambert)                                 | seed 000 |
//! | `Phong`      | `((R·V)⁺)^s`, `R = 2(L·N)N − L`             | seeds 000 (slide 71), 001, 002 |
//! | `BlinnPhong` | `((N·H)⁺)^s`, `H = normalize(L + V)`        | seeds 000 (slide 81), 001; OpenGL |
//! | `Lyon`       | `(1 − βλ)⁺^γ`, `γ = 2^n`, `β = s/γ`, `λ = 1 − R·V` or `(R−V)·(R−V)/2`, only where `R·V > 0` | seed 002 (Lyon 1993) |
//!
//! `f = 1` where `N·L > 0` and 0 elsewhere when [`ShadingOptions::gate_specular`]
//! is on (seed 002: "the specular term should only be included if the dot
//! product of the diffuse term is positive"; OpenGL does the same).
//! `k_d = k_s = 1` unless [`Normalization`] is on.
//!
//! This function is the specification: the CPU kernels and the WGSL
//! shaders are tested against it. It favours clarity and exactness over
//! speed, takes every decision per call, and never returns NaN or infinity.

use crate::maps::Texels;
use crate::{Color, Light, Material};
use core::f32::consts::PI;
use glam::Vec3;

/// The specular term's formula.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum SpecularModel {
    /// No specular term: Lambert diffuse (plus ambient and emission) only.
    None,
    /// Phong 1973: `((R·V)⁺)^s` with `R = 2(L·N)N − L`.
    Phong,
    /// Blinn 1977: `((N·H)⁺)^s` with `H = normalize(L + V)` (OpenGL's model).
    #[default]
    BlinnPhong,
    /// Lyon 1993's approximation of Phong: `max(0, 1 − βλ)^γ`, `γ = 2^squarings`,
    /// `β = s/γ`, computed by `squarings` squarings, and only where `R·V > 0`.
    /// `squarings` is taken as at most 16.
    Lyon {
        /// `n` in `γ = 2^n` (seed 002: "typically, 4 or 8 will be enough" for γ, i.e. n = 2 or 3).
        squarings: u32,
        /// How `λ ≈ 1 − R·V` is computed.
        lambda: LyonLambda,
    },
}

/// Lyon's `λ`, the distance of `R·V` from 1.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum LyonLambda {
    /// `λ = 1 − R·V` (exact).
    #[default]
    Dot,
    /// `λ = (R − V)·(R − V) / 2`, equal to `1 − R·V` for unit vectors (seed 002).
    Difference,
}

/// Energy normalisation of the BRDF (seed 000, slide 99: plain Phong "is not
/// energy preserving").
///
/// When on, `k_d = 1/π` and the specular term becomes a normalised lobe
/// times `(N·L)⁺` (the result is then radiance from a BRDF under irradiance
/// `I·(N·L)⁺`): Phong `k_s = (s + 2)/(2π)` (Lafortune & Willems 1994, energy
/// conserving when `d_m + s_m <= 1`), Blinn-Phong `k_s = (s + 8)/(8π)`
/// (Akenine-Möller et al., *Real-Time Rendering*; an approximation whose
/// directional albedo reaches 1.075 at normal incidence for `s ≈ 10`, measured
/// by the tests), or the exact Blinn-Phong factor
/// `k_s = (s + 2)(s + 4) / (8π(2^(−s/2) + s))`, the inverse of the lobe's
/// albedo at normal incidence `8π(s + 2^(−s/2))/((s + 2)(s + 4))`, where it is
/// largest, so energy conserving when `d_m + s_m <= 1`. The factor is applied
/// to whichever specular model is chosen.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Normalization {
    /// Classic, unnormalised model: `k_d = k_s = 1`, specular not multiplied by `N·L`.
    #[default]
    None,
    /// `k_d = 1/π`, `k_s = (s + 2)/(2π)`.
    Phong,
    /// `k_d = 1/π`, `k_s = (s + 8)/(8π)` (the common approximation).
    BlinnPhong,
    /// `k_d = 1/π`, `k_s = (s + 2)(s + 4) / (8π(2^(−s/2) + s))` (exact at normal incidence).
    BlinnPhongExact,
}

impl Normalization {
    /// `(k_d, k_s)` for shininess `s`.
    #[inline]
    pub fn factors(self, s: f32) -> (f32, f32) {
        match self {
            Normalization::None => (1.0, 1.0),
            Normalization::Phong => (1.0 / PI, (s + 2.0) / (2.0 * PI)),
            Normalization::BlinnPhong => (1.0 / PI, (s + 8.0) / (8.0 * PI)),
            Normalization::BlinnPhongExact => (1.0 / PI, (s + 2.0) * (s + 4.0) / (8.0 * PI * ((-s / 2.0).exp2() + s))),
        }
    }
}

/// Where the viewer is, for the view vector `V`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum View {
    /// Local viewer: `V = normalize(eye − P)` per point (perspective camera).
    Local {
        /// Eye position, world space.
        eye: Vec3,
    },
    /// Infinite viewer: one constant `V` (orthographic camera; OpenGL's
    /// default `GL_LIGHT_MODEL_LOCAL_VIEWER = false`, `V = (0, 0, 1)` in eye space).
    Infinite {
        /// Direction from the scene towards the viewer, any non-zero length.
        to_viewer: Vec3,
    },
}

impl View {
    /// The unit view vector `V` at `point`, zero when undefined.
    #[inline]
    pub fn at(&self, point: Vec3) -> Vec3 {
        match *self {
            View::Local { eye } => (eye - point).normalize_or_zero(),
            View::Infinite { to_viewer } => to_viewer.normalize_or_zero(),
        }
    }
}

/// The options of the model, each defaulting as documented.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadingOptions {
    /// Specular formula. Default: Blinn-Phong (OpenGL's).
    pub specular: SpecularModel,
    /// Specular only where `N·L > 0`. Default: on (seed 002; OpenGL).
    pub gate_specular: bool,
    /// Clamp the final colour to `[0, 1]`. Default: on (seed 001's `clamp`).
    /// The separate terms of [`Shading`] are never clamped.
    pub clamp: bool,
    /// Energy normalisation. Default: none.
    pub normalization: Normalization,
    /// Two-sided lighting. Default: off. For a lone point, [`shade`] flips the
    /// normal where `N·V < 0`; the renderers apply OpenGL's rule instead, which
    /// decides by polygon facing (a back-facing triangle is lit with its normals
    /// flipped, a front-facing one never), and call `shade` with this off.
    pub two_sided: bool,
}

impl Default for ShadingOptions {
    fn default() -> Self {
        ShadingOptions {
            specular: SpecularModel::BlinnPhong,
            gate_specular: true,
            clamp: true,
            normalization: Normalization::None,
            two_sided: false,
        }
    }
}

impl ShadingOptions {
    /// OpenGL 2.1 fixed-function lighting, term for term (spec §2.14.1):
    /// `c = e + a_m·a_g + Σ att·spot·[a_m·a_l + (N·L)⁺·d_m·d_l + f·((N·H)⁺)^s·s_m·s_l]`,
    /// `f = 1` only where `N·L > 0`, clamped to `[0, 1]`. The viewer (local
    /// or infinite) is the [`View`] passed to [`shade`]; two-sided lighting is
    /// `GL_LIGHT_MODEL_TWO_SIDE`.
    pub fn opengl(two_sided: bool) -> Self {
        ShadingOptions {
            specular: SpecularModel::BlinnPhong,
            gate_specular: true,
            clamp: true,
            normalization: Normalization::None,
            two_sided,
        }
    }
}

/// The global lighting environment: the ambient light `a_g` and the lights.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Lighting {
    ambient: Color,
    lights: Vec<Light>,
}

impl Lighting {
    /// Global ambient `ambient` (finite, `>= 0`) and `lights`.
    pub fn new(ambient: Color, lights: Vec<Light>) -> Result<Self, crate::Error> {
        if !ambient.is_finite_non_negative() {
            return Err(crate::Error::InvalidColor {
                what: "ambient light",
                value: ambient.to_array(),
            });
        }
        Ok(Lighting { ambient, lights })
    }
    /// The global ambient light `a_g` (Wikipedia's `i_a`).
    pub fn ambient(&self) -> Color {
        self.ambient
    }
    /// The lights.
    pub fn lights(&self) -> &[Light] {
        &self.lights
    }
}

/// A point to shade: its position and normal, world space. The normal need
/// not be unit length (it is normalised, as after Phong interpolation); a
/// zero or non-finite normal gives no diffuse or specular light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfacePoint {
    /// Position `P`.
    pub position: Vec3,
    /// Normal `N`, any length.
    pub normal: Vec3,
}

/// The result of [`shade`]: the colour and its terms (seed 000 slide 92:
/// "ambiente + diffusivo + speculare = totale").
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Shading {
    /// Emission plus every ambient term: `e_m + a_m⊗a_g + Σ att·spot·a_m⊗a_l`.
    pub ambient: Color,
    /// `Σ att·spot·k_d·(N·L)⁺·d_m⊗d_l`.
    pub diffuse: Color,
    /// `Σ att·spot·k_s·f·spec·s_m⊗s_l`.
    pub specular: Color,
    /// `ambient + diffuse + specular`, clamped to `[0, 1]` if the option is on.
    pub color: Color,
}

/// `(x⁺)^s`, with `0^s = 0` even for `s = 0`: OpenGL implementations give a
/// specular factor of 1 where the dot product is > 0 and 0 elsewhere when the
/// shininess is 0, and so does this. `x` is clamped to 1 against rounding.
///
/// (Mesa's fixed-function lighting deviates at `s = 0` under an attenuated or spot light:
/// its program overwrites the exponent with `N·L` and computes `(N·L)^(N·L)`; phong
/// follows the OpenGL 2.1 equation. Everywhere else phong's `opengl` model matches Mesa
/// within 1/255, tested in `crates/phong-raster/tests/mesa.rs`.)
#[inline]
pub fn pow_positive(x: f32, s: f32) -> f32 {
    if x > 0.0 { x.min(1.0).powf(s) } else { 0.0 }
}

/// Lyon's `max(0, 1 − βλ)^(2^n)` with `β = s / 2^n`, by `n` squarings.
#[inline]
pub fn lyon(lambda: f32, s: f32, squarings: u32) -> f32 {
    let n = squarings.min(16);
    let gamma = (1u32 << n) as f32;
    let mut t = (1.0 - (s / gamma) * lambda).max(0.0);
    for _ in 0..n {
        t *= t;
    }
    t
}

/// The specular factor `spec` of `model` for unit `n`, `l`, `v` and shininess
/// `s`; 0 where the half vector or reflection is undefined (`V + L = 0`, or a
/// zero `v`).
#[inline]
pub fn specular_factor(model: SpecularModel, n: Vec3, l: Vec3, v: Vec3, s: f32) -> f32 {
    match model {
        SpecularModel::None => 0.0,
        SpecularModel::Phong => {
            let r = 2.0 * l.dot(n) * n - l;
            pow_positive(r.dot(v), s)
        }
        SpecularModel::BlinnPhong => {
            let h = (l + v).normalize_or_zero();
            if h == Vec3::ZERO {
                0.0
            } else {
                pow_positive(n.dot(h), s)
            }
        }
        SpecularModel::Lyon { squarings, lambda } => {
            let r = 2.0 * l.dot(n) * n - l;
            let rv = r.dot(v);
            if rv <= 0.0 {
                return 0.0;
            }
            let lam = match lambda {
                LyonLambda::Dot => 1.0 - rv,
                LyonLambda::Difference => {
                    let d = r - v;
                    0.5 * d.dot(d)
                }
            };
            lyon(lam.max(0.0), s, squarings)
        }
    }
}

/// Shades one point: the Phong illumination model with every option (see
/// the module docs for the equation).
///
/// Degenerate input never gives NaN or infinity: a zero or NaN normal, a
/// point light at the point, or `V + L = 0` drop the terms that need the
/// undefined vector; a NaN position drops positional lights; whatever
/// remains NaN is replaced by 0 and an overflow by `f32::MAX`.
pub fn shade(
    point: &SurfacePoint,
    view: &View,
    material: &Material,
    lighting: &Lighting,
    options: &ShadingOptions,
) -> Shading {
    let s = material.shininess();
    let start = material.emission() + material.ambient() * lighting.ambient();
    let (ambient, diffuse, specular) = accumulate(point, view, material, s, lighting, options, start);
    let ambient = finite_or_zero(ambient);
    let diffuse = finite_or_zero(diffuse);
    let specular = finite_or_zero(specular);
    let sum = finite_or_zero(ambient + diffuse + specular);
    Shading {
        ambient,
        diffuse,
        specular,
        color: if options.clamp { sum.clamp01() } else { sum },
    }
}

/// Shades one point of a textured material: [`shade`]'s terms with the material's colours,
/// then the texels ([`Texels`], 1 where a map is absent) applied as OpenGL's `GL_MODULATE`
/// with `GL_SEPARATE_SPECULAR_COLOR`, generalised to one map per colour:
///
/// ```text
/// s' = s·T_Ns                                   (the shininess the terms are lit with)
/// P  = e_m·[no map_Ke] + A·[no map_Ka, no AO] + D  (A: every ambient term; D: the diffuse sum)
/// Q  = e_m⊗T_Ke·[map_Ke] + A⊗T_Ka·T_AO·[map_Ka or AO]     (T_Ka is T_Kd without map_Ka)
/// c  = clamp( clamp(P)⊗T_Kd + Q + clamp(S)⊗T_Ks )     (clamps only with `options.clamp`)
/// ```
///
/// `T_AO` is glTF's occlusion; glTF's metallic-roughness map gives `T_Kd`, `T_Ks` and `T_Ns`
/// ([`MetalRough`](crate::MetalRough)).
///
/// With only `map_Kd` this is OpenGL's fixed function exactly: the primary colour (emission +
/// ambient + diffuse) clamped, times the texel, plus the clamped specular, clamped. The
/// specular term is added after the texture, so a dark texel does not darken the highlight.
/// Without maps (every texel 1) it equals [`shade`] (the terms are non-negative). The terms
/// reported are `ambient = e_m⊗(T_Ke or T_Kd) + A⊗(T_Ka or T_Kd)·T_AO`, `diffuse = D⊗T_Kd`,
/// `specular = S⊗T_Ks`, before any clamp.
pub fn shade_textured(
    point: &SurfacePoint,
    view: &View,
    material: &Material,
    texels: &Texels,
    lighting: &Lighting,
    options: &ShadingOptions,
) -> Shading {
    let split = (
        texels.emission.is_some(),
        texels.ambient.is_some() || texels.occlusion.is_some(),
    );
    let (lit, [e, a, d, sp]) = light(point, view, material, texels.shininess, split, lighting, options);
    let td = Color::new(texels.diffuse[0], texels.diffuse[1], texels.diffuse[2]);
    Shading {
        ambient: finite_or_zero(e * texels.emission.unwrap_or(td) + a * texels.ambient_texel()),
        diffuse: finite_or_zero(d * td),
        specular: finite_or_zero(sp * texels.specular),
        color: lit.modulate(texels, options.clamp),
    }
}

/// A textured point's light before its texels (see [`shade_textured`]): what Gouraud shading
/// computes at each vertex and interpolates, so that the texels are applied per pixel.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Lit {
    /// `P`, the terms the diffuse map modulates (clamped with `clamp`).
    pub primary: Color,
    /// `e_m` where an emission map modulates it, else 0.
    pub emission: Color,
    /// `A` where an ambient map modulates it, else 0.
    pub ambient: Color,
    /// `S` (clamped with `clamp`).
    pub specular: Color,
}

impl Lit {
    /// The colour with `texels` applied: `clamp(P⊗T_Kd + e⊗T_Ke + A⊗T_Ka + S⊗T_Ks)`.
    #[inline]
    pub fn modulate(&self, t: &Texels, clamp: bool) -> Color {
        let td = Color::new(t.diffuse[0], t.diffuse[1], t.diffuse[2]);
        let sum = self.primary * td
            + self.emission * t.emission.unwrap_or(Color::WHITE)
            + self.ambient * t.ambient_texel()
            + self.specular * t.specular;
        let sum = finite_or_zero(sum);
        if clamp { sum.clamp01() } else { sum }
    }
}

/// The light of a textured point (shininess scaled by `shininess`; `split`: whether the
/// emission and the ambient terms have maps of their own): its [`Lit`] and the untextured
/// terms `[e_m, A, D, S]`.
pub fn light(
    point: &SurfacePoint,
    view: &View,
    material: &Material,
    shininess: f32,
    split: (bool, bool),
    lighting: &Lighting,
    options: &ShadingOptions,
) -> (Lit, [Color; 4]) {
    let s = material.shininess() * shininess.max(0.0);
    let start = material.ambient() * lighting.ambient();
    let (a, d, sp) = accumulate(point, view, material, s, lighting, options, start);
    let (a, d, sp) = (finite_or_zero(a), finite_or_zero(d), finite_or_zero(sp));
    let e = material.emission();
    let mut lit = Lit {
        primary: d,
        specular: sp,
        ..Lit::default()
    };
    if split.0 {
        lit.emission = e;
    } else {
        lit.primary += e;
    }
    if split.1 {
        lit.ambient = a;
    } else {
        lit.primary += a;
    }
    if options.clamp {
        lit.primary = lit.primary.clamp01();
        lit.specular = lit.specular.clamp01();
    }
    (lit, [e, a, d, sp])
}

/// The light sums of [`shade`] with shininess `s`: `(ambient, diffuse, specular)`, the ambient
/// starting from `ambient` (the emission and global ambient, as the caller splits them).
fn accumulate(
    point: &SurfacePoint,
    view: &View,
    material: &Material,
    s: f32,
    lighting: &Lighting,
    options: &ShadingOptions,
    mut ambient: Color,
) -> (Color, Color, Color) {
    let v = view.at(point.position);
    let mut n = point.normal.normalize_or_zero();
    if options.two_sided && n.dot(v) < 0.0 {
        n = -n;
    }
    let (kd, ks) = options.normalization.factors(s);
    let normalized = options.normalization != Normalization::None;
    let mut diffuse = Color::BLACK;
    let mut specular = Color::BLACK;

    for light in lighting.lights() {
        let inc = light.incidence(point.position);
        if !(inc.factor > 0.0 && inc.factor.is_finite()) {
            continue;
        }
        let lc = light.color();
        ambient += material.ambient() * lc.ambient() * inc.factor;
        let l = inc.to_light;
        if l == Vec3::ZERO || n == Vec3::ZERO {
            continue;
        }
        let ndotl = n.dot(l);
        if ndotl > 0.0 {
            diffuse += material.diffuse() * lc.diffuse() * (inc.factor * kd * ndotl);
        } else if options.gate_specular {
            continue;
        }
        if v == Vec3::ZERO {
            continue;
        }
        let mut spec = specular_factor(options.specular, n, l, v, s);
        if normalized {
            spec *= ndotl.max(0.0);
        }
        if spec > 0.0 {
            specular += material.specular() * lc.specular() * (inc.factor * ks * spec);
        }
    }
    (ambient, diffuse, specular)
}

/// NaN becomes 0 and ±infinity the largest finite `f32` of that sign.
#[inline]
fn finite_or_zero(c: Color) -> Color {
    let f = |x: f32| if x.is_nan() { 0.0 } else { x.clamp(f32::MIN, f32::MAX) };
    Color::new(f(c.r), f(c.g), f(c.b))
}
