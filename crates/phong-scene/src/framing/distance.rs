//! The model view's camera distance and depth range, from the model's points in the fitted
//! frame (centred, radius 1), four points at a time.

use super::{FILL, FOV};
use glam::{Vec3, Vec4};

/// The camera distance along `dir` (from the origin of the fitted frame) at which every vertex
/// is inside [`FILL`] of a frame of aspect `aspect`, the camera's up `up`.
pub(super) fn framing_distance(points: &[Vec3], dir: Vec3, up: Vec3, aspect: f32) -> f32 {
    let right = up.cross(dir).normalize();
    let up = dir.cross(right);
    let ty = (FOV.to_radians() * 0.5).tan() * FILL;
    let tx = ty * aspect;
    let distance = |z: f32, r: f32, u: f32| (z + r.abs() / tx).max(z + u.abs() / ty);
    // Four points at a time, each as the scalar form computes it; the largest is the same
    // whatever the order (every value is finite: the points are within the unit sphere).
    let mut blocks = points.chunks_exact(4);
    let (tx4, ty4) = (Vec4::splat(tx), Vec4::splat(ty));
    let mut far = Vec4::ZERO;
    for b in &mut blocks {
        let q = lanes(b);
        let z = dot4(q, dir);
        far = (z + dot4(q, right).abs() / tx4).max(far);
        far = (z + dot4(q, up).abs() / ty4).max(far);
    }
    let mut dist = far.max_element();
    for &q in blocks.remainder() {
        dist = dist.max(distance(q.dot(dir), q.dot(right), q.dot(up)));
    }
    // Never inside the bounding sphere.
    dist.max(1.05)
}

/// Four points' coordinates, x, y and z each in a vector of lanes.
#[inline(always)]
fn lanes(b: &[Vec3]) -> [Vec4; 3] {
    [
        Vec4::new(b[0].x, b[1].x, b[2].x, b[3].x),
        Vec4::new(b[0].y, b[1].y, b[2].y, b[3].y),
        Vec4::new(b[0].z, b[1].z, b[2].z, b[3].z),
    ]
}

/// `Vec3::dot` of each lane's point with `v`, summed as it sums: `(x·v.x + y·v.y) + z·v.z`.
#[inline(always)]
fn dot4([x, y, z]: [Vec4; 3], v: Vec3) -> Vec4 {
    (x * v.x + y * v.y) + z * v.z
}

/// Near and far planes for a camera at `eye` looking at `target`: just outside the vertices'
/// depths (a camera inside the model gets a near plane of 1/1000 of the model's radius).
pub(super) fn depth_range(points: &[Vec3], eye: Vec3, target: Vec3) -> (f32, f32) {
    let d = (target - eye).normalize_or(Vec3::NEG_Z);
    // Four points at a time, as `framing_distance`.
    let mut blocks = points.chunks_exact(4);
    let (mut lo4, mut hi4) = (Vec4::INFINITY, Vec4::NEG_INFINITY);
    let e = [Vec4::splat(eye.x), Vec4::splat(eye.y), Vec4::splat(eye.z)];
    for b in &mut blocks {
        let [x, y, z] = lanes(b);
        let z = dot4([x - e[0], y - e[1], z - e[2]], d);
        lo4 = z.min(lo4);
        hi4 = z.max(hi4);
    }
    let (mut lo, mut hi) = (lo4.min_element(), hi4.max_element());
    for &q in blocks.remainder() {
        let z = (q - eye).dot(d);
        lo = lo.min(z);
        hi = hi.max(z);
    }
    let near = (lo * 0.95).max(1e-3);
    let far = (hi * 1.05).max(near * 2.0);
    (((near * 1e6).floor() / 1e6).max(1e-3), (far * 1e6).ceil() / 1e6)
}

#[cfg(test)]
mod tests {
    use super::*;

    proptest::proptest! {
        /// The framing distance and depth range four points at a time are the scalar loops'
        /// results, bit for bit, for any number of points in the unit ball.
        #[test]
        fn lanes_frame_as_the_scalar_loops(
            pts in proptest::collection::vec((-0.6f32..0.6, -0.6f32..0.6, -0.6f32..0.6), 0..23),
            dir in (-1.0f32..1.0, -1.0f32..1.0, 0.2f32..1.0),
            aspect in 0.3f32..3.0,
        ) {
            let points: Vec<Vec3> = pts.iter().map(|&(x, y, z)| Vec3::new(x, y, z)).collect();
            let dir = Vec3::new(dir.0, dir.1, dir.2).normalize();
            let up = Vec3::Y;
            // The loops as they were, one point at a time.
            let right = up.cross(dir).normalize();
            let u = dir.cross(right);
            let ty = (FOV.to_radians() * 0.5).tan() * FILL;
            let tx = ty * aspect;
            let mut dist = 0.0f32;
            for &q in &points {
                let z = q.dot(dir);
                dist = dist.max(z + q.dot(right).abs() / tx).max(z + q.dot(u).abs() / ty);
            }
            let got = framing_distance(&points, dir, up, aspect);
            proptest::prop_assert_eq!(got.to_bits(), dist.max(1.05).to_bits());
            let eye = dir * got;
            let d = (Vec3::ZERO - eye).normalize_or(Vec3::NEG_Z);
            let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
            for &q in &points {
                let z = (q - eye).dot(d);
                lo = lo.min(z);
                hi = hi.max(z);
            }
            let near = (lo * 0.95).max(1e-3);
            let far = (hi * 1.05).max(near * 2.0);
            let want = (((near * 1e6).floor() / 1e6).max(1e-3), (far * 1e6).ceil() / 1e6);
            let (n, f) = depth_range(&points, eye, Vec3::ZERO);
            proptest::prop_assert_eq!((n.to_bits(), f.to_bits()), (want.0.to_bits(), want.1.to_bits()));
        }
    }
}
