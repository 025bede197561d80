//! What to render: the source, and the settings the user gives over it.

use crate::{Error, Models};
use phong_scene::{JsonError, Loaded, MeshLookup, ModelOptions, ModelPart, Overrides};
use serde_json::{Map, Value};
use std::cell::RefCell;
use std::path::{Path, PathBuf};

/// Where a scene comes from.
#[derive(Clone, Copy)]
pub enum Source<'a> {
    /// A scene file (`.toml`) or a model file (OBJ, glTF, PLY, STL: framed as `phong render
    /// MODEL` frames it), as `phong render` reads it.
    Path(&'a Path),
    /// A scene document: the scene file's schema as JSON. Its relative mesh and texture paths
    /// are taken from `anchor`'s folder; its meshes come from `meshes` where given.
    Document {
        /// The document.
        scene: &'a Value,
        /// The file the document stands for (its name in messages, its folder for paths).
        anchor: &'a Path,
        /// Meshes by the name an object's `mesh` key gives (models held in memory).
        meshes: Option<&'a MeshLookup<'a>>,
    },
}

/// What the user sets over the scene (each `None` or empty keeps the scene's).
#[derive(Clone, Debug, Default)]
pub struct Settings {
    /// Image width in pixels.
    pub width: Option<u32>,
    /// Image height in pixels.
    pub height: Option<u32>,
    /// Samples per pixel.
    pub samples: Option<phong_core::Samples>,
    /// Model, interpolation and output term for every object.
    pub overrides: Overrides,
    /// How a model alone is viewed (its `aspect` is set from the width and height).
    pub view: ModelOptions,
    /// Scene tables merged over the scene ([`merge_tables`]).
    pub tables: Map<String, Value>,
}

/// Loads `source` with `settings` applied, its models through `models`. `size_names` names
/// the width, height and samples in the message of an image they make invalid (`--width,
/// --height, --antialias`).
pub fn load(source: Source, settings: &Settings, models: &Models, size_names: &str) -> Result<Loaded, Error> {
    let default = phong_core::ImageSettings::default();
    let mut view = settings.view;
    if settings.width.is_some() || settings.height.is_some() {
        view.aspect =
            Some(settings.width.unwrap_or(default.width) as f32 / settings.height.unwrap_or(default.height) as f32);
    }
    let mut loaded = match source {
        Source::Path(path) if phong_scene::is_model_path(path) => load_model(path, settings, &view, models)?,
        Source::Path(path) => load_scene_file(path, settings, &view, models)?,
        Source::Document { scene, anchor, meshes } => {
            let mut doc = scene.clone();
            merge_tables(&mut doc, &settings.tables).map_err(|e| json_error(anchor, e))?;
            parse_document(&doc, anchor, meshes, models)?
        }
    };
    let scene = &mut loaded.scene;
    if let Some(w) = settings.width {
        scene.image.width = w;
    }
    if let Some(h) = settings.height {
        scene.image.height = h;
    }
    if let Some(s) = settings.samples {
        scene.image.samples = s;
    }
    if settings.width.is_some() || settings.height.is_some() || settings.samples.is_some() {
        scene
            .image
            .check()
            .map_err(|e| Error::Input(format!("{size_names}: {e}")))?;
    }
    settings.overrides.apply_to_scene(scene);
    Ok(loaded)
}

/// [`load`] for many views of few scenes (`phong batch`): a model file's or a document's
/// objects built once through `built` while only its camera, lights or image change. The same
/// scene as [`load`] gives; a scene file is read as [`load`] reads it.
pub fn load_viewed(
    source: Source,
    settings: &Settings,
    models: &Models,
    built: &crate::Built,
    size_names: &str,
) -> Result<Loaded, Error> {
    let default = phong_core::ImageSettings::default();
    let mut view = settings.view;
    if settings.width.is_some() || settings.height.is_some() {
        view.aspect =
            Some(settings.width.unwrap_or(default.width) as f32 / settings.height.unwrap_or(default.height) as f32);
    }
    let loaded = |scene, warnings, sources| Loaded {
        scene,
        warnings,
        sources,
        notes: Vec::new(),
        textures: Default::default(),
        times: Default::default(),
    };
    match source {
        Source::Path(path) if phong_scene::is_model_path(path) => {
            let (read, fresh) = models.get(path)?;
            let name = path
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default();
            let (doc, _) = phong_scene::model_scene(&name, &read, &view);
            let parts = &read.parts;
            let lookup = |_: &str| Ok(parts.clone());
            let scene = built.load(&doc, path, Some(&lookup), settings, models)?;
            let warnings = if fresh { read.warnings.clone() } else { Vec::new() };
            Ok(loaded(scene, warnings, read.sources.clone()))
        }
        Source::Document { scene, anchor, meshes } => {
            let scene = built.load(scene, anchor, meshes, settings, models)?;
            Ok(loaded(scene, Vec::new(), Vec::new()))
        }
        _ => load(source, settings, models, size_names),
    }
}

fn json_error(anchor: &Path, error: JsonError) -> Error {
    Error::Json {
        what: anchor.display().to_string(),
        error,
    }
}

/// A model file alone, read through `models`.
fn load_model(path: &Path, settings: &Settings, view: &ModelOptions, models: &Models) -> Result<Loaded, Error> {
    if settings.tables.is_empty() && !models.caches() {
        // The one-off render: exactly `phong render MODEL` (with its texture statistics).
        return Ok(phong_scene::load_with(path, view)?);
    }
    let (read, fresh) = models.get(path)?;
    let mut loaded = framed(path, &read, settings, view)?;
    if fresh {
        let mut w = read.warnings.clone();
        w.append(&mut loaded.warnings);
        loaded.warnings = w;
    }
    loaded.sources = read.sources.clone();
    Ok(loaded)
}

/// A model read from `path`, framed for `view`, `settings.tables` merged over its scene.
fn framed(
    path: &Path,
    model: &phong_scene::ModelFile,
    settings: &Settings,
    view: &ModelOptions,
) -> Result<Loaded, Error> {
    if settings.tables.is_empty() {
        return Ok(phong_scene::scene_of_model(path, model, view)?);
    }
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let (mut doc, notes) = phong_scene::model_scene(&name, model, view);
    merge_tables(&mut doc, &settings.tables).map_err(|e| json_error(path, e))?;
    let parts = &model.parts;
    let lookup = |_: &str| Ok(parts.clone());
    let mut loaded = phong_scene::parse_scene_json_at(&doc, path, Some(&lookup)).map_err(|e| json_error(path, e))?;
    loaded.notes = notes;
    Ok(loaded)
}

/// A scene file: as `phong render` reads it where nothing is cached or merged, else as its
/// document, its meshes through `models`.
fn load_scene_file(path: &Path, settings: &Settings, view: &ModelOptions, models: &Models) -> Result<Loaded, Error> {
    if settings.tables.is_empty() && !models.caches() {
        return Ok(phong_scene::load_with(path, view)?);
    }
    let src = phong_scene::read_text(
        path,
        phong_core::limits::MAX_SCENE_BYTES,
        "scene file (MAX_SCENE_BYTES)",
    )?;
    if settings.tables.is_empty() {
        let (lookup, found) = file_lookup(path, models);
        let mut loaded = phong_scene::parse_scene_from(&src, path, Some(&lookup), true)?;
        found.add_to(&mut loaded);
        return Ok(loaded);
    }
    let mut doc = phong_scene::toml_to_json(&src, path)?;
    merge_tables(&mut doc, &settings.tables).map_err(|e| json_error(path, e))?;
    let mut loaded = parse_document(&doc, path, None, models)?;
    loaded.sources.insert(0, path.to_path_buf());
    Ok(loaded)
}

/// A document's scene, its meshes from `meshes`, else files read through `models`.
fn parse_document(doc: &Value, anchor: &Path, meshes: Option<&MeshLookup>, models: &Models) -> Result<Loaded, Error> {
    if let Some(m) = meshes {
        return phong_scene::parse_scene_json_at(doc, anchor, Some(m)).map_err(|e| json_error(anchor, e));
    }
    let (lookup, found) = file_lookup(anchor, models);
    let mut loaded = phong_scene::parse_scene_json_at(doc, anchor, Some(&lookup)).map_err(|e| json_error(anchor, e))?;
    found.add_to(&mut loaded);
    Ok(loaded)
}

/// What a file lookup met: warnings and files read.
#[derive(Default)]
struct Found {
    warnings: RefCell<Vec<String>>,
    sources: RefCell<Vec<PathBuf>>,
}

impl Found {
    fn add_to(&self, loaded: &mut Loaded) {
        loaded.warnings.extend(self.warnings.take());
        loaded.sources.extend(self.sources.take());
    }
}

/// A mesh lookup that reads `name` relative to `anchor`'s folder through `models`, with the
/// messages the scene reader gives for files it reads itself.
fn file_lookup<'a>(
    anchor: &'a Path,
    models: &'a Models,
) -> (impl Fn(&str) -> Result<Vec<ModelPart>, String> + 'a, std::rc::Rc<Found>) {
    let found = std::rc::Rc::new(Found::default());
    let f = found.clone();
    let lookup = move |name: &str| {
        let file = anchor.parent().unwrap_or(Path::new("")).join(name);
        if !file.exists() {
            return Err(format!("file not found: {}", file.display()));
        }
        let (read, fresh) = models.get(&file).map_err(|e| e.to_string())?;
        if fresh {
            f.warnings.borrow_mut().extend(read.warnings.iter().cloned());
        }
        f.sources.borrow_mut().extend(read.sources.iter().cloned());
        Ok(read.parts.clone())
    };
    (lookup, found)
}

/// How a model alone is viewed, from values a caller has read: `up` and `view` by name,
/// `camera` as `[px, py, pz, tx, ty, tz]`, `two_sided` (`false`: cull). `key` names a value in
/// messages as the caller's user knows it (`` `camera` ``, `camera`).
pub fn view_options(
    up: Option<&str>,
    view: Option<&str>,
    camera: Option<[f64; 6]>,
    two_sided: Option<bool>,
    key: impl Fn(&str) -> String,
) -> Result<ModelOptions, String> {
    let camera = match camera {
        None => None,
        Some(c) if !c.iter().all(|x| x.is_finite()) => {
            return Err(format!(
                "{}: must be [px, py, pz, tx, ty, tz] (position, target), six finite numbers, got {c:?}",
                key("camera")
            ));
        }
        Some(c) if c[..3] == c[3..] => {
            return Err(format!(
                "{}: the position and the target are the same point",
                key("camera")
            ));
        }
        Some(c) => Some((glam::DVec3::new(c[0], c[1], c[2]), glam::DVec3::new(c[3], c[4], c[5]))),
    };
    Ok(ModelOptions {
        up: up
            .map(|v| phong_scene::parse_choice(&key("up"), v, &phong_scene::Axis::NAMES))
            .transpose()?,
        view: view
            .map(|v| phong_scene::parse_choice(&key("view"), v, &phong_scene::ViewName::NAMES))
            .transpose()?,
        camera,
        sides: two_sided.map(|t| {
            if t {
                phong_scene::Sides::TwoSided
            } else {
                phong_scene::Sides::Cull
            }
        }),
        aspect: None,
    })
}

/// Merges scene tables over a scene document, as the command line's flags override a scene:
/// `image`, `camera` and `shading` key by key; `light` (an array of lights, or one) replaces
/// the lights; `material` (a material's name or table) is every object's material, a table
/// merged over an object's own table, or over its named material (as `base`).
pub fn merge_tables(doc: &mut Value, tables: &Map<String, Value>) -> Result<(), JsonError> {
    let err = |path: &str, message: &str| JsonError {
        path: path.to_string(),
        message: message.to_string(),
    };
    let Value::Object(root) = doc else {
        return Err(err("", "a scene is a JSON object"));
    };
    for (k, v) in tables {
        match k.as_str() {
            "image" | "camera" | "shading" => {
                let Value::Object(over) = v else {
                    return Err(err(k, "must be a table (a JSON object)"));
                };
                let table = root.entry(k.clone()).or_insert_with(|| Value::Object(Map::new()));
                let Value::Object(table) = table else {
                    return Err(err(k, "the scene's own value is not a table"));
                };
                for (key, value) in over {
                    table.insert(key.clone(), value.clone());
                }
            }
            "light" => {
                let lights = match v {
                    Value::Array(_) => v.clone(),
                    Value::Object(_) => Value::Array(vec![v.clone()]),
                    _ => return Err(err(k, "must be a light (a table) or an array of lights")),
                };
                root.insert("light".into(), lights);
            }
            "material" => {
                if !matches!(v, Value::String(_) | Value::Object(_)) {
                    return Err(err(k, "must be a material's name or a material table"));
                }
                let Some(Value::Array(objects)) = root.get_mut("object") else {
                    continue;
                };
                for o in objects.iter_mut().filter_map(Value::as_object_mut) {
                    let merged = match (o.get("material"), v) {
                        (Some(Value::Object(own)), Value::Object(over)) => {
                            let mut m = own.clone();
                            m.extend(over.iter().map(|(a, b)| (a.clone(), b.clone())));
                            Value::Object(m)
                        }
                        (Some(Value::String(name)), Value::Object(over)) if !over.contains_key("base") => {
                            let mut m = over.clone();
                            m.insert("base".into(), Value::String(name.clone()));
                            Value::Object(m)
                        }
                        _ => v.clone(),
                    };
                    o.insert("material".into(), merged);
                }
            }
            _ => {
                return Err(err(
                    k,
                    "not a table that can be merged over a scene (image, camera, shading, light, material)",
                ));
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn merged(doc: Value, tables: Value) -> Value {
        let mut doc = doc;
        merge_tables(&mut doc, tables.as_object().expect("an object")).expect("merged");
        doc
    }

    #[test]
    fn tables_merge_key_by_key_and_lights_replace() {
        let doc = json!({"shading": {"model": "phong", "ambient": [0.1, 0.1, 0.1]},
                         "light": [{"type": "point", "position": [0, 1, 0]}]});
        let out = merged(
            doc,
            json!({"shading": {"model": "lambert"}, "camera": {"fov": 30},
                   "light": {"type": "directional", "direction": [0, -1, 0]}}),
        );
        assert_eq!(
            out,
            json!({"shading": {"model": "lambert", "ambient": [0.1, 0.1, 0.1]}, "camera": {"fov": 30},
                   "light": [{"type": "directional", "direction": [0, -1, 0]}]})
        );
    }

    #[test]
    fn a_material_table_merges_over_each_objects_material() {
        let doc = json!({"object": [
            {"shape": "sphere", "material": "gold"},
            {"shape": "cube", "material": {"diffuse": [1, 0, 0], "shininess": 8}},
            {"shape": "torus"},
        ]});
        let out = merged(doc, json!({"material": {"shininess": 64}}));
        assert_eq!(
            out["object"],
            json!([
                {"shape": "sphere", "material": {"base": "gold", "shininess": 64}},
                {"shape": "cube", "material": {"diffuse": [1, 0, 0], "shininess": 64}},
                {"shape": "torus", "material": {"shininess": 64}},
            ])
        );
        let named = merged(
            json!({"object": [{"shape": "sphere", "material": "gold"}]}),
            json!({"material": "jade"}),
        );
        assert_eq!(named["object"][0]["material"], json!("jade"));
    }

    /// A scene file read as its document, or with its meshes through the model cache, is the
    /// scene `phong render` reads: textures included.
    #[test]
    fn a_scene_read_through_the_cache_or_as_a_document_is_the_files() {
        let p = Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../examples/scenes/textures.toml"
        ));
        let src = std::fs::read_to_string(p).expect("textures.toml");
        let doc = phong_scene::toml_to_json(&src, p).expect("its document");
        let file = phong_scene::load(p).expect("the file").scene;
        assert!(file.objects.iter().any(|o| o.maps.diffuse.is_some()));
        let models = Models::keep_all();
        let document = Source::Document {
            scene: &doc,
            anchor: p,
            meshes: None,
        };
        for source in [document, Source::Path(p)] {
            let loaded = load(source, &Settings::default(), &models, "").expect("loaded");
            assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
            assert_eq!(format!("{:?}", loaded.scene), format!("{file:?}"));
        }
    }

    #[test]
    fn other_tables_are_refused_by_name() {
        let mut doc = json!({});
        let e = merge_tables(&mut doc, json!({"objects": {}}).as_object().expect("object")).expect_err("refused");
        assert_eq!(e.path, "objects");
        let e = merge_tables(&mut doc, json!({"shading": 3}).as_object().expect("object")).expect_err("refused");
        assert_eq!(
            (e.path.as_str(), e.message.as_str()),
            ("shading", "must be a table (a JSON object)")
        );
    }
}
