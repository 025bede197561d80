//! Model files by format: OBJ with its MTL libraries (`obj.rs`), PLY (ply-rs) and STL
//! (stl_io). The format is told by the content where the content tells it (PLY's `ply` line,
//! glTF's magic, a binary STL's size, an ASCII STL's `solid`), else by the extension; anything
//! else is an error naming the formats phong reads.

use crate::obj::{decode_text, obj_from_text};
use crate::{Error, ObjPart, read_bounded};
use glam::{DVec3, Vec3};
use phong_core::Mesh;
use phong_core::limits::MAX_MODEL_BYTES;
use ply_rs::parser::Parser;
use ply_rs::ply::{Property, PropertyAccess};
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
    pub parts: Vec<ObjPart>,
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
    pub fn new(parts: Vec<ObjPart>, format: ModelFormat) -> LoadedModel {
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
) -> Result<Vec<ObjPart>, Error> {
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
        let text = decode_text(path, bytes, warnings);
        return Ok(LoadedModel::new(obj_from_text(path, &text, warnings, sources)?, format));
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
    let model = read_bytes(path, &bytes, format, &resource, warnings);
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
        ModelFormat::Ply => Ok(LoadedModel::new(read_ply(path, bytes)?, format)),
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
pub fn parse_mesh_bytes(path: &Path, bytes: &[u8]) -> Result<Vec<ObjPart>, Error> {
    parse_mesh_bytes_with(path, bytes, &|uri| Err(format!("{uri} is not available here")))
}

/// [`parse_mesh_bytes`], a glTF's external buffers read by `resource` (given their URI).
pub fn parse_mesh_bytes_with(
    path: &Path,
    bytes: &[u8],
    resource: &dyn Fn(&str) -> Result<Vec<u8>, String>,
) -> Result<Vec<ObjPart>, Error> {
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
pub fn load_model(path: &Path, warnings: &mut Vec<String>) -> Result<Vec<ObjPart>, Error> {
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

/// A PLY vertex: position and, where the file has all three, a normal and a colour (`red`,
/// `green`, `blue`, or `r`, `g`, `b`: bytes as 0–255, floats as 0–1, as scanners write them).
#[derive(Default)]
struct PlyVertex {
    p: [Option<f64>; 3],
    n: [Option<f64>; 3],
    c: [Option<f64>; 3],
}

/// A PLY colour channel in [0, 1]: integers of 8 bits over 255, of 16 over 65535, floats as
/// they are (clamped).
fn channel(p: &Property) -> Option<f64> {
    let v = match *p {
        Property::UChar(v) => f64::from(v) / 255.0,
        Property::Char(v) => f64::from(v) / 127.0,
        Property::UShort(v) => f64::from(v) / 65535.0,
        Property::Float(v) => f64::from(v),
        Property::Double(v) => v,
        _ => return None,
    };
    v.is_finite().then(|| v.clamp(0.0, 1.0))
}

fn scalar(p: &Property) -> Option<f64> {
    Some(match *p {
        Property::Char(v) => f64::from(v),
        Property::UChar(v) => f64::from(v),
        Property::Short(v) => f64::from(v),
        Property::UShort(v) => f64::from(v),
        Property::Int(v) => f64::from(v),
        Property::UInt(v) => f64::from(v),
        Property::Float(v) => f64::from(v),
        Property::Double(v) => v,
        _ => return None,
    })
}

impl PropertyAccess for PlyVertex {
    fn new() -> Self {
        PlyVertex::default()
    }
    fn set_property(&mut self, name: String, property: Property) {
        let slot = match name.as_str() {
            "x" => &mut self.p[0],
            "y" => &mut self.p[1],
            "z" => &mut self.p[2],
            "nx" => &mut self.n[0],
            "ny" => &mut self.n[1],
            "nz" => &mut self.n[2],
            "red" | "r" | "diffuse_red" => return self.c[0] = channel(&property),
            "green" | "g" | "diffuse_green" => return self.c[1] = channel(&property),
            "blue" | "b" | "diffuse_blue" => return self.c[2] = channel(&property),
            _ => return,
        };
        *slot = scalar(&property);
    }
}

/// A PLY face: its vertex indices (`vertex_indices` or `vertex_index`).
#[derive(Default)]
struct PlyFace(Option<Vec<i64>>);

impl PropertyAccess for PlyFace {
    fn new() -> Self {
        PlyFace::default()
    }
    fn set_property(&mut self, name: String, property: Property) {
        if name != "vertex_indices" && name != "vertex_index" {
            return;
        }
        self.0 = match property {
            Property::ListChar(v) => Some(v.into_iter().map(i64::from).collect()),
            Property::ListUChar(v) => Some(v.into_iter().map(i64::from).collect()),
            Property::ListShort(v) => Some(v.into_iter().map(i64::from).collect()),
            Property::ListUShort(v) => Some(v.into_iter().map(i64::from).collect()),
            Property::ListInt(v) => Some(v.into_iter().map(i64::from).collect()),
            Property::ListUInt(v) => Some(v.into_iter().map(i64::from).collect()),
            _ => None,
        };
    }
}

/// What ply-rs's header grammar panics on instead of refusing: a number in a header line past
/// `u64` (its `uint` rule unwraps the parse). The header is its lines up to the one that is
/// `end_header` (as ply-rs reads them: a line merely containing the word goes on).
fn check_ply_header(bytes: &[u8]) -> Result<(), String> {
    for (i, line) in bytes.split(|&b| b == b'\n').enumerate() {
        let line = String::from_utf8_lossy(line);
        if line.trim() == "end_header" {
            break;
        }
        for run in line.split(|c: char| !c.is_ascii_digit()).filter(|r| !r.is_empty()) {
            if run.parse::<u64>().is_err() {
                return Err(format!("header line {}: the number {run} is too large", i + 1));
            }
        }
    }
    Ok(())
}

/// A PLY file's `vertex` and `face` elements as one part (polygons as fans; other elements
/// skipped).
fn read_ply(path: &Path, bytes: &[u8]) -> Result<Vec<ObjPart>, Error> {
    let fail = |m: String| model_error(path, format!("malformed PLY: {m}"));
    check_ply_header(bytes).map_err(fail)?;
    let mut reader = std::io::BufReader::new(bytes);
    let header = Parser::<PlyVertex>::new()
        .read_header(&mut reader)
        .map_err(|e| fail(e.to_string()))?;
    let (mut vertices, mut faces) = (Vec::new(), Vec::new());
    for (name, element) in &header.elements {
        match name.as_str() {
            "vertex" => {
                vertices = Parser::<PlyVertex>::new()
                    .read_payload_for_element(&mut reader, element, &header)
                    .map_err(|e| fail(format!("element vertex: {e}")))?;
            }
            "face" => {
                faces = Parser::<PlyFace>::new()
                    .read_payload_for_element(&mut reader, element, &header)
                    .map_err(|e| fail(format!("element face: {e}")))?;
            }
            other => {
                // Read past it (edges, materials, a scanner's extras).
                Parser::<ply_rs::ply::DefaultElement>::new()
                    .read_payload_for_element(&mut reader, element, &header)
                    .map_err(|e| fail(format!("element {other}: {e}")))?;
            }
        }
    }
    let mut points = Vec::with_capacity(vertices.len());
    let mut normals = Vec::with_capacity(vertices.len());
    let mut has_normals = !vertices.is_empty();
    // Colours where every vertex has them.
    let colors: Vec<phong_core::Color> = vertices
        .iter()
        .map(|v| match v.c {
            [Some(r), Some(g), Some(b)] => Some(phong_core::Color::new(r as f32, g as f32, b as f32)),
            _ => None,
        })
        .collect::<Option<Vec<_>>>()
        .unwrap_or_default();
    for (i, v) in vertices.iter().enumerate() {
        let [Some(x), Some(y), Some(z)] = v.p else {
            return Err(fail(format!("vertex {i} has no x, y and z")));
        };
        let p = DVec3::new(x, y, z);
        if !p.as_vec3().is_finite() {
            return Err(fail(format!("vertex {i} is not finite in f32: {p}")));
        }
        points.push(p);
        match v.n {
            [Some(x), Some(y), Some(z)] => normals.push(Vec3::new(x as f32, y as f32, z as f32).normalize_or_zero()),
            _ => {
                has_normals = false;
                normals.push(Vec3::ZERO);
            }
        }
    }
    let (positions, origin) = recentred(&points);
    let n = positions.len() as i64;
    let mut triangles = Vec::new();
    let mut corners = Vec::new();
    for (k, f) in faces.iter().enumerate() {
        let idx =
            f.0.as_deref()
                .ok_or_else(|| fail(format!("face {k} has no vertex_indices")))?;
        if let Some(bad) = idx.iter().find(|&&i| i < 0 || i >= n) {
            return Err(fail(format!(
                "face {k}: vertex index {bad} is out of range ({n} vertices)"
            )));
        }
        corners.clear();
        corners.extend(idx.iter().map(|&i| positions[i as usize]));
        triangles.extend(
            crate::polygon::triangulate(&corners)
                .into_iter()
                .map(|t| t.map(|k| idx[k as usize] as u32)),
        );
    }
    if triangles.is_empty() {
        return Err(model_error(
            path,
            format!(
                "no faces: a point cloud of {} points, nothing to render",
                positions.len()
            ),
        ));
    }
    if !has_normals {
        normals = vec![Vec3::ZERO; positions.len()];
    }
    let mesh = Mesh::new(positions, normals, triangles)
        .and_then(|m| m.with_colors(colors))
        .map_err(|e| fail(e.to_string()))?;
    // With colours, a white material: they are the ambient and diffuse colours.
    let material = (!mesh.colors().is_empty()).then(vertex_color_material);
    Ok(vec![ObjPart {
        name: part_name(path),
        mesh,
        material,
        maps: phong_core::Maps::default(),
        has_normals,
        origin,
    }])
}

/// The material of a part whose vertex colours stand for its ambient and diffuse colours
/// (OpenGL's `GL_COLOR_MATERIAL` with `GL_AMBIENT_AND_DIFFUSE`): ambient and diffuse white
/// (the colour multiplies them), the rest OpenGL's default.
pub(crate) fn vertex_color_material() -> phong_core::Material {
    let white = phong_core::Color::WHITE;
    phong_core::Material::new(white, white, phong_core::Color::BLACK, phong_core::Color::BLACK, 0.0)
        .expect("valid colours")
}

/// An STL file (ASCII or binary) as one part, its vertices shared where they are equal
/// (stl_io's indexing); the facets' normals are not used (the scene's `normals` choice makes
/// them).
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
