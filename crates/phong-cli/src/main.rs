//! `phong`: the command line. Glue only: parse arguments, load, render, write.

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use phong_core::{Material, named_materials};
use phong_raster::{RenderOptions, render_with_stats};
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
    /// List the built-in materials, or show one.
    Materials {
        /// A material name (case, spaces, '-' and '_' ignored).
        name: Option<String>,
    },
}

#[derive(clap::Args)]
struct RenderArgs {
    /// Scene file (.toml) or model (.obj).
    input: PathBuf,
    /// Output PNG file.
    #[arg(short = 'o', long = "out", value_name = "OUT.png")]
    output: PathBuf,
    /// Image width in pixels (overrides the scene).
    #[arg(long)]
    width: Option<u32>,
    /// Image height in pixels (overrides the scene).
    #[arg(long)]
    height: Option<u32>,
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
    /// Rendering threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// Print counts and the time of each stage.
    #[arg(short, long)]
    verbose: bool,
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
    let result = match cli.command {
        Command::Render(args) => render(args),
        Command::Materials { name } => materials(name.as_deref()),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            let is_input = e.chain().any(|c| {
                c.downcast_ref::<InputError>().is_some()
                    || c.downcast_ref::<phong_scene::Error>().is_some_and(|e| e.is_input())
                    || c.downcast_ref::<phong_core::Error>().is_some()
                    || matches!(
                        c.downcast_ref::<phong_raster::Error>(),
                        Some(phong_raster::Error::Samples(_) | phong_raster::Error::TooLarge { .. })
                    )
            });
            ExitCode::from(if is_input { 2 } else { 1 })
        }
    }
}

fn render(a: RenderArgs) -> Result<()> {
    let t0 = Instant::now();
    let is_png = a.output.extension().is_some_and(|e| e.eq_ignore_ascii_case("png"));
    if !is_png {
        bail!(InputError(format!("output {} must be a .png file", a.output.display())));
    }
    let loaded = phong_scene::load(&a.input)?;
    for w in &loaded.warnings {
        eprintln!("warning: {w}");
    }
    let mut scene = loaded.scene;
    let max = phong_core::limits::MAX_IMAGE_DIMENSION;
    for (flag, v) in [("--width", a.width), ("--height", a.height)] {
        if let Some(v) = v
            && !(1..=max).contains(&v)
        {
            bail!(InputError(format!("{flag} must be from 1 to {max}, got {v}")));
        }
    }
    if let Some(w) = a.width {
        scene.image.width = w;
    }
    if let Some(h) = a.height {
        scene.image.height = h;
    }
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
    if a.threads == Some(0) {
        bail!(InputError("--threads must be at least 1".into()));
    }
    let t_load = t0.elapsed();

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
    let options = RenderOptions {
        threads: a.threads,
        progress: Some(&progress),
    };
    let (mut image, stats) =
        render_with_stats(&scene, &options).with_context(|| format!("rendering {}", a.input.display()))?;
    bar.finish_and_clear();
    phong_core::text::draw_labels(&mut image, &scene.camera, &scene.labels);
    let t_write = Instant::now();
    phong_scene::write_png(&a.output, &image, scene.image.encoding)?;
    let t_write = t_write.elapsed();
    if a.verbose {
        let threads = a
            .threads
            .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
        eprintln!(
            "phong: {} -> {}: {}x{} x{} samples, backend cpu ({threads} threads)",
            a.input.display(),
            a.output.display(),
            scene.image.width,
            scene.image.height,
            scene.image.samples
        );
        eprintln!(
            "phong: triangles={} drawn={} pixels_shaded={}",
            stats.triangles, stats.triangles_drawn, stats.pixels_shaded
        );
        let ms = |d: Duration| d.as_secs_f64() * 1e3;
        eprintln!(
            "phong: load={:.1}ms setup={:.1}ms raster+shade+resolve={:.1}ms png={:.1}ms total={:.1}ms",
            ms(t_load),
            ms(stats.setup),
            ms(stats.raster),
            ms(t_write),
            ms(t0.elapsed())
        );
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
