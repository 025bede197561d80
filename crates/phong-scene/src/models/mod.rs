//! Model files, a reader a format behind one door: [`ModelFile::read`] for a file on disk,
//! [`ModelFile::from_bytes`] for bytes whose companion files (an OBJ's MTL libraries, a glTF's
//! buffers, texture images) a function gives. Each reader (`obj/`, `ply.rs`, `stl.rs`,
//! `gltf/`) returns [`ModelPart`]s. The format is told by the content where the content tells
//! it (PLY's `ply` line, glTF's magic, a binary STL's size, an ASCII STL's `solid`), else by
//! the extension; anything else is an error naming the formats phong reads.

mod gltf;
mod obj;
mod part;
mod ply;
mod polygon;
mod stl;

pub use gltf::{FileCamera, FileLight};
pub(crate) use obj::decode_text;
pub use part::ModelPart;
pub(crate) use part::{far_origin, model_error, part_name, recentred, vertex_color_material};

use crate::{Error, read_bounded};
use phong_core::limits::MAX_MODEL_BYTES;
use std::path::{Path, PathBuf};

const WHAT: &str = "model (MAX_MODEL_BYTES)";

/// A companion file of a model given its name as the model writes it (an OBJ's MTL library or
/// texture image, a glTF's buffer or image): its bytes, or why there are none.
pub type Resource<'a> = &'a dyn Fn(&str) -> Result<Vec<u8>, String>;

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

impl ModelFormat {
    /// The format of model `path` whose bytes are `bytes`; an error for what is none of them.
    pub fn detect(path: &Path, bytes: &[u8]) -> Result<ModelFormat, Error> {
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
}

/// A model file read: its parts and what the file also says (a glTF's camera, lights and
/// sides), with the warnings met and the files read.
#[derive(Clone, Debug)]
pub struct ModelFile {
    /// The parts (a group and material each).
    pub parts: Vec<ModelPart>,
    /// The file's camera (glTF).
    pub camera: Option<FileCamera>,
    /// The file's lights (glTF's KHR_lights_punctual).
    pub lights: Vec<FileLight>,
    /// Whether the file says which faces are drawn (glTF: `Some(true)` where a material is
    /// double-sided, `Some(false)` where none is); `None` for formats that do not say.
    pub double_sided: Option<bool>,
    /// Its format.
    pub format: ModelFormat,
    /// What the user should know of the file (an unsupported MTL `illum`, a texture not
    /// found, a Latin-1 text, ...).
    pub warnings: Vec<String>,
    /// Every file read: the model, then its MTL libraries, buffers and images.
    pub sources: Vec<PathBuf>,
    /// Whether it is closed and how it is wound, found when it is first framed.
    pub(crate) closed: std::sync::OnceLock<crate::framing::Closed>,
    /// The sums over its facets that its framing reads, found when it is first framed.
    pub(crate) facets: std::sync::OnceLock<crate::framing::Facets>,
    /// Its vertices in the fitted frame, which every view's framing reads, found when it is
    /// first framed.
    pub(crate) fitted: std::sync::OnceLock<crate::framing::Fitted>,
}

impl ModelFile {
    /// Reads the model at `path`, whichever format it is, its companion files beside it.
    pub fn read(path: &Path) -> Result<ModelFile, Error> {
        let _budget = crate::texture_file::TextureBudget::start();
        let bytes = read_bounded(path, MAX_MODEL_BYTES, WHAT)?;
        if bytes.iter().all(u8::is_ascii_whitespace) {
            return Err(model_error(path, "an empty file: no model to render".into()));
        }
        let format = ModelFormat::detect(path, &bytes)?;
        let mut warnings = Vec::new();
        let mut sources = vec![path.to_path_buf()];
        let mut model = if format == ModelFormat::Obj {
            crate::timing::timed(
                |t| &mut t.parse,
                || {
                    let text = decode_text(path, bytes, &mut warnings);
                    let parts = obj::obj_from_text(path, &text, &mut warnings, &mut sources)?;
                    Ok(ModelFile::of(parts, format))
                },
            )?
        } else {
            // A glTF's external buffers and images, beside it (each added to `sources`).
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
                || binary(path, &bytes, format, &resource, &mut warnings),
            );
            warnings.extend(moved.into_inner());
            sources.extend(read.into_inner());
            model?
        };
        model.warnings = warnings;
        model.sources = sources;
        Ok(model)
    }

    /// The model whose bytes are `bytes` (`path` names it in messages and tells the format as
    /// [`ModelFormat::detect`] does), its companion files given by `resource`: an OBJ's MTL
    /// libraries and images, a glTF's buffers and images (an MTL library `resource` cannot
    /// give is a warning, its faces the default material, as for a file). `sources` is empty.
    pub fn from_bytes(path: &Path, bytes: &[u8], resource: Resource) -> Result<ModelFile, Error> {
        let _budget = crate::texture_file::TextureBudget::start();
        let format = ModelFormat::detect(path, bytes)?;
        let mut warnings = Vec::new();
        let mut model = if format == ModelFormat::Obj {
            let text = decode_text(path, bytes.to_vec(), &mut warnings);
            let read_mtl = |mtl: &Path| -> std::io::Result<String> {
                let bytes = resource(&mtl.to_string_lossy())
                    .map_err(|e| std::io::Error::new(std::io::ErrorKind::NotFound, e))?;
                Ok(decode_text(mtl, bytes, &mut Vec::new()))
            };
            ModelFile::of(
                obj::load_obj_text(path, &text, &read_mtl, resource, &mut warnings)?,
                format,
            )
        } else {
            binary(path, bytes, format, resource, &mut warnings)?
        };
        model.warnings = warnings;
        Ok(model)
    }

    /// A model of `parts` made elsewhere (a mesh given as arrays), framed as an OBJ is.
    pub fn from_parts(parts: Vec<ModelPart>) -> ModelFile {
        ModelFile::of(parts, ModelFormat::Obj)
    }

    /// A model whose file says nothing of a camera, lights or which faces are drawn.
    fn of(parts: Vec<ModelPart>, format: ModelFormat) -> ModelFile {
        ModelFile {
            parts,
            camera: None,
            lights: Vec::new(),
            double_sided: None,
            format,
            warnings: Vec::new(),
            sources: Vec::new(),
            closed: Default::default(),
            facets: Default::default(),
            fitted: Default::default(),
        }
    }
}

/// A PLY, STL or glTF model of `format` from its bytes (`resource` reads a glTF's external
/// buffers and images).
fn binary(
    path: &Path,
    bytes: &[u8],
    format: ModelFormat,
    resource: Resource,
    warnings: &mut Vec<String>,
) -> Result<ModelFile, Error> {
    match format {
        ModelFormat::Ply => Ok(ModelFile::of(ply::read_ply(path, bytes)?, format)),
        ModelFormat::Stl => Ok(ModelFile::of(stl::read_stl(path, bytes)?, format)),
        ModelFormat::Gltf => {
            let m = gltf::read_gltf(path, bytes, resource, warnings)?;
            Ok(ModelFile {
                camera: m.camera,
                lights: m.lights,
                double_sided: Some(m.double_sided),
                ..ModelFile::of(m.parts, format)
            })
        }
        ModelFormat::Obj => Err(model_error(path, "an OBJ is read as text, not here".into())),
    }
}
