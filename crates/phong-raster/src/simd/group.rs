//! The vectors of one triangle ([`shade_group`], [`shade_group8`]): its pixels shaded
//! [`V::N`](Vf32::N) at a time with its plane coefficients broadcast, the colours given as
//! `f32` or encoded to 8 bits in the registers.

use super::kernel::{Batch, Broadcast, Planes, batch_color, centres, pixel_centre};
use super::vector::Vf32;

/// Shades the pixels of one triangle, [`V::N`](Vf32::N) at a time, with its `planes`
/// broadcast to every lane (no per-lane gathering of coefficients): `pixels` are packed
/// `row << 16 | column` relative to `(x0, y0)`, the pixel whose centre is `(x0 + ½, y0 + ½)`;
/// `out(pixel, rgb)` receives each colour. Only whole vectors are shaded: returns how many
/// pixels were (a multiple of `V::N`); the caller batches the rest with other triangles'
/// (BENCHMARKS.md, R1). Same arithmetic per pixel as
/// [`shade_batch`](super::kernel::shade_batch).
#[inline(always)]
pub(crate) fn shade_group<V: Vf32>(
    batch: Batch,
    planes: &Planes,
    origin: (u32, u32),
    pixels: &[u32],
    out: impl FnMut(u32, [&[f32]; 3]),
) -> usize {
    group_vectors::<V, _>(batch, planes, origin, pixels, &mut F32Out(out))
}

/// [`shade_group`] with the colours encoded to 8-bit RGBA as `Encoding::Linear` encodes them
/// (alpha 255), in the vector registers: `out(pixel, pixels)` takes a run of a row or one
/// pixel.
#[inline(always)]
pub(crate) fn shade_group8<V: Vf32>(
    batch: Batch,
    planes: &Planes,
    origin: (u32, u32),
    pixels: &[u32],
    out: impl FnMut(u32, &[[u8; 4]]),
) -> usize {
    group_vectors::<V, _>(batch, planes, origin, pixels, &mut Rgba8Out(out))
}

/// Where [`group_vectors`] puts each vector's colours: `put(chunk, run, rgb)` takes its
/// pixels, whether they are a run of one row, and their colours. (A trait, not a closure: a
/// closure is not compiled with the caller's AVX2, and its intrinsics become calls: C11.)
trait Sink<V: Vf32> {
    /// The sink encodes to 8 bits, which clamps to `[0, 1]` and maps NaN to 0: the lean
    /// kernel's own clamp and NaN step are left to it.
    const ENCODES: bool;
    fn put(&mut self, chunk: &[u32], run: bool, rgb: [V; 3]);
}

/// Colours as `f32`, per run or per pixel.
struct F32Out<F>(F);

impl<V: Vf32, F: FnMut(u32, [&[f32]; 3])> Sink<V> for F32Out<F> {
    const ENCODES: bool = false;
    #[inline(always)]
    fn put(&mut self, chunk: &[u32], run: bool, rgb: [V; 3]) {
        let rgb = rgb.map(V::to_array);
        let [r, g, b] = [rgb[0].as_ref(), rgb[1].as_ref(), rgb[2].as_ref()];
        if run {
            (self.0)(chunk[0], [r, g, b]);
        } else {
            for (i, &p) in chunk.iter().enumerate() {
                (self.0)(p, [&r[i..=i], &g[i..=i], &b[i..=i]]);
            }
        }
    }
}

/// Colours as 8-bit RGBA, per run or per pixel.
struct Rgba8Out<F>(F);

impl<V: Vf32, F: FnMut(u32, &[[u8; 4]])> Sink<V> for Rgba8Out<F> {
    const ENCODES: bool = true;
    #[inline(always)]
    fn put(&mut self, chunk: &[u32], run: bool, rgb: [V; 3]) {
        let px = V::encode_rgba8(rgb);
        if run {
            (self.0)(chunk[0], px.as_ref());
        } else {
            for (i, &p) in chunk.iter().enumerate() {
                (self.0)(p, &px.as_ref()[i..=i]);
            }
        }
    }
}

/// The whole vectors of [`shade_group`], their colours given to `sink`.
#[inline(always)]
fn group_vectors<V: Vf32, S: Sink<V>>(
    batch: Batch,
    planes: &Planes,
    (x0, y0): (u32, u32),
    pixels: &[u32],
    sink: &mut S,
) -> usize {
    let full = pixels.len() / V::N * V::N;
    if full == 0 {
        return 0;
    }
    let attrs = match batch {
        Batch::Phong(..) | Batch::Lean(..) => 6,
        Batch::Gouraud => 3,
    };
    let planes = Broadcast::<V>::new(planes, attrs);
    let mut lanes = V::A::default();
    for (i, l) in lanes.as_mut().iter_mut().enumerate() {
        *l = i as f32;
    }
    let lanes = V::from_array(lanes);
    for chunk in pixels[..full].chunks_exact(V::N) {
        // A run of a row (the common case inside a triangle): its centres from the first,
        // its colours given at once.
        // (`pixels` ascend: N of them spanning N columns are consecutive.)
        debug_assert!(chunk.windows(2).all(|w| w[0] < w[1]));
        let run = chunk[V::N - 1].wrapping_sub(chunk[0]) == (V::N - 1) as u32;
        let (x, y) = if run {
            let (x, y) = pixel_centre((x0, y0), chunk[0]);
            (V::splat(x).add(lanes), V::splat(y))
        } else {
            centres::<V>((x0, y0), chunk)
        };
        let (q, _) = planes.at(x, y, attrs);
        let rgb = if S::ENCODES {
            batch_color::<V, true>(batch, q)
        } else {
            batch_color::<V, false>(batch, q)
        };
        sink.put(chunk, run, rgb);
    }
    full
}
