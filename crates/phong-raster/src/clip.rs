//! Clipping in homogeneous clip space (OpenGL's volume `−w <= x, y, z <= w`).
//!
//! Triangles are clipped against the near and far planes, which the
//! projection needs (no division by `w <= 0`), and against a guard band
//! `|x|, |y| <= G·w` instead of the viewport: triangles that only cross the
//! viewport's sides, the common case, are not clipped at all, and the pixel
//! coordinates of what is left stay within `G` half-viewports of the centre.

use glam::{Vec2, Vec3, Vec4};
use phong_core::limits::GUARD_BAND;

/// A vertex in clip space with the attributes the rasteriser interpolates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClipVertex {
    /// Clip-space position.
    pub clip: Vec4,
    /// World-space position.
    pub world: Vec3,
    /// World-space normal (not renormalised).
    pub normal: Vec3,
    /// Colour lit at the vertex (Gouraud; a textured object's primary colour), else unused.
    pub color: Vec3,
    /// Gouraud with two-sided lighting: the colour lit with the flipped normal, for back faces.
    pub color_back: Vec3,
    /// A textured object's specular colour lit at the vertex (Gouraud), front and back.
    pub spec: [Vec3; 2],
    /// Texture coordinates.
    pub uv: Vec2,
    /// The second set of texture coordinates (zero where the mesh has none).
    pub uv1: Vec2,
    /// The vertex colour (white where the mesh has none).
    pub rgb: Vec3,
    /// The tangent (`w`: the bitangent's sign; zero where the mesh has none).
    pub tangent: Vec4,
}

impl ClipVertex {
    /// `a + t·(b − a)` for every attribute (linear in clip space, which is
    /// what perspective-correct interpolation needs).
    #[inline]
    pub fn lerp(&self, b: &ClipVertex, t: f32) -> ClipVertex {
        ClipVertex {
            clip: self.clip.lerp(b.clip, t),
            world: self.world.lerp(b.world, t),
            normal: self.normal.lerp(b.normal, t),
            color: self.color.lerp(b.color, t),
            color_back: self.color_back.lerp(b.color_back, t),
            spec: [0, 1].map(|k| self.spec[k].lerp(b.spec[k], t)),
            uv: self.uv.lerp(b.uv, t),
            uv1: self.uv1.lerp(b.uv1, t),
            rgb: self.rgb.lerp(b.rgb, t),
            tangent: self.tangent.lerp(b.tangent, t),
        }
    }
}

/// The planes clipped against, as `d(v) = dot(plane, v) >= 0` inside.
const CLIP_PLANES: [Vec4; 6] = [
    Vec4::new(0.0, 0.0, 1.0, 1.0),         // near: z + w >= 0
    Vec4::new(0.0, 0.0, -1.0, 1.0),        // far: w − z >= 0
    Vec4::new(1.0, 0.0, 0.0, GUARD_BAND),  // G·w + x >= 0
    Vec4::new(-1.0, 0.0, 0.0, GUARD_BAND), // G·w − x >= 0
    Vec4::new(0.0, 1.0, 0.0, GUARD_BAND),  // G·w + y >= 0
    Vec4::new(0.0, -1.0, 0.0, GUARD_BAND), // G·w − y >= 0
];

/// The view volume's planes, for trivial rejection.
const VIEW_PLANES: [Vec4; 6] = [
    Vec4::new(0.0, 0.0, 1.0, 1.0),
    Vec4::new(0.0, 0.0, -1.0, 1.0),
    Vec4::new(1.0, 0.0, 0.0, 1.0),
    Vec4::new(-1.0, 0.0, 0.0, 1.0),
    Vec4::new(0.0, 1.0, 0.0, 1.0),
    Vec4::new(0.0, -1.0, 0.0, 1.0),
];

/// What to do with a triangle.
#[derive(Debug, PartialEq)]
pub enum Clipped {
    /// Entirely outside the view volume (or not finite).
    Rejected,
    /// Inside every clipping plane: draw as is.
    Inside,
    /// Clipped: draw this convex polygon (as a fan), 3 to 9 vertices.
    Polygon(Vec<ClipVertex>),
}

/// Outcode bits of [`outcode`]: outside a view-volume plane (bits 0–5), outside a clipping
/// plane (bits 6–11), not finite (bit 12).
pub const OUTSIDE_VIEW: u16 = 0x3f;
/// See [`OUTSIDE_VIEW`].
pub const OUTSIDE_CLIP: u16 = 0xfc0;
/// See [`OUTSIDE_VIEW`].
pub const NOT_FINITE: u16 = 0x1000;

/// Which planes clip-space point `c` is outside of (the same tests as [`clip_triangle`]), so
/// that a triangle's trivial cases are decided from its vertices' codes: all sharing an
/// [`OUTSIDE_VIEW`] bit is [`Clipped::Rejected`], none with [`OUTSIDE_CLIP`] or [`NOT_FINITE`]
/// bits is [`Clipped::Inside`]; anything else goes to [`clip_triangle`].
#[inline]
pub fn outcode(c: Vec4) -> u16 {
    // The planes' dot products written out: each has two non-zero terms, so `a + b` here is
    // the dot product's value exactly (the zero terms add nothing; `G·w` is exact for the
    // power-of-two guard band) wherever `c` is finite; where it is not, the triangle is
    // rejected either way. Ten sums instead of ten 4-wide dot products; the test below checks
    // the decisions against `clip_triangle`.
    const _: () = assert!(GUARD_BAND == 4.0);
    let (x, y, z, w) = (c.x, c.y, c.z, c.w);
    let g = GUARD_BAND * w;
    let outside = [
        z + w,
        w - z,
        x + w,
        w - x,
        y + w,
        w - y,
        z + w,
        w - z,
        x + g,
        g - x,
        y + g,
        g - y,
    ];
    let mut code = if c.is_finite() { 0 } else { NOT_FINITE };
    for (i, d) in outside.iter().enumerate() {
        code |= u16::from(*d < 0.0) << i;
    }
    code
}

/// Clips triangle `t`.
pub fn clip_triangle(t: &[ClipVertex; 3]) -> Clipped {
    if !t.iter().all(|v| v.clip.is_finite()) {
        return Clipped::Rejected;
    }
    if VIEW_PLANES.iter().any(|p| t.iter().all(|v| p.dot(v.clip) < 0.0)) {
        return Clipped::Rejected;
    }
    if CLIP_PLANES.iter().all(|p| t.iter().all(|v| p.dot(v.clip) >= 0.0)) {
        return Clipped::Inside;
    }
    let mut poly: Vec<ClipVertex> = t.to_vec();
    let mut next = Vec::with_capacity(9);
    for p in &CLIP_PLANES {
        next.clear();
        for i in 0..poly.len() {
            let (a, b) = (&poly[i], &poly[(i + 1) % poly.len()]);
            let (da, db) = (p.dot(a.clip), p.dot(b.clip));
            if da >= 0.0 {
                next.push(*a);
            }
            if (da >= 0.0) != (db >= 0.0) {
                next.push(a.lerp(b, da / (da - db)));
            }
        }
        std::mem::swap(&mut poly, &mut next);
        if poly.len() < 3 {
            return Clipped::Rejected;
        }
    }
    Clipped::Polygon(poly)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f32, y: f32, z: f32, w: f32) -> ClipVertex {
        ClipVertex {
            clip: Vec4::new(x, y, z, w),
            world: Vec3::new(x, y, z),
            normal: Vec3::Z,
            color: Vec3::new(w, 0.0, 0.0),
            color_back: Vec3::ZERO,
            spec: [Vec3::ZERO; 2],
            uv: Vec2::ZERO,
            uv1: Vec2::ZERO,
            rgb: Vec3::ONE,
            tangent: Vec4::ZERO,
        }
    }

    #[test]
    fn inside_and_rejected() {
        let t = [v(0.0, 0.0, 0.0, 1.0), v(0.5, 0.0, 0.0, 1.0), v(0.0, 0.5, 0.0, 1.0)];
        assert_eq!(clip_triangle(&t), Clipped::Inside);
        let behind = [v(0.0, 0.0, -2.0, 1.0), v(0.5, 0.0, -2.0, 1.0), v(0.0, 0.5, -3.0, 1.0)];
        assert_eq!(clip_triangle(&behind), Clipped::Rejected);
        let nan = [v(f32::NAN, 0.0, 0.0, 1.0), v(0.5, 0.0, 0.0, 1.0), v(0.0, 0.5, 0.0, 1.0)];
        assert_eq!(clip_triangle(&nan), Clipped::Rejected);
    }

    #[test]
    fn near_plane_cuts_a_corner() {
        // One vertex behind the near plane (z = −2 < −w = −1): the triangle becomes a quad whose
        // new vertices lie exactly on z = −w, with attributes interpolated at the same t.
        let t = [v(0.0, 0.0, -2.0, 1.0), v(0.5, 0.0, 0.0, 1.0), v(0.0, 0.5, 0.0, 1.0)];
        let Clipped::Polygon(p) = clip_triangle(&t) else {
            panic!()
        };
        assert_eq!(p.len(), 4);
        for q in &p {
            assert!(q.clip.z + q.clip.w >= -1e-6);
        }
        // Edge v0 → v1: d0 = −1, d1 = 1, t = 0.5: x = 0.25, z = −1.
        assert!(
            p.iter()
                .any(|q| (q.clip.x - 0.25).abs() < 1e-6 && (q.clip.z + 1.0).abs() < 1e-6)
        );
    }

    /// The outcodes' trivial decisions agree with `clip_triangle` on random triangles around
    /// the view volume and the guard band (and NaN).
    #[test]
    fn outcodes_decide_as_clip_triangle() {
        let mut seed = 7u64;
        let mut r = move || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((seed >> 40) as f32 / (1u64 << 24) as f32) * 2.0 - 1.0
        };
        let (mut rejected, mut inside) = (0, 0);
        for i in 0..20000 {
            let t: [ClipVertex; 3] = std::array::from_fn(|_| {
                let w = 0.5 + r().abs() * 2.0;
                let s = if i % 3 == 0 { 8.0 } else { 1.5 };
                v(
                    r() * s * w,
                    r() * s * w,
                    r() * 1.5 * w,
                    if i % 97 == 0 { f32::NAN } else { w },
                )
            });
            let c = t.map(|v| outcode(v.clip));
            let got = clip_triangle(&t);
            if c[0] & c[1] & c[2] & OUTSIDE_VIEW != 0 {
                assert_eq!(got, Clipped::Rejected, "{t:?}");
                rejected += 1;
            } else if (c[0] | c[1] | c[2]) & (OUTSIDE_CLIP | NOT_FINITE) == 0 {
                assert_eq!(got, Clipped::Inside, "{t:?}");
                inside += 1;
            } else {
                assert_ne!(got, Clipped::Inside, "{t:?}");
            }
        }
        assert!(rejected > 100 && inside > 100, "{rejected} {inside}");
    }

    /// The written-out outcode equals the planes' dot products bit for bit on finite points,
    /// on the planes exactly (x = ±w, ±4w; z = ±w), one ulp off them, and at random.
    #[test]
    fn outcode_matches_plane_dot_products() {
        let by_dots = |c: Vec4| {
            let mut code = 0u16;
            for (i, p) in VIEW_PLANES.iter().chain(&CLIP_PLANES).enumerate() {
                code |= u16::from(p.dot(c) < 0.0) << i;
            }
            code
        };
        let mut seed = 11u64;
        let mut r = move || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((seed >> 40) as f32 / (1u64 << 24) as f32) * 2.0 - 1.0
        };
        let mut checked = 0;
        for _ in 0..5000 {
            let w = r() * 3.0;
            let on = [-GUARD_BAND * w, -w, w, GUARD_BAND * w, r() * 5.0 * w, 0.0];
            for &a in &on {
                for da in [
                    a,
                    f32::from_bits(a.to_bits() + 1),
                    f32::from_bits(a.to_bits().wrapping_sub(1)),
                ] {
                    for c in [
                        Vec4::new(da, r(), r(), w),
                        Vec4::new(r(), da, r(), w),
                        Vec4::new(r(), r(), da, w),
                    ] {
                        if c.is_finite() {
                            assert_eq!(outcode(c), by_dots(c), "{c:?}");
                            checked += 1;
                        }
                    }
                }
            }
        }
        assert!(checked > 200_000);
    }

    #[test]
    fn guard_band_only_beyond_g() {
        // Crosses the viewport's right side (x = w) but not the guard band: not clipped.
        let t = [v(0.0, 0.0, 0.0, 1.0), v(3.0, 0.0, 0.0, 1.0), v(0.0, 0.5, 0.0, 1.0)];
        assert_eq!(clip_triangle(&t), Clipped::Inside);
        let t = [v(0.0, 0.0, 0.0, 1.0), v(100.0, 0.0, 0.0, 1.0), v(0.0, 0.5, 0.0, 1.0)];
        let Clipped::Polygon(p) = clip_triangle(&t) else {
            panic!()
        };
        assert!(p.iter().all(|q| q.clip.x <= GUARD_BAND * q.clip.w + 1e-4));
    }
}
