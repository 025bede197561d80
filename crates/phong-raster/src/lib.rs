//! # phong-raster
//!
//! The CPU renderer: `render(&Scene, &RenderOptions) -> Result<Image, Error>`.
//!
//! ## Pipeline
//!
//! 1. **Setup** (per object): vertices to clip space with `clip_from_world`;
//!    for Gouraud, the lighting of [`phong_core::shade`] at each vertex; for
//!    flat, at each triangle's centroid with its facet normal.
//! 2. **Clipping** ([`clip`]): trivial reject against the view volume, then
//!    Sutherland–Hodgman in homogeneous space against the near and far planes
//!    and a guard band ([`GUARD_BAND`](phong_core::limits::GUARD_BAND)) in x and y, so
//!    that screen coordinates stay bounded for the fixed-point stage.
//! 3. **Triangle setup** ([`raster`]): viewport transform with pixel centres
//!    at +0.5, snapping to 1/256 pixel, back-face culling (counter-clockwise in
//!    NDC is front, as OpenGL) unless two-sided, integer edge functions with
//!    the top-left fill rule, binning into 64×64 tiles.
//! 4. **Tiles, in parallel** (rayon): per sample, exact integer coverage and
//!    a `GL_LESS` depth test; per pixel and triangle, one shading at the pixel
//!    centre (as MSAA), perspective-correct; written to the covered samples. The
//!    reference path shades as it draws; the fast path (the default) first finds
//!    each sample's visible triangle, then shades each visible (pixel, triangle)
//!    once, Phong- and Gouraud-interpolated pixels 8 or 16 at a time ([`simd`]).
//! 5. **Resolve**: the samples' average (straight alpha) into the [`Image`].
//!
//! Every pixel of a tile is processed by one thread in triangle order, so the
//! image is the same whatever the number of threads.

pub mod clip;
pub mod raster;
pub mod simd;

pub use raster::{coverage_counts, sample_pattern};

use phong_core::{Encoding, Image, Image8, Scene};
use std::time::Duration;
use thiserror::Error;

/// Why a render failed.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum Error {
    /// Samples per pixel other than 1, 4 or 16.
    #[error("antialias must be 1, 4 or 16 samples per pixel, got {0}")]
    Samples(u32),
    /// The image (times its samples) is larger than the renderer accepts.
    #[error(
        "image {width}x{height} with {samples} samples per pixel is too large (limits: 16384 pixels on a side, \
         and 16384x16384x4 samples in all)"
    )]
    TooLarge {
        /// Width.
        width: u32,
        /// Height.
        height: u32,
        /// Samples per pixel.
        samples: u32,
    },
    /// More threads than [`MAX_THREADS`](phong_core::limits::MAX_THREADS), or none.
    #[error("threads must be from 1 to {max}, got {0}", max = phong_core::limits::MAX_THREADS)]
    ThreadCount(usize),
    /// The thread pool could not be built.
    #[error("could not start {threads} rendering threads: {source}")]
    Threads {
        /// Threads asked for.
        threads: usize,
        /// The cause.
        source: rayon::ThreadPoolBuildError,
    },
    /// An invalid image (from the core crate).
    #[error(transparent)]
    Core(#[from] phong_core::Error),
}

/// How to render (what the scene does not say).
#[derive(Default)]
pub struct RenderOptions<'a> {
    /// Worker threads, 1 to [`MAX_THREADS`](phong_core::limits::MAX_THREADS); `None`: all cores
    /// (rayon's global pool).
    pub threads: Option<usize>,
    /// Called with (tiles done, tiles in all) as tiles finish, from any thread.
    pub progress: Option<&'a (dyn Fn(u64, u64) + Sync)>,
    /// Use the scalar reference path (one `shade` per pixel and covering triangle, in
    /// drawing order) instead of the fast path (visibility first, 8-lane shading kernel).
    pub reference: bool,
    /// Fast path: do not use the AVX2 build of the kernel even where the CPU has AVX2 (for
    /// tests; the images are the same).
    pub no_avx2: bool,
}

/// Counts and times of one render.
#[derive(Clone, Copy, Debug, Default)]
pub struct RenderStats {
    /// Triangles in the scene.
    pub triangles: usize,
    /// Triangles rasterised (after culling and clipping; clipping can add some).
    pub triangles_drawn: usize,
    /// Shadings done: on the fast path one per visible (pixel, triangle) pair; on the
    /// reference path one per pixel and triangle passing the depth test when drawn (overdraw
    /// included).
    pub pixels_shaded: u64,
    /// Vertex transform, per-vertex lighting, clipping, triangle setup and binning.
    pub setup: Duration,
    /// Coverage, depth and shading in the tiles, with the resolve (wall time).
    pub raster: Duration,
    /// In the tiles, CPU time summed over threads: coverage and depth (the reference path
    /// shades as it rasterises, so its shading counts here too).
    pub tile_raster: Duration,
    /// In the tiles, CPU time summed over threads: shading (fast path).
    pub tile_shade: Duration,
    /// In the tiles, CPU time summed over threads: the resolve.
    pub tile_resolve: Duration,
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
    scratch: raster::Scratch,
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
            raster::render(scene, options, image.pixels_mut(), Encoding::Linear, &mut self.scratch)
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
            raster::render(scene, options, image.pixels_mut(), encoding, &mut self.scratch)
        })?;
        Ok(Some((self.image8.as_ref().expect("set above"), stats)))
    }

    /// The last `f32` frame's image, if any.
    pub fn into_image(self) -> Option<Image> {
        self.image
    }

    /// The last 8-bit frame's image, if any.
    pub fn into_image8(self) -> Option<Image8> {
        self.image8
    }
}

/// The scene's and options' checks shared by both targets.
fn check(scene: &Scene, options: &RenderOptions) -> Result<(), Error> {
    let s = scene.image.samples;
    if !phong_core::limits::SAMPLE_COUNTS.contains(&s) {
        return Err(Error::Samples(s));
    }
    let (w, h) = (scene.image.width, scene.image.height);
    if w == 0
        || h == 0
        || w > phong_core::limits::MAX_IMAGE_DIMENSION
        || h > phong_core::limits::MAX_IMAGE_DIMENSION
        || u64::from(w) * u64::from(h) * u64::from(s) > phong_core::limits::MAX_SAMPLES_TOTAL
    {
        return Err(Error::TooLarge {
            width: w,
            height: h,
            samples: s,
        });
    }
    if let Some(n) = options.threads
        && !(1..=phong_core::limits::MAX_THREADS).contains(&n)
    {
        return Err(Error::ThreadCount(n));
    }
    Ok(())
}

/// Runs `f` on `options.threads` threads (a pool of its own), or on the current pool.
fn in_pool<T: Send>(options: &RenderOptions, f: impl FnOnce() -> Result<T, Error> + Send) -> Result<T, Error> {
    match options.threads {
        None => f(),
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .map_err(|source| Error::Threads { threads: n, source })?
            .install(f),
    }
}
