//! The reference path's tile: per pixel and triangle in drawing order, each sample's edge
//! functions evaluated directly, a `GL_LESS` depth test, and one `shade` at the pixel centre
//! written to the samples that passed (as MSAA); then the resolve. Kept simple: the fast
//! path is tested against it. A blended object's pixels are blended over the samples by
//! their alpha (`GL_ONE_MINUS_SRC_ALPHA`, in premultiplied form) without writing depth.

use super::Tile;
use super::Tiles;
use crate::fixed::map3;
use crate::stats::Marks;
use crate::target::resolve;
use phong_core::limits::SUBPIXEL_BITS;

impl Tiles<'_> {
    /// Draws and resolves `tile` into `rows`; returns the pixel shadings done (overdraw
    /// included). Rasterising and shading are interleaved, so both count as its `raster` stage.
    pub(super) fn tile_reference(&self, tile: &Tile, rows: &mut [&mut [[f32; 4]]]) -> u64 {
        let mut marks = Marks::start();
        let Tile { x0, y0, x1, y1, .. } = *tile;
        let (tw, th) = (tile.width(), tile.height());
        let ns = self.plan.pattern.len();
        let mut color = vec![self.plan.bg; tw * th * ns];
        let mut depth = vec![f32::INFINITY; tw * th * ns];
        let mut shaded = 0u64;
        let mut zs = [0f32; 16];
        for &ti in tile.bin {
            let t = self.binned.tri(ti);
            let blends = self.scene.objects[self.binned.object(ti)].blends();
            let bb = t.bbox();
            let (bx0, by0, bx1, by1) = (bb[0].max(x0), bb[1].max(y0), bb[2].min(x1), bb[3].min(y1));
            for py in by0..by1 {
                for px in bx0..bx1 {
                    let base = ((py - y0) as usize * tw + (px - x0) as usize) * ns;
                    let mut mask = 0u32;
                    for (s, &(ox, oy)) in self.plan.pattern.iter().enumerate() {
                        let sx = (i64::from(px) << SUBPIXEL_BITS) + ox;
                        let sy = (i64::from(py) << SUBPIXEL_BITS) + oy;
                        let Some(e) = t.covers(sx, sy) else {
                            continue;
                        };
                        let l = map3(e, |x| (x as f64 * t.inv_area) as f32);
                        let zz = l[0] * t.z[0] + l[1] * t.z[1] + l[2] * t.z[2];
                        if zz < depth[base + s] {
                            zs[s] = zz;
                            mask |= 1 << s;
                        }
                    }
                    if mask == 0 {
                        continue;
                    }
                    shaded += 1;
                    // Discarded by the alpha test: no colour, no depth.
                    let Some(c) = self.shade_pixel(ti, px, py) else {
                        continue;
                    };
                    for s in 0..ns {
                        if mask & (1 << s) != 0 {
                            if blends {
                                color[base + s] = over(c, color[base + s]);
                            } else {
                                depth[base + s] = zs[s];
                                color[base + s] = c;
                            }
                        }
                    }
                }
            }
        }
        marks.shading();
        marks.resolving();
        for (px, o) in color.chunks_exact(ns).zip(rows.iter_mut().flat_map(|r| r.iter_mut())) {
            *o = resolve(px.iter().copied(), ns, self.plan.bg);
        }
        tile.clock.add(marks);
        shaded
    }
}

/// `src` over `dst` (straight alpha both): in premultiplied form `src + dst·(1 − α_src)`, back
/// to straight alpha.
#[inline]
pub(crate) fn over(src: [f32; 4], dst: [f32; 4]) -> [f32; 4] {
    let a = src[3] + dst[3] * (1.0 - src[3]);
    if a <= 0.0 {
        return [0.0; 4];
    }
    let c = |i: usize| (src[i] * src[3] + dst[i] * dst[3] * (1.0 - src[3])) / a;
    [c(0), c(1), c(2), a]
}
