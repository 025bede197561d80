//! SIMD: the 8-lane shading kernel and its runtime dispatch. The only module of phong with
//! `unsafe`, confined to the dispatch below.
//!
//! The kernel is portable Rust ([`kernel`]) that LLVM vectorises. [`shade8`] runs it as
//! compiled for the target's baseline (SSE2 on x86-64: 4-wide), or, when the CPU has AVX2 and
//! FMA and the caller allows it, the same code compiled with those features enabled (8-wide).
//! Rust never contracts `a·b + c` into a fused multiply-add on its own, so both builds compute
//! bit-identical results (tested: `tests/fast.rs`).

pub mod kernel;

use glam::Vec3;
pub use kernel::{LANES, Prepared, Shaded8};

/// Whether the AVX2 build may be used: the CPU has AVX2 and FMA (checked once, cached by std).
pub fn avx2_available() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn shade8_avx2(p: &Prepared, position: &[Vec3; LANES], normal: &[Vec3; LANES]) -> Shaded8 {
    kernel::shade8(p, position, normal)
}

/// [`kernel::shade8`], with the AVX2 build when `avx2` is true (the caller checked
/// [`avx2_available`]), else the baseline build.
#[inline]
pub fn shade8(avx2: bool, p: &Prepared, position: &[Vec3; LANES], normal: &[Vec3; LANES]) -> Shaded8 {
    #[cfg(target_arch = "x86_64")]
    if avx2 {
        debug_assert!(avx2_available());
        // SAFETY: `avx2` is only true when `avx2_available()` found AVX2 and FMA on this CPU.
        return unsafe { shade8_avx2(p, position, normal) };
    }
    let _ = avx2;
    kernel::shade8(p, position, normal)
}
