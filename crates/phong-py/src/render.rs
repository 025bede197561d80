//! Rendering into numpy arrays, the GIL released: a scene's colour (the PNG's RGBA bytes),
//! a term, its depth or its normals.

use crate::scene::{SceneCore, ViewArgs};
use crate::{InputError, RenderError, guarded, py_err};
use numpy::{IntoPyArray, PyArrayMethods};
use phong_core::{Image, Output};
use phong_raster::{RenderOptions, Renderer};
use phong_run::{Backend, Models, Pool, Settings, Source};
use pyo3::prelude::*;
use std::path::PathBuf;
use std::sync::Mutex;

/// What the caller asked for.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Kind {
    /// RGBA bytes of the PNG (colour, or a term).
    Rgba,
    /// Linear depth.
    Depth,
    /// World-space unit normals.
    Normal,
}

/// The settings and the kind of array for `output` and the size arguments.
fn settings(
    width: Option<u32>,
    height: Option<u32>,
    antialias: Option<u32>,
    output: &str,
) -> PyResult<(Settings, Kind)> {
    let max = phong_core::limits::MAX_IMAGE_DIMENSION;
    for (k, v) in [("width", width), ("height", height)] {
        if let Some(v) = v
            && !(1..=max).contains(&v)
        {
            return Err(InputError::new_err(format!("{k} must be from 1 to {max}, got {v}")));
        }
    }
    let out = phong_scene::parse_choice("output", output, phong_scene::OUTPUTS).map_err(InputError::new_err)?;
    let kind = match out {
        Output::Depth => Kind::Depth,
        Output::Normal => Kind::Normal,
        _ => Kind::Rgba,
    };
    let mut samples = antialias
        .map(|n| {
            phong_core::Samples::from_count(n)
                .map_err(|_| InputError::new_err(format!("antialias must be 1, 4 or 16, got {n}")))
        })
        .transpose()?;
    if kind != Kind::Rgba {
        // One surface's value a pixel, not an average over an edge.
        samples = Some(phong_core::Samples::One);
    }
    let s = Settings {
        width,
        height,
        samples,
        // "color" is the scene as its file says (an object's own `output` kept), as `phong
        // render` without `--output`; every other term overrides every object, as `--output`.
        overrides: phong_scene::Overrides {
            output: (out != Output::Color).then_some(out),
            ..Default::default()
        },
        ..Settings::default()
    };
    Ok((s, kind))
}

/// A render's backend, owned: the CPU (with its pool) or a GPU.
pub(crate) struct Engine {
    pool: Pool,
    gpu: Option<phong_gpu::Gpu>,
}

impl Engine {
    fn new(threads: Option<usize>, backend: &str) -> PyResult<Engine> {
        let pool = Pool::new(threads).map_err(|e| py_err(e.into()))?;
        let gpu = match backend {
            "cpu" => None,
            "gpu" => Some(phong_gpu::Gpu::new().map_err(|e| RenderError::new_err(format!("backend \"gpu\": {e}")))?),
            "auto" => phong_gpu::Gpu::new().ok(),
            b => {
                return Err(InputError::new_err(format!(
                    "backend must be \"cpu\", \"gpu\" or \"auto\", got {b:?}"
                )));
            }
        };
        Ok(Engine { pool, gpu })
    }

    /// Draws `scene` as `kind` asks, into a flat array and its shape.
    fn draw(
        &self,
        scene: &mut phong_core::Scene,
        kind: Kind,
        renderer: &mut Renderer,
    ) -> Result<Array, phong_run::Error> {
        let options = RenderOptions::default();
        let backend = match &self.gpu {
            Some(g) => Backend::Gpu(g),
            None => Backend::Cpu(&options),
        };
        self.pool.install(|| {
            if kind == Kind::Rgba {
                let (picture, _) = phong_run::draw(scene, backend, renderer)?;
                let (w, h) = picture.size();
                return Ok(Array::U8(picture.rgba8(), vec![h as usize, w as usize, 4]));
            }
            // The background's alpha 0 tells the pixels no surface covers.
            scene.image.background = [0.0; 4];
            let image = phong_run::draw_linear(scene, backend, renderer)?;
            Ok(values(&image, kind, &scene.camera))
        })
    }
}

/// A flat array and its shape.
enum Array {
    U8(Vec<u8>, Vec<usize>),
    F32(Vec<f32>, Vec<usize>),
}

impl Array {
    fn into_py(self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        Ok(match self {
            Array::U8(v, shape) => v.into_pyarray(py).reshape(shape)?.into_any().unbind(),
            Array::F32(v, shape) => v.into_pyarray(py).reshape(shape)?.into_any().unbind(),
        })
    }
}

/// The depth (distance along the view axis) or the unit normal of each pixel, from the
/// renderer's depth and normal outputs; 0 where no surface is.
fn values(image: &Image, kind: Kind, camera: &phong_core::Camera) -> Array {
    let (w, h) = (image.width() as usize, image.height() as usize);
    let (near, far) = (camera.near(), camera.far());
    match kind {
        Kind::Depth => {
            let v = image
                .pixels()
                .iter()
                .map(|p| {
                    if p[3] > 0.0 {
                        near + (1.0 - p[0]) * (far - near)
                    } else {
                        0.0
                    }
                })
                .collect();
            Array::F32(v, vec![h, w])
        }
        _ => {
            let mut v = Vec::with_capacity(w * h * 3);
            for p in image.pixels() {
                let n = glam::Vec3::new(p[0], p[1], p[2]) * 2.0 - glam::Vec3::ONE;
                let n = if p[3] > 0.0 {
                    n.normalize_or_zero()
                } else {
                    glam::Vec3::ZERO
                };
                v.extend_from_slice(&n.to_array());
            }
            Array::F32(v, vec![h, w, 3])
        }
    }
}

/// The image size and samples: the Python keyword arguments `width`, `height` and
/// `antialias`, passed as one dict.
#[derive(FromPyObject, Default)]
#[pyo3(from_item_all)]
pub struct Size {
    width: Option<u32>,
    height: Option<u32>,
    antialias: Option<u32>,
}

/// `phong.render` of a path: exactly what `phong render PATH` draws.
#[pyfunction]
#[pyo3(signature = (path, size, output="color", backend="cpu", threads=None, view=None))]
pub fn render_path(
    py: Python<'_>,
    path: PathBuf,
    size: Size,
    output: &str,
    backend: &str,
    threads: Option<usize>,
    view: Option<ViewArgs>,
) -> PyResult<Py<PyAny>> {
    let (mut s, kind) = settings(size.width, size.height, size.antialias, output)?;
    let view = view.unwrap_or_default();
    s.view = view.options()?;
    if !phong_scene::is_model_path(&path) && view.given() {
        return Err(InputError::new_err(format!(
            "up, view, camera and two_sided apply to a model alone; {} is a scene file",
            path.display()
        )));
    }
    let array = py.detach(|| {
        guarded(|| {
            let engine = Engine::new(threads, backend)?;
            let mut loaded =
                phong_run::load(Source::Path(&path), &s, &Models::new(), "width, height, antialias").map_err(py_err)?;
            engine
                .draw(&mut loaded.scene, kind, &mut Renderer::new())
                .map_err(py_err)
        })
    })?;
    array.into_py(py)
}

/// A renderer kept between frames: its thread pool, GPU and working memory.
#[pyclass(module = "phong._phong", frozen)]
pub struct RendererCore {
    engine: Engine,
    renderer: Mutex<Renderer>,
    width: Option<u32>,
    height: Option<u32>,
    antialias: Option<u32>,
}

#[pymethods]
impl RendererCore {
    #[new]
    #[pyo3(signature = (width=None, height=None, antialias=None, threads=None, backend="cpu"))]
    fn new(
        width: Option<u32>,
        height: Option<u32>,
        antialias: Option<u32>,
        threads: Option<usize>,
        backend: &str,
    ) -> PyResult<RendererCore> {
        settings(width, height, antialias, "color")?;
        Ok(RendererCore {
            engine: Engine::new(threads, backend)?,
            renderer: Mutex::new(Renderer::new()),
            width,
            height,
            antialias,
        })
    }

    /// Renders `scene` (a `SceneCore`) as `output` asks.
    #[pyo3(signature = (scene, output="color", width=None, height=None, antialias=None))]
    fn render(
        &self,
        py: Python<'_>,
        scene: &SceneCore,
        output: &str,
        width: Option<u32>,
        height: Option<u32>,
        antialias: Option<u32>,
    ) -> PyResult<Py<PyAny>> {
        let (s, kind) = settings(
            width.or(self.width),
            height.or(self.height),
            antialias.or(self.antialias),
            output,
        )?;
        let array = py.detach(|| {
            guarded(|| {
                let mut built = scene.build(&s).map_err(py_err)?;
                let mut renderer = self
                    .renderer
                    .lock()
                    .map_err(|_| RenderError::new_err("the renderer failed in another thread"))?;
                self.engine.draw(&mut built, kind, &mut renderer).map_err(py_err)
            })
        })?;
        array.into_py(py)
    }

    /// The threads CPU frames are drawn on.
    #[getter]
    fn threads(&self) -> usize {
        self.engine.pool.threads()
    }
}

/// Writes `image` (`uint8` (H, W, 4) RGBA, or (H, W, 3) RGB) as a PNG at `path`, as phong
/// writes its images: RGB where every alpha is 255, through a temporary file renamed over
/// `path`.
#[pyfunction]
pub fn save_png(py: Python<'_>, path: PathBuf, image: numpy::PyReadonlyArray3<'_, u8>) -> PyResult<()> {
    let a = image.as_array();
    let (h, w, c) = a.dim();
    if !(c == 3 || c == 4) || h == 0 || w == 0 {
        return Err(InputError::new_err(format!(
            "image must be uint8 (H, W, 4) RGBA or (H, W, 3) RGB, got shape {:?}",
            a.shape()
        )));
    }
    let mut rgba = Vec::with_capacity(h * w * 4);
    for p in a.rows() {
        rgba.extend_from_slice(&[p[0], p[1], p[2], if c == 4 { p[3] } else { 255 }]);
    }
    py.detach(|| {
        let png = phong_scene::encode_rgba8(w as u32, h as u32, &rgba)
            .map_err(|e| RenderError::new_err(format!("encoding the PNG failed: {e}")))?;
        phong_scene::write_file(&path, &png).map_err(|e| RenderError::new_err(phong_run::message(&e)))
    })
}

/// Whether `path` holds a whole PNG file (its signature and its closing chunk): what
/// `phong batch` checks before it skips a job.
#[pyfunction]
pub fn is_complete_png(path: PathBuf) -> bool {
    phong_scene::is_complete_png(&path)
}
