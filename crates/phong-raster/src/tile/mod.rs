//! The tiles, in parallel: each 64×64 tile is planned once ([`TilePlan`]) and drawn by one
//! `match`, by one thread, its triangles in the input's order, so the image is the same
//! whatever the number of threads.
//!
//! - [`mod@reference`]: the reference path, shading as it draws.
//! - [`visible`]: the fast path's visibility, one sample or several a pixel.
//! - [`shade`]: the fast path's deferred shading of the visible pixels, and the scalar shading
//!   both paths share.
//! - [`gouraud`]: all-Gouraud frames with one sample, coloured during visibility.

mod gouraud;
mod reference;
mod shade;
mod visible;

use crate::binning::Binned;
use crate::plan::{FramePlan, Path, Visibility};
use crate::stats::StageClock;
use crate::target::{Pixel, TileTarget};
use phong_core::limits::TILE_SIZE;
use phong_core::{Encoding, Scene};
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};

/// How a tile is drawn, decided once per tile by [`Tiles::plan_tile`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum TilePlan {
    /// No triangle: every pixel is the background.
    Empty,
    /// The reference path: each covering triangle shaded as it is drawn.
    Reference,
    /// One sample, and the tile's only triangle covers all of it: every pixel sees it.
    Covered,
    /// An all-Gouraud frame with one sample: pixels coloured as they pass the depth test; by
    /// the AVX2 kernel with `kernel`.
    Gouraud { kernel: bool },
    /// One sample: visibility, then each visible pixel shaded once.
    Single,
    /// Several samples: visibility per sample, then one shading per visible (pixel, triangle).
    Multi,
}

/// One tile: where it is, its triangles (bin), and the clock its stages are added to.
pub(crate) struct Tile<'f> {
    pub x0: u32,
    pub y0: u32,
    pub x1: u32,
    pub y1: u32,
    pub bin: &'f [u32],
    pub clock: &'f StageClock,
}

impl Tile<'_> {
    /// Width in pixels.
    pub fn width(&self) -> usize {
        (self.x1 - self.x0) as usize
    }
    /// Height in pixels.
    pub fn height(&self) -> usize {
        (self.y1 - self.y0) as usize
    }
}

/// A tile task's working memory, reused from tile to tile (not allocated and zeroed per
/// tile: fresh buffers' page faults were a measurable part of a frame): its buffer for the
/// frame's pixels (see [`TileTarget`]), and the multi-sample path's lists.
#[derive(Default)]
struct TileBuffers {
    local: Vec<[f32; 4]>,
    multi: Multi,
    covered: CoveredPixels,
}

/// The pixels of a covered tile in row order, `row << 16 | column`: the same for every tile
/// of one size, so kept from tile to tile.
#[derive(Default)]
pub(crate) struct CoveredPixels {
    size: (u32, u32),
    pixels: Vec<u32>,
}

impl CoveredPixels {
    /// The pixels of a `width × height` tile.
    pub fn of(&mut self, width: u32, height: u32) -> &[u32] {
        if self.size != (width, height) || self.pixels.is_empty() {
            self.size = (width, height);
            self.pixels.clear();
            for r in 0..height {
                self.pixels.extend(r << 16..r << 16 | width);
            }
        }
        &self.pixels
    }
}

/// The depth and triangle of each sample, and (several samples) the shading jobs.
#[derive(Default)]
pub(crate) struct Multi {
    pub depth: Vec<f32>,
    pub ids: Vec<u32>,
    /// `(pixel, triangle)` per visible pair; a pixel's jobs are contiguous.
    pub jobs: Vec<(u32, u32)>,
    /// Where each pixel's jobs start in `jobs`.
    pub starts: Vec<usize>,
    /// Each job's colour.
    pub colors: Vec<[f32; 4]>,
    /// Each sample's colour, where blended triangles are laid over them.
    pub samples: Vec<[f32; 4]>,
    /// Per sample, the index in `jobs` of its triangle's job (`u32::MAX`: background).
    pub which: Vec<u32>,
}

/// Draws every tile of `plan` from `binned` into `pixels` (the frame, row-major), in
/// parallel, its stages added to `clock`; returns the pixel shadings done.
pub(crate) fn draw<P: Pixel>(
    plan: &FramePlan,
    scene: &Scene,
    binned: &Binned,
    pixels: &mut [P],
    encoding: Encoding,
    clock: &StageClock,
    progress: Option<&(dyn Fn(u64, u64) + Sync)>,
) -> u64 {
    Tiles { plan, scene, binned }.draw_tiles(pixels, encoding, clock, progress)
}

/// What the tiles read: the frame's plan, the scene, and the set-up triangles in their bins.
pub(crate) struct Tiles<'p> {
    pub plan: &'p FramePlan<'p>,
    pub scene: &'p Scene,
    pub binned: &'p Binned,
}

impl Tiles<'_> {
    /// Tile `index` (row-major) of this frame, its stages added to `clock`.
    pub fn tile<'f>(&'f self, index: u32, clock: &'f StageClock) -> Tile<'f> {
        let (x0, y0, x1, y1) = self.plan.tile_rect(index);
        Tile {
            x0,
            y0,
            x1,
            y1,
            bin: &self.binned.bins[index as usize],
            clock,
        }
    }

    /// The plan of `tile`.
    pub fn plan_tile(&self, tile: &Tile) -> TilePlan {
        let n = tile.bin.len();
        if n == 0 {
            TilePlan::Empty
        } else if self.plan.path == Path::Reference {
            TilePlan::Reference
        } else if self.plan.pattern.len() > 1 {
            TilePlan::Multi
        } else if n == 1
            && self.plan.objects[self.binned.object(tile.bin[0])].visibility == Visibility::Opaque
            && self.covers_rect(tile.bin[0], (tile.x0, tile.y0, tile.x1, tile.y1))
        {
            TilePlan::Covered
        } else if self.plan.gouraud_only {
            // The AVX2 kernel wherever the CPU has it, tiny triangles included (BENCHMARKS.md,
            // C4); the scalar loop elsewhere.
            TilePlan::Gouraud {
                kernel: self.plan.isa.is_avx2(),
            }
        } else {
            TilePlan::Single
        }
    }

    /// Draws one tile into its rows of the frame; returns the pixel shadings done.
    fn draw_tile<P: Pixel>(
        &self,
        tile: &Tile,
        rows: &mut [&mut [P]],
        encoding: Encoding,
        buffers: &mut TileBuffers,
    ) -> u64 {
        let plan = self.plan_tile(tile);
        let mut target = TileTarget {
            rows,
            encoding,
            // (A blended triangle reads the pixels it is laid over: not from streamed memory.)
            direct: plan == TilePlan::Reference
                || tile.bin.is_empty()
                || (tile.bin.len() == 1
                    && self.plan.objects[self.binned.object(tile.bin[0])].visibility != Visibility::Blended),
        };
        let TileBuffers { local, multi, covered } = buffers;
        let Multi { depth, ids, .. } = multi;
        match plan {
            TilePlan::Empty => {
                let marks = crate::stats::Marks::start();
                target.fill(self.plan.background);
                tile.clock.add(marks);
                0
            }
            TilePlan::Reference => target.draw(local, |rows, _| self.tile_reference(tile, rows)),
            TilePlan::Covered => {
                if let Some(Some(n)) = target.draw_linear8(|rows| self.tile_covered8(tile, rows, covered)) {
                    n
                } else if self.plan.colour_planes {
                    // The `f32` tile's shading reads whole planes: drawn as the frame's other tiles.
                    let kernel = self.plan.isa.is_avx2();
                    target.draw(local, |rows, _| self.tile_gouraud(tile, rows, depth, kernel))
                } else {
                    target.draw(local, |rows, store| self.tile_covered(tile, rows, store, ids))
                }
            }
            TilePlan::Gouraud { kernel } => {
                if kernel && let Some(n) = target.draw_linear8(|rows| self.tile_gouraud(tile, rows, depth, true)) {
                    n
                } else {
                    target.draw(local, |rows, _| self.tile_gouraud(tile, rows, depth, kernel))
                }
            }
            TilePlan::Single => {
                if self.plan.phong_only
                    && let Some(n) = target.draw_linear8(|rows| self.tile_single8(tile, rows, depth, ids))
                {
                    n
                } else {
                    target.draw(local, |rows, store| self.tile_single(tile, rows, store, depth, ids))
                }
            }
            TilePlan::Multi => target.draw(local, |rows, _| self.tile_multi(tile, rows, multi)),
        }
    }

    /// Draws every tile into `pixels` (the frame, row-major), in parallel; returns the pixel
    /// shadings done. Tasks write their tiles' rows of the frame directly (disjoint slices), a
    /// strip of 64 rows at a time, so that nothing frame-sized exists besides the frame.
    fn draw_tiles<P: Pixel>(
        &self,
        pixels: &mut [P],
        encoding: Encoding,
        clock: &StageClock,
        progress: Option<&(dyn Fn(u64, u64) + Sync)>,
    ) -> u64 {
        let row_len = self.plan.w as usize;
        debug_assert_eq!(pixels.len(), row_len * self.plan.h as usize);
        let total = u64::from(self.plan.tiles_x * self.plan.h.div_ceil(TILE_SIZE));
        let (done, shaded) = (AtomicU64::new(0), AtomicU64::new(0));
        pixels
            .par_chunks_mut(TILE_SIZE as usize * row_len)
            .enumerate()
            .for_each(|(ty, strip)| {
                let mut tiles: Vec<Vec<&mut [P]>> = (0..self.plan.tiles_x).map(|_| Vec::new()).collect();
                for row in strip.chunks_mut(row_len) {
                    for (tx, piece) in row.chunks_mut(TILE_SIZE as usize).enumerate() {
                        tiles[tx].push(piece);
                    }
                }
                tiles
                    .into_par_iter()
                    .enumerate()
                    .for_each_init(TileBuffers::default, |buffers, (tx, mut rows)| {
                        let tile = self.tile(ty as u32 * self.plan.tiles_x + tx as u32, clock);
                        let n = self.draw_tile(&tile, &mut rows, encoding, buffers);
                        shaded.fetch_add(n, Ordering::Relaxed);
                        let d = done.fetch_add(1, Ordering::Relaxed) + 1;
                        if let Some(p) = progress {
                            p(d, total);
                        }
                    });
            });
        shaded.into_inner()
    }
}
