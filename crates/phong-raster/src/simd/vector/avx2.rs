//! The AVX2 implementations of [`Vf32`]: [`Avx2`], one `__m256`, and [`Avx2x2`], two of
//! them side by side.

use super::{Splat, Vf32};
use core::arch::x86_64::*;

/// One `__m256`. Only used inside functions compiled with `avx2,fma` and called after the
/// CPU was found to have both (the `shade_*_avx2` entry points of [`crate::simd`]).
#[derive(Clone, Copy, Debug)]
pub struct Avx2(__m256);

// Each method runs one or a few AVX/AVX2/FMA intrinsics on register values (no memory
// access beyond the arrays passed by reference). They are sound to execute only on a CPU
// with AVX2 and FMA: this type is only instantiated by `crate::simd`'s `#[target_feature]`
// entry points, which are only called when `avx2_available()` returned true.
/// `y·w + x` per lane, `x` clamped into `0..w` and `y` into `0..h` (a NaN or out-of-range
/// conversion gives i32::MIN, clamped to 0): below `w·h`. Needs AVX2 (callers are the
/// gathers below, inside `avx2,fma` functions).
#[inline(always)]
fn texel_index(w: usize, h: usize, x: __m256, y: __m256) -> __m256i {
    // SAFETY: AVX2 is present (the callers' contract, see the impl below); register
    // arithmetic only.
    unsafe {
        let zero = _mm256_setzero_si256();
        let xi = _mm256_min_epi32(
            _mm256_max_epi32(_mm256_cvttps_epi32(x), zero),
            _mm256_set1_epi32(w as i32 - 1),
        );
        let yi = _mm256_min_epi32(
            _mm256_max_epi32(_mm256_cvttps_epi32(y), zero),
            _mm256_set1_epi32(h as i32 - 1),
        );
        _mm256_add_epi32(_mm256_mullo_epi32(yi, _mm256_set1_epi32(w as i32)), xi)
    }
}

/// `Encoding::Linear`'s 8-bit value of each lane once packed with signed, then unsigned
/// saturation (as [`Avx2::encode_rgba8`] packs it), as a 32-bit integer: `min(1, c)` (`minps`
/// with `c` second keeps a NaN), times 255, plus 0.5, truncated, each step rounded as the
/// scalar code rounds it (no fused multiply-add). The lower clamp is the packs': a value below
/// 0 truncates to 0 or a negative integer, NaN and `−∞` to `i32::MIN`, all packed to 0, as
/// `max(c, 0)` first would give. Needs AVX (callers are inside `avx2,fma` functions).
#[inline(always)]
fn encode_channel(c: __m256) -> __m256i {
    // SAFETY: AVX is present (the callers' contract); register arithmetic only.
    unsafe {
        let v = _mm256_min_ps(_mm256_set1_ps(1.0), c);
        _mm256_cvttps_epi32(_mm256_add_ps(
            _mm256_mul_ps(v, _mm256_set1_ps(255.0)),
            _mm256_set1_ps(0.5),
        ))
    }
}

/// Eight RGBA8 texels' red, green and blue as floats. Needs AVX2 (callers are the gathers
/// below, inside `avx2,fma` functions).
#[inline(always)]
fn rgb8(g: __m256i) -> [Avx2; 3] {
    // SAFETY: AVX2 is present (the callers' contract); register arithmetic only.
    unsafe {
        let byte = _mm256_set1_epi32(0xff);
        [
            Avx2(_mm256_cvtepi32_ps(_mm256_and_si256(g, byte))),
            Avx2(_mm256_cvtepi32_ps(_mm256_and_si256(_mm256_srli_epi32::<8>(g), byte))),
            Avx2(_mm256_cvtepi32_ps(_mm256_and_si256(_mm256_srli_epi32::<16>(g), byte))),
        ]
    }
}

impl Vf32 for Avx2 {
    const N: usize = 8;
    type A = [f32; 8];
    type Px = [[u8; 4]; 8];
    type M = __m256;
    #[inline(always)]
    fn gather_rgb8(texels: &[[u8; 4]], width: u32, height: u32, x: Self, y: Self) -> [Self; 3] {
        let (w, h) = (width as usize, height as usize);
        assert!(
            w >= 1 && h >= 1 && texels.len() >= w * h && w * h <= i32::MAX as usize,
            "a level's texels fit its size"
        );
        // SAFETY: AVX2 is present (see above). `texel_index` is below `w·h <=
        // texels.len()`: each gathered i32 is the 4 bytes of one texel of `texels`
        // (unaligned reads are allowed).
        unsafe {
            let idx = texel_index(w, h, x.0, y.0);
            rgb8(_mm256_i32gather_epi32::<4>(texels.as_ptr().cast::<i32>(), idx))
        }
    }
    #[inline(always)]
    fn gather_quad_rgb8(texels: &[[u8; 4]], width: u32, height: u32, x: Self, y: Self) -> [[Self; 3]; 4] {
        let (w, h) = (width as usize, height as usize);
        assert!(
            w.is_power_of_two() && h.is_power_of_two() && texels.len() >= w * h && w * h <= i32::MAX as usize,
            "a repeated power-of-two image within its texels"
        );
        // SAFETY: AVX2 is present (see above). Each index is `(y & (h − 1)) << log2 w |
        // (x & (w − 1))`, below `w·h <= texels.len()` whatever the lanes hold (a NaN or
        // out-of-range conversion gives i32::MIN, masked like any other): each gathered i32
        // is the 4 bytes of one texel of `texels`.
        unsafe {
            let (xi, yi) = (_mm256_cvttps_epi32(x.0), _mm256_cvttps_epi32(y.0));
            let one = _mm256_set1_epi32(1);
            let (wm, hm) = (_mm256_set1_epi32(w as i32 - 1), _mm256_set1_epi32(h as i32 - 1));
            let shift = _mm_cvtsi32_si128(w.trailing_zeros() as i32);
            let x0 = _mm256_and_si256(xi, wm);
            let x1 = _mm256_and_si256(_mm256_add_epi32(xi, one), wm);
            let y0 = _mm256_sll_epi32(_mm256_and_si256(yi, hm), shift);
            let y1 = _mm256_sll_epi32(_mm256_and_si256(_mm256_add_epi32(yi, one), hm), shift);
            let base = texels.as_ptr().cast::<i32>();
            [
                rgb8(_mm256_i32gather_epi32::<4>(base, _mm256_or_si256(y0, x0))),
                rgb8(_mm256_i32gather_epi32::<4>(base, _mm256_or_si256(y0, x1))),
                rgb8(_mm256_i32gather_epi32::<4>(base, _mm256_or_si256(y1, x0))),
                rgb8(_mm256_i32gather_epi32::<4>(base, _mm256_or_si256(y1, x1))),
            ]
        }
    }
    #[inline(always)]
    fn gather_rgb16(texels: &[[u16; 4]], width: u32, height: u32, x: Self, y: Self) -> [Self; 3] {
        let (w, h) = (width as usize, height as usize);
        assert!(
            w >= 1 && h >= 1 && texels.len() >= w * h && 2 * w * h <= i32::MAX as usize,
            "a level's texels fit its size"
        );
        // SAFETY: AVX2 is present (see above). A texel is two i32: red and green at
        // `2·index`, blue and alpha at `2·index + 1`, with `index = texel_index(..) < w·h
        // <= texels.len()`, so both within `texels` and within i32 (checked above).
        unsafe {
            let idx = _mm256_slli_epi32::<1>(texel_index(w, h, x.0, y.0));
            let base = texels.as_ptr().cast::<i32>();
            let rg = _mm256_i32gather_epi32::<4>(base, idx);
            let ba = _mm256_i32gather_epi32::<4>(base, _mm256_add_epi32(idx, _mm256_set1_epi32(1)));
            let low = _mm256_set1_epi32(0xffff);
            [
                Avx2(_mm256_cvtepi32_ps(_mm256_and_si256(rg, low))),
                Avx2(_mm256_cvtepi32_ps(_mm256_srli_epi32::<16>(rg))),
                Avx2(_mm256_cvtepi32_ps(_mm256_and_si256(ba, low))),
            ]
        }
    }
    #[inline(always)]
    fn splat(x: f32) -> Self {
        // SAFETY: AVX is present (see the comment above the impl).
        Avx2(unsafe { _mm256_set1_ps(x) })
    }
    #[inline(always)]
    fn from_array(a: [f32; 8]) -> Self {
        // SAFETY: AVX is present (see above); `a` is 8 readable f32 (unaligned load).
        Avx2(unsafe { _mm256_loadu_ps(a.as_ptr()) })
    }
    #[inline(always)]
    fn to_array(self) -> [f32; 8] {
        let mut a = [0f32; 8];
        // SAFETY: AVX is present (see above); `a` is 8 writable f32 (unaligned store).
        unsafe { _mm256_storeu_ps(a.as_mut_ptr(), self.0) };
        a
    }
    #[inline(always)]
    fn add(self, b: Self) -> Self {
        // SAFETY: AVX is present (see above).
        Avx2(unsafe { _mm256_add_ps(self.0, b.0) })
    }
    #[inline(always)]
    fn sub(self, b: Self) -> Self {
        // SAFETY: AVX is present (see above).
        Avx2(unsafe { _mm256_sub_ps(self.0, b.0) })
    }
    #[inline(always)]
    fn mul(self, b: Self) -> Self {
        // SAFETY: AVX is present (see above).
        Avx2(unsafe { _mm256_mul_ps(self.0, b.0) })
    }
    #[inline(always)]
    fn mul_add(self, b: Self, c: Self) -> Self {
        // SAFETY: FMA is present (see above).
        Avx2(unsafe { _mm256_fmadd_ps(self.0, b.0, c.0) })
    }
    #[inline(always)]
    fn rsqrt(self) -> Self {
        // The 12-bit estimate and one Newton step y·(1.5 − ½a·y²): relative error about
        // 2^−22. The step's 0·∞ at a = 0 is NaN: keep the estimate (+∞) there.
        // SAFETY: AVX and FMA are present (see above).
        unsafe {
            let y = _mm256_rsqrt_ps(self.0);
            let hy = _mm256_mul_ps(_mm256_mul_ps(self.0, _mm256_set1_ps(0.5)), y);
            let t = _mm256_fnmadd_ps(hy, y, _mm256_set1_ps(1.5));
            let r = _mm256_mul_ps(y, t);
            let zero = _mm256_cmp_ps::<_CMP_EQ_OQ>(self.0, _mm256_setzero_ps());
            Avx2(_mm256_blendv_ps(r, y, zero))
        }
    }
    #[inline(always)]
    fn rsqrt_positive(self) -> Self {
        // `rsqrt`'s estimate and Newton step, without its care for 0.
        // SAFETY: AVX and FMA are present (see above).
        unsafe {
            let y = _mm256_rsqrt_ps(self.0);
            let hy = _mm256_mul_ps(_mm256_mul_ps(self.0, _mm256_set1_ps(0.5)), y);
            Avx2(_mm256_mul_ps(y, _mm256_fnmadd_ps(hy, y, _mm256_set1_ps(1.5))))
        }
    }
    #[inline(always)]
    fn load_splat(s: &Splat) -> Self {
        // SAFETY: AVX is present (see above); `s` holds 16 readable f32, 64-byte aligned.
        Avx2(unsafe { _mm256_load_ps(s.0.as_ptr()) })
    }
    #[inline(always)]
    fn encode_rgba8(rgb: [Self; 3]) -> [[u8; 4]; 8] {
        let mut out = [[0u8; 4]; 8];
        // Channels as 32-bit integers, packed to 16 then 8 bits (per 128-bit half: four
        // reds, greens, blues, alphas), then each half's 4×4 bytes transposed into pixels.
        // SAFETY: AVX2 is present (see above); `out` is 32 writable bytes.
        unsafe {
            let rg = _mm256_packs_epi32(encode_channel(rgb[0].0), encode_channel(rgb[1].0));
            let ba = _mm256_packs_epi32(encode_channel(rgb[2].0), _mm256_set1_epi32(255));
            let planar = _mm256_packus_epi16(rg, ba);
            let order = _mm256_setr_epi8(
                0, 4, 8, 12, 1, 5, 9, 13, 2, 6, 10, 14, 3, 7, 11, 15, 0, 4, 8, 12, 1, 5, 9, 13, 2, 6, 10, 14, 3, 7, 11,
                15,
            );
            _mm256_storeu_si256(out.as_mut_ptr().cast(), _mm256_shuffle_epi8(planar, order));
        }
        out
    }
    #[inline(always)]
    fn recip(self) -> Self {
        // The 12-bit estimate and one Newton step y·(2 − a·y): relative error about 2^−22.
        // SAFETY: AVX and FMA are present (see above).
        unsafe {
            let y = _mm256_rcp_ps(self.0);
            let t = _mm256_fnmadd_ps(self.0, y, _mm256_set1_ps(2.0));
            Avx2(_mm256_mul_ps(y, t))
        }
    }
    #[inline(always)]
    fn min(self, b: Self) -> Self {
        // SAFETY: AVX is present (see above).
        Avx2(unsafe { _mm256_min_ps(self.0, b.0) })
    }
    #[inline(always)]
    fn max(self, b: Self) -> Self {
        // SAFETY: AVX is present (see above).
        Avx2(unsafe { _mm256_max_ps(self.0, b.0) })
    }
    #[inline(always)]
    fn lt(self, b: Self) -> Self::M {
        // SAFETY: AVX is present (see above).
        unsafe { _mm256_cmp_ps::<_CMP_LT_OQ>(self.0, b.0) }
    }
    #[inline(always)]
    fn gt(self, b: Self) -> Self::M {
        // SAFETY: AVX is present (see above).
        unsafe { _mm256_cmp_ps::<_CMP_GT_OQ>(self.0, b.0) }
    }
    #[inline(always)]
    fn ge(self, b: Self) -> Self::M {
        // SAFETY: AVX is present (see above).
        unsafe { _mm256_cmp_ps::<_CMP_GE_OQ>(self.0, b.0) }
    }
    #[inline(always)]
    fn finite(self) -> Self::M {
        // |x| < ∞ (false for NaN).
        // SAFETY: AVX is present (see above).
        unsafe {
            let abs = _mm256_andnot_ps(_mm256_set1_ps(-0.0), self.0);
            _mm256_cmp_ps::<_CMP_LT_OQ>(abs, _mm256_set1_ps(f32::INFINITY))
        }
    }
    #[inline(always)]
    fn nan(self) -> Self::M {
        // SAFETY: AVX is present (see above).
        unsafe { _mm256_cmp_ps::<_CMP_UNORD_Q>(self.0, self.0) }
    }
    #[inline(always)]
    fn select(m: Self::M, a: Self, b: Self) -> Self {
        // SAFETY: AVX is present (see above).
        Avx2(unsafe { _mm256_blendv_ps(b.0, a.0, m) })
    }
    #[inline(always)]
    fn all_true() -> Self::M {
        // SAFETY: AVX is present (see above).
        unsafe { _mm256_castsi256_ps(_mm256_set1_epi32(-1)) }
    }
    #[inline(always)]
    fn and(m: Self::M, n: Self::M) -> Self::M {
        // SAFETY: AVX is present (see above).
        unsafe { _mm256_and_ps(m, n) }
    }
    #[inline(always)]
    fn or(m: Self::M, n: Self::M) -> Self::M {
        // SAFETY: AVX is present (see above).
        unsafe { _mm256_or_ps(m, n) }
    }
    #[inline(always)]
    fn not(m: Self::M) -> Self::M {
        // SAFETY: AVX is present (see above).
        unsafe { _mm256_xor_ps(m, _mm256_castsi256_ps(_mm256_set1_epi32(-1))) }
    }
    #[inline(always)]
    fn any(m: Self::M) -> bool {
        // SAFETY: AVX is present (see above).
        unsafe { _mm256_movemask_ps(m) != 0 }
    }
    #[inline(always)]
    fn frexp(self) -> (Self, Self) {
        // SAFETY: AVX2 is present (see above).
        unsafe {
            let bits = _mm256_castps_si256(self.0);
            let e = _mm256_sub_epi32(_mm256_srli_epi32::<23>(bits), _mm256_set1_epi32(127));
            let m = _mm256_or_si256(
                _mm256_and_si256(bits, _mm256_set1_epi32(0x007f_ffff)),
                _mm256_set1_epi32(0x3f80_0000),
            );
            (Avx2(_mm256_cvtepi32_ps(e)), Avx2(_mm256_castsi256_ps(m)))
        }
    }
    #[inline(always)]
    fn pow2i(self) -> Self {
        // SAFETY: AVX2 is present (see above).
        unsafe {
            let k = _mm256_cvttps_epi32(self.0);
            let bits = _mm256_slli_epi32::<23>(_mm256_add_epi32(k, _mm256_set1_epi32(127)));
            Avx2(_mm256_castsi256_ps(bits))
        }
    }
    #[inline(always)]
    fn frexp_folded(self) -> (Self, Self) {
        // SAFETY: AVX2 is present (see above).
        unsafe {
            let bits = _mm256_castps_si256(self.0);
            let e = _mm256_srai_epi32::<23>(_mm256_sub_epi32(bits, _mm256_set1_epi32(super::SQRT_HALF_BITS)));
            let m = _mm256_sub_epi32(bits, _mm256_slli_epi32::<23>(e));
            (Avx2(_mm256_cvtepi32_ps(e)), Avx2(_mm256_castsi256_ps(m)))
        }
    }
    #[inline(always)]
    fn scale_pow2(self, k: Self) -> Self {
        // SAFETY: AVX2 is present (see above).
        unsafe {
            let shift = _mm256_slli_epi32::<23>(_mm256_cvtps_epi32(k.0));
            Avx2(_mm256_castsi256_ps(_mm256_add_epi32(
                _mm256_castps_si256(self.0),
                shift,
            )))
        }
    }
    #[inline(always)]
    fn round(self) -> Self {
        // SAFETY: AVX is present (see above).
        Avx2(unsafe { _mm256_round_ps::<{ _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC }>(self.0) })
    }
    #[inline(always)]
    fn floor(self) -> Self {
        // SAFETY: AVX is present (see above).
        Avx2(unsafe { _mm256_round_ps::<{ _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC }>(self.0) })
    }
    #[inline(always)]
    fn transpose(rows: &[&[f32; 8]]) -> [Self; 8] {
        let rows: &[&[f32; 8]; 8] = rows.try_into().expect("8 rows for 8 lanes");
        // SAFETY: AVX is present (see above); each row is 8 readable f32 (unaligned loads).
        unsafe {
            let r = rows.map(|row| _mm256_loadu_ps(row.as_ptr()));
            // Pairs interleaved, then quadruples, then the 128-bit halves swapped.
            let t = [
                _mm256_unpacklo_ps(r[0], r[1]),
                _mm256_unpackhi_ps(r[0], r[1]),
                _mm256_unpacklo_ps(r[2], r[3]),
                _mm256_unpackhi_ps(r[2], r[3]),
                _mm256_unpacklo_ps(r[4], r[5]),
                _mm256_unpackhi_ps(r[4], r[5]),
                _mm256_unpacklo_ps(r[6], r[7]),
                _mm256_unpackhi_ps(r[6], r[7]),
            ];
            let q = [
                _mm256_shuffle_ps::<0x44>(t[0], t[2]),
                _mm256_shuffle_ps::<0xee>(t[0], t[2]),
                _mm256_shuffle_ps::<0x44>(t[1], t[3]),
                _mm256_shuffle_ps::<0xee>(t[1], t[3]),
                _mm256_shuffle_ps::<0x44>(t[4], t[6]),
                _mm256_shuffle_ps::<0xee>(t[4], t[6]),
                _mm256_shuffle_ps::<0x44>(t[5], t[7]),
                _mm256_shuffle_ps::<0xee>(t[5], t[7]),
            ];
            [
                Avx2(_mm256_permute2f128_ps::<0x20>(q[0], q[4])),
                Avx2(_mm256_permute2f128_ps::<0x20>(q[1], q[5])),
                Avx2(_mm256_permute2f128_ps::<0x20>(q[2], q[6])),
                Avx2(_mm256_permute2f128_ps::<0x20>(q[3], q[7])),
                Avx2(_mm256_permute2f128_ps::<0x31>(q[0], q[4])),
                Avx2(_mm256_permute2f128_ps::<0x31>(q[1], q[5])),
                Avx2(_mm256_permute2f128_ps::<0x31>(q[2], q[6])),
                Avx2(_mm256_permute2f128_ps::<0x31>(q[3], q[7])),
            ]
        }
    }
}

/// Two [`Avx2`] vectors as one of 16 lanes: every operation is issued twice, on
/// independent registers, so that the long dependency chains of the kernel (normalisations,
/// `log2` and `exp2` polynomials) of one half overlap the other's.
#[derive(Clone, Copy, Debug)]
pub struct Avx2x2(Avx2, Avx2);

macro_rules! both {
    ($a:ident, $f:ident $(, $b:ident)*) => {
        Avx2x2($a.0.$f($($b.0),*), $a.1.$f($($b.1),*))
    };
}

impl Vf32 for Avx2x2 {
    const N: usize = 16;
    type A = [f32; 16];
    type Px = [[u8; 4]; 16];
    type M = (__m256, __m256);
    #[inline(always)]
    fn gather_rgb8(texels: &[[u8; 4]], width: u32, height: u32, x: Self, y: Self) -> [Self; 3] {
        let a = Avx2::gather_rgb8(texels, width, height, x.0, y.0);
        let b = Avx2::gather_rgb8(texels, width, height, x.1, y.1);
        [Avx2x2(a[0], b[0]), Avx2x2(a[1], b[1]), Avx2x2(a[2], b[2])]
    }
    #[inline(always)]
    fn gather_quad_rgb8(texels: &[[u8; 4]], width: u32, height: u32, x: Self, y: Self) -> [[Self; 3]; 4] {
        let a = Avx2::gather_quad_rgb8(texels, width, height, x.0, y.0);
        let b = Avx2::gather_quad_rgb8(texels, width, height, x.1, y.1);
        let mut out = [[Avx2x2::splat(0.0); 3]; 4];
        for k in 0..4 {
            for c in 0..3 {
                out[k][c] = Avx2x2(a[k][c], b[k][c]);
            }
        }
        out
    }
    #[inline(always)]
    fn gather_rgb16(texels: &[[u16; 4]], width: u32, height: u32, x: Self, y: Self) -> [Self; 3] {
        let a = Avx2::gather_rgb16(texels, width, height, x.0, y.0);
        let b = Avx2::gather_rgb16(texels, width, height, x.1, y.1);
        [Avx2x2(a[0], b[0]), Avx2x2(a[1], b[1]), Avx2x2(a[2], b[2])]
    }
    #[inline(always)]
    fn splat(x: f32) -> Self {
        let v = Avx2::splat(x);
        Avx2x2(v, v)
    }
    #[inline(always)]
    fn from_array(a: [f32; 16]) -> Self {
        let (lo, hi) = a.split_at(8);
        Avx2x2(
            Avx2::from_array(lo.try_into().unwrap_or_default()),
            Avx2::from_array(hi.try_into().unwrap_or_default()),
        )
    }
    #[inline(always)]
    fn to_array(self) -> [f32; 16] {
        let mut a = [0f32; 16];
        a[..8].copy_from_slice(&self.0.to_array());
        a[8..].copy_from_slice(&self.1.to_array());
        a
    }
    #[inline(always)]
    fn add(self, b: Self) -> Self {
        both!(self, add, b)
    }
    #[inline(always)]
    fn sub(self, b: Self) -> Self {
        both!(self, sub, b)
    }
    #[inline(always)]
    fn mul(self, b: Self) -> Self {
        both!(self, mul, b)
    }
    #[inline(always)]
    fn mul_add(self, b: Self, c: Self) -> Self {
        both!(self, mul_add, b, c)
    }
    #[inline(always)]
    fn rsqrt(self) -> Self {
        both!(self, rsqrt)
    }
    #[inline(always)]
    fn rsqrt_positive(self) -> Self {
        both!(self, rsqrt_positive)
    }
    #[inline(always)]
    fn load_splat(s: &Splat) -> Self {
        let v = Avx2::load_splat(s);
        Avx2x2(v, v)
    }
    #[inline(always)]
    fn encode_rgba8(rgb: [Self; 3]) -> [[u8; 4]; 16] {
        let lo = Avx2::encode_rgba8([rgb[0].0, rgb[1].0, rgb[2].0]);
        let hi = Avx2::encode_rgba8([rgb[0].1, rgb[1].1, rgb[2].1]);
        let mut out = [[0u8; 4]; 16];
        out[..8].copy_from_slice(&lo);
        out[8..].copy_from_slice(&hi);
        out
    }
    #[inline(always)]
    fn recip(self) -> Self {
        both!(self, recip)
    }
    #[inline(always)]
    fn min(self, b: Self) -> Self {
        both!(self, min, b)
    }
    #[inline(always)]
    fn max(self, b: Self) -> Self {
        both!(self, max, b)
    }
    #[inline(always)]
    fn lt(self, b: Self) -> Self::M {
        (self.0.lt(b.0), self.1.lt(b.1))
    }
    #[inline(always)]
    fn gt(self, b: Self) -> Self::M {
        (self.0.gt(b.0), self.1.gt(b.1))
    }
    #[inline(always)]
    fn ge(self, b: Self) -> Self::M {
        (self.0.ge(b.0), self.1.ge(b.1))
    }
    #[inline(always)]
    fn finite(self) -> Self::M {
        (self.0.finite(), self.1.finite())
    }
    #[inline(always)]
    fn nan(self) -> Self::M {
        (self.0.nan(), self.1.nan())
    }
    #[inline(always)]
    fn select(m: Self::M, a: Self, b: Self) -> Self {
        Avx2x2(Avx2::select(m.0, a.0, b.0), Avx2::select(m.1, a.1, b.1))
    }
    #[inline(always)]
    fn all_true() -> Self::M {
        (Avx2::all_true(), Avx2::all_true())
    }
    #[inline(always)]
    fn and(m: Self::M, n: Self::M) -> Self::M {
        (Avx2::and(m.0, n.0), Avx2::and(m.1, n.1))
    }
    #[inline(always)]
    fn or(m: Self::M, n: Self::M) -> Self::M {
        (Avx2::or(m.0, n.0), Avx2::or(m.1, n.1))
    }
    #[inline(always)]
    fn not(m: Self::M) -> Self::M {
        (Avx2::not(m.0), Avx2::not(m.1))
    }
    #[inline(always)]
    fn any(m: Self::M) -> bool {
        Avx2::any(Avx2::or(m.0, m.1))
    }
    #[inline(always)]
    fn frexp(self) -> (Self, Self) {
        let (e0, m0) = self.0.frexp();
        let (e1, m1) = self.1.frexp();
        (Avx2x2(e0, e1), Avx2x2(m0, m1))
    }
    #[inline(always)]
    fn pow2i(self) -> Self {
        both!(self, pow2i)
    }
    #[inline(always)]
    fn frexp_folded(self) -> (Self, Self) {
        let (e0, m0) = self.0.frexp_folded();
        let (e1, m1) = self.1.frexp_folded();
        (Avx2x2(e0, e1), Avx2x2(m0, m1))
    }
    #[inline(always)]
    fn scale_pow2(self, k: Self) -> Self {
        both!(self, scale_pow2, k)
    }
    #[inline(always)]
    fn round(self) -> Self {
        both!(self, round)
    }
    #[inline(always)]
    fn floor(self) -> Self {
        both!(self, floor)
    }
    #[inline(always)]
    fn transpose(rows: &[&[f32; 8]]) -> [Self; 8] {
        let (lo, hi) = (Avx2::transpose(&rows[..8]), Avx2::transpose(&rows[8..16]));
        core::array::from_fn(|j| Avx2x2(lo[j], hi[j]))
    }
}
