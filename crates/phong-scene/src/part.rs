//! A model file's part: what every format's reader returns.

use glam::DVec3;
use phong_core::{Maps, Material, Mesh};

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
}
