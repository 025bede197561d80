//! Visibility of an opaque triangle in a tile, four samples a vector (AVX2): the scalar loops
//! of `Tiles::tile_multi` (four samples of a pixel) and `visible_single` (one sample of four
//! pixels of a row) without a branch per sample; the same depths and ids.
//!
//! The edge functions are integers below 2^53 in magnitude (`Tri`), so their sums in `f64`
//! are exact: a sample's sign test and its `e · inv_area` are the scalar loop's, bit for bit.

use super::Isa;
#[cfg(target_arch = "x86_64")]
use super::tile::{covered_span, window_depths};
#[cfg(target_arch = "x86_64")]
use crate::fixed::each3;
use crate::setup::Tri;
#[cfg(target_arch = "x86_64")]
use phong_core::limits::SUBPIXEL_BITS;

/// A tile's sample buffers: per pixel (row-major, `x1 − x0` a row, origin `(x0, y0)`,
/// exclusive end `(x1, y1)`) its samples' nearest depths and the ids of their triangles.
pub(crate) struct SampleBuffers<'a> {
    pub rect: (u32, u32, u32, u32),
    pub depth: &'a mut [f32],
    pub ids: &'a mut [u32],
}

impl SampleBuffers<'_> {
    /// Panics unless the buffers hold `samples` a pixel over the whole tile: the kernels'
    /// windows then stay inside them.
    fn check(&self, samples: usize) {
        let (x0, y0, x1, y1) = self.rect;
        let n = (x1 - x0) as usize * (y1 - y0) as usize * samples;
        assert!(
            self.depth.len() >= n && self.ids.len() >= n,
            "sample buffers smaller than the tile"
        );
    }
}

/// Triangle `t` (id `id`) drawn into `buf`'s samples: each covered sample (top-left rule)
/// nearer than what it holds takes its depth and `id`. The AVX2 kernel, for patterns of 4, 8,
/// 12 or 16 samples; returns false (nothing drawn) otherwise or with a portable `isa`.
pub(crate) fn multi_visible(isa: Isa, t: &Tri, id: u32, pattern: &[(i64, i64)], buf: &mut SampleBuffers) -> bool {
    multi_visible_run(isa, 1, |_| (t, id), pattern, buf)
}

/// Triangles `tri(0)`, ..., `tri(n − 1)` (each with its id) drawn in turn into `buf`'s samples
/// as [`multi_visible`] draws one: a tile's opaque triangles in one call, the pattern's offsets
/// converted once (a 70k-triangle model at 256×256 has about one triangle a pixel, and a call
/// a triangle with its bookkeeping was about a tenth of the visibility's instructions).
/// Returns false (nothing drawn) where [`multi_visible`] does.
pub(crate) fn multi_visible_run<'t>(
    isa: Isa,
    n: usize,
    tri: impl Fn(usize) -> (&'t Tri, u32),
    pattern: &[(i64, i64)],
    buf: &mut SampleBuffers,
) -> bool {
    buf.check(pattern.len());
    #[cfg(target_arch = "x86_64")]
    if isa.is_avx2() && !pattern.is_empty() && pattern.len().is_multiple_of(4) && pattern.len() <= 16 {
        // SAFETY: an AVX2 `Isa` exists only where the CPU has AVX2 and FMA (`Isa::detect`).
        unsafe { multi_visible_avx2(n, tri, pattern, buf) };
        return true;
    }
    let _ = (isa, n, tri, pattern);
    false
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn multi_visible_avx2<'t>(
    n: usize,
    tri: impl Fn(usize) -> (&'t Tri, u32),
    pattern: &[(i64, i64)],
    buf: &mut SampleBuffers,
) {
    use core::arch::x86_64::*;
    let (x0, y0, x1, y1) = buf.rect;
    let (tw, ns) = ((x1 - x0) as usize, pattern.len());
    let groups = ns / 4;
    // The pattern's offsets, 4 samples a vector.
    let mut oxy = [(_mm256_setzero_pd(), _mm256_setzero_pd()); 4];
    for (o, four) in oxy.iter_mut().zip(pattern.chunks_exact(4)) {
        *o = (
            _mm256_setr_pd(four[0].0 as f64, four[1].0 as f64, four[2].0 as f64, four[3].0 as f64),
            _mm256_setr_pd(four[0].1 as f64, four[1].1 as f64, four[2].1 as f64, four[3].1 as f64),
        );
    }
    for k in 0..n {
        let (t, id) = tri(k);
        // Per group of 4 samples and edge: `a·ox + b·oy − bias`, the scalar loop's offsets
        // (exact: products below 2^33).
        let mut off = [[_mm256_setzero_pd(); 3]; 4];
        let ab: [(__m256d, __m256d, __m256d); 3] = std::array::from_fn(|i| {
            let f = |v: i64| _mm256_set1_pd(v as f64);
            (f(t.a(i)), f(t.b(i)), f(t.bias(i)))
        });
        for (o, &(ox, oy)) in off[..groups].iter_mut().zip(&oxy) {
            for (o, (a, b, bias)) in o.iter_mut().zip(ab) {
                *o = _mm256_fmadd_pd(a, ox, _mm256_fmsub_pd(b, oy, bias));
            }
        }
        let bias = ab.map(|(_, _, b)| b);
        let step: [f64; 3] = std::array::from_fn(|i| (t.a(i) << SUBPIXEL_BITS) as f64);
        let inv = _mm256_set1_pd(t.inv_area);
        let z = t.z.map(|v| _mm_set1_ps(v));
        let idv = _mm_castsi128_ps(_mm_set1_epi32(id as i32));
        let bb = t.bbox();
        let (bx0, bx1) = (bb[0].max(x0), bb[2].min(x1));
        for py in bb[1].max(y0)..bb[3].min(y1) {
            let (cx, cy) = (i64::from(bx0) << SUBPIXEL_BITS, i64::from(py) << SUBPIXEL_BITS);
            let e = t.edges_at(cx, cy);
            let mut row: [f64; 3] = std::array::from_fn(|i| e[i] as f64);
            let mut base = ((py - y0) as usize * tw + (bx0 - x0) as usize) * ns;
            for _ in bx0..bx1 {
                for (g, o) in off[..groups].iter().enumerate() {
                    let e: [__m256d; 3] = std::array::from_fn(|i| _mm256_add_pd(_mm256_set1_pd(row[i]), o[i]));
                    // A sign bit on any edge: outside (the sums are exact integers, never −0).
                    let outside = _mm256_movemask_pd(_mm256_or_pd(_mm256_or_pd(e[0], e[1]), e[2])) as u32;
                    if outside == 15 {
                        continue;
                    }
                    let zz = window_depths(e, bias, inv, z);
                    window(buf, base + 4 * g, zz, !outside & 15, idv);
                }
                for i in 0..3 {
                    row[i] += step[i];
                }
                base += ns;
            }
        }
    }
}

/// Triangle `t` (id `id`) drawn into a tile's one-sample buffers over its columns `cols`
/// (clipped to the tile), `o` its edge functions' offset at the sample (bias subtracted), as
/// `visible_single` draws an opaque triangle: each covered pixel nearer than what it holds
/// takes its depth and `id`. The AVX2 kernel; returns false (nothing drawn) with a portable
/// `isa`.
pub(crate) fn single_visible(
    isa: Isa,
    t: &Tri,
    id: u32,
    o: [i64; 3],
    cols: (u32, u32),
    buf: &mut SampleBuffers,
) -> bool {
    buf.check(1);
    #[cfg(target_arch = "x86_64")]
    if isa.is_avx2() {
        // SAFETY: an AVX2 `Isa` exists only where the CPU has AVX2 and FMA (`Isa::detect`).
        unsafe { single_visible_avx2(t, id, o, cols, buf) };
        return true;
    }
    let _ = (isa, t, id, o, cols);
    false
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn single_visible_avx2(t: &Tri, id: u32, o: [i64; 3], (bx0, bx1): (u32, u32), buf: &mut SampleBuffers) {
    use core::arch::x86_64::*;
    let (x0, y0, x1, y1) = buf.rect;
    if bx1 <= bx0 {
        return;
    }
    let tw = i64::from(x1 - x0);
    let step = each3(|i| t.a(i) << SUBPIXEL_BITS);
    let lanes_pd = _mm256_setr_pd(0.0, 1.0, 2.0, 3.0);
    let lane_step = step.map(|s| _mm256_mul_pd(lanes_pd, _mm256_set1_pd(s as f64)));
    let step4 = step.map(|s| _mm256_set1_pd((4 * s) as f64));
    let bias: [__m256d; 3] = std::array::from_fn(|i| _mm256_set1_pd(t.bias(i) as f64));
    let inv = _mm256_set1_pd(t.inv_area);
    let z = t.z.map(|v| _mm_set1_ps(v));
    let idv = _mm_castsi128_ps(_mm_set1_epi32(id as i32));
    let bb = t.bbox();
    let n = i64::from(bx1 - bx0);
    // The tile column of the box's first pixel.
    let c0 = i64::from(bx0 - x0);
    // A triangle whose columns lie in one or two aligned windows inside the tile (most
    // triangles of a fine mesh): each row's windows stepped down from the row above's.
    let base = c0 & !3;
    let columns = ((c0 + n + 3) & !3) - base;
    if columns <= 8 && base + columns <= tw {
        let first = bb[1].max(y0);
        let (cx, cy) = (
            (i64::from(x0) + base) << SUBPIXEL_BITS,
            i64::from(first) << SUBPIXEL_BITS,
        );
        let e0 = t.edges_at(cx, cy);
        let e: [__m256d; 3] =
            std::array::from_fn(|i| _mm256_add_pd(_mm256_set1_pd((e0[i] + o[i]) as f64), lane_step[i]));
        let step_y: [__m256d; 3] = std::array::from_fn(|i| _mm256_set1_pd((t.b(i) << SUBPIXEL_BITS) as f64));
        let at = (first - y0) as usize * tw as usize + base as usize;
        let rows = (first..bb[3].min(y1)).len();
        let (wz, line) = ((bias, inv, z, idv), (at, tw as usize, rows));
        if columns == 4 {
            narrow_rows::<1>(buf, e, step_y, step4, wz, line);
        } else {
            narrow_rows::<2>(buf, e, step_y, step4, wz, line);
        }
        return;
    }
    for py in bb[1].max(y0)..bb[3].min(y1) {
        let (cx, cy) = (i64::from(bx0) << SUBPIXEL_BITS, i64::from(py) << SUBPIXEL_BITS);
        // e − bias at the row's first pixel, and the exact span of covered pixels.
        let e = t.edges_at(cx, cy);
        let row = each3(|i| e[i] + o[i]);
        let (lo, hi) = covered_span(row, step, n);
        if lo >= hi {
            continue;
        }
        let line = (py - y0) as usize * tw as usize;
        // Windows of 4 aligned in the tile, so that a window's loads and stores meet the
        // previous triangles' at the same addresses (store forwarding). Lanes outside the span
        // are outside an edge; lanes past the tile's right edge are masked.
        let end = c0 + hi;
        let mut col = (c0 + lo) & !3;
        let mut e: [__m256d; 3] = std::array::from_fn(|i| {
            _mm256_add_pd(_mm256_set1_pd((row[i] + step[i] * (col - c0)) as f64), lane_step[i])
        });
        while col < end {
            let outside = _mm256_movemask_pd(_mm256_or_pd(_mm256_or_pd(e[0], e[1]), e[2])) as u32;
            let inside = !outside & (15u32 >> (col + 4 - tw).max(0));
            if inside != 0 {
                window(buf, line + col as usize, window_depths(e, bias, inv, z), inside, idv);
            }
            for i in 0..3 {
                e[i] = _mm256_add_pd(e[i], step4[i]);
            }
            col += 4;
        }
    }
}

/// [`single_visible_avx2`]'s rows of a triangle whose columns lie in `NW` aligned windows
/// inside the tile: `e` holds `E − bias` at the 4 pixels of the first row's first window,
/// `line` is `(index of that window in buf, the tile's width, rows)`; each window is the one
/// to its left plus `step4`, each row the one above plus `step_y` (exact integer steps).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
#[inline]
fn narrow_rows<const NW: usize>(
    buf: &mut SampleBuffers,
    mut e: [core::arch::x86_64::__m256d; 3],
    step_y: [core::arch::x86_64::__m256d; 3],
    step4: [core::arch::x86_64::__m256d; 3],
    (bias, inv, z, idv): (
        [core::arch::x86_64::__m256d; 3],
        core::arch::x86_64::__m256d,
        [core::arch::x86_64::__m128; 3],
        core::arch::x86_64::__m128,
    ),
    (mut at, tw, rows): (usize, usize, usize),
) {
    use core::arch::x86_64::*;
    for _ in 0..rows {
        let mut ew = e;
        for w in 0..NW {
            let outside = _mm256_movemask_pd(_mm256_or_pd(_mm256_or_pd(ew[0], ew[1]), ew[2])) as u32;
            if outside != 15 {
                window(buf, at + 4 * w, window_depths(ew, bias, inv, z), !outside & 15, idv);
            }
            if w + 1 < NW {
                ew = std::array::from_fn(|i| _mm256_add_pd(ew[i], step4[i]));
            }
        }
        e = std::array::from_fn(|i| _mm256_add_pd(e[i], step_y[i]));
        at += tw;
    }
}

/// The depth test of the 4 samples at `buf`'s `at..`: each `inside` lane whose depth `zz` is
/// below the stored one stores it and the id `idv`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
#[inline]
fn window(
    buf: &mut SampleBuffers,
    at: usize,
    zz: core::arch::x86_64::__m128,
    inside: u32,
    idv: core::arch::x86_64::__m128,
) {
    use core::arch::x86_64::*;
    if let (Some(d4), Some(i4)) = (buf.depth.get_mut(at..at + 4), buf.ids.get_mut(at..at + 4)) {
        // Loaded by `lddqu` so that LLVM does not make the blends masked stores
        // (BENCHMARKS.md, K1).
        // SAFETY: `d4` is 4 readable f32.
        let d = _mm_castsi128_ps(unsafe { _mm_lddqu_si128(d4.as_ptr().cast()) });
        let pass = _mm_and_ps(_mm_cmplt_ps(zz, d), lanes(inside));
        if _mm_movemask_ps(pass) != 0 {
            // SAFETY: `i4` is 4 readable u32.
            let old = _mm_castsi128_ps(unsafe { _mm_lddqu_si128(i4.as_ptr().cast()) });
            // SAFETY: `d4` and `i4` are 4 writable f32 and u32.
            unsafe {
                _mm_storeu_ps(d4.as_mut_ptr(), _mm_blendv_ps(d, zz, pass));
                _mm_storeu_ps(i4.as_mut_ptr().cast(), _mm_blendv_ps(old, idv, pass));
            }
        }
        return;
    }
    // The buffers' last window, short of 4: one lane at a time.
    let mut zs = [0f32; 4];
    // SAFETY: `zs` is 4 writable f32.
    unsafe { _mm_storeu_ps(zs.as_mut_ptr(), zz) };
    let id = _mm_cvtsi128_si32(_mm_castps_si128(idv)) as u32;
    for (j, &zj) in zs.iter().enumerate() {
        if inside & (1 << j) != 0 && zj < buf.depth[at + j] {
            buf.depth[at + j] = zj;
            buf.ids[at + j] = id;
        }
    }
}

/// All-ones lanes where `bits` has bit j set, lane j.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
#[inline]
fn lanes(bits: u32) -> core::arch::x86_64::__m128 {
    use core::arch::x86_64::*;
    let bit = _mm_setr_epi32(1, 2, 4, 8);
    _mm_castsi128_ps(_mm_cmpeq_epi32(_mm_and_si128(_mm_set1_epi32(bits as i32), bit), bit))
}
