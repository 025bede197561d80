//! All-Gouraud frames with one sample ([`TilePlan::Gouraud`](super::TilePlan::Gouraud)): every
//! visible pixel is coloured during visibility (see `visible::Forward`), so
//! the tile starts as background and needs no ids, no scan and no deferred shading. By the
//! AVX2 kernel ([`gouraud_tile`]) or the scalar loop (`visible_single`), the same bits, into
//! `f32` rows or straight into an 8-bit frame's.

use super::Tile;
use super::Tiles;
use super::visible::{ColorPlanes, Forward, PREFETCH_AHEAD, Scan, visible_single};
use crate::fixed::each3;
use crate::simd::{GouraudTri, TilePixel, gouraud_tile, prefetch};
use crate::stats::Marks;
use crate::target::resolve;
use phong_core::limits::SUBPIXEL_BITS;

impl Tiles<'_> {
    /// Draws `tile` of an all-Gouraud, one-sample frame into `rows`, by the AVX2 kernel with
    /// `kernel` (an AVX2 frame), else by the scalar loop; returns the pixels covered. Not
    /// inlined into the tile's `match` (BENCHMARKS.md, C7).
    #[inline(never)]
    pub(super) fn tile_gouraud<T: TilePixel>(
        &self,
        tile: &Tile,
        rows: &mut [&mut [T]],
        depth: &mut Vec<f32>,
        kernel: bool,
    ) -> u64 {
        let marks = Marks::start();
        let Tile {
            x0, y0, x1, y1, bin, ..
        } = *tile;
        // The kernel tests windows of 4 pixels aligned in the tile: rows of a multiple of 4
        // depths (the extra ones stay infinite).
        let tw = tile.width();
        let stride = if kernel { tw.next_multiple_of(4) } else { tw };
        depth.clear();
        depth.resize(stride * tile.height(), f32::INFINITY);
        let background = T::from_linear(resolve(std::iter::once(self.plan.bg), 1, self.plan.bg));
        for line in rows.iter_mut() {
            line.fill(background);
        }
        let isa = if kernel {
            self.plan.isa
        } else {
            crate::simd::Isa::PORTABLE
        };
        let triangle = |k: usize| {
            // Ahead, the records this triangle's successors read (a bin's triangles are
            // scattered through memory; a fine mesh's tile draws thousands).
            if let Some(&ahead) = bin.get(k + PREFETCH_AHEAD) {
                prefetch(self.binned.tri(ahead));
                prefetch(self.binned.colour(ahead));
            }
            self.gouraud_tri(bin[k], (x0, y0, x1, y1))
        };
        if let Some(covered) = gouraud_tile(isa, (x0, y0), stride, bin.len(), triangle, depth, rows) {
            tile.clock.add(marks);
            return covered;
        }
        for &ti in bin {
            let scan = Scan::new(self.binned.tri(ti), 0, self.plan.pattern[0], (x0, x1));
            let forward = Forward {
                planes: ColorPlanes::new(self.binned.colour(ti)),
                rows: &mut *rows,
            };
            visible_single::<false, T>(scan, (x0, y0, tw, y1), depth, &mut [], Some(forward), |_, _| true);
        }
        tile.clock.add(marks);
        depth.iter().filter(|&&d| d != f32::INFINITY).count() as u64
    }

    /// Triangle `ti` as the Gouraud kernel draws it into the tile `(x0, y0, x1, y1)`.
    #[inline(always)]
    fn gouraud_tri(&self, ti: u32, (x0, y0, x1, y1): (u32, u32, u32, u32)) -> GouraudTri<'_> {
        let (ox, oy) = self.plan.pattern[0];
        let t = self.binned.tri(ti);
        let bb = t.bbox();
        let (bx0, by0) = (bb[0].max(x0), bb[1].max(y0));
        let (cx, cy) = (i64::from(bx0) << SUBPIXEL_BITS, i64::from(by0) << SUBPIXEL_BITS);
        GouraudTri {
            start: {
                let e = t.edges_at(cx + ox, cy + oy);
                each3(|i| e[i] - t.bias(i))
            },
            step_x: each3(|i| t.a(i) << SUBPIXEL_BITS),
            step_y: each3(|i| t.b(i) << SUBPIXEL_BITS),
            bias: each3(|i| t.bias(i)),
            inv_area: t.inv_area,
            z: t.z,
            cols: (bx0 - x0, bb[2].min(x1).max(bx0) - x0),
            rows: (by0 - y0, bb[3].min(y1).max(by0) - y0),
            planes: self.binned.colour(ti),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::TilePlan;
    use super::*;
    use crate::plan::{FramePlan, Path};
    use crate::setup::Scratch;
    use crate::stats::StageClock;
    use crate::target::encode;
    use crate::testkit::xorshift;
    use crate::{RenderOptions, Renderer};
    use glam::Vec3;
    use phong_core::Encoding;

    /// The AVX2 Gouraud tile kernel draws every tile of a frame bit for bit as the scalar loop
    /// (`visible_single`): each colour and depth, and the count of covered pixels; and into an
    /// 8-bit frame, the scalar loop's colours as `Encoding::Linear` encodes them. Whole frames
    /// too: `render` chooses the kernel for some tiles, and its 8-bit frames are the `f32`
    /// frames' bytes. Frames of 203 × 149 pixels (a last column of tiles 11 pixels wide, not a
    /// multiple of the kernel's 4) with a sphere, a torus and a two-sided ground plane through
    /// the near plane, and a soup of random triangles from under a pixel to wider than the
    /// frame, interpenetrating, drawn twice in two materials (equal depths: the first stays),
    /// some of them also with their vertices rotated.
    #[test]
    fn gouraud_kernel_is_the_scalar_loop() {
        let Some(avx2) = crate::testkit::avx2() else {
            return;
        };
        let src = r#"
[image]
width = 203
height = 149
background = [0.1, 0.2, 0.3]
[camera]
position = [0.0, 0.4, 0.5]
target = [0.0, 0.0, -2.0]
near = 0.1
[shading]
model = "blinn-phong"
interpolation = "gouraud"
two_sided = true
[[light]]
type = "point"
position = [0.5, 2.0, -1.0]
attenuation = [1.0, 0.1, 0.05]
[[object]]
shape = "sphere"
segments = 40
material = "gold"
position = [-0.4, 0.0, -2.0]
scale = 0.7
[[object]]
shape = "torus"
segments = 32
material = "ruby"
position = [0.5, 0.0, -1.5]
[[object]]
shape = "plane"
segments = 6
material = "pewter"
position = [0.0, -0.5, 0.0]
scale = 300.0
"#;
        let path = std::path::Path::new("gouraud-kernel.toml");
        let shapes = phong_scene::parse_scene(src, path).unwrap().scene;
        let mut soup = shapes.clone();
        soup.objects.truncate(2);
        let mut next = xorshift(0x9e37_79b9_7f4a_7c15);
        let mut unit = move || (next() >> 11) as f32 / (1u64 << 53) as f32;
        let mut positions = Vec::new();
        let mut triangles = Vec::new();
        for k in 0..400u32 {
            let centre = Vec3::new(unit() * 3.0 - 1.5, unit() * 2.0 - 1.0, -1.0 - unit() * 3.0);
            let size = [0.004, 0.05, 0.3, 2.5][k as usize % 4] * (0.5 + unit());
            for _ in 0..3 {
                positions.push(centre + (Vec3::new(unit(), unit(), unit()) - 0.5) * size);
            }
            triangles.push([3 * k, 3 * k + 1, 3 * k + 2]);
            if k % 10 == 0 {
                triangles.push([3 * k + 1, 3 * k + 2, 3 * k]);
            }
        }
        // Twice, in two materials: the same depths, other colours.
        let mesh = phong_core::Mesh::from_triangles(positions, triangles).unwrap();
        for object in &mut soup.objects {
            object.mesh = mesh.clone();
        }
        for (name, scene) in [("shapes", &shapes), ("soup", &soup)] {
            let plan = FramePlan::new(scene, Path::Fast, avx2);
            let binned = crate::setup::run(&plan, scene, &mut Scratch::default());
            let frame = Tiles {
                plan: &plan,
                scene,
                binned: &binned,
            };
            let clock = StageClock::default();
            let (mut drawn, mut wide, mut chosen) = (0, 0, 0);
            for index in 0..binned.bins.len() as u32 {
                let tile = frame.tile(index, &clock);
                chosen += usize::from(frame.plan_tile(&tile) == TilePlan::Gouraud { kernel: true });
                let (tw, th) = (tile.width(), tile.height());
                let draw = |kernel: bool| {
                    let mut pixels = vec![[f32::NAN; 4]; tw * th];
                    let mut rows: Vec<&mut [[f32; 4]]> = pixels.chunks_mut(tw).collect();
                    let mut depth = Vec::new();
                    let n = frame.tile_gouraud(&tile, &mut rows, &mut depth, kernel);
                    let stride = depth.len() / th;
                    let depth: Vec<f32> = depth.chunks(stride).flat_map(|r| r[..tw].to_vec()).collect();
                    let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                    (n, bits(pixels.as_flattened()), bits(&depth))
                };
                let (scalar, vector) = (draw(false), draw(true));
                assert!(scalar == vector, "{name}: tile {index} differs");
                // Straight into 8 bits, by the kernel and by the scalar loop: the scalar loop's
                // f32 pixels encoded.
                let encoded: Vec<[u8; 4]> = scalar
                    .1
                    .chunks(4)
                    .map(|p| encode([0, 1, 2, 3].map(|i| f32::from_bits(p[i])), Encoding::Linear))
                    .collect();
                for kernel in [true, false] {
                    let mut bytes = vec![[7u8; 4]; tw * th];
                    let mut rows: Vec<&mut [[u8; 4]]> = bytes.chunks_mut(tw).collect();
                    let n8 = frame.tile_gouraud(&tile, &mut rows, &mut Vec::new(), kernel);
                    assert_eq!(n8, scalar.0, "{name}: tile {index}");
                    assert!(bytes == encoded, "{name}: tile {index} differs in 8 bits");
                }
                drawn += scalar.0;
                wide += u64::from(tw % 4 != 0 && scalar.0 > 0);
            }
            assert!(drawn > 203 * 149 / 2, "{name}: only {drawn} pixels drawn");
            assert!(wide > 0, "{name}: nothing drawn in the narrow tiles");
            assert!(chosen > 0, "{name}: no tile for the kernel");
            // Whole frames: `render` chooses the kernel for some tiles (straight into 8 bits
            // for the 8-bit frame), and the frames are the `f32` image's bytes, with 1 and 3
            // threads.
            for threads in [1, 3] {
                let options = RenderOptions {
                    threads: Some(threads),
                    ..Default::default()
                };
                let f32_bytes = crate::render(scene, &options)
                    .unwrap()
                    .to_bytes(Encoding::Linear, false);
                let mut renderer = Renderer::new();
                let (image8, _) = renderer.render_8bit(scene, &options).unwrap().unwrap();
                assert!(image8.to_bytes(false) == f32_bytes, "{name}: 8-bit frame differs");
            }
        }
    }
}
