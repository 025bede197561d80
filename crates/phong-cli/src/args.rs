//! The arguments `render` and `bench` share, resolved once: the flags checked, the scene
//! loaded with its warnings printed, and the overrides applied.

use crate::InputError;
use anyhow::{Context, Result, bail};
use phong_raster::RenderOptions;
use phong_scene::{INTERPOLATIONS, MODELS, OUTPUTS, Overrides, parse_choice};
use std::path::PathBuf;

#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Backend {
    /// The multi-core CPU rasteriser.
    Cpu,
    /// The wgpu renderer (an error when no adapter is found).
    Gpu,
    /// The GPU when an adapter is found, else the CPU.
    Auto,
}

#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum GpuPathArg {
    /// On a GPU the compute rasterizer where it can draw the frame, else the pipeline; on a
    /// CPU adapter (lavapipe) the pipeline.
    Auto,
    /// The GPU's render pipeline (its own rasterizer).
    Pipeline,
    /// The compute rasterizer (an error where it cannot draw the frame).
    Compute,
}

/// What `render` and `bench` share: the input, its overrides and how to render it.
#[derive(clap::Args)]
pub struct RunArgs {
    /// Scene file (.toml) or model (.obj, .gltf, .glb, .ply, .stl).
    pub input: PathBuf,
    /// Image width in pixels (overrides the scene).
    #[arg(long)]
    pub width: Option<u32>,
    /// Image height in pixels (overrides the scene).
    #[arg(long)]
    pub height: Option<u32>,
    /// Rendering threads for the CPU backend (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Renderer.
    #[arg(long, value_enum, default_value_t = Backend::Cpu)]
    pub backend: Backend,
    /// GPU: how frames are drawn.
    #[arg(long, value_enum, default_value_t = GpuPathArg::Auto)]
    pub gpu_path: GpuPathArg,
    /// CPU: the scalar reference path instead of the fast path.
    #[arg(long)]
    pub reference: bool,
    /// CPU: which builds of the fast path's vector kernels may run, for comparisons. The AVX2
    /// builds' images are the same, bit for bit; the portable build's within 1/255 of them.
    #[arg(long, value_enum, default_value_t = KernelsArg::Auto)]
    pub kernels: KernelsArg,
    /// The same as `--kernels avx2` (kept for scripts that use it).
    #[arg(long, hide = true)]
    pub no_avx512: bool,
    /// Print counts, the backend and the time of each stage.
    #[arg(short, long)]
    pub verbose: bool,
    /// How a model alone is viewed.
    #[command(flatten)]
    pub view: ViewArgs,
}

/// How a model alone (not a scene file) is viewed: `render MODEL`, `bench MODEL`,
/// `serve MODEL`.
#[derive(clap::Args, Default)]
pub struct ViewArgs {
    /// A model alone: its up axis, x, y, z, -x, -y or -z (default: detected).
    #[arg(long, value_name = "AXIS", allow_hyphen_values = true)]
    pub up: Option<String>,
    /// A model alone: front, back, left, right, top, bottom or iso (default: the front, a
    /// little right and above).
    #[arg(long)]
    pub view: Option<String>,
    /// A model alone: the camera's position and target in the model file's coordinates.
    #[arg(long, value_name = "PX,PY,PZ,TX,TY,TZ", allow_hyphen_values = true)]
    pub camera: Option<String>,
    /// A model alone: draw back faces, lit with their normals flipped (the default for a model
    /// that is not closed).
    #[arg(long, conflicts_with = "cull")]
    pub two_sided: bool,
    /// A model alone: cull back faces (the default for a closed model).
    #[arg(long)]
    pub cull: bool,
}

impl ViewArgs {
    /// Whether any flag is given.
    fn given(&self) -> bool {
        self.up.is_some() || self.view.is_some() || self.camera.is_some() || self.two_sided || self.cull
    }

    /// The flags as the scene reader's options, framed for `aspect` (width / height).
    pub fn options(&self, aspect: Option<f32>) -> Result<phong_scene::ModelOptions> {
        let camera = match &self.camera {
            None => None,
            Some(c) => {
                let v: Vec<f64> = c
                    .split(',')
                    .map(|x| x.trim().parse::<f64>().ok().filter(|x| x.is_finite()))
                    .collect::<Option<_>>()
                    .filter(|v: &Vec<f64>| v.len() == 6)
                    .ok_or_else(|| {
                        InputError(format!(
                            "--camera must be six finite numbers PX,PY,PZ,TX,TY,TZ (position, target), got {c:?}"
                        ))
                    })?;
                let (p, t) = (glam::DVec3::new(v[0], v[1], v[2]), glam::DVec3::new(v[3], v[4], v[5]));
                if p == t {
                    bail!(InputError(
                        "--camera: the position and the target are the same point".into()
                    ));
                }
                Some((p, t))
            }
        };
        Ok(phong_scene::ModelOptions {
            up: choice("--up", &self.up, &phong_scene::Axis::NAMES)?,
            view: choice("--view", &self.view, &phong_scene::ViewName::NAMES)?,
            camera,
            sides: if self.two_sided {
                Some(phong_scene::Sides::TwoSided)
            } else if self.cull {
                Some(phong_scene::Sides::Cull)
            } else {
                None
            },
            aspect,
        })
    }
}

/// The shading overrides `render` takes (as an object's keys override the scene's
/// `[shading]`).
#[derive(clap::Args)]
pub struct ShadingArgs {
    /// Samples per pixel: 1, 4 or 16 (overrides the scene).
    #[arg(long)]
    pub antialias: Option<u32>,
    /// Shading model: lambert, phong, blinn-phong, phong-lyon, opengl.
    #[arg(long)]
    pub model: Option<String>,
    /// Interpolation: flat, gouraud, phong.
    #[arg(long)]
    pub interpolation: Option<String>,
    /// What to show: color, ambient, diffuse, specular, normal, depth.
    #[arg(long = "output", value_name = "TERM")]
    pub term: Option<String>,
}

/// A run's arguments resolved: the scene as it will be rendered, every file it read, and the
/// renderer's settings.
pub struct Job {
    pub scene: phong_core::Scene,
    pub sources: Vec<PathBuf>,
    pub input: PathBuf,
    pub threads: Option<usize>,
    pub backend: Backend,
    pub gpu_path: GpuPathArg,
    pub reference: bool,
    pub kernels: phong_raster::Kernels,
    pub verbose: bool,
}

impl RunArgs {
    /// Checks the flags, loads the scene (printing its warnings), and applies the size and
    /// `shading` overrides.
    pub fn resolve(self, shading: Option<&ShadingArgs>) -> Result<Job> {
        let max = phong_core::limits::MAX_IMAGE_DIMENSION;
        for (flag, v) in [("--width", self.width), ("--height", self.height)] {
            if let Some(v) = v
                && !(1..=max).contains(&v)
            {
                bail!(InputError(format!("{flag} must be from 1 to {max}, got {v}")));
            }
        }
        threads_flag(self.threads)?;
        let overrides = shading.map(ShadingArgs::overrides).transpose()?.unwrap_or_default();
        let samples = match shading.and_then(|s| s.antialias) {
            Some(n) => Some(
                phong_core::Samples::from_count(n)
                    .map_err(|_| InputError(format!("--antialias must be 1, 4 or 16, got {n}")))?,
            ),
            None => None,
        };
        let is_model = phong_scene::is_model_path(&self.input);
        if !is_model && self.view.given() {
            bail!(InputError(format!(
                "--up, --view, --camera, --two-sided and --cull apply to a model alone; {} is a scene file \
                 (set its [camera] and [shading] two_sided instead)",
                self.input.display()
            )));
        }
        let settings = phong_run::Settings {
            width: self.width,
            height: self.height,
            samples,
            overrides,
            view: self.view.options(None)?,
            tables: Default::default(),
        };
        let source = phong_run::Source::Path(&self.input);
        let loaded = phong_run::load(
            source,
            &settings,
            &phong_run::Models::new(),
            "--width, --height, --antialias",
        )?;
        for w in &loaded.warnings {
            eprintln!("warning: {w}");
        }
        if self.verbose {
            for n in &loaded.notes {
                eprintln!("phong: {n}");
            }
            let l = &loaded.times;
            eprintln!(
                "phong: load stages: read={:.1}ms parse={:.1}ms normals={:.1}ms framing={:.1}ms (a large model's normals and framing side by side; the rest of load= builds the scene)",
                l.read.as_secs_f64() * 1e3,
                l.parse.as_secs_f64() * 1e3,
                l.normals.as_secs_f64() * 1e3,
                l.framing.as_secs_f64() * 1e3
            );
            let t = &loaded.textures;
            if t.images + t.shared > 0 {
                eprintln!(
                    "phong: textures: {} images ({} from the texture cache), {} shared, {:.1} MiB with mipmaps; read={:.1}ms decode={:.1}ms mipmaps={:.1}ms cache-write={:.1}ms",
                    t.images,
                    t.from_store,
                    t.shared,
                    t.bytes as f64 / f64::from(1u32 << 20),
                    t.read.as_secs_f64() * 1e3,
                    t.decode.as_secs_f64() * 1e3,
                    t.mipmaps.as_secs_f64() * 1e3,
                    t.store_writes.as_secs_f64() * 1e3
                );
            }
            if t.store_failures > 0 {
                eprintln!(
                    "phong: texture cache: {} writes failed: {}",
                    t.store_failures,
                    phong_scene::last_store_error().unwrap_or_default()
                );
            }
        }
        let scene = loaded.scene;
        Ok(Job {
            scene,
            sources: loaded.sources,
            input: self.input,
            threads: self.threads,
            backend: self.backend,
            gpu_path: self.gpu_path,
            reference: self.reference,
            kernels: if self.no_avx512 {
                phong_raster::Kernels::Avx2
            } else {
                self.kernels.into()
            },
            verbose: self.verbose,
        })
    }
}

impl ShadingArgs {
    /// The flags as scene overrides (each checked against its names).
    fn overrides(&self) -> Result<Overrides> {
        Ok(Overrides {
            model: choice("--model", &self.model, MODELS)?,
            interpolation: choice("--interpolation", &self.interpolation, INTERPOLATIONS)?,
            output: choice("--output", &self.term, OUTPUTS)?,
        })
    }
}

/// `value` of `flag` looked up in `table`, if given.
fn choice<T: Copy>(flag: &str, value: &Option<String>, table: &[(&str, T)]) -> Result<Option<T>> {
    Ok(value
        .as_deref()
        .map(|v| parse_choice(flag, v, table).map_err(InputError))
        .transpose()?)
}

impl Job {
    /// The CPU renderer's options.
    pub fn options<'a>(&self, progress: Option<&'a (dyn Fn(u64, u64) + Sync)>) -> RenderOptions<'a> {
        RenderOptions {
            threads: self.threads,
            progress,
            reference: self.reference,
            kernels: self.kernels,
        }
    }

    /// The GPU when asked for (an error if there is none), or for `auto` when one is found.
    pub fn open_gpu(&self) -> Result<Option<phong_gpu::Gpu>> {
        open_gpu(self.backend, self.gpu_path)
    }
}

/// The GPU when asked for (an error if there is none), or for `auto` when one is found.
pub fn open_gpu(backend: Backend, path: GpuPathArg) -> Result<Option<phong_gpu::Gpu>> {
    let mut gpu = match backend {
        Backend::Cpu => None,
        Backend::Gpu => Some(phong_gpu::Gpu::new().context("--backend gpu")?),
        Backend::Auto => phong_gpu::Gpu::new().ok(),
    };
    if let Some(g) = &mut gpu {
        g.set_path(match path {
            GpuPathArg::Auto => phong_gpu::GpuPath::Auto,
            GpuPathArg::Pipeline => phong_gpu::GpuPath::Pipeline,
            GpuPathArg::Compute => phong_gpu::GpuPath::Compute,
        });
    }
    Ok(gpu)
}

/// `--kernels`: which builds of the CPU's vector kernels may run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum KernelsArg {
    /// The best this CPU has (AVX2 with AVX-512's registers, AVX2, or portable)
    Auto,
    /// At most AVX2 with 16 vector registers
    Avx2,
    /// The portable build
    Portable,
}

impl From<KernelsArg> for phong_raster::Kernels {
    fn from(k: KernelsArg) -> Self {
        match k {
            KernelsArg::Auto => phong_raster::Kernels::Auto,
            KernelsArg::Avx2 => phong_raster::Kernels::Avx2,
            KernelsArg::Portable => phong_raster::Kernels::Portable,
        }
    }
}

/// `--threads`, checked by the renderer's one rule ([`phong_raster::Pool::check`]) and refused
/// in the flag's name.
pub fn threads_flag(threads: Option<usize>) -> Result<()> {
    phong_raster::Pool::check(threads).map_err(|_| {
        InputError(format!(
            "--threads must be from 1 to {}, got {}",
            phong_core::limits::MAX_THREADS,
            threads.unwrap_or(0)
        ))
    })?;
    Ok(())
}
