//! The Gouraud tile kernel (AVX2): visibility and colour of a tile's triangles, four pixels of
//! a row at a time, bit for bit the scalar loop's (`tile::visible`'s `visible_single` with its
//! colour planes), which stays as the twin on CPUs without AVX2 and is tested against it.
//!
//! Per four pixels of a row: the three edge functions as exact integers in `f64` lanes (an
//! edge value inside a triangle's box is below 2^51 in magnitude, so integer steps added in
//! `f64` are exact, and `E as f64` is the scalar's conversion of the same integer), coverage
//! as their sign bits, the barycentrics `(E · 1/area) as f32` and the depth `Σ λ_i z_i` in the
//! scalar's order, the depth test and its blended store, then the colours `q_rgb / q_w` of the
//! passing pixels, `q = c + g_x·dx + g_y·dy` per channel in the scalar's order (no fused
//! multiply-adds, an exact division), transposed into `[r, g, b, 1]` pixels and blended into
//! the row.
//!
//! Signs: `E − bias` is never `−0.0` (sums of integers in `f64` give `+0.0` where they cancel,
//! and a lane's first value is a converted integer plus `0·step`, `+0.0 + −0.0 = +0.0`), so the
//! sign bit is exactly `E − bias < 0`.
//!
//! A triangle whose columns lie in at most four aligned windows (most triangles of a fine
//! mesh) steps its windows down from row to row instead of setting each row up, so the kernel
//! draws every tile of an AVX2 frame, tiny triangles included (BENCHMARKS.md, C4). Measurements
//! and dead ends: BENCHMARKS.md ("Dead ends", K1–K10).

// Elsewhere than x86-64 only the scalar fallback of this module is compiled.
#![cfg_attr(not(target_arch = "x86_64"), allow(dead_code, unused_imports))]

use super::Isa;
use super::planes::ColourPlanes;

/// The most windows of 4 a triangle's columns may span in a tile to be drawn by
/// `narrow_triangle` (every row's windows stepped down and tested) rather than row by row
/// (each row's covered span found, its first window set up).
const NARROW_WINDOWS: u32 = 4;

/// The pixels a triangle's row covers, as a range of `k` over `0..n` (pixels from the row's
/// first column), given per edge `row[i]` = `E_i − bias_i` at the first pixel and its step per
/// pixel `step[i]`: exact integer bounds of `row + k·step >= 0` for rows of 8 pixels or more,
/// where the three divisions cost less than testing each pixel; `0..n` for narrower rows.
#[inline(always)]
pub(crate) fn covered_span(row: [i64; 3], step: [i64; 3], n: i64) -> (i64, i64) {
    let (mut lo, mut hi) = (0i64, n);
    if n >= 8 {
        for i in 0..3 {
            let (e, s) = (row[i], step[i]);
            if e < 0 {
                if s > 0 {
                    lo = lo.max((-e + s - 1) / s);
                } else {
                    hi = 0;
                }
            } else if s < 0 {
                hi = hi.min(e / -s + 1);
            }
        }
    }
    (lo, hi)
}

/// A pixel [`gouraud_tile`] writes: linear `f32` RGBA, or 8-bit RGBA as
/// `Encoding::Linear` encodes it (see `encode_linear`), alpha 255.
pub trait TilePixel: bytemuck::Pod + Send {
    /// 8 bits a channel (else `f32`).
    const EIGHT: bool;
    /// `c` as this pixel: the kernel's store of it, for the scalar loop.
    fn from_linear(c: [f32; 4]) -> Self;
}

impl TilePixel for [f32; 4] {
    const EIGHT: bool = false;
    #[inline(always)]
    fn from_linear(c: [f32; 4]) -> Self {
        c
    }
}

impl TilePixel for [u8; 4] {
    const EIGHT: bool = true;
    #[inline(always)]
    fn from_linear(c: [f32; 4]) -> Self {
        c.map(|x| phong_core::Encoding::Linear.encode(x))
    }
}

/// A triangle as [`gouraud_tile`] draws it into a tile, in the tile's pixels.
#[derive(Clone, Copy)]
pub struct GouraudTri<'p> {
    /// Per edge `i`: `E_i − bias_i` at the sample of the first pixel (column `cols.0`, row
    /// `rows.0`), in 1/256² pixel².
    pub start: [i64; 3],
    /// Per edge: the change of `E_i` per pixel to the right.
    pub step_x: [i64; 3],
    /// Per edge: the change of `E_i` per row down.
    pub step_y: [i64; 3],
    /// Per edge: 1 where the edge is not top-left (`E_i = start + … + bias_i`), else 0.
    pub bias: [i64; 3],
    /// `1 / (twice the signed area)`: barycentrics are `E_i · inv_area`.
    pub inv_area: f64,
    /// Window depth per vertex.
    pub z: [f32; 3],
    /// Columns of the tile to draw, `cols.0..cols.1`.
    pub cols: (u32, u32),
    /// Rows of the tile to draw, `rows.0..rows.1`.
    pub rows: (u32, u32),
    /// The colour planes: `attr[0..3]` red, green and blue over `w`, `inv_w` the `1/w` plane,
    /// each `[c, g_x, g_y]` about `origin`.
    pub planes: &'p ColourPlanes,
}

/// Draws `n` triangles, `tri(0)` first, into a tile at `(x0, y0)` of the frame: `depth`
/// (row-major, `stride` a row; a multiple of 4 at least the tile's width is fastest) keeps
/// the nearest depth, and each pixel that passes its depth test (`z < depth`) gets its
/// triangle's colour in `rows` (see [`TilePixel`]); returns how many pixels
/// of `depth` were `+∞` before and are not after. The AVX2 kernel: with a portable `isa` it
/// returns `None` and draws nothing (the caller then draws with the scalar loop).
pub fn gouraud_tile<'p, P: TilePixel>(
    isa: Isa,
    (x0, y0): (u32, u32),
    stride: usize,
    n: usize,
    tri: impl Fn(usize) -> GouraudTri<'p>,
    depth: &mut [f32],
    rows: &mut [&mut [P]],
) -> Option<u64> {
    #[cfg(target_arch = "x86_64")]
    if isa.is_avx2() {
        // SAFETY: an AVX2 `Isa` exists only where the CPU has AVX2 and FMA (`Isa::detect`).
        return Some(unsafe { gouraud_tile_avx2((x0, y0), stride, n, tri, depth, rows) });
    }
    let _ = (isa, x0, y0, stride, n, tri, depth, rows);
    None
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn gouraud_tile_avx2<'p, P: TilePixel>(
    (x0, y0): (u32, u32),
    stride: usize,
    n: usize,
    tri: impl Fn(usize) -> GouraudTri<'p>,
    depth: &mut [f32],
    rows: &mut [&mut [P]],
) -> u64 {
    use core::arch::x86_64::*;
    // Pixels whose depth left +∞ (no depth returns to it: `z < d` fails at `z = +∞`).
    let mut covered = 0u64;
    let lanes_pd = _mm256_setr_pd(0.0, 1.0, 2.0, 3.0);
    let lanes_epi = _mm_setr_epi32(0, 1, 2, 3);
    let (half, four) = (_mm_set1_ps(0.5), _mm_set1_ps(4.0));
    // The tile's width (its rows' length).
    let tw = rows.first().map_or(0, |r| r.len());
    for k in 0..n {
        let t = tri(k);
        let ((c0, c1), (r0, r1)) = (t.cols, t.rows);
        if c1 <= c0 || r1 <= r0 {
            continue;
        }
        // A triangle whose columns lie in at most four aligned windows inside the tile (most
        // triangles of a fine mesh): its rows' windows are stepped down, not set up per row.
        let base = c0 & !3;
        let windows = (c1.next_multiple_of(4) - base) / 4;
        if windows <= NARROW_WINDOWS && (base + 4 * windows) as usize <= tw.min(stride) {
            let at = (x0, y0);
            match windows {
                1 => narrow_triangle::<P, 1>(&t, at, stride, base, depth, rows, &mut covered),
                2 => narrow_triangle::<P, 2>(&t, at, stride, base, depth, rows, &mut covered),
                3 => narrow_triangle::<P, 3>(&t, at, stride, base, depth, rows, &mut covered),
                _ => narrow_triangle::<P, 4>(&t, at, stride, base, depth, rows, &mut covered),
            }
            continue;
        }
        let width = i64::from(c1 - c0);
        let p = t.planes;
        let inv = _mm256_set1_pd(t.inv_area);
        let z = t.z.map(|v| _mm_set1_ps(v));
        let bias = t.bias.map(|b| _mm256_set1_pd(b as f64));
        let lane_step = t.step_x.map(|s| _mm256_mul_pd(lanes_pd, _mm256_set1_pd(s as f64)));
        let step4 = t.step_x.map(|s| _mm256_set1_pd((4 * s) as f64));
        // Per channel (r, g, b, w): the plane's [c, g_x, g_y].
        let plane = |ch: usize| if ch < 3 { p.attr[ch] } else { p.inv_w };
        let cc: [__m128; 4] = std::array::from_fn(|ch| _mm_set1_ps(plane(ch)[0]));
        let gx: [__m128; 4] = std::array::from_fn(|ch| _mm_set1_ps(plane(ch)[1]));
        let ox = _mm_set1_ps(p.origin[0]);
        let mut row_e = t.start;
        for r in r0..r1 {
            let (lo, hi) = covered_span(row_e, t.step_x, width);
            if lo < hi {
                let dy = _mm_set1_ps((y0 + r) as f32 + 0.5 - p.origin[1]);
                let gyy: [__m128; 4] = std::array::from_fn(|ch| _mm_mul_ps(_mm_set1_ps(plane(ch)[2]), dy));
                // Windows of 4 pixels aligned in the tile: a window's loads and stores are at
                // the same addresses as its neighbours' of the triangles before it, so that
                // they forward from the store buffer. Lanes outside the triangle's box (in the
                // tile) are tested too: no sample there is inside the three edges.
                let end = i64::from(c0) + hi;
                let mut col = (i64::from(c0) + lo) & !3;
                let mut e: [__m256d; 3] = std::array::from_fn(|i| {
                    _mm256_add_pd(
                        _mm256_set1_pd((row_e[i] + t.step_x[i] * (col - i64::from(c0))) as f64),
                        lane_step[i],
                    )
                });
                let line = r as usize * stride;
                let row = &mut *rows[r as usize];
                // The row's windows, whole inside the tile's depths and pixels (every row but
                // those of a frame's last column of tiles, when its width is not a multiple
                // of 4): taken as 4-element arrays, without a bounds check or a lane past the
                // edge per window.
                let (first, span) = (col as usize, ((end - col + 3) & !3) as usize);
                if let (Some(dw), Some(pw)) = (
                    depth.get_mut(line + first..line + first + span),
                    row.get_mut(first..first + span),
                ) {
                    // The pixels' columns, exact integers in `f32`, 4 more each window.
                    let mut xs =
                        _mm_cvtepi32_ps(_mm_add_epi32(_mm_set1_epi32((x0 as usize + first) as i32), lanes_epi));
                    for (d4, p4) in dw.as_chunks_mut::<4>().0.iter_mut().zip(pw.as_chunks_mut::<4>().0) {
                        let inside = !_mm256_movemask_pd(_mm256_or_pd(_mm256_or_pd(e[0], e[1]), e[2])) as u32 & 15;
                        if inside != 0 {
                            let zz = window_depths(e, bias, inv, z);
                            let (pass, mask) = depth_window4(d4, zz, inside, &mut covered);
                            if pass != 0 {
                                let dx = _mm_sub_ps(_mm_add_ps(xs, half), ox);
                                let rgb = window_colour(cc, gx, gyy, dx);
                                if P::EIGHT {
                                    store_rgba8_window(bytemuck::cast_mut(p4), mask, rgb);
                                } else {
                                    store_rgba32(bytemuck::cast_slice_mut(p4), 0, pass, rgb);
                                }
                            }
                        }
                        for i in 0..3 {
                            e[i] = _mm256_add_pd(e[i], step4[i]);
                        }
                        xs = _mm_add_ps(xs, four);
                    }
                } else {
                    while col < end {
                        let outside = _mm256_movemask_pd(_mm256_or_pd(_mm256_or_pd(e[0], e[1]), e[2])) as u32;
                        // Lanes past the tile's right edge (a frame's last column of tiles).
                        let valid = 15u32 >> (col + 4 - row.len() as i64).max(0);
                        let inside = !outside & valid;
                        if inside != 0 {
                            let zz = window_depths(e, bias, inv, z);
                            let pass = depth_window(depth, line + col as usize, zz, inside, &mut covered);
                            if pass != 0 {
                                let c = col as usize;
                                let px =
                                    _mm_cvtepi32_ps(_mm_add_epi32(_mm_set1_epi32((x0 as usize + c) as i32), lanes_epi));
                                let dx = _mm_sub_ps(_mm_add_ps(px, half), ox);
                                let rgb = window_colour(cc, gx, gyy, dx);
                                if P::EIGHT {
                                    store_rgba8(bytemuck::cast_slice_mut(row), c, pass, rgb);
                                } else {
                                    store_rgba32(bytemuck::cast_slice_mut(row), c, pass, rgb);
                                }
                            }
                        }
                        for i in 0..3 {
                            e[i] = _mm256_add_pd(e[i], step4[i]);
                        }
                        col += 4;
                    }
                }
            }
            for (e, s) in row_e.iter_mut().zip(t.step_y) {
                *e += s;
            }
        }
    }
    covered
}

/// [`gouraud_tile_avx2`]'s drawing of triangle `t`, whose columns lie in the `NW` windows of 4
/// from tile column `base` (all inside the tile's rows and depths): each row's windows from
/// the row above's by one exact step of the edge functions, without the row's span, bounds or
/// start found again. The same arithmetic per window as the general loop.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
#[inline]
fn narrow_triangle<P: TilePixel, const NW: usize>(
    t: &GouraudTri,
    (x0, y0): (u32, u32),
    stride: usize,
    base: u32,
    depth: &mut [f32],
    rows: &mut [&mut [P]],
    covered: &mut u64,
) {
    use core::arch::x86_64::*;
    let ((c0, _), (r0, r1)) = (t.cols, t.rows);
    let p = t.planes;
    let inv = _mm256_set1_pd(t.inv_area);
    let z = t.z.map(|v| _mm_set1_ps(v));
    let bias = t.bias.map(|b| _mm256_set1_pd(b as f64));
    let step4 = t.step_x.map(|s| _mm256_set1_pd((4 * s) as f64));
    let step_y = t.step_y.map(|s| _mm256_set1_pd(s as f64));
    // `E − bias` at the 4 pixels of the first window of row `r0`: exact integers (the edge
    // functions' values near the triangle's box), so every step below is exact.
    let lanes_pd = _mm256_setr_pd(0.0, 1.0, 2.0, 3.0);
    let back = i64::from(base) - i64::from(c0);
    let mut e: [__m256d; 3] = std::array::from_fn(|i| {
        _mm256_fmadd_pd(
            lanes_pd,
            _mm256_set1_pd(t.step_x[i] as f64),
            _mm256_set1_pd((t.start[i] + t.step_x[i] * back) as f64),
        )
    });
    let plane = |ch: usize| if ch < 3 { p.attr[ch] } else { p.inv_w };
    let cc: [__m128; 4] = std::array::from_fn(|ch| _mm_set1_ps(plane(ch)[0]));
    let gx: [__m128; 4] = std::array::from_fn(|ch| _mm_set1_ps(plane(ch)[1]));
    // Each window's `dx` from the planes' origin, the same in every row.
    let dx: [__m128; NW] = std::array::from_fn(|w| {
        let first = _mm_set1_epi32((x0 + base) as i32 + 4 * w as i32);
        let px = _mm_cvtepi32_ps(_mm_add_epi32(first, _mm_setr_epi32(0, 1, 2, 3)));
        _mm_sub_ps(_mm_add_ps(px, _mm_set1_ps(0.5)), _mm_set1_ps(p.origin[0]))
    });
    let gy: [__m128; 4] = std::array::from_fn(|ch| _mm_set1_ps(plane(ch)[2]));
    for r in r0..r1 {
        let mut ew = e;
        // The row's `g_y·dy`, made once for its windows (one window: where it passes).
        let row_gyy = || {
            let dy = _mm_set1_ps((y0 + r) as f32 + 0.5 - p.origin[1]);
            gy.map(|g| _mm_mul_ps(g, dy))
        };
        let shared = (NW > 1).then(row_gyy);
        // The row's windows, inside the tile's depths and pixels (the caller's test): no
        // bounds check per window.
        let (line, first) = (r as usize * stride + base as usize, base as usize);
        if let (Some(dw), Some(pw)) = (
            depth.get_mut(line..line + 4 * NW),
            rows[r as usize].get_mut(first..first + 4 * NW),
        ) {
            let windows = dw.as_chunks_mut::<4>().0.iter_mut().zip(pw.as_chunks_mut::<4>().0);
            for (w, ((d4, p4), &dxw)) in windows.zip(&dx).enumerate() {
                let inside = !_mm256_movemask_pd(_mm256_or_pd(_mm256_or_pd(ew[0], ew[1]), ew[2])) as u32 & 15;
                if inside != 0 {
                    let zz = window_depths(ew, bias, inv, z);
                    let (pass, mask) = depth_window4(d4, zz, inside, covered);
                    if pass != 0 {
                        let gyy = shared.unwrap_or_else(row_gyy);
                        let rgb = window_colour(cc, gx, gyy, dxw);
                        if P::EIGHT {
                            store_rgba8_window(bytemuck::cast_mut(p4), mask, rgb);
                        } else {
                            store_rgba32(bytemuck::cast_slice_mut(p4), 0, pass, rgb);
                        }
                    }
                }
                if w + 1 < NW {
                    ew = std::array::from_fn(|i| _mm256_add_pd(ew[i], step4[i]));
                }
            }
        }
        e = std::array::from_fn(|i| _mm256_add_pd(e[i], step_y[i]));
    }
}

/// The depths of a window's 4 samples from their edge functions `e` (bias subtracted, exact
/// integers in `f64`): barycentrics `(e + bias) · inv_area` rounded to `f32`, then
/// `Σ l_i · z_i` unfused in the scalar loops' order, so the same bits as theirs.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
#[inline]
pub(super) fn window_depths(
    e: [core::arch::x86_64::__m256d; 3],
    bias: [core::arch::x86_64::__m256d; 3],
    inv: core::arch::x86_64::__m256d,
    z: [core::arch::x86_64::__m128; 3],
) -> core::arch::x86_64::__m128 {
    use core::arch::x86_64::*;
    let l: [__m128; 3] = std::array::from_fn(|i| _mm256_cvtpd_ps(_mm256_mul_pd(_mm256_add_pd(e[i], bias[i]), inv)));
    _mm_add_ps(
        _mm_add_ps(_mm_mul_ps(l[0], z[0]), _mm_mul_ps(l[1], z[1])),
        _mm_mul_ps(l[2], z[2]),
    )
}

/// A window's colours from the planes `q = c + g_x·dx + g_y·dy` per channel (`gyy` is
/// `g_y·dy`) in the scalar loop's order (no fused multiply-adds), `[r, g, b]` over `w` by an
/// exact division.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
#[inline]
fn window_colour(
    cc: [core::arch::x86_64::__m128; 4],
    gx: [core::arch::x86_64::__m128; 4],
    gyy: [core::arch::x86_64::__m128; 4],
    dx: core::arch::x86_64::__m128,
) -> [core::arch::x86_64::__m128; 3] {
    use core::arch::x86_64::*;
    let q: [__m128; 4] = std::array::from_fn(|ch| _mm_add_ps(_mm_add_ps(cc[ch], _mm_mul_ps(gx[ch], dx)), gyy[ch]));
    let w = _mm_div_ps(_mm_set1_ps(1.0), q[3]);
    [_mm_mul_ps(q[0], w), _mm_mul_ps(q[1], w), _mm_mul_ps(q[2], w)]
}

/// How many bits of a window's 4 are set.
const POP4: [u8; 16] = [0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4];

/// The depth test of a window of 4 pixels `d4`: each `inside` lane whose depth `zz` is below
/// the stored one stores it. Returns the lanes that passed, as bits and as a blend mask,
/// adding to `covered` those that were `+∞`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
#[inline]
fn depth_window4(
    d4: &mut [f32; 4],
    zz: core::arch::x86_64::__m128,
    inside: u32,
    covered: &mut u64,
) -> (u32, core::arch::x86_64::__m128) {
    use core::arch::x86_64::*;
    // Loaded by `lddqu`, which LLVM does not see as a load: a load, a blend and a store of the
    // same address are otherwise turned into a masked store (`vmaskmovps`), slow on AMD and
    // not forwarded to later loads (BENCHMARKS.md, K1).
    // SAFETY: `d4` is 4 readable f32.
    let d = _mm_castsi128_ps(unsafe { _mm_lddqu_si128(d4.as_ptr().cast()) });
    let pass = _mm_movemask_ps(_mm_cmplt_ps(zz, d)) as u32 & inside;
    let fresh = pass & _mm_movemask_ps(_mm_cmpeq_ps(d, _mm_set1_ps(f32::INFINITY))) as u32;
    *covered += u64::from(POP4[fresh as usize & 15]);
    let mask = lane_mask(pass);
    // SAFETY: `d4` is 4 writable f32.
    unsafe { _mm_storeu_ps(d4.as_mut_ptr(), _mm_blendv_ps(d, zz, mask)) };
    (pass, mask)
}

/// [`depth_window4`] for the window at `depth[at..]`, which may run past `depth`'s end (its
/// lanes there are not `inside`). Returns the lanes that passed.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
#[inline]
fn depth_window(depth: &mut [f32], at: usize, zz: core::arch::x86_64::__m128, inside: u32, covered: &mut u64) -> u32 {
    use core::arch::x86_64::*;
    if let Some(d4) = depth
        .get_mut(at..at + 4)
        .and_then(|d| <&mut [f32; 4]>::try_from(d).ok())
    {
        return depth_window4(d4, zz, inside, covered).0;
    }
    // A caller's depth without room for whole windows: one at a time.
    let mut zs = [0f32; 4];
    // SAFETY: `zs` is 4 writable f32.
    unsafe { _mm_storeu_ps(zs.as_mut_ptr(), zz) };
    let mut pass = 0;
    for (j, &zj) in zs.iter().enumerate() {
        if inside & (1 << j) != 0 && zj < depth[at + j] {
            *covered += u64::from(depth[at + j] == f32::INFINITY);
            depth[at + j] = zj;
            pass |= 1 << j;
        }
    }
    pass
}

/// A blend mask from a window's bits: bit j into the sign of lane j.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
#[inline]
fn lane_mask(bits: u32) -> core::arch::x86_64::__m128 {
    use core::arch::x86_64::*;
    _mm_castsi128_ps(_mm_sllv_epi32(
        _mm_set1_epi32(bits as i32),
        _mm_setr_epi32(31, 30, 29, 28),
    ))
}

/// A window's colours `rgb` (channel planes of 4 pixels) as four 8-bit RGBA pixels, as
/// `encode_linear` computes them: `(clamp(v, 0, 1)·255 + 0.5)` truncated, NaN as 0, alpha 255.
/// Only the upper clamp is taken in `f32` (`min(1, v)`, which keeps a NaN): the conversion of
/// a value below 0 truncates to 0 or to a negative integer, and of NaN or `−∞` to `i32::MIN`,
/// and the saturating packs take all of those to 0, as the lower clamp would.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
#[inline]
fn encode_window(rgb: [core::arch::x86_64::__m128; 3]) -> core::arch::x86_64::__m128 {
    use core::arch::x86_64::*;
    let (one, half, c255) = (_mm_set1_ps(1.0), _mm_set1_ps(0.5), _mm_set1_ps(255.0));
    let enc = |v: __m128| _mm_cvttps_epi32(_mm_add_ps(_mm_mul_ps(_mm_min_ps(one, v), c255), half));
    // [r0..r3 g0..g3 b0..b3 a a a a] bytes, then pixel by pixel.
    let planar = _mm_packus_epi16(
        _mm_packs_epi32(enc(rgb[0]), enc(rgb[1])),
        _mm_packs_epi32(enc(rgb[2]), _mm_set1_epi32(255)),
    );
    let interleave = _mm_setr_epi8(0, 4, 8, 12, 1, 5, 9, 13, 2, 6, 10, 14, 3, 7, 11, 15);
    _mm_castsi128_ps(_mm_shuffle_epi8(planar, interleave))
}

/// The colours `rgb` (channel planes of 4 pixels) written as 8-bit pixels ([`encode_window`])
/// into the lanes of `win` that `mask` selects.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
#[inline]
fn store_rgba8_window(win: &mut [[u8; 4]; 4], mask: core::arch::x86_64::__m128, rgb: [core::arch::x86_64::__m128; 3]) {
    use core::arch::x86_64::*;
    let packed = encode_window(rgb);
    let ptr = win.as_mut_ptr().cast::<f32>();
    // SAFETY: `win` is 16 readable and writable bytes from `ptr`. By `lddqu`, as the depth
    // in `depth_window4` (K1).
    unsafe {
        let old = _mm_castsi128_ps(_mm_lddqu_si128(ptr.cast()));
        _mm_storeu_ps(ptr, _mm_blendv_ps(old, packed, mask));
    }
}

/// [`store_rgba8_window`] for the window at `row[c..]`, which may run past the row's end (its
/// lanes there are not in `pass`).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
#[inline]
fn store_rgba8(row: &mut [[u8; 4]], c: usize, pass: u32, rgb: [core::arch::x86_64::__m128; 3]) {
    use core::arch::x86_64::*;
    if let Some(win) = row
        .get_mut(c..c + 4)
        .and_then(|w| <&mut [[u8; 4]; 4]>::try_from(w).ok())
    {
        return store_rgba8_window(win, lane_mask(pass), rgb);
    }
    // A row without room for the whole window: pixel by pixel.
    let mut bytes = [[0u8; 4]; 4];
    // SAFETY: `bytes` is 16 writable bytes.
    unsafe { _mm_storeu_ps(bytes.as_mut_ptr().cast(), encode_window(rgb)) };
    let mut m = pass;
    while m != 0 {
        let j = m.trailing_zeros() as usize;
        row[c + j] = bytes[j];
        m &= m - 1;
    }
}

/// The colours `rgb` (channel planes of 4 pixels) of a window's `pass` lanes written as
/// `[r, g, b, 1]` f32 pixels to `row[c..]`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
#[inline]
fn store_rgba32(row: &mut [[f32; 4]], c: usize, pass: u32, [cr, cg, cb]: [core::arch::x86_64::__m128; 3]) {
    use core::arch::x86_64::*;
    let one = _mm_set1_ps(1.0);
    // Transposed: pixel j is [r_j, g_j, b_j, 1].
    let (rg_lo, rg_hi) = (_mm_unpacklo_ps(cr, cg), _mm_unpackhi_ps(cr, cg));
    let (b1_lo, b1_hi) = (_mm_unpacklo_ps(cb, one), _mm_unpackhi_ps(cb, one));
    let pixels = [
        _mm_movelh_ps(rg_lo, b1_lo),
        _mm_movehl_ps(b1_lo, rg_lo),
        _mm_movelh_ps(rg_hi, b1_hi),
        _mm_movehl_ps(b1_hi, rg_hi),
    ];
    if let Some(win) = row.get_mut(c..c + 4) {
        // The masks of pixels 0, 1 and of 2, 3: bit j into the sign of lanes 4·j..4·j + 4.
        let pb = _mm256_set1_epi32(pass as i32);
        let m01 = _mm256_castsi256_ps(_mm256_sllv_epi32(pb, _mm256_setr_epi32(31, 31, 31, 31, 30, 30, 30, 30)));
        let m23 = _mm256_castsi256_ps(_mm256_sllv_epi32(pb, _mm256_setr_epi32(29, 29, 29, 29, 28, 28, 28, 28)));
        let ptr = win.as_mut_ptr().cast::<f32>();
        // SAFETY: `win` is 4 pixels, 16 readable and writable f32 from `ptr`.
        unsafe {
            // By `lddqu`, as the depth in `depth_window`.
            let old01 = _mm256_castsi256_ps(_mm256_lddqu_si256(ptr.cast()));
            let old23 = _mm256_castsi256_ps(_mm256_lddqu_si256(ptr.add(8).cast()));
            let new01 = _mm256_set_m128(pixels[1], pixels[0]);
            let new23 = _mm256_set_m128(pixels[3], pixels[2]);
            _mm256_storeu_ps(ptr, _mm256_blendv_ps(old01, new01, m01));
            _mm256_storeu_ps(ptr.add(8), _mm256_blendv_ps(old23, new23, m23));
        }
    } else {
        let mut m = pass;
        while m != 0 {
            let j = m.trailing_zeros() as usize;
            // SAFETY: `row[c + j]` is 4 writable f32 (bounds-checked).
            unsafe { _mm_storeu_ps(row[c + j].as_mut_ptr(), pixels[j]) };
            m &= m - 1;
        }
    }
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use phong_core::Encoding;

    /// The Gouraud kernel's window encoding (its lower clamp the saturating packs') is
    /// `Encoding::Linear`'s, bit for bit, on
    /// [`encoding_values`](crate::testkit::encoding_values).
    #[test]
    fn encode_window_is_the_scalar_encoding() {
        if crate::testkit::avx2().is_none() {
            return;
        }
        #[target_feature(enable = "avx2,fma")]
        fn check(values: &[f32]) {
            use core::arch::x86_64::*;
            for c in values.chunks_exact(4) {
                let load = |v: [f32; 4]| _mm_setr_ps(v[0], v[1], v[2], v[3]);
                let rot = [c[1], c[2], c[3], c[0]];
                let packed = super::encode_window([load([c[0], c[1], c[2], c[3]]), load(rot), load(rot)]);
                let mut px = [[0u8; 4]; 4];
                // SAFETY: `px` is 16 writable bytes.
                unsafe { _mm_storeu_ps(px.as_mut_ptr().cast(), packed) };
                let e = |x: f32| Encoding::Linear.encode(x);
                for i in 0..4 {
                    assert_eq!(px[i], [e(c[i]), e(rot[i]), e(rot[i]), 255], "{:e}, {:e}", c[i], rot[i]);
                }
            }
        }
        // SAFETY: the CPU has AVX2 and FMA (checked above).
        unsafe { check(&crate::testkit::encoding_values()) };
    }
}
