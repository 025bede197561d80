//! # phong-raster
//!
//! The CPU renderer: `render(&Scene, &RenderOptions) -> Result<Image, Error>`.
//!
//! ## Pipeline, a module a stage
//!
//! 1. **Plan** (`plan`): the decisions made once per frame (reference or fast path, the
//!    instruction set, the sample pattern, the background) and per object (`ObjectPlan`: how
//!    it is set up and shaded); `frame` runs the stages below on it.
//! 2. **Vertices** (`vertex`): to clip space with `clip_from_world`, outcodes, window
//!    positions snapped to 1/256 pixel (`fixed`); for Gouraud, the lighting of
//!    [`phong_core::shade`] at each vertex that a drawn triangle uses.
//! 3. **Clipping** (`clip`): trivial reject against the view volume, then Sutherland–Hodgman
//!    in homogeneous space against the near and far planes and a guard band
//!    ([`GUARD_BAND`](phong_core::limits::GUARD_BAND)) in x and y, so that screen coordinates
//!    stay bounded for the fixed-point stage.
//! 4. **Setup** (`setup`): back-face culling (counter-clockwise in NDC is front, as OpenGL)
//!    unless two-sided, integer edge functions with the top-left fill rule, the pixel box,
//!    plane equations; then **binning** (`binning`) into 64×64 tiles.
//! 5. **Tiles, in parallel** (`tile`): per sample, exact integer coverage and a `GL_LESS`
//!    depth test; per pixel and triangle, one shading at the pixel centre (as MSAA),
//!    perspective-correct. The reference path shades as it draws; the fast path (the
//!    default) first finds each sample's visible triangle, then shades each visible (pixel,
//!    triangle) once, by the vector kernels (`simd`).
//! 6. **Resolve and store** (`target`): the samples' average (straight alpha) into an `f32`
//!    [`Image`] or an 8-bit [`Image8`].
//!
//! Every pixel of a tile is processed by one thread in triangle order, so the image is the
//! same whatever the number of threads.

mod binning;
mod census;
mod clip;
mod fixed;
mod frame;
mod plan;
mod pool;
mod setup;
mod simd;
mod stats;
mod target;
mod tile;
mod vertex;

pub use census::{Census, census};
pub use frame::coverage_counts;
pub use phong_core::limits::sample_pattern;
pub use pool::Pool;
pub use stats::RenderStats;

/// The kernels and the clipper, for phong-raster's own benchmarks and tests: not a stable API.
#[doc(hidden)]
pub mod internals {
    pub use crate::clip::{ClipVertex, Clipped, clip_triangle};
    pub use crate::simd::{
        Isa, LANES, Lean, Prepared, Shaded8, Term, VertexTerm, avx2_available, light_vertices, shade8, shade8_lean,
    };
}

use phong_core::{Encoding, Image, Image8, Scene};
use thiserror::Error;

/// Why a render failed.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum Error {
    /// More threads than [`MAX_THREADS`](phong_core::limits::MAX_THREADS), or none.
    #[error("threads must be from 1 to {max}, got {0}", max = phong_core::limits::MAX_THREADS)]
    ThreadCount(usize),
    /// The thread pool could not be built.
    #[error("could not start {threads} rendering threads: {reason}")]
    Threads {
        /// Threads asked for.
        threads: usize,
        /// Why (the system's words).
        reason: String,
    },
    /// An invalid image (from the core crate).
    #[error(transparent)]
    Core(#[from] phong_core::Error),
}

impl Error {
    /// Whether the error is in what the caller asked for (the scene or the options), not in
    /// the machine.
    pub fn is_input(&self) -> bool {
        matches!(self, Error::ThreadCount(_) | Error::Core(_))
    }
}

/// How to render (what the scene does not say).
#[derive(Default)]
pub struct RenderOptions<'a> {
    /// Worker threads, 1 to [`MAX_THREADS`](phong_core::limits::MAX_THREADS); `None`: all cores
    /// (rayon's global pool). See [`Pool`] for where the system refuses threads.
    pub threads: Option<usize>,
    /// Called with (tiles done, tiles in all) as tiles finish, from any thread.
    pub progress: Option<&'a (dyn Fn(u64, u64) + Sync)>,
    /// Use the scalar reference path (one `shade` per pixel and covering triangle, in
    /// drawing order) instead of the fast path (visibility first, 8-lane shading kernel).
    pub reference: bool,
    /// Fast path: which builds of the vector kernels may run (every choice draws the same
    /// image, bit for bit).
    pub kernels: Kernels,
}

/// Which builds of the fast path's vector kernels may run on this CPU. The images are the same
/// whichever runs, bit for bit (tested); the choice is for tests and comparisons.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Kernels {
    /// The best this CPU has: the AVX2 build, with AVX-512's 32 vector registers where the CPU
    /// has AVX-512VL; the portable build without AVX2 and FMA.
    #[default]
    Auto,
    /// At most the AVX2 build with its 16 vector registers.
    Avx2,
    /// The portable build, whatever the CPU has.
    Portable,
}

/// The CPU path and kernel build `options` render with on this CPU, in words: `reference
/// path`, or the fast path's kernels: `AVX2 kernels (AVX-512 registers)` (the untextured
/// kernels and the common textured form have that build; see `Isa::wide`), `AVX2 kernels` or
/// `portable kernels`.
pub fn kernels(options: &RenderOptions) -> &'static str {
    if options.reference {
        return "reference path";
    }
    let isa = crate::simd::Isa::detect(options.kernels);
    match (isa.is_avx2(), isa.wide()) {
        (true, true) => "AVX2 kernels (AVX-512 registers)",
        (true, false) => "AVX2 kernels",
        _ => "portable kernels",
    }
}

/// Renders `scene` into a linear RGBA image.
pub fn render(scene: &Scene, options: &RenderOptions) -> Result<Image, Error> {
    render_with_stats(scene, options).map(|(img, _)| img)
}

/// [`render`], with counts and stage times.
pub fn render_with_stats(scene: &Scene, options: &RenderOptions) -> Result<(Image, RenderStats), Error> {
    let mut renderer = Renderer::new();
    let stats = renderer.render(scene, options)?.1;
    Ok((renderer.into_image().expect("an image after a render"), stats))
}

/// A renderer for repeated frames (`phong bench`, an interactive view): it keeps its
/// framebuffer and its working memory (set-up triangles, bins, vertex buffers) from one frame
/// to the next. A 1080p image is 33 MB, and the 1M-triangle benchmark sphere's 246 531 drawn
/// triangles take 43 MB (80 + 96 bytes each) besides its 10 MB of vertex records: as fresh
/// allocations, their first-touch page faults and their unmapping cost each frame what a kept
/// buffer does not.
#[derive(Default)]
pub struct Renderer {
    image: Option<Image>,
    image8: Option<Image8>,
    scratch: setup::Scratch,
}

impl Renderer {
    /// A renderer with nothing allocated yet.
    pub fn new() -> Renderer {
        Renderer::default()
    }

    /// Renders `scene`, reusing the memory of previous frames (every pixel is written; a size
    /// change reallocates the image).
    pub fn render(&mut self, scene: &Scene, options: &RenderOptions) -> Result<(&Image, RenderStats), Error> {
        check(scene, options)?;
        let (w, h) = (scene.image.width, scene.image.height);
        if self.image.as_ref().is_none_or(|i| (i.width(), i.height()) != (w, h)) {
            // Zeroed (the allocator's zero pages, no fill): the tiles write every pixel.
            self.image = Some(Image::new(w, h, [0.0; 4])?);
        }
        let image = self.image.as_mut().expect("set above");
        let stats = in_pool(options, || {
            frame::render(scene, options, image.pixels_mut(), Encoding::Linear, &mut self.scratch)
        })?;
        Ok((self.image.as_ref().expect("set above"), stats))
    }

    /// [`Renderer::render`] straight into 8 bits, encoded by the scene's encoding: the same
    /// bytes as the `f32` image's [`Image::to_bytes`], a quarter of the memory written. `None`
    /// where 8 bits cannot tell transparency as the `f32` image does (a background alpha in
    /// `(1 − 8/255, 1)`, see [`Image8::exact_for_background`]): render in `f32` then.
    pub fn render_8bit(
        &mut self,
        scene: &Scene,
        options: &RenderOptions,
    ) -> Result<Option<(&Image8, RenderStats)>, Error> {
        check(scene, options)?;
        if !Image8::exact_for_background(scene.image.background[3]) {
            return Ok(None);
        }
        let (w, h, encoding) = (scene.image.width, scene.image.height, scene.image.encoding);
        if self
            .image8
            .as_ref()
            .is_none_or(|i| (i.width(), i.height(), i.encoding()) != (w, h, encoding))
        {
            self.image8 = Some(Image8::new(w, h, encoding)?);
        }
        let image = self.image8.as_mut().expect("set above");
        let stats = in_pool(options, || {
            frame::render(scene, options, image.pixels_mut(), encoding, &mut self.scratch)
        })?;
        Ok(Some((self.image8.as_ref().expect("set above"), stats)))
    }

    /// Takes the last `f32` frame's image, if any (the next frame allocates another).
    pub fn take_image(&mut self) -> Option<Image> {
        self.image.take()
    }

    /// Takes the last 8-bit frame's image, if any (the next frame allocates another).
    pub fn take_image8(&mut self) -> Option<Image8> {
        self.image8.take()
    }

    /// The last `f32` frame's image, if any.
    pub fn into_image(self) -> Option<Image> {
        self.image
    }

    /// The last 8-bit frame's image, if any.
    pub fn into_image8(self) -> Option<Image8> {
        self.image8
    }

    /// Renders `scene` into the target its PNG needs: 8 bits where they give the bytes of the
    /// `f32` image ([`Renderer::render_8bit`]), else `f32` ([`Renderer::render`]). The one place
    /// that choice is made.
    pub fn render_for_png(
        &mut self,
        scene: &Scene,
        options: &RenderOptions,
    ) -> Result<(Rendered<'_>, RenderStats), Error> {
        check(scene, options)?;
        if Image8::exact_for_background(scene.image.background[3]) {
            let (image, stats) = self.render_8bit(scene, options)?.expect("8 bits are exact here");
            return Ok((Rendered::Eight(image), stats));
        }
        let (image, stats) = self.render(scene, options)?;
        Ok((Rendered::Linear(image), stats))
    }
}

/// A frame as [`Renderer::render_for_png`] drew it.
#[derive(Clone, Copy, Debug)]
pub enum Rendered<'a> {
    /// Linear `f32` RGBA.
    Linear(&'a Image),
    /// 8 bits, in the scene's encoding.
    Eight(&'a Image8),
}

/// The scene's and options' checks shared by both targets.
fn check(scene: &Scene, options: &RenderOptions) -> Result<(), Error> {
    scene.image.check()?;
    Pool::check(options.threads)
}

/// Runs `f` on `options.threads` threads (a pool of its own), or on the current pool.
fn in_pool<T: Send>(options: &RenderOptions, f: impl FnOnce() -> Result<T, Error> + Send) -> Result<T, Error> {
    Pool::new(options.threads)?.install(f)
}

/// What phong-raster's unit tests share.
#[cfg(test)]
pub(crate) mod testkit {
    use crate::Kernels;
    use crate::simd::Isa;

    /// A xorshift64 generator: the tests' reproducible random numbers.
    pub fn xorshift(mut seed: u64) -> impl FnMut() -> u64 {
        move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        }
    }

    /// Values to check an 8-bit encoding with: every 1/4096 step of [−0.5, 1.5], the values
    /// just around each rounding threshold `(k + 0.5) / 255`, random bit patterns, and NaN,
    /// the infinities and the extremes.
    pub fn encoding_values() -> Vec<f32> {
        let mut values: Vec<f32> = (-2048..=6144).map(|i| i as f32 / 4096.0).collect();
        for k in 0..256 {
            let t = (k as f32 + 0.5) / 255.0;
            values.extend([t, f32::from_bits(t.to_bits() - 1), f32::from_bits(t.to_bits() + 1)]);
        }
        let mut next = xorshift(7);
        values.extend((0..10_000).map(|_| f32::from_bits(next() as u32)));
        values.extend([
            f32::NAN,
            -f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            -0.0,
            f32::MAX,
            f32::MIN,
            f32::MIN_POSITIVE,
            -f32::MIN_POSITIVE,
            -1e-30,
            -1.0,
            2.0,
        ]);
        values
    }

    /// The AVX2 build, or `None` (the test skips, saying so) on a CPU without it; with
    /// `PHONG_REQUIRE_AVX2=1` a CPU without it fails the test instead.
    pub fn avx2() -> Option<Isa> {
        let isa = Isa::detect(Kernels::Auto);
        if isa.is_avx2() {
            return Some(isa);
        }
        assert!(
            std::env::var_os("PHONG_REQUIRE_AVX2").is_none_or(|v| v != "1"),
            "PHONG_REQUIRE_AVX2=1 and this CPU has no AVX2 and FMA"
        );
        eprintln!("skipped: this CPU has no AVX2 and FMA");
        None
    }
}
