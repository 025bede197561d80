//! # phong-gpu
//!
//! The GPU renderer on wgpu: the same images as `phong-raster` (within 1/255), from WGSL
//! shaders that port [`phong_core::shade`] line for line (`shaders/shade.wgsl`) and are
//! tested against it.
//!
//! Headless: the scene is drawn into an `Rgba16Float` texture and read back into the same
//! [`Image`] type the CPU renderer returns. Two ways to draw ([`GpuPath`]): the render
//! pipeline (the GPU's rasterizer, `Depth32Float`, MSAA) and the compute rasterizer (the CPU's
//! coverage arithmetic in 64-bit atomics), the default on a GPU where it can draw the frame.
//! BENCHMARKS.md has their speeds.
//!
//! A stage a module: `device` (the adapter, limits, error scopes), `upload` (geometry,
//! buffers, the choice of path), `pipeline` and `compute` (each path's preparation),
//! `frame` (drawing and timing), `readback` (the image), `harness` (the shading test kernel).
//!
//! ## Matching the CPU renderer
//!
//! - The same `clip_from_world` (OpenGL clip depth, converted to WebGPU's in the vertex
//!   shader), so window depth and the `GL_LESS` test are the CPU's.
//! - Counter-clockwise front faces; back faces culled unless the object is two-sided.
//! - Multisampling shades once per pixel at its centre, as the CPU renderer; the standard
//!   4-sample pattern is the CPU's; 16 samples use the device's pattern in the pipeline (the
//!   CPU uses a 4×4 grid), which only moves silhouette pixels.
//! - Flat shading lights each triangle at its centroid with its facet normal (de-indexed
//!   vertices carry both); Gouraud lights vertices in the vertex shader; Phong per fragment.
//! - Straight alpha: fragments are written premultiplied (alpha 1 over a premultiplied clear)
//!   and the read-back divides by the resolved alpha, as the CPU resolve.
//!
//! Lights live in a storage buffer, objects' materials and options in another (indexed by the
//! instance index of each object's draw), so any number of each is one pipeline.

mod compute;
mod device;
mod frame;
mod gpu_types;
mod harness;
mod pipeline;
mod readback;
mod textures;
mod upload;

pub use gpu_types::{GpuCase, GpuFrame, GpuGlobals, GpuLight, GpuMaps, GpuObject, GpuRaster, GpuVertex};

use compute::{ComputeStage, Kernels};
use phong_core::{Image, Scene};
use std::collections::HashMap;
use std::sync::Mutex;
use std::time::{Duration, Instant};
use thiserror::Error;

/// The WGSL shading function (a port of `phong_core::shade`).
pub const SHADE_WGSL: &str = include_str!("shaders/shade.wgsl");
const RENDER_WGSL: &str = concat!(
    include_str!("shaders/shade.wgsl"),
    include_str!("shaders/frame.wgsl"),
    include_str!("shaders/render.wgsl")
);
const RASTER_WGSL: &str = concat!(
    include_str!("shaders/shade.wgsl"),
    include_str!("shaders/frame.wgsl"),
    include_str!("shaders/raster.wgsl")
);
/// The shading function alone, run on test points by [`Gpu::shade_cases`].
const SHADE_CASES_WGSL: &str = concat!(
    include_str!("shaders/shade.wgsl"),
    include_str!("shaders/shade_cases.wgsl")
);
/// Tile items (triangle, 16×16 tile) the compute rasterizer holds per frame (8 bytes each): a
/// frame that needs more is drawn again by the pipeline.
const ITEM_CAPACITY: u32 = 1 << 21;
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
    /// An invalid image size (from the core crate).
    #[error(transparent)]
    Core(#[from] phong_core::Error),
}

impl Error {
    /// Whether the error is in what the caller asked for (the scene is too large for this
    /// device, or cannot be drawn on the path asked for), not in the machine or its driver.
    pub fn is_input(&self) -> bool {
        matches!(self, Error::Limit { .. } | Error::Compute(_) | Error::Core(_))
    }
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
    /// lavapipe), where the pipeline is the faster (BENCHMARKS.md).
    #[default]
    Auto,
    /// The compute rasterizer where it can draw the frame ([`Gpu::compute_reason`]) and its
    /// tile list holds the frame, else the render pipeline.
    PreferCompute,
    /// The render pipeline: the GPU's own rasterizer, MSAA, any geometry.
    Pipeline,
    /// The compute rasterizer; an error where it cannot draw the frame.
    Compute,
}

/// A frame uploaded by [`Gpu::prepare`]: buffers, targets and bind groups, drawn by
/// [`Gpu::draw`] as often as asked and read back by [`Gpu::read`].
pub struct Prepared {
    pub(crate) width: u32,
    pub(crate) height: u32,
    pub(crate) background: [f32; 4],
    pub(crate) premultiplied: [f32; 4],
    pub(crate) triangles: usize,
    pub(crate) resolved: wgpu::Texture,
    pub(crate) resolved_view: wgpu::TextureView,
    /// Timestamps (the start and end of each pass) and the buffer they are resolved into.
    pub(crate) timing: Option<(wgpu::QuerySet, wgpu::Buffer)>,
    /// Mapped after each draw: the compute path's counters (item count, large triangles,
    /// overflow flag; 16 bytes), then the timestamps.
    pub(crate) feedback: wgpu::Buffer,
    /// Timed passes at most: one (the pipeline's) or one per compute kernel.
    pub(crate) passes: u32,
    pub(crate) drawing: Drawing,
}

impl Prepared {
    /// Whether this frame is drawn by the compute rasterizer.
    pub fn is_compute(&self) -> bool {
        matches!(self.drawing, Drawing::Compute { .. })
    }
}

pub(crate) enum Drawing {
    Pipeline {
        vb: wgpu::Buffer,
        ib: wgpu::Buffer,
        bind: wgpu::BindGroup,
        /// Per object: its maps and textures (group 1).
        maps: Vec<wgpu::BindGroup>,
        msaa_view: Option<wgpu::TextureView>,
        depth_view: wgpu::TextureView,
        /// Each object's index range and whether back faces are culled.
        draws: Vec<(std::ops::Range<u32>, bool, bool)>,
        /// By (cull, blend): `pipelines[2·blend + cull]`.
        pipelines: Box<[wgpu::RenderPipeline; 4]>,
    },
    Compute {
        stages: Vec<ComputeStage>,
        counter: wgpu::Buffer,
        dispatch: wgpu::Buffer,
        /// Kept alive with the bind groups that use them.
        _buffers: Vec<wgpu::Buffer>,
    },
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

/// A GPU device ready to render scenes.
pub struct Gpu {
    pub(crate) device: wgpu::Device,
    pub(crate) queue: wgpu::Queue,
    pub(crate) info: wgpu::AdapterInfo,
    pub(crate) limits: wgpu::Limits,
    pub(crate) module: wgpu::ShaderModule,
    pub(crate) layout: wgpu::BindGroupLayout,
    /// Group 1 of the pipeline: an object's maps and textures.
    pub(crate) maps_layout: wgpu::BindGroupLayout,
    pub(crate) pipeline_layout: wgpu::PipelineLayout,
    pub(crate) pipelines: Mutex<HashMap<(u32, bool, bool), wgpu::RenderPipeline>>,
    /// Textures uploaded, kept while the CPU's texture lives (frames of one scene upload each
    /// texture once; a freed texture's entry is dropped at the next frame).
    pub(crate) textures: Mutex<Vec<(std::sync::Weak<phong_core::Texture>, wgpu::TextureView)>>,
    pub(crate) kernels: std::sync::OnceLock<Result<Kernels, String>>,
    pub(crate) path: GpuPath,
    pub(crate) item_capacity: u32,
    pub(crate) lost: std::sync::Arc<Mutex<Option<String>>>,
}

impl Gpu {
    /// Renders `scene` into a linear RGBA image (labels are not drawn: the caller does, as
    /// for the CPU renderer): [`Gpu::prepare_drawn`], then [`Gpu::read`].
    pub fn render(&self, scene: &Scene) -> Result<(Image, GpuStats), Error> {
        let (prepared, drawn, upload) = self.prepare_drawn(scene)?;
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

    /// [`Gpu::prepare`] and [`Gpu::draw`], with the one overflow policy of every caller
    /// (`render`, `phong bench`, the explorer): where the compute rasterizer's tile list
    /// overflows, the frame is prepared and drawn again by the pipeline ([`GpuPath::Auto`],
    /// [`GpuPath::PreferCompute`]), or the draw fails ([`GpuPath::Compute`]). Returns the
    /// prepared frame, its draw, and the time spent preparing.
    pub fn prepare_drawn(&self, scene: &Scene) -> Result<(Prepared, Drawn, Duration), Error> {
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
        Ok((prepared, drawn, upload))
    }
}

#[cfg(test)]
mod tests {
    /// render.wgsl's shininess cap is phong-core's: the WGSL constant parsed back.
    #[test]
    fn wgsl_shininess_cap_is_phong_core_s() {
        let line = super::RENDER_WGSL
            .lines()
            .find_map(|l| l.strip_prefix("const MAX_SHININESS: f32 = "))
            .expect("render.wgsl declares MAX_SHININESS");
        let value: f32 = line.trim_end_matches(';').parse().expect("a number");
        assert_eq!(value, phong_core::MetalRough::MAX_SHININESS);
    }
}
