//! # phong-gpu
//!
//! The GPU renderer on wgpu: the same images as `phong-raster`, from WGSL shaders that port
//! [`phong_core::shade`] line for line (`shade.wgsl`) and are tested against it.
//!
//! Headless: the scene is drawn into a multisampled `Rgba16Float` texture with a
//! `Depth32Float` depth buffer, resolved, copied into a buffer and read back into the same
//! [`Image`] type the CPU renderer returns.
//!
//! ## Matching the CPU renderer
//!
//! - The same `clip_from_world` (OpenGL clip depth, converted to WebGPU's in the vertex
//!   shader), so window depth and the `GL_LESS` test are the CPU's.
//! - Counter-clockwise front faces; back faces culled unless the object is two-sided.
//! - Multisampling shades once per pixel at its centre, as the CPU renderer; the standard
//!   4-sample pattern is the CPU's; 16 samples use the device's pattern (the CPU uses a 4×4
//!   grid), which only moves silhouette pixels.
//! - Flat shading lights each triangle at its centroid with its facet normal (de-indexed
//!   vertices carry both); Gouraud lights vertices in the vertex shader; Phong per fragment.
//! - Straight alpha: fragments are written premultiplied (alpha 1 over a premultiplied clear)
//!   and the read-back divides by the resolved alpha, as the CPU resolve.
//!
//! Lights live in a storage buffer, objects' materials and options in another (indexed by the
//! instance index of each object's draw), so any number of each is one pipeline.

mod gpu_types;

pub use gpu_types::{GpuCase, GpuFrame, GpuGlobals, GpuLight, GpuObject, GpuVertex};

use phong_core::mesh::facet_normal;
use phong_core::{
    Color, Image, Interpolation, Lighting, Material, Scene, Shading, ShadingSettings, SurfacePoint, View,
};
use std::collections::HashMap;
use std::sync::Mutex;
use std::time::{Duration, Instant};
use thiserror::Error;
use wgpu::util::DeviceExt;

/// The WGSL shading function (a port of `phong_core::shade`).
pub const SHADE_WGSL: &str = include_str!("shade.wgsl");
const RENDER_WGSL: &str = concat!(include_str!("shade.wgsl"), include_str!("render.wgsl"));
const COMPUTE_WGSL: &str = concat!(include_str!("shade.wgsl"), include_str!("compute.wgsl"));

const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// Why the GPU renderer failed.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum Error {
    /// No GPU adapter (no Vulkan driver, or none that wgpu can use).
    #[error(
        "no GPU adapter found ({0}); install a Vulkan driver (e.g. Debian's mesa-vulkan-drivers) or use --backend cpu"
    )]
    NoAdapter(String),
    /// The adapter refused to create a device.
    #[error("the GPU adapter {adapter} could not create a device: {reason}")]
    Device {
        /// Adapter name.
        adapter: String,
        /// wgpu's reason.
        reason: String,
    },
    /// The scene needs more than the device allows.
    #[error("{what} ({asked}) exceeds the GPU's limit ({limit}) on {adapter}")]
    Limit {
        /// What was asked for.
        what: &'static str,
        /// How much.
        asked: u64,
        /// The device's limit.
        limit: u64,
        /// Adapter name.
        adapter: String,
    },
    /// The device reported an error (out of memory, device lost, validation) while rendering.
    #[error("the GPU failed while {doing} on {adapter}: {reason}")]
    Failed {
        /// What was being done.
        doing: &'static str,
        /// Adapter name.
        adapter: String,
        /// The device's report.
        reason: String,
    },
    /// Samples per pixel other than 1, 4 or 16.
    #[error("antialias must be 1, 4 or 16 samples per pixel, got {0}")]
    Samples(u32),
    /// An invalid image size (from the core crate).
    #[error(transparent)]
    Core(#[from] phong_core::Error),
}

/// Times of one GPU render.
#[derive(Clone, Copy, Debug, Default)]
pub struct GpuStats {
    /// Building and uploading vertex, index, light and object buffers.
    pub upload: Duration,
    /// Submitting the render pass and waiting for it to finish.
    pub render: Duration,
    /// Copying the resolved image to a buffer, mapping and converting it.
    pub readback: Duration,
    /// Triangles drawn.
    pub triangles: usize,
}

/// A GPU device ready to render scenes.
pub struct Gpu {
    device: wgpu::Device,
    queue: wgpu::Queue,
    info: wgpu::AdapterInfo,
    limits: wgpu::Limits,
    module: wgpu::ShaderModule,
    layout: wgpu::BindGroupLayout,
    pipeline_layout: wgpu::PipelineLayout,
    pipelines: Mutex<HashMap<(u32, bool), wgpu::RenderPipeline>>,
    lost: std::sync::Arc<Mutex<Option<String>>>,
}

fn storage_entry(binding: u32, read_only: bool, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

fn uniform_entry(binding: u32, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

/// Bind group entries for `buffers`, bound at 0, 1, 2, … in order.
fn entries<'a>(buffers: &[&'a wgpu::Buffer]) -> Vec<wgpu::BindGroupEntry<'a>> {
    buffers
        .iter()
        .enumerate()
        .map(|(i, b)| wgpu::BindGroupEntry {
            binding: i as u32,
            resource: b.as_entire_binding(),
        })
        .collect()
}

/// Storage buffers may not be empty: pad with one zeroed element.
fn non_empty<T: bytemuck::Pod + bytemuck::Zeroable>(v: &[T]) -> Vec<u8> {
    if v.is_empty() {
        bytemuck::bytes_of(&T::zeroed()).to_vec()
    } else {
        bytemuck::cast_slice(v).to_vec()
    }
}

/// IEEE half to f32.
fn f16_to_f32(h: u16) -> f32 {
    let sign = if h & 0x8000 != 0 { -1.0 } else { 1.0 };
    let exp = i32::from((h >> 10) & 0x1f);
    let frac = f32::from(h & 0x3ff);
    sign * match exp {
        0 => frac * (2.0f32).powi(-24),
        31 => {
            if frac == 0.0 {
                f32::INFINITY
            } else {
                f32::NAN
            }
        }
        _ => (1.0 + frac / 1024.0) * (2.0f32).powi(exp - 15),
    }
}

impl Gpu {
    /// Opens the first adapter wgpu finds (high performance preferred); `WGPU_BACKEND` and
    /// `WGPU_ADAPTER_NAME` select another, as wgpu documents.
    pub fn new() -> Result<Gpu, Error> {
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: None,
            ..Default::default()
        }))
        .map_err(|e| Error::NoAdapter(e.to_string()))?;
        let info = adapter.get_info();
        let limits = adapter.limits();
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("phong"),
            required_limits: limits.clone(),
            ..Default::default()
        }))
        .map_err(|e| Error::Device {
            adapter: info.name.clone(),
            reason: e.to_string(),
        })?;
        // Errors are caught with error scopes around each render; anything else is recorded
        // here instead of wgpu's default panic, and reported by the next render.
        let lost = std::sync::Arc::new(Mutex::new(None));
        let sink = lost.clone();
        device.on_uncaptured_error(std::sync::Arc::new(move |e: wgpu::Error| {
            *sink.lock().unwrap_or_else(|p| p.into_inner()) = Some(e.to_string());
        }));
        let sink = lost.clone();
        device.set_device_lost_callback(move |_, msg| {
            *sink.lock().unwrap_or_else(|p| p.into_inner()) = Some(format!("device lost: {msg}"));
        });
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("phong render"),
            source: wgpu::ShaderSource::Wgsl(RENDER_WGSL.into()),
        });
        let both = wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("phong frame"),
            entries: &[
                uniform_entry(0, both),
                storage_entry(1, true, both),
                storage_entry(2, true, both),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("phong"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        Ok(Gpu {
            device,
            queue,
            info,
            limits,
            module,
            layout,
            pipeline_layout,
            pipelines: Mutex::new(HashMap::new()),
            lost,
        })
    }

    /// The adapter's name and backend, e.g. "llvmpipe (LLVM 15.0.6, 256 bits) (Vulkan)".
    pub fn adapter_name(&self) -> String {
        format!(
            "{} ({:?}, {:?})",
            self.info.name, self.info.backend, self.info.device_type
        )
    }

    fn fail(&self, doing: &'static str, reason: String) -> Error {
        Error::Failed {
            doing,
            adapter: self.info.name.clone(),
            reason,
        }
    }

    fn check_lost(&self, doing: &'static str) -> Result<(), Error> {
        match self.lost.lock().unwrap_or_else(|p| p.into_inner()).take() {
            Some(reason) => Err(self.fail(doing, reason)),
            None => Ok(()),
        }
    }

    fn wait(&self, doing: &'static str) -> Result<(), Error> {
        self.device
            .poll(wgpu::PollType::Wait {
                submission_index: None,
                timeout: None,
            })
            .map_err(|e| self.fail(doing, e.to_string()))?;
        self.check_lost(doing)
    }

    fn pipeline(&self, samples: u32, cull: bool) -> wgpu::RenderPipeline {
        let mut cache = self.pipelines.lock().unwrap_or_else(|p| p.into_inner());
        cache
            .entry((samples, cull))
            .or_insert_with(|| {
                let attributes = wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x3];
                self.device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                    label: Some("phong"),
                    layout: Some(&self.pipeline_layout),
                    vertex: wgpu::VertexState {
                        module: &self.module,
                        entry_point: Some("vs_main"),
                        compilation_options: Default::default(),
                        buffers: &[Some(wgpu::VertexBufferLayout {
                            array_stride: std::mem::size_of::<GpuVertex>() as u64,
                            step_mode: wgpu::VertexStepMode::Vertex,
                            attributes: &attributes,
                        })],
                    },
                    primitive: wgpu::PrimitiveState {
                        topology: wgpu::PrimitiveTopology::TriangleList,
                        front_face: wgpu::FrontFace::Ccw,
                        cull_mode: cull.then_some(wgpu::Face::Back),
                        ..Default::default()
                    },
                    depth_stencil: Some(wgpu::DepthStencilState {
                        format: DEPTH_FORMAT,
                        depth_write_enabled: Some(true),
                        depth_compare: Some(wgpu::CompareFunction::Less),
                        stencil: Default::default(),
                        bias: Default::default(),
                    }),
                    multisample: wgpu::MultisampleState {
                        count: samples,
                        mask: !0,
                        alpha_to_coverage_enabled: false,
                    },
                    fragment: Some(wgpu::FragmentState {
                        module: &self.module,
                        entry_point: Some("fs_main"),
                        compilation_options: Default::default(),
                        targets: &[Some(wgpu::ColorTargetState {
                            format: COLOR_FORMAT,
                            blend: None,
                            write_mask: wgpu::ColorWrites::ALL,
                        })],
                    }),
                    multiview_mask: None,
                    cache: None,
                })
            })
            .clone()
    }

    fn check_limit(&self, what: &'static str, asked: u64, limit: u64) -> Result<(), Error> {
        if asked > limit {
            return Err(Error::Limit {
                what,
                asked,
                limit,
                adapter: self.info.name.clone(),
            });
        }
        Ok(())
    }

    /// Renders `scene` into a linear RGBA image (labels are not drawn: the caller does, as
    /// for the CPU renderer).
    pub fn render(&self, scene: &Scene) -> Result<(Image, GpuStats), Error> {
        let t0 = Instant::now();
        let samples = scene.image.samples;
        if !phong_core::limits::SAMPLE_COUNTS.contains(&samples) {
            return Err(Error::Samples(samples));
        }
        let (w, h) = (scene.image.width, scene.image.height);
        if w == 0
            || h == 0
            || w > phong_core::limits::MAX_IMAGE_DIMENSION
            || h > phong_core::limits::MAX_IMAGE_DIMENSION
        {
            return Err(phong_core::Error::OutOfRange {
                what: "image size",
                range: "from 1 to 16384 pixels on a side",
                value: w.max(h) as f32,
            }
            .into());
        }
        let samples_total = u64::from(w) * u64::from(h) * u64::from(samples);
        if samples_total > phong_core::limits::MAX_SAMPLES_TOTAL {
            return Err(Error::Limit {
                what: "pixels × samples per pixel",
                asked: samples_total,
                limit: phong_core::limits::MAX_SAMPLES_TOTAL,
                adapter: self.info.name.clone(),
            });
        }
        let max_tex = u64::from(self.limits.max_texture_dimension_2d);
        self.check_limit("image width", u64::from(w), max_tex)?;
        self.check_limit("image height", u64::from(h), max_tex)?;
        self.check_lost("starting a render")?;

        // Geometry: smooth objects indexed, flat objects de-indexed with centroids.
        let mut vertices: Vec<GpuVertex> = Vec::new();
        let mut indices: Vec<u32> = Vec::new();
        let mut draws: Vec<(std::ops::Range<u32>, i32, bool)> = Vec::new();
        let mut objects = Vec::with_capacity(scene.objects.len());
        let mut triangles = 0usize;
        for o in &scene.objects {
            let view = scene.camera.view(o.shading.viewer);
            objects.push(GpuObject::new(&o.material, &o.shading, &view));
            let m = &o.mesh;
            let base = vertices.len();
            let first = indices.len() as u32;
            if o.shading.interpolation == Interpolation::Flat {
                for (t, _) in m.triangles().iter().enumerate() {
                    let [a, b, c] = m.corners(t);
                    let n = facet_normal(a, b, c).to_array();
                    let centroid = ((a + b + c) / 3.0).to_array();
                    for p in [a, b, c] {
                        indices.push((vertices.len() - base) as u32);
                        vertices.push(GpuVertex {
                            position: p.to_array(),
                            normal: n,
                            centroid,
                        });
                    }
                }
            } else {
                vertices.extend(m.positions().iter().zip(m.normals()).map(|(p, n)| GpuVertex {
                    position: p.to_array(),
                    normal: n.to_array(),
                    centroid: p.to_array(),
                }));
                indices.extend(m.triangles().iter().flatten());
            }
            triangles += m.triangles().len();
            draws.push((first..indices.len() as u32, base as i32, !o.shading.options.two_sided));
        }
        let max_buf = self
            .limits
            .max_buffer_size
            .min(self.limits.max_storage_buffer_binding_size);
        self.check_limit(
            "vertex buffer bytes",
            (vertices.len() * size_of::<GpuVertex>()) as u64,
            self.limits.max_buffer_size,
        )?;
        self.check_limit(
            "index buffer bytes",
            (indices.len() * 4) as u64,
            self.limits.max_buffer_size,
        )?;
        self.check_limit(
            "lights",
            scene.lighting.lights().len() as u64 * size_of::<GpuLight>() as u64,
            max_buf,
        )?;

        let lights: Vec<GpuLight> = scene.lighting.lights().iter().map(GpuLight::from).collect();
        let cam = &scene.camera;
        let frame = GpuFrame {
            clip_from_world: cam.clip_from_world(w as f32 / h as f32).to_cols_array(),
            eye: [cam.eye().x, cam.eye().y, cam.eye().z, cam.near()],
            forward: [cam.forward().x, cam.forward().y, cam.forward().z, cam.far()],
            ambient: [
                scene.lighting.ambient().r,
                scene.lighting.ambient().g,
                scene.lighting.ambient().b,
                0.0,
            ],
            counts: [lights.len() as u32, 0, 0, 0],
        };

        let scope = self.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let validation = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let d = &self.device;
        let buf = |label, contents: &[u8], usage| {
            d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage,
            })
        };
        let vb = buf("vertices", &non_empty(&vertices), wgpu::BufferUsages::VERTEX);
        let ib = buf("indices", &non_empty(&indices), wgpu::BufferUsages::INDEX);
        let fb = buf("frame", bytemuck::bytes_of(&frame), wgpu::BufferUsages::UNIFORM);
        let lb = buf("lights", &non_empty(&lights), wgpu::BufferUsages::STORAGE);
        let ob = buf("objects", &non_empty(&objects), wgpu::BufferUsages::STORAGE);
        let bind = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("phong frame"),
            layout: &self.layout,
            entries: &entries(&[&fb, &lb, &ob]),
        });
        let size = wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        };
        let texture = |label, format, samples, usage| {
            d.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size,
                mip_level_count: 1,
                sample_count: samples,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        let resolved = texture(
            "resolved",
            COLOR_FORMAT,
            1,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        );
        let msaa =
            (samples > 1).then(|| texture("msaa", COLOR_FORMAT, samples, wgpu::TextureUsages::RENDER_ATTACHMENT));
        let depth = texture("depth", DEPTH_FORMAT, samples, wgpu::TextureUsages::RENDER_ATTACHMENT);
        let resolved_view = resolved.create_view(&Default::default());
        let msaa_view = msaa.as_ref().map(|t| t.create_view(&Default::default()));
        let depth_view = depth.create_view(&Default::default());
        let pipelines = [self.pipeline(samples, false), self.pipeline(samples, true)];
        let bg = scene.image.background;
        let upload = t0.elapsed();

        let t1 = Instant::now();
        let mut enc = d.create_command_encoder(&Default::default());
        {
            let (view, resolve_target) = match &msaa_view {
                Some(m) => (m, Some(&resolved_view)),
                None => (&resolved_view, None),
            };
            let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("phong"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view,
                    depth_slice: None,
                    resolve_target,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color {
                            r: f64::from(bg[0] * bg[3]),
                            g: f64::from(bg[1] * bg[3]),
                            b: f64::from(bg[2] * bg[3]),
                            a: f64::from(bg[3]),
                        }),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &depth_view,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Discard,
                    }),
                    stencil_ops: None,
                }),
                ..Default::default()
            });
            pass.set_bind_group(0, &bind, &[]);
            pass.set_vertex_buffer(0, vb.slice(..));
            pass.set_index_buffer(ib.slice(..), wgpu::IndexFormat::Uint32);
            for (i, (range, base, cull)) in draws.iter().enumerate() {
                if range.is_empty() {
                    continue;
                }
                pass.set_pipeline(&pipelines[usize::from(*cull)]);
                pass.draw_indexed(range.clone(), *base, i as u32..i as u32 + 1);
            }
        }
        self.queue.submit([enc.finish()]);
        self.wait("rendering")?;
        let render = t1.elapsed();

        let t2 = Instant::now();
        let row = u64::from(w) * 8;
        let align = u64::from(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
        let padded = row.div_ceil(align) * align;
        self.check_limit(
            "read-back buffer bytes",
            padded * u64::from(h),
            self.limits.max_buffer_size,
        )?;
        let out = d.create_buffer(&wgpu::BufferDescriptor {
            label: Some("read-back"),
            size: padded * u64::from(h),
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let mut enc = d.create_command_encoder(&Default::default());
        enc.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture: &resolved,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &out,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(padded as u32),
                    rows_per_image: Some(h),
                },
            },
            size,
        );
        self.queue.submit([enc.finish()]);
        let (tx, rx) = std::sync::mpsc::channel();
        out.map_async(wgpu::MapMode::Read, .., move |r| {
            let _ = tx.send(r);
        });
        self.wait("reading the image back")?;
        if let Some(e) = pollster::block_on(validation.pop()) {
            return Err(self.fail("rendering", e.to_string()));
        }
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(self.fail("rendering (out of memory)", e.to_string()));
        }
        rx.recv()
            .map_err(|e| self.fail("reading the image back", e.to_string()))?
            .map_err(|e| self.fail("reading the image back", e.to_string()))?;
        let pixels = {
            let data = out
                .get_mapped_range(..)
                .map_err(|e| self.fail("reading the image back", e.to_string()))?;
            let mut pixels = Vec::with_capacity(w as usize * h as usize);
            for y in 0..h as usize {
                let line = &data[y * padded as usize..y * padded as usize + row as usize];
                for px in line.chunks_exact(8) {
                    let c = [0, 1, 2, 3].map(|k| f16_to_f32(u16::from_le_bytes([px[2 * k], px[2 * k + 1]])));
                    pixels.push(if c[3] > 0.0 {
                        [c[0] / c[3], c[1] / c[3], c[2] / c[3], c[3]]
                    } else {
                        [bg[0], bg[1], bg[2], 0.0]
                    });
                }
            }
            pixels
        };
        out.unmap();
        let image = Image::from_pixels(w, h, pixels)?;
        Ok((
            image,
            GpuStats {
                upload,
                render,
                readback: t2.elapsed(),
                triangles,
            },
        ))
    }

    /// Runs the WGSL shading function on `cases` in a compute pass: case `i` shades point
    /// `cases[i].0` with material `cases[i].1`, settings `cases[i].2` and view `cases[i].3`
    /// under `lighting`. For testing the WGSL port against [`phong_core::shade`].
    pub fn shade_cases(
        &self,
        lighting: &Lighting,
        cases: &[(SurfacePoint, Material, ShadingSettings, View)],
    ) -> Result<Vec<Shading>, Error> {
        let d = &self.device;
        let scope = d.push_error_scope(wgpu::ErrorFilter::Validation);
        let module = d.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("phong shade cases"),
            source: wgpu::ShaderSource::Wgsl(COMPUTE_WGSL.into()),
        });
        let pipeline = d.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("phong shade cases"),
            layout: None,
            module: &module,
            entry_point: Some("cs_main"),
            compilation_options: Default::default(),
            cache: None,
        });
        let lights: Vec<GpuLight> = lighting.lights().iter().map(GpuLight::from).collect();
        let objects: Vec<GpuObject> = cases.iter().map(|(_, m, s, v)| GpuObject::new(m, s, v)).collect();
        let gcases: Vec<GpuCase> = cases
            .iter()
            .map(|(p, ..)| GpuCase {
                position: [p.position.x, p.position.y, p.position.z, 0.0],
                normal: [p.normal.x, p.normal.y, p.normal.z, 0.0],
            })
            .collect();
        let a = lighting.ambient();
        let globals = GpuGlobals {
            ambient: [a.r, a.g, a.b, 0.0],
            counts: [lights.len() as u32, cases.len() as u32, 0, 0],
        };
        let buf = |contents: &[u8], usage| {
            d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: None,
                contents,
                usage,
            })
        };
        let gb = buf(bytemuck::bytes_of(&globals), wgpu::BufferUsages::UNIFORM);
        let lb = buf(&non_empty(&lights), wgpu::BufferUsages::STORAGE);
        let ob = buf(&non_empty(&objects), wgpu::BufferUsages::STORAGE);
        let cb = buf(&non_empty(&gcases), wgpu::BufferUsages::STORAGE);
        let size = (cases.len().max(1) * 64) as u64;
        let rb = d.create_buffer(&wgpu::BufferDescriptor {
            label: None,
            size,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let out = d.create_buffer(&wgpu::BufferDescriptor {
            label: None,
            size,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let bind = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &pipeline.get_bind_group_layout(0),
            entries: &entries(&[&gb, &lb, &ob, &cb, &rb]),
        });
        let mut enc = d.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            pass.set_pipeline(&pipeline);
            pass.set_bind_group(0, &bind, &[]);
            pass.dispatch_workgroups((cases.len() as u32).div_ceil(64), 1, 1);
        }
        enc.copy_buffer_to_buffer(&rb, 0, &out, 0, size);
        self.queue.submit([enc.finish()]);
        out.map_async(wgpu::MapMode::Read, .., |_| {});
        self.wait("shading test cases")?;
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(self.fail("shading test cases", e.to_string()));
        }
        let data = out
            .get_mapped_range(..)
            .map_err(|e| self.fail("reading test results", e.to_string()))?;
        let floats: &[f32] = bytemuck::cast_slice(&data);
        let c = |i: usize| Color::new(floats[i], floats[i + 1], floats[i + 2]);
        Ok((0..cases.len())
            .map(|k| Shading {
                ambient: c(k * 16),
                diffuse: c(k * 16 + 4),
                specular: c(k * 16 + 8),
                color: c(k * 16 + 12),
            })
            .collect())
    }
}
