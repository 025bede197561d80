//! What becomes of a scene's triangles, counted per object for `-v`: outside the view,
//! culled (back faces of one-sided objects, and triangles of no area), clipped (crossing the
//! near or far plane or the guard band, so cut before they are drawn), and the rest drawn as
//! they are. The same outcodes and facing rule as the setup; a triangle whose snapped area is
//! zero only on the 1/256-pixel grid is counted here by its unsnapped area.

use crate::clip::{NOT_FINITE, OUTSIDE_CLIP, OUTSIDE_VIEW, outcode};
use phong_core::Scene;

/// One object's triangles by fate.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Census {
    /// The object's name.
    pub name: String,
    /// Its triangles.
    pub triangles: usize,
    /// Outside the view volume (or not finite).
    pub outside: usize,
    /// Back faces of a one-sided object, and triangles of no area on screen.
    pub culled: usize,
    /// Crossing a clipping plane: cut, then drawn.
    pub clipped: usize,
    /// Inside every plane and facing the camera (or two-sided): drawn as they are.
    pub inside: usize,
}

/// [`Census`] of every object of `scene`, for an image of its size.
pub fn census(scene: &Scene) -> Vec<Census> {
    let aspect = scene.image.width as f32 / scene.image.height as f32;
    let clip_from_world = scene.camera.clip_from_world(aspect);
    scene
        .objects
        .iter()
        .map(|o| {
            let mut c = Census {
                name: o.name.clone(),
                triangles: o.mesh.triangles().len(),
                ..Census::default()
            };
            let clip: Vec<glam::Vec4> = o
                .mesh
                .positions()
                .iter()
                .map(|p| clip_from_world * p.extend(1.0))
                .collect();
            let codes: Vec<u16> = clip.iter().map(|v| outcode(*v)).collect();
            for t in o.mesh.triangles() {
                let [a, b, d] = t.map(|i| i as usize);
                let (ca, cb, cd) = (codes[a], codes[b], codes[d]);
                if ca & cb & cd & OUTSIDE_VIEW != 0 || (ca | cb | cd) & NOT_FINITE != 0 {
                    c.outside += 1;
                } else if (ca | cb | cd) & OUTSIDE_CLIP != 0 {
                    c.clipped += 1;
                } else {
                    let [pa, pb, pd] = [a, b, d].map(|i| clip[i].truncate() / clip[i].w);
                    // Counter-clockwise in NDC is front-facing (OpenGL's rule, as the setup's).
                    let area = (pb.x - pa.x) * (pd.y - pa.y) - (pd.x - pa.x) * (pb.y - pa.y);
                    if area == 0.0 || (area < 0.0 && !o.shading.options.two_sided) {
                        c.culled += 1;
                    } else {
                        c.inside += 1;
                    }
                }
            }
            c
        })
        .collect()
}
