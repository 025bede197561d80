//! `phong render`: one scene or model to a PNG, on the CPU or the GPU, with a progress bar on
//! a terminal for long renders.

use crate::args::{Job, RunArgs, ShadingArgs};
use crate::{InputError, refuse_overwriting};
use anyhow::{Context, Result, bail};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use phong_raster::Renderer;
use phong_run::{Backend, Picture, Stats as Stages};
use std::io::IsTerminal;
use std::path::PathBuf;
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

/// One render, its labels drawn: the picture and what the renderer measured.
fn render_once(
    job: &Job,
    gpu: Option<&phong_gpu::Gpu>,
    progress: &(dyn Fn(u64, u64) + Sync),
) -> Result<(Picture, Stages)> {
    let options = job.options(Some(progress));
    let backend = match gpu {
        Some(g) => Backend::Gpu(g),
        None => Backend::Cpu(&options),
    };
    Ok(phong_run::draw(&job.scene, backend, &mut Renderer::new())?)
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
    let (picture, stages) =
        render_once(&job, gpu.as_ref(), &progress).with_context(|| format!("rendering {}", job.input.display()))?;
    bar.finish_and_clear();
    let t_write = Instant::now();
    picture.write_png(&a.output)?;
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
