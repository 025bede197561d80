//! `phong bench`: one warm-up render, then `frames` timed renders, reported as the mean per
//! frame of the rendering alone: setup and raster on the CPU; the draw on the GPU, with upload
//! and read-back printed separately by `-v`.

use crate::InputError;
use crate::args::RunArgs;
use crate::report::{CpuSum, GpuSum};
use anyhow::{Result, bail};
use phong_raster::{RenderOptions, Renderer};
use std::time::{Duration, Instant};

#[derive(clap::Args)]
pub struct BenchArgs {
    #[command(flatten)]
    pub run: RunArgs,
    /// Frames to time, after one warm-up frame.
    #[arg(long, default_value_t = 10)]
    pub frames: u32,
}

/// Benchmarks `a.run.input`.
pub fn bench(a: BenchArgs) -> Result<()> {
    if a.frames == 0 {
        bail!(InputError("--frames must be at least 1".into()));
    }
    let frames = a.frames;
    let job = a.run.resolve(None)?;
    let scene = &job.scene;
    let gpu = job.open_gpu()?;
    let (timed, report): (Duration, Box<dyn FnOnce()>) = match &gpu {
        Some(g) => {
            // Uploaded once and drawn `frames` times (as the CPU renderer keeps its buffers),
            // read back from the first few frames; the overflow policy is `render`'s.
            let (prepared, _, upload) = g.prepare_drawn(scene)?;
            let mut sum = GpuSum {
                upload,
                gpu_pass: Some(Duration::ZERO),
                reads: frames.min(3),
                ..GpuSum::default()
            };
            for frame in 0..frames {
                let drawn = g.draw(&prepared)?;
                sum.render += drawn.wall;
                sum.gpu_pass = sum.gpu_pass.zip(drawn.gpu).map(|(a, b)| a + b);
                if frame < sum.reads {
                    let t = Instant::now();
                    g.read(&prepared)?;
                    sum.readback += t.elapsed();
                }
            }
            // -v: the compute kernels' times, from as many frames again, each kernel in its
            // own timed pass (not in the frame times above: the passes cost time of their own).
            for _ in 0..if job.verbose { frames } else { 0 } {
                let drawn = g.draw_stages(&prepared)?;
                if sum.kernels.is_empty() {
                    sum.kernels = drawn.stages.iter().map(|&(k, _)| (k, Duration::ZERO)).collect();
                }
                for (total, (_, d)) in sum.kernels.iter_mut().zip(&drawn.stages) {
                    total.1 += *d;
                }
            }
            let compute = prepared.is_compute();
            (sum.render, Box::new(move || sum.report(g, compute, frames)))
        }
        None => {
            // As a real-time renderer runs: one thread pool, one framebuffer and one working
            // memory for all frames (llvmpipe's harness, too, draws every frame into the same
            // buffer), in the target `phong render` writes (8 bits where they are exact, as
            // llvmpipe renders into an RGBA8 buffer).
            let pool = phong_raster::Pool::own(job.threads, "phong-bench")?;
            let options = RenderOptions {
                threads: None,
                ..job.options(None)
            };
            let mut renderer = Renderer::new();
            let mut sum = CpuSum::default();
            pool.install(|| -> Result<()> {
                renderer.render_for_png(scene, &options)?;
                for _ in 0..frames {
                    sum.add(&renderer.render_for_png(scene, &options)?.1);
                }
                Ok(())
            })?;
            (sum.setup + sum.raster, Box::new(move || sum.report(frames)))
        }
    };
    let per = timed.as_secs_f64() / f64::from(frames);
    let pixels = f64::from(scene.image.width) * f64::from(scene.image.height);
    println!(
        "phong: {}x{} tris={} frames={frames} ms_per_frame={:.1} mpix_per_s={:.1}",
        scene.image.width,
        scene.image.height,
        scene.triangle_count(),
        per * 1e3,
        pixels / per / 1e6
    );
    if job.verbose {
        report();
    }
    Ok(())
}
