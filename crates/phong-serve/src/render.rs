//! Frames for the server: a scene to the PNG file `phong render` writes for it, on the CPU
//! renderer's own thread pool or on the GPU, never on the async threads.

use phong_core::Scene;
use phong_raster::{RenderOptions, Rendered, Renderer};
use std::sync::Mutex;

/// Which renderer draws the frames.
pub enum Backend {
    /// The CPU renderer on a pool of its own, with renderers (their working memory) reused
    /// between frames.
    Cpu {
        /// The rendering threads.
        pool: rayon::ThreadPool,
        /// Idle renderers, one taken per frame.
        renderers: Mutex<Vec<Renderer>>,
    },
    /// The wgpu renderer (one frame at a time).
    Gpu(Box<Mutex<phong_gpu::Gpu>>),
}

impl Backend {
    /// The CPU renderer on `threads` threads (all cores when `None`).
    pub fn cpu(threads: Option<usize>) -> Result<Backend, String> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads.unwrap_or(0))
            .thread_name(|i| format!("phong-render-{i}"))
            .build()
            .map_err(|e| format!("could not start the rendering threads: {e}"))?;
        Ok(Backend::Cpu {
            pool,
            renderers: Mutex::new(Vec::new()),
        })
    }

    /// Words for the startup line: "cpu, 2 threads" or the GPU adapter.
    pub fn describe(&self) -> String {
        match self {
            Backend::Cpu { pool, .. } => format!("cpu, {} threads", pool.current_num_threads()),
            Backend::Gpu(g) => format!("gpu, {}", g.lock().map(|g| g.adapter_name()).unwrap_or_default()),
        }
    }

    /// `scene` as the PNG file `phong render` writes for it (labels drawn, the same encoder),
    /// byte for byte; with `raw`, the same pixels as RGBA bytes, row by row (the page shows
    /// these while the user drags: no encoding here, no decoding in the browser).
    pub fn frame(&self, scene: &Scene, raw: bool) -> Result<Vec<u8>, String> {
        let fail = |e: &dyn std::fmt::Display| format!("rendering failed: {e}");
        match self {
            Backend::Cpu { pool, renderers } => {
                let mut renderer = renderers.lock().ok().and_then(|mut r| r.pop()).unwrap_or_default();
                let options = RenderOptions::default();
                let out = pool.install(|| -> Result<Vec<u8>, String> {
                    // The target `phong render` writes (the renderer chooses it).
                    let (image, _) = renderer.render_for_png(scene, &options).map_err(|e| fail(&e))?;
                    match image {
                        Rendered::Eight(image) if scene.labels.is_empty() => encode8(image, raw),
                        Rendered::Eight(image) => {
                            let mut image = image.clone();
                            phong_core::text::draw_labels(&mut image, &scene.camera, &scene.labels);
                            encode8(&image, raw)
                        }
                        Rendered::Linear(image) => {
                            let mut image = image.clone();
                            phong_core::text::draw_labels(&mut image, &scene.camera, &scene.labels);
                            encode(&image, scene.image.encoding, raw)
                        }
                    }
                });
                if let Ok(mut r) = renderers.lock() {
                    r.push(renderer);
                }
                out
            }
            Backend::Gpu(gpu) => {
                let gpu = gpu.lock().map_err(|_| "the GPU renderer failed earlier".to_string())?;
                let (mut image, _) = gpu.render(scene).map_err(|e| fail(&e))?;
                phong_core::text::draw_labels(&mut image, &scene.camera, &scene.labels);
                encode(&image, scene.image.encoding, raw)
            }
        }
    }
}

fn encode8(image: &phong_core::Image8, raw: bool) -> Result<Vec<u8>, String> {
    if raw {
        Ok(image.to_bytes(true))
    } else {
        phong_scene::encode_png8(image).map_err(|e| format!("encoding the PNG failed: {e}"))
    }
}

fn encode(image: &phong_core::Image, encoding: phong_core::Encoding, raw: bool) -> Result<Vec<u8>, String> {
    if raw {
        Ok(image.to_bytes(encoding, true))
    } else {
        phong_scene::encode_png(image, encoding).map_err(|e| format!("encoding the PNG failed: {e}"))
    }
}
