//! A model alone as a scene: the view that finds it, its lights and background, the model as
//! the only object. `phong render MODEL` and `phong serve MODEL` both read it.
//!
//! The model is drawn with `fit = true` (centred, bounding sphere of radius 1, in f64 where it
//! lay far from the origin), so that any finite model, whatever its size and offset, is
//! framed by the same arithmetic. The view is built in the model's frame: its up axis (given,
//! or detected), its front, and the camera placed so that every vertex is inside the frame.

use crate::beside::Beside;
use crate::toml_scene::object::{DEFAULT_CREASE, default_normals, drawn_mesh};
use crate::{Error, Loaded, ModelFile, ModelFormat, ModelPart};
use glam::{DVec3, Vec3};
use phong_core::Mesh;
use phong_core::join::Join;
use std::path::Path;

mod distance;
use distance::{depth_range, framing_distance};

/// An axis, signed: the model's up (`--up`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Axis {
    /// +x
    X,
    /// +y
    Y,
    /// +z
    Z,
    /// −x
    NegX,
    /// −y
    NegY,
    /// −z
    NegZ,
}

impl Axis {
    /// The names `--up` takes, with their axes.
    pub const NAMES: [(&'static str, Axis); 6] = [
        ("x", Axis::X),
        ("y", Axis::Y),
        ("z", Axis::Z),
        ("-x", Axis::NegX),
        ("-y", Axis::NegY),
        ("-z", Axis::NegZ),
    ];

    /// The unit vector.
    pub fn vector(self) -> Vec3 {
        match self {
            Axis::X => Vec3::X,
            Axis::Y => Vec3::Y,
            Axis::Z => Vec3::Z,
            Axis::NegX => Vec3::NEG_X,
            Axis::NegY => Vec3::NEG_Y,
            Axis::NegZ => Vec3::NEG_Z,
        }
    }

    fn name(self) -> &'static str {
        Axis::NAMES.iter().find(|(_, a)| *a == self).map_or("?", |(n, _)| n)
    }
}

/// A named view of a model alone (`--view`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ViewName {
    /// From the front, straight on.
    Front,
    /// From behind.
    Back,
    /// From the model's left (the viewer's left when seen from the front).
    Left,
    /// From the model's right.
    Right,
    /// From above, the front at the bottom of the image.
    Top,
    /// From below, the front at the top of the image.
    Bottom,
    /// From the front, right and above, at equal angles (isometric).
    Iso,
}

impl ViewName {
    /// The names `--view` takes.
    pub const NAMES: [(&'static str, ViewName); 7] = [
        ("front", ViewName::Front),
        ("back", ViewName::Back),
        ("left", ViewName::Left),
        ("right", ViewName::Right),
        ("top", ViewName::Top),
        ("bottom", ViewName::Bottom),
        ("iso", ViewName::Iso),
    ];
}

/// Which faces of a model alone are drawn (`--two-sided`, `--cull`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sides {
    /// Every face, a back face lit with its normal flipped (OpenGL's two-sided lighting).
    TwoSided,
    /// Front faces only (counter-clockwise, as OpenGL): back faces are culled.
    Cull,
}

/// How a model alone is viewed; `None` fields are decided from the model.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ModelOptions {
    /// The model's up axis (default: detected, see [`model_scene`]).
    pub up: Option<Axis>,
    /// A named view (default: from the front, a little right and above).
    pub view: Option<ViewName>,
    /// Camera position and target in the file's coordinates (overrides `view`; f64, so that
    /// a model far from the origin can be looked at closely).
    pub camera: Option<(DVec3, DVec3)>,
    /// Faces drawn (default: culled for a closed, consistently wound model; else two-sided).
    pub sides: Option<Sides>,
    /// Image width / height the view is framed for (default: the scene's default 4:3).
    pub aspect: Option<f32>,
}

/// A scene for a model alone: [`model_scene`] read by the scene reader, the model's parts as
/// its mesh (so that `phong render MODEL` and `phong serve MODEL` draw the same). What the view
/// decided goes to `notes` (`-v`).
pub(crate) fn scene_for_model(path: &Path, options: &ModelOptions) -> Result<Loaded, Error> {
    let mut model = ModelFile::read(path)?;
    // The framing (its closedness check) and the parts as drawn (their normals) do not depend
    // on each other and take milliseconds each for a large model: side by side. What the scene
    // reader would compute for the model-alone scene's object, by its own function.
    let draw = |parts: &[ModelPart]| -> Vec<Option<Mesh>> {
        let fit = fit_of(parts);
        parts
            .iter()
            .map(|p| drawn_mesh(&p.mesh, fit, default_normals(p), DEFAULT_CREASE).ok())
            .collect()
    };
    let (json, notes) = if beside_worth_it(&model) {
        let parts = &model.parts;
        // (The normals' times are taken where they ran and added to this thread's.)
        let (framing, drawn) = Beside.join(
            || framed(path, &model, options),
            || (draw(parts), crate::timing::take_times()),
        );
        crate::timing::add_times(drawn.1);
        for (p, d) in model.parts.iter_mut().zip(drawn.0) {
            p.drawn = d;
        }
        framing
    } else {
        framed(path, &model, options)
    };
    hand_on_fitted(&mut model);
    let ModelFile {
        parts,
        warnings,
        sources,
        ..
    } = model;
    // Read for this scene alone: its parts move into the scene's object, not copied (the
    // model-alone scene names the model once).
    let parts = std::cell::RefCell::new(Some(parts));
    let lookup = |_: &str| {
        parts
            .borrow_mut()
            .take()
            .ok_or_else(|| "the model is named twice in its own scene".to_string())
    };
    let mut loaded = scene_from(path, &json, &lookup, notes)?;
    loaded.warnings.splice(0..0, warnings);
    loaded.sources = sources;
    Ok(loaded)
}

/// The framing's vertices in the fitted frame handed to the parts not already drawn, for the
/// scene reader to take instead of computing them again (the model is read for one scene).
fn hand_on_fitted(model: &mut ModelFile) {
    let Some(Fitted { mut points, .. }) = model.fitted.take() else {
        return;
    };
    // `points` holds every part's vertices in the parts' order: split from the last part.
    for p in model.parts.iter_mut().rev() {
        let rest = points.len().saturating_sub(p.mesh.positions().len());
        // (The first part takes what is left as it is: `split_off(0)` would copy it.)
        let own = if rest == 0 {
            std::mem::take(&mut points)
        } else {
            points.split_off(rest)
        };
        if p.drawn.is_none() && own.len() == p.mesh.positions().len() {
            p.fitted = Some(own);
        }
    }
}

/// Whether the framing and the normals of `parts` are worth computing side by side ([`Beside`]
/// takes a second thread where there are two cores): where both
/// are computed (a model without normals of its own, not a glTF, whose closedness the framing
/// checks) and large enough that a thread's start (tens of µs) is small beside them.
fn beside_worth_it(model: &ModelFile) -> bool {
    const MIN_TRIANGLES: usize = 20_000;
    let parts = &model.parts;
    let triangles: usize = parts.iter().map(|p| p.mesh.triangles().len()).sum();
    model.format != ModelFormat::Gltf
        && (MIN_TRIANGLES..=MAX_CLOSED_CHECK).contains(&triangles)
        && parts.iter().any(|p| default_normals(p) == "angle")
}

/// The scene of a model alone (as `phong render MODEL` frames it) for a model already read
/// from `path` (a model read once and viewed many times: `phong batch`, the Python module).
/// `sources` is left empty and `warnings` holds the scene reader's only.
pub fn scene_of_model(path: &Path, model: &ModelFile, options: &ModelOptions) -> Result<Loaded, Error> {
    let (json, notes) = framed(path, model, options);
    let parts = &model.parts;
    scene_from(path, &json, &|_: &str| Ok(parts.clone()), notes)
}

/// The model-alone scene of `model` (read from `path`) as JSON, and its notes.
fn framed(path: &Path, model: &ModelFile, options: &ModelOptions) -> (serde_json::Value, Vec<String>) {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    crate::timing::timed(|t| &mut t.framing, || model_scene(&name, model, options))
}

/// The scene of `json` (a model-alone scene of the model at `path`), its model's parts from
/// `lookup`, with `notes`.
fn scene_from(
    path: &Path,
    json: &serde_json::Value,
    lookup: &crate::toml_scene::MeshLookup,
    notes: Vec<String>,
) -> Result<Loaded, Error> {
    let mut loaded = crate::parse_scene_json(json, lookup).map_err(|e| Error::Parse {
        path: path.to_path_buf(),
        line: 1,
        col: 1,
        key: Some(e.path),
        message: format!("the model cannot be framed: {}", e.message),
    })?;
    loaded.notes = notes;
    Ok(loaded)
}

/// The centre and bounding-sphere radius of a model's parts (half its bounding box's
/// diagonal; 1 for a model of one point), in the parts' coordinates: what `fit = true` maps to
/// the origin and to 1.
pub(crate) fn fit_of(parts: &[ModelPart]) -> Option<(DVec3, f64)> {
    let (lo, hi) = bounds_of(parts)?;
    let (lo, hi) = (lo.as_dvec3(), hi.as_dvec3());
    let radius = (hi - lo).length() * 0.5;
    let radius = if radius > 0.0 && radius.is_finite() {
        radius
    } else {
        1.0
    };
    Some(((lo + hi) * 0.5, radius))
}

/// A model's fit (the centre and radius of its bounding box's sphere; the origin and 1 without
/// vertices) and its vertices in the fitted frame (centred, radius 1), in its parts' order.
#[derive(Clone, Debug)]
pub(crate) struct Fitted {
    centre: DVec3,
    radius: f64,
    points: Vec<Vec3>,
}

impl Fitted {
    fn of(parts: &[ModelPart]) -> Fitted {
        let (centre, radius) = fit_of(parts).unwrap_or((DVec3::ZERO, 1.0));
        let points = parts
            .iter()
            .flat_map(|p| p.mesh.positions())
            .map(|&p| fitted_point(p, centre, radius))
            .collect();
        Fitted { centre, radius, points }
    }
}

/// `p` in the fitted frame of `centre` and `radius`. In f64: a model's coordinates may be near
/// f32's largest, its radius's inverse below f32's smallest normal number.
#[inline]
fn fitted_point(p: Vec3, centre: DVec3, radius: f64) -> Vec3 {
    ((p.as_dvec3() - centre) / radius).as_vec3()
}

/// The bounding box of a model's parts together (`None`: no vertices).
fn bounds_of(parts: &[ModelPart]) -> Option<(Vec3, Vec3)> {
    parts
        .iter()
        .filter_map(|p| p.mesh.bounds())
        .reduce(|(a, b), (c, d)| (a.min(c), b.max(d)))
}

/// The lights of a model alone, `(direction, grey level)` in the default view's camera frame
/// (x right, y up, z toward the viewer): key, fill, back and a headlight. They turn with the
/// camera, so every view is lit alike.
const MODEL_LIGHTS: [([f32; 3], f32); 4] = [
    ([1.0, -1.0, -1.0], 0.8),
    ([-1.0, -0.3, -0.5], 0.35),
    ([0.0, -0.5, 1.0], 0.3),
    // A headlight, from the camera along its axis: every face the camera sees is lit by it,
    // so none is lost in the background (as most model viewers light).
    ([-DEFAULT_VIEW.x, -DEFAULT_VIEW.y, -DEFAULT_VIEW.z], 0.2),
];

/// The background of a model alone.
const MODEL_BACKGROUND: [f32; 4] = [0.08, 0.08, 0.1, 1.0];

/// The default view's direction in the model's frame (right, up, front): from the front, a
/// little right and above.
const DEFAULT_VIEW: Vec3 = Vec3::new(0.35, 0.45, 1.0);

/// Vertical field of view of a model alone, degrees.
const FOV: f32 = 45.0;

/// The share of the frame's half-width or half-height the model may fill.
const FILL: f32 = 0.92;

/// The scene of a model alone, as JSON with the scene file's schema, and notes on what was
/// decided (for `-v`):
/// - the model with `fit = true` and its MTL materials (or OpenGL's default);
/// - up: `options.up`, else detected: y for a model long along y, z for one
///   long along z or standing on a flat base facing −z (a scan of a statue or bust, like
///   Nefertiti's), else y;
/// - front: +z for a y-up model, −y for a z-up one (Blender's front view), the convention's
///   axis turned likewise for other ups;
/// - faces: `options.sides`, else as the file says (glTF's `doubleSided`), else culled where
///   the model is closed (each edge shared by two faces, wound opposite ways) and wound
///   outward (positive volume), else two-sided;
/// - the camera: `options.camera`, else the named view (default: front, a little right and
///   above), at the distance where every vertex is inside 92% of the frame, its near and
///   far planes from the vertices' depths; perspective, 45°.
///
/// A glTF is y up with its front +z (the format's convention, so neither is detected), viewed
/// from its first camera where it has one (unless `options` name a view or camera), and lit by
/// its KHR_lights_punctual lights where it has some: their colours times their intensities,
/// scaled so that the brightest is 1, without distance falloff (glTF's are physical units, which
/// Phong's clamped sum has no use for).
pub fn model_scene(name: &str, model: &ModelFile, options: &ModelOptions) -> (serde_json::Value, Vec<String>) {
    let parts = &model.parts[..];
    let gltf = model.format == ModelFormat::Gltf;
    let mut notes = Vec::new();
    let Fitted {
        centre,
        radius,
        ref points,
    } = *model.fitted.get_or_init(|| Fitted::of(parts));
    let fitted = |p: Vec3| fitted_point(p, centre, radius);
    let origin = parts.first().map_or(DVec3::ZERO, |p| p.origin);
    if origin != DVec3::ZERO {
        notes.push(format!(
            "the model lies far from the origin: re-centred on ({}, {}, {}) in f64",
            origin.x, origin.y, origin.z
        ));
    }
    // Computed once per model read, where asked: its views all ask.
    let facets = || *model.facets.get_or_init(|| facets(parts));
    let up = up_axis(&facets, gltf, options, &mut notes);
    let u = up.vector();
    // A glTF says its front and its faces: its edges are not examined.
    let closed = (!gltf).then(|| *model.closed.get_or_init(|| closedness(parts)));
    let f = front(parts, &facets, up, closed, options, &mut notes);
    let r = u.cross(f);
    let two_sided = two_sided(model, closed, options, &mut notes);
    let aspect = options
        .aspect
        .filter(|a| a.is_finite() && *a > 0.0)
        .unwrap_or(4.0 / 3.0);
    let to_parts = |x: DVec3| (x - origin).as_vec3();
    let mut fov = FOV;
    let file_camera = model
        .camera
        .filter(|_| options.camera.is_none() && options.view.is_none());
    let camera = match (options.camera, file_camera) {
        (Some(c), _) => Some(c),
        (None, Some(c)) => {
            // Looking at the model's centre's depth along the camera's axis.
            let eye = c.position;
            let centre_file = centre + origin;
            let depth = (centre_file - eye).dot(c.forward).max(radius * 1e-3);
            fov = c.fov_deg.filter(|f| *f > 0.0 && *f < 180.0).unwrap_or(FOV);
            notes.push(format!(
                "the file's camera{} (--view or --camera to choose another)",
                if c.fov_deg.is_none() {
                    ", orthographic, drawn in perspective"
                } else {
                    ""
                }
            ));
            Some((eye, eye + c.forward * depth))
        }
        (None, None) => None,
    };
    let file_up = file_camera.map(|c| c.up.as_vec3());
    let (position, target, cam_up) = match camera {
        Some((p, t)) => {
            let (p, t) = (fitted(to_parts(p)), fitted(to_parts(t)));
            let d = (p - t).normalize_or_zero();
            // The file camera's up, else the model's unless the camera looks along it.
            let cu = file_up.unwrap_or(if d.cross(u).length() > 1e-3 { u } else { f });
            (p, t, cu)
        }
        None => {
            let (dir, cu) = view_direction(options.view, (r, u, f));
            let dist = framing_distance(points, dir, cu, aspect);
            (dir * dist, Vec3::ZERO, cu)
        }
    };
    let (near, far) = depth_range(points, position, target);
    let lights = match file_lights(model, &|x| fitted(to_parts(x))) {
        Some(l) => {
            notes.push(format!("the file's {} lights", model.lights.len()));
            l
        }
        None => rig_lights(position, target, cam_up),
    };
    let bg = MODEL_BACKGROUND;
    let json = serde_json::json!({
        "image": {"background": [short(bg[0]), short(bg[1]), short(bg[2])], "antialias": 4},
        "camera": {"position": round6(position), "target": round6(target), "up": round6(cam_up),
                   "fov": short(fov), "near": short(near), "far": short(far)},
        "shading": {"viewer": "local", "two_sided": two_sided},
        "light": lights,
        "object": [{"mesh": name, "fit": true}],
    });
    (json, notes)
}

/// The up axis: `options.up`, y for a glTF, else detected (said in `notes`).
fn up_axis(facets: &dyn Fn() -> Facets, gltf: bool, options: &ModelOptions, notes: &mut Vec<String>) -> Axis {
    match options.up {
        Some(a) => a,
        None if gltf => Axis::Y,
        None => {
            let (a, why) = detect_up(&facets());
            notes.push(format!(
                "up axis {} (detected{}; --up to choose)",
                a.name(),
                why.map(|w| format!(": {w}")).unwrap_or_default()
            ));
            a
        }
    }
}

/// The front: where the model tells it ([`detect_front`], said in `notes` unless the camera is
/// given), else the convention's axis for `up` (+z for y up, −y for z up).
fn front(
    parts: &[ModelPart],
    facets: &dyn Fn() -> Facets,
    up: Axis,
    closed: Option<Closed>,
    options: &ModelOptions,
    notes: &mut Vec<String>,
) -> Vec3 {
    let f = match up {
        Axis::Y => Vec3::Z,
        Axis::NegY => Vec3::NEG_Z,
        Axis::Z => Vec3::NEG_Y,
        Axis::NegZ => Vec3::Y,
        Axis::X => Vec3::Z,
        Axis::NegX => Vec3::Z,
    };
    match closed.and_then(|c| detect_front(parts, &facets(), (up.vector(), f), c)) {
        Some((front, why)) => {
            if options.camera.is_none() {
                notes.push(format!("front {} ({why})", axis_name(front)));
            }
            front
        }
        None => f,
    }
}

/// Whether the model is lit two-sided and not culled: `options.sides`, else the file's
/// materials (glTF), else two-sided unless it is closed and wound outward (said in `notes`).
fn two_sided(model: &ModelFile, closed: Option<Closed>, options: &ModelOptions, notes: &mut Vec<String>) -> bool {
    match (options.sides, model.double_sided) {
        (Some(s), _) => s == Sides::TwoSided,
        (None, Some(d)) => {
            notes.push(if d {
                "two-sided lighting, no culling: the file's materials are double-sided (--cull to cull)".into()
            } else {
                "back faces culled: the file's materials are single-sided (--two-sided to draw them)".into()
            });
            d
        }
        (None, None) => {
            let c = closed.unwrap_or(Closed::Unchecked);
            let two = !c.closed_outward();
            notes.push(match (two, c) {
                (false, _) => {
                    "back faces culled: the model is closed and wound outward (--two-sided to draw them)".into()
                }
                (
                    true,
                    Closed::Open {
                        open_edges,
                        inconsistent,
                    },
                ) => format!(
                    "two-sided lighting, no culling: the model is not closed ({open_edges} open edges, \
                     {inconsistent} edges wound alike; --cull to cull)"
                ),
                (true, Closed::Inward) => {
                    "two-sided lighting, no culling: the model is closed but wound inward (--cull to cull)".into()
                }
                (true, _) => "two-sided lighting, no culling: the model was not checked (too large)".into(),
            });
            two
        }
    }
}

/// The direction from the target to the camera, and the camera's up, for a named view (the
/// default: from the front, a little right and above) in the model's frame `(r, u, f)`.
fn view_direction(view: Option<ViewName>, (r, u, f): (Vec3, Vec3, Vec3)) -> (Vec3, Vec3) {
    match view {
        None => (
            (r * DEFAULT_VIEW.x + u * DEFAULT_VIEW.y + f * DEFAULT_VIEW.z).normalize(),
            u,
        ),
        Some(ViewName::Front) => (f, u),
        Some(ViewName::Back) => (-f, u),
        Some(ViewName::Right) => (r, u),
        Some(ViewName::Left) => (-r, u),
        Some(ViewName::Top) => (u, -f),
        Some(ViewName::Bottom) => (-u, f),
        Some(ViewName::Iso) => ((r + u + f).normalize(), u),
    }
}

/// The rig of [`MODEL_LIGHTS`], carried from the default view's camera frame to this camera's.
fn rig_lights(position: Vec3, target: Vec3, cam_up: Vec3) -> Vec<serde_json::Value> {
    let d0 = DEFAULT_VIEW.normalize();
    let r0 = Vec3::Y.cross(d0).normalize();
    let u0 = d0.cross(r0);
    let dc = (position - target).normalize_or(Vec3::Z);
    let rc = cam_up.cross(dc).normalize_or(Vec3::X);
    let uc = dc.cross(rc);
    MODEL_LIGHTS
        .iter()
        .map(|(d, c)| {
            let l = Vec3::from_array(*d);
            let (x, y, z) = (l.dot(r0), l.dot(u0), l.dot(d0));
            let w = rc * x + uc * y + dc * z;
            serde_json::json!({"type": "directional", "direction": round6(w), "color": [short(*c), short(*c), short(*c)]})
        })
        .collect()
}

/// The file's own lights (glTF's KHR_lights_punctual), their colours scaled so that the
/// brightest is 1, positions carried into the fitted frame by `fitted`; `None` where it has
/// none that shine.
fn file_lights(model: &ModelFile, fitted: &dyn Fn(DVec3) -> Vec3) -> Option<Vec<serde_json::Value>> {
    let brightest = model.lights.iter().flat_map(|l| l.color).fold(0.0f32, f32::max);
    if !(brightest > 0.0 && brightest.is_finite()) {
        return None;
    }
    Some(
        model
            .lights
            .iter()
            .filter_map(|l| {
                let color = l.color.map(|c| short(c / brightest));
                let dir = round6(l.direction.as_vec3());
                let pos = round6(fitted(l.position));
                (dir != [0.0; 3] || l.kind == "point").then(|| match l.kind {
                    "directional" => serde_json::json!({"type": "directional", "direction": dir, "color": color}),
                    "point" => serde_json::json!({"type": "point", "position": pos, "color": color}),
                    _ => serde_json::json!({"type": "spot", "position": pos, "direction": dir, "color": color,
                                            "cutoff": l.cutoff_deg, "exponent": 0.0}),
                })
            })
            .collect(),
    )
}

/// `x` with 6 decimals, so that the scene's text (and the explorer's "Download TOML") is
/// short: `0.8`, not f32's `0.800000011920929` written as f64.
fn short(x: f32) -> f64 {
    // `+ 0.0` writes −0 as 0.
    (f64::from(x) * 1e6).round() / 1e6 + 0.0
}

/// [`short`] of each coordinate.
fn round6(v: Vec3) -> [f64; 3] {
    v.to_array().map(short)
}

/// The name of a unit axis vector (`+x`, `-z`).
fn axis_name(v: Vec3) -> String {
    let i = v.abs().max_position();
    format!("{}{}", if v[i] < 0.0 { '-' } else { '+' }, ['x', 'y', 'z'][i])
}

/// The model's front where it tells one other than the convention's `f` (`None` keeps `f`),
/// with the reason, looking only across the four horizontal axes (`±f`, `±(u × f)`):
/// - a model that is not closed faces the way its surface does: the horizontal part of its
///   area vector (Σ area·n), where that holds at least 10% of its area (the open side of a
///   Cornell box, a single triangle, a flat model standing on edge);
/// - else, a model longer along `f` than it is tall (an animal on its legs, as Spot) turns its
///   top toward its front (the head above the body): `−f` when the vertices of its top tenth
///   lie behind the middle by more than 10% of its depth.
fn detect_front(
    parts: &[ModelPart],
    facets: &Facets,
    (u, f): (Vec3, Vec3),
    closed: Closed,
) -> Option<(Vec3, &'static str)> {
    let r = u.cross(f);
    let (lo, hi) = facets.bounds?;
    if !matches!(closed, Closed::Outward | Closed::Inward) {
        let Facets {
            area,
            area_total: total,
            ..
        } = *facets;
        let along = |d: Vec3| d.as_dvec3().dot(area);
        let best = [f, -f, r, -r]
            .into_iter()
            .max_by(|a, b| along(*a).total_cmp(&along(*b)))?;
        if along(best) >= 0.1 * total {
            return (best != f).then_some((best, "the open model's surface faces that way"));
        }
    }
    // A model longer along the front axis than it is tall (an animal on its legs).
    let (h_lo, h_hi) = (lo.dot(u).min(hi.dot(u)), lo.dot(u).max(hi.dot(u)));
    let (d_lo, d_hi) = (lo.dot(f).min(hi.dot(f)), lo.dot(f).max(hi.dot(f)));
    let depth = f64::from(d_hi - d_lo);
    if depth < f64::from(h_hi - h_lo) {
        return None;
    }
    let top = h_hi - 0.1 * (h_hi - h_lo);
    let (mut sum, mut n) = (0.0f64, 0u64);
    for p in parts.iter().flat_map(|p| p.mesh.positions()) {
        if p.dot(u) >= top {
            sum += f64::from(p.dot(f));
            n += 1;
        }
    }
    let middle = f64::from(d_lo + d_hi) * 0.5;
    (n > 0 && depth > 0.0 && sum / n as f64 - middle < -0.1 * depth).then_some((-f, "its top, a head, leans that way"))
}

/// The up axis, and why where it is not y. Long along y and round across (y at least twice
/// the other two extents, which are within a factor of 2 of each other): y. Long along z and
/// round across (a bottle, a figure, a column scanned z up; taken y up, it would be seen
/// end-on): z. Standing on a flat base facing −z (faces within 18° of −z in the lowest 2% of
/// its height hold at least 2% of its area, and 3 times the area that faces −y in its lowest
/// 2% along y): z. Else y.
fn detect_up(facets: &Facets) -> (Axis, Option<&'static str>) {
    let Some((lo, hi)) = facets.bounds else {
        return (Axis::Y, None);
    };
    let ext = hi.as_dvec3() - lo.as_dvec3();
    let Facets {
        total, base_z, base_y, ..
    } = *facets;
    // Long along `along`, round across the other two.
    let long = |along: f64, a: f64, b: f64| along >= 2.0 * a.max(b) && a.min(b) >= 0.5 * a.max(b);
    if long(ext.y, ext.x, ext.z) {
        // Standing y up as the convention has it (a lying one's side may be a flat facet).
        (Axis::Y, None)
    } else if long(ext.z, ext.x, ext.y) {
        (Axis::Z, Some("long along z, round across"))
    } else if total > 0.0 && base_z >= 0.02 * total && base_z > 3.0 * base_y {
        (Axis::Z, Some("a flat base facing -z"))
    } else {
        (Axis::Y, None)
    }
}

/// The sums over a model's facets that the up and front detections read, found in one pass
/// (in f64: a model's coordinates may be near f32's largest).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Facets {
    /// The bounding box ([`bounds_of`]).
    bounds: Option<(Vec3, Vec3)>,
    /// Twice the area of the facets of positive area, and of those among them facing within
    /// 18° of −z (−y) with their centroid in the lowest 2% of the height along z (y).
    total: f64,
    base_z: f64,
    base_y: f64,
    /// The area vector (Σ area·n) and the area of every facet.
    area: DVec3,
    area_total: f64,
}

fn facets(parts: &[ModelPart]) -> Facets {
    let Some((lo, hi)) = bounds_of(parts) else {
        return Facets::default();
    };
    let mut sums = Facets {
        bounds: Some((lo, hi)),
        ..Facets::default()
    };
    let (lo, hi) = (lo.as_dvec3(), hi.as_dvec3());
    let ext = hi - lo;
    for p in parts {
        let pos = p.mesh.positions();
        for t in p.mesh.triangles() {
            let [a, b, c] = t.map(|i| pos[i as usize].as_dvec3());
            let n = (b - a).cross(c - a);
            let half = n * 0.5;
            let area2 = n.length();
            sums.area += half;
            // `half.length()`, one root fewer: halving is exact in f64 for products of f32
            // coordinates (no underflow or overflow), and so is the root's.
            sums.area_total += area2 * 0.5;
            if area2.is_nan() || area2 <= 0.0 {
                continue;
            }
            sums.total += area2;
            let centroid = (a + b + c) / 3.0;
            let unit = n / area2;
            if unit.z < -0.95 && centroid.z - lo.z <= 0.02 * ext.z {
                sums.base_z += area2;
            }
            if unit.y < -0.95 && centroid.y - lo.y <= 0.02 * ext.y {
                sums.base_y += area2;
            }
        }
    }
    sums
}

/// Whether a model is closed, and which way it is wound.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Closed {
    /// Every edge is shared by two faces wound opposite ways, and the volume is positive.
    Outward,
    /// Closed and consistent, but the volume is negative (normals point in).
    Inward,
    /// Edges with one face (open) or with faces wound alike.
    Open { open_edges: usize, inconsistent: usize },
    /// Not checked (more than [`MAX_CLOSED_CHECK`] triangles).
    Unchecked,
}

impl Closed {
    /// A model with `open_edges` edges of one face or more than two, `inconsistent` edges of
    /// two faces wound alike, and the signed volume `volume` (six times it).
    fn judged(open_edges: usize, inconsistent: usize, volume: f64) -> Closed {
        match (open_edges + inconsistent, volume > 0.0) {
            (0, true) => Closed::Outward,
            (0, false) => Closed::Inward,
            _ => Closed::Open {
                open_edges,
                inconsistent,
            },
        }
    }

    fn closed_outward(self) -> bool {
        self == Closed::Outward
    }
}

/// Each face of `parts` with three distinct welded ids (`ids`, all parts' vertices in turn;
/// `identity`: each id is the vertex's index), given to `f` with its positions (zeros without
/// `POSITIONS`: a pass that reads none does not fetch them). Generic, so that each pass is one
/// loop (as a `dyn` callback it was a call per face).
#[inline(always)]
fn each_face<const POSITIONS: bool>(
    parts: &[ModelPart],
    ids: &[u32],
    identity: bool,
    mut f: impl FnMut([u32; 3], [Vec3; 3]),
) {
    let mut first = 0;
    for p in parts {
        let pos = p.mesh.positions();
        let id = &ids[first..first + pos.len()];
        let base = first as u32;
        first += pos.len();
        for t in p.mesh.triangles() {
            let [a, b, c] = if identity {
                t.map(|i| base + i)
            } else {
                t.map(|i| id[i as usize])
            };
            if a != b && b != c && c != a {
                f(
                    [a, b, c],
                    if POSITIONS {
                        t.map(|i| pos[i as usize])
                    } else {
                        [Vec3::ZERO; 3]
                    },
                );
            }
        }
    }
}

/// Models with more triangles than this are not checked for closedness (and drawn two-sided):
/// the edge lists take about 36 bytes a triangle.
const MAX_CLOSED_CHECK: usize = 4_000_000;

/// [`Closed`] for a model's parts together, vertices joined where their positions are equal.
fn closedness(parts: &[ModelPart]) -> Closed {
    let count: usize = parts.iter().map(|p| p.mesh.triangles().len()).sum();
    if count > MAX_CLOSED_CHECK {
        return Closed::Unchecked;
    }
    // Positions welded (one id where parts or vertices share a position), all parts at once.
    let (distinct, ids) = match parts {
        [p] => phong_core::mesh::weld_ids(p.mesh.positions()),
        _ => phong_core::mesh::weld_ids(
            &parts
                .iter()
                .flat_map(|p| p.mesh.positions())
                .copied()
                .collect::<Vec<_>>(),
        ),
    };
    // Every position distinct (most files): a vertex's id is its index.
    let identity = distinct == ids.len();
    // Each face's edges (x, y) as (higher id, +1 or -1), kept under the lower id; a closed,
    // consistent model has two faces on every edge, wound opposite ways. Lists under each id
    // (counted in a first pass over the faces, filled in a second), not a hash map of edges:
    // linear, and a few times faster.
    let mut start = vec![0u32; distinct + 1];
    let mut volume = 0.0f64;
    each_face::<true>(parts, &ids, identity, |[a, b, c], [pa, pb, pc]| {
        volume += pa.as_dvec3().dot(pb.as_dvec3().cross(pc.as_dvec3()));
        for (x, y) in [(a, b), (b, c), (c, a)] {
            start[x.min(y) as usize + 1] += 1;
        }
    });
    for i in 0..distinct {
        start[i + 1] += start[i];
    }
    let mut under = vec![(0u32, 0i32); start[distinct] as usize];
    let mut fill = start.clone();
    each_face::<false>(parts, &ids, identity, |[a, b, c], _| {
        for (x, y) in [(a, b), (b, c), (c, a)] {
            let (lo, hi, sign) = if x < y { (x, y, 1) } else { (y, x, -1) };
            under[fill[lo as usize] as usize] = (hi, sign);
            fill[lo as usize] += 1;
        }
    });
    // Per list, the faces on each edge counted in `on` (indexed by the higher id), then each
    // edge judged once and its count cleared: linear, no sort.
    let (mut open_edges, mut inconsistent) = (0, 0);
    let mut on = vec![(0u32, 0i32); distinct];
    for w in start.windows(2) {
        let list = &under[w[0] as usize..w[1] as usize];
        for &(hi, sign) in list {
            let e = &mut on[hi as usize];
            e.0 += 1;
            e.1 += sign;
        }
        for &(hi, _) in list {
            let e = &mut on[hi as usize];
            match *e {
                (0, _) => continue,
                (2, 0) => {}
                (2, _) => inconsistent += 1,
                _ => open_edges += 1,
            }
            *e = (0, 0);
        }
    }
    Closed::judged(open_edges, inconsistent, volume)
}

#[cfg(test)]
mod tests {
    use super::*;
    use phong_core::{Mesh, primitives};

    fn part(mesh: Mesh) -> ModelPart {
        ModelPart {
            name: "t".into(),
            mesh,
            material: None,
            maps: Default::default(),
            has_normals: false,
            flat_without_normals: false,
            origin: DVec3::ZERO,
            drawn: None,
            fitted: None,
        }
    }

    /// Parts whose positions are all distinct (each id its index, counted on from part to
    /// part): two welded cubes apart are closed, a cube and a plane apart are open at the
    /// plane's 8 border edges, and the same parts with each position repeated (ids by table)
    /// are judged alike.
    #[test]
    fn closedness_of_distinct_parts() {
        let cube = primitives::cube().welded();
        assert_eq!(cube.positions().len(), 8, "a welded cube has its 8 corners");
        let moved = |m: &Mesh, dx: f32| m.transformed(&glam::Mat4::from_translation(Vec3::new(dx, 0.0, 0.0)));
        let two = [part(cube.clone()), part(moved(&cube, 5.0))];
        assert_eq!(closedness(&two), Closed::Outward);
        let plane = primitives::plane(2).welded();
        let open = [part(cube.clone()), part(moved(&plane, 5.0))];
        let want = Closed::Open {
            open_edges: 8,
            inconsistent: 0,
        };
        assert_eq!(closedness(&open), want);
        // Each part's positions twice over (the second copy unused): ids from the table.
        let doubled = |m: &Mesh| {
            let mut p = m.positions().to_vec();
            p.extend_from_slice(m.positions());
            Mesh::from_triangles(p, m.triangles().to_vec()).unwrap()
        };
        assert_eq!(
            closedness(&[part(doubled(&cube)), part(moved(&doubled(&cube), 5.0))]),
            Closed::Outward
        );
        assert_eq!(
            closedness(&[part(doubled(&cube)), part(moved(&doubled(&plane), 5.0))]),
            want
        );
    }

    /// [`closedness`] from its definition: every edge of a face of three distinct positions
    /// counted in a map with its faces' directions.
    fn closedness_by_map(parts: &[ModelPart]) -> Closed {
        let key = |p: Vec3| p.to_array().map(|c| if c == 0.0 { 0 } else { c.to_bits() });
        let mut edges: std::collections::HashMap<([u32; 3], [u32; 3]), (usize, i64)> = Default::default();
        let mut volume = 0.0f64;
        for p in parts {
            for t in p.mesh.triangles() {
                let [a, b, c] = t.map(|i| p.mesh.positions()[i as usize]);
                let [ka, kb, kc] = [a, b, c].map(key);
                if ka == kb || kb == kc || kc == ka {
                    continue;
                }
                volume += a.as_dvec3().dot(b.as_dvec3().cross(c.as_dvec3()));
                for (x, y) in [(ka, kb), (kb, kc), (kc, ka)] {
                    let e = edges.entry((x.min(y), x.max(y))).or_default();
                    e.0 += 1;
                    e.1 += if x < y { 1 } else { -1 };
                }
            }
        }
        let open_edges = edges.values().filter(|e| e.0 != 2).count();
        let inconsistent = edges.values().filter(|e| e.0 == 2 && e.1 != 0).count();
        Closed::judged(open_edges, inconsistent, volume)
    }

    proptest::proptest! {
        /// Faces over a few positions (some equal, some faces repeated, turned or degenerate),
        /// in one part or two: the counts the definition gives.
        #[test]
        fn closedness_is_the_maps(
            faces in proptest::collection::vec((0u32..7, 0u32..7, 0u32..7), 1..40),
            split in 0usize..40,
        ) {
            let values = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z, Vec3::ONE, Vec3::new(-0.0, 0.0, 0.0), Vec3::X];
            let mesh = |fs: &[(u32, u32, u32)]| {
                let tris = fs.iter().map(|&(a, b, c)| [a, b, c]).collect();
                part(Mesh::from_triangles(values.to_vec(), tris).expect("mesh"))
            };
            let one = [mesh(&faces)];
            proptest::prop_assert_eq!(closedness(&one), closedness_by_map(&one));
            let k = split.min(faces.len());
            if k > 0 && k < faces.len() {
                let two = [mesh(&faces[..k]), mesh(&faces[k..])];
                proptest::prop_assert_eq!(closedness(&two), closedness_by_map(&two));
            }
        }
    }

    /// The cube (its faces' vertices apart, joined by position) is closed; a plane is open;
    /// the cube inside out is closed and inward.
    #[test]
    fn closedness_of_shapes() {
        assert_eq!(closedness(&[part(primitives::cube())]), Closed::Outward);
        let open = closedness(&[part(primitives::plane(2))]);
        assert!(
            matches!(
                open,
                Closed::Open {
                    open_edges: 8,
                    inconsistent: 0
                }
            ),
            "{open:?}"
        );
        // The cube inside out.
        let c = primitives::cube();
        let flipped: Vec<[u32; 3]> = c.triangles().iter().map(|t| [t[0], t[2], t[1]]).collect();
        let inward = Mesh::from_triangles(c.positions().to_vec(), flipped).unwrap();
        assert_eq!(closedness(&[part(inward)]), Closed::Inward);
        // One side turned over (its two triangles): its 4 edges wound alike with the
        // neighbours', its diagonal still opposite.
        let mut one: Vec<[u32; 3]> = c.triangles().to_vec();
        assert!(
            one[0].iter().filter(|v| one[1].contains(v)).count() == 2,
            "the cube's triangles 0 and 1 make one side"
        );
        for t in &mut one[..2] {
            *t = [t[0], t[2], t[1]];
        }
        let turned = Mesh::from_triangles(c.positions().to_vec(), one).unwrap();
        let want = Closed::Open {
            open_edges: 0,
            inconsistent: 4,
        };
        assert_eq!(closedness(&[part(turned)]), want);
        // A fin on one edge: that edge has 3 faces, the fin's other two have 1.
        let mut positions = c.positions().to_vec();
        positions.push(glam::Vec3::splat(5.0));
        let mut fin: Vec<[u32; 3]> = c.triangles().to_vec();
        let [a, b, _] = fin[0];
        fin.push([b, a, positions.len() as u32 - 1]);
        let finned = Mesh::from_triangles(positions, fin).unwrap();
        let want = Closed::Open {
            open_edges: 3,
            inconsistent: 0,
        };
        assert_eq!(closedness(&[part(finned)]), want);
    }
}
