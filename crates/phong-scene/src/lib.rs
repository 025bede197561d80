//! # phong-scene
//!
//! Scene files (TOML), OBJ/MTL import and PNG output: everything between a
//! file on disk and a [`phong_core::Scene`], and between an
//! [`Image`](phong_core::Image) and a PNG.
//!
//! Every error names the file, and for parse and validation errors the line,
//! column and key (`scene.toml:12:13: \`shininess\`: must be >= 0, got -1`).

mod beside;
mod error;
mod framing;
mod json_scene;
mod models;
mod overrides;
mod png_out;
mod read;
mod texture_file;
mod texture_store;
mod timing;
mod toml_scene;

pub use error::Error;
pub use framing::{Axis, ModelOptions, Sides, ViewName, model_scene, scene_of_model};
pub use json_scene::{JsonError, TomlText, json_to_toml, parse_scene_json, parse_scene_json_at, toml_to_json};
pub use models::{FileCamera, FileLight, ModelFile, ModelFormat, ModelPart, Resource};
pub use overrides::Overrides;
pub use png_out::{encode_png, encode_png8, encode_rgba8, is_complete_png, write_file, write_png, write_png8};
pub use read::{read_bounded, read_text};
pub use texture_file::{TextureStats, decode as decode_texture, last_store_error};
pub use texture_store::{TextureStore, set_texture_store, texture_store};
pub use timing::LoadTimes;
pub use toml_scene::{
    INTERPOLATIONS, MODELS, MeshLookup, Model, OUTPUTS, apply_model, parse_choice, parse_scene, parse_scene_from,
    parse_scene_with,
};

use std::path::Path;

/// A loaded scene and the warnings met on the way (unsupported MTL `illum`, ...).
#[derive(Debug)]
pub struct Loaded {
    /// The scene.
    pub scene: phong_core::Scene,
    /// Warnings for the user.
    pub warnings: Vec<String>,
    /// Every file read (the scene, its models and their MTL libraries), so that an output can
    /// be checked not to be one of them.
    pub sources: Vec<std::path::PathBuf>,
    /// What was decided for the user's information (`-v`): a model alone's up axis, culling,
    /// re-centring.
    pub notes: Vec<String>,
    /// The texture images read, and what they cost (`-v`).
    pub textures: TextureStats,
    /// Where the load's time went (`-v`).
    pub times: LoadTimes,
}

/// Loads a scene file (`.toml`) or a model (`.obj`, `.ply`, `.stl`, framed by a default camera
/// and lights). A file of another extension is a model where its content says so (a PLY or
/// STL), else a scene file.
pub fn load(path: &Path) -> Result<Loaded, Error> {
    load_with(path, &ModelOptions::default())
}

/// Extensions of mesh formats phong does not read (OFF, as ModelNet's, COLLADA, FBX, USD, ...).
const FOREIGN_MODELS: [&str; 20] = [
    "off", "coff", "noff", "dae", "fbx", "3ds", "blend", "usd", "usda", "usdc", "usdz", "x3d", "wrl", "vrml", "3mf",
    "amf", "abc", "ifc", "lwo", "ms3d",
];

/// Whether `path` is read as a model rather than a scene file (its extension, else its first
/// bytes).
pub fn is_model_path(path: &Path) -> bool {
    let ext = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase());
    match ext.as_deref() {
        Some("toml") => false,
        Some("obj" | "ply" | "stl" | "gltf" | "glb") => true,
        // Other formats of meshes: the model reader names the formats phong reads (as a scene,
        // such a file would give a TOML syntax error).
        Some(e) if FOREIGN_MODELS.contains(&e) => true,
        _ => sniff_model(path),
    }
}

/// [`load`], a model alone viewed as `options` says (a scene file ignores them).
pub fn load_with(path: &Path, options: &ModelOptions) -> Result<Loaded, Error> {
    let _budget = texture_file::TextureBudget::start();
    texture_file::take_stats();
    timing::take_times();
    let mut loaded = load_without_stats(path, options)?;
    loaded.textures = texture_file::take_stats();
    loaded.times = timing::take_times();
    Ok(loaded)
}

fn load_without_stats(path: &Path, options: &ModelOptions) -> Result<Loaded, Error> {
    if is_model_path(path) {
        framing::scene_for_model(path, options)
    } else {
        let src = read_text(
            path,
            phong_core::limits::MAX_SCENE_BYTES,
            "scene file (MAX_SCENE_BYTES)",
        )?;
        let mut loaded = parse_scene(&src, path)?;
        loaded.sources.insert(0, path.to_path_buf());
        Ok(loaded)
    }
}

/// Whether the file at `path` begins as a PLY, STL or glTF model does (the first bytes of a
/// regular file; anything unreadable is left to the scene reader's message).
fn sniff_model(path: &Path) -> bool {
    use std::io::Read;
    if !std::fs::metadata(path).is_ok_and(|m| m.is_file()) {
        return false;
    }
    let mut head = Vec::new();
    let read = std::fs::File::open(path).and_then(|f| f.take(1024).read_to_end(&mut head));
    read.is_ok()
        && (head.starts_with(b"ply\n")
            || head.starts_with(b"ply\r\n")
            || head.starts_with(b"glTF")
            || String::from_utf8_lossy(&head).trim_start().starts_with("solid"))
}
