//! A model file's part, what every format's reader returns, and what every reader uses to
//! build one (its name, errors, re-centring, the vertex-colour material).

use crate::Error;
use glam::{DVec3, Vec3};
use phong_core::{Maps, Material, Mesh};
use std::path::Path;
use std::sync::Arc;

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
    /// The point the positions are relative to, in the file's coordinates: a model far from
    /// the origin for its size is re-centred in f64 before its positions become f32 (so that
    /// it keeps its detail); zero otherwise. Every part of a model has the same.
    pub origin: DVec3,
    /// Its mesh fitted and with normals by crease angle, made ahead of the scene reader
    /// ([`crate::scene_of_model`]), which takes it where its fit and crease are the ones asked.
    pub(crate) prepared: Option<Arc<Prepared>>,
}

/// A part's mesh in a fitted frame with normals by crease angle ([`ModelPart::prepared`]).
#[derive(Debug)]
pub(crate) struct Prepared {
    /// The fitted frame: centre and radius.
    pub fit: Option<(DVec3, f64)>,
    /// The crease angle, degrees.
    pub crease: f32,
    pub mesh: Mesh,
}

impl ModelPart {
    /// A part of `mesh`, named `name`, with the file's material and maps where it has them;
    /// `has_normals` where `mesh`'s normals are the file's, `origin` where the positions are
    /// re-centred (see the fields).
    pub fn new(
        name: String,
        mesh: Mesh,
        material: Option<Material>,
        maps: Maps,
        has_normals: bool,
        origin: DVec3,
    ) -> ModelPart {
        ModelPart {
            name,
            mesh,
            material,
            maps,
            has_normals,
            origin,
            prepared: None,
        }
    }

    /// Whether the file's normals are drawn as they are (given for every vertex, none zero).
    pub(crate) fn normals_usable(&self) -> bool {
        self.has_normals && self.mesh.normals().iter().all(|n| *n != Vec3::ZERO)
    }

    /// Its mesh [`fitted`] (where `fit` is given) with normals by crease angle, as the scene
    /// reader makes a mesh object's; `None` where the fit fails (the reader then says why).
    pub(crate) fn prepare(&self, fit: Option<(DVec3, f64)>, crease: f32) -> Option<Prepared> {
        let mesh = match fit {
            Some(f) => fitted(self.mesh.clone(), f, &self.name)
                .ok()?
                .with_crease_normals(crease),
            None => self.mesh.with_crease_normals(crease),
        };
        Some(Prepared { fit, crease, mesh })
    }
}

/// `mesh` (of the part `name`) moved into the frame of centre and radius `fit`, in f64
/// (coordinates near f32's largest, a radius whose inverse is below its smallest normal
/// number). A uniform scale and a move: the file's normals keep their directions.
pub(crate) fn fitted(mesh: Mesh, (centre, radius): (DVec3, f64), name: &str) -> Result<Mesh, String> {
    let positions = mesh
        .positions()
        .iter()
        .map(|x| ((x.as_dvec3() - centre) / radius).as_vec3())
        .collect();
    mesh.with_positions(positions).map_err(|e| format!("{name}: {e}"))
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
