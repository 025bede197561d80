//! # phong-gpu
//!
//! The GPU renderer on wgpu: the same images as `phong-raster`, from WGSL shaders that port
//! [`phong_core::shade`] line for line (`shade.wgsl`) and are tested against it.
//!
//! Headless: the scene is drawn into an `Rgba16Float` texture, copied into a buffer and read
//! back into the same [`Image`] type the CPU renderer returns. Two ways to draw ([`GpuPath`]):
//!
//! - the render pipeline: the GPU's rasterizer, a `Depth32Float` depth buffer, MSAA;
//! - the compute rasterizer (`raster.wgsl`): a visibility buffer filled by 64-bit atomics with
//!   the CPU renderer's coverage arithmetic, then shaded per pixel by the same fragment
//!   function, per pixel and triangle, then resolved as the CPU renderer resolves. Where it
//!   can draw a frame (64-bit atomics, no triangle to clip, buffers within the adapter's
//!   limits: [`Gpu::compute_reason`]) it is the default: on an H100, whose graphics stages
//!   run on 2 of 66 TPCs, it draws a 1M-triangle sphere with 8 lights at 4K in 0.43 ms
//!   against the pipeline's 13.2 ms, and its images are within 1/255 of the CPU's.
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

pub use gpu_types::{GpuCase, GpuFrame, GpuGlobals, GpuLight, GpuObject, GpuRaster, GpuVertex};

use half::slice::{HalfBitsSliceExt, HalfFloatSliceExt};
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
const RENDER_WGSL: &str = concat!(
    include_str!("shade.wgsl"),
    include_str!("frame.wgsl"),
    include_str!("render.wgsl")
);
const RASTER_WGSL: &str = concat!(
    include_str!("shade.wgsl"),
    include_str!("frame.wgsl"),
    include_str!("raster.wgsl")
);
/// Tile items (triangle, 16×16 tile) the compute rasterizer holds per frame (8 bytes each): a
/// frame that needs more is drawn again by the pipeline.
const ITEM_CAPACITY: u32 = 1 << 21;
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
    /// The compute rasterizer was asked for and cannot draw the frame.
    #[error("the compute rasterizer cannot draw this frame: {0}; use the pipeline path")]
    Compute(String),
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
    /// Submitting the render pass and waiting for it to finish (wall clock).
    pub render: Duration,
    /// The render pass's own time on the GPU, from timestamp queries (`None` when the adapter
    /// has no `TIMESTAMP_QUERY`).
    pub gpu_pass: Option<Duration>,
    /// Copying the resolved image to a buffer, mapping and converting it.
    pub readback: Duration,
    /// Triangles drawn.
    pub triangles: usize,
    /// Drawn by the compute rasterizer (else by the render pipeline).
    pub compute: bool,
}

/// How the GPU draws a frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum GpuPath {
    /// [`GpuPath::PreferCompute`] on a GPU; the render pipeline on a CPU adapter (Mesa's
    /// lavapipe), whose rasterizer ran the benchmark scenes 1.6–3.2× faster than the compute
    /// rasterizer there.
    #[default]
    Auto,
    /// The compute rasterizer where it can draw the frame ([`Gpu::compute_reason`]) and its
    /// tile list holds the frame, else the render pipeline.
    PreferCompute,
    /// The render pipeline: the GPU's own rasterizer, MSAA, any geometry.
    Pipeline,
    /// The compute rasterizer (raster.wgsl); an error where it cannot draw the frame.
    Compute,
}

/// A frame uploaded by [`Gpu::prepare`]: buffers, targets and bind groups, drawn by
/// [`Gpu::draw`] as often as asked and read back by [`Gpu::read`].
pub struct Prepared {
    width: u32,
    height: u32,
    background: [f32; 4],
    premultiplied: [f32; 4],
    triangles: usize,
    resolved: wgpu::Texture,
    resolved_view: wgpu::TextureView,
    /// Timestamps (the start and end of each pass) and the buffer they are resolved into.
    timing: Option<(wgpu::QuerySet, wgpu::Buffer)>,
    /// Mapped after each draw: the compute path's counters (item count, large triangles,
    /// overflow flag; 16 bytes), then the timestamps.
    feedback: wgpu::Buffer,
    /// Timed passes at most: one (the pipeline's) or one per compute kernel.
    passes: u32,
    drawing: Drawing,
}

impl Prepared {
    /// Whether this frame is drawn by the compute rasterizer.
    pub fn is_compute(&self) -> bool {
        matches!(self.drawing, Drawing::Compute { .. })
    }
}

enum Drawing {
    Pipeline {
        vb: wgpu::Buffer,
        ib: wgpu::Buffer,
        bind: wgpu::BindGroup,
        msaa_view: Option<wgpu::TextureView>,
        depth_view: wgpu::TextureView,
        /// Each object's index range and whether back faces are culled.
        draws: Vec<(std::ops::Range<u32>, bool)>,
        pipelines: [wgpu::RenderPipeline; 2],
    },
    Compute {
        stages: Vec<ComputeStage>,
        counter: wgpu::Buffer,
        dispatch: wgpu::Buffer,
        /// Kept alive with the bind groups that use them.
        _buffers: Vec<wgpu::Buffer>,
    },
}

/// One dispatch of the compute rasterizer: workgroups `(x, y)`, or indirect from this offset
/// of the dispatch buffer (large triangles, tiles).
struct ComputeStage {
    kernel: Kernel,
    pipeline: wgpu::ComputePipeline,
    bind: wgpu::BindGroup,
    groups: Result<(u32, u32), u64>,
}

/// The compute rasterizer's entry points, in dispatch order.
#[derive(Clone, Copy)]
enum Kernel {
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
    const STAGES: u32 = 7;

    fn name(self) -> &'static str {
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

struct Kernels([wgpu::ComputePipeline; 8]);

impl Kernels {
    fn get(&self, k: Kernel) -> &wgpu::ComputePipeline {
        &self.0[k as usize]
    }
}

/// What [`Gpu::draw`] measured.
#[derive(Clone, Debug)]
pub struct Drawn {
    /// Submitting the frame and waiting for it (wall clock).
    pub wall: Duration,
    /// The frame's time on the GPU, from the start of its first pass to the end of its last
    /// (timestamp queries), where the adapter has them.
    pub gpu: Option<Duration>,
    /// The compute rasterizer's kernels' times on the GPU, in order ([`Gpu::draw_stages`] with
    /// timestamps; empty otherwise).
    pub stages: Vec<(&'static str, Duration)>,
    /// The compute rasterizer's tile list overflowed: the image is incomplete.
    pub overflowed: bool,
}

/// Workgroups `(x, y)` for `n` threads of `size` per group, `x` at most `max`: the shaders'
/// `linear_id` is `gid.x + gid.y · x · size`. `None` when even `max²` groups are too few.
fn dispatch_groups(n: u64, size: u32, max: u32) -> Option<(u32, u32)> {
    let groups = n.div_ceil(u64::from(size)).max(1);
    let x = groups.min(u64::from(max));
    let y = groups.div_ceil(x);
    (y <= u64::from(max)).then_some((x as u32, y as u32))
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
    kernels: std::sync::OnceLock<Result<Kernels, String>>,
    path: GpuPath,
    item_capacity: u32,
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

/// Error scopes around GPU work: what they catch becomes [`Error::Failed`] ([`Gpu::check`]).
struct Scopes {
    out_of_memory: wgpu::ErrorScopeGuard,
    validation: wgpu::ErrorScopeGuard,
}

impl Gpu {
    fn scopes(&self) -> Scopes {
        Scopes {
            out_of_memory: self.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory),
            validation: self.device.push_error_scope(wgpu::ErrorFilter::Validation),
        }
    }

    /// Pops `scopes` (the last pushed first): a validation or out-of-memory error while
    /// `doing` is an error.
    fn check(&self, scopes: Scopes, doing: &'static str) -> Result<(), Error> {
        if let Some(e) = pollster::block_on(scopes.validation.pop()) {
            return Err(self.fail(doing, e.to_string()));
        }
        if let Some(e) = pollster::block_on(scopes.out_of_memory.pop()) {
            return Err(self.fail(doing, format!("out of memory: {e}")));
        }
        Ok(())
    }

    /// Maps `buffer` (a copy into it submitted), waits for the GPU, checks `scopes`, and
    /// returns its contents.
    fn read_buffer<T: bytemuck::Pod>(
        &self,
        buffer: &wgpu::Buffer,
        scopes: Scopes,
        doing: &'static str,
    ) -> Result<Vec<T>, Error> {
        self.read_mapped(buffer, scopes, doing, |data| bytemuck::pod_collect_to_vec(data))
    }

    /// [`Gpu::read_buffer`], `f` reading the mapped bytes in place.
    fn read_mapped<R>(
        &self,
        buffer: &wgpu::Buffer,
        scopes: Scopes,
        doing: &'static str,
        f: impl FnOnce(&[u8]) -> R,
    ) -> Result<R, Error> {
        let (tx, rx) = std::sync::mpsc::channel();
        buffer.map_async(wgpu::MapMode::Read, .., move |r| {
            let _ = tx.send(r);
        });
        self.wait(doing)?;
        self.check(scopes, doing)?;
        rx.recv()
            .map_err(|e| self.fail(doing, e.to_string()))?
            .map_err(|e| self.fail(doing, e.to_string()))?;
        let out = {
            let data = buffer
                .get_mapped_range(..)
                .map_err(|e| self.fail(doing, e.to_string()))?;
            f(&data[..])
        };
        buffer.unmap();
        Ok(out)
    }

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
            // Timestamps time the render pass on the GPU itself, where the adapter has them.
            // and 64-bit integers and atomics make the compute rasterizer.
            required_features: adapter.features()
                & (wgpu::Features::TIMESTAMP_QUERY
                    | wgpu::Features::SHADER_INT64
                    | wgpu::Features::SHADER_INT64_ATOMIC_MIN_MAX),
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
            kernels: std::sync::OnceLock::new(),
            path: GpuPath::Auto,
            item_capacity: ITEM_CAPACITY,
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

    /// Chooses how frames are drawn from now on (default [`GpuPath::Auto`]).
    pub fn set_path(&mut self, path: GpuPath) {
        self.path = path;
    }

    /// Sets the compute rasterizer's tile item capacity (for tests of its overflow).
    #[doc(hidden)]
    pub fn set_item_capacity(&mut self, items: u32) {
        self.item_capacity = items.max(1);
    }

    /// Whether the adapter runs on the CPU (Mesa's lavapipe): [`GpuPath::Auto`] takes the
    /// pipeline there.
    pub fn is_cpu_adapter(&self) -> bool {
        self.info.device_type == wgpu::DeviceType::Cpu
    }

    /// The largest storage buffer binding the device allows, in bytes.
    pub fn max_storage_bytes(&self) -> u64 {
        self.limits
            .max_buffer_size
            .min(self.limits.max_storage_buffer_binding_size)
    }

    /// Whether renders time their pass on the GPU ([`GpuStats::gpu_pass`]): the adapter has
    /// timestamp queries.
    pub fn has_timestamps(&self) -> bool {
        self.device.features().contains(wgpu::Features::TIMESTAMP_QUERY)
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
    /// for the CPU renderer): [`Gpu::prepare`], [`Gpu::draw`], [`Gpu::read`]. Where the
    /// compute rasterizer's tile list overflows, the frame is drawn again by the pipeline
    /// ([`GpuPath::Auto`], [`GpuPath::PreferCompute`]) or the render fails
    /// ([`GpuPath::Compute`]).
    pub fn render(&self, scene: &Scene) -> Result<(Image, GpuStats), Error> {
        let t0 = Instant::now();
        let mut prepared = self.prepare(scene)?;
        let mut upload = t0.elapsed();
        let mut drawn = self.draw(&prepared)?;
        if drawn.overflowed {
            if self.path == GpuPath::Compute {
                return Err(Error::Compute(format!(
                    "its list of large triangles' tiles overflowed (capacity {})",
                    self.item_capacity
                )));
            }
            let t0 = Instant::now();
            prepared = self.prepare_path(scene, GpuPath::Pipeline)?;
            upload += t0.elapsed();
            drawn = self.draw(&prepared)?;
        }
        let t2 = Instant::now();
        let image = self.read(&prepared)?;
        Ok((
            image,
            GpuStats {
                upload,
                render: drawn.wall,
                gpu_pass: drawn.gpu,
                readback: t2.elapsed(),
                triangles: prepared.triangles,
                compute: prepared.is_compute(),
            },
        ))
    }

    /// Uploads `scene` (buffers, targets, bind groups) for [`Gpu::draw`], on the path set by
    /// [`Gpu::set_path`].
    pub fn prepare(&self, scene: &Scene) -> Result<Prepared, Error> {
        self.prepare_path(scene, self.path)
    }

    /// [`Gpu::prepare`] on the given path.
    pub fn prepare_path(&self, scene: &Scene, path: GpuPath) -> Result<Prepared, Error> {
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
        let clip_from_world = scene.camera.clip_from_world(w as f32 / h as f32);
        let compute = match path {
            GpuPath::Pipeline => false,
            // A driver that cannot build the compute rasterizer leaves the pipeline.
            GpuPath::Auto if self.is_cpu_adapter() => false,
            GpuPath::Auto | GpuPath::PreferCompute => self.compute_reason(scene).is_none() && self.kernels().is_ok(),
            GpuPath::Compute => match self.compute_reason(scene) {
                None => true,
                Some(why) => return Err(Error::Compute(why)),
            },
        };

        // Geometry: smooth objects indexed, flat objects de-indexed with centroids; indices
        // absolute (one vertex buffer for all objects).
        let mut vertices: Vec<GpuVertex> = Vec::new();
        let mut vertex_object: Vec<u32> = Vec::new();
        let mut indices: Vec<u32> = Vec::new();
        let mut draws: Vec<(std::ops::Range<u32>, bool)> = Vec::new();
        let mut objects = Vec::with_capacity(scene.objects.len());
        for (i, o) in scene.objects.iter().enumerate() {
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
                        indices.push(vertices.len() as u32);
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
                indices.extend(m.triangles().iter().flatten().map(|&k| k + base as u32));
            }
            vertex_object.resize(vertices.len(), i as u32);
            draws.push((first..indices.len() as u32, !o.shading.options.two_sided));
        }
        let triangles = indices.len() / 3;
        let max_buf = self
            .limits
            .max_buffer_size
            .min(self.limits.max_storage_buffer_binding_size);
        let vertex_limit = if compute { max_buf } else { self.limits.max_buffer_size };
        self.check_limit(
            "vertex buffer bytes",
            (vertices.len() * size_of::<GpuVertex>()) as u64,
            vertex_limit,
        )?;
        self.check_limit("index buffer bytes", (indices.len() * 4) as u64, vertex_limit)?;
        self.check_limit(
            "lights",
            scene.lighting.lights().len() as u64 * size_of::<GpuLight>() as u64,
            max_buf,
        )?;
        if compute {
            self.check_limit("visibility buffer bytes", samples_total * 8, max_buf)?;
            self.check_limit(
                "per-vertex colour bytes",
                vertices.len() as u64 * size_of::<[[f32; 4]; 4]>() as u64,
                max_buf,
            )?;
        }

        let lights: Vec<GpuLight> = scene.lighting.lights().iter().map(GpuLight::from).collect();
        let cam = &scene.camera;
        let frame = GpuFrame {
            clip_from_world: clip_from_world.to_cols_array(),
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
        let bg = scene.image.background;
        let premultiplied = [bg[0] * bg[3], bg[1] * bg[3], bg[2] * bg[3], bg[3]];

        let scopes = self.scopes();
        let d = &self.device;
        let buf = |label, contents: &[u8], usage| {
            d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage,
            })
        };
        let empty = |label, size: u64, usage| {
            d.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: size.max(16),
                usage,
                mapped_at_creation: false,
            })
        };
        let storage = wgpu::BufferUsages::STORAGE;
        let fb = buf("frame", bytemuck::bytes_of(&frame), wgpu::BufferUsages::UNIFORM);
        let lb = buf("lights", &non_empty(&lights), storage);
        let ob = buf("objects", &non_empty(&objects), storage);
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
            wgpu::TextureUsages::COPY_SRC
                | if compute {
                    wgpu::TextureUsages::STORAGE_BINDING
                } else {
                    wgpu::TextureUsages::RENDER_ATTACHMENT
                },
        );
        let resolved_view = resolved.create_view(&Default::default());
        let passes = if compute { Kernel::STAGES } else { 1 };
        let timing = self.has_timestamps().then(|| {
            let set = d.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("phong pass times"),
                ty: wgpu::QueryType::Timestamp,
                count: 2 * passes,
            });
            let resolved = empty(
                "pass times",
                16 * u64::from(passes),
                wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            );
            (set, resolved)
        });
        let feedback = empty(
            "feedback",
            16 + 16 * u64::from(passes),
            wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        );

        let drawing = if compute {
            let kernels = self.kernels()?;
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
                size: [w, h, vertices.len() as u32, triangles as u32],
                background: premultiplied,
                items: [self.item_capacity, samples, 0, 0],
                span: [
                    xs.clone().min().unwrap_or(128),
                    xs.max().unwrap_or(128),
                    ys.clone().min().unwrap_or(128),
                    ys.max().unwrap_or(128),
                ],
                pattern,
            };
            let rb = buf("raster", bytemuck::bytes_of(&raster), wgpu::BufferUsages::UNIFORM);
            let vb = buf("vertices", &non_empty(&vertices), storage);
            let vob = buf("vertex objects", &non_empty(&vertex_object), storage);
            let ib = buf("indices", &non_empty(&indices), storage);
            let projected = empty("projected", vertices.len() as u64 * 16, storage);
            let colors = empty("vertex colours", vertices.len() as u64 * 64, storage);
            let visibility = empty(
                "visibility",
                u64::from(w) * u64::from(h) * u64::from(samples) * 8,
                storage,
            );
            let items = empty("items", u64::from(self.item_capacity) * 8, storage);
            let counter = empty("item counters", 16, storage | wgpu::BufferUsages::COPY_SRC);
            let dispatch = empty("dispatches", 32, storage | wgpu::BufferUsages::INDIRECT);
            let large = empty("large triangles", u64::from(self.item_capacity / 2 + 1) * 16, storage);
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
                (14, wgpu::BindingResource::TextureView(&resolved_view)),
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
                let bind = d.create_bind_group(&wgpu::BindGroupDescriptor {
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
            let stages = vec![
                stage(Kernel::Clear, Ok((samples_total, 64)))?,
                stage(Kernel::Vertex, Ok((vertices.len() as u64, 64)))?,
                stage(Kernel::Raster, Ok((triangles as u64, 64)))?,
                stage(Kernel::Args, Ok((1, 1)))?,
                stage(Kernel::Expand, Err(0))?,
                stage(Kernel::Tiles, Err(16))?,
                ComputeStage {
                    groups: Ok((w.div_ceil(8), h.div_ceil(8))),
                    ..stage(
                        if samples == 1 {
                            Kernel::Shade
                        } else {
                            Kernel::ShadeSamples
                        },
                        Err(0),
                    )?
                },
            ];
            Drawing::Compute {
                stages,
                counter,
                dispatch,
                _buffers: vec![fb, lb, ob, rb, vb, vob, ib, projected, colors, visibility, items, large],
            }
        } else {
            let vb = buf("vertices", &non_empty(&vertices), wgpu::BufferUsages::VERTEX);
            let ib = buf("indices", &non_empty(&indices), wgpu::BufferUsages::INDEX);
            let bind = d.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("phong frame"),
                layout: &self.layout,
                entries: &entries(&[&fb, &lb, &ob]),
            });
            let msaa =
                (samples > 1).then(|| texture("msaa", COLOR_FORMAT, samples, wgpu::TextureUsages::RENDER_ATTACHMENT));
            let depth = texture("depth", DEPTH_FORMAT, samples, wgpu::TextureUsages::RENDER_ATTACHMENT);
            Drawing::Pipeline {
                vb,
                ib,
                bind,
                msaa_view: msaa.as_ref().map(|t| t.create_view(&Default::default())),
                depth_view: depth.create_view(&Default::default()),
                draws,
                pipelines: [self.pipeline(samples, false), self.pipeline(samples, true)],
            }
        };
        self.check(scopes, "preparing the frame")?;
        Ok(Prepared {
            width: w,
            height: h,
            background: bg,
            premultiplied,
            triangles,
            resolved,
            resolved_view,
            timing,
            feedback,
            passes,
            drawing,
        })
    }

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
            (
                "visibility buffer",
                u64::from(scene.image.width) * u64::from(scene.image.height) * u64::from(scene.image.samples) * 8,
            ),
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
                let sx = (c.x / c.w * 0.5 + 0.5) * w;
                let sy = (0.5 - c.y / c.w * 0.5) * h;
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

    fn kernels(&self) -> Result<&Kernels, Error> {
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

    /// Draws a prepared frame and waits for it: wall-clock time, the GPU's own time, and
    /// whether the compute rasterizer's tile list overflowed (the image is then incomplete).
    pub fn draw(&self, p: &Prepared) -> Result<Drawn, Error> {
        self.draw_timed(p, false)
    }

    /// [`Gpu::draw`], the compute rasterizer's kernels each in its own timed pass
    /// ([`Drawn::stages`]). The passes' boundaries cost time of their own (about 0.08 ms of a
    /// 4K frame on an H100), so frames are timed whole by [`Gpu::draw`].
    pub fn draw_stages(&self, p: &Prepared) -> Result<Drawn, Error> {
        self.draw_timed(p, true)
    }

    fn draw_timed(&self, p: &Prepared, per_kernel: bool) -> Result<Drawn, Error> {
        let per_kernel = per_kernel && matches!(p.drawing, Drawing::Compute { .. });
        let passes = if per_kernel { p.passes } else { 1 };
        let scopes = self.scopes();
        let t1 = Instant::now();
        let mut enc = self.device.create_command_encoder(&Default::default());
        match &p.drawing {
            Drawing::Pipeline {
                vb,
                ib,
                bind,
                msaa_view,
                depth_view,
                draws,
                pipelines,
            } => {
                let (view, resolve_target) = match msaa_view {
                    Some(m) => (m, Some(&p.resolved_view)),
                    None => (&p.resolved_view, None),
                };
                let bg = p.premultiplied.map(f64::from);
                let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("phong"),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view,
                        depth_slice: None,
                        resolve_target,
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Clear(wgpu::Color {
                                r: bg[0],
                                g: bg[1],
                                b: bg[2],
                                a: bg[3],
                            }),
                            store: wgpu::StoreOp::Store,
                        },
                    })],
                    depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                        view: depth_view,
                        depth_ops: Some(wgpu::Operations {
                            load: wgpu::LoadOp::Clear(1.0),
                            store: wgpu::StoreOp::Discard,
                        }),
                        stencil_ops: None,
                    }),
                    timestamp_writes: p.timing.as_ref().map(|(set, _)| wgpu::RenderPassTimestampWrites {
                        query_set: set,
                        beginning_of_pass_write_index: Some(0),
                        end_of_pass_write_index: Some(1),
                    }),
                    ..Default::default()
                });
                pass.set_bind_group(0, bind, &[]);
                pass.set_vertex_buffer(0, vb.slice(..));
                pass.set_index_buffer(ib.slice(..), wgpu::IndexFormat::Uint32);
                for (i, (range, cull)) in draws.iter().enumerate() {
                    if range.is_empty() {
                        continue;
                    }
                    pass.set_pipeline(&pipelines[usize::from(*cull)]);
                    pass.draw_indexed(range.clone(), 0, i as u32..i as u32 + 1);
                }
            }
            Drawing::Compute {
                stages,
                counter,
                dispatch,
                ..
            } => {
                // One pass (wgpu puts barriers between its dispatches), or one per kernel.
                let groups: Vec<&[ComputeStage]> = if per_kernel {
                    stages.chunks(1).collect()
                } else {
                    vec![&stages[..]]
                };
                for (i, group) in (0u32..).zip(groups) {
                    let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                        label: Some("phong compute rasterizer"),
                        timestamp_writes: p.timing.as_ref().map(|(set, _)| wgpu::ComputePassTimestampWrites {
                            query_set: set,
                            beginning_of_pass_write_index: Some(2 * i),
                            end_of_pass_write_index: Some(2 * i + 1),
                        }),
                    });
                    for s in group {
                        pass.set_pipeline(&s.pipeline);
                        pass.set_bind_group(0, &s.bind, &[]);
                        match s.groups {
                            Ok((x, y)) => pass.dispatch_workgroups(x, y, 1),
                            Err(offset) => pass.dispatch_workgroups_indirect(dispatch, offset),
                        }
                    }
                }
                enc.copy_buffer_to_buffer(counter, 0, &p.feedback, 0, 16);
            }
        }
        if let Some((set, resolved)) = &p.timing {
            enc.resolve_query_set(set, 0..2 * passes, resolved, 0);
            enc.copy_buffer_to_buffer(resolved, 0, &p.feedback, 16, 16 * u64::from(passes));
        }
        self.queue.submit([enc.finish()]);
        let words: Vec<u32> = self.read_buffer(&p.feedback, scopes, "rendering")?;
        let wall = t1.elapsed();
        let overflow_flag = words[2];
        let ticks: Vec<u64> = words[4..]
            .chunks_exact(2)
            .map(|w| u64::from(w[0]) | u64::from(w[1]) << 32)
            .collect();
        // Ticks × period (ns per tick); a counter that went backwards gives none.
        let period = f64::from(self.queue.get_timestamp_period());
        let span = |a: u64, b: u64| Some(Duration::from_secs_f64(b.checked_sub(a)? as f64 * period * 1e-9));
        let (gpu, stages) = match &p.timing {
            None => (None, Vec::new()),
            Some(_) => {
                let ticks = &ticks[..2 * passes as usize];
                let stages = match &p.drawing {
                    Drawing::Compute { stages, .. } if per_kernel => stages
                        .iter()
                        .zip(ticks.chunks_exact(2))
                        .filter_map(|(s, t)| Some((s.kernel.name(), span(t[0], t[1])?)))
                        .collect(),
                    _ => Vec::new(),
                };
                (span(ticks[0], ticks[ticks.len() - 1]), stages)
            }
        };
        let overflowed = matches!(p.drawing, Drawing::Compute { .. }) && overflow_flag != 0;
        Ok(Drawn {
            wall,
            gpu,
            stages,
            overflowed,
        })
    }

    /// Reads a drawn frame back into a straight-alpha linear image.
    pub fn read(&self, p: &Prepared) -> Result<Image, Error> {
        let (w, h) = (p.width, p.height);
        let d = &self.device;
        let scopes = self.scopes();
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
                texture: &p.resolved,
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
            wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
        );
        self.queue.submit([enc.finish()]);
        // Row by row from the mapping: each row's halves converted by `half` (F16C where the
        // processor has it) into a small buffer, then made straight alpha into the image. On
        // the H100 machine (4K frame) the whole-frame copies this replaces (66 MB of halves,
        // 133 MB of floats, both freshly allocated) took 175–194 ms beside a 44–58 ms copy
        // out of the mapping.
        let bg = p.background;
        let stride = padded as usize;
        let pixels = self.read_mapped(&out, scopes, "reading the image back", |data| {
            let mut pixels = Vec::with_capacity(w as usize * h as usize);
            let mut floats = vec![0f32; 4 * w as usize];
            for y in 0..h as usize {
                let halves: Vec<u16> = bytemuck::pod_collect_to_vec(&data[y * stride..y * stride + row as usize]);
                halves.reinterpret_cast::<half::f16>().convert_to_f32_slice(&mut floats);
                pixels.extend(floats.chunks_exact(4).map(|c| {
                    if c[3] == 1.0 {
                        [c[0], c[1], c[2], 1.0]
                    } else if c[3] > 0.0 {
                        [c[0] / c[3], c[1] / c[3], c[2] / c[3], c[3]]
                    } else {
                        [bg[0], bg[1], bg[2], 0.0]
                    }
                }));
            }
            pixels
        })?;
        Ok(Image::from_pixels(w, h, pixels)?)
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
        let scopes = self.scopes();
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
        let floats: Vec<f32> = self.read_buffer(&out, scopes, "shading test cases")?;
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
