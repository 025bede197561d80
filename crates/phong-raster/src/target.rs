//! What the tiles write into: the frame's pixels (linear `f32` or 8-bit), the resolve of a
//! pixel's samples, and where each tile is drawn (straight into the frame, or into the task's
//! cache-resident buffer and then stored).

use crate::simd::{encode_linear, stream_copy, stream_fence, stream_fill};
use phong_core::Encoding;
use phong_core::limits::TILE_SIZE;

/// Resolves one pixel: the straight-alpha average of its `ns` samples, in sample order
/// (both CPU paths use it, so they sum in the same order).
#[inline]
pub(crate) fn resolve(samples: impl Iterator<Item = [f32; 4]>, ns: usize, bg: [f32; 4]) -> [f32; 4] {
    let mut acc = [0f32; 4];
    for s in samples {
        for k in 0..3 {
            acc[k] += s[k] * s[3];
        }
        acc[3] += s[3];
    }
    if acc[3] > 0.0 {
        [acc[0] / acc[3], acc[1] / acc[3], acc[2] / acc[3], acc[3] / ns as f32]
    } else {
        [bg[0], bg[1], bg[2], 0.0]
    }
}

/// [`Image::to_bytes`](phong_core::Image::to_bytes)'s encoding of one pixel: colour by
/// `encoding`, alpha linearly.
#[inline]
pub(crate) fn encode(p: [f32; 4], encoding: Encoding) -> [u8; 4] {
    [
        encoding.encode(p[0]),
        encoding.encode(p[1]),
        encoding.encode(p[2]),
        Encoding::Linear.encode(p[3]),
    ]
}

/// How `f32` rows are written: streamed past the caches (the frame's own rows, not read
/// again), or plain stores (the task's buffer, read again at once).
#[derive(Clone, Copy, PartialEq, Eq)]
pub(crate) enum Store {
    Stream,
    Cached,
}

/// Fills `line` with `value` as `store` says.
#[inline]
pub(crate) fn fill(line: &mut [[f32; 4]], value: [f32; 4], store: Store) {
    match store {
        Store::Stream => stream_fill(line, value),
        Store::Cached => line.fill(value),
    }
}

/// A frame's pixel: linear `f32` (an [`Image`](phong_core::Image)'s) or 8-bit (an
/// [`Image8`](phong_core::Image8)'s, encoded by the frame's encoding).
pub(crate) trait Pixel: Copy + Send + Sync {
    /// The frame's row as `f32` pixels, for tiles drawn straight into it (`f32` only).
    fn as_linear(row: &mut [Self]) -> Option<&mut [[f32; 4]]>;
    /// The frame's row as 8-bit pixels that `Encoding::Linear` encodes (8-bit frames in that
    /// encoding only), for Gouraud tiles the AVX2 kernel draws straight into it.
    fn as_linear8(row: &mut [Self], encoding: Encoding) -> Option<&mut [[u8; 4]]>;
    /// `dst` from the tile buffer's `src`.
    fn store(dst: &mut [Self], src: &[[f32; 4]], encoding: Encoding);
    /// `value` as a pixel of the frame.
    fn from_linear(value: [f32; 4], encoding: Encoding) -> Self;
    /// `dst` all `value`.
    fn fill(dst: &mut [Self], value: Self);
}

impl Pixel for [f32; 4] {
    fn as_linear(row: &mut [Self]) -> Option<&mut [[f32; 4]]> {
        Some(row)
    }
    fn as_linear8(_: &mut [Self], _: Encoding) -> Option<&mut [[u8; 4]]> {
        None
    }
    fn store(dst: &mut [Self], src: &[[f32; 4]], _: Encoding) {
        stream_copy(dst, src);
    }
    fn from_linear(value: [f32; 4], _: Encoding) -> Self {
        value
    }
    fn fill(dst: &mut [Self], value: Self) {
        stream_fill(dst, value);
    }
}

impl Pixel for [u8; 4] {
    fn as_linear(_: &mut [Self]) -> Option<&mut [[f32; 4]]> {
        None
    }
    fn as_linear8(row: &mut [Self], encoding: Encoding) -> Option<&mut [[u8; 4]]> {
        (encoding == Encoding::Linear).then_some(row)
    }
    fn store(dst: &mut [Self], src: &[[f32; 4]], encoding: Encoding) {
        match encoding {
            // By SSE2 (BENCHMARKS.md, R8).
            Encoding::Linear => encode_linear(dst, src),
            Encoding::Srgb => {
                for (d, &s) in dst.iter_mut().zip(src) {
                    *d = encode(s, encoding);
                }
            }
        }
    }
    fn from_linear(value: [f32; 4], encoding: Encoding) -> Self {
        encode(value, encoding)
    }
    fn fill(dst: &mut [Self], value: Self) {
        dst.fill(value);
    }
}

/// A tile's rows of the frame, and where the tile is drawn. Tiles of at most one triangle (and
/// the reference path's) go straight into an `f32` frame, streamed; the others into the
/// task's buffer (cache-resident while the tile is drawn), then stored into the frame
/// (BENCHMARKS.md, R2).
pub(crate) struct TileTarget<'t, 'r, P> {
    pub rows: &'t mut [&'r mut [P]],
    pub encoding: Encoding,
    /// Draw straight into an `f32` frame.
    pub direct: bool,
}

impl<P: Pixel> TileTarget<'_, '_, P> {
    /// Every pixel `value`.
    pub fn fill(&mut self, value: [f32; 4]) {
        let v = P::from_linear(value, self.encoding);
        for row in self.rows.iter_mut() {
            P::fill(row, v);
        }
        stream_fence();
    }

    /// Draws the tile by `draw`, into `f32` rows: the frame's, or `buffer`'s then stored.
    pub fn draw(&mut self, buffer: &mut Vec<[f32; 4]>, draw: impl FnOnce(&mut [&mut [[f32; 4]]], Store) -> u64) -> u64 {
        if self.direct
            && let Some(mut rows) = self
                .rows
                .iter_mut()
                .map(|r| P::as_linear(r))
                .collect::<Option<Vec<_>>>()
        {
            let n = draw(&mut rows, Store::Stream);
            stream_fence();
            return n;
        }
        let tw = self.rows[0].len();
        buffer.resize((TILE_SIZE * TILE_SIZE) as usize, [0.0; 4]);
        let mut local: Vec<&mut [[f32; 4]]> = buffer.chunks_mut(tw).take(self.rows.len()).collect();
        let n = draw(&mut local, Store::Cached);
        for (dst, src) in self.rows.iter_mut().zip(&local) {
            P::store(dst, src, self.encoding);
        }
        stream_fence();
        n
    }

    /// Draws the tile by `draw` straight into the rows of an 8-bit frame that `Encoding::Linear`
    /// encodes; `None` (nothing drawn) for other frames.
    pub fn draw_linear8<R>(&mut self, draw: impl FnOnce(&mut [&mut [[u8; 4]]]) -> R) -> Option<R> {
        let mut rows = self
            .rows
            .iter_mut()
            .map(|r| P::as_linear8(r, self.encoding))
            .collect::<Option<Vec<_>>>()?;
        Some(draw(&mut rows))
    }
}
