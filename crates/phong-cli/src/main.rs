//! `phong`: the command line. Glue only: parse arguments, load, render, write.

mod fit;
mod serve;

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use phong_core::{Material, named_materials};
use phong_raster::{RenderOptions, RenderStats, Renderer, render_with_stats};
use phong_scene::{INTERPOLATIONS, MODELS, OUTPUTS, apply_model, parse_choice};
use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Once;
use std::time::{Duration, Instant};

#[derive(Parser)]
#[command(name = "phong", version, about = "Render scenes with the Phong illumination model.")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene file (.toml) or an OBJ model (.obj) to a PNG.
    Render(RenderArgs),
    /// Render a scene repeatedly and print the time per frame.
    Bench(BenchArgs),
    /// Serve the live explorer in the browser (until Ctrl-C).
    Serve(serve::ServeArgs),
    /// Fit a material to a target image of a scene, or to a BRDF.
    Fit(fit::FitArgs),
    /// List the built-in materials, or show one.
    Materials {
        /// A material name (case, spaces, '-' and '_' ignored).
        name: Option<String>,
    },
}

#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum Backend {
    /// The multi-core CPU rasteriser.
    Cpu,
    /// The wgpu renderer (an error when no adapter is found).
    Gpu,
    /// The GPU when an adapter is found, else the CPU.
    Auto,
}

#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum GpuPathArg {
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
struct RunArgs {
    /// Scene file (.toml) or model (.obj).
    input: PathBuf,
    /// Image width in pixels (overrides the scene).
    #[arg(long)]
    width: Option<u32>,
    /// Image height in pixels (overrides the scene).
    #[arg(long)]
    height: Option<u32>,
    /// Rendering threads for the CPU backend (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// Renderer.
    #[arg(long, value_enum, default_value_t = Backend::Cpu)]
    backend: Backend,
    /// GPU: how frames are drawn.
    #[arg(long, value_enum, default_value_t = GpuPathArg::Auto)]
    gpu_path: GpuPathArg,
    /// CPU: the scalar reference path instead of the fast path.
    #[arg(long)]
    reference: bool,
    /// Print counts, the backend and the time of each stage.
    #[arg(short, long)]
    verbose: bool,
}

impl RunArgs {
    /// Checks the flags, loads the scene (printing its warnings) and applies the size overrides.
    fn load(&self) -> Result<phong_core::Scene> {
        Ok(self.load_with_sources()?.0)
    }

    /// [`RunArgs::load`] and every file the scene read.
    fn load_with_sources(&self) -> Result<(phong_core::Scene, Vec<PathBuf>)> {
        let max = phong_core::limits::MAX_IMAGE_DIMENSION;
        for (flag, v) in [("--width", self.width), ("--height", self.height)] {
            if let Some(v) = v
                && !(1..=max).contains(&v)
            {
                bail!(InputError(format!("{flag} must be from 1 to {max}, got {v}")));
            }
        }
        if let Some(t) = self.threads
            && !(1..=phong_core::limits::MAX_THREADS).contains(&t)
        {
            bail!(InputError(format!(
                "--threads must be from 1 to {}, got {t}",
                phong_core::limits::MAX_THREADS
            )));
        }
        let loaded = phong_scene::load(&self.input)?;
        for w in &loaded.warnings {
            eprintln!("warning: {w}");
        }
        let mut scene = loaded.scene;
        if let Some(w) = self.width {
            scene.image.width = w;
        }
        if let Some(h) = self.height {
            scene.image.height = h;
        }
        Ok((scene, loaded.sources))
    }

    /// The CPU renderer's options.
    fn options<'a>(&self, progress: Option<&'a (dyn Fn(u64, u64) + Sync)>) -> RenderOptions<'a> {
        RenderOptions {
            threads: self.threads,
            progress,
            reference: self.reference,
            no_avx2: false,
        }
    }
}

#[derive(clap::Args)]
struct RenderArgs {
    #[command(flatten)]
    run: RunArgs,
    /// Output PNG file.
    #[arg(short = 'o', long = "out", value_name = "OUT.png")]
    output: PathBuf,
    /// Samples per pixel: 1, 4 or 16 (overrides the scene).
    #[arg(long)]
    antialias: Option<u32>,
    /// Shading model: lambert, phong, blinn-phong, phong-lyon, opengl.
    #[arg(long)]
    model: Option<String>,
    /// Interpolation: flat, gouraud, phong.
    #[arg(long)]
    interpolation: Option<String>,
    /// What to show: color, ambient, diffuse, specular, normal, depth.
    #[arg(long = "output", value_name = "TERM")]
    term: Option<String>,
}

#[derive(clap::Args)]
struct BenchArgs {
    #[command(flatten)]
    run: RunArgs,
    /// Frames to time, after one warm-up frame.
    #[arg(long, default_value_t = 10)]
    frames: u32,
}

/// An error in what the user gave (exit code 2).
#[derive(Debug)]
struct InputError(String);
impl std::fmt::Display for InputError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}
impl std::error::Error for InputError {}

fn input<T>(r: Result<T, String>) -> Result<T> {
    r.map_err(|m| InputError(m).into())
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    // A panic is a bug: one line and exit 1, not a backtrace (RUST_BACKTRACE=1 still gives one).
    if std::env::var_os("RUST_BACKTRACE").is_none() {
        std::panic::set_hook(Box::new(|info| {
            eprintln!("error: internal error (a bug in phong; please report it): {info}");
        }));
    }
    let result = match std::panic::catch_unwind(move || run(cli)) {
        Ok(r) => r,
        Err(_) => return ExitCode::from(1),
    };
    report(result)
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Render(args) => render(args),
        Command::Bench(args) => bench(args),
        Command::Serve(args) => serve::serve(args),
        Command::Fit(args) => fit::fit(args),
        Command::Materials { name } => materials(name.as_deref()),
    }
}

/// The exit code of a command's result, its error printed.
fn report(result: Result<()>) -> ExitCode {
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            let is_input = e.chain().any(|c| {
                c.downcast_ref::<InputError>().is_some()
                    || c.downcast_ref::<phong_scene::Error>().is_some_and(|e| e.is_input())
                    || c.downcast_ref::<phong_core::Error>().is_some()
                    || matches!(
                        c.downcast_ref::<phong_fit::FitError>(),
                        Some(phong_fit::FitError::Input(_))
                    )
                    || matches!(
                        c.downcast_ref::<phong_serve::StartError>(),
                        Some(phong_serve::StartError::Input(_) | phong_serve::StartError::Usage(_))
                    )
                    || matches!(
                        c.downcast_ref::<phong_gpu::Error>(),
                        Some(
                            phong_gpu::Error::Samples(_)
                                | phong_gpu::Error::Limit { .. }
                                | phong_gpu::Error::Core(_)
                                | phong_gpu::Error::Compute(_)
                        )
                    )
                    || matches!(
                        c.downcast_ref::<phong_raster::Error>(),
                        Some(phong_raster::Error::Samples(_) | phong_raster::Error::TooLarge { .. })
                    )
            });
            ExitCode::from(if is_input { 2 } else { 1 })
        }
    }
}

/// An error (exit 2) when `output` is one of the files read: the same path, a symlink to it, or
/// a hard link (the same device and inode).
fn refuse_overwriting(output: &std::path::Path, inputs: &[PathBuf]) -> Result<()> {
    use std::os::unix::fs::MetadataExt;
    let Ok(out) = std::fs::metadata(output) else {
        return Ok(()); // not there yet: it cannot be an input
    };
    for input in inputs {
        if let Ok(m) = std::fs::metadata(input)
            && (m.dev(), m.ino()) == (out.dev(), out.ino())
        {
            bail!(InputError(format!(
                "the output {} is the input {}: refusing to overwrite it",
                output.display(),
                input.display()
            )));
        }
    }
    Ok(())
}

/// The GPU when asked for (an error if there is none), or for `auto` when one is found.
fn open_gpu(backend: Backend, path: GpuPathArg) -> Result<Option<phong_gpu::Gpu>> {
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

/// A rendered image: the GPU's in `f32`, the CPU's in 8 bits where that is exact (see
/// `Renderer::render_8bit`), else in `f32`.
enum Rendered {
    Linear(phong_core::Image),
    Bits(phong_core::Image8),
}

impl Rendered {
    fn draw_labels(&mut self, scene: &phong_core::Scene) {
        match self {
            Rendered::Linear(i) => phong_core::text::draw_labels(i, &scene.camera, &scene.labels),
            Rendered::Bits(i) => phong_core::text::draw_labels(i, &scene.camera, &scene.labels),
        }
    }

    fn write_png(&self, path: &std::path::Path, scene: &phong_core::Scene) -> Result<()> {
        match self {
            Rendered::Linear(i) => phong_scene::write_png(path, i, scene.image.encoding)?,
            Rendered::Bits(i) => phong_scene::write_png8(path, i)?,
        }
        Ok(())
    }
}

/// One render: the image, times (setup or upload, raster or GPU render pass, read-back, then
/// the CPU's stage times), triangles drawn, pixels shaded, and whether the GPU's compute
/// rasterizer drew it.
fn render_once(
    scene: &phong_core::Scene,
    gpu: Option<&phong_gpu::Gpu>,
    options: &RenderOptions,
) -> Result<(Rendered, [Duration; 6], usize, u64, bool)> {
    Ok(match gpu {
        Some(g) => {
            let (img, st) = g.render(scene)?;
            let z = Duration::ZERO;
            (
                Rendered::Linear(img),
                [st.upload, st.render, st.readback, z, z, z],
                st.triangles,
                0,
                st.compute,
            )
        }
        None => {
            let mut renderer = Renderer::new();
            match renderer.render_8bit(scene, options)?.map(|(_, st)| st) {
                Some(st) => (
                    Rendered::Bits(renderer.into_image8().expect("an 8-bit image after its render")),
                    cpu_times(&st),
                    st.triangles_drawn,
                    st.pixels_shaded,
                    false,
                ),
                None => {
                    let (img, st) = render_with_stats(scene, options)?;
                    (
                        Rendered::Linear(img),
                        cpu_times(&st),
                        st.triangles_drawn,
                        st.pixels_shaded,
                        false,
                    )
                }
            }
        }
    })
}

/// The CPU renderer's times in [`render_once`]'s order: setup, raster, (no read-back), then the
/// tiles' rasterisation, shading and resolve CPU times.
fn cpu_times(st: &phong_raster::RenderStats) -> [Duration; 6] {
    [
        st.setup,
        st.raster,
        Duration::ZERO,
        st.tile_raster,
        st.tile_shade,
        st.tile_resolve,
    ]
}

fn render(a: RenderArgs) -> Result<()> {
    let t0 = Instant::now();
    let is_png = a.output.extension().is_some_and(|e| e.eq_ignore_ascii_case("png"));
    if !is_png {
        bail!(InputError(format!("output {} must be a .png file", a.output.display())));
    }
    let (mut scene, sources) = a.run.load_with_sources()?;
    refuse_overwriting(&a.output, &sources)?;
    if let Some(s) = a.antialias {
        if !phong_core::limits::SAMPLE_COUNTS.contains(&s) {
            bail!(InputError(format!("--antialias must be 1, 4 or 16, got {s}")));
        }
        scene.image.samples = s;
    }
    // Flags override the file, for the scene's defaults and every object.
    let model = a
        .model
        .as_deref()
        .map(|m| input(parse_choice("--model", m, MODELS)))
        .transpose()?;
    let interpolation = a
        .interpolation
        .as_deref()
        .map(|i| input(parse_choice("--interpolation", i, INTERPOLATIONS)))
        .transpose()?;
    let term = a
        .term
        .as_deref()
        .map(|t| input(parse_choice("--output", t, OUTPUTS)))
        .transpose()?;
    for sh in std::iter::once(&mut scene.shading).chain(scene.objects.iter_mut().map(|o| &mut o.shading)) {
        if let Some(model) = model {
            let lyon = match sh.options.specular {
                phong_core::SpecularModel::Lyon { squarings, lambda } => (squarings, lambda),
                _ => (3, phong_core::LyonLambda::Dot),
            };
            apply_model(&mut sh.options, model, lyon);
        }
        if let Some(i) = interpolation {
            sh.interpolation = i;
        }
        if let Some(t) = term {
            sh.output = t;
        }
    }
    let t_load = t0.elapsed();

    let gpu = open_gpu(a.run.backend, a.run.gpu_path)?;
    let bar = ProgressBar::hidden();
    bar.set_style(ProgressStyle::with_template("{bar:40} {percent:>3}% {elapsed}").expect("valid template"));
    let tty = std::io::stderr().is_terminal();
    let show = Once::new();
    let start = Instant::now();
    let progress = |done: u64, total: u64| {
        if !tty || start.elapsed() < Duration::from_secs(1) {
            return;
        }
        show.call_once(|| bar.set_draw_target(ProgressDrawTarget::stderr()));
        bar.set_length(total);
        bar.set_position(done);
    };
    let options = a.run.options(Some(&progress));
    let (mut image, times, triangles, shaded, gpu_compute) =
        render_once(&scene, gpu.as_ref(), &options).with_context(|| format!("rendering {}", a.run.input.display()))?;
    bar.finish_and_clear();
    image.draw_labels(&scene);
    let t_write = Instant::now();
    image.write_png(&a.output, &scene)?;
    let t_write = t_write.elapsed();
    if a.run.verbose {
        let backend = match &gpu {
            Some(g) => format!(
                "gpu, {}, {}",
                g.adapter_name(),
                if gpu_compute {
                    "compute rasterizer"
                } else {
                    "render pipeline"
                }
            ),
            None => {
                let n = a
                    .run
                    .threads
                    .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
                format!("cpu, {n} threads")
            }
        };
        eprintln!(
            "phong: {} -> {}: {}x{} x{} samples, backend {backend}",
            a.run.input.display(),
            a.output.display(),
            scene.image.width,
            scene.image.height,
            scene.image.samples
        );
        eprintln!(
            "phong: triangles={} drawn={triangles} pixels_shaded={shaded}",
            scene.triangle_count()
        );
        let ms = |d: Duration| d.as_secs_f64() * 1e3;
        let (first, second) = if gpu.is_some() {
            ("upload", "render")
        } else {
            ("setup", "raster+shade+resolve")
        };
        eprintln!(
            "phong: load={:.1}ms {first}={:.1}ms {second}={:.1}ms readback={:.1}ms png={:.1}ms total={:.1}ms",
            ms(t_load),
            ms(times[0]),
            ms(times[1]),
            ms(times[2]),
            ms(t_write),
            ms(t0.elapsed())
        );
    }
    Ok(())
}

/// `phong bench`: one warm-up render, then `frames` timed renders, reported as the mean per
/// frame of the rendering alone: setup and raster on the CPU; the render pass on the GPU, with
/// upload and read-back printed separately by -v.
fn bench(a: BenchArgs) -> Result<()> {
    if a.frames == 0 {
        bail!(InputError("--frames must be at least 1".into()));
    }
    let scene = a.run.load()?;
    let gpu = open_gpu(a.run.backend, a.run.gpu_path)?;
    let mut sum = [Duration::ZERO; 6];
    // The GPU's own time of the pass (timestamp queries), where every frame had one.
    let mut gpu_pass = Some(Duration::ZERO);
    // GPU: uploaded once and drawn `frames` times (as the CPU renderer's buffers are kept);
    // read back from the first few frames.
    let mut gpu_path = "";
    // Preparing the frame and its first (warm-up) draw, once.
    let mut upload = Duration::ZERO;
    // The compute rasterizer's kernels on the GPU, summed over frames.
    let mut gpu_stages: Vec<(&str, Duration)> = Vec::new();
    let reads = a.frames.min(3);
    match &gpu {
        Some(g) => {
            let t0 = Instant::now();
            let mut prepared = g.prepare(&scene)?;
            if g.draw(&prepared)?.overflowed {
                prepared = g.prepare_path(&scene, phong_gpu::GpuPath::Pipeline)?;
                g.draw(&prepared)?;
            }
            upload = t0.elapsed();
            gpu_path = if prepared.is_compute() {
                "compute rasterizer"
            } else {
                "render pipeline"
            };
            for frame in 0..a.frames {
                let drawn = g.draw(&prepared)?;
                sum[1] += drawn.wall;
                gpu_pass = gpu_pass.zip(drawn.gpu).map(|(a, b)| a + b);
                if frame < reads {
                    let t = Instant::now();
                    g.read(&prepared)?;
                    sum[2] += t.elapsed();
                }
            }
            // -v: the compute kernels' times, from as many frames again, each kernel in its
            // own timed pass (not in the frame times above: the passes cost time of their own).
            for _ in 0..if a.run.verbose { a.frames } else { 0 } {
                let drawn = g.draw_stages(&prepared)?;
                if gpu_stages.is_empty() {
                    gpu_stages = drawn.stages.iter().map(|&(k, _)| (k, Duration::ZERO)).collect();
                }
                for (total, (_, d)) in gpu_stages.iter_mut().zip(&drawn.stages) {
                    total.1 += *d;
                }
            }
        }
        None => {
            // As a real-time renderer runs: one thread pool, one framebuffer and one working
            // memory for all frames (llvmpipe's harness, too, draws every frame into the same
            // buffer).
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(a.run.threads.unwrap_or(0))
                .build()
                .context("starting the rendering threads")?;
            let options = RenderOptions {
                threads: None,
                ..a.run.options(None)
            };
            // In 8 bits where `phong render` writes 8 bits (the same bytes), as llvmpipe renders
            // into an RGBA8 buffer.
            let mut renderer = Renderer::new();
            let frame = |renderer: &mut Renderer| -> Result<RenderStats> {
                Ok(match renderer.render_8bit(&scene, &options)?.map(|(_, st)| st) {
                    Some(st) => st,
                    None => renderer.render(&scene, &options)?.1,
                })
            };
            pool.install(|| -> Result<()> {
                frame(&mut renderer)?;
                for _ in 0..a.frames {
                    let st = frame(&mut renderer)?;
                    for (k, d) in cpu_times(&st).into_iter().enumerate() {
                        sum[k] += d;
                    }
                }
                Ok(())
            })?;
        }
    }
    let timed = if gpu.is_some() { sum[1] } else { sum[0] + sum[1] };
    let per = timed.as_secs_f64() / f64::from(a.frames);
    let pixels = f64::from(scene.image.width) * f64::from(scene.image.height);
    println!(
        "phong: {}x{} tris={} frames={} ms_per_frame={:.1} mpix_per_s={:.1}",
        scene.image.width,
        scene.image.height,
        scene.triangle_count(),
        a.frames,
        per * 1e3,
        pixels / per / 1e6
    );
    if a.run.verbose {
        let ms = |d: Duration| d.as_secs_f64() * 1e3 / f64::from(a.frames);
        match &gpu {
            Some(g) => {
                eprintln!(
                    "phong: gpu ({}, {gpu_path}) upload (once)={:.2}ms per frame: render={:.3}ms (on the GPU: {}) \
                     readback={:.2}ms",
                    g.adapter_name(),
                    upload.as_secs_f64() * 1e3,
                    ms(sum[1]),
                    gpu_pass.map_or("no timestamps".into(), |d| format!("pass={:.3}ms", ms(d))),
                    sum[2].as_secs_f64() * 1e3 / f64::from(reads)
                );
                if !gpu_stages.is_empty() {
                    let list: Vec<String> = gpu_stages
                        .iter()
                        .map(|(k, d)| format!("{}={:.3}ms", k.trim_start_matches("cs_"), ms(*d)))
                        .collect();
                    eprintln!(
                        "phong: gpu kernels per frame (each timed in its own pass): {}",
                        list.join(" ")
                    );
                }
            }
            None => eprintln!(
                "phong: cpu per frame: setup+binning={:.2}ms raster+shade+resolve={:.2}ms \
                 (in the tiles, CPU time over all threads: rasterisation={:.2}ms shading={:.2}ms resolve={:.2}ms)",
                ms(sum[0]),
                ms(sum[1]),
                ms(sum[3]),
                ms(sum[4]),
                ms(sum[5])
            ),
        }
    }
    Ok(())
}

fn fmt3(c: phong_core::Color) -> String {
    format!("{:.6} {:.6} {:.6}", c.r, c.g, c.b)
}

fn materials(name: Option<&str>) -> Result<()> {
    match name {
        None => {
            println!(
                "{:<16} {:<27} {:<27} {:<27} {:>5} {:>9}",
                "name", "ambient", "diffuse", "specular", "alpha", "shininess"
            );
            for m in named_materials() {
                let v = &m.material;
                println!(
                    "{:<16} {:<27} {:<27} {:<27} {:>5} {:>9}",
                    m.name,
                    fmt3(v.ambient()),
                    fmt3(v.diffuse()),
                    fmt3(v.specular()),
                    v.alpha(),
                    v.shininess()
                );
            }
        }
        Some(n) => {
            let m = Material::named(n).map_err(|e| InputError(e.to_string()))?;
            let canonical = named_materials().iter().find(|x| x.material == m).map_or(n, |x| x.name);
            println!("{canonical}");
            println!("  ambient   {}", fmt3(m.ambient()));
            println!("  diffuse   {}", fmt3(m.diffuse()));
            println!("  specular  {}", fmt3(m.specular()));
            println!("  emission  {}", fmt3(m.emission()));
            println!("  shininess {}", m.shininess());
            println!("  alpha     {}", m.alpha());
        }
    }
    Ok(())
}
