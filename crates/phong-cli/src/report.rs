//! `-v`: what a render or a benchmark measured, in one line per subject on stderr.

use crate::args::Job;
use std::path::Path;
use std::time::Duration;

use phong_run::Stats as Stages;

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// The backend in words: the GPU's adapter and path, or the CPU's threads.
pub fn backend(job: &Job, gpu: Option<&phong_gpu::Gpu>, compute: bool) -> String {
    match gpu {
        Some(g) => format!("gpu, {}, {}", g.adapter_name(), path_name(compute)),
        None => {
            let n = job
                .threads
                .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
            let kernels = phong_raster::kernels(&job.options(None));
            format!("cpu, {n} threads, {kernels}")
        }
    }
}

/// The GPU path in words.
pub fn path_name(compute: bool) -> &'static str {
    if compute {
        "compute rasterizer"
    } else {
        "render pipeline"
    }
}

/// `phong render -v`.
pub fn render(
    job: &Job,
    output: &Path,
    backend: &str,
    stages: &Stages,
    load: Duration,
    png: Duration,
    total: Duration,
) {
    let image = &job.scene.image;
    eprintln!(
        "phong: {} -> {}: {}x{} x{} samples, backend {backend}",
        job.input.display(),
        output.display(),
        image.width,
        image.height,
        image.samples
    );
    let (drawn, shaded, first, second, readback) = match stages {
        Stages::Cpu(s) => (
            s.triangles_drawn,
            s.pixels_shaded,
            ("setup", s.setup),
            ("raster+shade+resolve", s.raster),
            Duration::ZERO,
        ),
        Stages::Gpu(s) => (s.triangles, 0, ("upload", s.upload), ("render", s.render), s.readback),
    };
    eprintln!(
        "phong: triangles={} drawn={drawn} pixels_shaded={shaded}",
        job.scene.triangle_count()
    );
    census(&job.scene);
    eprintln!(
        "phong: load={:.1}ms {}={:.1}ms {}={:.1}ms readback={:.1}ms png={:.1}ms total={:.1}ms",
        ms(load),
        first.0,
        ms(first.1),
        second.0,
        ms(second.1),
        ms(readback),
        ms(png),
        ms(total)
    );
}

/// The CPU renderer's stage times summed over a benchmark's frames.
#[derive(Default)]
pub struct CpuSum {
    pub setup: Duration,
    pub raster: Duration,
    pub tile_raster: Duration,
    pub tile_shade: Duration,
    pub tile_resolve: Duration,
}

impl CpuSum {
    pub fn add(&mut self, s: &phong_raster::RenderStats) {
        self.setup += s.setup;
        self.raster += s.raster;
        self.tile_raster += s.tile_raster;
        self.tile_shade += s.tile_shade;
        self.tile_resolve += s.tile_resolve;
    }

    /// `phong bench -v` for the CPU, per frame of `frames`.
    pub fn report(&self, frames: u32) {
        let per = |d: Duration| ms(d) / f64::from(frames);
        eprintln!(
            "phong: cpu per frame: setup+binning={:.2}ms raster+shade+resolve={:.2}ms \
             (in the tiles, CPU time over all threads: rasterisation={:.2}ms shading={:.2}ms resolve={:.2}ms)",
            per(self.setup),
            per(self.raster),
            per(self.tile_raster),
            per(self.tile_shade),
            per(self.tile_resolve)
        );
    }
}

/// The GPU's times over a benchmark's frames.
#[derive(Default)]
pub struct GpuSum {
    /// Preparing the frame and its warm-up draw, once.
    pub upload: Duration,
    /// Submitting and waiting, summed over frames.
    pub render: Duration,
    /// The frames' time on the GPU, where every frame had timestamps.
    pub gpu_pass: Option<Duration>,
    /// Read-backs, summed over `reads` frames.
    pub readback: Duration,
    pub reads: u32,
    /// The compute rasterizer's kernels on the GPU, summed over frames (`-v`).
    pub kernels: Vec<(&'static str, Duration)>,
}

impl GpuSum {
    /// `phong bench -v` for the GPU, per frame of `frames`.
    pub fn report(&self, gpu: &phong_gpu::Gpu, compute: bool, frames: u32) {
        let per = |d: Duration| ms(d) / f64::from(frames);
        eprintln!(
            "phong: gpu ({}, {}) upload (once)={:.2}ms per frame: render={:.3}ms (on the GPU: {}) readback={:.2}ms",
            gpu.adapter_name(),
            path_name(compute),
            ms(self.upload),
            per(self.render),
            self.gpu_pass
                .map_or("no timestamps".into(), |d| format!("pass={:.3}ms", per(d))),
            ms(self.readback) / f64::from(self.reads.max(1))
        );
        if !self.kernels.is_empty() {
            let list: Vec<String> = self
                .kernels
                .iter()
                .map(|(k, d)| format!("{}={:.3}ms", k.trim_start_matches("cs_"), per(*d)))
                .collect();
            eprintln!(
                "phong: gpu kernels per frame (each timed in its own pass): {}",
                list.join(" ")
            );
        }
    }
}

/// Per model or shape (a model's parts, `file:group`, counted together): its triangles read
/// and what became of them.
fn census(scene: &phong_core::Scene) {
    let mut groups: Vec<phong_raster::Census> = Vec::new();
    for c in phong_raster::census(scene) {
        let name = c.name.split(':').next().unwrap_or(&c.name).to_string();
        match groups.iter_mut().find(|g| g.name == name) {
            Some(g) => {
                g.triangles += c.triangles;
                g.outside += c.outside;
                g.culled += c.culled;
                g.clipped += c.clipped;
                g.inside += c.inside;
            }
            None => groups.push(phong_raster::Census { name, ..c }),
        }
    }
    for g in groups {
        eprintln!(
            "phong: {}: {} triangles read: {} drawn, {} clipped then drawn, {} culled (back faces, no area), {} outside the view",
            g.name, g.triangles, g.inside, g.clipped, g.culled, g.outside
        );
    }
}
