//! The fast setup's vertex stage, 8 vertices at a time (AVX2): clip-space transform, outcode
//! and window projection, with the scalar code's operations in its order (no fused
//! multiply-adds, exact divisions), so the same bits (tested against `vertex`'s scalar loop,
//! edge cases included). Why it exists: BENCHMARKS.md, C8.

// Elsewhere than x86-64 only the scalar fallback of this module is compiled.
#![cfg_attr(not(target_arch = "x86_64"), allow(dead_code, unused_imports))]

use crate::clip::{NOT_FINITE, OUTSIDE_CLIP};
use glam::{Mat4, Vec3};
use phong_core::limits::GUARD_BAND;

/// A projected vertex as the kernel hands it over: snapped window `[x, y]` (1/`one` pixel),
/// depth in [0, 1], `1/w` (all zero unless the vertex is inside the clip volume), outcode.
pub type WindowVertex = ([i32; 2], f32, f32, u16);

/// The kernel: `out[i] = make(projected)` for each vertex `i` of `positions`; vertices it
/// cannot match bit for bit (a group of 8 with one whose snapped position leaves `i32`, such as
/// `w = 0` at the eye) get `scalar(position)` instead, and so do the last `len % 8`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
pub(crate) fn project_avx2<O>(
    m: &Mat4,
    (wf, hf, one): (f32, f32, f32),
    positions: &[Vec3],
    out: &mut [O],
    make: impl Fn(WindowVertex) -> O,
    scalar: impl Fn(Vec3) -> O,
) {
    assert_eq!(positions.len(), out.len());
    use core::arch::x86_64::*;
    let s = |x: f32| _mm256_set1_ps(x);
    let cols = m.to_cols_array_2d();
    let (half, zero) = (s(0.5), _mm256_setzero_ps());
    let abs_mask = _mm256_castsi256_ps(_mm256_set1_epi32(i32::MAX));
    let inf = s(f32::INFINITY);
    let limit = _mm256_set1_pd(f64::from(1u32 << 30));
    let groups = positions.len() / 8;
    for g in 0..groups {
        let p = &positions[g * 8..g * 8 + 8];
        let load = |f: fn(&Vec3) -> f32| {
            _mm256_setr_ps(
                f(&p[0]),
                f(&p[1]),
                f(&p[2]),
                f(&p[3]),
                f(&p[4]),
                f(&p[5]),
                f(&p[6]),
                f(&p[7]),
            )
        };
        let (x, y, z) = (load(|v| v.x), load(|v| v.y), load(|v| v.z));
        // `Mat4 * Vec4` as glam's SSE2 build: ((c0·x + c1·y) + c2·z) + c3·1.
        let row = |r: usize| {
            let a = _mm256_add_ps(_mm256_mul_ps(s(cols[0][r]), x), _mm256_mul_ps(s(cols[1][r]), y));
            _mm256_add_ps(
                _mm256_add_ps(a, _mm256_mul_ps(s(cols[2][r]), z)),
                _mm256_mul_ps(s(cols[3][r]), s(1.0)),
            )
        };
        let (cx, cy, cz, cw) = (row(0), row(1), row(2), row(3));
        // `clip::outcode`: bit i set where plane sum i is below zero.
        let g4 = _mm256_mul_ps(s(GUARD_BAND), cw);
        let sums = [
            _mm256_add_ps(cz, cw),
            _mm256_sub_ps(cw, cz),
            _mm256_add_ps(cx, cw),
            _mm256_sub_ps(cw, cx),
            _mm256_add_ps(cy, cw),
            _mm256_sub_ps(cw, cy),
            _mm256_add_ps(cz, cw),
            _mm256_sub_ps(cw, cz),
            _mm256_add_ps(cx, g4),
            _mm256_sub_ps(g4, cx),
            _mm256_add_ps(cy, g4),
            _mm256_sub_ps(g4, cy),
        ];
        let mut code = _mm256_setzero_si256();
        for (i, d) in sums.iter().enumerate() {
            let below = _mm256_castps_si256(_mm256_cmp_ps::<_CMP_LT_OQ>(*d, zero));
            code = _mm256_or_si256(code, _mm256_and_si256(below, _mm256_set1_epi32(1 << i)));
        }
        let finite = |v: __m256| _mm256_cmp_ps::<_CMP_LT_OQ>(_mm256_and_ps(v, abs_mask), inf);
        let all_finite = _mm256_and_ps(
            _mm256_and_ps(finite(cx), finite(cy)),
            _mm256_and_ps(finite(cz), finite(cw)),
        );
        code = _mm256_or_si256(
            code,
            _mm256_andnot_si256(
                _mm256_castps_si256(all_finite),
                _mm256_set1_epi32(i32::from(NOT_FINITE)),
            ),
        );
        // `Stage::project`, in every lane (the caller keeps it only where the code allows).
        let iw = _mm256_div_ps(s(1.0), cw);
        let sx = _mm256_mul_ps(_mm256_add_ps(_mm256_mul_ps(_mm256_mul_ps(cx, iw), half), half), s(wf));
        let sy = _mm256_mul_ps(_mm256_sub_ps(half, _mm256_mul_ps(_mm256_mul_ps(cy, iw), half)), s(hf));
        let depth = _mm256_add_ps(_mm256_mul_ps(_mm256_mul_ps(cz, iw), half), half);
        // `round_i64`: ⌊|v| + ½⌋ in f64 with v's sign; bit k of `ok` clear where that leaves
        // 2^30 (or is NaN): the scalar code's saturating casts decide those.
        let mut ok = 0xffi32;
        let mut round = |v: __m256| -> [i32; 8] {
            let mut out = [0i32; 8];
            for (h, part) in [_mm256_castps256_ps128(v), _mm256_extractf128_ps::<1>(v)]
                .into_iter()
                .enumerate()
            {
                let d = _mm256_cvtps_pd(part);
                let a = _mm256_add_pd(
                    _mm256_and_pd(d, _mm256_castsi256_pd(_mm256_set1_epi64x(i64::MAX))),
                    _mm256_set1_pd(0.5),
                );
                ok &= !(0xf << (4 * h)) | (_mm256_movemask_pd(_mm256_cmp_pd::<_CMP_LT_OQ>(a, limit)) << (4 * h));
                let r = _mm256_cvttpd_epi32(a);
                let neg = _mm_castps_si128(_mm_cmplt_ps(part, _mm_setzero_ps()));
                let r = _mm_sub_epi32(_mm_xor_si128(r, neg), neg);
                // SAFETY: `out[h * 4..]` holds 4 writable i32 (h is 0 or 1).
                unsafe { _mm_storeu_si128(out[h * 4..].as_mut_ptr() as *mut __m128i, r) };
            }
            out
        };
        let (rx, ry) = (round(_mm256_mul_ps(sx, s(one))), round(_mm256_mul_ps(sy, s(one))));
        let mut codes = [0i32; 8];
        let (mut zs, mut iws) = ([0f32; 8], [0f32; 8]);
        // SAFETY: each destination is an array of 8 writable 4-byte lanes.
        unsafe {
            _mm256_storeu_si256(codes.as_mut_ptr() as *mut __m256i, code);
            _mm256_storeu_ps(zs.as_mut_ptr(), depth);
            _mm256_storeu_ps(iws.as_mut_ptr(), iw);
        }
        let inside = |k: usize| codes[k] as u16 & (OUTSIDE_CLIP | NOT_FINITE) == 0;
        if (0..8).any(|k| inside(k) && ok >> k & 1 == 0) {
            for k in 0..8 {
                out[g * 8 + k] = scalar(p[k]);
            }
            continue;
        }
        for k in 0..8 {
            let c = codes[k] as u16;
            let v = if inside(k) {
                ([rx[k], ry[k]], zs[k], iws[k], c)
            } else {
                ([0, 0], 0.0, 0.0, c)
            };
            out[g * 8 + k] = make(v);
        }
    }
    for i in groups * 8..positions.len() {
        out[i] = scalar(positions[i]);
    }
}
