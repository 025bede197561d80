//! Drawing a loaded scene: on the CPU (in a thread pool chosen once) or the GPU, the scene's
//! labels drawn over it, into the image its PNG is encoded from.

use crate::Error;
use phong_core::{Encoding, Image, Image8, Scene};
use phong_raster::{RenderOptions, Rendered, Renderer};
use std::path::Path;

/// The renderer a frame is drawn by.
#[derive(Clone, Copy)]
pub enum Backend<'a> {
    /// The CPU rasterizer, with its options (threads are the pool's: see [`Pool`](crate::Pool)).
    Cpu(&'a RenderOptions<'a>),
    /// The GPU.
    Gpu(&'a phong_gpu::Gpu),
}

/// What a frame's renderer measured.
pub enum Stats {
    /// The CPU's counts and stage times.
    Cpu(phong_raster::RenderStats),
    /// The GPU's.
    Gpu(phong_gpu::GpuStats),
}

impl Stats {
    /// Drawn by the GPU's compute rasterizer.
    pub fn compute(&self) -> bool {
        matches!(self, Stats::Gpu(s) if s.compute)
    }
}

/// A frame with its labels, as its PNG is encoded: in `f32` (the GPU's, or a background
/// alpha that 8 bits cannot tell) or already in 8 bits.
pub enum Picture {
    /// Linear `f32`, encoded with the scene's encoding.
    Linear(Image, Encoding),
    /// 8 bits in the scene's encoding.
    Eight(Image8),
}

impl Picture {
    /// Width and height in pixels.
    pub fn size(&self) -> (u32, u32) {
        match self {
            Picture::Linear(i, _) => (i.width(), i.height()),
            Picture::Eight(i) => (i.width(), i.height()),
        }
    }

    /// The PNG's pixels as RGBA, 8 bits a channel, rows top first (an opaque PNG's alpha is
    /// 255).
    pub fn rgba8(&self) -> Vec<u8> {
        match self {
            Picture::Linear(i, e) => i.to_bytes(*e, true),
            Picture::Eight(i) => i.to_bytes(true),
        }
    }

    /// The PNG file's bytes.
    pub fn png(&self) -> Result<Vec<u8>, Error> {
        match self {
            Picture::Linear(i, e) => phong_scene::encode_png(i, *e),
            Picture::Eight(i) => phong_scene::encode_png8(i),
        }
        .map_err(Error::Encode)
    }

    /// Writes the PNG to `path` atomically (a temporary file renamed over it).
    pub fn write_png(&self, path: &Path) -> Result<(), Error> {
        match self {
            Picture::Linear(i, e) => phong_scene::write_png(path, i, *e)?,
            Picture::Eight(i) => phong_scene::write_png8(path, i)?,
        }
        Ok(())
    }
}

/// Draws `scene` and its labels: on the GPU, or with `renderer` on the current thread pool
/// (its working memory kept for the next frame), into the target its PNG needs.
pub fn draw(scene: &Scene, backend: Backend, renderer: &mut Renderer) -> Result<(Picture, Stats), Error> {
    let (mut picture, stats) = match backend {
        Backend::Gpu(g) => {
            let (image, stats) = g.render(scene)?;
            (Picture::Linear(image, scene.image.encoding), Stats::Gpu(stats))
        }
        Backend::Cpu(options) => {
            let (rendered, stats) = renderer.render_for_png(scene, options)?;
            let eight = matches!(rendered, Rendered::Eight(_));
            let picture = match eight {
                true => Picture::Eight(renderer.take_image8().expect("an image after its render")),
                false => Picture::Linear(
                    renderer.take_image().expect("an image after its render"),
                    scene.image.encoding,
                ),
            };
            (picture, Stats::Cpu(stats))
        }
    };
    match &mut picture {
        Picture::Linear(i, _) => phong_core::text::draw_labels(i, &scene.camera, &scene.labels),
        Picture::Eight(i) => phong_core::text::draw_labels(i, &scene.camera, &scene.labels),
    }
    Ok((picture, stats))
}

/// Draws `scene` in linear `f32`, without labels (the normal and depth outputs' values).
pub fn draw_linear(scene: &Scene, backend: Backend, renderer: &mut Renderer) -> Result<Image, Error> {
    Ok(match backend {
        Backend::Gpu(g) => g.render(scene)?.0,
        Backend::Cpu(options) => {
            renderer.render(scene, options)?;
            renderer.take_image().expect("an image after its render")
        }
    })
}
