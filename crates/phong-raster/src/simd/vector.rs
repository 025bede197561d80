//! An 8-lane `f32` vector with two implementations: [`Portable`] (`[f32; 8]` and plain loops,
//! any target, exact reciprocals and reciprocal square roots) and, on x86-64, [`Avx2`] (one `__m256`,
//! AVX2 + FMA intrinsics, with fused multiply-adds and refined reciprocal estimates).
//!
//! The kernels in [`super::kernel`] are written once, generic over [`Vf32`]. The AVX2
//! instantiation is only ever called from functions compiled with `avx2,fma` enabled and reached
//! after the CPU was checked ([`super::avx2_available`]); the methods here are
//! `#[inline(always)]` so that they compile into those callers.
//!
//! Measured (fill scene, 1 thread, perf): the earlier kernel, `[f32; 8]` loops left to LLVM's
//! auto-vectoriser and compiled with AVX2, spent most of its time in scalar code (lane
//! extraction, `vpinsrw`, scalar compares on masks of `bool`): 900 `xmm` against 745 `ymm`
//! instructions. Explicit intrinsics remove that.

/// An 8-lane `f32` vector and its lane mask.
///
/// Comparisons are ordered (false when a lane is NaN); `min` and `max` return `b` when a lane
/// of either is NaN (as x86's `minps`/`maxps`), in both implementations.
pub trait Vf32: Copy {
    /// Lanes.
    const N: usize;
    /// `[f32; N]`.
    type A: Copy + Default + AsRef<[f32]> + AsMut<[f32]>;
    /// A lane mask.
    type M: Copy;
    /// `[[u8; 4]; N]`: a vector's 8-bit RGBA pixels.
    type Px: Copy + Default + AsRef<[[u8; 4]]>;
    /// Every lane `x`.
    fn splat(x: f32) -> Self;
    /// The texels `texels[y·width + x]` of the lanes (`x`, `y` whole numbers, clamped into
    /// `width × height`; NaN reads 0) as their red, green and blue, each `0.0..=255.0`.
    fn gather_rgb8(texels: &[[u8; 4]], width: u32, height: u32, x: Self, y: Self) -> [Self; 3];
    /// The 2×2 texels from `(x, y)` of the lanes (`x`, `y` whole numbers of magnitude below
    /// 2^31; NaN reads column or row 0) in a `width × height` image, both powers of two,
    /// wrapped by repeat: `[(x, y), (x + 1, y), (x, y + 1), (x + 1, y + 1)]`, each as
    /// [`Vf32::gather_rgb8`] gives it. The wrap is a mask, the row a shift.
    fn gather_quad_rgb8(texels: &[[u8; 4]], width: u32, height: u32, x: Self, y: Self) -> [[Self; 3]; 4];
    /// [`Vf32::gather_rgb8`] of 16-bit texels: each channel `0.0..=65535.0`.
    fn gather_rgb16(texels: &[[u16; 4]], width: u32, height: u32, x: Self, y: Self) -> [Self; 3];
    /// From an array.
    fn from_array(a: Self::A) -> Self;
    /// To an array.
    fn to_array(self) -> Self::A;
    /// `a + b`.
    fn add(self, b: Self) -> Self;
    /// `a − b`.
    fn sub(self, b: Self) -> Self;
    /// `a · b`.
    fn mul(self, b: Self) -> Self;
    /// `a · b + c` (fused where the hardware has it).
    fn mul_add(self, b: Self, c: Self) -> Self;
    /// `1/√a`, relative error below 1e-6 (exact in [`Portable`]); `+∞` at 0.
    fn rsqrt(self) -> Self;
    /// `1/√a` for finite `a > 0` (no care for 0: the caller keeps it out), relative error
    /// below 1e-6 (exact in [`Portable`]).
    fn rsqrt_positive(self) -> Self;
    /// `1/a`, relative error below 1e-6 (exact in [`Portable`]).
    fn recip(self) -> Self;
    /// Every lane `s`'s value, loaded whole (a memory operand of the instruction that uses it,
    /// where a broadcast of one `f32` would be an instruction of its own).
    fn load_splat(s: &Splat) -> Self;
    /// `if a < b { a } else { b }`.
    fn min(self, b: Self) -> Self;
    /// `if a > b { a } else { b }`.
    fn max(self, b: Self) -> Self;
    /// `a < b`.
    fn lt(self, b: Self) -> Self::M;
    /// `a > b`.
    fn gt(self, b: Self) -> Self::M;
    /// `a >= b`.
    fn ge(self, b: Self) -> Self::M;
    /// Lanes that are neither infinite nor NaN.
    fn finite(self) -> Self::M;
    /// Lanes that are NaN.
    fn nan(self) -> Self::M;
    /// `m ? a : b`, per lane.
    fn select(m: Self::M, a: Self, b: Self) -> Self;
    /// Every lane true.
    fn all_true() -> Self::M;
    /// `m & n`.
    fn and(m: Self::M, n: Self::M) -> Self::M;
    /// `m | n`.
    fn or(m: Self::M, n: Self::M) -> Self::M;
    /// `!m`.
    fn not(m: Self::M) -> Self::M;
    /// Whether any lane is true.
    fn any(m: Self::M) -> bool;
    /// For finite `a > 0` (normal): `(e, m)` with `a = m · 2^e`, `m` in `[1, 2)`, `e` as a float.
    fn frexp(self) -> (Self, Self);
    /// `2^k` for lanes holding integers `k` in `[−126, 127]`.
    fn pow2i(self) -> Self;
    /// For finite `a > 0` (normal): `(e, m)` with `a = m · 2^e`, `m` in `[√½, √2)`, `e` as a
    /// float (the mantissa folded around 1, for a logarithm without cancellation near 1).
    fn frexp_folded(self) -> (Self, Self);
    /// `a · 2^k` for lanes holding integers `k`, by adding `k` to the exponent's bits: for
    /// normal `a` whose result is normal.
    fn scale_pow2(self, k: Self) -> Self;
    /// Round to the nearest integer, ties to even.
    fn round(self) -> Self;
    /// Round down (`|x| < 2^22`: larger values are whole already, or kept).
    fn floor(self) -> Self;
    /// The lanes' colours `rgb` as 8-bit RGBA pixels: each channel as
    /// [`phong_core::Encoding::Linear`] encodes it (`clamp(c, 0, 1)·255 + 0.5` truncated, NaN
    /// as 0), alpha 255.
    fn encode_rgba8(rgb: [Self; 3]) -> Self::Px;
    /// Transposes `N` rows of 8 floats (lane `i` takes row `i`) into 8 vectors: vector `j`
    /// holds element `j` of every row. How a batch gathers its lanes' plane coefficients
    /// (8 loads and 24 shuffles per 8 lanes in the AVX2 build, instead of 64 scalar stores and
    /// reloads through an array).
    fn transpose(rows: &[&[f32; 8]]) -> [Self; 8];
}

/// The bits of `√½` rounded down to an `f32`: [`Vf32::frexp_folded`] takes the exponent of
/// `a / √½`.
const SQRT_HALF_BITS: i32 = 0x3f35_04f3;

/// One constant repeated in every lane of the widest vector, for [`Vf32::load_splat`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub struct Splat(pub [f32; 16]);

impl Splat {
    /// `x` in every lane.
    pub const fn new(x: f32) -> Splat {
        Splat([x; 16])
    }
}

/// The portable twin: `[f32; 8]`, plain loops, exact `rsqrt` and `recip`.
#[derive(Clone, Copy, Debug)]
pub struct Portable(pub [f32; 8]);

#[inline(always)]
fn lanes<T: Copy + Default>(f: impl Fn(usize) -> T) -> [T; 8] {
    let mut r = [T::default(); 8];
    for (i, x) in r.iter_mut().enumerate() {
        *x = f(i);
    }
    r
}

impl Vf32 for Portable {
    const N: usize = 8;
    type A = [f32; 8];
    type Px = [[u8; 4]; 8];
    type M = [bool; 8];
    // The portable gathers are calls: 8 scalar loads a channel gain nothing from inlining,
    // and inlined into the textured kernels they made them minutes to compile (BENCHMARKS.md, C10).
    #[inline(never)]
    fn gather_rgb8(texels: &[[u8; 4]], width: u32, height: u32, x: Self, y: Self) -> [Self; 3] {
        gather_portable(texels, width, height, x, y)
    }
    #[inline(never)]
    fn gather_rgb16(texels: &[[u16; 4]], width: u32, height: u32, x: Self, y: Self) -> [Self; 3] {
        gather_portable(texels, width, height, x, y)
    }
    #[inline(never)]
    fn gather_quad_rgb8(texels: &[[u8; 4]], width: u32, height: u32, x: Self, y: Self) -> [[Self; 3]; 4] {
        assert!(
            width.is_power_of_two() && height.is_power_of_two(),
            "a repeated power-of-two image"
        );
        let mut out = [[Portable([0.0; 8]); 3]; 4];
        let (wm, hm) = (width as i32 - 1, height as i32 - 1);
        for i in 0..8 {
            // `as` saturates and maps NaN to 0; the masks wrap two's complement by repeat.
            let (xi, yi) = (x.0[i] as i32, y.0[i] as i32);
            for (k, (dx, dy)) in [(0, 0), (1, 0), (0, 1), (1, 1)].into_iter().enumerate() {
                let (xk, yk) = (xi.wrapping_add(dx) & wm, yi.wrapping_add(dy) & hm);
                let t = texels
                    .get(yk as usize * width as usize + xk as usize)
                    .copied()
                    .unwrap_or_default();
                for (o, c) in out[k].iter_mut().zip(t) {
                    o.0[i] = c.into();
                }
            }
        }
        out
    }
    #[inline(always)]
    fn splat(x: f32) -> Self {
        Portable([x; 8])
    }
    #[inline(always)]
    fn from_array(a: [f32; 8]) -> Self {
        Portable(a)
    }
    #[inline(always)]
    fn to_array(self) -> [f32; 8] {
        self.0
    }
    #[inline(always)]
    fn add(self, b: Self) -> Self {
        Portable(lanes(|i| self.0[i] + b.0[i]))
    }
    #[inline(always)]
    fn sub(self, b: Self) -> Self {
        Portable(lanes(|i| self.0[i] - b.0[i]))
    }
    #[inline(always)]
    fn mul(self, b: Self) -> Self {
        Portable(lanes(|i| self.0[i] * b.0[i]))
    }
    #[inline(always)]
    fn mul_add(self, b: Self, c: Self) -> Self {
        Portable(lanes(|i| self.0[i] * b.0[i] + c.0[i]))
    }
    #[inline(always)]
    fn rsqrt(self) -> Self {
        Portable(lanes(|i| 1.0 / self.0[i].sqrt()))
    }
    #[inline(always)]
    fn rsqrt_positive(self) -> Self {
        self.rsqrt()
    }
    #[inline(always)]
    fn encode_rgba8(rgb: [Self; 3]) -> [[u8; 4]; 8] {
        let e = |c: f32| phong_core::Encoding::Linear.encode(c);
        lanes(|i| [e(rgb[0].0[i]), e(rgb[1].0[i]), e(rgb[2].0[i]), 255])
    }
    #[inline(always)]
    fn load_splat(s: &Splat) -> Self {
        Portable(lanes(|i| s.0[i]))
    }
    #[inline(always)]
    fn recip(self) -> Self {
        Portable(lanes(|i| 1.0 / self.0[i]))
    }
    #[inline(always)]
    fn min(self, b: Self) -> Self {
        Portable(lanes(|i| if self.0[i] < b.0[i] { self.0[i] } else { b.0[i] }))
    }
    #[inline(always)]
    fn max(self, b: Self) -> Self {
        Portable(lanes(|i| if self.0[i] > b.0[i] { self.0[i] } else { b.0[i] }))
    }
    #[inline(always)]
    fn lt(self, b: Self) -> Self::M {
        lanes(|i| self.0[i] < b.0[i])
    }
    #[inline(always)]
    fn gt(self, b: Self) -> Self::M {
        lanes(|i| self.0[i] > b.0[i])
    }
    #[inline(always)]
    fn ge(self, b: Self) -> Self::M {
        lanes(|i| self.0[i] >= b.0[i])
    }
    #[inline(always)]
    fn finite(self) -> Self::M {
        lanes(|i| self.0[i].is_finite())
    }
    #[inline(always)]
    fn nan(self) -> Self::M {
        lanes(|i| self.0[i].is_nan())
    }
    #[inline(always)]
    fn select(m: Self::M, a: Self, b: Self) -> Self {
        Portable(lanes(|i| if m[i] { a.0[i] } else { b.0[i] }))
    }
    #[inline(always)]
    fn all_true() -> Self::M {
        [true; 8]
    }
    #[inline(always)]
    fn and(m: Self::M, n: Self::M) -> Self::M {
        lanes(|i| m[i] & n[i])
    }
    #[inline(always)]
    fn or(m: Self::M, n: Self::M) -> Self::M {
        lanes(|i| m[i] | n[i])
    }
    #[inline(always)]
    fn not(m: Self::M) -> Self::M {
        lanes(|i| !m[i])
    }
    #[inline(always)]
    fn any(m: Self::M) -> bool {
        m.iter().any(|&b| b)
    }
    #[inline(always)]
    fn frexp(self) -> (Self, Self) {
        let e = lanes(|i| ((self.0[i].to_bits() >> 23) & 0xff) as i32 as f32 - 127.0);
        let m = lanes(|i| f32::from_bits((self.0[i].to_bits() & 0x007f_ffff) | 0x3f80_0000));
        (Portable(e), Portable(m))
    }
    #[inline(always)]
    fn pow2i(self) -> Self {
        Portable(lanes(|i| f32::from_bits(((self.0[i] as i32 + 127) as u32) << 23)))
    }
    #[inline(always)]
    fn frexp_folded(self) -> (Self, Self) {
        let e = lanes(|i| (self.0[i].to_bits() as i32).wrapping_sub(SQRT_HALF_BITS) >> 23);
        let m = lanes(|i| f32::from_bits((self.0[i].to_bits() as i32).wrapping_sub(e[i] << 23) as u32));
        (Portable(e.map(|e| e as f32)), Portable(m))
    }
    #[inline(always)]
    fn scale_pow2(self, k: Self) -> Self {
        Portable(lanes(|i| {
            f32::from_bits((self.0[i].to_bits() as i32).wrapping_add((k.0[i] as i32) << 23) as u32)
        }))
    }
    #[inline(always)]
    fn round(self) -> Self {
        // 1.5·2^23: adding and subtracting it rounds to nearest even for |x| < 2^22.
        const MAGIC: f32 = 12_582_912.0;
        Portable(lanes(|i| {
            let x = self.0[i];
            if x.abs() < 4_194_304.0 { (x + MAGIC) - MAGIC } else { x }
        }))
    }
    #[inline(always)]
    fn floor(self) -> Self {
        let r = self.round();
        Portable(lanes(|i| if r.0[i] > self.0[i] { r.0[i] - 1.0 } else { r.0[i] }))
    }
    #[inline(always)]
    fn transpose(rows: &[&[f32; 8]]) -> [Self; 8] {
        let mut out = [Portable([0.0; 8]); 8];
        for (i, row) in rows.iter().enumerate().take(8) {
            for (j, o) in out.iter_mut().enumerate() {
                o.0[i] = row[j];
            }
        }
        out
    }
}

/// [`Vf32::gather_rgb8`] and `gather_rgb16` lane by lane.
#[inline(always)]
fn gather_portable<T: Copy + Default + Into<f32>>(
    texels: &[[T; 4]],
    width: u32,
    height: u32,
    x: Portable,
    y: Portable,
) -> [Portable; 3] {
    let mut out = [Portable([0.0; 8]); 3];
    for i in 0..8 {
        // `as` saturates and maps NaN to 0.
        let xi = (x.0[i] as i64).clamp(0, i64::from(width) - 1) as usize;
        let yi = (y.0[i] as i64).clamp(0, i64::from(height) - 1) as usize;
        let t = texels.get(yi * width as usize + xi).copied().unwrap_or_default();
        for (o, c) in out.iter_mut().zip(t) {
            o.0[i] = c.into();
        }
    }
    out
}

#[cfg(target_arch = "x86_64")]
pub use avx2::{Avx2, Avx2x2};

#[cfg(target_arch = "x86_64")]
mod avx2;

#[cfg(test)]
mod tests {
    use super::*;

    /// Element `j` of row `i` lands in lane `i` of vector `j`, for 8 and (AVX2) 16 lanes.
    fn check_transpose<V: Vf32>() {
        let rows: Vec<[f32; 8]> = (0..V::N)
            .map(|i| core::array::from_fn(|j| (i * 8 + j) as f32))
            .collect();
        let refs: Vec<&[f32; 8]> = rows.iter().collect();
        let out = V::transpose(&refs);
        for (j, v) in out.iter().enumerate() {
            let a = v.to_array();
            for (i, row) in rows.iter().enumerate() {
                assert_eq!(a.as_ref()[i], row[j], "row {i}, element {j}");
            }
        }
    }

    #[test]
    fn transpose_moves_rows_into_lanes() {
        check_transpose::<Portable>();
        #[cfg(target_arch = "x86_64")]
        if crate::simd::avx2_available() {
            #[target_feature(enable = "avx2,fma")]
            fn avx2() {
                check_transpose::<Avx2>();
                check_transpose::<Avx2x2>();
            }
            // SAFETY: the CPU has AVX2 and FMA (checked above).
            unsafe { avx2() };
        }
    }
}
