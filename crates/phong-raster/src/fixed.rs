//! The fixed-point grid (1/256 pixel, [`SUBPIXEL_BITS`]) and the small always-inlined
//! helpers of the per-triangle and per-pixel loops.

use phong_core::Samples;
use phong_core::limits::{SUBPIXEL_BITS, sample_pattern};

/// One pixel in grid units.
pub(crate) const ONE: f32 = (1u32 << SUBPIXEL_BITS) as f32;
/// Half a pixel in grid units: a pixel's centre from its corner.
pub(crate) const HALF: i64 = 1 << (SUBPIXEL_BITS - 1);

/// The sample pattern of `samples` per pixel in grid units, from the pixel's corner.
pub(crate) fn pattern(samples: Samples) -> Vec<(i64, i64)> {
    sample_pattern(samples)
        .into_iter()
        .map(|(x, y)| ((x * ONE).round() as i64, (y * ONE).round() as i64))
        .collect()
}

/// `v.round() as i64` (half away from zero) without a libm call, exact for `|v| < 2^24`
/// (the guard band keeps snapped coordinates below that): in `f64`, `|v| + ½` is exact and
/// truncation is the floor. Branch-free (BENCHMARKS.md, C1).
#[inline]
pub(crate) fn round_i64(v: f32) -> i64 {
    let r = (f64::from(v).abs() + 0.5) as i64;
    if v < 0.0 { -r } else { r }
}

/// `[f(0), f(1), f(2)]`, always inlined: `[T; 3]::map` was not, in these loops (C2).
#[inline(always)]
pub(crate) fn each3<U>(f: impl Fn(usize) -> U) -> [U; 3] {
    [f(0), f(1), f(2)]
}

/// `a.map(f)` for three elements, always inlined (see [`each3`]).
#[inline(always)]
pub(crate) fn map3<T: Copy, U>(a: [T; 3], f: impl Fn(T) -> U) -> [U; 3] {
    [f(a[0]), f(a[1]), f(a[2])]
}

#[cfg(test)]
mod tests {
    use super::round_i64;

    #[test]
    fn round_matches_f32_round() {
        let mut x = -17_000_000.0f32;
        while x < 17_000_000.0 {
            for v in [
                x,
                x + 0.5,
                x - 0.5,
                x + 0.49999997,
                x + 0.25,
                f32::from_bits(x.to_bits() + 1),
            ] {
                assert_eq!(round_i64(v), v.round() as i64, "{v}");
            }
            x += 9_973.37;
        }
        for v in [0.49999997f32, -0.49999997, 0.5, -0.5, 1.5, -2.5, 8388607.5, -8388607.5] {
            assert_eq!(round_i64(v), v.round() as i64, "{v}");
        }
    }
}
