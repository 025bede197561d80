//! What a render counts and times: [`RenderStats`], and the tiles' per-stage CPU clock.

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

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

/// CPU time of the tiles' stages, summed over threads, in nanoseconds.
#[derive(Default)]
pub(crate) struct StageClock {
    raster: AtomicU64,
    shade: AtomicU64,
    resolve: AtomicU64,
}

/// When a tile's stages began: visibility at `start`, then shading and the resolve where
/// the tile has them; each stage lasts until the next one's mark (the last until the end).
#[derive(Clone, Copy)]
pub(crate) struct Marks {
    start: Instant,
    shade: Option<Instant>,
    resolve: Option<Instant>,
}

impl Marks {
    /// A tile's visibility begins now.
    pub fn start() -> Marks {
        Marks {
            start: Instant::now(),
            shade: None,
            resolve: None,
        }
    }

    /// Its shading begins now.
    pub fn shading(&mut self) {
        self.shade = Some(Instant::now());
    }

    /// Its resolve begins now.
    pub fn resolving(&mut self) {
        self.resolve = Some(Instant::now());
    }
}

impl StageClock {
    /// Adds a tile's stages, `marks` to now.
    pub fn add(&self, marks: Marks) {
        let end = Instant::now();
        let shade = marks.shade.unwrap_or(end);
        let resolve = marks.resolve.unwrap_or(end).max(shade);
        let ns = |a: Instant, b: Instant| (b - a).as_nanos() as u64;
        self.raster.fetch_add(ns(marks.start, shade), Ordering::Relaxed);
        self.shade.fetch_add(ns(shade, resolve), Ordering::Relaxed);
        self.resolve.fetch_add(ns(resolve, end), Ordering::Relaxed);
    }

    /// The stages' sums: (raster, shade, resolve).
    pub fn into_durations(self) -> (Duration, Duration, Duration) {
        let d = |a: AtomicU64| Duration::from_nanos(a.into_inner());
        (d(self.raster), d(self.shade), d(self.resolve))
    }
}
