//! A model alone as a scene: the camera that frames it, its lights and background, the model
//! as the only object. `phong render MODEL.obj` and `phong serve MODEL.obj` both read it.

use crate::{Error, Loaded, ObjPart, load_model_sources};
use glam::Vec3;
use std::path::Path;

/// A scene for an OBJ model alone: [`model_scene`] read by the scene reader, the OBJ's parts
/// as its mesh (so that `phong render MODEL.obj` and `phong serve MODEL.obj` draw the same).
pub(crate) fn scene_for_model(path: &Path) -> Result<Loaded, Error> {
    let (mut warnings, mut sources) = (Vec::new(), Vec::new());
    let parts = load_model_sources(path, &mut warnings, &mut sources)?;
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let bounds = parts
        .iter()
        .filter_map(|p| p.mesh.bounds())
        .reduce(|(a, b), (c, d)| (a.min(c), b.max(d)));
    let v = model_view(bounds);
    if !(v.position.is_finite() && v.near.is_finite() && v.far.is_finite()) {
        let extent = bounds.map_or(0.0, |(lo, hi)| (hi - lo).max_element());
        return Err(Error::Parse {
            path: path.to_path_buf(),
            line: 1,
            col: 1,
            key: None,
            message: format!(
                "the model is too large for the automatic camera (its extent is {extent:e}, past f32's range once framed); \
                 put it in a scene file with a `scale` and a camera"
            ),
        });
    }
    let json = model_scene(&name, &parts);
    let lookup = |_: &str| Ok(parts.clone());
    let mut loaded = crate::parse_scene_json(&json, &lookup).map_err(|e| Error::Parse {
        path: path.to_path_buf(),
        line: 1,
        col: 1,
        key: Some(e.path),
        message: format!("the model cannot be framed: {}", e.message),
    })?;
    warnings.append(&mut loaded.warnings);
    loaded.warnings = warnings;
    loaded.sources = sources;
    Ok(loaded)
}

/// The scene of a model alone, as JSON with the scene file's schema: its MTL materials (or
/// OpenGL's default), a perspective camera framing its bounding sphere ([`model_view`]),
/// three lights (key, fill, back), 4 samples per pixel, the model as its only object
/// (`mesh = name`).
pub fn model_scene(name: &str, parts: &[ObjPart]) -> serde_json::Value {
    let bounds = parts
        .iter()
        .filter_map(|p| p.mesh.bounds())
        .reduce(|(a, b), (c, d)| (a.min(c), b.max(d)));
    let v = model_view(bounds);
    let bg = MODEL_BACKGROUND;
    let lights: Vec<_> = MODEL_LIGHTS
        .iter()
        .map(|(d, c)| serde_json::json!({"type": "directional", "direction": d, "color": [c, c, c]}))
        .collect();
    serde_json::json!({
        "image": {"background": [bg[0], bg[1], bg[2]], "antialias": 4},
        "camera": {"position": v.position.to_array(), "target": v.target.to_array(), "fov": v.fov,
                   "near": v.near, "far": v.far},
        "shading": {"viewer": "local"},
        "light": lights,
        "object": [{"mesh": name}],
    })
}

/// The view of a model alone: a perspective camera, its vertical field of view 45°, looking
/// at the centre of the bounding box `(lo, hi)` from above right, far enough that the box's
/// bounding sphere fits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModelView {
    /// Camera position.
    pub position: Vec3,
    /// Camera target.
    pub target: Vec3,
    /// Near plane.
    pub near: f32,
    /// Far plane.
    pub far: f32,
    /// Vertical field of view, degrees.
    pub fov: f32,
}

/// The lights of a model alone, `(direction, grey level)`: key, fill and back.
const MODEL_LIGHTS: [([f32; 3], f32); 3] = [
    ([1.0, -1.0, -1.0], 0.8),
    ([-1.0, -0.3, -0.5], 0.35),
    ([0.0, -0.5, 1.0], 0.3),
];

/// The background of a model alone.
const MODEL_BACKGROUND: [f32; 4] = [0.08, 0.08, 0.1, 1.0];

/// [`ModelView`] for a model with bounds `bounds` (the unit cube's when `None`).
pub fn model_view(bounds: Option<(Vec3, Vec3)>) -> ModelView {
    let (lo, hi) = bounds.unwrap_or((Vec3::splat(-1.0), Vec3::splat(1.0)));
    let centre = (lo + hi) * 0.5;
    let radius = ((hi - lo).length() * 0.5).max(1e-3);
    let fov = 45.0f32;
    let dist = radius / (fov.to_radians() * 0.5).sin() * 1.05;
    let dir = Vec3::new(0.35, 0.45, 1.0).normalize();
    ModelView {
        position: centre + dir * dist,
        target: centre,
        near: (dist - radius * 1.5).max(dist * 0.01),
        far: dist + radius * 1.5,
        fov,
    }
}
