//! The fast path's deferred shading of the visible pixels, and the scalar shading of one pixel
//! that the reference path and the fast path's scalar objects share.
//!
//! Phong and Gouraud pixels are shaded by the vector kernels: with one sample, sorted by
//! triangle so that each triangle's whole vectors share its plane coefficients
//! ([`shade_group`]), the rest gathered lane by lane ([`Tiles::shade_gathered`]); with
//! several, one job per visible (pixel, triangle), gathered, then the reference's resolve.

use super::Tiles;
use super::reference::over;
use super::visible::{Bits, FORWARD};
use super::{Multi, Tile};
use crate::clip::ClipVertex;
use crate::fixed::{HALF, each3, map3};
use crate::plan::{Mode, lit_term};
use crate::setup::{Corners, Tri};
use crate::simd::kernel::pixel_centre;
use crate::simd::{
    Planes, group_lanes, prefetch, shade_batch, shade_batch_lit, shade_batch_textured, shade_batch8, shade_group,
    shade_group_textured, shade_group8,
};
use crate::stats::Marks;
use crate::target::{Store, encode, fill, resolve};
use glam::{Vec2, Vec3};
use phong_core::limits::SUBPIXEL_BITS;
use phong_core::{
    Color, Encoding, Interpolation, Lit, Maps, Output, ShadingOptions, SurfacePoint, depth_color, normal_color,
    perturb, shade_textured,
};

/// How many of `ids` from the start equal `k`: 8 compared at a time (a branch-free mask LLVM
/// vectorises; BENCHMARKS.md, C5).
#[inline]
pub(super) fn run_length(ids: &[u32], k: u32) -> usize {
    let mut chunks = ids.chunks_exact(8);
    let mut n = 0;
    for c in &mut chunks {
        let mut differ = 0u32;
        for (i, &id) in c.iter().enumerate() {
            differ |= u32::from(id != k) << i;
        }
        if differ != 0 {
            return n + differ.trailing_zeros() as usize;
        }
        n += 8;
    }
    n + chunks.remainder().iter().take_while(|&&id| id == k).count()
}

/// The counting sort of a one-sample tile's visible pixels by triangle: `ids` is, per pixel,
/// the index in the bin of its visible triangle, or [`FORWARD`], or `u32::MAX`; runs of equal
/// ids along rows are counted, and `other(row, columns, id)` takes the runs of the last two.
/// Returns `starts` (where triangle `k`'s pixels begin in `order`, `starts[bin.len()]` all of
/// them) and `order`, the pixels as `row << 16 | column`, each triangle's in row order.
fn sort_by_triangle(
    tile: &Tile,
    ids: &[u32],
    mut other: impl FnMut(usize, std::ops::Range<usize>, u32),
) -> (Vec<u32>, Vec<u32>) {
    let (tw, th) = (tile.width(), tile.height());
    let n = tile.bin.len();
    // starts[k + 1]: how many visible pixels triangle k of the bin has, then (prefix sums)
    // where its pixels end in `order`. Runs are `(row << 16 | first column, length, k)`.
    let mut starts = vec![0u32; n + 1];
    let mut runs: Vec<(u32, u32, u32)> = Vec::with_capacity(tw * th / 4);
    for row in 0..th {
        let ids = &ids[row * tw..(row + 1) * tw];
        let mut col = 0;
        while col < tw {
            let k = ids[col];
            let len = run_length(&ids[col..], k);
            if k == u32::MAX || k == FORWARD {
                other(row, col..col + len, k);
            } else {
                starts[k as usize + 1] += len as u32;
                runs.push(((row as u32) << 16 | col as u32, len as u32, k));
            }
            col += len;
        }
    }
    for k in 0..n {
        starts[k + 1] += starts[k];
    }
    let mut order = vec![0u32; starts[n] as usize];
    let mut next = starts.clone();
    for &(first, len, k) in &runs {
        let at = next[k as usize] as usize;
        for (i, o) in order[at..at + len as usize].iter_mut().enumerate() {
            *o = first + i as u32;
        }
        next[k as usize] += len;
    }
    (starts, order)
}

/// A sample's colour from its job index `j` in a multi-sample tile's `colors` (`Multi::which`;
/// `u32::MAX`: the background `bg`).
#[inline(always)]
fn sample_colour(colors: &[[f32; 4]], j: u32, bg: [f32; 4]) -> [f32; 4] {
    if j == u32::MAX { bg } else { colors[j as usize] }
}

/// How many pixels ahead a gathered batch asks for its triangles' planes: two vectors of 8
/// (a fine mesh's planes are scattered through memory, one triangle every pixel or two).
const GATHER_AHEAD: usize = 16;

/// A textured object's jobs of a multi-sample tile: `(pixel, triangle)`, and each one's index
/// in the tile's jobs.
type TexturedJobs = (Vec<(u32, u32)>, Vec<u32>);

impl Tiles<'_> {
    /// Shades, by object, pixels whose triangles differ lane to lane (each lane gathers its
    /// triangle's planes): `batches[object]` are the items, `lane(item)` gives a pixel's centre
    /// and planes, `out(item, rgb)` takes its colour. Scalar-shaded objects are skipped.
    fn shade_gathered<'a, T: Copy>(
        &'a self,
        batches: &[Vec<T>],
        lane: impl Fn(T) -> (f32, f32, &'a Planes),
        mut out: impl FnMut(T, [f32; 3]),
    ) {
        for (object, batch) in batches.iter().enumerate() {
            let Some(kind) = self.plan.objects[object].mode.batch() else {
                continue;
            };
            shade_batch(
                self.plan.isa,
                kind,
                batch.len(),
                |i| {
                    if let Some(&ahead) = batch.get(i + GATHER_AHEAD) {
                        prefetch(lane(ahead).2);
                    }
                    lane(batch[i])
                },
                |i, rgb| out(batch[i], rgb),
            );
        }
    }

    /// The shading of a one-sample tile after visibility: each visible pixel shaded once and
    /// written straight into `out` (the resolve of one opaque sample is the sample itself).
    /// `ids` is, per pixel of the tile, the index in its bin of the visible triangle (or
    /// [`FORWARD`], or `u32::MAX`). The pixels are sorted by triangle (a counting sort over the
    /// bin, by runs of equal ids along rows), so that each triangle's pixels are shaded together
    /// with its plane coefficients broadcast.
    pub(super) fn shade_single(
        &self,
        tile: &Tile,
        ids: &[u32],
        out: &mut [&mut [[f32; 4]]],
        store: Store,
        marks: Marks,
    ) -> u64 {
        let (bin, x0, y0) = (tile.bin, tile.x0, tile.y0);
        let background = resolve(std::iter::once(self.plan.bg), 1, self.plan.bg);
        let mut forward = 0u32;
        let (starts, order) = sort_by_triangle(tile, ids, |row, cols, k| {
            if k == u32::MAX {
                fill(&mut out[row][cols], background, store);
            } else {
                // Coloured during visibility.
                forward += cols.len() as u32;
            }
        });
        crate::simd::stream_fence();
        let shaded = forward + starts[bin.len()];
        // Per object, the pixels left over from whole vectors, with their triangles; and the
        // pixels of textured objects.
        let mut rest: Vec<Vec<(u32, u32)>> = vec![Vec::new(); self.scene.objects.len()];
        let mut textured: Vec<Vec<(u32, u32)>> = vec![Vec::new(); self.scene.objects.len()];
        let at = |p: u32| ((p >> 16) as usize, (p & 0xffff) as usize);
        let group = group_lanes(self.plan.isa);
        let mut unsampled = Vec::new();
        for (k, &id) in bin.iter().enumerate() {
            let pixels = &order[starts[k] as usize..starts[k + 1] as usize];
            if pixels.is_empty() {
                continue;
            }
            let object = self.binned.object(id);
            if let Mode::Textured { prep, lean, .. } = &self.plan.objects[object].mode {
                // Whole vectors of one triangle with its planes broadcast where the vector
                // sampler covers the maps; the rest batched with the object's other pixels.
                let done = match &self.plan.objects[object].maps {
                    Some(maps) if pixels.len() >= group => shade_group_textured(
                        self.plan.isa,
                        ((prep, lean.as_ref()), maps),
                        (self.binned.planes(id), self.binned.uv_planes(id)),
                        (x0, y0),
                        pixels,
                        |p, rgb| {
                            let (r, c) = at(p);
                            out[r][c] = [rgb[0], rgb[1], rgb[2], 1.0];
                        },
                        &mut unsampled,
                    ),
                    _ => 0,
                };
                let tinted = !self.scene.objects[object].mesh.colors().is_empty();
                for (p, light) in unsampled.drain(..) {
                    let (r, c) = at(p);
                    let rgb = self.textured_color(object, (p, id), (x0, y0), tinted, light);
                    out[r][c] = [rgb[0], rgb[1], rgb[2], 1.0];
                }
                textured[object].extend(pixels[done..].iter().map(|&p| (p, id)));
                continue;
            }
            let Some(kind) = self.plan.objects[object].mode.batch() else {
                for &p in pixels {
                    let (r, c) = at(p);
                    // Frames with an alpha test are the reference path's: nothing is discarded here.
                    let color = self
                        .shade_pixel(id, x0 + c as u32, y0 + r as u32)
                        .unwrap_or(self.plan.bg);
                    out[r][c] = resolve(std::iter::once(color), 1, self.plan.bg);
                }
                continue;
            };
            // Fewer pixels than a vector: straight to the gathered batch (no call; a 1M-triangle
            // tile has thousands of one-pixel triangles).
            let done = if pixels.len() < group {
                0
            } else {
                shade_group(
                    self.plan.isa,
                    kind,
                    self.binned.planes(id),
                    (x0, y0),
                    pixels,
                    |p, [red, green, blue]| {
                        let (r, c) = at(p);
                        let run = &mut out[r][c..c + red.len()];
                        for (((o, &r), &g), &b) in run.iter_mut().zip(red).zip(green).zip(blue) {
                            *o = [r, g, b, 1.0];
                        }
                    },
                )
            };
            rest[object].extend(pixels[done..].iter().map(|&p| (p, id)));
        }
        self.shade_gathered(
            &rest,
            |(p, id)| {
                let (x, y) = pixel_centre((x0, y0), p);
                (x, y, self.binned.planes(id))
            },
            |(p, _), rgb| {
                let (r, c) = at(p);
                out[r][c] = [rgb[0], rgb[1], rgb[2], 1.0];
            },
        );
        for (object, items) in textured.iter().enumerate() {
            let Mode::Textured { prep, .. } = &self.plan.objects[object].mode else {
                continue;
            };
            self.shade_textured_batch(object, prep, items, x0, y0, |i, rgb| {
                let (r, c) = at(items[i].0);
                out[r][c] = [rgb[0], rgb[1], rgb[2], 1.0];
            });
        }
        tile.clock.add(marks);
        u64::from(shaded)
    }

    /// [`Tiles::shade_single`] into the rows of an 8-bit frame that `Encoding::Linear`
    /// encodes, for a frame of opaque per-pixel Phong objects only
    /// ([`FramePlan::phong_only`](crate::plan::FramePlan::phong_only)): the same vectors (so
    /// the same colours), encoded in the kernel and written straight into the frame.
    pub(super) fn shade_single8(&self, tile: &Tile, ids: &[u32], rows: &mut [&mut [[u8; 4]]], marks: Marks) -> u64 {
        let (bin, x0, y0) = (tile.bin, tile.x0, tile.y0);
        let background = encode(
            resolve(std::iter::once(self.plan.bg), 1, self.plan.bg),
            Encoding::Linear,
        );
        let (starts, order) = sort_by_triangle(tile, ids, |row, cols, _| rows[row][cols].fill(background));
        let at = |p: u32| ((p >> 16) as usize, (p & 0xffff) as usize);
        let group = group_lanes(self.plan.isa);
        let mut rest: Vec<Vec<(u32, u32)>> = vec![Vec::new(); self.scene.objects.len()];
        for (k, &id) in bin.iter().enumerate() {
            let pixels = &order[starts[k] as usize..starts[k + 1] as usize];
            let object = self.binned.object(id);
            let Some(kind) = self.plan.objects[object].mode.batch() else {
                debug_assert!(false, "a phong_only frame has vector-shaded objects only");
                continue;
            };
            let done = if pixels.len() < group {
                0
            } else {
                shade_group8(
                    self.plan.isa,
                    kind,
                    self.binned.planes(id),
                    (x0, y0),
                    pixels,
                    |p, px| {
                        let (r, c) = at(p);
                        rows[r][c..c + px.len()].copy_from_slice(px);
                    },
                )
            };
            rest[object].extend(pixels[done..].iter().map(|&p| (p, id)));
        }
        for (object, batch) in rest.iter().enumerate() {
            let Some(kind) = self.plan.objects[object].mode.batch() else {
                continue;
            };
            shade_batch8(
                self.plan.isa,
                kind,
                batch.len(),
                |i| {
                    if let Some(&(_, ahead)) = batch.get(i + GATHER_AHEAD) {
                        prefetch(self.binned.planes(ahead));
                    }
                    let (p, id) = batch[i];
                    let (x, y) = pixel_centre((x0, y0), p);
                    (x, y, self.binned.planes(id))
                },
                |i, px| {
                    let (r, c) = at(batch[i].0);
                    rows[r][c] = px;
                },
            );
        }
        tile.clock.add(marks);
        u64::from(starts[bin.len()])
    }

    /// [`TilePlan::Covered`](super::TilePlan::Covered) into the rows of an 8-bit frame that
    /// `Encoding::Linear` encodes, for an object the vector kernels shade untextured: the
    /// tile's pixels in row order, in the vectors [`Tiles::shade_single`] makes of them (so
    /// the same colours), encoded in the kernel and written straight into the frame. `None`
    /// (nothing drawn) for other objects. `covered` keeps the pixel list from tile to tile.
    pub(super) fn tile_covered8(
        &self,
        tile: &Tile,
        rows: &mut [&mut [[u8; 4]]],
        covered: &mut super::CoveredPixels,
    ) -> Option<u64> {
        let id = tile.bin[0];
        let kind = self.plan.objects[self.binned.object(id)].mode.batch()?;
        let mut marks = Marks::start();
        marks.shading();
        let (x0, y0) = (tile.x0, tile.y0);
        let (tw, th) = (tile.width() as u32, tile.height() as u32);
        let pixels = covered.of(tw, th);
        let at = |p: u32| ((p >> 16) as usize, (p & 0xffff) as usize);
        // Its colour planes alone where the frame keeps only those (one triangle: one copy).
        let whole;
        let planes = if self.plan.colour_planes {
            whole = Planes::from(self.binned.colour(id));
            &whole
        } else {
            self.binned.planes(id)
        };
        let done = if pixels.len() < group_lanes(self.plan.isa) {
            0
        } else {
            shade_group8(self.plan.isa, kind, planes, (x0, y0), pixels, |p, px| {
                let (r, c) = at(p);
                rows[r][c..c + px.len()].copy_from_slice(px);
            })
        };
        let rest = &pixels[done..];
        shade_batch8(
            self.plan.isa,
            kind,
            rest.len(),
            |i| {
                let (x, y) = pixel_centre((x0, y0), rest[i]);
                (x, y, planes)
            },
            |i, px| {
                let (r, c) = at(rest[i]);
                rows[r][c] = px;
            },
        );
        tile.clock.add(marks);
        Some(u64::from(tw * th))
    }

    /// Shades a textured object's pixels `items` (`(row << 16 | column, triangle id)` in the
    /// tile at `(x0, y0)`): by the vector sampler where it covers the maps, else their light by
    /// the vector kernel and their maps sampled per pixel ([`Tiles::textured_color`]).
    /// `out(i, rgb)` takes item `i`'s colour.
    fn shade_textured_batch(
        &self,
        object: usize,
        prep: &crate::simd::Prepared,
        items: &[(u32, u32)],
        x0: u32,
        y0: u32,
        mut out: impl FnMut(usize, [f32; 3]),
    ) {
        let tinted = !self.scene.objects[object].mesh.colors().is_empty();
        if let Some(maps) = &self.plan.objects[object].maps {
            let lean = match &self.plan.objects[object].mode {
                Mode::Textured { lean, .. } => lean.as_ref(),
                _ => None,
            };
            let mut unsampled = Vec::new();
            shade_batch_textured(
                self.plan.isa,
                (prep, lean),
                maps,
                items.len(),
                |i| {
                    let (p, id) = items[i];
                    let (x, y) = pixel_centre((x0, y0), p);
                    (x, y, self.binned.planes(id), self.binned.uv_planes(id))
                },
                &mut out,
                &mut unsampled,
            );
            for (i, light) in unsampled {
                out(i, self.textured_color(object, items[i], (x0, y0), tinted, light));
            }
            return;
        }
        shade_batch_lit(
            self.plan.isa,
            prep,
            items.len(),
            |i| {
                let (p, id) = items[i];
                let (x, y) = pixel_centre((x0, y0), p);
                (x, y, self.binned.planes(id))
            },
            |i, primary, specular| {
                out(
                    i,
                    self.textured_color(object, items[i], (x0, y0), tinted, [primary, specular, [0.0; 3]]),
                )
            },
        );
    }

    /// The colour of a textured pixel (`(row << 16 | column, triangle id)` in the tile at
    /// `origin`) from its light `[primary, specular, ambient]` (the ambient terms used where an
    /// ambient map has them apart; see [`crate::simd::Unsampled`]): its maps sampled at the coordinates and
    /// exact derivatives of the triangle's planes and applied (`Lit::modulate`), the diffuse
    /// texel `tinted` by the vertex colours where the mesh has them.
    fn textured_color(
        &self,
        object: usize,
        (p, id): (u32, u32),
        origin: (u32, u32),
        tinted: bool,
        [primary, specular, ambient]: [[f32; 3]; 3],
    ) -> [f32; 3] {
        let obj = &self.scene.objects[object];
        let (x, y) = pixel_centre(origin, p);
        let ([first, second], rgb) = uv_from_planes(self.binned.uv_planes(id), x, y);
        let mut texels = if self.plan.objects[object].second_set {
            obj.maps.sample_sets(&[first, second])
        } else {
            obj.maps.sample(first[0], first[1], first[2])
        };
        if tinted {
            texels = texels.tinted(rgb);
        }
        // As `phong_core::light` splits them: the emission and the ambient terms apart where
        // maps of their own modulate them (the light was prepared so: `emission_apart`); never
        // for light made per vertex (Gouraud: only the diffuse and specular maps apply).
        let per_vertex = matches!(self.plan.objects[object].mode, Mode::Textured { per_vertex: true, .. });
        let (emission_apart, ambient_apart) = if per_vertex { (false, false) } else { obj.maps.apart() };
        let lit = Lit {
            primary: Color::new(primary[0], primary[1], primary[2]),
            specular: Color::new(specular[0], specular[1], specular[2]),
            emission: if emission_apart {
                obj.material.emission()
            } else {
                Color::BLACK
            },
            ambient: if ambient_apart {
                Color::new(ambient[0], ambient[1], ambient[2])
            } else {
                Color::BLACK
            },
        };
        let c = lit.modulate(&texels, obj.shading.options.clamp);
        [c.r, c.g, c.b]
    }

    /// The shading of a tile of several samples a pixel after visibility (`ids`: per sample,
    /// the packed id of its visible triangle or `u32::MAX`): one job per visible (pixel,
    /// triangle), then `blended` (blended objects' triangles, in drawing order) laid over the
    /// samples, then the reference's resolve, sample by sample.
    pub(super) fn shade_multi(
        &self,
        tile: &Tile,
        work: &mut Multi,
        rows: &mut [&mut [[f32; 4]]],
        blended: &[u32],
        mut marks: Marks,
    ) -> u64 {
        let Multi {
            ids,
            jobs,
            starts,
            colors,
            which,
            ..
        } = work;
        let (x0, y0) = (tile.x0, tile.y0);
        let (tw, th) = (tile.width(), tile.height());
        let ns = self.plan.pattern.len();
        // The pixel as `row << 16 | column` in the tile (no division to find it again); a
        // pixel's jobs are contiguous.
        jobs.clear();
        starts.clear();
        which.clear();
        which.resize(ids.len(), u32::MAX);
        for row in 0..th {
            for col in 0..tw {
                let pixel = row * tw + col;
                let packed = (row as u32) << 16 | col as u32;
                starts.push(jobs.len());
                let first = jobs.len();
                let samples = pixel * ns..(pixel + 1) * ns;
                for (job, &id) in which[samples.clone()].iter_mut().zip(&ids[samples]) {
                    if id == u32::MAX {
                        continue;
                    }
                    *job = if let Some(j) = jobs[first..].iter().position(|j| j.1 == id) {
                        (first + j) as u32
                    } else {
                        jobs.push((packed, id));
                        (jobs.len() - 1) as u32
                    };
                }
            }
        }
        starts.push(jobs.len());
        let at = |packed: u32| (x0 + (packed & 0xffff), y0 + (packed >> 16));
        colors.clear();
        colors.resize(jobs.len(), [0.0; 4]);
        let mut batches: Vec<Vec<u32>> = vec![Vec::new(); self.scene.objects.len()];
        // Per textured object, its jobs `(pixel, triangle)` and where each is in `jobs`.
        let mut textured: Vec<TexturedJobs> = vec![Default::default(); self.scene.objects.len()];
        if let [only] = &self.plan.objects[..]
            && only.mode.batch().is_some()
        {
            // One object, shaded by the vector kernels: every job is its.
            batches[0].extend(0..jobs.len() as u32);
        } else {
            for (k, &(pixel, ti)) in jobs.iter().enumerate() {
                match self.plan.objects[self.binned.object(ti)].mode {
                    Mode::Scalar => {
                        let (px, py) = at(pixel);
                        colors[k] = self.shade_pixel(ti, px, py).unwrap_or(self.plan.bg);
                    }
                    Mode::Textured { .. } => {
                        let (items, at) = &mut textured[self.binned.object(ti)];
                        items.push((pixel, ti));
                        at.push(k as u32);
                    }
                    _ => batches[self.binned.object(ti)].push(k as u32),
                }
            }
        }
        self.shade_gathered(
            &batches,
            |k| {
                let (pixel, ti) = jobs[k as usize];
                let (x, y) = pixel_centre((x0, y0), pixel);
                (x, y, self.binned.planes(ti))
            },
            |k, rgb| colors[k as usize] = [rgb[0], rgb[1], rgb[2], 1.0],
        );
        for (object, (items, at)) in textured.iter().enumerate() {
            if let Mode::Textured { prep, .. } = &self.plan.objects[object].mode {
                self.shade_textured_batch(object, prep, items, x0, y0, |i, rgb| {
                    colors[at[i] as usize] = [rgb[0], rgb[1], rgb[2], 1.0];
                });
            }
        }
        if !blended.is_empty() {
            return self.blend_multi(tile, work, rows, blended, marks);
        }
        marks.resolving();
        let out = rows.iter_mut().flat_map(|r| r.iter_mut());
        for (pixel, o) in out.enumerate() {
            if starts[pixel] == starts[pixel + 1] {
                // Every sample is background (each visible id has a job).
                *o = self.plan.background;
                continue;
            }
            let samples = which[pixel * ns..(pixel + 1) * ns]
                .iter()
                .map(|&j| sample_colour(colors, j, self.plan.bg));
            *o = resolve(samples, ns, self.plan.bg);
        }
        tile.clock.add(marks);
        jobs.len() as u64
    }

    /// [`Tiles::shade_multi`]'s end where the tile has `blended` triangles (blended objects', in
    /// drawing order): each sample's colour, the blended triangles laid over the samples they
    /// cover nearer than the opaque depth (as the reference path lays them), then the resolve.
    /// Returns the shadings done. (Apart, so that the opaque tiles' code stays as it was.)
    #[inline(never)]
    fn blend_multi(
        &self,
        tile: &Tile,
        work: &mut Multi,
        rows: &mut [&mut [[f32; 4]]],
        blended: &[u32],
        mut marks: Marks,
    ) -> u64 {
        let Multi {
            depth,
            jobs,
            colors,
            samples,
            which,
            ..
        } = work;
        let ns = self.plan.pattern.len();
        samples.clear();
        samples.extend(which.iter().map(|&j| sample_colour(colors, j, self.plan.bg)));
        let mut shaded = jobs.len() as u64;
        for &ti in blended {
            self.covered_multi(self.binned.tri(ti), tile, |px, py, base, zs, covered| {
                let mut mask = 0u32;
                for s in Bits(covered) {
                    mask |= u32::from(zs[s] < depth[base + s]) << s;
                }
                if mask == 0 {
                    return;
                }
                shaded += 1;
                if let Some(c) = self.shade_pixel(ti, px, py) {
                    for s in Bits(mask) {
                        samples[base + s] = over(c, samples[base + s]);
                    }
                }
            });
        }
        marks.resolving();
        let out = rows.iter_mut().flat_map(|r| r.iter_mut());
        for (px, o) in samples.chunks_exact(ns).zip(out) {
            *o = resolve(px.iter().copied(), ns, self.plan.bg);
        }
        tile.clock.add(marks);
        shaded
    }

    /// Perspective-correct weights of triangle `t`'s vertices at the centre of pixel
    /// `(px, py)`: `(λ_i / w_i) / Σ (λ_j / w_j)`.
    #[inline]
    fn weights(t: &Tri, corners: &Corners, px: u32, py: u32) -> [f32; 3] {
        let sx = (i64::from(px) << SUBPIXEL_BITS) + HALF;
        let sy = (i64::from(py) << SUBPIXEL_BITS) + HALF;
        let (e, k) = (t.edges_at(sx, sy), t.inv_area);
        let e = each3(|i| e[i] as f64 * k);
        let q = each3(|i| e[i] as f32 * corners.inv_w[i]);
        let sum = q[0] + q[1] + q[2];
        map3(q, |x| x / sum)
    }

    /// (See [`uv_from_planes`] for the fast path's.) Perspective-correct texture coordinates
    /// (the set that `set` reads) of triangle `t` at the centre of pixel `(px, py)` and their
    /// exact screen derivatives `[uv, ∂uv/∂x, ∂uv/∂y]` (per pixel), in
    /// `f64`: with `q_i = λ_i/w_i`, `uv = Σ q_i uv_i / Σ q_i` and
    /// `∂uv = (Σ ∂q_i uv_i − uv Σ ∂q_i) / Σ q_i`.
    fn uv_at(t: &Tri, corners: &Corners, px: u32, py: u32, set: fn(&ClipVertex) -> Vec2) -> [Vec2; 3] {
        let sx = (i64::from(px) << SUBPIXEL_BITS) + HALF;
        let sy = (i64::from(py) << SUBPIXEL_BITS) + HALF;
        let step = f64::from(1u32 << SUBPIXEL_BITS) * t.inv_area;
        let inv_w = corners.inv_w.map(f64::from);
        let uv = corners.v.map(|v| set(&v).as_dvec2());
        let e = t.edges_at(sx, sy);
        let q = each3(|i| e[i] as f64 * t.inv_area * inv_w[i]);
        let qx = each3(|i| t.a(i) as f64 * step * inv_w[i]);
        let qy = each3(|i| t.b(i) as f64 * step * inv_w[i]);
        let sum = |w: [f64; 3]| uv[0] * w[0] + uv[1] * w[1] + uv[2] * w[2];
        let total = q[0] + q[1] + q[2];
        let at = sum(q) / total;
        let d = |w: [f64; 3]| (sum(w) - at * (w[0] + w[1] + w[2])) / total;
        [at.as_vec2(), d(qx).as_vec2(), d(qy).as_vec2()]
    }

    /// The colour of triangle `id` at the centre of pixel `(px, py)`, perspective-correct, by
    /// phong-core's `Object::shade` (or the vertices' or the triangle's colours it made), or for
    /// a textured object its texels applied as `shade_textured` does; `None` where the alpha
    /// test discards the point.
    pub(crate) fn shade_pixel(&self, id: u32, px: u32, py: u32) -> Option<[f32; 4]> {
        let (t, corners) = (self.binned.tri(id), self.binned.corners(id));
        let obj = &self.scene.objects[self.binned.object(id)];
        if obj.textured() && lit_term(obj.shading.output).is_some() {
            return self.shade_textured_pixel(id, px, py);
        }
        let q = Self::weights(t, corners, px, py);
        let v = &corners.v;
        let lerp3 = |f: fn(&ClipVertex) -> Vec3| f(&v[0]) * q[0] + f(&v[1]) * q[1] + f(&v[2]) * q[2];
        let scene = self.scene;
        let obj = &scene.objects[self.binned.object(id)];
        let output = obj.shading.output;
        let c = match output {
            Output::Normal => {
                let n = match corners.flat {
                    Some((_, _, n)) => n,
                    None if t.back => -lerp3(|v| v.normal).normalize_or_zero(),
                    None => lerp3(|v| v.normal).normalize_or_zero(),
                };
                normal_color(n)
            }
            Output::Depth => depth_color(&scene.camera, lerp3(|v| v.world)),
            _ => match (corners.flat, obj.shading.interpolation) {
                (Some((c, _, _)), _) => c,
                (None, Interpolation::Gouraud) => {
                    let c = if t.back {
                        lerp3(|v| v.color_back)
                    } else {
                        lerp3(|v| v.color)
                    };
                    Color::new(c.x, c.y, c.z)
                }
                _ => {
                    let n = lerp3(|v| v.normal);
                    let n = if t.back { -n } else { n };
                    let view = &self.plan.objects[self.binned.object(id)].view;
                    output.term(&obj.shade(&scene.lighting, view, lerp3(|v| v.world), n))
                }
            },
        };
        Some([c.r, c.g, c.b, obj.plain_alpha()])
    }

    /// Whether triangle `id` (an alpha-tested object's) passes the alpha test at the centre of
    /// pixel `(px, py)`: the alpha [`Tiles::shade_pixel`] tests, from the same coordinates.
    pub(crate) fn alpha_passes(&self, id: u32, px: u32, py: u32) -> bool {
        let obj = &self.scene.objects[self.binned.object(id)];
        !obj.maps
            .discards(obj.maps.alpha_sets(&obj.material, &self.uv_sets(id, px, py)))
    }

    /// Triangle `id`'s two sets of texture coordinates (the first twice where no map reads the
    /// second) at the centre of pixel `(px, py)`, as [`Tiles::uv_at`] gives them.
    fn uv_sets(&self, id: u32, px: u32, py: u32) -> [[Vec2; 3]; 2] {
        let (t, corners) = (self.binned.tri(id), self.binned.corners(id));
        let first = Self::uv_at(t, corners, px, py, |v| v.uv);
        let second = if self.plan.objects[self.binned.object(id)].second_set {
            Self::uv_at(t, corners, px, py, |v| v.uv1)
        } else {
            first
        };
        [first, second]
    }

    /// [`Tiles::shade_pixel`] for a textured object's lit outputs: its maps sampled at the
    /// pixel's texture coordinates with their exact derivatives, then applied to the light per
    /// pixel (Phong: `shade_textured`) or to the primary and specular colours made per vertex
    /// or triangle (Gouraud, flat: OpenGL's `GL_MODULATE` with a separate specular colour).
    fn shade_textured_pixel(&self, id: u32, px: u32, py: u32) -> Option<[f32; 4]> {
        let (t, corners) = (self.binned.tri(id), self.binned.corners(id));
        let object = self.binned.object(id);
        let obj = &self.scene.objects[object];
        let sets = self.uv_sets(id, px, py);
        let q = Self::weights(t, corners, px, py);
        let v = &corners.v;
        let lerp3 = |f: &dyn Fn(&ClipVertex) -> Vec3| f(&v[0]) * q[0] + f(&v[1]) * q[1] + f(&v[2]) * q[2];
        let mut texels = obj.maps.sample_sets(&sets);
        if !obj.mesh.colors().is_empty() {
            let c = lerp3(&|v| v.rgb);
            texels = texels.tinted(Color::new(c.x, c.y, c.z));
        }
        let alpha = Maps::alpha(&obj.material, &texels);
        if obj.maps.discards(alpha) {
            return None;
        }
        let color = |c: Vec3| Color::new(c.x, c.y, c.z);
        let clamp = obj.shading.options.clamp;
        let side = usize::from(t.back);
        let c = match (corners.flat, obj.shading.interpolation) {
            (Some((p, s, _)), _) => Lit {
                primary: p,
                specular: s,
                ..Lit::default()
            }
            .modulate(&texels, clamp),
            (None, Interpolation::Gouraud) => {
                let p = if t.back {
                    lerp3(&|v| v.color_back)
                } else {
                    lerp3(&|v| v.color)
                };
                Lit {
                    primary: color(p),
                    specular: color(lerp3(&|v| v.spec[side])),
                    ..Lit::default()
                }
                .modulate(&texels, clamp)
            }
            _ => {
                let n = lerp3(&|v| v.normal);
                let n = if t.back { -n } else { n };
                // A normal map tilts the interpolated normal in its tangent frame.
                let normal = match texels.normal {
                    Some(ts) => {
                        let tangent = v[0].tangent * q[0] + v[1].tangent * q[1] + v[2].tangent * q[2];
                        perturb(n, tangent, ts)
                    }
                    None => n,
                };
                let point = SurfacePoint {
                    position: lerp3(&|v| v.world),
                    normal,
                };
                let options = ShadingOptions {
                    two_sided: false,
                    ..obj.shading.options
                };
                let view = &self.plan.objects[self.binned.object(id)].view;
                let s = shade_textured(&point, view, &obj.material, &texels, &self.scene.lighting, &options);
                obj.shading.output.term(&s)
            }
        };
        Some([c.r, c.g, c.b, if obj.blends() { alpha } else { 1.0 }])
    }
}

/// Texture coordinates at pixel centre `(x, y)` from a triangle's planes of `u/w`, `v/w` and
/// `1/w` (see `setup::uv_planes`), their screen derivatives, and the vertex colour: with
/// `q = 1/w`, `u = q_u/q` and `∂u/∂x = (∂q_u/∂x − u·∂q/∂x)/q` (the planes' gradients are
/// constant).
/// The second set, where the object's maps read one, is in `attr[2]`, `attr[3]` instead of the
/// colour (`setup::uv_planes`): `[first, second]` and the colour.
#[inline]
fn uv_from_planes(p: &Planes, x: f32, y: f32) -> ([[Vec2; 3]; 2], Color) {
    let (dx, dy) = (x - p.origin[0], y - p.origin[1]);
    let eval = |k: [f32; 3]| k[0] + k[1] * dx + k[2] * dy;
    let q = eval(p.inv_w);
    let set = |a: usize| {
        let uv = Vec2::new(eval(p.attr[a]) / q, eval(p.attr[a + 1]) / q);
        let d = |g: usize| Vec2::new(p.attr[a][g] - uv.x * p.inv_w[g], p.attr[a + 1][g] - uv.y * p.inv_w[g]) / q;
        [uv, d(1), d(2)]
    };
    let rgb = Color::new(eval(p.attr[2]) / q, eval(p.attr[3]) / q, eval(p.attr[4]) / q);
    ([set(0), set(2)], rgb)
}

#[cfg(test)]
mod tests {
    use super::run_length;

    /// `run_length` counts the leading run exactly, at every length and position around its
    /// blocks of 8.
    #[test]
    fn run_length_counts_the_leading_run() {
        for len in 0..40 {
            for run in 0..=len {
                let mut ids = vec![7u32; len];
                if run < len {
                    ids[run] = 3;
                }
                assert_eq!(run_length(&ids, 7), run, "length {len}");
                assert_eq!(run_length(&ids, 3), usize::from(run == 0 && len > 0), "length {len}");
            }
        }
    }
}
