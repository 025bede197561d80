//! A model file's part, what every format's reader returns, and what every reader uses to
//! build one (its name, errors, re-centring, the vertex-colour material).

use crate::Error;
use glam::{DVec3, Vec3};
use phong_core::{Maps, Material, Mesh};
use std::path::Path;

/// One part of a model file, with one material: an OBJ group, a PLY file, an STL solid, a glTF
/// primitive.
#[derive(Debug, Clone)]
pub struct ModelPart {
    /// `file:group` (or the format's own name for the part).
    pub name: String,
    /// Object-space geometry (normals from the file, or zero when it has none).
    pub mesh: Mesh,
    /// Its material from the file, if any.
    pub material: Option<Material>,
    /// Its material's texture maps (none where it has none, or none could be read).
    pub maps: Maps,
    /// True when the file gave normals for every vertex of this part.
    pub has_normals: bool,
    /// Without normals of its own, the part's format asks for flat normals (glTF: "client
    /// implementations MUST calculate flat normals"); else they are computed by angle.
    pub flat_without_normals: bool,
    /// The point the positions are relative to, in the file's coordinates: a model far from
    /// the origin for its size is re-centred in f64 before its positions become f32 (so that
    /// it keeps its detail); zero otherwise. Every part of a model has the same.
    pub origin: DVec3,
    /// The mesh as the model-alone scene draws it (fitted to the model's bounding sphere, its
    /// normals by the default rule), where `phong render MODEL` computed it beside the framing;
    /// `None` from the readers. The scene reader uses it for an object with `fit` and no
    /// `normals` or `crease` of its own, and computes the same otherwise.
    pub drawn: Option<Mesh>,
    /// Its positions in the model's fitted frame (centred on the bounding sphere of the whole
    /// model, radius 1), where `phong render MODEL` computed them for its framing; `None` from
    /// the readers. The scene reader takes them for an object with `fit` instead of computing
    /// the same again.
    pub fitted: Option<Vec<glam::Vec3>>,
}

/// The name of a model's one part: its file name.
pub(crate) fn part_name(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default()
}

pub(crate) fn model_error(path: &Path, message: String) -> Error {
    Error::Model {
        path: path.to_path_buf(),
        message,
    }
}

/// The material of a part whose vertex colours stand for its ambient and diffuse colours
/// (OpenGL's `GL_COLOR_MATERIAL` with `GL_AMBIENT_AND_DIFFUSE`): ambient and diffuse white
/// (the colour multiplies them), the rest OpenGL's default.
pub(crate) fn vertex_color_material() -> phong_core::Material {
    let white = phong_core::Color::WHITE;
    phong_core::Material::new(white, white, phong_core::Color::BLACK, phong_core::Color::BLACK, 0.0)
        .expect("valid colours")
}

/// Where a model with vertices `points` is re-centred: the centre of its bounding box where
/// that lies far from the origin for its size (more than 4 times its largest side: f32 would
/// lose its detail there), else the origin (a model near the origin keeps its coordinates
/// exactly).
pub(crate) fn far_origin(points: impl IntoIterator<Item = DVec3>) -> DVec3 {
    let (lo, hi) = points.into_iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(p), hi.max(p)),
    );
    if lo.x.partial_cmp(&hi.x).is_none_or(|o| o.is_gt()) {
        return DVec3::ZERO;
    }
    let (centre, extent) = ((lo + hi) * 0.5, (hi - lo).max_element());
    if centre.abs().max_element() > extent.max(f64::MIN_POSITIVE) * 4.0 {
        centre
    } else {
        DVec3::ZERO
    }
}

/// `points` as f32 positions relative to their [`far_origin`], and that origin.
pub(crate) fn recentred(points: &[DVec3]) -> (Vec<Vec3>, DVec3) {
    let origin = far_origin(points.iter().copied());
    (points.iter().map(|p| (*p - origin).as_vec3()).collect(), origin)
}
