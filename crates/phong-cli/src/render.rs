//! `phong render`: one scene or model to a PNG, on the CPU or the GPU, with a progress bar on
//! a terminal for long renders.

use crate::args::{Job, RunArgs, ShadingArgs};
use crate::report::Stages;
use crate::{InputError, refuse_overwriting};
use anyhow::{Context, Result, bail};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use phong_raster::{Rendered, Renderer};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::Once;
use std::time::{Duration, Instant};

#[derive(clap::Args)]
pub struct RenderArgs {
    #[command(flatten)]
    pub run: RunArgs,
    /// Output PNG file.
    #[arg(short = 'o', long = "out", value_name = "OUT.png")]
    pub output: PathBuf,
    #[command(flatten)]
    pub shading: ShadingArgs,
}

/// An image ready to write: the GPU's in `f32`, the CPU's as its renderer chose.
enum Image {
    Linear(phong_core::Image),
    Eight(phong_core::Image8),
}

impl Image {
    fn draw_labels(&mut self, scene: &phong_core::Scene) {
        match self {
            Image::Linear(i) => phong_core::text::draw_labels(i, &scene.camera, &scene.labels),
            Image::Eight(i) => phong_core::text::draw_labels(i, &scene.camera, &scene.labels),
        }
    }

    fn write_png(&self, path: &Path, scene: &phong_core::Scene) -> Result<()> {
        match self {
            Image::Linear(i) => phong_scene::write_png(path, i, scene.image.encoding)?,
            Image::Eight(i) => phong_scene::write_png8(path, i)?,
        }
        Ok(())
    }
}

/// One render: the image and what the renderer measured.
fn render_once(
    job: &Job,
    gpu: Option<&phong_gpu::Gpu>,
    progress: &(dyn Fn(u64, u64) + Sync),
) -> Result<(Image, Stages)> {
    if let Some(g) = gpu {
        let (image, stats) = g.render(&job.scene)?;
        return Ok((Image::Linear(image), Stages::Gpu(stats)));
    }
    let mut renderer = Renderer::new();
    let (rendered, stats) = renderer.render_for_png(&job.scene, &job.options(Some(progress)))?;
    let eight = matches!(rendered, Rendered::Eight(_));
    let image = match eight {
        true => renderer.into_image8().map(Image::Eight),
        false => renderer.into_image().map(Image::Linear),
    };
    Ok((image.expect("an image after its render"), Stages::Cpu(stats)))
}

/// Renders `a.run.input` to `a.output`.
pub fn render(a: RenderArgs) -> Result<()> {
    let t0 = Instant::now();
    let is_png = a.output.extension().is_some_and(|e| e.eq_ignore_ascii_case("png"));
    if !is_png {
        bail!(InputError(format!("output {} must be a .png file", a.output.display())));
    }
    let job = a.run.resolve(Some(&a.shading))?;
    refuse_overwriting(&a.output, &job.sources)?;
    let t_load = t0.elapsed();
    let gpu = job.open_gpu()?;
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
    let (mut image, stages) =
        render_once(&job, gpu.as_ref(), &progress).with_context(|| format!("rendering {}", job.input.display()))?;
    bar.finish_and_clear();
    image.draw_labels(&job.scene);
    let t_write = Instant::now();
    image.write_png(&a.output, &job.scene)?;
    if job.verbose {
        let backend = crate::report::backend(&job, gpu.as_ref(), stages.compute());
        crate::report::render(
            &job,
            &a.output,
            &backend,
            &stages,
            t_load,
            t_write.elapsed(),
            t0.elapsed(),
        );
    }
    Ok(())
}
