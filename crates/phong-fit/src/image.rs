//! Fitting a material to a target image of a known scene, by variable projection.
//!
//! For a fixed exponent `s` the rendered object is, per channel, linear in the material's
//! colours: `c = e·E + a·A + d·D + k·S(s)`, where `E`, `A`, `D`, `S` are the renderer's own
//! term images of the object with a unit colour in that term (emission, ambient, diffuse,
//! specular), every other object black but still occluding. So the colours come from a
//! box-constrained linear least-squares solve ([`crate::lsq`]), and `s` alone is searched:
//! a grid on `log s`, then golden-section search between the best grid point's neighbours.
//!
//! A channel the target clipped (0 or its largest value) is a censored observation: 255 says
//! the true value is at least 254.5/255, 0 that it is at most 0.5/255. Such a channel is a
//! one-sided constraint of the solve (a squared penalty only where the model breaks it), not
//! data, and not left out: leaving it out moves the exponent (a clipped highlight's peak is
//! where `s` shows most). The colours are bounded by 0 only: under the scene's lights a
//! material may need colours past 1 (a conductor's highlight, brighter than lights of 1 make
//! it), and the fit says so ([`ImageFit::notes`]). Pixels partly covered by the object
//! (antialiased edges) or covered by something in front are left out: the `E` image tells
//! them (exactly 1 on the object's own pixels).
//!
//! [`best_by_search`] is the check of the method: the same model's best material by brute
//! force (exact least squares for the colours at each of many exponents, every covered pixel
//! as data).

use crate::FitError;
use phong_core::{Color, Encoding, Image, Material, Output, Scene, named_materials};
use phong_raster::{RenderOptions, Renderer};
use std::path::Path;

/// A target image in linear colour, with the channels that were clipped.
pub struct Target {
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
    /// Linear RGB per pixel.
    pub rgb: Vec<[f32; 3]>,
    /// Per pixel and channel: 0 or the largest value (clipped).
    pub clipped: Vec<[bool; 3]>,
    /// In linear colour: the most a channel at 0 can be, and the least a channel at the
    /// largest value can be (half a step from each end, decoded).
    pub censor: (f32, f32),
}

impl Target {
    /// Reads an 8- or 16-bit PNG (grey, grey+alpha, RGB, RGBA, palette), decoding its values
    /// from `encoding` to linear.
    pub fn read(path: &Path, encoding: Encoding) -> Result<Target, FitError> {
        let bytes = phong_scene::read_bounded(
            path,
            phong_core::limits::MAX_IMAGE_FILE_BYTES,
            "image (MAX_IMAGE_FILE_BYTES)",
        )
        .map_err(|e| {
            FitError::Input(format!(
                "{e}: {}",
                std::error::Error::source(&e).map(|s| s.to_string()).unwrap_or_default()
            ))
        })?;
        Target::decode(&bytes, encoding).map_err(|e| FitError::Input(format!("{}: {e}", path.display())))
    }

    /// [`Target::read`] of a PNG file's bytes.
    pub fn decode(bytes: &[u8], encoding: Encoding) -> Result<Target, String> {
        let bad = |why: String| why;
        let mut dec = png::Decoder::new(std::io::Cursor::new(bytes));
        dec.set_transformations(png::Transformations::EXPAND);
        let mut r = dec.read_info().map_err(|e| bad(format!("not a PNG image: {e}")))?;
        let max = phong_core::limits::MAX_IMAGE_DIMENSION;
        let (iw, ih) = (r.info().width, r.info().height);
        if iw > max || ih > max {
            return Err(bad(format!(
                "{iw}x{ih} is larger than any scene image ({max} pixels on a side)"
            )));
        }
        let size = r
            .output_buffer_size()
            .ok_or_else(|| bad("the image is too large".into()))?;
        let mut buf = vec![0; size];
        let info = r.next_frame(&mut buf).map_err(|e| bad(format!("cannot decode: {e}")))?;
        let (w, h) = (info.width, info.height);
        let channels = info.color_type.samples();
        let sixteen = info.bit_depth == png::BitDepth::Sixteen;
        let max = if sixteen { 65535.0 } else { 255.0 };
        let at = |i: usize| -> f32 {
            if sixteen {
                f32::from(u16::from_be_bytes([buf[2 * i], buf[2 * i + 1]]))
            } else {
                f32::from(buf[i])
            }
        };
        let mut rgb = Vec::with_capacity((w * h) as usize);
        let mut clipped = Vec::with_capacity((w * h) as usize);
        for p in 0..(w * h) as usize {
            let base = p * channels;
            let raw: [f32; 3] = if channels < 3 {
                [at(base); 3]
            } else {
                [at(base), at(base + 1), at(base + 2)]
            };
            clipped.push(raw.map(|v| v == 0.0 || v == max));
            rgb.push(raw.map(|v| decode(v / max, encoding)));
        }
        Ok(Target {
            width: w,
            height: h,
            rgb,
            clipped,
            censor: (decode(0.5 / max, encoding), decode(1.0 - 0.5 / max, encoding)),
        })
    }
}

/// An encoded value in `[0, 1]` to linear.
fn decode(v: f32, encoding: Encoding) -> f32 {
    match encoding {
        Encoding::Linear => v,
        Encoding::Srgb if v <= 0.04045 => v / 12.92,
        Encoding::Srgb => ((v + 0.055) / 1.055).powf(2.4),
    }
}

/// Which material parameters the fit may change (the others keep the scene's values).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Free {
    /// `a_m`.
    pub ambient: bool,
    /// `d_m`.
    pub diffuse: bool,
    /// `s_m`.
    pub specular: bool,
    /// `s`.
    pub shininess: bool,
    /// `e_m`.
    pub emission: bool,
}

impl Free {
    /// Parses `ambient,diffuse,...`.
    pub fn parse(list: &str) -> Result<Free, FitError> {
        let mut f = Free {
            ambient: false,
            diffuse: false,
            specular: false,
            shininess: false,
            emission: false,
        };
        for w in list.split(',').map(str::trim).filter(|w| !w.is_empty()) {
            match w {
                "ambient" => f.ambient = true,
                "diffuse" => f.diffuse = true,
                "specular" => f.specular = true,
                "shininess" => f.shininess = true,
                "emission" => f.emission = true,
                other => {
                    return Err(FitError::Input(format!(
                        "--free: unknown parameter \"{other}\"; expected ambient, diffuse, specular, shininess, emission"
                    )));
                }
            }
        }
        if f == Free::parse_none() {
            return Err(FitError::Input(
                "--free names no parameter: nothing to fit (e.g. --free diffuse,specular,shininess)".into(),
            ));
        }
        Ok(f)
    }

    fn parse_none() -> Free {
        Free {
            ambient: false,
            diffuse: false,
            specular: false,
            shininess: false,
            emission: false,
        }
    }

    /// The default: the colours and the exponent, not emission.
    pub fn default_set() -> Free {
        Free {
            ambient: true,
            diffuse: true,
            specular: true,
            shininess: true,
            emission: false,
        }
    }

    /// In the solve's order: emission, ambient, diffuse, specular.
    fn colours(&self) -> [bool; 4] {
        [self.emission, self.ambient, self.diffuse, self.specular]
    }
}

/// The result of an image fit.
pub struct ImageFit {
    /// The fitted material.
    pub material: Material,
    /// RMSE in linear colour over the fitted pixels' channels, of the fitted material's render.
    pub rmse: f64,
    /// `20·log10(1/rmse)`.
    pub psnr: f64,
    /// Pixels fitted (fully covered by the object, in the mask).
    pub pixels: usize,
    /// What the target does not determine, in words.
    pub undetermined: Vec<String>,
    /// What the user should know of the fitted values, in words (colours past 1).
    pub notes: Vec<String>,
    /// `(s, rmse of the linear fit)` for every exponent tried, in order of `s`.
    pub curve: Vec<(f32, f64)>,
    /// The scene rendered with the fitted material.
    pub image: Image,
    /// The nearest classic material and its RMSE (rendered through the same basis).
    pub nearest: (&'static str, f64),
    /// Which pixels were fitted.
    pub used: Vec<bool>,
}

/// Term images of the object for the solve: `E` (coverage), `A`, `D`, and `S(s)` on demand.
struct Basis<'a> {
    scene: Scene,
    object: usize,
    renderer: Renderer,
    options: RenderOptions<'a>,
    e: Image,
    a: Image,
    d: Image,
}

impl<'a> Basis<'a> {
    fn new(scene: &Scene, object: usize, options: RenderOptions<'a>) -> Result<Basis<'a>, FitError> {
        let mut base = scene.clone();
        base.image.background = [0.0, 0.0, 0.0, 1.0];
        base.labels.clear();
        let black = Material::new(Color::BLACK, Color::BLACK, Color::BLACK, Color::BLACK, 0.0).expect("valid");
        for (i, o) in base.objects.iter_mut().enumerate() {
            if i != object {
                o.material = black;
            }
        }
        let mut b = Basis {
            scene: base,
            object,
            renderer: Renderer::new(),
            options,
            e: Image::new(1, 1, [0.0; 4]).expect("1x1"),
            a: Image::new(1, 1, [0.0; 4]).expect("1x1"),
            d: Image::new(1, 1, [0.0; 4]).expect("1x1"),
        };
        let w = Color::WHITE;
        let z = Color::BLACK;
        b.e = b.term(Material::new(z, z, z, w, 0.0).expect("valid"), Output::Ambient)?;
        b.a = b.term(Material::new(w, z, z, z, 0.0).expect("valid"), Output::Ambient)?;
        b.d = b.term(Material::new(z, w, z, z, 0.0).expect("valid"), Output::Diffuse)?;
        Ok(b)
    }

    /// The object's `output` term image with material `m`.
    fn term(&mut self, m: Material, output: Output) -> Result<Image, FitError> {
        let o = &mut self.scene.objects[self.object];
        o.material = m;
        o.shading.output = output;
        let (img, _) = self
            .renderer
            .render(&self.scene, &self.options)
            .map_err(|e| FitError::Render(e.to_string()))?;
        Ok(img.clone())
    }

    /// The pixels the object covers whole (its coverage image is 1: no antialiased edge, nothing
    /// in front), within `mask`.
    fn whole_pixels(&self, mask: Option<&[bool]>) -> Vec<bool> {
        self.e
            .pixels()
            .iter()
            .enumerate()
            .map(|(p, px)| px[0] >= 0.999 && mask.is_none_or(|m| m[p]))
            .collect()
    }

    fn specular(&mut self, s: f32) -> Result<Image, FitError> {
        let (w, z) = (Color::WHITE, Color::BLACK);
        self.term(Material::new(z, z, w, z, s).expect("valid"), Output::Specular)
    }
}

/// A material's colours per channel as the solve orders them: `[e, a, d, k]`.
fn colours_of(m: &Material) -> [[f64; 4]; 3] {
    let c3 = |c: Color| [c.r, c.g, c.b].map(f64::from);
    let (e, a, d, k) = (c3(m.emission()), c3(m.ambient()), c3(m.diffuse()), c3(m.specular()));
    [0, 1, 2].map(|c| [e[c], a[c], d[c], k[c]])
}

/// One channel's observations at one exponent: the uncensored rows' normal equations, and the
/// censored rows apart (free terms' basis values, the bound less the fixed terms, whether the
/// model must reach at least the bound).
#[derive(Default)]
struct Channel {
    n: crate::lsq::Normal<4>,
    censored: Vec<([f64; 4], f64, bool)>,
}

impl Channel {
    /// The least squares over `x ≥ 0` with each censored row a one-sided constraint (a squared
    /// penalty where broken): the rows broken at the last solution join as equalities at their
    /// bound, and the solve is repeated until that set stops changing (a few rounds: the
    /// objective is convex and piecewise quadratic). The solution and its objective.
    fn solve(&self, free: &[bool; 4], fixed: &[f64; 4]) -> ([f64; 4], f64) {
        let broken = |x: &[f64; 4]| -> Vec<bool> {
            self.censored
                .iter()
                .map(|(b, bound, high)| {
                    let v: f64 = (0..4).map(|k| b[k] * x[k]).sum();
                    if *high { v < *bound } else { v > *bound }
                })
                .collect()
        };
        let with = |active: &[bool]| {
            let mut n = self.n;
            for ((b, bound, _), on) in self.censored.iter().zip(active) {
                if *on {
                    n.add(b, *bound);
                }
            }
            n
        };
        let mut active = vec![false; self.censored.len()];
        let mut x = self.n.solve(free, fixed, 0.0, f64::INFINITY).0;
        for _ in 0..50 {
            let now = broken(&x);
            if now == active {
                break;
            }
            active = now;
            x = with(&active).solve(free, fixed, 0.0, f64::INFINITY).0;
        }
        // The objective: every broken constraint's squared distance at the solution.
        let objective = with(&broken(&x)).residual(&x);
        (x, objective)
    }
}

/// The observations at one exponent, per channel, over the used pixels: terms that are not
/// free are moved to the target's side; with `censor`, clipped channels are constraints,
/// else plain data at their value.
fn observations(
    b: &Basis,
    s_img: &Image,
    target: &Target,
    used: &[bool],
    fixed: &[[f64; 4]; 3],
    free: &[bool; 4],
    censor: bool,
) -> [Channel; 3] {
    let mut ch: [Channel; 3] = Default::default();
    let (e, a, d, sp) = (b.e.pixels(), b.a.pixels(), b.d.pixels(), s_img.pixels());
    for (p, &u) in used.iter().enumerate() {
        if !u {
            continue;
        }
        for c in 0..3 {
            let row = [e[p][c], a[p][c], d[p][c], sp[p][c]].map(f64::from);
            let mut t = f64::from(target.rgb[p][c]);
            let high = t >= 0.5;
            if censor && target.clipped[p][c] {
                t = f64::from(if high { target.censor.1 } else { target.censor.0 });
            }
            let mut r = [0.0; 4];
            for k in 0..4 {
                if free[k] {
                    r[k] = row[k];
                } else {
                    t -= row[k] * fixed[c][k];
                }
            }
            if censor && target.clipped[p][c] {
                ch[c].censored.push((r, t, high));
            } else {
                ch[c].n.add(&r, t);
            }
        }
    }
    ch
}

/// Solves the colours at one exponent: per channel `[e, a, d, k]` and the summed objective.
fn solve(ch: &[Channel; 3], free: &[bool; 4], fixed: &[[f64; 4]; 3]) -> ([[f64; 4]; 3], f64) {
    let mut x = [[0.0; 4]; 3];
    let mut r = 0.0;
    for c in 0..3 {
        let (xc, rc) = ch[c].solve(free, &fixed[c]);
        for k in 0..4 {
            x[c][k] = if free[k] { xc[k] } else { fixed[c][k] };
        }
        r += rc;
    }
    (x, r)
}

/// The material of the solved colours; an error where a colour left `f32`'s range (an
/// unclamped model with a basis term near zero can ask for that).
fn material_of(x: &[[f64; 4]; 3], s: f32) -> Result<Material, FitError> {
    let col = |k: usize| Color::new(x[0][k] as f32, x[1][k] as f32, x[2][k] as f32);
    Material::new(col(1), col(2), col(3), col(0), s).map_err(|e| {
        FitError::Input(format!(
            "the fit needs a material the renderer cannot hold ({e}): the target is far brighter than this scene's lights can make it"
        ))
    })
}

/// Finds the object by name (case-insensitive) or index.
pub fn find_object(scene: &Scene, which: Option<&str>) -> Result<usize, FitError> {
    let names = || {
        scene
            .objects
            .iter()
            .enumerate()
            .map(|(i, o)| format!("{i}: {}", o.name))
            .collect::<Vec<_>>()
            .join(", ")
    };
    match which {
        None if scene.objects.len() == 1 => Ok(0),
        None => Err(FitError::Input(format!(
            "the scene has {} objects; choose one with --object NAME|INDEX ({})",
            scene.objects.len(),
            names()
        ))),
        Some(w) => {
            if let Ok(i) = w.parse::<usize>() {
                return if i < scene.objects.len() {
                    Ok(i)
                } else {
                    Err(FitError::Input(format!(
                        "--object {i}: the scene's objects are {}",
                        names()
                    )))
                };
            }
            scene
                .objects
                .iter()
                .position(|o| o.name.eq_ignore_ascii_case(w))
                .ok_or_else(|| {
                    FitError::Input(format!(
                        "--object \"{w}\": no such object; the scene's objects are {}",
                        names()
                    ))
                })
        }
    }
}

/// An error unless `target` (and `mask`, one flag a pixel) has the scene's image size.
fn same_size(scene: &Scene, target: &Target, mask: Option<&[bool]>) -> Result<(), FitError> {
    let (w, h) = (scene.image.width, scene.image.height);
    if (target.width, target.height) != (w, h) {
        return Err(FitError::Input(format!(
            "the target is {}x{} but the scene's image is {w}x{h}",
            target.width, target.height
        )));
    }
    if mask.is_some_and(|m| m.len() != (w * h) as usize) {
        return Err(FitError::Input(format!("the mask is not {w}x{h}, the scene's image")));
    }
    Ok(())
}

/// Fits object `object`'s material in `scene` to `target`; `mask` (one flag a pixel) limits
/// the pixels.
pub fn fit_image(
    scene: &Scene,
    object: usize,
    target: &Target,
    free: Free,
    mask: Option<&[bool]>,
    options: RenderOptions,
) -> Result<ImageFit, FitError> {
    same_size(scene, target, mask)?;
    let start = scene.objects[object].material;
    let mut basis = Basis::new(scene, object, options)?;
    let used = basis.whole_pixels(mask);
    let pixels = used.iter().filter(|&&u| u).count();
    if pixels == 0 {
        return Err(FitError::Input(format!(
            "no pixel shows object {object} ({}) whole{}: nothing to fit",
            scene.objects[object].name,
            if mask.is_some() { " inside the mask" } else { "" }
        )));
    }
    let unclipped = used
        .iter()
        .zip(&target.clipped)
        .filter(|(u, c)| **u && c.iter().any(|x| !x))
        .count();
    if unclipped == 0 {
        return Err(FitError::Input(format!(
            "every one of the object's {pixels} pixels is clipped (0 or 255) in the target: nothing to fit"
        )));
    }
    let fixed = colours_of(&start);
    let mut free_c = free.colours();
    let mut undetermined = Vec::new();
    // Emission and ambient are one unknown where the ambient light is the same everywhere.
    if free_c[0] && free_c[1] {
        let ch = observations(
            &basis,
            &basis.d.clone(),
            target,
            &used,
            &fixed,
            &[true, true, false, false],
            false,
        );
        let g = ch[0].n.g;
        if g[0][0] * g[1][1] - g[0][1] * g[1][0] <= 1e-9 * g[0][0] * g[1][1] {
            free_c[0] = false;
            undetermined.push(
                "emission: the ambient light is uniform here, so only e_m + a_m⊗a is determined; emission kept at the scene's value"
                    .into(),
            );
        }
    }
    let mut curve: Vec<(f32, f64)> = Vec::new();
    let mut eval = |s: f32, basis: &mut Basis| -> Result<([[f64; 4]; 3], f64), FitError> {
        let si = basis.specular(s)?;
        let ch = observations(basis, &si, target, &used, &fixed, &free_c, true);
        let (x, r) = solve(&ch, &free_c, &fixed);
        let count: usize = ch.iter().map(|c| c.n.rows + c.censored.len()).sum::<usize>().max(1);
        curve.push((s, (r / count as f64).sqrt()));
        Ok((x, r))
    };
    let (x, s_best) = if free.shininess && (free_c[3] || start.specular() != Color::BLACK) {
        // Grid on log s over [1, 1000], then golden section between the best's neighbours.
        let grid: Vec<f32> = (0..=24).map(|k| 10f32.powf(3.0 * k as f32 / 24.0)).collect();
        let ((x, _), s) = crate::search_exponent(&grid, 14, |s| eval(s, &mut basis))?;
        (x, s)
    } else {
        let (x, _) = eval(start.shininess(), &mut basis)?;
        (x, start.shininess())
    };
    curve.sort_by(|a, b| a.0.total_cmp(&b.0));
    let material = material_of(&x, s_best)?;
    let material = material.with_alpha(start.alpha()).unwrap_or(material);
    // The highlight: how much the fitted specular term adds anywhere on the fitted pixels.
    let si = basis.specular(s_best)?;
    let peak = used
        .iter()
        .zip(si.pixels())
        .filter(|(u, _)| **u)
        .map(|(_, p)| (0..3).map(|c| f64::from(p[c]) * x[c][3]).fold(0.0, f64::max))
        .fold(0.0, f64::max);
    if free.specular && peak < 2.0 / 255.0 {
        undetermined.push(format!(
            "specular and shininess: no highlight is visible on the fitted pixels (the fitted specular term adds at most {:.4}); their values are not determined",
            peak
        ));
    }
    // The fitted material rendered as the scene shows it.
    let mut fitted_scene = scene.clone();
    fitted_scene.objects[object].material = material;
    let image = phong_raster::render(&fitted_scene, &basis.options).map_err(|e| FitError::Render(e.to_string()))?;
    let rmse = rmse_of(&image, target, &used, scene.image.encoding);
    // The nearest classic material, through the same basis.
    let mut nearest = ("", f64::INFINITY);
    for m in named_materials() {
        let mm = m.material;
        let xs = colours_of(&mm);
        let si = basis.specular(mm.shininess())?;
        let ch = observations(&basis, &si, target, &used, &[[0.0; 4]; 3], &[true; 4], false);
        let (r, count) = (0..3).fold((0.0, 0), |(r, k), c| (r + ch[c].n.residual(&xs[c]), k + ch[c].n.rows));
        let e = (r / count.max(1) as f64).sqrt();
        if e < nearest.1 {
            nearest = (m.name, e);
        }
    }
    Ok(ImageFit {
        material,
        rmse,
        psnr: 20.0 * (1.0 / rmse.max(1e-12)).log10(),
        pixels,
        undetermined,
        notes: past_one(&x, &free_c),
        curve,
        image,
        nearest,
        used,
    })
}

/// The fitted colours past 1, in words: the largest term's value and the light scale that
/// would bring it into [0, 1].
fn past_one(x: &[[f64; 4]; 3], free: &[bool; 4]) -> Vec<String> {
    let names = ["emission", "ambient", "diffuse", "specular"];
    (0..4)
        .filter(|&k| free[k])
        .filter_map(|k| {
            let top = (0..3).map(|c| x[c][k]).fold(0.0, f64::max);
            (top > 1.0).then(|| {
                format!(
                    "{} {top:.2}: brighter than these lights allow in [0, 1]; scale the lights by {top:.2} to keep it in range",
                    names[k]
                )
            })
        })
        .collect()
}

/// RMSE of `image` (as the PNG would store it, decoded to linear) against the target over the
/// used pixels' channels, clipped ones included (the image is clipped alike).
fn rmse_of(image: &Image, target: &Target, used: &[bool], encoding: Encoding) -> f64 {
    let (mut sum, mut n) = (0.0, 0usize);
    for (p, px) in image.pixels().iter().enumerate() {
        if !used[p] {
            continue;
        }
        for c in 0..3 {
            let v = decode(f32::from(encoding.encode(px[c])) / 255.0, encoding);
            let d = f64::from(v - target.rgb[p][c]);
            sum += d * d;
            n += 1;
        }
    }
    (sum / n.max(1) as f64).sqrt()
}

/// The best material of the scene's model by brute force, the yardstick of [`fit_image`]: at
/// each of 400 exponents from 1 to 2000 (evenly in `log s`), the exact least-squares colours
/// (at least 0, no upper bound; the free terms of `free`, the others the scene's) over every
/// pixel the object covers whole, clipped channels as data; the best of those by the PSNR of
/// the image they make (the term images summed, clamped where the scene clamps, stored in 8
/// bits as the PNG would be).
pub struct Search {
    /// The best exponent on the grid.
    pub shininess: f32,
    /// Its image's PSNR against the target, in dB.
    pub psnr: f64,
}

/// See [`Search`].
pub fn best_by_search(
    scene: &Scene,
    object: usize,
    target: &Target,
    free: Free,
    mask: Option<&[bool]>,
    options: RenderOptions,
) -> Result<Search, FitError> {
    same_size(scene, target, mask)?;
    let start = scene.objects[object].material;
    let mut basis = Basis::new(scene, object, options)?;
    let used = basis.whole_pixels(mask);
    let fixed = colours_of(&start);
    let free_c = free.colours();
    let clamp = scene.objects[object].shading.options.clamp;
    let encoding = scene.image.encoding;
    let mut best = Search {
        shininess: start.shininess(),
        psnr: f64::NEG_INFINITY,
    };
    for k in 0..400 {
        let s = 2000f32.powf(k as f32 / 399.0);
        let si = basis.specular(s)?;
        let ch = observations(&basis, &si, target, &used, &fixed, &free_c, false);
        let x: [[f64; 4]; 3] = [0, 1, 2].map(|c| {
            let xc = ch[c].n.solve(&free_c, &fixed[c], 0.0, f64::INFINITY).0;
            [0, 1, 2, 3].map(|t| if free_c[t] { xc[t] } else { fixed[c][t] })
        });
        let (e, a, d, sp) = (basis.e.pixels(), basis.a.pixels(), basis.d.pixels(), si.pixels());
        let (mut sum, mut n) = (0.0, 0usize);
        for (p, _) in used.iter().enumerate().filter(|(_, u)| **u) {
            for c in 0..3 {
                let row = [e[p][c], a[p][c], d[p][c], sp[p][c]].map(f64::from);
                let v = (0..4).map(|t| row[t] * x[c][t]).sum::<f64>();
                let v = if clamp { v.clamp(0.0, 1.0) } else { v } as f32;
                let stored = decode(f32::from(encoding.encode(v)) / 255.0, encoding);
                sum += f64::from(stored - target.rgb[p][c]).powi(2);
                n += 1;
            }
        }
        let psnr = 20.0 * (1.0 / (sum / n.max(1) as f64).sqrt().max(1e-12)).log10();
        if psnr > best.psnr {
            best = Search { shininess: s, psnr };
        }
    }
    Ok(best)
}
