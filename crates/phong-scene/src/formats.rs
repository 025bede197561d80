//! Model files by format: OBJ with its MTL libraries (`obj/`), PLY (`ply.rs`), STL (`stl.rs`)
//! and glTF (`gltf_model.rs`). The format is told by the content where the content tells it (PLY's `ply` line,
//! glTF's magic, a binary STL's size, an ASCII STL's `solid`), else by the extension; anything
//! else is an error naming the formats phong reads.

use crate::obj::{decode_text, obj_from_text};
use crate::{Error, ModelPart, read_bounded};
use glam::{DVec3, Vec3};
use phong_core::limits::MAX_MODEL_BYTES;
use std::path::{Path, PathBuf};

const WHAT: &str = "model (MAX_MODEL_BYTES)";

/// The model formats phong reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ModelFormat {
    /// Wavefront OBJ (with MTL libraries).
    Obj,
    /// Stanford PLY, ASCII or binary.
    Ply,
    /// STL, ASCII or binary.
    Stl,
    /// glTF 2.0: `.gltf` (JSON, with `.bin` files or data URIs) or `.glb`.
    Gltf,
}

/// A model file read: its parts and, for glTF, the file's first camera and its lights.
#[derive(Clone, Debug)]
pub struct LoadedModel {
    /// The parts (a group and material each).
    pub parts: Vec<ModelPart>,
    /// The file's camera (glTF).
    pub camera: Option<crate::gltf_model::FileCamera>,
    /// The file's lights (glTF's KHR_lights_punctual).
    pub lights: Vec<crate::gltf_model::FileLight>,
    /// Whether the file says which faces are drawn (glTF: `Some(true)` where a material is
    /// double-sided, `Some(false)` where none is); `None` for formats that do not say.
    pub double_sided: Option<bool>,
    /// Its format.
    pub format: ModelFormat,
    /// Whether it is closed and how it is wound, found when it is first framed.
    pub(crate) closed: std::sync::OnceLock<crate::model::Closed>,
}

impl LoadedModel {
    /// A model whose file says nothing of a camera, lights or which faces are drawn (OBJ, PLY,
    /// STL).
    pub fn new(parts: Vec<ModelPart>, format: ModelFormat) -> LoadedModel {
        LoadedModel {
            parts,
            camera: None,
            lights: Vec::new(),
            double_sided: None,
            format,
            closed: Default::default(),
        }
    }
}

/// The format of model `path` whose bytes are `bytes`; an error for glTF (not read yet) and
/// for what is none of them.
pub fn model_format(path: &Path, bytes: &[u8]) -> Result<ModelFormat, Error> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let fail = |message: String| Error::Model {
        path: path.to_path_buf(),
        message,
    };
    if bytes.starts_with(b"ply\n") || bytes.starts_with(b"ply\r\n") {
        return Ok(ModelFormat::Ply);
    }
    if bytes.starts_with(b"glTF") || ext == "gltf" || ext == "glb" {
        return Ok(ModelFormat::Gltf);
    }
    // A binary STL: an 80-byte header, a triangle count, 50 bytes a triangle (its header may
    // begin with "solid" too, so the size decides first).
    if bytes.len() >= 84 {
        let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]);
        if 84 + 50 * u64::from(n) == bytes.len() as u64 {
            return Ok(ModelFormat::Stl);
        }
    }
    let head = String::from_utf8_lossy(&bytes[..bytes.len().min(1024)]);
    if head.trim_start().starts_with("solid") && head.contains("facet") {
        return Ok(ModelFormat::Stl);
    }
    match ext.as_str() {
        "obj" => Ok(ModelFormat::Obj),
        "ply" => Ok(ModelFormat::Ply),
        "stl" => Ok(ModelFormat::Stl),
        _ => Err(fail(format!(
            "not a model phong reads (OBJ .obj, PLY .ply, STL .stl, glTF .gltf/.glb){}",
            if ext.is_empty() {
                String::new()
            } else {
                format!("; .{ext} is not one of them")
            }
        ))),
    }
}

/// Reads the model at `path` in whichever format it is, adding every file read to `sources`
/// (the model and its MTL libraries).
pub fn load_model_sources(
    path: &Path,
    warnings: &mut Vec<String>,
    sources: &mut Vec<PathBuf>,
) -> Result<Vec<ModelPart>, Error> {
    load_model_full(path, warnings, sources).map(|m| m.parts)
}

/// [`load_model_sources`] with what a glTF file also holds (its camera and lights).
pub fn load_model_full(
    path: &Path,
    warnings: &mut Vec<String>,
    sources: &mut Vec<PathBuf>,
) -> Result<LoadedModel, Error> {
    let _budget = crate::texture_file::TextureBudget::start();
    let bytes = read_bounded(path, MAX_MODEL_BYTES, WHAT)?;
    if bytes.iter().all(u8::is_ascii_whitespace) {
        return Err(model_error(path, "an empty file: no model to render".into()));
    }
    sources.push(path.to_path_buf());
    let format = model_format(path, &bytes)?;
    if format == ModelFormat::Obj {
        return crate::timing::timed(
            |t| &mut t.parse,
            || {
                let text = decode_text(path, bytes, warnings);
                Ok(LoadedModel::new(obj_from_text(path, &text, warnings, sources)?, format))
            },
        );
    }
    // A glTF's external buffers, beside it (each added to `sources`).
    let dir = path.parent().unwrap_or(Path::new(""));
    let read = std::cell::RefCell::new(Vec::new());
    let moved = std::cell::RefCell::new(Vec::new());
    let resource = |uri: &str| -> Result<Vec<u8>, String> {
        let p = crate::read::found(dir, uri, true, path, &moved);
        read.borrow_mut().push(p.clone());
        read_bounded(&p, MAX_MODEL_BYTES, WHAT).map_err(|e| match e {
            Error::Read { source, .. } => format!("cannot read {}: {source}", p.display()),
            other => other.to_string(),
        })
    };
    let model = crate::timing::timed(
        |t| &mut t.parse,
        || read_bytes(path, &bytes, format, &resource, warnings),
    );
    warnings.extend(moved.into_inner());
    sources.extend(read.into_inner());
    model
}

/// A PLY, STL or glTF model of `format` from its bytes (`resource` reads a glTF's external
/// buffers).
fn read_bytes(
    path: &Path,
    bytes: &[u8],
    format: ModelFormat,
    resource: &dyn Fn(&str) -> Result<Vec<u8>, String>,
    warnings: &mut Vec<String>,
) -> Result<LoadedModel, Error> {
    match format {
        ModelFormat::Ply => Ok(LoadedModel::new(crate::ply::read_ply(path, bytes)?, format)),
        ModelFormat::Stl => Ok(LoadedModel::new(crate::stl::read_stl(path, bytes)?, format)),
        ModelFormat::Gltf => {
            let m = crate::gltf_model::read_gltf(path, bytes, resource, warnings)?;
            Ok(LoadedModel {
                parts: m.parts,
                camera: m.camera,
                lights: m.lights,
                double_sided: Some(m.double_sided),
                format,
                closed: Default::default(),
            })
        }
        ModelFormat::Obj => Err(model_error(
            path,
            "an OBJ is read with its MTL libraries, not here".into(),
        )),
    }
}

/// A PLY, STL or glTF model from its bytes (`path` names it and tells the format as
/// [`model_format`] does); an OBJ is refused here (its MTL libraries are files: use
/// [`load_model_sources`] or [`load_obj_text`](crate::load_obj_text)).
pub fn parse_mesh_bytes(path: &Path, bytes: &[u8]) -> Result<Vec<ModelPart>, Error> {
    parse_mesh_bytes_with(path, bytes, &|uri| Err(format!("{uri} is not available here")))
}

/// [`parse_mesh_bytes`], a glTF's external buffers read by `resource` (given their URI).
pub fn parse_mesh_bytes_with(
    path: &Path,
    bytes: &[u8],
    resource: &dyn Fn(&str) -> Result<Vec<u8>, String>,
) -> Result<Vec<ModelPart>, Error> {
    parse_model_bytes_with(path, bytes, resource).map(|m| m.parts)
}

/// [`parse_mesh_bytes_with`] with what a glTF file also holds (its camera, lights and
/// `doubleSided`), as [`load_model_full`] gives for a file.
pub fn parse_model_bytes_with(
    path: &Path,
    bytes: &[u8],
    resource: &dyn Fn(&str) -> Result<Vec<u8>, String>,
) -> Result<LoadedModel, Error> {
    let _budget = crate::texture_file::TextureBudget::start();
    read_bytes(path, bytes, model_format(path, bytes)?, resource, &mut Vec::new())
}

/// [`load_model_sources`] without the list of files read.
pub fn load_model(path: &Path, warnings: &mut Vec<String>) -> Result<Vec<ModelPart>, Error> {
    load_model_sources(path, warnings, &mut Vec::new())
}

/// The name of a model's one part: its file name.
pub(crate) fn part_name(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default()
}

pub(crate) fn model_error(path: &Path, message: String) -> Error {
    Error::Model {
        path: path.to_path_buf(),
        message,
    }
}

/// The material of a part whose vertex colours stand for its ambient and diffuse colours
/// (OpenGL's `GL_COLOR_MATERIAL` with `GL_AMBIENT_AND_DIFFUSE`): ambient and diffuse white
/// (the colour multiplies them), the rest OpenGL's default.
pub(crate) fn vertex_color_material() -> phong_core::Material {
    let white = phong_core::Color::WHITE;
    phong_core::Material::new(white, white, phong_core::Color::BLACK, phong_core::Color::BLACK, 0.0)
        .expect("valid colours")
}

/// Where a model with vertices `points` is re-centred: the centre of its bounding box where
/// that lies far from the origin for its size (more than 4 times its largest side: f32 would
/// lose its detail there), else the origin (a model near the origin keeps its coordinates
/// exactly).
pub(crate) fn far_origin(points: impl IntoIterator<Item = DVec3>) -> DVec3 {
    let (lo, hi) = points.into_iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(p), hi.max(p)),
    );
    if lo.x.partial_cmp(&hi.x).is_none_or(|o| o.is_gt()) {
        return DVec3::ZERO;
    }
    let (centre, extent) = ((lo + hi) * 0.5, (hi - lo).max_element());
    if centre.abs().max_element() > extent.max(f64::MIN_POSITIVE) * 4.0 {
        centre
    } else {
        DVec3::ZERO
    }
}

/// `points` as f32 positions relative to their [`far_origin`], and that origin.
pub(crate) fn recentred(points: &[DVec3]) -> (Vec<Vec3>, DVec3) {
    let origin = far_origin(points.iter().copied());
    (points.iter().map(|p| (*p - origin).as_vec3()).collect(), origin)
}
