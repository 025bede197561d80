//! Polygons into triangles: a fan where a fan is exact (a convex polygon), else ear clipping
//! (earcutr) in the plane that best fits the polygon (Newell's normal), so that concave,
//! non-planar, collinear and repeated-vertex polygons are filled as drawn.

use glam::{DVec2, DVec3, Vec3};

/// The triangles of polygon `points` (in order), as indices into `points`, each wound as the
/// polygon is. Degenerate pieces (zero area) may be dropped; a polygon with no area at all is
/// fanned (its triangles cover nothing).
pub(crate) fn triangulate(points: &[Vec3]) -> Vec<[u32; 3]> {
    let n = points.len();
    let fan = || (1..n.saturating_sub(1)).map(|i| [0, i as u32, i as u32 + 1]).collect();
    if n <= 3 {
        return fan();
    }
    let p: Vec<DVec3> = points.iter().map(|p| p.as_dvec3()).collect();
    // Newell's normal: the polygon's area vector, robust to collinear and repeated vertices.
    let mut normal = DVec3::ZERO;
    for i in 0..n {
        let (a, b) = (p[i], p[(i + 1) % n]);
        normal += DVec3::new(
            (a.y - b.y) * (a.z + b.z),
            (a.z - b.z) * (a.x + b.x),
            (a.x - b.x) * (a.y + b.y),
        );
    }
    let Some(normal) = normal.try_normalize() else {
        return fan();
    };
    // An orthonormal basis of the plane, (u, v, normal) right-handed: the polygon winds
    // counter-clockwise in (u, v).
    let u = normal.any_orthonormal_vector();
    let v = normal.cross(u);
    let q: Vec<DVec2> = p
        .iter()
        .map(|&x| DVec2::new((x - p[0]).dot(u), (x - p[0]).dot(v)))
        .collect();
    if is_convex(&q) {
        return fan();
    }
    let flat: Vec<f64> = q.iter().flat_map(|x| [x.x, x.y]).collect();
    match earcutr::earcut(&flat, &[], 2) {
        Ok(idx) if !idx.is_empty() => idx
            .chunks_exact(3)
            .map(|t| {
                let (a, b, c) = (q[t[0]], q[t[1]], q[t[2]]);
                // Wound as the polygon (counter-clockwise in the plane).
                if (b - a).perp_dot(c - a) < 0.0 {
                    [t[0] as u32, t[2] as u32, t[1] as u32]
                } else {
                    [t[0] as u32, t[1] as u32, t[2] as u32]
                }
            })
            .collect(),
        _ => fan(),
    }
}

/// Whether the polygon `q` (counter-clockwise) is convex and simple: no right turn, and its
/// turns add up to one full turn (a star's add up to more).
fn is_convex(q: &[DVec2]) -> bool {
    let n = q.len();
    let mut turning = 0.0;
    for i in 0..n {
        let a = q[(i + n - 1) % n];
        let b = q[i];
        let c = q[(i + 1) % n];
        let (e1, e2) = (b - a, c - b);
        if e1 == DVec2::ZERO || e2 == DVec2::ZERO {
            return false;
        }
        let cross = e1.perp_dot(e2);
        if cross < 0.0 {
            return false;
        }
        turning += cross.atan2(e1.dot(e2));
    }
    (turning - std::f64::consts::TAU).abs() < 1e-6
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area(points: &[Vec3], tris: &[[u32; 3]]) -> f64 {
        tris.iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| points[i as usize].as_dvec3());
                (b - a).cross(c - a).z * 0.5
            })
            .sum()
    }

    /// An L-shaped hexagon (area 3) starting at its reflex vertex: a fan from there would
    /// cover the notch; the triangles cover exactly the L, each wound as the polygon.
    #[test]
    fn concave_l_is_filled_exactly() {
        let l: Vec<Vec3> = [[1., 1.], [1., 2.], [0., 2.], [0., 0.], [2., 0.], [2., 1.]]
            .iter()
            .map(|p| Vec3::new(p[0], p[1], 0.0))
            .collect();
        let t = triangulate(&l);
        assert_eq!(t.len(), 4);
        assert!((area(&l, &t) - 3.0).abs() < 1e-9, "{t:?}");
        for tri in &t {
            assert!(area(&l, &[*tri]) > 0.0, "{tri:?} is wound backwards");
        }
    }

    /// A convex quad is the fan tobj makes (the same triangles as before), collinear and
    /// repeated vertices give no negative triangles, and a clockwise polygon stays clockwise.
    #[test]
    fn convex_collinear_repeated_and_clockwise() {
        let quad: Vec<Vec3> = [[0., 0.], [1., 0.], [1., 1.], [0., 1.]]
            .iter()
            .map(|p| Vec3::new(p[0], p[1], 0.0))
            .collect();
        assert_eq!(triangulate(&quad), vec![[0, 1, 2], [0, 2, 3]]);
        let odd: Vec<Vec3> = [[0., 0.], [1., 0.], [2., 0.], [2., 0.], [2., 2.], [1., 1.], [0., 2.]]
            .iter()
            .map(|p| Vec3::new(p[0], p[1], 0.0))
            .collect();
        let t = triangulate(&odd);
        assert!((area(&odd, &t) - 3.0).abs() < 1e-9, "{t:?}");
        let cw: Vec<Vec3> = quad.iter().rev().copied().collect();
        assert!((area(&cw, &triangulate(&cw)) + 1.0).abs() < 1e-9);
    }
}
