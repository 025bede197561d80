//! The compute rasterizer (`shaders/raster.wgsl`): a visibility buffer filled by 64-bit atomics
//! with the CPU renderer's coverage arithmetic, then shaded per pixel by the same fragment
//! function and resolved as the CPU renderer resolves. It draws a frame where no triangle needs
//! clipping and its buffers fit the adapter ([`Gpu::compute_reason`]); its list of large
//! triangles' tiles has a fixed capacity, and a frame that overflows it is drawn again by the
//! pipeline (see [`Gpu::render`]).

use crate::upload::{Upload, non_empty};
use crate::{Drawing, Error, Gpu, GpuRaster, RASTER_WGSL};
use phong_core::{Interpolation, Samples, Scene};

/// One dispatch of the compute rasterizer: workgroups `(x, y)`, or indirect from this offset
/// of the dispatch buffer (large triangles, tiles).
pub(crate) struct ComputeStage {
    pub kernel: Kernel,
    pub pipeline: wgpu::ComputePipeline,
    pub bind: wgpu::BindGroup,
    pub groups: Result<(u32, u32), u64>,
}

/// The compute rasterizer's entry points, in dispatch order.
#[derive(Clone, Copy)]
pub(crate) enum Kernel {
    Clear,
    Vertex,
    Raster,
    Args,
    Expand,
    Tiles,
    Shade,
    ShadeSamples,
}

impl Kernel {
    const ALL: [Kernel; 8] = [
        Kernel::Clear,
        Kernel::Vertex,
        Kernel::Raster,
        Kernel::Args,
        Kernel::Expand,
        Kernel::Tiles,
        Kernel::Shade,
        Kernel::ShadeSamples,
    ];
    /// Dispatches per frame (one of the two shading kernels).
    pub const STAGES: u32 = 7;

    pub fn name(self) -> &'static str {
        match self {
            Kernel::Clear => "cs_clear",
            Kernel::Vertex => "cs_vertex",
            Kernel::Raster => "cs_raster",
            Kernel::Args => "cs_args",
            Kernel::Expand => "cs_expand",
            Kernel::Tiles => "cs_tiles",
            Kernel::Shade => "cs_shade",
            Kernel::ShadeSamples => "cs_shade_samples",
        }
    }

    /// The bindings its entry point uses (its automatic layout holds exactly these).
    fn bindings(self) -> &'static [u32] {
        match self {
            Kernel::Clear => &[3, 11, 13],
            Kernel::Vertex => &[0, 1, 2, 3, 4, 5, 7, 8],
            Kernel::Raster => &[2, 3, 5, 6, 7, 9, 11, 15],
            Kernel::Args => &[3, 11, 12],
            Kernel::Expand => &[10, 11, 15],
            Kernel::Tiles => &[2, 3, 5, 6, 7, 9, 10, 11],
            Kernel::Shade | Kernel::ShadeSamples => &[0, 1, 2, 3, 4, 5, 6, 7, 8, 13, 14],
        }
    }
}

pub(crate) struct Kernels([wgpu::ComputePipeline; 8]);

impl Kernels {
    fn get(&self, k: Kernel) -> &wgpu::ComputePipeline {
        &self.0[k as usize]
    }
}

/// Workgroups `(x, y)` for `n` threads of `size` per group, `x` at most `max`: the shaders'
/// `linear_id` is `gid.x + gid.y · x · size`. `None` when even `max²` groups are too few.
fn dispatch_groups(n: u64, size: u32, max: u32) -> Option<(u32, u32)> {
    let groups = n.div_ceil(u64::from(size)).max(1);
    let x = groups.min(u64::from(max));
    let y = groups.div_ceil(x);
    (y <= u64::from(max)).then_some((x as u32, y as u32))
}

impl Gpu {
    /// Why the compute rasterizer cannot draw `scene` (`None`: it can): it needs 64-bit
    /// atomics, its buffers within the adapter's storage limit, fewer than 2^32 - 1 triangles,
    /// and every object's bounding box in front of the near plane, behind the far plane and
    /// less than 32768 pixels from the window's origin (so that no triangle needs clipping and
    /// snapped coordinates fit its integers).
    pub fn compute_reason(&self, scene: &Scene) -> Option<String> {
        let needed = wgpu::Features::SHADER_INT64 | wgpu::Features::SHADER_INT64_ATOMIC_MIN_MAX;
        if !self.device.features().contains(needed) {
            return Some(format!("the adapter {} has no 64-bit atomics", self.info.name));
        }
        if let Some(o) = scene.objects.iter().find(|o| o.textured() || o.blends()) {
            return Some(format!(
                "object {} is textured or blended (the render pipeline draws those)",
                o.name
            ));
        }
        // Its storage buffers: the visibility buffer, and per vertex its record, projection and
        // colours (flat objects' vertices de-indexed, three per triangle).
        let max = self.max_storage_bytes();
        let vertices: u64 = scene
            .objects
            .iter()
            .map(|o| match o.shading.interpolation {
                Interpolation::Flat => 3 * o.mesh.triangles().len() as u64,
                _ => o.mesh.positions().len() as u64,
            })
            .sum();
        let triangles = scene.triangle_count() as u64;
        for (what, bytes) in [
            ("visibility buffer", scene.image.samples_total() * 8),
            ("per-vertex colours", vertices * 64),
            ("indices", triangles * 12),
        ] {
            if bytes > max {
                return Some(format!(
                    "its {what} ({bytes} bytes) exceeds the adapter's storage buffer limit ({max} bytes)"
                ));
            }
        }
        if triangles >= u64::from(u32::MAX) {
            return Some(format!("it numbers triangles in 32 bits ({triangles} triangles)"));
        }
        let (w, h) = (scene.image.width as f32, scene.image.height as f32);
        let clip_from_world = scene.camera.clip_from_world(w / h);
        for (i, o) in scene.objects.iter().enumerate() {
            let Some((lo, hi)) = o.mesh.bounds() else { continue };
            for k in 0..8 {
                let p = glam::Vec3::new(
                    if k & 1 == 0 { lo.x } else { hi.x },
                    if k & 2 == 0 { lo.y } else { hi.y },
                    if k & 4 == 0 { lo.z } else { hi.z },
                );
                let c = clip_from_world * p.extend(1.0);
                let (glam::Vec3 { x: sx, y: sy, .. }, _) = phong_core::window_from_clip(c, w, h);
                // Snapped (× 256), |x| < 2^23: exact in f32 and in the shader's i32.
                let inside = c.w > 0.0 && c.z >= -c.w && c.z <= c.w && sx.abs() < 32768.0 && sy.abs() < 32768.0;
                if !inside {
                    return Some(format!(
                        "object {} reaches outside the view volume (near or far plane, or far off screen)",
                        i + 1
                    ));
                }
            }
        }
        None
    }

    /// The compute rasterizer's pipelines, built once (an error where the driver cannot).
    pub(crate) fn kernels(&self) -> Result<&Kernels, Error> {
        self.kernels
            .get_or_init(|| {
                let d = &self.device;
                let scope = d.push_error_scope(wgpu::ErrorFilter::Validation);
                let module = d.create_shader_module(wgpu::ShaderModuleDescriptor {
                    label: Some("phong compute rasterizer"),
                    source: wgpu::ShaderSource::Wgsl(RASTER_WGSL.into()),
                });
                let make = |k: Kernel| {
                    d.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                        label: Some(k.name()),
                        layout: None,
                        module: &module,
                        entry_point: Some(k.name()),
                        compilation_options: Default::default(),
                        cache: None,
                    })
                };
                let kernels = Kernels(Kernel::ALL.map(make));
                match pollster::block_on(scope.pop()) {
                    Some(e) => Err(e.to_string()),
                    None => Ok(kernels),
                }
            })
            .as_ref()
            .map_err(|e| self.fail("building the compute rasterizer", e.clone()))
    }
    /// The compute rasterizer's buffers, bind groups and dispatches for `upload`, drawing into
    /// `resolved`.
    pub(crate) fn prepare_compute(&self, upload: Upload, resolved: &wgpu::TextureView) -> Result<Drawing, Error> {
        let kernels = self.kernels()?;
        let samples_total = upload.samples_total();
        let Upload {
            width: w,
            height: h,
            samples,
            geometry,
            premultiplied,
            frame: fb,
            lights: lb,
            objects: ob,
        } = upload;
        let (vertices, triangles) = (geometry.vertices.len() as u64, geometry.triangles() as u64);
        // The CPU renderer's sample pattern, as it snaps it (1/256 pixel).
        let offsets: Vec<[i32; 2]> = phong_core::limits::sample_pattern(samples)
            .iter()
            .map(|&(x, y)| [(x * 256.0).round() as i32, (y * 256.0).round() as i32])
            .collect();
        let mut pattern = [[0i32; 4]; 16];
        for (p, o) in pattern.iter_mut().zip(&offsets) {
            *p = [o[0], o[1], 0, 0];
        }
        let xs = offsets.iter().map(|o| o[0]);
        let ys = offsets.iter().map(|o| o[1]);
        let raster = GpuRaster {
            size: [w, h, vertices as u32, triangles as u32],
            background: premultiplied,
            items: [self.item_capacity, samples.count(), 0, 0],
            span: [
                xs.clone().min().unwrap_or(128),
                xs.max().unwrap_or(128),
                ys.clone().min().unwrap_or(128),
                ys.max().unwrap_or(128),
            ],
            pattern,
        };
        let storage = wgpu::BufferUsages::STORAGE;
        let rb = self.buffer_init("raster", bytemuck::bytes_of(&raster), wgpu::BufferUsages::UNIFORM);
        let vb = self.buffer_init("vertices", &non_empty(&geometry.vertices), storage);
        let vob = self.buffer_init("vertex objects", &non_empty(&geometry.vertex_object), storage);
        let ib = self.buffer_init("indices", &non_empty(&geometry.indices), storage);
        let projected = self.buffer("projected", vertices * 16, storage);
        let colors = self.buffer("vertex colours", vertices * 64, storage);
        let visibility = self.buffer("visibility", samples_total * 8, storage);
        let items = self.buffer("items", u64::from(self.item_capacity) * 8, storage);
        let counter = self.buffer("item counters", 16, storage | wgpu::BufferUsages::COPY_SRC);
        let dispatch = self.buffer("dispatches", 32, storage | wgpu::BufferUsages::INDIRECT);
        let large = self.buffer("large triangles", u64::from(self.item_capacity / 2 + 1) * 16, storage);
        let resources: [(u32, wgpu::BindingResource); 16] = [
            (0, fb.as_entire_binding()),
            (1, lb.as_entire_binding()),
            (2, ob.as_entire_binding()),
            (3, rb.as_entire_binding()),
            (4, vb.as_entire_binding()),
            (5, vob.as_entire_binding()),
            (6, ib.as_entire_binding()),
            (7, projected.as_entire_binding()),
            (8, colors.as_entire_binding()),
            (9, visibility.as_entire_binding()),
            (10, items.as_entire_binding()),
            (11, counter.as_entire_binding()),
            (12, dispatch.as_entire_binding()),
            (13, visibility.as_entire_binding()),
            (14, wgpu::BindingResource::TextureView(resolved)),
            (15, large.as_entire_binding()),
        ];
        let max_groups = self.limits.max_compute_workgroups_per_dimension;
        let stage = |k: Kernel, threads: Result<(u64, u32), u64>| -> Result<ComputeStage, Error> {
            let pipeline = kernels.get(k).clone();
            let used = k.bindings();
            let entries: Vec<wgpu::BindGroupEntry> = resources
                .iter()
                .filter(|(b, _)| used.contains(b))
                .map(|(b, r)| wgpu::BindGroupEntry {
                    binding: *b,
                    resource: r.clone(),
                })
                .collect();
            let bind = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(k.name()),
                layout: &pipeline.get_bind_group_layout(0),
                entries: &entries,
            });
            let groups = match threads {
                Err(offset) => Err(offset),
                Ok((n, size)) => Ok(dispatch_groups(n, size, max_groups)
                    .ok_or_else(|| self.fail("preparing the compute rasterizer", format!("{n} threads")))?),
            };
            Ok(ComputeStage {
                kernel: k,
                pipeline,
                bind,
                groups,
            })
        };
        let shade = if samples == Samples::One {
            Kernel::Shade
        } else {
            Kernel::ShadeSamples
        };
        let stages = vec![
            stage(Kernel::Clear, Ok((samples_total, 64)))?,
            stage(Kernel::Vertex, Ok((vertices, 64)))?,
            stage(Kernel::Raster, Ok((triangles, 64)))?,
            stage(Kernel::Args, Ok((1, 1)))?,
            stage(Kernel::Expand, Err(0))?,
            stage(Kernel::Tiles, Err(16))?,
            ComputeStage {
                groups: Ok((w.div_ceil(8), h.div_ceil(8))),
                ..stage(shade, Err(0))?
            },
        ];
        Ok(Drawing::Compute {
            stages,
            counter,
            dispatch,
            _buffers: vec![fb, lb, ob, rb, vb, vob, ib, projected, colors, visibility, items, large],
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every thread has a group, `x` within the limit, and no whole row of groups is idle.
    #[test]
    fn dispatch_groups_cover_every_thread() {
        for (n, size, max) in [
            (0u64, 64u32, 65535u32),
            (1, 64, 65535),
            (64, 64, 65535),
            (65, 64, 65535),
            (999_000, 64, 65535),
            (65535 * 64, 64, 65535),
            (65535 * 64 + 1, 64, 65535),
            (16_000_000, 64, 65535),
            (40, 1, 7),
        ] {
            let (x, y) = dispatch_groups(n, size, max).unwrap();
            assert!(x <= max && x >= 1 && y >= 1, "{n} {size} {max}: {x} {y}");
            assert!(u64::from(x) * u64::from(y) * u64::from(size) >= n, "{n}: {x} {y}");
            assert!(
                u64::from(x) * u64::from(y - 1) * u64::from(size) < n.max(1),
                "{n}: {x} {y}"
            );
        }
        assert_eq!(dispatch_groups(50, 1, 7), None);
    }
}
