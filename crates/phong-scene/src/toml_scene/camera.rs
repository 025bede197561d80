//! `[camera]`: position, target, up, projection, near and far.

use super::choices::PROJECTIONS;
use super::ctx::{Ctx, S};
use super::raw::RawCamera;
use crate::Error;
use glam::Vec3;
use phong_core::{Camera, Projection};

pub(super) fn camera(ctx: &Ctx, r: RawCamera) -> Result<Camera, Error> {
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
