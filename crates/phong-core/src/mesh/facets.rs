//! Triangles' facet normals, and a mesh's normals taken through a matrix, four at a time:
//! each component of four in one glam `Vec4` (a vector register). Every lane does glam's
//! operations in glam's order (`(b − a) × (c − a)`, `normalize_or_zero`, `Mat3 * Vec3`), each
//! correctly rounded, so the results are the same bits as the scalar forms (the tests compare
//! them). (A point moved by a `Mat4` is already one vector operation a column in glam: in
//! lanes, gathering and storing cost more than they save.)

use glam::{Mat3, Vec3, Vec4};

/// Triangles a block holds.
const LANES: usize = 4;

/// Per triangle of `tris` (indices into `positions`, checked by the caller's mesh), its unit
/// facet normal (zero for a degenerate facet) taken through `m` (a normal matrix) and
/// normalised again, in blocks of [`LANES`] triangles (the last block padded with its first
/// triangle): a third fewer instructions than glam's `Vec3A` one triangle at a time (BENCHMARKS.md,
/// "Loading against trimesh", `e6e3988`).
pub(super) fn unit_normals_through(positions: &[Vec3], tris: &[[u32; 3]], m: &Mat3, out: &mut [Vec3]) {
    let splat = |c: Vec3| [Vec4::splat(c.x), Vec4::splat(c.y), Vec4::splat(c.z)];
    let m = [splat(m.x_axis), splat(m.y_axis), splat(m.z_axis)];
    for (block, out) in tris.chunks(LANES).zip(out.chunks_mut(LANES)) {
        let u = normalized(&crossed(positions, block));
        store(&normalized(&through(&m, &u)), out);
    }
}

/// Each of `normals` taken through `m` (a normal matrix) and normalised, as
/// `(m * n).normalize_or_zero()` gives it, in blocks of [`LANES`].
pub(super) fn normals_through(normals: &mut [Vec3], m: &Mat3) {
    let splat = |c: Vec3| [Vec4::splat(c.x), Vec4::splat(c.y), Vec4::splat(c.z)];
    let m = [splat(m.x_axis), splat(m.y_axis), splat(m.z_axis)];
    for block in normals.chunks_mut(LANES) {
        let v = normalized(&through(&m, &gathered(block)));
        store(&v, block);
    }
}

/// A block of at most [`LANES`] vectors as x, y and z lanes (the last block padded with its
/// first vector).
#[inline(always)]
fn gathered(block: &[Vec3]) -> [Vec4; 3] {
    let v = |l: usize| *block.get(l).unwrap_or(&block[0]);
    let (a, b, c, d) = (v(0), v(1), v(2), v(3));
    [
        Vec4::new(a.x, b.x, c.x, d.x),
        Vec4::new(a.y, b.y, c.y, d.y),
        Vec4::new(a.z, b.z, c.z, d.z),
    ]
}

/// The facets `(b − a) × (c − a)` of a block of at most [`LANES`] triangles, x, y and z.
#[inline(always)]
fn crossed(positions: &[Vec3], block: &[[u32; 3]]) -> [Vec4; 3] {
    let corners = |l: usize| {
        let t = block.get(l).unwrap_or(&block[0]);
        let p = |k: usize| positions[t[k] as usize];
        (p(0), p(1), p(2))
    };
    let (a0, b0, c0) = corners(0);
    let (a1, b1, c1) = corners(1);
    let (a2, b2, c2) = corners(2);
    let (a3, b3, c3) = corners(3);
    let ax = Vec4::new(a0.x, a1.x, a2.x, a3.x);
    let ay = Vec4::new(a0.y, a1.y, a2.y, a3.y);
    let az = Vec4::new(a0.z, a1.z, a2.z, a3.z);
    let ux = Vec4::new(b0.x, b1.x, b2.x, b3.x) - ax;
    let uy = Vec4::new(b0.y, b1.y, b2.y, b3.y) - ay;
    let uz = Vec4::new(b0.z, b1.z, b2.z, b3.z) - az;
    let vx = Vec4::new(c0.x, c1.x, c2.x, c3.x) - ax;
    let vy = Vec4::new(c0.y, c1.y, c2.y, c3.y) - ay;
    let vz = Vec4::new(c0.z, c1.z, c2.z, c3.z) - az;
    // glam's cross: x = u.y·v.z − u.z·v.y, and so on round (products commute exactly).
    [uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx]
}

/// glam's `normalize_or_zero` in each lane: `1 / √((x² + y²) + z²)` times each component
/// where that is finite and positive, else zero.
#[inline(always)]
fn normalized(v: &[Vec4; 3]) -> [Vec4; 3] {
    let d = (v[0] * v[0] + v[1] * v[1]) + v[2] * v[2];
    let rcp = Vec4::ONE / sqrt(d);
    // Finite and positive: a NaN fails both tests.
    let ok = rcp.cmpgt(Vec4::ZERO) & rcp.cmplt(Vec4::INFINITY);
    [
        Vec4::select(ok, v[0] * rcp, Vec4::ZERO),
        Vec4::select(ok, v[1] * rcp, Vec4::ZERO),
        Vec4::select(ok, v[2] * rcp, Vec4::ZERO),
    ]
}

/// Each lane's square root, correctly rounded as `f32::sqrt`: four scalar square roots (the
/// vector intrinsic needs `unsafe`, which phong-core forbids).
#[inline(always)]
fn sqrt(v: Vec4) -> Vec4 {
    Vec4::new(v.x.sqrt(), v.y.sqrt(), v.z.sqrt(), v.w.sqrt())
}

/// `m * v` in each lane (`m`'s columns, each element splat), as glam sums it:
/// `(x_axis·v.x + y_axis·v.y) + z_axis·v.z`.
#[inline(always)]
fn through(m: &[[Vec4; 3]; 3], v: &[Vec4; 3]) -> [Vec4; 3] {
    let row = |k: usize| (m[0][k] * v[0] + m[1][k] * v[1]) + m[2][k] * v[2];
    [row(0), row(1), row(2)]
}

/// The first `out.len()` lanes of `v` as vectors.
#[inline(always)]
fn store(v: &[Vec4; 3], out: &mut [Vec3]) {
    let (x, y, z) = (v[0].to_array(), v[1].to_array(), v[2].to_array());
    for (l, o) in out.iter_mut().enumerate() {
        *o = Vec3::new(x[l], y[l], z[l]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Mat3A, Mat4, Quat, Vec3A};
    use proptest::prelude::*;

    fn coord() -> impl Strategy<Value = f32> {
        prop_oneof![
            -1e3f32..1e3,
            -1e-3f32..1e-3,
            Just(0.0),
            Just(1.0),
            Just(-0.0),
            Just(f32::MAX),
            Just(1e-30),
        ]
    }

    fn matrix() -> impl Strategy<Value = Mat4> {
        (
            prop_oneof![
                Just(Vec3::ONE),
                Just(Vec3::new(2.0, -0.5, 3.0)),
                Just(Vec3::splat(1e-20)),
                Just(Vec3::new(1.0, 1.0, 0.0))
            ],
            -3.0f32..3.0,
            -3.0f32..3.0,
            (coord(), coord(), coord()),
        )
            .prop_map(|(scale, a, b, (x, y, z))| {
                let turn = Quat::from_rotation_y(a) * Quat::from_rotation_x(b);
                Mat4::from_scale_rotation_translation(scale, turn, Vec3::new(x, y, z))
            })
    }

    proptest! {
        /// Normals taken through a normal matrix four at a time are glam's scalar
        /// `(nm * n).normalize_or_zero()` bit for bit (mirrors, a flattening scale, overflow,
        /// zero, ±0, blocks full and partial).
        #[test]
        fn turned_lanes_are_the_scalar_forms_bits(
            pts in prop::collection::vec((coord(), coord(), coord()), 1..23),
            m in matrix(),
        ) {
            let points: Vec<Vec3> = pts.iter().map(|&(x, y, z)| Vec3::new(x, y, z)).collect();
            let nm = Mat3::from_mat4(m).inverse().transpose();
            let mut turned = points.clone();
            normals_through(&mut turned, &nm);
            let bits = |v: Vec3| v.to_array().map(f32::to_bits);
            for (i, &p) in points.iter().enumerate() {
                prop_assert_eq!(bits(turned[i]), bits((nm * p).normalize_or_zero()));
            }
        }

        /// Bit for bit what the scalar forms give (glam's `Vec3A`, as the callers computed
        /// one triangle at a time), for blocks full and partial, degenerate and overflowing
        /// facets included.
        #[test]
        fn lanes_are_the_scalar_forms_bits(
            pts in prop::collection::vec((coord(), coord(), coord()), 3..40),
            picks in prop::collection::vec((0usize..1000, 0usize..1000, 0usize..1000), 1..30),
            scale in prop_oneof![Just(Vec3::ONE), Just(Vec3::new(2.0, -0.5, 3.0))],
            angle in -3.0f32..3.0,
        ) {
            let positions: Vec<Vec3> = pts.iter().map(|&(x, y, z)| Vec3::new(x, y, z)).collect();
            let n = positions.len();
            let tris: Vec<[u32; 3]> =
                picks.iter().map(|&(a, b, c)| [a % n, b % n, c % n].map(|i| i as u32)).collect();
            let m = Mat4::from_scale_rotation_translation(scale, Quat::from_rotation_y(angle), Vec3::X);
            let nm = Mat3::from_mat4(m).inverse().transpose();
            let mut through = vec![Vec3::NAN; tris.len()];
            unit_normals_through(&positions, &tris, &nm, &mut through);
            let bits = |v: Vec3| v.to_array().map(f32::to_bits);
            for (i, t) in tris.iter().enumerate() {
                let [a, b, c] = t.map(|i| Vec3A::from(positions[i as usize]));
                let f = (b - a).cross(c - a);
                let n = (Mat3A::from(nm) * f.normalize_or_zero()).normalize_or_zero();
                prop_assert_eq!(bits(through[i]), bits(n.into()));
            }
        }
    }
}
