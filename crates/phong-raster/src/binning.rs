//! Binning: each set-up triangle into the 64×64 tiles its box meets and its edges do not
//! trivially reject, in the input's order.

use crate::setup::{Chunk, Corners, ID_INDEX_BITS, Scratch, Tri};
use crate::simd::{ColourPlanes, Planes};
use phong_core::limits::{SUBPIXEL_BITS, TILE_SIZE};
use rayon::prelude::*;

/// The setup's result: the set-up triangles, in the chunks the parallel setup made them (not
/// copied into one vector), and each tile's triangles in drawing order. Ids pack (chunk,
/// index), see [`Binned::tri`].
pub(crate) struct Binned {
    pub tris: Vec<Chunk>,
    pub bins: Vec<Vec<u32>>,
}

/// The tiles each triangle of `chunk` goes into, as `(tile, index)` pairs in triangle order
/// (made in the setup's parallel tasks), in a frame `tiles_x` tiles wide.
pub(crate) fn bin_entries(chunk: &mut Chunk, tiles_x: u32) {
    // A setup chunk of SETUP_CHUNK input triangles makes at most 7 triangles of each.
    debug_assert!(chunk.tris.len() < 1 << ID_INDEX_BITS);
    for (i, t) in chunk.tris.iter().enumerate() {
        let [px0, py0, px1, py1] = t.bbox();
        let (tx0, tx1) = (px0 / TILE_SIZE, (px1 - 1) / TILE_SIZE);
        let (ty0, ty1) = (py0 / TILE_SIZE, (py1 - 1) / TILE_SIZE);
        let several = tx0 != tx1 || ty0 != ty1;
        for ty in ty0..=ty1 {
            for tx in tx0..=tx1 {
                if several && misses_tile(t, tx, ty) {
                    continue;
                }
                chunk.binned.push((ty * tiles_x + tx, i as u32));
            }
        }
    }
}

impl Binned {
    /// No triangles yet, `tiles` empty bins, in memory taken from `scratch`.
    pub fn new(tiles: usize, scratch: &mut Scratch) -> Binned {
        let mut bins = std::mem::take(&mut scratch.bins);
        bins.resize(tiles, Vec::new());
        Binned { tris: Vec::new(), bins }
    }

    /// Keeps set-up chunks and adds their triangles to the bins, in order (chunk by chunk,
    /// triangle by triangle: the tiles draw them in the input's order). Bands of tiles are
    /// filled in parallel, each from every chunk's entries ([`bin_entries`]).
    pub(crate) fn bin_chunks(&mut self, chunks: Vec<Chunk>) {
        let base = self.tris.len() as u32;
        debug_assert!(base as usize + chunks.len() < 1 << (32 - ID_INDEX_BITS));
        let tiles = self.bins.len();
        let band = tiles.div_ceil(rayon::current_num_threads()).max(1);
        self.bins.par_chunks_mut(band).enumerate().for_each(|(b, bins)| {
            let first = (b * band) as u32;
            for (c, chunk) in chunks.iter().enumerate() {
                let c = (base + c as u32) << ID_INDEX_BITS;
                for &(tile, i) in &chunk.binned {
                    if let Some(bin) = bins.get_mut(tile.wrapping_sub(first) as usize) {
                        bin.push(c | i);
                    }
                }
            }
        });
        self.tris.extend(chunks);
    }

    /// Gives the memory back to `scratch`, emptied, for the next frame. Spare chunks are kept
    /// up to the number this frame used: the full setup makes chunks of its own rather than
    /// taking spare ones, and keeping all of them grew the memory of every repeated frame that
    /// has such objects.
    pub fn recycle(self, scratch: &mut Scratch) {
        let keep = self.tris.len();
        for mut chunk in self.tris {
            if scratch.chunks.len() >= keep {
                break;
            }
            chunk.clear();
            scratch.chunks.push(chunk);
        }
        scratch.bins = self.bins;
        for bin in &mut scratch.bins {
            bin.clear();
        }
    }

    /// The triangle with packed id `id` (chunk in the high bits, index in the low ones).
    #[inline]
    pub fn tri(&self, id: u32) -> &Tri {
        &self.tris[(id >> ID_INDEX_BITS) as usize].tris[(id & ((1 << ID_INDEX_BITS) - 1)) as usize]
    }

    /// The object of triangle `id`.
    #[inline]
    pub fn object(&self, id: u32) -> usize {
        self.tris[(id >> ID_INDEX_BITS) as usize].object as usize
    }

    /// The fast path's plane equations of triangle `id`.
    #[inline]
    pub fn planes(&self, id: u32) -> &Planes {
        &self.tris[(id >> ID_INDEX_BITS) as usize].planes[(id & ((1 << ID_INDEX_BITS) - 1)) as usize]
    }

    /// The colour planes of triangle `id` in a frame that keeps them
    /// ([`FramePlan::colour_planes`](crate::plan::FramePlan::colour_planes)).
    #[inline]
    pub fn colour(&self, id: u32) -> &ColourPlanes {
        &self.tris[(id >> ID_INDEX_BITS) as usize].colour[(id & ((1 << ID_INDEX_BITS) - 1)) as usize]
    }

    /// The planes of a textured triangle's texture coordinates (`Mode::Textured`).
    #[inline]
    pub fn uv_planes(&self, id: u32) -> &Planes {
        &self.tris[(id >> ID_INDEX_BITS) as usize].uv[(id & ((1 << ID_INDEX_BITS) - 1)) as usize]
    }

    /// The [`Corners`] of triangle `id` (kept for the reference path and scalar-shaded objects).
    #[inline]
    pub fn corners(&self, id: u32) -> &Corners {
        &self.tris[(id >> ID_INDEX_BITS) as usize].corners[(id & ((1 << ID_INDEX_BITS) - 1)) as usize]
    }
}

/// Trivial reject of a tile: some edge of `t` is negative on all of tile `(tx, ty)`'s square
/// (pixel corners, so every sample position of every pattern is inside it), tested at the
/// square's corner where the edge is largest. Binning by bounding box alone put both
/// triangles of a full-screen quad in every tile.
#[inline]
pub(crate) fn misses_tile(t: &Tri, tx: u32, ty: u32) -> bool {
    let (x0, y0) = (
        i64::from(tx * TILE_SIZE) << SUBPIXEL_BITS,
        i64::from(ty * TILE_SIZE) << SUBPIXEL_BITS,
    );
    let side = i64::from(TILE_SIZE) << SUBPIXEL_BITS;
    (0..3).any(|i| {
        let x = if t.a[i] >= 0 { x0 + side } else { x0 };
        let y = if t.b[i] >= 0 { y0 + side } else { y0 };
        t.edge(i, x, y) - t.bias(i) < 0
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixed::pattern;
    use crate::setup::{SampleSpan, setup_edges};
    use crate::testkit::xorshift;
    use crate::vertex::Projected;

    /// Binning's trivial reject never drops a tile where a sample of any pattern is covered,
    /// and does drop some (random triangles up to 2.5 tiles across, in a 4×4-tile image).
    #[test]
    fn tile_reject_is_conservative() {
        let (w, h) = (4 * TILE_SIZE, 4 * TILE_SIZE);
        let mut bits = xorshift(0x2545_f491_4f6c_dd1du64);
        let mut next = |range: i64| (bits() % range as u64) as i64;
        let patterns: Vec<Vec<(i64, i64)>> = phong_core::Samples::ALL.iter().map(|&n| pattern(n)).collect();
        let all = SampleSpan::of(&patterns.concat());
        let mut rejected = 0;
        for _ in 0..400 {
            let span = i64::from(TILE_SIZE) * 160 * 2;
            let (cx, cy) = (next(i64::from(w) * 256), next(i64::from(h) * 256));
            let proj = [0; 3].map(|_| {
                Projected(
                    (cx + next(span) - span / 2) as i32,
                    (cy + next(span) - span / 2) as i32,
                    0.5,
                    1.0,
                )
            });
            let Some(s) = setup_edges(proj, true, w, h, all) else {
                continue;
            };
            let t = &s.tri;
            for ty in 0..h / TILE_SIZE {
                for tx in 0..w / TILE_SIZE {
                    if !misses_tile(t, tx, ty) {
                        continue;
                    }
                    rejected += 1;
                    for py in ty * TILE_SIZE..(ty + 1) * TILE_SIZE {
                        for px in tx * TILE_SIZE..(tx + 1) * TILE_SIZE {
                            for &(ox, oy) in patterns.iter().flatten() {
                                let (sx, sy) = (
                                    (i64::from(px) << SUBPIXEL_BITS) + ox,
                                    (i64::from(py) << SUBPIXEL_BITS) + oy,
                                );
                                assert!(
                                    t.covers(sx, sy).is_none(),
                                    "tile ({tx}, {ty}) rejected, ({px}, {py}) covered"
                                );
                            }
                        }
                    }
                }
            }
        }
        assert!(rejected > 100, "only {rejected} tiles rejected");
    }
}
