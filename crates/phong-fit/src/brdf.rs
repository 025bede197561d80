//! Fitting a Phong material to a BRDF: analytic microfacet models (GGX, Beckmann), Ward, or a
//! measured BRDF in the MERL format.
//!
//! The fit compares reflected radiance under unit irradiance, `f(l, v)·cos θ_l`, over a grid of
//! incident and outgoing directions on the hemisphere, weighted by the grid's solid angle (the
//! cosine-weighted error of Ngan, Durand and Matusik 2005). The Phong side is phong-core's
//! `shade` with a unit directional light and the model's energy normalisation (the form that is
//! a BRDF): for a fixed exponent it is linear in the diffuse and specular colours, so the fit is
//! the image fit's variable projection in two unknowns a channel.

use crate::FitError;
use crate::lsq::Normal;
use glam::Vec3;
use phong_core::{
    Color, Light, LightColor, Lighting, Material, Normalization, ShadingOptions, SpecularModel, SurfacePoint, View,
    shade,
};
use std::f64::consts::PI;
use std::path::Path;

/// A reflectance to fit.
pub enum Brdf {
    /// Cook-Torrance with the GGX (Trowbridge-Reitz) distribution, Smith's shadowing and
    /// Schlick's Fresnel, over a Lambert base.
    Ggx {
        /// Roughness `α` (GGX's, the square of the "perceptual" roughness).
        alpha: f64,
        /// Fresnel reflectance at normal incidence, per channel.
        f0: [f64; 3],
        /// Lambert albedo, per channel.
        kd: [f64; 3],
    },
    /// The same with Beckmann's distribution and the V-cavity shadowing of Cook and Torrance.
    Beckmann {
        /// RMS slope `m`.
        alpha: f64,
        /// Fresnel reflectance at normal incidence.
        f0: [f64; 3],
        /// Lambert albedo.
        kd: [f64; 3],
    },
    /// Ward's isotropic model.
    Ward {
        /// Roughness `α`.
        alpha: f64,
        /// Specular albedo.
        ks: [f64; 3],
        /// Lambert albedo.
        kd: [f64; 3],
    },
    /// A measured BRDF in the MERL layout.
    Merl(Merl),
}

/// A MERL BRDF: 90 θ_h × 90 θ_d × 180 φ_d bins per channel, already scaled.
pub struct Merl {
    data: Vec<f64>,
}

/// Bins of the MERL layout.
const TH: usize = 90;
const TD: usize = 90;
const PD: usize = 180;
const SCALE: [f64; 3] = [1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0];

impl Merl {
    /// Reads a MERL `.binary` file: three little-endian int32 dimensions (90, 90, 180), then
    /// 3 × 1 458 000 float64 values, channel by channel.
    pub fn read(path: &Path) -> Result<Merl, FitError> {
        let bad = |why: String| FitError::Input(format!("{}: {why}", path.display()));
        // A MERL file is 34 992 012 bytes; twice that is the bound.
        let bytes = phong_scene::read_bounded(path, 70_000_000, "MERL file").map_err(|e| {
            bad(format!(
                "cannot read: {}",
                std::error::Error::source(&e).map(|s| s.to_string()).unwrap_or_default()
            ))
        })?;
        Merl::parse(&bytes).map_err(bad)
    }

    /// [`Merl::read`] of the file's bytes.
    pub fn parse(bytes: &[u8]) -> Result<Merl, String> {
        if bytes.len() < 12 {
            return Err(format!(
                "a MERL file starts with 12 bytes of dimensions; it has {} bytes",
                bytes.len()
            ));
        }
        let dim = |i: usize| i32::from_le_bytes([bytes[4 * i], bytes[4 * i + 1], bytes[4 * i + 2], bytes[4 * i + 3]]);
        let dims = [dim(0), dim(1), dim(2)];
        if dims != [TH as i32, TD as i32, PD as i32] {
            return Err(format!("dimensions {dims:?}; a MERL file has [90, 90, 180]"));
        }
        let n = TH * TD * PD;
        let want = 12 + 3 * n * 8;
        if bytes.len() != want {
            return Err(format!(
                "{} bytes; a MERL file of these dimensions has {want} (truncated?)",
                bytes.len()
            ));
        }
        let data = bytes[12..]
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes")))
            .collect();
        Ok(Merl { data })
    }

    /// The file's bytes for `f(θ_h, θ_d, φ_d)` per channel (unscaled as the format stores it):
    /// for tests and for writing synthetic measurements.
    pub fn encode(f: impl Fn(f64, f64, f64) -> [f64; 3]) -> Vec<u8> {
        let n = TH * TD * PD;
        let mut vals = vec![0.0; 3 * n];
        for ih in 0..TH {
            // Bin centres; θ_h has square-root spacing: index = sqrt(θ_h / 90°) · 90.
            let th = ((ih as f64 + 0.5) / TH as f64).powi(2) * PI / 2.0;
            for id in 0..TD {
                let td = (id as f64 + 0.5) / TD as f64 * PI / 2.0;
                for ip in 0..PD {
                    let pd = (ip as f64 + 0.5) / PD as f64 * PI;
                    let v = f(th, td, pd);
                    let i = ip + id * PD + ih * PD * TD;
                    for c in 0..3 {
                        vals[i + c * n] = v[c] / SCALE[c];
                    }
                }
            }
        }
        let mut out = Vec::with_capacity(12 + vals.len() * 8);
        for d in [TH as i32, TD as i32, PD as i32] {
            out.extend_from_slice(&d.to_le_bytes());
        }
        for v in vals {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out
    }

    /// The BRDF for unit `l`, `v` in the frame whose normal is +z (MERL's lookup: half and
    /// difference angles, nearest bin); `None` where unmeasured (negative), or where the file
    /// holds a value no measurement has (not finite, or above 10⁶).
    pub fn eval(&self, l: [f64; 3], v: [f64; 3]) -> Option<[f64; 3]> {
        let (th, td, pd) = half_diff(l, v);
        let ih = if th <= 0.0 {
            0
        } else {
            (((th / (PI / 2.0)) * 90.0 * 90.0).sqrt() as usize).min(TH - 1)
        };
        let id = ((td / (PI / 2.0) * TD as f64) as usize).min(TD - 1);
        let pd = if pd < 0.0 { pd + PI } else { pd };
        let ip = ((pd / PI * PD as f64) as usize).min(PD - 1);
        let i = ip + id * PD + ih * PD * TD;
        let n = TH * TD * PD;
        let out = [0, 1, 2].map(|c| self.data[i + c * n] * SCALE[c]);
        out.iter().all(|x| (0.0..=1e6).contains(x)).then_some(out)
    }
}

/// Rusinkiewicz's half/difference angles `(θ_h, θ_d, φ_d)` of `l`, `v` (normal +z).
fn half_diff(l: [f64; 3], v: [f64; 3]) -> (f64, f64, f64) {
    let h = norm([l[0] + v[0], l[1] + v[1], l[2] + v[2]]);
    let th = h[2].clamp(-1.0, 1.0).acos();
    let ph = h[1].atan2(h[0]);
    // Rotate l by −φ_h about z, then by −θ_h about y.
    let rot_z = |p: [f64; 3], a: f64| [p[0] * a.cos() - p[1] * a.sin(), p[0] * a.sin() + p[1] * a.cos(), p[2]];
    let rot_y = |p: [f64; 3], a: f64| [p[0] * a.cos() + p[2] * a.sin(), p[1], -p[0] * a.sin() + p[2] * a.cos()];
    let d = rot_y(rot_z(l, -ph), -th);
    let td = d[2].clamp(-1.0, 1.0).acos();
    let pd = d[1].atan2(d[0]);
    (th, td, pd)
}

fn norm(a: [f64; 3]) -> [f64; 3] {
    let l = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    if l > 0.0 { a.map(|x| x / l) } else { a }
}

impl Brdf {
    /// Parses `ggx:alpha=0.2,f0=0.04,kd=0.5`, `beckmann:...`, `ward:alpha=..,ks=..,kd=..` (a
    /// colour is one number or `r/g/b`) or `merl:FILE.binary`.
    pub fn parse(spec: &str) -> Result<Brdf, FitError> {
        let bad = |m: String| FitError::Input(format!("--brdf {spec}: {m}"));
        let (kind, rest) = spec.split_once(':').ok_or_else(|| {
            bad("expected KIND:PARAMS (ggx:alpha=0.2,f0=0.04,kd=0.5; beckmann:...; ward:alpha=..,ks=..,kd=..; merl:FILE)".into())
        })?;
        if kind == "merl" {
            return Ok(Brdf::Merl(Merl::read(Path::new(rest))?));
        }
        let mut alpha = None;
        let (mut f0, mut kd, mut ks) = (None, None, None);
        for kv in rest.split(',').filter(|s| !s.is_empty()) {
            let (k, v) = kv
                .split_once('=')
                .ok_or_else(|| bad(format!("\"{kv}\" is not KEY=VALUE")))?;
            let nums: Vec<f64> = v
                .split('/')
                .map(|x| x.trim().parse::<f64>().ok().filter(|x| x.is_finite() && *x >= 0.0))
                .collect::<Option<_>>()
                .ok_or_else(|| bad(format!("`{k}`: \"{v}\" is not a number >= 0 (or r/g/b)")))?;
            let col = match nums.as_slice() {
                [x] => [*x; 3],
                [r, g, b] => [*r, *g, *b],
                _ => return Err(bad(format!("`{k}`: one number or r/g/b"))),
            };
            match k {
                "alpha" | "roughness" => alpha = Some(col[0]),
                "f0" => f0 = Some(col),
                "kd" => kd = Some(col),
                "ks" => ks = Some(col),
                _ => return Err(bad(format!("unknown key `{k}`"))),
            }
        }
        let alpha = alpha.ok_or_else(|| bad("needs alpha=...".into()))?;
        if !(1e-3..=2.0).contains(&alpha) {
            return Err(bad(format!("`alpha` must be in [0.001, 2], got {alpha}")));
        }
        let kd = kd.unwrap_or([0.0; 3]);
        Ok(match kind {
            "ggx" => Brdf::Ggx {
                alpha,
                f0: f0.unwrap_or([0.04; 3]),
                kd,
            },
            "beckmann" => Brdf::Beckmann {
                alpha,
                f0: f0.unwrap_or([0.04; 3]),
                kd,
            },
            "ward" => Brdf::Ward {
                alpha,
                ks: ks.unwrap_or([0.05; 3]),
                kd,
            },
            other => {
                return Err(bad(format!(
                    "unknown kind \"{other}\"; expected ggx, beckmann, ward or merl"
                )));
            }
        })
    }

    /// `f(l, v)` per channel for unit `l`, `v` above the surface (normal +z); `None` where
    /// unmeasured.
    pub fn eval(&self, l: [f64; 3], v: [f64; 3]) -> Option<[f64; 3]> {
        let (nl, nv) = (l[2], v[2]);
        if nl <= 0.0 || nv <= 0.0 {
            return Some([0.0; 3]);
        }
        let h = norm([l[0] + v[0], l[1] + v[1], l[2] + v[2]]);
        let nh = h[2].max(1e-9);
        let vh = (v[0] * h[0] + v[1] * h[1] + v[2] * h[2]).max(0.0);
        let schlick = |f0: f64| f0 + (1.0 - f0) * (1.0 - vh).powi(5);
        let lambert = |kd: &[f64; 3]| kd.map(|k| k / PI);
        Some(match self {
            Brdf::Ggx { alpha, f0, kd } => {
                let a2 = alpha * alpha;
                let dd = a2 / (PI * (nh * nh * (a2 - 1.0) + 1.0).powi(2));
                let g1 = |x: f64| 2.0 * x / (x + (a2 + (1.0 - a2) * x * x).sqrt());
                let spec = dd * g1(nl) * g1(nv) / (4.0 * nl * nv);
                let base = lambert(kd);
                [0, 1, 2].map(|c| base[c] + spec * schlick(f0[c]))
            }
            Brdf::Beckmann { alpha, f0, kd } => {
                let a2 = alpha * alpha;
                let tan2 = (1.0 - nh * nh) / (nh * nh);
                let dd = (-tan2 / a2).exp() / (PI * a2 * nh.powi(4));
                let g = (2.0 * nh * nv / vh.max(1e-9))
                    .min(2.0 * nh * nl / vh.max(1e-9))
                    .min(1.0);
                let spec = dd * g / (4.0 * nl * nv);
                let base = lambert(kd);
                [0, 1, 2].map(|c| base[c] + spec * schlick(f0[c]))
            }
            Brdf::Ward { alpha, ks, kd } => {
                let a2 = alpha * alpha;
                let tan2 = (1.0 - nh * nh) / (nh * nh);
                let spec = (-tan2 / a2).exp() / (4.0 * PI * a2 * (nl * nv).sqrt());
                let base = lambert(kd);
                [0, 1, 2].map(|c| base[c] + ks[c] * spec)
            }
            Brdf::Merl(m) => return m.eval(l, v),
        })
    }
}

/// The Phong models the BRDF fit knows, each with its energy normalisation.
pub fn model_options(model: SpecularModel) -> ShadingOptions {
    ShadingOptions {
        specular: model,
        normalization: match model {
            SpecularModel::Phong => Normalization::Phong,
            _ => Normalization::BlinnPhong,
        },
        clamp: false,
        ..ShadingOptions::default()
    }
}

/// The unit white directional light arriving from `l` (towards the light, normal +z).
fn unit_light(l: [f64; 3]) -> Lighting {
    let to_light = Vec3::new(l[0] as f32, l[1] as f32, l[2] as f32);
    let light =
        Light::directional(-to_light, LightColor::uniform(Color::WHITE).expect("white")).expect("unit direction");
    Lighting::new(Color::BLACK, vec![light]).expect("a light")
}

/// The Phong side at directions `l`, `v` (normal +z): `shade` of material `m` under a unit
/// light from `l`, seen from `v`, that is `f·cos θ_l` of the Phong BRDF the options define.
pub fn reflected(m: &Material, options: &ShadingOptions, lighting: &Lighting, v: [f64; 3]) -> phong_core::Shading {
    let point = SurfacePoint {
        position: Vec3::ZERO,
        normal: Vec3::Z,
    };
    let view = View::Infinite {
        to_viewer: Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32),
    };
    shade(&point, &view, m, lighting, options)
}

/// [`reflected`]'s green channel (diffuse plus specular) for the fitted material, for plots.
pub fn fitted_lobe(fit: &BrdfFit, l: [f64; 3], v: [f64; 3]) -> f64 {
    let s = reflected(&fit.material, &fit.options, &unit_light(l), v);
    f64::from(s.diffuse.g + s.specular.g)
}

/// The result of a BRDF fit.
pub struct BrdfFit {
    /// The fitted material (diffuse and specular colours, exponent; render it with `options`).
    pub material: Material,
    /// The shading options the material is meant for (normalisation on).
    pub options: ShadingOptions,
    /// Cosine-weighted RMS error of `f·cos θ_l`.
    pub rmse: f64,
    /// `(s, rmse)` for every exponent tried.
    pub curve: Vec<(f32, f64)>,
    /// Samples used.
    pub samples: usize,
    /// The error by incident angle: `(from °, to °, rmse, samples)`, 15° bins.
    pub by_incidence: Vec<(f64, f64, f64, usize)>,
}

/// One sample: directions, weight, the target's `f·cos θ_l`.
struct Sample {
    l: [f64; 3],
    v: [f64; 3],
    w: f64,
    t: [f64; 3],
}

/// Directions on MERL's own grid of half and difference angles, as Ngan et al. fit: θ_h with
/// square-root spacing (dense at the specular peak, so narrow lobes are resolved), θ_d and
/// φ_d uniform (φ_h = 0 by isotropy, φ_d over [0, π] by reciprocity). Each sample is weighted
/// by the solid angle it stands for, `dω_l dω_v = 4 cos θ_d dω_h dω_d` (Rusinkiewicz 1998);
/// pairs with `l` or `v` below the horizon are left out.
fn samples(brdf: &Brdf) -> Vec<Sample> {
    let (nh, nd, np) = (64, 32, 32);
    let mut out = Vec::new();
    for i in 0..nh {
        let u = (i as f64 + 0.5) / nh as f64;
        let th = u * u * PI / 2.0;
        let dth = 2.0 * u / nh as f64 * PI / 2.0;
        let h = [th.sin(), 0.0, th.cos()];
        for j in 0..nd {
            let td = (j as f64 + 0.5) / nd as f64 * PI / 2.0;
            for k in 0..np {
                let pd = (k as f64 + 0.5) / np as f64 * PI;
                // d in the half vector's frame, then rotated by θ_h about y.
                let d = [td.sin() * pd.cos(), td.sin() * pd.sin(), td.cos()];
                let l = [
                    d[0] * th.cos() + d[2] * th.sin(),
                    d[1],
                    -d[0] * th.sin() + d[2] * th.cos(),
                ];
                let hl = h[0] * l[0] + h[2] * l[2];
                let v = [2.0 * hl * h[0] - l[0], -l[1], 2.0 * hl * h[2] - l[2]];
                if l[2] <= 0.01 || v[2] <= 0.01 {
                    continue;
                }
                let Some(f) = brdf.eval(l, v) else { continue };
                let w = 4.0 * td.cos() * th.sin() * td.sin() * dth * (PI / 2.0 / nd as f64) * (PI / np as f64);
                out.push(Sample {
                    l,
                    v,
                    w,
                    t: f.map(|x| x * l[2]),
                });
            }
        }
    }
    out
}

/// Fits `model` to `brdf`.
pub fn fit_brdf(brdf: &Brdf, model: SpecularModel) -> Result<BrdfFit, FitError> {
    let options = model_options(model);
    let samples = samples(brdf);
    if samples.len() < 100 {
        return Err(FitError::Input(format!(
            "the BRDF has only {} measured samples over the hemisphere: nothing to fit",
            samples.len()
        )));
    }
    let lightings: Vec<Lighting> = samples.iter().map(|s| unit_light(s.l)).collect();
    // Basis values at exponent s: (diffuse, specular) of shade with unit colours.
    let basis = |s: f32| -> Vec<(f64, f64)> {
        let m = Material::new(Color::BLACK, Color::WHITE, Color::WHITE, Color::BLACK, s).expect("valid");
        samples
            .iter()
            .zip(&lightings)
            .map(|(smp, lighting)| {
                let sh = reflected(&m, &options, lighting, smp.v);
                (f64::from(sh.diffuse.r), f64::from(sh.specular.r))
            })
            .collect()
    };
    let mut curve = Vec::new();
    let total_w: f64 = samples.iter().map(|s| s.w).sum::<f64>() * 3.0;
    let mut eval = |s: f32| -> ([[f64; 2]; 3], f64) {
        let b = basis(s);
        let mut n = [Normal::<2>::default(); 3];
        for (smp, (d, sp)) in samples.iter().zip(&b) {
            let r = smp.w.sqrt();
            for c in 0..3 {
                n[c].add(&[d * r, sp * r], smp.t[c] * r);
            }
        }
        let mut x = [[0.0; 2]; 3];
        let mut res = 0.0;
        for c in 0..3 {
            // Colours up to 1: what a material can hold.
            let (xc, rc) = n[c].solve(&[true, true], &[0.0; 2], 0.0, 1.0);
            x[c] = xc;
            res += rc;
        }
        let rmse = (res / total_w).sqrt();
        curve.push((s, rmse));
        (x, rmse)
    };
    let grid: Vec<f32> = (0..=30).map(|k| 10f32.powf(4.0 * k as f32 / 30.0)).collect();
    let ((x, rmse), s) = crate::search_exponent(&grid, 20, |s| Ok::<_, FitError>(eval(s)))?;
    curve.sort_by(|a, b| a.0.total_cmp(&b.0));
    let col = |k: usize| Color::new(x[0][k] as f32, x[1][k] as f32, x[2][k] as f32);
    let material = Material::new(Color::BLACK, col(0), col(1), Color::BLACK, s)
        .map_err(|e| FitError::Input(format!("the BRDF gives no Phong material ({e})")))?;
    // The error table: weighted RMS residual by incident angle.
    let b = basis(s);
    let mut bins = [(0.0f64, 0.0f64, 0usize); 6];
    for (smp, (d, sp)) in samples.iter().zip(&b) {
        let deg = smp.l[2].clamp(-1.0, 1.0).acos().to_degrees();
        let k = ((deg / 15.0) as usize).min(5);
        for c in 0..3 {
            let e = x[c][0] * d + x[c][1] * sp - smp.t[c];
            bins[k].0 += smp.w * e * e;
            bins[k].1 += smp.w;
        }
        bins[k].2 += 1;
    }
    let by_incidence = bins
        .iter()
        .enumerate()
        .filter(|(_, b)| b.2 > 0)
        .map(|(k, b)| {
            (
                k as f64 * 15.0,
                k as f64 * 15.0 + 15.0,
                (b.0 / b.1.max(1e-300)).sqrt(),
                b.2,
            )
        })
        .collect();
    Ok(BrdfFit {
        material,
        options,
        rmse,
        curve,
        samples: samples.len(),
        by_incidence,
    })
}
