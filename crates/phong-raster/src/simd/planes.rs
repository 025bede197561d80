//! A triangle's attribute planes (perspective-correct, in pixel coordinates) and their
//! evaluation at pixel centres: broadcast to every lane for one triangle's pixels, or gathered
//! lane by lane for pixels of many triangles.

use super::kernel::MAX_LANES;
use super::vector::Vf32;

/// A triangle's perspective-correct attributes as plane equations in pixel coordinates:
/// `q(x, y) = c + gx·(x − ox) + gy·(y − oy)` for `1/w` and for each attribute divided by `w`;
/// the attribute is `q_a / q_w` (interpolating `a/w` and `1/w` linearly in screen space).
///
/// 24 floats in this order (`repr(C)`, plain data), read by a batch as three rows of 8 that
/// it transposes into vectors: Gouraud needs the first two rows, Phong all three.
#[derive(Clone, Copy, Debug, Default, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C)]
pub struct Planes {
    /// `(ox, oy)`: where the planes' constants are taken (a vertex), in pixels.
    pub origin: [f32; 2],
    /// `1/w`: `[c, gx, gy]`.
    pub inv_w: [f32; 3],
    /// Attributes over `w`: Phong: world position then normal; Gouraud: the colour.
    pub attr: [[f32; 3]; 6],
    /// Padding to three rows of 8.
    pub pad: f32,
}

/// The first 14 floats of a Gouraud triangle's [`Planes`] (origin, `1/w` and the colour, the
/// rest unused), in one 64-byte line: what an all-Gouraud frame of one sample keeps per drawn
/// triangle (`FramePlan::colour_planes`), a third less memory traffic than the whole record
/// in a set-up bound by it (BENCHMARKS.md, C14).
#[derive(Clone, Copy, Debug, Default, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C, align(64))]
pub struct ColourPlanes {
    /// As [`Planes::origin`].
    pub origin: [f32; 2],
    /// As [`Planes::inv_w`].
    pub inv_w: [f32; 3],
    /// Red, green and blue over `w`, as [`Planes::attr`]'s first three.
    pub attr: [[f32; 3]; 3],
    /// Padding to 16 floats.
    pub pad: [f32; 2],
}

impl From<&Planes> for ColourPlanes {
    #[inline(always)]
    fn from(p: &Planes) -> ColourPlanes {
        ColourPlanes {
            origin: p.origin,
            inv_w: p.inv_w,
            attr: [p.attr[0], p.attr[1], p.attr[2]],
            pad: [0.0; 2],
        }
    }
}

impl From<&ColourPlanes> for Planes {
    /// The whole record, its other attributes 0 (for the kernels that read [`Planes`]).
    #[inline(always)]
    fn from(c: &ColourPlanes) -> Planes {
        let mut attr = [[0.0; 3]; 6];
        attr[..3].copy_from_slice(&c.attr);
        Planes {
            origin: c.origin,
            inv_w: c.inv_w,
            attr,
            pad: 0.0,
        }
    }
}

impl Planes {
    /// The 24 floats as three rows of 8.
    #[inline(always)]
    fn rows(&self) -> &[[f32; 8]; 3] {
        bytemuck::cast_ref(self)
    }
}

/// The centre of pixel `p` (`row << 16 | column` from `(x0, y0)`, the tiles' packing) in the
/// frame.
#[inline(always)]
pub fn pixel_centre((x0, y0): (u32, u32), p: u32) -> (f32, f32) {
    ((x0 + (p & 0xffff)) as f32 + 0.5, (y0 + (p >> 16)) as f32 + 0.5)
}

/// The centres of `pixels` ([`pixel_centre`]), one per lane.
#[inline(always)]
pub(super) fn centres<V: Vf32>(origin: (u32, u32), pixels: &[u32]) -> (V, V) {
    let mut xs = V::A::default();
    let mut ys = V::A::default();
    for (i, &p) in pixels.iter().enumerate().take(V::N) {
        (xs.as_mut()[i], ys.as_mut()[i]) = pixel_centre(origin, p);
    }
    (V::from_array(xs), V::from_array(ys))
}

/// One triangle's planes broadcast to every lane: its pixels interpolated without gathering
/// coefficients lane by lane.
pub(super) struct Broadcast<V> {
    origin: (V, V),
    inv_w: [V; 3],
    attr: [[V; 3]; 6],
}

impl<V: Vf32> Broadcast<V> {
    /// `planes`' origin, `1/w` and first `attrs` attributes, broadcast.
    #[inline(always)]
    pub(super) fn new(planes: &Planes, attrs: usize) -> Broadcast<V> {
        let mut attr = [[V::splat(0.0); 3]; 6];
        for (a, k) in attr.iter_mut().zip(&planes.attr).take(attrs) {
            *a = [V::splat(k[0]), V::splat(k[1]), V::splat(k[2])];
        }
        let [c, gx, gy] = planes.inv_w;
        Broadcast {
            origin: (V::splat(planes.origin[0]), V::splat(planes.origin[1])),
            inv_w: [V::splat(c), V::splat(gx), V::splat(gy)],
            attr,
        }
    }

    /// The first `attrs` attributes at pixel centres `(x, y)`, and where, as [`interpolate`]
    /// computes them.
    #[inline(always)]
    pub(super) fn at(&self, x: V, y: V, attrs: usize) -> ([V; 6], (V, V, V)) {
        let (dx, dy) = (x.sub(self.origin.0), y.sub(self.origin.1));
        let w = self.inv_w[2]
            .mul_add(dy, self.inv_w[1].mul_add(dx, self.inv_w[0]))
            .recip();
        let mut q = [V::splat(0.0); 6];
        for (o, k) in q.iter_mut().zip(&self.attr).take(attrs) {
            *o = k[2].mul_add(dy, k[1].mul_add(dx, k[0])).mul(w);
        }
        (q, (dx, dy, w))
    }
}

/// The first `rows` rows of 8 of the lanes' planes' 24 floats as vectors (the rest 0):
/// broadcast when one triangle has every lane (the usual case in large triangles), else
/// gathered by transposing each lane's rows.
#[inline(always)]
pub(super) fn coefficients<V: Vf32>(planes: &[&Planes], rows: usize) -> [V; 24] {
    let mut k = [V::splat(0.0); 24];
    if planes.iter().all(|p| std::ptr::eq(*p, planes[0])) {
        let f = bytemuck::cast_ref::<_, [f32; 24]>(planes[0]);
        for (v, &c) in k.iter_mut().zip(f).take(rows * 8) {
            *v = V::splat(c);
        }
    } else {
        for r in 0..rows {
            let mut lanes: [&[f32; 8]; MAX_LANES] = [&planes[0].rows()[r]; MAX_LANES];
            for (l, p) in lanes.iter_mut().zip(planes) {
                *l = &p.rows()[r];
            }
            k[r * 8..r * 8 + 8].copy_from_slice(&V::transpose(&lanes[..V::N]));
        }
    }
    k
}

/// Evaluates the first `attrs` attribute planes at `(x, y)` per lane and divides by `1/w`;
/// with where it evaluated them, `(x − ox, y − oy, w)` (the texture coordinates' planes share
/// the origin and `1/w`).
#[inline(always)]
pub(super) fn interpolate<V: Vf32>(planes: &[&Planes], attrs: usize, x: V, y: V) -> ([V; 6], (V, V, V)) {
    let k = coefficients::<V>(planes, if attrs > 3 { 3 } else { 2 });
    let (dx, dy) = (x.sub(k[0]), y.sub(k[1]));
    // `c + gx·dx + gy·dy` from floats `i..i + 3`.
    let plane = |i: usize| k[i + 2].mul_add(dy, k[i + 1].mul_add(dx, k[i]));
    let w = plane(2).recip();
    let mut out = [V::splat(0.0); 6];
    for (a, o) in out.iter_mut().enumerate().take(attrs) {
        *o = plane(5 + 3 * a).mul(w);
    }
    (out, (dx, dy, w))
}
