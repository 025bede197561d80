//! Tessellated primitives with analytic normals (seed 001: "if a surface is
//! given by a formula, then we can generally compute vertex normals based on
//! the formula").
//!
//! | shape | size | parameters |
//! |---|---|---|
//! | sphere | radius 1 at the origin, axis y | `segments` slices around the axis, `segments/2` stacks |
//! | torus | seed 001's parametrisation, axis z: `((R + r cos a1) cos a2, (R + r cos a1) sin a2, r sin a1)` | `radius` R (1), `tube` r (0.25), `segments` around the axis, `segments/2` around the tube |
//! | cylinder | radius 1, y in [−1, 1], with caps | `segments` around the axis |
//! | cone | base radius 1 at y = −1, apex at y = 1, with base cap | `segments` around the axis |
//! | cube | [−1, 1]³ | none |
//! | plane | [−1, 1]² in y = 0, normal +y | `segments` × `segments` quads |
//! | teapot | Newell's Utah teapot, 32 bicubic Bézier patches, as `glutSolidTeapot(1)`: y up, x from −1.5 to 1.7, y from −0.75 to 0.825 | `segments` × `segments` quads per patch, normals from the patch derivatives |

use crate::Mesh;
use crate::mesh::facet_normal;
use core::f32::consts::{PI, TAU};
use glam::{Vec2, Vec3};

/// Builds a `(rows+1) × (cols+1)` vertex grid from `f(u, v) -> (position, normal)`
/// with `u, v` in [0, 1], texture coordinates `uv(u, v)`, and two triangles per quad, each
/// wound counter-clockwise about its vertices' normals; triangles with zero area (at poles)
/// are dropped.
fn grid(rows: u32, cols: u32, f: impl Fn(f32, f32) -> (Vec3, Vec3), uv: impl Fn(f32, f32) -> Vec2, out: &mut Mesh) {
    let mut positions = Vec::with_capacity(((rows + 1) * (cols + 1)) as usize);
    let mut normals = Vec::with_capacity(positions.capacity());
    let mut uvs = Vec::with_capacity(positions.capacity());
    for i in 0..=rows {
        for j in 0..=cols {
            let (u, v) = (j as f32 / cols as f32, i as f32 / rows as f32);
            let (p, n) = f(u, v);
            positions.push(p);
            normals.push(n.normalize_or_zero());
            uvs.push(uv(u, v));
        }
    }
    let idx = |i: u32, j: u32| i * (cols + 1) + j;
    let mut triangles = Vec::with_capacity((rows * cols * 2) as usize);
    for i in 0..rows {
        for j in 0..cols {
            let (a, b, c, d) = (idx(i, j), idx(i, j + 1), idx(i + 1, j + 1), idx(i + 1, j));
            for t in [[a, b, c], [a, c, d]] {
                let [p, q, r] = t.map(|k| positions[k as usize]);
                let fnorm = facet_normal(p, q, r);
                if fnorm == Vec3::ZERO || (q - p).cross(r - p).length() < 1e-12 {
                    continue;
                }
                let avg: Vec3 = t.iter().map(|&k| normals[k as usize]).sum();
                triangles.push(if fnorm.dot(avg) < 0.0 { [t[0], t[2], t[1]] } else { t });
            }
        }
    }
    let part = Mesh::new(positions, normals, triangles)
        .and_then(|m| m.with_uvs(uvs))
        .expect("grid builds a valid mesh");
    out.append(&part);
}

fn segs(segments: u32) -> u32 {
    segments.clamp(3, crate::limits::MAX_SEGMENTS)
}

/// Unit sphere: `p = n = (sin θ cos φ, cos θ, sin θ sin φ)`.
pub fn sphere(segments: u32) -> Mesh {
    let s = segs(segments);
    let mut m = Mesh::default();
    grid(
        (s / 2).max(2),
        s,
        |u, v| {
            let (th, ph) = (v * PI, u * TAU);
            let n = Vec3::new(th.sin() * ph.cos(), th.cos(), th.sin() * ph.sin());
            (n, n)
        },
        |u, v| Vec2::new(u, 1.0 - v),
        &mut m,
    );
    m
}

/// Torus of seed 001 about the z axis: big radius `radius`, small radius `tube`,
/// normal `(cos a1 cos a2, cos a1 sin a2, sin a1)`.
pub fn torus(segments: u32, radius: f32, tube: f32) -> Mesh {
    let s = segs(segments);
    let mut m = Mesh::default();
    grid(
        (s / 2).max(3),
        s,
        |u, v| {
            let (a2, a1) = (u * TAU, v * TAU);
            let ring = radius + tube * a1.cos();
            let p = Vec3::new(ring * a2.cos(), ring * a2.sin(), tube * a1.sin());
            let n = Vec3::new(a1.cos() * a2.cos(), a1.cos() * a2.sin(), a1.sin());
            (p, n)
        },
        Vec2::new,
        &mut m,
    );
    m
}

/// A disc of radius 1 at height `y` facing `±y`.
fn disc(s: u32, y: f32, up: bool, m: &mut Mesh) {
    let n = if up { Vec3::Y } else { -Vec3::Y };
    grid(
        1,
        s,
        |u, v| {
            let ph = u * TAU;
            (Vec3::new(v * ph.cos(), y, v * ph.sin()), n)
        },
        // Seen from outside: x to the right, and −z (top) or +z (bottom) up.
        |u, v| {
            let ph = u * TAU;
            let (x, z) = (v * ph.cos(), v * ph.sin());
            Vec2::new(0.5 + 0.5 * x, if up { 0.5 - 0.5 * z } else { 0.5 + 0.5 * z })
        },
        m,
    );
}

/// Cylinder of radius 1 about the y axis, y in [−1, 1], with caps. Side normal `(cos φ, 0, sin φ)`.
pub fn cylinder(segments: u32) -> Mesh {
    let s = segs(segments);
    let mut m = Mesh::default();
    grid(
        1,
        s,
        |u, v| {
            let ph = u * TAU;
            let n = Vec3::new(ph.cos(), 0.0, ph.sin());
            (Vec3::new(n.x, 1.0 - 2.0 * v, n.z), n)
        },
        |u, v| Vec2::new(u, 1.0 - v),
        &mut m,
    );
    disc(s, 1.0, true, &mut m);
    disc(s, -1.0, false, &mut m);
    m
}

/// Cone with base radius 1 at y = −1 and apex at y = 1, with base cap.
/// Side normal: the gradient of `√(x² + z²) − (1 − y)/2`, `(2 cos φ, 1, 2 sin φ)/√5`.
pub fn cone(segments: u32) -> Mesh {
    let s = segs(segments);
    let mut m = Mesh::default();
    grid(
        s.div_ceil(4).max(1),
        s,
        |u, v| {
            let ph = u * TAU;
            let r = v; // v = 0 at the apex
            let p = Vec3::new(r * ph.cos(), 1.0 - 2.0 * v, r * ph.sin());
            (p, Vec3::new(2.0 * ph.cos(), 1.0, 2.0 * ph.sin()))
        },
        |u, v| Vec2::new(u, 1.0 - v),
        &mut m,
    );
    disc(s, -1.0, false, &mut m);
    m
}

/// Cube [−1, 1]³, 24 vertices with face normals.
pub fn cube() -> Mesh {
    let mut m = Mesh::default();
    for axis in 0..3 {
        for sign in [1.0f32, -1.0] {
            let mut n = Vec3::ZERO;
            n[axis] = sign;
            let (a, b) = ((axis + 1) % 3, (axis + 2) % 3);
            grid(
                1,
                1,
                |u, v| {
                    let mut p = n;
                    p[a] = 2.0 * u - 1.0;
                    p[b] = 2.0 * v - 1.0;
                    (p, n)
                },
                // Not mirrored seen from outside: u runs along −a on the negative faces.
                |u, v| Vec2::new(if sign > 0.0 { u } else { 1.0 - u }, v),
                &mut m,
            );
        }
    }
    m
}

/// Plane [−1, 1]² in y = 0, normal +y, `segments` × `segments` quads.
pub fn plane(segments: u32) -> Mesh {
    let s = segments.clamp(1, crate::limits::MAX_SEGMENTS);
    let mut m = Mesh::default();
    grid(
        s,
        s,
        |u, v| (Vec3::new(2.0 * u - 1.0, 0.0, 2.0 * v - 1.0), Vec3::Y),
        |u, v| Vec2::new(u, 1.0 - v),
        &mut m,
    );
    m
}

/// Newell's teapot as GLUT's `teapot.c` stores it: 10 patches indexing 127
/// control points; rim, body, lid and bottom are reflected in x and y, handle
/// and spout in y only, giving 32 patches. Public-domain data (Newell 1975).
const TEAPOT_PATCHES: [[u8; 16]; 10] = [
    [102, 103, 104, 105, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15],
    [12, 13, 14, 15, 16, 17, 18, 19, 20, 21, 22, 23, 24, 25, 26, 27],
    [24, 25, 26, 27, 29, 30, 31, 32, 33, 34, 35, 36, 37, 38, 39, 40],
    [96, 96, 96, 96, 97, 98, 99, 100, 101, 101, 101, 101, 0, 1, 2, 3],
    [0, 1, 2, 3, 106, 107, 108, 109, 110, 111, 112, 113, 114, 115, 116, 117],
    [
        118, 118, 118, 118, 124, 122, 119, 121, 123, 126, 125, 120, 40, 39, 38, 37,
    ],
    [41, 42, 43, 44, 45, 46, 47, 48, 49, 50, 51, 52, 53, 54, 55, 56],
    [53, 54, 55, 56, 57, 58, 59, 60, 61, 62, 63, 64, 28, 65, 66, 67],
    [68, 69, 70, 71, 72, 73, 74, 75, 76, 77, 78, 79, 80, 81, 82, 83],
    [80, 81, 82, 83, 84, 85, 86, 87, 88, 89, 90, 91, 92, 93, 94, 95],
];

#[rustfmt::skip]
const TEAPOT_POINTS: [[f32; 3]; 127] = [
    [0.2, 0.0, 2.7], [0.2, -0.112, 2.7], [0.112, -0.2, 2.7], [0.0, -0.2, 2.7],
    [1.3375, 0.0, 2.53125], [1.3375, -0.749, 2.53125], [0.749, -1.3375, 2.53125], [0.0, -1.3375, 2.53125],
    [1.4375, 0.0, 2.53125], [1.4375, -0.805, 2.53125], [0.805, -1.4375, 2.53125], [0.0, -1.4375, 2.53125],
    [1.5, 0.0, 2.4], [1.5, -0.84, 2.4], [0.84, -1.5, 2.4], [0.0, -1.5, 2.4],
    [1.75, 0.0, 1.875], [1.75, -0.98, 1.875], [0.98, -1.75, 1.875], [0.0, -1.75, 1.875],
    [2.0, 0.0, 1.35], [2.0, -1.12, 1.35], [1.12, -2.0, 1.35], [0.0, -2.0, 1.35],
    [2.0, 0.0, 0.9], [2.0, -1.12, 0.9], [1.12, -2.0, 0.9], [0.0, -2.0, 0.9],
    [-2.0, 0.0, 0.9], [2.0, 0.0, 0.45], [2.0, -1.12, 0.45], [1.12, -2.0, 0.45],
    [0.0, -2.0, 0.45], [1.5, 0.0, 0.225], [1.5, -0.84, 0.225], [0.84, -1.5, 0.225],
    [0.0, -1.5, 0.225], [1.5, 0.0, 0.15], [1.5, -0.84, 0.15], [0.84, -1.5, 0.15],
    [0.0, -1.5, 0.15], [-1.6, 0.0, 2.025], [-1.6, -0.3, 2.025], [-1.5, -0.3, 2.25],
    [-1.5, 0.0, 2.25], [-2.3, 0.0, 2.025], [-2.3, -0.3, 2.025], [-2.5, -0.3, 2.25],
    [-2.5, 0.0, 2.25], [-2.7, 0.0, 2.025], [-2.7, -0.3, 2.025], [-3.0, -0.3, 2.25],
    [-3.0, 0.0, 2.25], [-2.7, 0.0, 1.8], [-2.7, -0.3, 1.8], [-3.0, -0.3, 1.8],
    [-3.0, 0.0, 1.8], [-2.7, 0.0, 1.575], [-2.7, -0.3, 1.575], [-3.0, -0.3, 1.35],
    [-3.0, 0.0, 1.35], [-2.5, 0.0, 1.125], [-2.5, -0.3, 1.125], [-2.65, -0.3, 0.9375],
    [-2.65, 0.0, 0.9375], [-2.0, -0.3, 0.9], [-1.9, -0.3, 0.6], [-1.9, 0.0, 0.6],
    [1.7, 0.0, 1.425], [1.7, -0.66, 1.425], [1.7, -0.66, 0.6], [1.7, 0.0, 0.6],
    [2.6, 0.0, 1.425], [2.6, -0.66, 1.425], [3.1, -0.66, 0.825], [3.1, 0.0, 0.825],
    [2.3, 0.0, 2.1], [2.3, -0.25, 2.1], [2.4, -0.25, 2.025], [2.4, 0.0, 2.025],
    [2.7, 0.0, 2.4], [2.7, -0.25, 2.4], [3.3, -0.25, 2.4], [3.3, 0.0, 2.4],
    [2.8, 0.0, 2.475], [2.8, -0.25, 2.475], [3.525, -0.25, 2.49375], [3.525, 0.0, 2.49375],
    [2.9, 0.0, 2.475], [2.9, -0.15, 2.475], [3.45, -0.15, 2.5125], [3.45, 0.0, 2.5125],
    [2.8, 0.0, 2.4], [2.8, -0.15, 2.4], [3.2, -0.15, 2.4], [3.2, 0.0, 2.4],
    [0.0, 0.0, 3.15], [0.8, 0.0, 3.15], [0.8, -0.45, 3.15], [0.45, -0.8, 3.15],
    [0.0, -0.8, 3.15], [0.0, 0.0, 2.85], [1.4, 0.0, 2.4], [1.4, -0.784, 2.4],
    [0.784, -1.4, 2.4], [0.0, -1.4, 2.4], [0.4, 0.0, 2.55], [0.4, -0.224, 2.55],
    [0.224, -0.4, 2.55], [0.0, -0.4, 2.55], [1.3, 0.0, 2.55], [1.3, -0.728, 2.55],
    [0.728, -1.3, 2.55], [0.0, -1.3, 2.55], [1.3, 0.0, 2.4], [1.3, -0.728, 2.4],
    [0.728, -1.3, 2.4], [0.0, -1.3, 2.4], [0.0, 0.0, 0.0], [1.425, -0.798, 0.0],
    [1.5, 0.0, 0.075], [1.425, 0.0, 0.0], [0.798, -1.425, 0.0], [0.0, -1.5, 0.075],
    [0.0, -1.425, 0.0], [1.5, -0.84, 0.075], [0.84, -1.5, 0.075],
];

/// Cubic Bernstein basis and its derivative at `t`.
fn bernstein(t: f32) -> ([f32; 4], [f32; 4]) {
    let s = 1.0 - t;
    (
        [s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t],
        [
            -3.0 * s * s,
            3.0 * s * s - 6.0 * t * s,
            6.0 * t * s - 3.0 * t * t,
            3.0 * t * t,
        ],
    )
}

/// `(p(u, v), ∂p/∂u × ∂p/∂v)` of a bicubic patch `cp[row v][col u]`; the
/// normal is zero where a derivative vanishes (a row collapsed to a pole).
fn patch_eval(cp: &[[Vec3; 4]; 4], u: f32, v: f32) -> (Vec3, Vec3) {
    let (bu, du) = bernstein(u);
    let (bv, dv) = bernstein(v);
    let (mut p, mut pu, mut pv) = (Vec3::ZERO, Vec3::ZERO, Vec3::ZERO);
    for j in 0..4 {
        for k in 0..4 {
            p += cp[j][k] * (bv[j] * bu[k]);
            pu += cp[j][k] * (bv[j] * du[k]);
            pv += cp[j][k] * (dv[j] * bu[k]);
        }
    }
    if pu.length() < 1e-4 || pv.length() < 1e-4 {
        return (p, Vec3::ZERO);
    }
    (p, pu.cross(pv))
}

/// The Utah teapot, `segments` × `segments` quads per patch, normals from the
/// patch derivatives `∂p/∂u × ∂p/∂v` (at a degenerate pole, taken a hair
/// inside the patch), which point outwards; placed as `glutSolidTeapot(1)`:
/// `p' = 0.5·(x, z − 1.5, −y)` of Newell's z-up data.
pub fn teapot(segments: u32) -> Mesh {
    let s = segments.clamp(1, crate::limits::MAX_SEGMENTS);
    let to_world = |p: Vec3| 0.5 * Vec3::new(p.x, p.z - 1.5, -p.y);
    let rot = |n: Vec3| Vec3::new(n.x, n.z, -n.y);
    let mut m = Mesh::default();
    for (i, patch) in TEAPOT_PATCHES.iter().enumerate() {
        let copies: &[(f32, f32, bool)] = if i < 6 {
            &[
                (1.0, 1.0, false),
                (1.0, -1.0, true),
                (-1.0, 1.0, true),
                (-1.0, -1.0, false),
            ]
        } else {
            &[(1.0, 1.0, false), (1.0, -1.0, true)]
        };
        for &(sx, sy, reverse) in copies {
            let mut cp = [[Vec3::ZERO; 4]; 4];
            for (j, row) in cp.iter_mut().enumerate() {
                for (k, c) in row.iter_mut().enumerate() {
                    let kk = if reverse { 3 - k } else { k };
                    let [x, y, z] = TEAPOT_POINTS[patch[j * 4 + kk] as usize];
                    *c = Vec3::new(x * sx, y * sy, z);
                }
            }
            grid(
                s,
                s,
                |u, v| {
                    let (p, mut n) = patch_eval(&cp, u, v);
                    if n == Vec3::ZERO {
                        let e = 1e-3;
                        n = patch_eval(&cp, u.clamp(e, 1.0 - e), v.clamp(e, 1.0 - e)).1;
                    }
                    (to_world(p), rot(n))
                },
                Vec2::new,
                &mut m,
            );
        }
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Signed volume of a closed mesh (divergence theorem): Σ p1·(p2 × p3) / 6, positive when
    /// triangles are counter-clockwise seen from outside.
    fn volume(m: &Mesh) -> f32 {
        (0..m.triangles().len())
            .map(|t| {
                let [a, b, c] = m.corners(t);
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    }

    /// Every triangle's facet normal agrees with its vertex normals.
    fn consistent(m: &Mesh) -> f32 {
        let mut worst = 1.0f32;
        for (t, tri) in m.triangles().iter().enumerate() {
            let [a, b, c] = m.corners(t);
            let f = facet_normal(a, b, c);
            for &i in tri {
                worst = worst.min(f.dot(m.normals()[i as usize]));
            }
        }
        worst
    }

    #[test]
    fn sphere_normals_are_positions_and_volume_converges() {
        let m = sphere(128);
        for (p, n) in m.positions().iter().zip(m.normals()) {
            assert!((p.length() - 1.0).abs() < 1e-6);
            assert!((*p - *n).length() < 1e-6);
        }
        // Inscribed polyhedron: volume slightly below 4π/3 = 4.18879.
        let v = volume(&m);
        assert!(v < 4.188_79 && v > 4.17, "{v}");
        assert!(consistent(&m) > 0.99);
    }

    #[test]
    fn torus_matches_seed_001() {
        let (r_big, r_small) = (1.0, 0.25);
        let m = torus(64, r_big, r_small);
        for (p, n) in m.positions().iter().zip(m.normals()) {
            // The normal points from the tube's centre circle to the point, at distance r.
            let centre = Vec3::new(p.x, p.y, 0.0).normalize() * r_big;
            assert!(((*p - centre).length() - r_small).abs() < 1e-5);
            assert!(((*p - centre) / r_small - *n).length() < 1e-4);
        }
        // Volume 2π²Rr² = 1.2337.
        let v = volume(&m);
        assert!((v - 2.0 * PI * PI * r_big * r_small * r_small).abs() < 0.01, "{v}");
        assert!(consistent(&m) > 0.95);
    }

    #[test]
    fn closed_primitives_have_outward_triangles() {
        // Cylinder 2π, cone 2π/3, cube 8.
        let cases = [
            (cylinder(256), 2.0 * PI, 1e-3),
            (cone(256), 2.0 * PI / 3.0, 1e-3),
            (cube(), 8.0, 1e-6),
        ];
        for (m, expect, tol) in cases {
            let v = volume(&m);
            assert!((v - expect).abs() < expect * tol + 1e-4, "{v} vs {expect}");
            assert!(consistent(&m) > 0.7, "{}", consistent(&m));
        }
    }

    #[test]
    fn cone_normal_is_perpendicular_to_slant() {
        let m = cone(16);
        let (p, n) = (m.positions()[40], m.normals()[40]);
        // Along the slant from apex (0,1,0) to the base point, the normal is perpendicular.
        let slant = p - Vec3::Y;
        if slant.length() > 1e-3 && n.y > 0.0 {
            assert!(slant.dot(n).abs() < 1e-5);
        }
        assert!((n.length() - 1.0).abs() < 1e-6);
    }

    #[test]
    fn teapot_is_outward_and_glut_sized() {
        let m = teapot(8);
        assert!(m.triangles().len() >= 32 * 8 * 8 * 2 - 4 * 8 * 4);
        let (lo, hi) = m.bounds().unwrap();
        // glutSolidTeapot(1): x from the handle (−3·0.5 = −1.5) to the spout tip (3.525·0.5 = 1.7625);
        // y from (0 − 1.5)·0.5 = −0.75 to (3.15 − 1.5)·0.5 = 0.825.
        assert!((lo.x + 1.5).abs() < 0.01 && (hi.x - 1.7).abs() < 0.07, "{lo} {hi}");
        assert!((lo.y + 0.75).abs() < 1e-5 && (hi.y - 0.825).abs() < 1e-5, "{lo} {hi}");
        // Normals point outwards: at the body's widest ring (radius 1, y = 0.9·0.5 − 0.75 = −0.3),
        // the normal points away from the axis (the handle's end at (−1, −0.3, 0) excepted).
        let mut checked = 0;
        for (p, n) in m.positions().iter().zip(m.normals()) {
            let radial = Vec3::new(p.x, 0.0, p.z);
            let on_handle = p.x < 0.0 && p.z.abs() < 0.2;
            if (radial.length() - 1.0).abs() < 1e-4 && (p.y + 0.3).abs() < 1e-4 && !on_handle {
                assert!(n.dot(radial) > 0.9, "{p} {n}");
                checked += 1;
            }
        }
        assert!(checked >= 4);
        // The top of the lid knob (0, 0.825, 0) faces up; the bottom centre faces down.
        for (p, n) in m.positions().iter().zip(m.normals()) {
            if p.x.abs() < 1e-6 && p.z.abs() < 1e-6 {
                if (p.y - 0.825).abs() < 1e-5 {
                    assert!(n.y > 0.99, "{n}");
                } else if (p.y + 0.75).abs() < 1e-5 {
                    assert!(n.y < -0.99, "{n}");
                }
            }
        }
        assert!(consistent(&m) > -0.5);
    }
}
