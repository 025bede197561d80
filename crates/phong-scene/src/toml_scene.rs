//! The TOML scene format (see README.md for every key).
//!
//! serde with `deny_unknown_fields` rejects unknown keys and wrong types
//! with the span toml gives; values that need checking are read as
//! `Spanned` so that a bad one is reported at its own line and column.

use crate::overrides::Overrides;
use crate::{Error, Loaded, ObjPart, load_obj_sources};
use glam::{EulerRot, Mat4, Quat, Vec3};
use phong_core::limits::{MAX_IMAGE_DIMENSION, MAX_LIGHTS, MAX_SEGMENTS};
use phong_core::{
    Attenuation, Camera, Color, Encoding, ImageSettings, Interpolation, Label, Light, LightColor, Lighting, LyonLambda,
    Material, Mesh, Normalization, Object, Output, Projection, Samples, Scene, ShadingOptions, ShadingSettings,
    SpecularModel, Viewer, nearest_names, normalize_name, primitives,
};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::Path;
use toml::Spanned;

type S<T> = Spanned<T>;

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawScene {
    image: Option<RawImage>,
    camera: Option<RawCamera>,
    shading: Option<RawShading>,
    #[serde(default)]
    light: Vec<S<RawLight>>,
    #[serde(default)]
    materials: BTreeMap<String, S<RawMaterial>>,
    #[serde(default)]
    object: Vec<S<RawObject>>,
    #[serde(default)]
    label: Vec<S<RawLabel>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawLabel {
    text: S<String>,
    position: S<Vec<f32>>,
    color: Option<S<Vec<f32>>>,
    size: Option<S<i64>>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawImage {
    width: Option<S<i64>>,
    height: Option<S<i64>>,
    background: Option<S<Vec<f32>>>,
    antialias: Option<S<i64>>,
    encoding: Option<S<String>>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawCamera {
    projection: Option<S<String>>,
    position: Option<S<Vec<f32>>>,
    target: Option<S<Vec<f32>>>,
    up: Option<S<Vec<f32>>>,
    fov: Option<S<f32>>,
    height: Option<S<f32>>,
    near: Option<S<f32>>,
    far: Option<S<f32>>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawShading {
    model: Option<S<String>>,
    interpolation: Option<S<String>>,
    viewer: Option<S<String>>,
    ambient: Option<S<Vec<f32>>>,
    normalization: Option<S<String>>,
    two_sided: Option<bool>,
    output: Option<S<String>>,
    gate_specular: Option<bool>,
    clamp: Option<bool>,
    lyon_squarings: Option<S<i64>>,
    lyon_lambda: Option<S<String>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawLight {
    #[serde(rename = "type")]
    kind: S<String>,
    direction: Option<S<Vec<f32>>>,
    position: Option<S<Vec<f32>>>,
    color: Option<S<Vec<f32>>>,
    ambient: Option<S<Vec<f32>>>,
    diffuse: Option<S<Vec<f32>>>,
    specular: Option<S<Vec<f32>>>,
    attenuation: Option<S<Vec<f32>>>,
    cutoff: Option<S<f32>>,
    exponent: Option<S<f32>>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawMaterial {
    base: Option<S<String>>,
    paint: Option<S<Vec<f32>>>,
    ambient: Option<S<Vec<f32>>>,
    diffuse: Option<S<Vec<f32>>>,
    specular: Option<S<Vec<f32>>>,
    emission: Option<S<Vec<f32>>>,
    shininess: Option<S<f32>>,
    alpha: Option<S<f32>>,
}

/// An inline material table: the same keys, without per-key spans (serde's
/// untagged enums cannot carry them); its own span, on one line, is used.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PlainMaterial {
    base: Option<String>,
    paint: Option<Vec<f32>>,
    ambient: Option<Vec<f32>>,
    diffuse: Option<Vec<f32>>,
    specular: Option<Vec<f32>>,
    emission: Option<Vec<f32>>,
    shininess: Option<f32>,
    alpha: Option<f32>,
}

#[derive(Deserialize)]
#[serde(untagged)]
enum MaterialRef {
    Name(String),
    Inline(PlainMaterial),
}

#[derive(Deserialize)]
#[serde(untagged)]
enum Scale {
    Uniform(f32),
    Axes(Vec<f32>),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawObject {
    shape: Option<S<String>>,
    mesh: Option<S<String>>,
    segments: Option<S<i64>>,
    radius: Option<S<f32>>,
    tube: Option<S<f32>>,
    material: Option<S<MaterialRef>>,
    position: Option<S<Vec<f32>>>,
    rotation: Option<S<Vec<f32>>>,
    scale: Option<S<Scale>>,
    normals: Option<S<String>>,
    crease: Option<S<f32>>,
    model: Option<S<String>>,
    interpolation: Option<S<String>>,
    output: Option<S<String>>,
}

/// The shading models of the `model` key and `--model`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Model {
    /// No specular term.
    Lambert,
    /// Phong's `(R·V)^s`.
    Phong,
    /// Blinn-Phong's `(N·H)^s`.
    BlinnPhong,
    /// Lyon's approximation of Phong.
    PhongLyon,
    /// OpenGL 2.1 fixed function.
    OpenGl,
}

/// `model` values.
pub const MODELS: &[(&str, Model)] = &[
    ("lambert", Model::Lambert),
    ("phong", Model::Phong),
    ("blinn-phong", Model::BlinnPhong),
    ("phong-lyon", Model::PhongLyon),
    ("opengl", Model::OpenGl),
];
/// `interpolation` values.
pub const INTERPOLATIONS: &[(&str, Interpolation)] = &[
    ("flat", Interpolation::Flat),
    ("gouraud", Interpolation::Gouraud),
    ("phong", Interpolation::Phong),
];
/// `output` values.
pub const OUTPUTS: &[(&str, Output)] = &[
    ("color", Output::Color),
    ("ambient", Output::Ambient),
    ("diffuse", Output::Diffuse),
    ("specular", Output::Specular),
    ("normal", Output::Normal),
    ("depth", Output::Depth),
];
const NORMALIZATIONS: &[(&str, Normalization)] = &[
    ("none", Normalization::None),
    ("phong", Normalization::Phong),
    ("blinn-phong", Normalization::BlinnPhong),
    ("blinn-phong-exact", Normalization::BlinnPhongExact),
];
const VIEWERS: &[(&str, Viewer)] = &[("local", Viewer::Local), ("infinite", Viewer::Infinite)];
const ENCODINGS: &[(&str, Encoding)] = &[("linear", Encoding::Linear), ("srgb", Encoding::Srgb)];
const PROJECTIONS: &[&str] = &["perspective", "orthographic"];
const LIGHT_TYPES: &[&str] = &["directional", "point", "spot"];
const SHAPES: &[&str] = &["sphere", "torus", "cylinder", "cone", "cube", "plane", "teapot"];
const LYON_LAMBDAS: &[(&str, LyonLambda)] = &[("dot", LyonLambda::Dot), ("difference", LyonLambda::Difference)];

/// Looks `value` up in `table`; the error lists the choices and the nearest ones.
pub fn parse_choice<T: Copy>(key: &str, value: &str, table: &[(&str, T)]) -> Result<T, String> {
    if let Some((_, v)) = table.iter().find(|(n, _)| *n == value) {
        return Ok(*v);
    }
    let names: Vec<&str> = table.iter().map(|(n, _)| *n).collect();
    let near = nearest_names(value, names.iter().copied());
    let hint = if near.is_empty() {
        String::new()
    } else {
        format!(
            " (did you mean {}?)",
            near.iter().map(|n| format!("\"{n}\"")).collect::<Vec<_>>().join(" or ")
        )
    };
    Err(format!(
        "unknown {key} \"{value}\"{hint}; expected one of {}",
        names.iter().map(|n| format!("\"{n}\"")).collect::<Vec<_>>().join(", ")
    ))
}

/// Sets `options` for `model` (`opengl`: the OpenGL preset, keeping `two_sided`).
pub fn apply_model(options: &mut ShadingOptions, model: Model, lyon: (u32, LyonLambda)) {
    options.specular = match model {
        Model::Lambert => SpecularModel::None,
        Model::Phong => SpecularModel::Phong,
        Model::BlinnPhong | Model::OpenGl => SpecularModel::BlinnPhong,
        Model::PhongLyon => SpecularModel::Lyon {
            squarings: lyon.0,
            lambda: lyon.1,
        },
    };
    if model == Model::OpenGl {
        *options = ShadingOptions::opengl(options.two_sided);
    }
}

struct Ctx<'a> {
    path: &'a Path,
    src: &'a str,
    warnings: Vec<String>,
    /// Files read for the scene's meshes (OBJ and MTL).
    sources: Vec<std::path::PathBuf>,
    /// Triangles of the objects read so far (the per-scene budget).
    triangles: std::cell::Cell<u64>,
    /// Where `mesh = "..."` names come from: `None` reads files beside the scene; `Some`
    /// looks them up in memory (the server's uploads) and never opens a file.
    meshes: Option<&'a MeshLookup<'a>>,
}

/// Resolves a `mesh` name to its parts without touching the file system (the error is the
/// message shown for the `mesh` key).
pub type MeshLookup<'a> = dyn Fn(&str) -> Result<Vec<ObjPart>, String> + 'a;

impl Ctx<'_> {
    /// Counts an object's triangles against the scene's budget.
    fn add_triangles(&self, n: u64, span: &std::ops::Range<usize>, key: &str) -> Result<(), Error> {
        self.triangles.set(self.triangles.get().saturating_add(n));
        let max = phong_core::limits::MAX_SCENE_TRIANGLES;
        if self.triangles.get() > max {
            return self.err(
                span,
                key,
                format!(
                    "the scene's objects have {} triangles so far; a scene may have at most {max} (MAX_SCENE_TRIANGLES)",
                    self.triangles.get()
                ),
            );
        }
        Ok(())
    }

    fn err<T>(&self, span: &std::ops::Range<usize>, key: &str, msg: impl Into<String>) -> Result<T, Error> {
        Err(Error::at(self.path, self.src, span.start, Some(key), msg.into()))
    }

    fn choice<T: Copy>(&self, s: &S<String>, key: &str, table: &[(&str, T)]) -> Result<T, Error> {
        parse_choice(key, s.get_ref(), table).or_else(|m| self.err(&s.span(), key, m))
    }

    fn name<'b>(&self, s: &S<String>, key: &str, names: &[&'b str]) -> Result<&'b str, Error> {
        let table: Vec<(&str, &str)> = names.iter().map(|n| (*n, *n)).collect();
        self.choice(s, key, &table)
    }

    fn vec3(&self, s: &S<Vec<f32>>, key: &str) -> Result<Vec3, Error> {
        let v = s.get_ref();
        if v.len() != 3 {
            return self.err(&s.span(), key, format!("expected 3 numbers [x, y, z], got {}", v.len()));
        }
        if v.iter().any(|x| !x.is_finite()) {
            return self.err(&s.span(), key, "numbers must be finite");
        }
        Ok(Vec3::new(v[0], v[1], v[2]))
    }

    fn color(&self, s: &S<Vec<f32>>, key: &str) -> Result<Color, Error> {
        let v = s.get_ref();
        if v.len() != 3 {
            return self.err(&s.span(), key, format!("expected 3 numbers [r, g, b], got {}", v.len()));
        }
        if v.iter().any(|x| !x.is_finite() || *x < 0.0) {
            return self.err(&s.span(), key, "colour components must be finite and >= 0");
        }
        Ok(Color::new(v[0], v[1], v[2]))
    }

    fn opt_color(&self, s: &Option<S<Vec<f32>>>, key: &str) -> Result<Option<Color>, Error> {
        s.as_ref().map(|s| self.color(s, key)).transpose()
    }

    fn num(&self, s: &S<f32>, key: &str, ok: impl Fn(f32) -> bool, range: &str) -> Result<f32, Error> {
        let v = *s.get_ref();
        if v.is_finite() && ok(v) {
            Ok(v)
        } else {
            self.err(&s.span(), key, format!("must be {range}, got {v}"))
        }
    }

    fn int(&self, s: &S<i64>, key: &str, lo: i64, hi: i64) -> Result<i64, Error> {
        let v = *s.get_ref();
        if (lo..=hi).contains(&v) {
            Ok(v)
        } else {
            self.err(&s.span(), key, format!("must be from {lo} to {hi}, got {v}"))
        }
    }
}

/// Parses a scene file's text; `path` names it in errors and anchors relative mesh paths.
pub fn parse_scene(src: &str, path: &Path) -> Result<Loaded, Error> {
    parse_scene_with(src, path, None)
}

/// [`parse_scene`] with meshes from `meshes` instead of the file system (when given).
pub fn parse_scene_with(src: &str, path: &Path, meshes: Option<&MeshLookup>) -> Result<Loaded, Error> {
    let raw: RawScene = toml::from_str(src).map_err(|e| {
        let offset = e.span().map_or(0, |s| s.start);
        // The whole line the error is on (an error at a key's start, as "duplicate key", has
        // nothing before it on the line).
        let offset_c = offset.min(src.len());
        let start = src[..offset_c].rfind('\n').map_or(0, |i| i + 1);
        let end = src[offset_c..].find('\n').map_or(src.len(), |i| offset_c + i);
        let line_text = src.get(start..end).unwrap_or("");
        let key = line_text
            .split_once('=')
            .map(|(k, _)| k.trim().to_string())
            .filter(|k| !k.is_empty())
            .map(|k| unquote_key(&k));
        let message = e
            .message()
            .trim()
            .replace("expected i64", "expected an integer")
            .replace("expected f32", "expected a number")
            .replace("expected a sequence", "expected an array");
        Error::at(path, src, offset, key.as_deref(), message)
    })?;
    let mut ctx = Ctx {
        path,
        src,
        warnings: Vec::new(),
        sources: Vec::new(),
        triangles: std::cell::Cell::new(0),
        meshes,
    };
    let scene = build(&mut ctx, raw)?;
    Ok(Loaded {
        scene,
        warnings: ctx.warnings,
        sources: ctx.sources,
    })
}

/// A quoted key (`"my key"`) as the key itself; a bare key as it is.
fn unquote_key(k: &str) -> String {
    if (k.starts_with('"') || k.starts_with('\''))
        && let Ok(t) = toml::from_str::<toml::Table>(&format!("{k} = 0"))
        && let Some(name) = t.keys().next()
    {
        return name.clone();
    }
    k.to_string()
}

fn build(ctx: &mut Ctx, raw: RawScene) -> Result<Scene, Error> {
    let image = image_settings(ctx, raw.image.unwrap_or_default())?;
    let camera = camera(ctx, raw.camera.unwrap_or_default())?;
    let shading = shading(ctx, raw.shading.as_ref(), &camera)?;
    let ambient = match raw.shading.as_ref().and_then(|s| s.ambient.as_ref()) {
        Some(a) => ctx.color(a, "ambient")?,
        None => Color::splat(0.2),
    };
    if raw.light.len() > MAX_LIGHTS {
        return ctx.err(
            &raw.light[MAX_LIGHTS].span(),
            "light",
            format!("at most {MAX_LIGHTS} lights"),
        );
    }
    let mut lights = Vec::new();
    for l in &raw.light {
        lights.push(light(ctx, l)?);
    }
    if raw.light.is_empty() {
        // OpenGL's light 0 in eye space, (0, 0, 1, 0): white, from the camera.
        lights.push(Light::directional(camera.forward(), LightColor::default()).expect("unit direction"));
    }
    let lighting = Lighting::new(ambient, lights).expect("checked colour");
    let mut named = BTreeMap::new();
    for (name, m) in &raw.materials {
        let key = format!("materials.{name}");
        let mat = material(ctx, m.get_ref(), &key, &named)?;
        named.insert(normalize_name(name), mat);
    }
    let mut objects = Vec::new();
    for o in &raw.object {
        let r = o.get_ref();
        let overrides = Overrides {
            model: r.model.as_ref().map(|m| ctx.choice(m, "model", MODELS)).transpose()?,
            interpolation: (r.interpolation.as_ref())
                .map(|i| ctx.choice(i, "interpolation", INTERPOLATIONS))
                .transpose()?,
            output: r
                .output
                .as_ref()
                .map(|o| ctx.choice(o, "output", OUTPUTS))
                .transpose()?,
        };
        let mut sh = shading;
        overrides.apply(&mut sh);
        objects.extend(object(ctx, o, &named, sh)?);
    }
    let mut labels = Vec::new();
    for l in &raw.label {
        let l = l.get_ref();
        let size = match &l.size {
            Some(sz) => ctx.int(sz, "size", 1, 64)? as u32,
            None => 2,
        };
        labels.push(Label {
            text: l.text.get_ref().clone(),
            position: ctx.vec3(&l.position, "position")?,
            color: ctx.opt_color(&l.color, "color")?.unwrap_or(Color::WHITE),
            size,
        });
    }
    Ok(Scene {
        image,
        camera,
        lighting,
        shading,
        objects,
        labels,
    })
}

fn image_settings(ctx: &Ctx, r: RawImage) -> Result<ImageSettings, Error> {
    let mut s = ImageSettings::default();
    let max = i64::from(MAX_IMAGE_DIMENSION);
    if let Some(w) = &r.width {
        s.width = ctx.int(w, "width", 1, max)? as u32;
    }
    if let Some(h) = &r.height {
        s.height = ctx.int(h, "height", 1, max)? as u32;
    }
    if let Some(b) = &r.background {
        let v = b.get_ref();
        if !(v.len() == 3 || v.len() == 4) || v.iter().any(|x| !x.is_finite() || !(0.0..=1.0).contains(x)) {
            return ctx.err(
                &b.span(),
                "background",
                "expected [r, g, b] or [r, g, b, a] with values in [0, 1]",
            );
        }
        s.background = [v[0], v[1], v[2], v.get(3).copied().unwrap_or(1.0)];
    }
    if let Some(a) = &r.antialias {
        let v = *a.get_ref();
        let samples = u32::try_from(v).ok().and_then(|n| Samples::from_count(n).ok());
        let Some(samples) = samples else {
            return ctx.err(
                &a.span(),
                "antialias",
                format!("must be 1, 4 or 16 samples per pixel, got {v}"),
            );
        };
        s.samples = samples;
    }
    if let Some(e) = &r.encoding {
        s.encoding = ctx.choice(e, "encoding", ENCODINGS)?;
    }
    Ok(s)
}

fn camera(ctx: &Ctx, r: RawCamera) -> Result<Camera, Error> {
    let ortho = match &r.projection {
        Some(p) => ctx.name(p, "projection", PROJECTIONS)? == "orthographic",
        None => false,
    };
    let v = |s: &Option<S<Vec<f32>>>, key, d: Vec3| s.as_ref().map_or(Ok(d), |s| ctx.vec3(s, key));
    let eye = v(&r.position, "position", Vec3::new(0.0, 0.0, 5.0))?;
    let target = v(&r.target, "target", Vec3::ZERO)?;
    let up = v(&r.up, "up", Vec3::Y)?;
    let projection = if ortho {
        let h = match &r.height {
            Some(h) => ctx.num(h, "height", |x| x > 0.0, "> 0")?,
            None => 3.0,
        };
        Projection::Orthographic { height: h }
    } else {
        let f = match &r.fov {
            Some(f) => ctx.num(f, "fov", |x| x > 0.0 && x < 180.0, "in (0, 180) degrees")?,
            None => 45.0,
        };
        Projection::Perspective { fov_y_deg: f }
    };
    let near = match &r.near {
        Some(n) if ortho => ctx.num(n, "near", |_| true, "finite")?,
        Some(n) => ctx.num(n, "near", |x| x > 0.0, "> 0 for a perspective camera")?,
        None => 0.1,
    };
    let far = match &r.far {
        Some(f) => ctx.num(f, "far", |x| x > near, &format!("> near ({near})"))?,
        None => 100.0_f32.max(near * 2.0),
    };
    Camera::new(eye, target, up, projection, near, far).or_else(|e| {
        let span =
            r.up.as_ref()
                .or(r.target.as_ref())
                .or(r.position.as_ref())
                .map_or(0..0, |s| s.span());
        ctx.err(&span, "camera", e.to_string())
    })
}

fn shading(ctx: &Ctx, r: Option<&RawShading>, camera: &Camera) -> Result<ShadingSettings, Error> {
    let mut options = ShadingOptions::default();
    let mut s = ShadingSettings {
        options,
        interpolation: Interpolation::Phong,
        viewer: camera.default_viewer(),
        output: Output::Color,
    };
    let Some(r) = r else { return Ok(s) };
    options.two_sided = r.two_sided.unwrap_or(false);
    options.gate_specular = r.gate_specular.unwrap_or(true);
    options.clamp = r.clamp.unwrap_or(true);
    if let Some(n) = &r.normalization {
        options.normalization = ctx.choice(n, "normalization", NORMALIZATIONS)?;
    }
    let squarings = match &r.lyon_squarings {
        Some(n) => ctx.int(n, "lyon_squarings", 0, 16)? as u32,
        None => 3,
    };
    let lambda = match &r.lyon_lambda {
        Some(l) => ctx.choice(l, "lyon_lambda", LYON_LAMBDAS)?,
        None => LyonLambda::Dot,
    };
    let model = match &r.model {
        Some(m) => ctx.choice(m, "model", MODELS)?,
        None => Model::BlinnPhong,
    };
    if model == Model::OpenGl {
        for (set, key) in [(
            r.normalization
                .as_ref()
                .map(|n| n.span())
                .filter(|_| options.normalization != Normalization::None),
            "normalization",
        )] {
            if let Some(span) = set {
                return ctx.err(&span, key, "the \"opengl\" model has no normalization");
            }
        }
        if r.clamp == Some(false) || r.gate_specular == Some(false) {
            let span = r.model.as_ref().map_or(0..0, |m| m.span());
            return ctx.err(
                &span,
                "model",
                "the \"opengl\" model always clamps and gates the specular term",
            );
        }
    }
    apply_model(&mut options, model, (squarings, lambda));
    s.options = options;
    if let Some(i) = &r.interpolation {
        s.interpolation = ctx.choice(i, "interpolation", INTERPOLATIONS)?;
    }
    if let Some(v) = &r.viewer {
        s.viewer = ctx.choice(v, "viewer", VIEWERS)?;
    }
    if let Some(o) = &r.output {
        s.output = ctx.choice(o, "output", OUTPUTS)?;
    }
    Ok(s)
}

fn light(ctx: &Ctx, l: &S<RawLight>) -> Result<Light, Error> {
    let span = l.span();
    let l = l.get_ref();
    let kind = ctx.name(&l.kind, "type", LIGHT_TYPES)?;
    let base = ctx.opt_color(&l.color, "color")?.unwrap_or(Color::WHITE);
    let colors = LightColor::new(
        ctx.opt_color(&l.ambient, "ambient")?.unwrap_or(Color::BLACK),
        ctx.opt_color(&l.diffuse, "diffuse")?.unwrap_or(base),
        ctx.opt_color(&l.specular, "specular")?.unwrap_or(base),
    )
    .expect("checked colours");
    let attenuation = match &l.attenuation {
        Some(a) => {
            let v = a.get_ref();
            if v.len() != 3 {
                return ctx.err(
                    &a.span(),
                    "attenuation",
                    "expected 3 numbers [constant, linear, quadratic]",
                );
            }
            Attenuation::new(v[0], v[1], v[2]).or_else(|e| ctx.err(&a.span(), "attenuation", e.to_string()))?
        }
        None => Attenuation::NONE,
    };
    let need = |s: &Option<S<Vec<f32>>>, key: &str| match s {
        Some(s) => ctx.vec3(s, key),
        None => ctx.err(&span, key, format!("a {kind} light needs `{key}`")),
    };
    let reject = |present: bool, key: &str| {
        if present {
            ctx.err(&span, key, format!("a {kind} light has no `{key}`"))
        } else {
            Ok(())
        }
    };
    let dir_err = |s: &Option<S<Vec<f32>>>, e: phong_core::Error| {
        ctx.err(
            &s.as_ref().map_or(span.clone(), |s| s.span()),
            "direction",
            e.to_string(),
        )
    };
    match kind {
        "directional" => {
            reject(l.position.is_some(), "position")?;
            reject(l.attenuation.is_some(), "attenuation")?;
            reject(l.cutoff.is_some(), "cutoff")?;
            reject(l.exponent.is_some(), "exponent")?;
            Light::directional(need(&l.direction, "direction")?, colors).or_else(|e| dir_err(&l.direction, e))
        }
        "point" => {
            reject(l.direction.is_some(), "direction")?;
            reject(l.cutoff.is_some(), "cutoff")?;
            reject(l.exponent.is_some(), "exponent")?;
            Ok(Light::point(need(&l.position, "position")?, colors, attenuation).expect("checked position"))
        }
        _ => {
            let cutoff = match &l.cutoff {
                Some(c) => ctx.num(c, "cutoff", |x| (0.0..=90.0).contains(&x), "in [0, 90] degrees")?,
                None => return ctx.err(&span, "cutoff", "a spot light needs `cutoff` (degrees, 0 to 90)"),
            };
            let exponent = match &l.exponent {
                Some(e) => ctx.num(e, "exponent", |x| x >= 0.0, ">= 0")?,
                None => 0.0,
            };
            let direction = need(&l.direction, "direction")?;
            Light::spot(
                need(&l.position, "position")?,
                direction,
                cutoff,
                exponent,
                colors,
                attenuation,
            )
            .or_else(|e| dir_err(&l.direction, e))
        }
    }
}

fn material(ctx: &Ctx, m: &RawMaterial, key: &str, named: &BTreeMap<String, Material>) -> Result<Material, Error> {
    let start = match &m.base {
        Some(b) => lookup_material(ctx, b, named)?,
        None => match &m.paint {
            Some(_) => Material::paint(Color::BLACK, 0.0).expect("valid"),
            None => Material::default(),
        },
    };
    let paint = ctx.opt_color(&m.paint, "paint")?;
    let ambient = ctx
        .opt_color(&m.ambient, "ambient")?
        .or(paint)
        .unwrap_or(start.ambient());
    let diffuse = ctx
        .opt_color(&m.diffuse, "diffuse")?
        .or(paint)
        .unwrap_or(start.diffuse());
    let specular = ctx.opt_color(&m.specular, "specular")?.unwrap_or(start.specular());
    let emission = ctx.opt_color(&m.emission, "emission")?.unwrap_or(start.emission());
    let shininess = match &m.shininess {
        Some(s) => ctx.num(s, "shininess", |x| x >= 0.0, ">= 0")?,
        None => start.shininess(),
    };
    let alpha = match &m.alpha {
        Some(a) => ctx.num(a, "alpha", |x| (0.0..=1.0).contains(&x), "in [0, 1]")?,
        None => start.alpha(),
    };
    let _ = key;
    Ok(Material::new(ambient, diffuse, specular, emission, shininess)
        .and_then(|m| m.with_alpha(alpha))
        .expect("checked values"))
}

fn lookup_material(ctx: &Ctx, name: &S<String>, named: &BTreeMap<String, Material>) -> Result<Material, Error> {
    if let Some(m) = named.get(&normalize_name(name.get_ref())) {
        return Ok(*m);
    }
    Material::named(name.get_ref()).or_else(|_| {
        let all: Vec<&str> = named
            .keys()
            .map(String::as_str)
            .chain(phong_core::named_materials().iter().map(|m| m.name))
            .collect();
        let near = nearest_names(name.get_ref(), all.iter().copied());
        let hint = if near.is_empty() {
            "; `phong materials` lists the built-in ones".to_string()
        } else {
            format!("; did you mean {}?", near.join(" or "))
        };
        ctx.err(
            &name.span(),
            "material",
            format!("unknown material \"{}\"{hint}", name.get_ref()),
        )
    })
}

fn object(
    ctx: &mut Ctx,
    o: &S<RawObject>,
    named: &BTreeMap<String, Material>,
    shading: ShadingSettings,
) -> Result<Vec<Object>, Error> {
    let span = o.span();
    let o = o.get_ref();
    let material = match &o.material {
        None => None,
        Some(m) => Some(match m.get_ref() {
            MaterialRef::Name(n) => lookup_material(ctx, &Spanned::new(m.span(), n.clone()), named)?,
            MaterialRef::Inline(p) => {
                let sp = |v: &Option<Vec<f32>>| v.clone().map(|v| Spanned::new(m.span(), v));
                let spf = |v: Option<f32>| v.map(|v| Spanned::new(m.span(), v));
                let raw = RawMaterial {
                    base: p.base.clone().map(|b| Spanned::new(m.span(), b)),
                    paint: sp(&p.paint),
                    ambient: sp(&p.ambient),
                    diffuse: sp(&p.diffuse),
                    specular: sp(&p.specular),
                    emission: sp(&p.emission),
                    shininess: spf(p.shininess),
                    alpha: spf(p.alpha),
                };
                material(ctx, &raw, "material", named)?
            }
        }),
    };
    let world_from_object = transform(ctx, o)?;
    let normals_choice = o.normals.as_ref();
    let crease = match &o.crease {
        Some(c) => ctx.num(c, "crease", |x| (0.0..=180.0).contains(&x), "in [0, 180] degrees")?,
        None => 60.0,
    };
    let apply_normals = |mesh: Mesh, default: &str, allowed: &[&str]| -> Result<Mesh, Error> {
        let choice = match normals_choice {
            Some(n) => ctx.name(n, "normals", allowed)?,
            None => default,
        };
        Ok(match choice {
            "flat" => mesh.with_flat_normals(),
            "smooth" => mesh.with_smooth_normals(),
            "angle" => mesh.with_crease_normals(crease),
            _ => mesh,
        })
    };
    match (&o.shape, &o.mesh) {
        (Some(_), Some(m)) | (None, Some(m)) if o.shape.is_some() => {
            ctx.err(&m.span(), "mesh", "an object has either `shape` or `mesh`, not both")
        }
        (Some(shape), None) => {
            let kind = ctx.name(shape, "shape", SHAPES)?;
            let default_segments = match kind {
                "plane" => 1,
                "teapot" => 10,
                _ => 64,
            };
            let min = if matches!(kind, "plane" | "teapot") { 1 } else { 3 };
            let segments = match &o.segments {
                Some(s) => ctx.int(s, "segments", min, i64::from(MAX_SEGMENTS))? as u32,
                None => default_segments,
            };
            let n = u64::from(segments);
            let triangles = match kind {
                "teapot" => 64 * n * n,
                "plane" => 2 * n * n,
                "cube" => 12,
                _ => n * n + 4 * n,
            };
            if triangles > phong_core::limits::MAX_PRIMITIVE_TRIANGLES {
                let span = o.segments.as_ref().map_or(span.clone(), |s| s.span());
                return ctx.err(
                    &span,
                    "segments",
                    format!(
                        "a {kind} with {segments} segments has about {triangles} triangles; the limit is {}",
                        phong_core::limits::MAX_PRIMITIVE_TRIANGLES
                    ),
                );
            }
            ctx.add_triangles(
                triangles,
                &o.segments.as_ref().map_or(span.clone(), |s| s.span()),
                "segments",
            )?;
            if kind != "torus" {
                for (v, key) in [(&o.radius, "radius"), (&o.tube, "tube")] {
                    if let Some(v) = v {
                        return ctx.err(&v.span(), key, format!("only a torus has `{key}`; use `scale`"));
                    }
                }
            }
            let mesh = match kind {
                "sphere" => primitives::sphere(segments),
                "torus" => {
                    let r = match &o.radius {
                        Some(r) => ctx.num(r, "radius", |x| x > 0.0, "> 0")?,
                        None => 1.0,
                    };
                    let t = match &o.tube {
                        Some(t) => ctx.num(t, "tube", |x| x > 0.0, "> 0")?,
                        None => 0.25,
                    };
                    primitives::torus(segments, r, t)
                }
                "cylinder" => primitives::cylinder(segments),
                "cone" => primitives::cone(segments),
                "cube" => primitives::cube(),
                "plane" => primitives::plane(segments),
                _ => primitives::teapot(segments),
            };
            let mesh = apply_normals(mesh, "analytic", &["analytic", "flat", "smooth", "angle"])?;
            Ok(vec![Object {
                name: kind.to_string(),
                mesh: mesh.transformed(&world_from_object),
                material: material.unwrap_or_default(),
                shading,
            }])
        }
        (None, Some(m)) => {
            if let Some(s) = &o.segments {
                return ctx.err(&s.span(), "segments", "a mesh has no `segments`");
            }
            let mut warnings = Vec::new();
            let mut sources = Vec::new();
            let parts = match ctx.meshes {
                Some(lookup) => match lookup(m.get_ref()) {
                    Ok(parts) => parts,
                    Err(msg) => return ctx.err(&m.span(), "mesh", msg),
                },
                None => {
                    let file = ctx.path.parent().unwrap_or(Path::new("")).join(m.get_ref());
                    if !file.exists() {
                        return ctx.err(&m.span(), "mesh", format!("file not found: {}", file.display()));
                    }
                    let ext_ok = file.extension().is_some_and(|e| e.eq_ignore_ascii_case("obj"));
                    if !ext_ok {
                        return ctx.err(&m.span(), "mesh", "only Wavefront .obj meshes are supported");
                    }
                    load_obj_sources(&file, &mut warnings, &mut sources)?
                }
            };
            let mut out = Vec::new();
            for p in parts {
                let default = if p.has_normals { "file" } else { "angle" };
                let mesh = apply_normals(p.mesh, default, &["file", "flat", "smooth", "angle"])?;
                out.push(Object {
                    name: p.name,
                    mesh: mesh.transformed(&world_from_object),
                    material: material.or(p.material).unwrap_or_default(),
                    shading,
                });
            }
            let tris: u64 = out.iter().map(|o| o.mesh.triangles().len() as u64).sum();
            ctx.warnings.extend(warnings);
            ctx.sources.extend(sources);
            ctx.add_triangles(tris, &m.span(), "mesh")?;
            Ok(out)
        }
        _ => ctx.err(
            &span,
            "object",
            "an object needs `shape` (sphere, torus, ...) or `mesh` (a file)",
        ),
    }
}

/// `world_from_object = T · Rz · Ry · Rx · S`: scale, then rotate about x, y, z (degrees), then move.
fn transform(ctx: &Ctx, o: &RawObject) -> Result<Mat4, Error> {
    let t = o
        .position
        .as_ref()
        .map_or(Ok(Vec3::ZERO), |p| ctx.vec3(p, "position"))?;
    let r = o
        .rotation
        .as_ref()
        .map_or(Ok(Vec3::ZERO), |p| ctx.vec3(p, "rotation"))?;
    let s = match &o.scale {
        None => Vec3::ONE,
        Some(sc) => {
            let v = match sc.get_ref() {
                Scale::Uniform(k) => Vec3::splat(*k),
                Scale::Axes(v) if v.len() == 3 => Vec3::new(v[0], v[1], v[2]),
                Scale::Axes(_) => return ctx.err(&sc.span(), "scale", "expected a number or [x, y, z]"),
            };
            if !v.is_finite() || v.cmpeq(Vec3::ZERO).any() {
                return ctx.err(&sc.span(), "scale", "must be finite and non-zero");
            }
            v
        }
    };
    let q = Quat::from_euler(EulerRot::ZYX, r.z.to_radians(), r.y.to_radians(), r.x.to_radians());
    Ok(Mat4::from_scale_rotation_translation(s, q, t))
}
