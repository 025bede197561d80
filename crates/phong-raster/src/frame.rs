//! A frame, stage by stage: its plan ([`FramePlan`]), the setup of its triangles into tiles
//! ([`setup::run`]), then the tiles ([`tile::draw`]).

use crate::plan::{FramePlan, Path};
use crate::setup::{self, Scratch};
use crate::simd::Isa;
use crate::stats::{RenderStats, StageClock};
use crate::target::Pixel;
use crate::tile;
use crate::{Error, RenderOptions};
use phong_core::limits::SUBPIXEL_BITS;
use phong_core::{Encoding, Scene};
use std::time::Instant;

/// Renders into `pixels`, the scene's size row-major (8-bit pixels encoded by `encoding`);
/// every pixel is written.
pub(crate) fn render<P: Pixel>(
    scene: &Scene,
    options: &RenderOptions,
    pixels: &mut [P],
    encoding: Encoding,
    scratch: &mut Scratch,
) -> Result<RenderStats, Error> {
    let t0 = Instant::now();
    let path = if options.reference { Path::Reference } else { Path::Fast };
    let plan = FramePlan::new(scene, path, Isa::detect(options.kernels));
    let binned = setup::run(&plan, scene, scratch);
    let setup = t0.elapsed();
    let t1 = Instant::now();
    let clock = StageClock::default();
    let shaded = tile::draw(&plan, scene, &binned, pixels, encoding, &clock, options.progress);
    let triangles_drawn = binned.tris.iter().map(|c| c.tris.len()).sum();
    binned.recycle(scratch);
    let raster = t1.elapsed();
    let (tile_raster, tile_shade, tile_resolve) = clock.into_durations();
    Ok(RenderStats {
        triangles: scene.triangle_count(),
        triangles_drawn,
        pixels_shaded: shaded,
        setup,
        raster,
        tile_raster,
        tile_shade,
        tile_resolve,
    })
}

/// Diagnostic for coverage tests: for each sample of each pixel (row-major,
/// samples innermost), how many triangles cover it, depth ignored. Culling
/// and clipping apply as in [`render`](crate::render).
pub fn coverage_counts(scene: &Scene) -> Vec<u16> {
    let plan = FramePlan::new(scene, Path::Fast, Isa::PORTABLE);
    let binned = setup::run(&plan, scene, &mut Scratch::default());
    let ns = plan.pattern.len();
    let mut counts = vec![0u16; plan.w as usize * plan.h as usize * ns];
    for t in binned.tris.iter().flat_map(|c| &c.tris) {
        let bb = t.bbox();
        for py in bb[1]..bb[3] {
            for px in bb[0]..bb[2] {
                for (s, &(ox, oy)) in plan.pattern.iter().enumerate() {
                    let sx = (i64::from(px) << SUBPIXEL_BITS) + ox;
                    let sy = (i64::from(py) << SUBPIXEL_BITS) + oy;
                    if t.covers(sx, sy).is_some() {
                        counts[(py as usize * plan.w as usize + px as usize) * ns + s] += 1;
                    }
                }
            }
        }
    }
    counts
}
