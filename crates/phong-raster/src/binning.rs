//! Binning: each set-up triangle into the 64×64 tiles its box meets and its edges do not
//! trivially reject, in the input's order.

use crate::frame::Frame;
use crate::setup::{Chunk, ID_INDEX_BITS, Tri};
use phong_core::limits::{SUBPIXEL_BITS, TILE_SIZE};
use rayon::prelude::*;

impl Frame<'_> {
    /// The tiles each triangle of `chunk` goes into, as `(tile, index)` pairs in triangle order
    /// (made in the setup's parallel tasks).
    pub(crate) fn bin_entries(&self, chunk: &mut Chunk) {
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
                    chunk.binned.push((ty * self.tiles_x + tx, i as u32));
                }
            }
        }
    }

    /// Keeps set-up chunks and adds their triangles to the bins, in order (chunk by chunk,
    /// triangle by triangle: the tiles draw them in the input's order). Bands of tiles are
    /// filled in parallel, each from every chunk's entries ([`Frame::bin_entries`]).
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
        t.a(i) * x + t.b(i) * y + t.c[i] - t.bias(i) < 0
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
