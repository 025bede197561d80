//! SIMD: the 8-lane kernels and their runtime dispatch. The only module of phong with
//! `unsafe`: the AVX2 vector type's intrinsics (`vector/avx2.rs`) and the calls below into functions
//! compiled with AVX2 and FMA.
//!
//! The kernels ([`kernel`]) are written once over the `vector::Vf32` trait. Each entry point
//! here runs them either on `vector::Portable` (plain `[f32; 8]` loops, any CPU; LLVM
//! vectorises what it can) or, when the CPU has AVX2 and FMA and the caller allows it, on
//! `vector::Avx2` inside a `#[target_feature(enable = "avx2,fma")]` function. The two builds
//! differ in rounding (fused multiply-adds, refined reciprocal estimates): both are tested
//! against `phong_core::shade`, and the images of both against the reference path. Most
//! per-pixel shading runs a third build where the CPU has AVX-512: the AVX2 code compiled
//! with AVX-512VL as well, for its 32 vector registers ([`Isa::wide`]); its images are the
//! AVX2 build's, bit for bit.

mod filter;
mod group;
pub mod kernel;
mod lean;
mod planes;
/// Private to the crate: the AVX2 vector type may only be used where AVX2 and FMA were detected.
mod project;
mod sampler;
mod tile;
mod vector;
mod visible;

use crate::Kernels;
use glam::Vec3;
pub use kernel::{Batch, LANES, Planes, Prepared, Shaded8, Term, VertexTerm};
pub use lean::Lean;
pub use planes::ColourPlanes;
pub use project::WindowVertex;
pub use sampler::{Unsampled, VectorMaps};
pub(crate) use tile::covered_span;
pub use tile::{GouraudTri, TilePixel, gouraud_tile};
pub(crate) use visible::{SampleBuffers, multi_visible, multi_visible_run, single_visible};

/// Whether the CPU has AVX2 and FMA (checked once, cached by std).
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

/// Whether the CPU has the AVX-512 features (F, VL, BW, DQ) that the shading kernels'
/// wide-register build is compiled with (see [`Isa::wide`]).
#[cfg(target_arch = "x86_64")]
fn avx512_available() -> bool {
    std::arch::is_x86_feature_detected!("avx512f")
        && std::arch::is_x86_feature_detected!("avx512vl")
        && std::arch::is_x86_feature_detected!("avx512bw")
        && std::arch::is_x86_feature_detected!("avx512dq")
}

/// The instruction set the kernels run on, chosen once per frame. An AVX2 `Isa` is made only
/// by [`Isa::detect`] on a CPU with AVX2 and FMA (and a wide one only on a CPU with AVX-512F,
/// VL, BW and DQ too), so holding one is what the AVX2 builds' `unsafe` calls rely on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Isa {
    avx2: bool,
    wide: bool,
}

impl Isa {
    /// Plain Rust (`[f32; 8]` loops): any CPU.
    pub const PORTABLE: Isa = Isa {
        avx2: false,
        wide: false,
    };

    /// AVX2 and FMA where the CPU has them and `allow_avx2`, else [`Isa::PORTABLE`]; with wide
    /// registers ([`Isa::wide`]) where the CPU has AVX-512 and `allow_avx512`.
    pub fn detect(kernels: Kernels) -> Isa {
        let avx2 = kernels != Kernels::Portable && avx2_available();
        #[cfg(target_arch = "x86_64")]
        let wide = avx2 && kernels == Kernels::Auto && avx512_available();
        #[cfg(not(target_arch = "x86_64"))]
        let wide = false;
        Isa { avx2, wide }
    }

    /// Whether this is the AVX2 build.
    pub fn is_avx2(self) -> bool {
        self.avx2
    }

    /// Whether the per-pixel shading kernels (untextured, and textured in the common form:
    /// diffuse and specular maps, light per pixel) run in their wide-register build: the same
    /// AVX2 code compiled with AVX-512VL, so that LLVM has 32 vector registers instead of 16
    /// (the textured kernels spill less). The arithmetic is the same instructions: the images
    /// are the AVX2 build's, bit for bit (tested).
    pub fn wide(self) -> bool {
        self.wide
    }
}

/// Defines one kernel entry point twice: `$avx2`, compiled with AVX2 and FMA, and `$wide`, the
/// same body compiled with AVX-512F, VL, BW and DQ as well (see [`Isa::wide`]). Generics go
/// in brackets.
macro_rules! avx2_and_wide {
    (fn $avx2:ident / $wide:ident [$($g:tt)*] ($($arg:ident: $ty:ty),* $(,)?) $(-> $ret:ty)? $body:block) => {
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx2,fma")]
        fn $avx2<$($g)*>($($arg: $ty),*) $(-> $ret)? $body

        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx2,fma,avx512f,avx512vl,avx512bw,avx512dq")]
        fn $wide<$($g)*>($($arg: $ty),*) $(-> $ret)? $body
    };
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn shade8_avx2(p: &Prepared, position: &[Vec3; LANES], normal: &[Vec3; LANES]) -> Shaded8 {
    kernel::shade_points::<vector::Avx2>(p, position, normal)
}

/// `phong_core::shade` on 8 points (`pow` approximated, see `kernel.rs`), by `isa`'s build.
#[inline]
pub fn shade8(isa: Isa, p: &Prepared, position: &[Vec3; LANES], normal: &[Vec3; LANES]) -> Shaded8 {
    #[cfg(target_arch = "x86_64")]
    if isa.is_avx2() {
        // SAFETY: an AVX2 `Isa` exists only where the CPU has AVX2 and FMA (`Isa::detect`).
        return unsafe { shade8_avx2(p, position, normal) };
    }
    let _ = isa;
    kernel::shade8(p, position, normal)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn shade8_lean_avx2(p: &Prepared, lean: &Lean, position: &[Vec3; LANES], normal: &[Vec3; LANES]) -> [[f32; LANES]; 3] {
    kernel::lean_points::<vector::Avx2>(p, lean, position, normal)
}

/// The lean kernel's colour (`lean.rs`) on 8 points, by `isa`'s build; `None` where it does
/// not shade `p`'s objects.
pub fn shade8_lean(
    isa: Isa,
    p: &Prepared,
    position: &[Vec3; LANES],
    normal: &[Vec3; LANES],
) -> Option<[[f32; LANES]; 3]> {
    let lean = Lean::of(p)?;
    #[cfg(target_arch = "x86_64")]
    if isa.is_avx2() {
        // SAFETY: an AVX2 `Isa` exists only where the CPU has AVX2 and FMA (`Isa::detect`).
        return Some(unsafe { shade8_lean_avx2(p, &lean, position, normal) });
    }
    let _ = isa;
    Some(kernel::lean_points::<vector::Portable>(p, &lean, position, normal))
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn shade_batch_lit_avx2<'p>(
    prep: &Prepared,
    n: usize,
    lane: impl Fn(usize) -> (f32, f32, &'p Planes),
    out: impl FnMut(usize, [f32; 3], [f32; 3]),
) {
    kernel::shade_batch_lit::<vector::Avx2x2>(prep, n, lane, out)
}

/// Interpolates and lights `n` pixels of a textured object, 8 at a time: `out(i, primary,
/// specular)` takes each pixel's light before its texels (see `kernel::shade_batch_lit`).
#[inline]
pub fn shade_batch_lit<'p>(
    isa: Isa,
    prep: &Prepared,
    n: usize,
    lane: impl Fn(usize) -> (f32, f32, &'p Planes),
    out: impl FnMut(usize, [f32; 3], [f32; 3]),
) {
    #[cfg(target_arch = "x86_64")]
    if isa.is_avx2() {
        // SAFETY: an AVX2 `Isa` exists only where the CPU has AVX2 and FMA (`Isa::detect`).
        unsafe { shade_batch_lit_avx2(prep, n, lane, out) };
        return;
    }
    let _ = isa;
    kernel::shade_batch_lit::<vector::Portable>(prep, n, lane, out)
}

avx2_and_wide! {
    fn shade_batch_textured_avx2 / shade_batch_textured_wide ['p, const FULL: bool, const PER_VERTEX: bool] (
        prep: (&Prepared, Option<&Lean>),
        maps: &VectorMaps,
        n: usize,
        lane: impl Fn(usize) -> (f32, f32, &'p Planes, &'p Planes),
        out: impl FnMut(usize, [f32; 3]),
        unsampled: &mut Vec<Unsampled<usize>>,
    ) {
        sampler::shade_batch_textured::<vector::Avx2x2, FULL, PER_VERTEX>(prep, maps, n, lane, out, unsampled)
    }
}

/// Interpolates, lights and textures `n` pixels of an object whose maps the vector sampler
/// covers ([`VectorMaps`]): `lane(i)` gives pixel `i`'s centre, its triangle's planes and its
/// texture coordinates' planes; `out(i, rgb)` takes its colour, or `unsampled` its light where
/// the maps must be sampled per pixel ([`Unsampled`]). The light by the lean kernel where
/// `prep` comes with its data.
#[inline]
pub fn shade_batch_textured<'p>(
    isa: Isa,
    prep: (&Prepared, Option<&Lean>),
    maps: &VectorMaps,
    n: usize,
    lane: impl Fn(usize) -> (f32, f32, &'p Planes, &'p Planes),
    out: impl FnMut(usize, [f32; 3]),
    unsampled: &mut Vec<Unsampled<usize>>,
) {
    #[cfg(target_arch = "x86_64")]
    if isa.is_avx2() {
        // SAFETY: an AVX2 `Isa` exists only where the CPU has AVX2 and FMA, a wide one only
        // where it has AVX-512F, VL, BW and DQ too (`Isa::detect`).
        unsafe {
            // The wide build for the common form only (diffuse and specular maps, light per
            // pixel): the general and Gouraud forms' wide builds made the release build 47 s
            // longer (benches/HISTORY.md, "The shading kernels' wide-register build").
            match (maps.full(), maps.per_vertex()) {
                (false, false) if isa.wide() => {
                    shade_batch_textured_wide::<false, false>(prep, maps, n, lane, out, unsampled)
                }
                (true, true) => shade_batch_textured_avx2::<true, true>(prep, maps, n, lane, out, unsampled),
                (true, false) => shade_batch_textured_avx2::<true, false>(prep, maps, n, lane, out, unsampled),
                (false, true) => shade_batch_textured_avx2::<false, true>(prep, maps, n, lane, out, unsampled),
                (false, false) => shade_batch_textured_avx2::<false, false>(prep, maps, n, lane, out, unsampled),
            }
        };
        return;
    }
    let _ = isa;
    type P = vector::Portable;
    match (maps.full(), maps.per_vertex()) {
        (true, true) => sampler::shade_batch_textured::<P, true, true>(prep, maps, n, lane, out, unsampled),
        (true, false) => sampler::shade_batch_textured::<P, true, false>(prep, maps, n, lane, out, unsampled),
        (false, true) => sampler::shade_batch_textured::<P, false, true>(prep, maps, n, lane, out, unsampled),
        (false, false) => sampler::shade_batch_textured::<P, false, false>(prep, maps, n, lane, out, unsampled),
    }
}

avx2_and_wide! {
    fn shade_group_textured_avx2 / shade_group_textured_wide [const FULL: bool, const PER_VERTEX: bool] (
        prep: (&Prepared, Option<&Lean>),
        maps: &VectorMaps,
        planes: (&Planes, &Planes),
        origin: (u32, u32),
        pixels: &[u32],
        out: impl FnMut(u32, [f32; 3]),
        unsampled: &mut Vec<Unsampled<u32>>,
    ) -> usize {
        sampler::shade_group_textured::<vector::Avx2x2, FULL, PER_VERTEX>(
            prep, maps, planes, origin, pixels, out, unsampled,
        )
    }
}

/// [`shade_batch_textured`] for the pixels of one triangle, its planes and its coordinates'
/// planes broadcast (as [`shade_group`]): whole vectors only; returns how many of `pixels`
/// (from the start) were shaded.
#[inline]
pub fn shade_group_textured(
    isa: Isa,
    (prep, maps): ((&Prepared, Option<&Lean>), &VectorMaps),
    planes: (&Planes, &Planes),
    origin: (u32, u32),
    pixels: &[u32],
    out: impl FnMut(u32, [f32; 3]),
    unsampled: &mut Vec<Unsampled<u32>>,
) -> usize {
    #[cfg(target_arch = "x86_64")]
    if isa.is_avx2() {
        // SAFETY: an AVX2 `Isa` exists only where the CPU has AVX2 and FMA, a wide one only
        // where it has AVX-512F, VL, BW and DQ too (`Isa::detect`).
        return unsafe {
            let (p, m, o, u) = (prep, maps, origin, unsampled);
            // The wide build for the common form only (see `shade_batch_textured`).
            match (maps.full(), maps.per_vertex()) {
                (false, false) if isa.wide() => {
                    shade_group_textured_wide::<false, false>(p, m, planes, o, pixels, out, u)
                }
                (true, true) => shade_group_textured_avx2::<true, true>(p, m, planes, o, pixels, out, u),
                (true, false) => shade_group_textured_avx2::<true, false>(p, m, planes, o, pixels, out, u),
                (false, true) => shade_group_textured_avx2::<false, true>(p, m, planes, o, pixels, out, u),
                (false, false) => shade_group_textured_avx2::<false, false>(p, m, planes, o, pixels, out, u),
            }
        };
    }
    let _ = isa;
    type P = vector::Portable;
    match (maps.full(), maps.per_vertex()) {
        (true, true) => {
            sampler::shade_group_textured::<P, true, true>(prep, maps, planes, origin, pixels, out, unsampled)
        }
        (true, false) => {
            sampler::shade_group_textured::<P, true, false>(prep, maps, planes, origin, pixels, out, unsampled)
        }
        (false, true) => {
            sampler::shade_group_textured::<P, false, true>(prep, maps, planes, origin, pixels, out, unsampled)
        }
        (false, false) => {
            sampler::shade_group_textured::<P, false, false>(prep, maps, planes, origin, pixels, out, unsampled)
        }
    }
}

avx2_and_wide! {
    fn shade_batch_avx2 / shade_batch_wide ['p] (
        batch: Batch,
        n: usize,
        lane: impl Fn(usize) -> (f32, f32, &'p Planes),
        out: impl FnMut(usize, [f32; 3]),
    ) {
        kernel::shade_batch::<vector::Avx2x2>(batch, n, lane, out)
    }
}

avx2_and_wide! {
    fn shade_batch8_avx2 / shade_batch8_wide ['p] (
        batch: Batch,
        n: usize,
        lane: impl Fn(usize) -> (f32, f32, &'p Planes),
        out: impl FnMut(usize, [u8; 4]),
    ) {
        kernel::shade_batch8::<vector::Avx2x2>(batch, n, lane, out)
    }
}

/// [`shade_batch`] with the colours encoded to 8-bit RGBA in the kernel, as
/// `Encoding::Linear` encodes them (alpha 255): `out(i, pixel)`.
#[inline]
pub fn shade_batch8<'p>(
    isa: Isa,
    batch: Batch,
    n: usize,
    lane: impl Fn(usize) -> (f32, f32, &'p Planes),
    out: impl FnMut(usize, [u8; 4]),
) {
    #[cfg(target_arch = "x86_64")]
    if isa.is_avx2() {
        // SAFETY: an AVX2 `Isa` exists only where the CPU has AVX2 and FMA, a wide one only
        // where it has AVX-512F, VL, BW and DQ too (`Isa::detect`).
        unsafe {
            if isa.wide() {
                shade_batch8_wide(batch, n, lane, out)
            } else {
                shade_batch8_avx2(batch, n, lane, out)
            }
        };
        return;
    }
    let _ = isa;
    kernel::shade_batch8::<vector::Portable>(batch, n, lane, out)
}

/// Interpolates and shades `n` pixels, 8 at a time: `lane(i)` gives pixel `i`'s centre and its
/// triangle's [`Planes`], `out(i, rgb)` takes its colour.
#[inline]
pub fn shade_batch<'p>(
    isa: Isa,
    batch: Batch,
    n: usize,
    lane: impl Fn(usize) -> (f32, f32, &'p Planes),
    out: impl FnMut(usize, [f32; 3]),
) {
    #[cfg(target_arch = "x86_64")]
    if isa.is_avx2() {
        // SAFETY: an AVX2 `Isa` exists only where the CPU has AVX2 and FMA, a wide one only
        // where it has AVX-512F, VL, BW and DQ too (`Isa::detect`).
        unsafe {
            if isa.wide() {
                shade_batch_wide(batch, n, lane, out)
            } else {
                shade_batch_avx2(batch, n, lane, out)
            }
        };
        return;
    }
    let _ = isa;
    kernel::shade_batch::<vector::Portable>(batch, n, lane, out)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn light_vertices_avx2(
    p: &Prepared,
    term: VertexTerm,
    positions: &[Vec3],
    normals: &[Vec3],
    flip: bool,
    out: &mut [Vec3],
) {
    kernel::light_vertices::<vector::Avx2x2>(p, term, positions, normals, flip, out)
}

/// Gouraud's vertex lighting: `out[i]` = `term` of `phong_core::shade` at `positions[i]` with
/// `normals[i]` (negated with `flip`), `pow` approximated as in `kernel.rs` (AVX2: 16 lanes);
/// the colour by the lean kernel with [`VertexTerm::Lean`] (see `lean.rs`).
pub fn light_vertices(
    isa: Isa,
    p: &Prepared,
    term: VertexTerm,
    positions: &[Vec3],
    normals: &[Vec3],
    flip: bool,
    out: &mut [Vec3],
) {
    assert!(positions.len() == normals.len() && out.len() == positions.len());
    #[cfg(target_arch = "x86_64")]
    if isa.is_avx2() {
        // SAFETY: an AVX2 `Isa` exists only where the CPU has AVX2 and FMA (`Isa::detect`).
        return unsafe { light_vertices_avx2(p, term, positions, normals, flip, out) };
    }
    let _ = isa;
    kernel::light_vertices::<vector::Portable>(p, term, positions, normals, flip, out)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn light_vertices_lit_avx2(p: &Prepared, positions: &[Vec3], normals: &[Vec3], flip: bool, out: [&mut [Vec3]; 2]) {
    kernel::light_vertices_lit::<vector::Avx2x2>(p, positions, normals, flip, out)
}

/// Gouraud's vertex lighting of a textured object: `out[0][i]` its primary colour (emission,
/// ambient and diffuse) and `out[1][i]` its specular colour at `positions[i]` with
/// `normals[i]` (negated with `flip`), each clamped where the options clamp, as
/// `phong_core::light` makes them (`pow` approximated as in `kernel.rs`).
pub fn light_vertices_lit(
    isa: Isa,
    p: &Prepared,
    positions: &[Vec3],
    normals: &[Vec3],
    flip: bool,
    out: [&mut [Vec3]; 2],
) {
    assert!(positions.len() == normals.len() && out.iter().all(|o| o.len() == positions.len()));
    #[cfg(target_arch = "x86_64")]
    if isa.is_avx2() {
        // SAFETY: an AVX2 `Isa` exists only where the CPU has AVX2 and FMA (`Isa::detect`).
        return unsafe { light_vertices_lit_avx2(p, positions, normals, flip, out) };
    }
    let _ = isa;
    kernel::light_vertices_lit::<vector::Portable>(p, positions, normals, flip, out)
}

/// The lanes of [`shade_group`]'s vectors: it shades whole vectors only.
pub fn group_lanes(isa: Isa) -> usize {
    #[cfg(target_arch = "x86_64")]
    if isa.is_avx2() {
        return <vector::Avx2x2 as vector::Vf32>::N;
    }
    let _ = isa;
    <vector::Portable as vector::Vf32>::N
}

avx2_and_wide! {
    fn shade_group_avx2 / shade_group_wide [] (
        batch: Batch,
        planes: &Planes,
        origin: (u32, u32),
        pixels: &[u32],
        out: impl FnMut(u32, [&[f32]; 3]),
    ) -> usize {
        group::shade_group::<vector::Avx2x2>(batch, planes, origin, pixels, out)
    }
}

/// Interpolates and shades the pixels of one triangle (its [`Planes`] broadcast to all lanes):
/// `pixels` are `row << 16 | column` from `origin`; `out(pixel, [r, g, b])` takes the colours
/// of that pixel and of the ones after it on its row (a vector's run), or of that pixel
/// alone. Whole vectors only: returns how many of `pixels` (from the start) were shaded.
#[inline]
pub fn shade_group(
    isa: Isa,
    batch: Batch,
    planes: &Planes,
    origin: (u32, u32),
    pixels: &[u32],
    out: impl FnMut(u32, [&[f32]; 3]),
) -> usize {
    #[cfg(target_arch = "x86_64")]
    if isa.is_avx2() {
        // SAFETY: an AVX2 `Isa` exists only where the CPU has AVX2 and FMA, a wide one only
        // where it has AVX-512F, VL, BW and DQ too (`Isa::detect`).
        return unsafe {
            if isa.wide() {
                shade_group_wide(batch, planes, origin, pixels, out)
            } else {
                shade_group_avx2(batch, planes, origin, pixels, out)
            }
        };
    }
    let _ = isa;
    group::shade_group::<vector::Portable>(batch, planes, origin, pixels, out)
}

avx2_and_wide! {
    fn shade_group8_avx2 / shade_group8_wide [] (
        batch: Batch,
        planes: &Planes,
        origin: (u32, u32),
        pixels: &[u32],
        out: impl FnMut(u32, &[[u8; 4]]),
    ) -> usize {
        group::shade_group8::<vector::Avx2x2>(batch, planes, origin, pixels, out)
    }
}

/// [`shade_group`] with the colours encoded to 8-bit RGBA in the kernel, as
/// `Encoding::Linear` encodes them (alpha 255): `out(pixel, pixels)` takes a run of a row or
/// one pixel.
#[inline]
pub fn shade_group8(
    isa: Isa,
    batch: Batch,
    planes: &Planes,
    origin: (u32, u32),
    pixels: &[u32],
    out: impl FnMut(u32, &[[u8; 4]]),
) -> usize {
    #[cfg(target_arch = "x86_64")]
    if isa.is_avx2() {
        // SAFETY: an AVX2 `Isa` exists only where the CPU has AVX2 and FMA, a wide one only
        // where it has AVX-512F, VL, BW and DQ too (`Isa::detect`).
        return unsafe {
            if isa.wide() {
                shade_group8_wide(batch, planes, origin, pixels, out)
            } else {
                shade_group8_avx2(batch, planes, origin, pixels, out)
            }
        };
    }
    let _ = isa;
    group::shade_group8::<vector::Portable>(batch, planes, origin, pixels, out)
}

/// The fast setup's vertex stage (see `project.rs`): `out[i] = make(vertex)` for each vertex
/// of `positions`, its window position (in 1/`one` pixel, for a `w × h` window), depth, `1/w`
/// and outcode after `clip_from_world`, bit for bit `scalar(position)`'s, which makes the
/// vertices the vector kernel leaves and every vertex without AVX2.
#[inline]
pub fn project_vertices<O>(
    isa: Isa,
    clip_from_world: &glam::Mat4,
    (w, h, one): (f32, f32, f32),
    positions: &[Vec3],
    out: &mut [O],
    make: impl Fn(WindowVertex) -> O,
    scalar: impl Fn(Vec3) -> O,
) {
    #[cfg(target_arch = "x86_64")]
    if isa.is_avx2() {
        // SAFETY: an AVX2 `Isa` exists only where the CPU has AVX2 and FMA (`Isa::detect`).
        return unsafe { project::project_avx2(clip_from_world, (w, h, one), positions, out, make, scalar) };
    }
    let _ = (isa, clip_from_world, w, h, one, make);
    for (o, &p) in out.iter_mut().zip(positions) {
        *o = scalar(p);
    }
}

/// Fills `dst` with `value` by non-temporal stores where `dst` is 16-byte aligned (on x86-64),
/// else by plain stores: the background of a tile is written once and not read back by the
/// renderer, so its cache lines need not be fetched before being written. Call
/// [`stream_fence`] before the tile's pixels are read.
pub fn stream_fill(dst: &mut [[f32; 4]], value: [f32; 4]) {
    #[cfg(target_arch = "x86_64")]
    if (dst.as_ptr() as usize).is_multiple_of(16) {
        use core::arch::x86_64::{_mm_loadu_ps, _mm_stream_ps};
        // SAFETY: SSE is part of x86-64; `value` is 4 readable f32.
        let v = unsafe { _mm_loadu_ps(value.as_ptr()) };
        for d in dst {
            // SAFETY: SSE is part of x86-64; `d` is 4 writable f32 at a 16-byte aligned address
            // (every element of a 16-byte aligned slice of `[f32; 4]` is).
            unsafe { _mm_stream_ps(d.as_mut_ptr(), v) };
        }
        return;
    }
    dst.fill(value);
}

/// Copies `src` into `dst` (the same length) by non-temporal stores where `dst` is 16-byte
/// aligned (on x86-64), else by plain stores: a tile drawn in a cache-resident buffer reaches
/// the image without its cache lines being fetched first (BENCHMARKS.md, R2). Call
/// [`stream_fence`] before the image is read.
pub fn stream_copy(dst: &mut [[f32; 4]], src: &[[f32; 4]]) {
    assert_eq!(dst.len(), src.len());
    #[cfg(target_arch = "x86_64")]
    if (dst.as_ptr() as usize).is_multiple_of(16) {
        use core::arch::x86_64::{_mm_loadu_ps, _mm_stream_ps};
        for (d, s) in dst.iter_mut().zip(src) {
            // SAFETY: SSE is part of x86-64; `s` is 4 readable f32, `d` 4 writable f32 at a
            // 16-byte aligned address (every element of a 16-byte aligned slice of `[f32; 4]`
            // is).
            unsafe { _mm_stream_ps(d.as_mut_ptr(), _mm_loadu_ps(s.as_ptr())) };
        }
        return;
    }
    dst.copy_from_slice(src);
}

/// `dst[i]` = `src[i]` in 8 bits, every channel as [`phong_core::Encoding::Linear`] encodes
/// it: `(clamp(c, 0, 1) · 255 + 0.5)` truncated, NaN as 0. By SSE2 on x86-64 (`maxps` with 0
/// second maps NaN to 0; the product and sum rounded as the scalar code rounds them), else
/// by the scalar encoding.
pub fn encode_linear(dst: &mut [[u8; 4]], src: &[[f32; 4]]) {
    assert_eq!(dst.len(), src.len());
    #[cfg(target_arch = "x86_64")]
    {
        use core::arch::x86_64::{
            _mm_add_ps, _mm_cvtsi128_si32, _mm_cvttps_epi32, _mm_loadu_ps, _mm_max_ps, _mm_min_ps, _mm_mul_ps,
            _mm_packs_epi32, _mm_packus_epi16, _mm_set1_ps, _mm_setzero_ps, _mm_storeu_si128,
        };
        // One pixel's four channels as 32-bit integers in [0, 255].
        // SAFETY (of the callers' blocks): SSE2 is part of x86-64; `s` is 4 readable f32.
        let channels = |s: &[f32; 4]| unsafe {
            let v = _mm_min_ps(_mm_max_ps(_mm_loadu_ps(s.as_ptr()), _mm_setzero_ps()), _mm_set1_ps(1.0));
            _mm_cvttps_epi32(_mm_add_ps(_mm_mul_ps(v, _mm_set1_ps(255.0)), _mm_set1_ps(0.5)))
        };
        // Four pixels packed together and stored as 16 bytes (one pixel at a time: 6.7% of a
        // 1-thread 100k-triangle Gouraud frame).
        let (mut d4, mut s4) = (dst.chunks_exact_mut(4), src.chunks_exact(4));
        for (d, s) in (&mut d4).zip(&mut s4) {
            // SAFETY: SSE2 is part of x86-64; `d` is 16 writable bytes.
            unsafe {
                let lo = _mm_packs_epi32(channels(&s[0]), channels(&s[1]));
                let hi = _mm_packs_epi32(channels(&s[2]), channels(&s[3]));
                _mm_storeu_si128(d.as_mut_ptr().cast(), _mm_packus_epi16(lo, hi));
            }
        }
        for (d, s) in d4.into_remainder().iter_mut().zip(s4.remainder()) {
            let i = channels(s);
            // SAFETY: SSE2 is part of x86-64.
            let word = unsafe { _mm_cvtsi128_si32(_mm_packus_epi16(_mm_packs_epi32(i, i), _mm_packs_epi32(i, i))) };
            *d = word.to_le_bytes();
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    for (d, s) in dst.iter_mut().zip(src) {
        *d = s.map(|c| phong_core::Encoding::Linear.encode(c));
    }
}

/// Orders earlier non-temporal stores ([`stream_fill`], [`stream_copy`]) before later stores.
pub fn stream_fence() {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: SSE is part of x86-64.
    unsafe {
        core::arch::x86_64::_mm_sfence()
    };
}

/// Asks the CPU to bring `x` into the caches ahead of its use: for records read in an order the
/// hardware cannot predict (a tile's triangles, a sparse subset of the frame's).
#[inline(always)]
pub(crate) fn prefetch<T>(x: &T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a prefetch reads nothing the program sees and cannot fault; `x` is a reference.
    unsafe {
        use core::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        let first = (x as *const T).cast::<i8>();
        _mm_prefetch::<_MM_HINT_T0>(first);
        // A record that crosses into the next line (80- and 96-byte records mostly do; a
        // 64-byte record aligned to 64 never does).
        if size_of::<T>() > 1 && !(align_of::<T>() >= 64 && size_of::<T>() <= 64) {
            _mm_prefetch::<_MM_HINT_T0>(first.wrapping_add(size_of::<T>() - 1));
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = x;
}

#[cfg(test)]
mod tests {
    /// The vector encoding is `Encoding::Linear`'s, bit for bit, on
    /// [`encoding_values`](crate::testkit::encoding_values).
    #[test]
    fn encode_linear_is_the_scalar_encoding() {
        use phong_core::Encoding;
        let values = crate::testkit::encoding_values();
        let src: Vec<[f32; 4]> = values
            .chunks(4)
            .filter(|c| c.len() == 4)
            .map(|c| [c[0], c[1], c[2], c[3]])
            .collect();
        let mut dst = vec![[0u8; 4]; src.len()];
        super::encode_linear(&mut dst, &src);
        for (d, s) in dst.iter().zip(&src) {
            assert_eq!(*d, s.map(|c| Encoding::Linear.encode(c)), "{s:?}");
        }
    }

    /// The kernels' in-register encodings (the lean kernel's `encode_rgba8`, 8 and 16 lanes,
    /// whose lower clamp is the saturating packs') are `Encoding::Linear`'s, bit for bit, on
    /// [`encoding_values`](crate::testkit::encoding_values).
    #[test]
    fn vector_encode_rgba8_is_the_scalar_encoding() {
        use super::vector::{Portable, Vf32};
        use phong_core::Encoding;
        fn check<V: Vf32>(values: &[f32]) {
            for chunk in values.chunks_exact(V::N) {
                let mut a = V::A::default();
                a.as_mut().copy_from_slice(chunk);
                let v = V::from_array(a);
                // Each channel a rotation of the lanes, so that every value meets every channel.
                let mut b = V::A::default();
                for (i, l) in b.as_mut().iter_mut().enumerate() {
                    *l = chunk[(i + 1) % V::N];
                }
                let w = V::from_array(b);
                let px = V::encode_rgba8([v, w, v]);
                for (i, p) in px.as_ref().iter().enumerate() {
                    let (x, y) = (chunk[i], chunk[(i + 1) % V::N]);
                    let e = |c: f32| Encoding::Linear.encode(c);
                    assert_eq!(*p, [e(x), e(y), e(x), 255], "{x:e}, {y:e}");
                }
            }
        }
        let values = crate::testkit::encoding_values();
        check::<Portable>(&values);
        #[cfg(target_arch = "x86_64")]
        if crate::testkit::avx2().is_some() {
            #[target_feature(enable = "avx2,fma")]
            fn avx2(values: &[f32]) {
                check::<super::vector::Avx2>(values);
                check::<super::vector::Avx2x2>(values);
            }
            // SAFETY: the CPU has AVX2 and FMA (checked above).
            unsafe { avx2(&values) };
        }
    }

    /// Aligned (streamed) and unaligned (plain) destinations are both filled, and nothing
    /// outside them.
    /// Aligned (streamed) and unaligned (plain) destinations get exactly the source.
    #[test]
    fn stream_copy_copies_exactly_its_slice() {
        let src: Vec<[f32; 4]> = (0..32).map(|i| [i as f32, 0.5, -1.5 * i as f32, 1.0]).collect();
        let mut buf = vec![0f32; 4 * 40 + 8];
        for offset in 0..4 {
            buf.fill(-1.0);
            let pixels: &mut [[f32; 4]] = bytemuck::cast_slice_mut(&mut buf[offset..offset + 4 * 37]);
            super::stream_copy(&mut pixels[3..35], &src);
            super::stream_fence();
            for (i, p) in pixels.iter().enumerate() {
                let want = if (3..35).contains(&i) { src[i - 3] } else { [-1.0; 4] };
                assert_eq!(*p, want, "offset {offset}, pixel {i}");
            }
            assert!(buf[offset + 4 * 37..].iter().all(|&x| x == -1.0));
        }
    }

    #[test]
    fn stream_fill_fills_exactly_its_slice() {
        let mut buf = vec![0f32; 4 * 40 + 8];
        for offset in 0..4 {
            buf.fill(-1.0);
            let pixels: &mut [[f32; 4]] = bytemuck::cast_slice_mut(&mut buf[offset..offset + 4 * 37]);
            super::stream_fill(&mut pixels[3..35], [0.25, 0.5, 0.75, 1.0]);
            super::stream_fence();
            for (i, p) in pixels.iter().enumerate() {
                let want = if (3..35).contains(&i) {
                    [0.25, 0.5, 0.75, 1.0]
                } else {
                    [-1.0; 4]
                };
                assert_eq!(*p, want, "offset {offset}, pixel {i}");
            }
            assert!(buf[offset + 4 * 37..].iter().all(|&x| x == -1.0));
        }
    }
}
