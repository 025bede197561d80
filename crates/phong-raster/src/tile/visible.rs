//! The fast path's visibility: per sample the nearest triangle, with the reference's
//! coverage and depth arithmetic (exact integer edge functions stepped incrementally, the same
//! barycentrics and depths), so the same triangle wins every sample.
//!
//! With one sample ([`Tiles::tile_single`]) wide rows first find their covered span exactly,
//! and Gouraud triangles colour their pixels as they pass (see [`Forward`]); with several
//! ([`Tiles::tile_multi`]) each sample is tested in turn.

use super::Tiles;
use super::reference::over;
use super::{Multi, Tile};
use crate::fixed::{HALF, each3, map3};
use crate::plan::{Mode, Visibility};
use crate::setup::Tri;
use crate::simd::{
    ColourPlanes, Isa, SampleBuffers, TilePixel, covered_span, multi_visible, multi_visible_run, prefetch,
    single_visible,
};
use crate::stats::Marks;
use crate::target::{Store, resolve};
use phong_core::limits::SUBPIXEL_BITS;

/// How many triangles of a bin ahead the tiles ask for their records: a bin's triangles are a
/// sparse subset of the frame's, in an order the hardware does not predict.
pub(super) const PREFETCH_AHEAD: usize = 8;

/// The id of a pixel coloured during visibility (see [`Forward`]); bin indices stay below it.
pub(super) const FORWARD: u32 = u32::MAX - 1;

/// Gouraud with one sample: colours written into the tile's rows as pixels pass the depth
/// test, from the triangle's colour planes. Interpolating a colour costs less than sorting the
/// pixel for a deferred pass (BENCHMARKS.md, R7), and a later, nearer triangle overwrites it.
pub(super) struct Forward<'r, 'i, T> {
    pub planes: ColorPlanes,
    pub rows: &'r mut [&'i mut [T]],
}

/// A triangle's Gouraud planes (see [`ColourPlanes`]) as columns of four, `[r/w, g/w, b/w, 1/w]`, so
/// that a pixel's colour is one 4-wide vector from start to store, the layout of the
/// `[f32; 4]` pixel it is written to (BENCHMARKS.md, C6).
#[derive(Clone, Copy)]
pub(super) struct ColorPlanes {
    c: [f32; 4],
    gx: [f32; 4],
    gy: [f32; 4],
    origin: [f32; 2],
}

impl ColorPlanes {
    #[inline(always)]
    pub fn new(p: &ColourPlanes) -> ColorPlanes {
        let column = |k: usize| [p.attr[0][k], p.attr[1][k], p.attr[2][k], p.inv_w[k]];
        ColorPlanes {
            c: column(0),
            gx: column(1),
            gy: column(2),
            origin: p.origin,
        }
    }

    /// The colour at the centre of pixel `(px, py)`: `q_c / q_w`, each `q = c + gx·dx + gy·dy`
    /// in `f32` (no fused multiply-adds), an exact division: the arithmetic of the reference's
    /// interpolation of Gouraud colours.
    #[inline(always)]
    pub fn at(&self, px: u32, py: u32) -> [f32; 4] {
        let (dx, dy) = (px as f32 + 0.5 - self.origin[0], py as f32 + 0.5 - self.origin[1]);
        let q: [f32; 4] = std::array::from_fn(|i| self.c[i] + self.gx[i] * dx + self.gy[i] * dy);
        let w = 1.0 / q[3];
        [q[0] * w, q[1] * w, q[2] * w, 1.0]
    }
}

/// A tile's rectangle as the row loop reads it: `(x0, y0, width, y1)`.
pub(super) type Span = (u32, u32, usize, u32);

/// One triangle's scan of a tile's rows with one sample a pixel: the triangle, its id, the
/// sample's offset of its edge functions (bias subtracted), and the columns `cols.0..cols.1`.
#[derive(Clone, Copy)]
pub(super) struct Scan<'t> {
    pub t: &'t Tri,
    pub id: u32,
    pub o: [i64; 3],
    pub cols: (u32, u32),
}

impl<'t> Scan<'t> {
    /// Triangle `t` (id `id`) in the tile `(x0, x1)` columns, for sample offset `(ox, oy)`.
    #[inline(always)]
    pub fn new(t: &'t Tri, id: u32, (ox, oy): (i64, i64), (x0, x1): (u32, u32)) -> Scan<'t> {
        let bb = t.bbox();
        Scan {
            t,
            id,
            o: each3(|i| t.a(i) * ox + t.b(i) * oy - t.bias(i)),
            cols: (bb[0].max(x0), bb[2].min(x1)),
        }
    }
}

impl Tiles<'_> {
    /// Whether triangle `id` covers the centre of every pixel of the rectangle `(x0, y0, x1, y1)`
    /// (exclusive max) by the top-left rule: the four corner pixels are covered, and the
    /// triangle is convex.
    pub(crate) fn covers_rect(&self, id: u32, (x0, y0, x1, y1): (u32, u32, u32, u32)) -> bool {
        let t = self.binned.tri(id);
        let centre = |p: u32| (i64::from(p) << SUBPIXEL_BITS) + HALF;
        [(x0, y0), (x1 - 1, y0), (x0, y1 - 1), (x1 - 1, y1 - 1)]
            .iter()
            .all(|&(px, py)| t.covers(centre(px), centre(py)).is_some())
    }

    /// [`TilePlan::Covered`](super::TilePlan::Covered): every pixel sees the tile's only
    /// triangle (its depth, finite inside the clipped volume, passes against the cleared
    /// buffer), so there is no edge, depth or sorting work.
    pub(super) fn tile_covered(
        &self,
        tile: &Tile,
        rows: &mut [&mut [[f32; 4]]],
        store: Store,
        ids: &mut Vec<u32>,
    ) -> u64 {
        let mut marks = Marks::start();
        marks.shading();
        ids.clear();
        ids.resize(tile.width() * tile.height(), 0);
        self.shade_single(tile, ids, rows, store, marks)
    }

    /// A one-sample tile's `depth` (all `+∞`) and `ids` (all `u32::MAX`), and the build of the
    /// visibility kernels for it: the AVX2 kernel costs more per triangle and less per pixel
    /// than the scalar loop, so it draws tiles of 8 pixels per triangle or more (BENCHMARKS.md,
    /// C4: every tile by it was no faster on the 1M Phong sphere, whose time is its shading).
    fn single_buffers(&self, tile: &Tile, depth: &mut Vec<f32>, ids: &mut Vec<u32>) -> Isa {
        let n = tile.width() * tile.height();
        depth.clear();
        depth.resize(n, f32::INFINITY);
        ids.clear();
        ids.resize(n, u32::MAX);
        if n >= 8 * tile.bin.len() {
            self.plan.isa
        } else {
            Isa::PORTABLE
        }
    }

    /// [`TilePlan::Single`](super::TilePlan::Single): one sample a pixel. `ids` gets, per
    /// pixel, the index in the bin of its visible triangle, or [`FORWARD`] where a Gouraud
    /// triangle coloured it, or `u32::MAX` (background); then [`Tiles::shade_single`].
    pub(super) fn tile_single(
        &self,
        tile: &Tile,
        rows: &mut [&mut [[f32; 4]]],
        store: Store,
        depth: &mut Vec<f32>,
        ids: &mut Vec<u32>,
    ) -> u64 {
        let mut marks = Marks::start();
        let isa = self.single_buffers(tile, depth, ids);
        let span = (tile.x0, tile.y0, tile.width(), tile.y1);
        // Blended triangles come last in a bin (`Scene::draw_order`), after the opaque image.
        let mut blended = tile.bin.len();
        for (k, &ti) in tile.bin.iter().enumerate() {
            if let Some(&ahead) = tile.bin.get(k + PREFETCH_AHEAD) {
                prefetch(self.binned.tri(ahead));
            }
            let scan = Scan::new(self.binned.tri(ti), k as u32, self.plan.pattern[0], (tile.x0, tile.x1));
            match self.plan.objects[self.binned.object(ti)].visibility {
                Visibility::Blended => {
                    blended = k;
                    break;
                }
                Visibility::AlphaTested => {
                    let passes = |px, py| self.alpha_passes(ti, px, py);
                    visible_single::<true, [f32; 4]>(scan, span, depth, ids, None, passes);
                }
                Visibility::Opaque if matches!(self.plan.objects[self.binned.object(ti)].mode, Mode::Gouraud) => {
                    let forward = Forward {
                        planes: ColorPlanes::new(&ColourPlanes::from(self.binned.planes(ti))),
                        rows: &mut *rows,
                    };
                    visible_single::<true, _>(scan, span, depth, ids, Some(forward), |_, _| true);
                }
                Visibility::Opaque => opaque_single(isa, tile, scan, depth, ids),
            }
        }
        marks.shading();
        let shaded = self.shade_single(tile, ids, rows, store, marks);
        shaded + self.blend_single(tile, &tile.bin[blended..], depth, rows)
    }

    /// [`Tiles::tile_single`] into the rows of an 8-bit frame that `Encoding::Linear` encodes,
    /// for a frame whose objects are all opaque and per-pixel Phong
    /// ([`FramePlan::phong_only`](crate::plan::FramePlan::phong_only)): the same visibility,
    /// then [`Tiles::shade_single8`].
    pub(super) fn tile_single8(
        &self,
        tile: &Tile,
        rows: &mut [&mut [[u8; 4]]],
        depth: &mut Vec<f32>,
        ids: &mut Vec<u32>,
    ) -> u64 {
        let mut marks = Marks::start();
        let isa = self.single_buffers(tile, depth, ids);
        for (k, &ti) in tile.bin.iter().enumerate() {
            if let Some(&ahead) = tile.bin.get(k + PREFETCH_AHEAD) {
                prefetch(self.binned.tri(ahead));
            }
            let scan = Scan::new(self.binned.tri(ti), k as u32, self.plan.pattern[0], (tile.x0, tile.x1));
            opaque_single(isa, tile, scan, depth, ids);
        }
        marks.shading();
        self.shade_single8(tile, ids, rows, marks)
    }

    /// Blends `bin`'s triangles (blended objects', in drawing order) over the shaded tile
    /// `rows`, where nearer than `depth` (the opaque triangles'), as the reference path does:
    /// each point shaded by [`Tiles::shade_pixel`] and laid `over` the pixel, depth unchanged.
    /// Returns the shadings done.
    fn blend_single(&self, tile: &Tile, bin: &[u32], depth: &[f32], rows: &mut [&mut [[f32; 4]]]) -> u64 {
        let mut shaded = 0;
        let tw = tile.width();
        for &ti in bin {
            let t = self.binned.tri(ti);
            let scan = Scan::new(t, 0, self.plan.pattern[0], (tile.x0, tile.x1));
            covered_single(scan, (tile.x0, tile.y0, tw, tile.y1), |px, py, zz| {
                let at = (py - tile.y0) as usize * tw + (px - tile.x0) as usize;
                if zz < depth[at] {
                    shaded += 1;
                    if let Some(c) = self.shade_pixel(ti, px, py) {
                        let o = &mut rows[(py - tile.y0) as usize][(px - tile.x0) as usize];
                        *o = resolve(std::iter::once(over(c, *o)), 1, self.plan.bg);
                    }
                }
            });
        }
        shaded
    }

    /// [`TilePlan::Multi`](super::TilePlan::Multi): several samples a pixel. `ids` gets, per
    /// sample, the packed id of its visible triangle or `u32::MAX`; then
    /// [`Tiles::shade_multi`].
    pub(super) fn tile_multi(&self, tile: &Tile, rows: &mut [&mut [[f32; 4]]], work: &mut Multi) -> u64 {
        let Multi { depth, ids, .. } = work;
        let mut marks = Marks::start();
        let Tile { x0, y0, x1, y1, .. } = *tile;
        let tw = tile.width();
        let ns = self.plan.pattern.len();
        depth.clear();
        depth.resize(tw * tile.height() * ns, f32::INFINITY);
        ids.clear();
        ids.resize(tw * tile.height() * ns, u32::MAX);
        if self.plan.opaque_only {
            let bin = tile.bin;
            let mut buf = SampleBuffers {
                rect: (x0, y0, x1, y1),
                depth,
                ids,
            };
            let tri = |k: usize| {
                if let Some(&ahead) = bin.get(k + PREFETCH_AHEAD) {
                    prefetch(self.binned.tri(ahead));
                }
                (self.binned.tri(bin[k]), bin[k])
            };
            if multi_visible_run(self.plan.isa, bin.len(), tri, &self.plan.pattern, &mut buf) {
                marks.shading();
                return self.shade_multi(tile, work, rows, &[], marks);
            }
        }
        let mut offsets = [[0i64; 3]; 16];
        // Blended triangles come last in a bin (`Scene::draw_order`), after the opaque samples.
        let mut blended = tile.bin.len();
        for (k, &ti) in tile.bin.iter().enumerate() {
            if let Some(&ahead) = tile.bin.get(k + PREFETCH_AHEAD) {
                prefetch(self.binned.tri(ahead));
            }
            let t = self.binned.tri(ti);
            match self.plan.objects[self.binned.object(ti)].visibility {
                Visibility::Blended => {
                    blended = k;
                    break;
                }
                Visibility::AlphaTested => {
                    // As the reference: the samples nearer than what they hold, then the alpha
                    // test once at the pixel's centre.
                    self.covered_multi(t, tile, |px, py, base, zs, covered| {
                        let mut mask = 0u32;
                        for s in Bits(covered) {
                            mask |= u32::from(zs[s] < depth[base + s]) << s;
                        }
                        if mask != 0 && self.alpha_passes(ti, px, py) {
                            for s in Bits(mask) {
                                depth[base + s] = zs[s];
                                ids[base + s] = ti;
                            }
                        }
                    });
                    continue;
                }
                Visibility::Opaque => {}
            }
            let mut buf = SampleBuffers {
                rect: (x0, y0, x1, y1),
                depth,
                ids,
            };
            if multi_visible(self.plan.isa, t, ti, &self.plan.pattern, &mut buf) {
                continue;
            }
            // Per sample an offset from the pixel corner, per pixel a step of `a·256`: exact
            // integer adds, the reference's values.
            for (o, &(ox, oy)) in offsets.iter_mut().zip(&self.plan.pattern) {
                *o = each3(|i| t.a(i) * ox + t.b(i) * oy - t.bias(i));
            }
            let step = each3(|i| t.a(i) << SUBPIXEL_BITS);
            let bb = t.bbox();
            let (bx0, bx1) = (bb[0].max(x0), bb[2].min(x1));
            for py in bb[1].max(y0)..bb[3].min(y1) {
                let (cx, cy) = (i64::from(bx0) << SUBPIXEL_BITS, i64::from(py) << SUBPIXEL_BITS);
                let mut row = t.edges_at(cx, cy);
                for px in bx0..bx1 {
                    let base = ((py - y0) as usize * tw + (px - x0) as usize) * ns;
                    for (s, o) in offsets[..ns].iter().enumerate() {
                        // e − bias >= 0 on every edge: covered (top-left rule).
                        let eb = [row[0] + o[0], row[1] + o[1], row[2] + o[2]];
                        if (eb[0] | eb[1] | eb[2]) < 0 {
                            continue;
                        }
                        let e = each3(|i| eb[i] + t.bias(i));
                        let l = map3(e, |x| (x as f64 * t.inv_area) as f32);
                        let zz = l[0] * t.z[0] + l[1] * t.z[1] + l[2] * t.z[2];
                        if zz < depth[base + s] {
                            depth[base + s] = zz;
                            ids[base + s] = ti;
                        }
                    }
                    for i in 0..3 {
                        row[i] += step[i];
                    }
                }
            }
        }
        marks.shading();
        self.shade_multi(tile, work, rows, &tile.bin[blended..], marks)
    }

    /// Each pixel of `tile` with a sample that triangle `t` covers, handed to
    /// `pixel(px, py, base, depths, covered)`: `base` indexes its first sample in the tile's
    /// buffers, `covered` has bit `s` set for each covered sample and `depths[s]` its depth
    /// ([`Tiles::tile_multi`]'s arithmetic, without the depth test).
    #[inline(never)]
    pub(super) fn covered_multi(&self, t: &Tri, tile: &Tile, mut pixel: impl FnMut(u32, u32, usize, &[f32; 16], u32)) {
        let Tile { x0, y0, x1, y1, .. } = *tile;
        let (tw, ns) = (tile.width(), self.plan.pattern.len());
        let mut offsets = [[0i64; 3]; 16];
        for (o, &(ox, oy)) in offsets.iter_mut().zip(&self.plan.pattern) {
            *o = each3(|i| t.a(i) * ox + t.b(i) * oy - t.bias(i));
        }
        let step = each3(|i| t.a(i) << SUBPIXEL_BITS);
        let bb = t.bbox();
        let (bx0, bx1) = (bb[0].max(x0), bb[2].min(x1));
        let mut zs = [0f32; 16];
        for py in bb[1].max(y0)..bb[3].min(y1) {
            let (cx, cy) = (i64::from(bx0) << SUBPIXEL_BITS, i64::from(py) << SUBPIXEL_BITS);
            let mut row = t.edges_at(cx, cy);
            for px in bx0..bx1 {
                let mut covered = 0u32;
                for (s, o) in offsets[..ns].iter().enumerate() {
                    let eb = [row[0] + o[0], row[1] + o[1], row[2] + o[2]];
                    if (eb[0] | eb[1] | eb[2]) < 0 {
                        continue;
                    }
                    let e = each3(|i| eb[i] + t.bias(i));
                    let l = map3(e, |x| (x as f64 * t.inv_area) as f32);
                    zs[s] = l[0] * t.z[0] + l[1] * t.z[1] + l[2] * t.z[2];
                    covered |= 1 << s;
                }
                if covered != 0 {
                    pixel(
                        px,
                        py,
                        ((py - y0) as usize * tw + (px - x0) as usize) * ns,
                        &zs,
                        covered,
                    );
                }
                for i in 0..3 {
                    row[i] += step[i];
                }
            }
        }
    }
}

/// The visibility of an opaque triangle in a one-sample tile: by the vector kernel where
/// `isa` has it, else the scalar loop.
fn opaque_single(isa: Isa, tile: &Tile, scan: Scan, depth: &mut [f32], ids: &mut [u32]) {
    let span = (tile.x0, tile.y0, tile.width(), tile.y1);
    let mut buf = SampleBuffers {
        rect: (tile.x0, tile.y0, tile.x1, tile.y1),
        depth,
        ids,
    };
    if !single_visible(isa, scan.t, scan.id, scan.o, scan.cols, &mut buf) {
        visible_single::<true, [f32; 4]>(scan, span, depth, ids, None, |_, _| true);
    }
}

/// Visibility of one triangle with one sample per pixel (see [`Scan`]), over its rows in the
/// tile `span`. Wide rows first find their covered span exactly (per edge, the integer bound
/// of `e − bias + k·step >= 0`), so the loop over pixels tests no edges; narrow ones (under 8
/// pixels, where the three divisions cost more) test each pixel.
///
/// With `forward`, each pixel that passes gets its colour at once and the id [`FORWARD`].
/// Without `IDS` (all-Gouraud tiles) no id is written and `ids` is not read. A pixel that
/// passes the depth test must then pass `passes(px, py)` (the alpha test) to be written.
#[inline(always)]
pub(super) fn visible_single<const IDS: bool, T: TilePixel>(
    Scan {
        t,
        id: ti,
        o,
        cols: (bx0, bx1),
    }: Scan,
    (x0, y0, tw, y1): Span,
    depth: &mut [f32],
    ids: &mut [u32],
    mut forward: Option<Forward<T>>,
    passes: impl Fn(u32, u32) -> bool,
) {
    let step = each3(|i| t.a(i) << SUBPIXEL_BITS);
    let bb = t.bbox();
    let n = i64::from(bx1 - bx0);
    for py in bb[1].max(y0)..bb[3].min(y1) {
        let (cx, cy) = (i64::from(bx0) << SUBPIXEL_BITS, i64::from(py) << SUBPIXEL_BITS);
        // e − bias at the row's first pixel.
        let e = t.edges_at(cx, cy);
        let row = each3(|i| e[i] + o[i]);
        let (lo, hi) = covered_span(row, step, n);
        let line = (py - y0) as usize * tw + (bx0 - x0) as usize;
        let mut eb = each3(|i| row[i] + step[i] * lo);
        // Forward: the pixels of this row (at most a tile's 64) that passed.
        let mut passed = 0u64;
        for k in lo..hi {
            if (eb[0] | eb[1] | eb[2]) >= 0 {
                let e = each3(|i| eb[i] + t.bias(i));
                let l = map3(e, |x| (x as f64 * t.inv_area) as f32);
                let zz = l[0] * t.z[0] + l[1] * t.z[1] + l[2] * t.z[2];
                let at = line + k as usize;
                if zz < depth[at] && passes(bx0 + k as u32, py) {
                    depth[at] = zz;
                    if forward.is_some() {
                        if IDS {
                            ids[at] = FORWARD;
                        }
                        passed |= 1 << k;
                    } else if IDS {
                        ids[at] = ti;
                    }
                }
            }
            for i in 0..3 {
                eb[i] += step[i];
            }
        }
        if let Some(f) = &mut forward
            && passed != 0
        {
            let row = &mut f.rows[(py - y0) as usize][(bx0 - x0) as usize..(bx1 - x0) as usize];
            let mut m = passed;
            while m != 0 {
                let j = m.trailing_zeros();
                row[j as usize] = T::from_linear(f.planes.at(bx0 + j, py));
                m &= m - 1;
            }
        }
    }
}

/// Each pixel centre of the tile `span` that triangle `scan.t` covers, with its depth, handed to
/// `point(px, py, depth)`: [`visible_single`]'s coverage and depth arithmetic, without the test.
pub(super) fn covered_single(
    Scan {
        t, o, cols: (bx0, bx1), ..
    }: Scan,
    (_, y0, _, y1): Span,
    mut point: impl FnMut(u32, u32, f32),
) {
    let step = each3(|i| t.a(i) << SUBPIXEL_BITS);
    let bb = t.bbox();
    let n = i64::from(bx1 - bx0);
    for py in bb[1].max(y0)..bb[3].min(y1) {
        let (cx, cy) = (i64::from(bx0) << SUBPIXEL_BITS, i64::from(py) << SUBPIXEL_BITS);
        let e = t.edges_at(cx, cy);
        let row = each3(|i| e[i] + o[i]);
        let (lo, hi) = covered_span(row, step, n);
        let mut eb = each3(|i| row[i] + step[i] * lo);
        for k in lo..hi {
            if (eb[0] | eb[1] | eb[2]) >= 0 {
                let e = each3(|i| eb[i] + t.bias(i));
                let l = map3(e, |x| (x as f64 * t.inv_area) as f32);
                point(bx0 + k as u32, py, l[0] * t.z[0] + l[1] * t.z[1] + l[2] * t.z[2]);
            }
            for i in 0..3 {
                eb[i] += step[i];
            }
        }
    }
}

/// The set bits of a mask, lowest first.
pub(super) struct Bits(pub u32);

impl Iterator for Bits {
    type Item = usize;
    #[inline]
    fn next(&mut self) -> Option<usize> {
        (self.0 != 0).then(|| {
            let s = self.0.trailing_zeros() as usize;
            self.0 &= self.0 - 1;
            s
        })
    }
}
