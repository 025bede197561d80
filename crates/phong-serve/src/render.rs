//! Frames for the server: a scene to the PNG file `phong render` writes for it, on the CPU
//! renderer's own thread pool or on the GPU, never on the async threads.

use phong_core::Scene;
use phong_raster::{Pool, RenderOptions, Renderer};
use std::sync::Mutex;

/// Which renderer draws the frames.
pub enum Backend {
    /// The CPU renderer on a pool of its own, with renderers (their working memory) reused
    /// between frames.
    Cpu {
        /// The rendering threads.
        pool: Pool,
        /// Idle renderers, one taken per frame.
        renderers: Mutex<Vec<Renderer>>,
    },
    /// The wgpu renderer (one frame at a time).
    Gpu(Box<Mutex<phong_gpu::Gpu>>),
}

impl Backend {
    /// The CPU renderer on `threads` threads (all cores when `None`).
    pub fn cpu(threads: Option<usize>) -> Result<Backend, String> {
        let pool = Pool::own(threads, "phong-render").map_err(|e| e.to_string())?;
        Ok(Backend::Cpu {
            pool,
            renderers: Mutex::new(Vec::new()),
        })
    }

    /// Words for the startup line: "cpu, 2 threads" or the GPU adapter.
    pub fn describe(&self) -> String {
        match self {
            Backend::Cpu { pool, .. } => format!("cpu, {} threads", pool.threads()),
            Backend::Gpu(g) => format!("gpu, {}", g.lock().map(|g| g.adapter_name()).unwrap_or_default()),
        }
    }

    /// `scene` as the PNG file `phong render` writes for it (labels drawn, the same encoder),
    /// byte for byte; with `raw`, the same pixels as RGBA bytes, row by row (the page shows
    /// these while the user drags: no encoding here, no decoding in the browser).
    pub fn frame(&self, scene: &Scene, raw: bool) -> Result<Vec<u8>, String> {
        let fail = |e: &dyn std::fmt::Display| format!("rendering failed: {e}");
        let (picture, _) = match self {
            Backend::Cpu { pool, renderers } => {
                let mut renderer = renderers.lock().ok().and_then(|mut r| r.pop()).unwrap_or_default();
                let options = RenderOptions::default();
                let drawn = pool.install(|| phong_run::draw(scene, phong_run::Backend::Cpu(&options), &mut renderer));
                if let Ok(mut r) = renderers.lock() {
                    r.push(renderer);
                }
                drawn.map_err(|e| fail(&e))?
            }
            Backend::Gpu(gpu) => {
                let gpu = gpu.lock().map_err(|_| "the GPU renderer failed earlier".to_string())?;
                phong_run::draw(scene, phong_run::Backend::Gpu(&gpu), &mut Renderer::new()).map_err(|e| fail(&e))?
            }
        };
        if raw {
            Ok(picture.rgba8())
        } else {
            picture.png().map_err(|e| e.to_string())
        }
    }
}
