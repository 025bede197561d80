//! `SceneCore`: a scene as its document (the scene file's schema as JSON), where its relative
//! paths are taken from, and the model it frames when it came from a model file or arrays.
//! Immutable: an edit makes a new core (validated), which shares the built-scene cache.

use crate::{InputError, guarded, py_err};
use numpy::PyReadonlyArray2;
use phong_run::{Models, Settings, Source};
use phong_scene::{ModelFile, ModelOptions};
use pyo3::prelude::*;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// A model held in memory, and how it is viewed.
pub(crate) struct Backing {
    pub model: ModelFile,
}

/// A model's automatic cameras.
#[derive(Default)]
pub(crate) struct Cache {
    /// A model's automatic camera per view and image aspect (its bits).
    pub framings: Vec<(ModelOptions, u32, Value)>,
}

/// A scene: its document, its anchor and what it is built from.
#[pyclass(module = "phong._phong", frozen)]
#[derive(Clone)]
pub struct SceneCore {
    pub(crate) doc: Arc<Value>,
    pub(crate) anchor: PathBuf,
    pub(crate) backing: Option<Arc<Backing>>,
    pub(crate) view: ModelOptions,
    /// The camera is the model's framing for each render's aspect (not set by the user).
    pub(crate) camera_auto: bool,
    pub(crate) models: Arc<Models>,
    pub(crate) cache: Arc<Mutex<Cache>>,
    /// The objects built, shared by the edits and views of one scene.
    pub(crate) built: Arc<phong_run::Built>,
}

fn parse_json(text: &str) -> PyResult<Value> {
    serde_json::from_str(text).map_err(|e| InputError::new_err(format!("not a JSON scene: {e}")))
}

/// How a model alone is viewed: the Python keyword arguments `up`, `view`, `camera` and
/// `two_sided`, passed as one dict.
#[derive(FromPyObject, Default)]
#[pyo3(from_item_all)]
pub(crate) struct ViewArgs {
    up: Option<String>,
    view: Option<String>,
    camera: Option<[f64; 6]>,
    two_sided: Option<bool>,
}

impl ViewArgs {
    /// Whether any is given.
    pub(crate) fn given(&self) -> bool {
        self.up.is_some() || self.view.is_some() || self.camera.is_some() || self.two_sided.is_some()
    }

    /// The scene reader's options.
    pub(crate) fn options(&self) -> PyResult<ModelOptions> {
        phong_run::view_options(
            self.up.as_deref(),
            self.view.as_deref(),
            self.camera,
            self.two_sided,
            str::to_string,
        )
        .map_err(InputError::new_err)
    }
}

impl SceneCore {
    fn new(doc: Value, anchor: PathBuf, backing: Option<Arc<Backing>>, view: ModelOptions) -> SceneCore {
        SceneCore {
            doc: Arc::new(doc),
            anchor,
            camera_auto: backing.is_some(),
            backing,
            view,
            models: Arc::new(Models::keep_all()),
            cache: Arc::default(),
            built: Arc::new(phong_run::Built::new(1)),
        }
    }

    /// A core for a model: its framing at the default aspect. `like` shares its built objects
    /// (another view of the same model).
    fn framed_model(
        path: &Path,
        backing: Arc<Backing>,
        view: ModelOptions,
        like: Option<&SceneCore>,
    ) -> PyResult<SceneCore> {
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let (doc, _) = phong_scene::model_scene(&name, &backing.model, &view);
        let mut core = SceneCore::new(doc, path.to_path_buf(), Some(backing), view);
        if let Some(like) = like {
            core.models = like.models.clone();
            core.built = like.built.clone();
            core.cache = like.cache.clone();
        }
        core.build(&Settings::default()).map_err(py_err)?;
        Ok(core)
    }

    /// The document as rendered at `aspect`: a model's automatic camera framed for it.
    pub(crate) fn doc_for(&self, aspect: Option<f32>) -> Value {
        let (Some(b), true, Some(aspect)) = (&self.backing, self.camera_auto, aspect) else {
            return (*self.doc).clone();
        };
        let mut cache = self.cache.lock().expect("not poisoned");
        let found = cache
            .framings
            .iter()
            .find(|(v, a, _)| *v == self.view && *a == aspect.to_bits());
        let camera = match found {
            Some((_, _, c)) => c.clone(),
            None => {
                let view = ModelOptions {
                    aspect: Some(aspect),
                    ..self.view
                };
                let (doc, _) = phong_scene::model_scene(&self.mesh_name(), &b.model, &view);
                let camera = doc["camera"].clone();
                if cache.framings.len() >= 8 {
                    cache.framings.remove(0);
                }
                cache.framings.push((self.view, aspect.to_bits(), camera.clone()));
                camera
            }
        };
        let mut doc = (*self.doc).clone();
        doc["camera"] = camera;
        doc
    }

    fn mesh_name(&self) -> String {
        self.anchor
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default()
    }

    /// The scene built with `settings`: its objects built once per document (less its
    /// camera, lights and image) and kept ([`phong_run::Built`]).
    pub(crate) fn build(&self, settings: &Settings) -> Result<phong_core::Scene, phong_run::Error> {
        let default = phong_core::ImageSettings::default();
        let aspect = (settings.width.is_some() || settings.height.is_some())
            .then(|| settings.width.unwrap_or(default.width) as f32 / settings.height.unwrap_or(default.height) as f32);
        let doc = self.doc_for(aspect.or(Some(4.0 / 3.0)).filter(|_| self.camera_auto));
        let name = self.mesh_name();
        let parts = self.backing.as_ref().map(|b| &b.model.parts);
        let lookup = |n: &str| match parts {
            Some(p) if n == name => Ok(p.clone()),
            _ => Err(format!("no model named {n:?} in this scene")),
        };
        let meshes = parts.map(|_| &lookup as &phong_scene::MeshLookup);
        self.built.load(&doc, &self.anchor, meshes, settings, &self.models)
    }
}

#[pymethods]
impl SceneCore {
    /// Loads a scene file or a model file (framed as `phong render MODEL` frames it).
    #[staticmethod]
    #[pyo3(signature = (path, view=None))]
    fn load(py: Python<'_>, path: PathBuf, view: Option<ViewArgs>) -> PyResult<SceneCore> {
        let view = view.unwrap_or_default();
        let options = view.options()?;
        py.detach(|| {
            guarded(|| {
                if phong_scene::is_model_path(&path) {
                    let model = phong_scene::ModelFile::read(&path).map_err(|e| py_err(e.into()))?;
                    return SceneCore::framed_model(&path, Arc::new(Backing { model }), options, None);
                }
                if view.given() {
                    return Err(InputError::new_err(format!(
                        "up, view, camera and two_sided apply to a model alone; {} is a scene file",
                        path.display()
                    )));
                }
                // Read as `phong render` reads it (its errors), then kept as its document.
                phong_run::load(Source::Path(&path), &Settings::default(), &Models::new(), "").map_err(py_err)?;
                let src = phong_scene::read_text(
                    &path,
                    phong_core::limits::MAX_SCENE_BYTES,
                    "scene file (MAX_SCENE_BYTES)",
                )
                .map_err(|e| py_err(e.into()))?;
                let doc = phong_scene::toml_to_json(&src, &path).map_err(|e| py_err(e.into()))?;
                Ok(SceneCore::new(doc, path, None, ModelOptions::default()))
            })
        })
    }

    /// A scene from its JSON document; relative paths from `base` (a folder).
    #[staticmethod]
    fn from_json(py: Python<'_>, text: &str, base: PathBuf) -> PyResult<SceneCore> {
        let doc = parse_json(text)?;
        py.detach(|| {
            guarded(|| {
                let core = SceneCore::new(doc, base.join("scene.json"), None, ModelOptions::default());
                core.build(&Settings::default()).map_err(py_err)?;
                Ok(core)
            })
        })
    }

    /// A model from arrays: `vertices` (N, 3), `faces` (M, 3), optional `normals` (N, 3) and
    /// `uvs` (N, 2), framed as a model file.
    #[staticmethod]
    #[pyo3(signature = (vertices, faces, normals=None, uvs=None, view=None))]
    fn from_mesh(
        py: Python<'_>,
        vertices: PyReadonlyArray2<'_, f64>,
        faces: PyReadonlyArray2<'_, i64>,
        normals: Option<PyReadonlyArray2<'_, f64>>,
        uvs: Option<PyReadonlyArray2<'_, f64>>,
        view: Option<ViewArgs>,
    ) -> PyResult<SceneCore> {
        let options = view.unwrap_or_default().options()?;
        let v = vertices.as_array();
        let f = faces.as_array();
        if v.ncols() != 3 || f.ncols() != 3 {
            return Err(InputError::new_err(format!(
                "vertices must be (N, 3) and faces (M, 3), got {:?} and {:?}",
                v.shape(),
                f.shape()
            )));
        }
        let n = v.nrows();
        if n > u32::MAX as usize || f.nrows() as u64 > phong_core::limits::MAX_SCENE_TRIANGLES {
            return Err(InputError::new_err(format!(
                "too many vertices or faces: {n} and {} (at most {} triangles)",
                f.nrows(),
                phong_core::limits::MAX_SCENE_TRIANGLES
            )));
        }
        let vec3s = |a: ndarray_view::View2<'_>, what: &str| -> PyResult<Vec<glam::Vec3>> {
            if a.nrows() != n || a.ncols() != 3 {
                return Err(InputError::new_err(format!(
                    "{what} must be ({n}, 3), got {:?}",
                    a.shape()
                )));
            }
            a.rows()
                .into_iter()
                .enumerate()
                .map(|(i, r)| {
                    let p = glam::DVec3::new(r[0], r[1], r[2]);
                    if p.is_finite() {
                        Ok(p.as_vec3())
                    } else {
                        Err(InputError::new_err(format!(
                            "{what}[{i}] is not finite: {:?}",
                            [r[0], r[1], r[2]]
                        )))
                    }
                })
                .collect()
        };
        let positions = vec3s(v, "vertices")?;
        let mut triangles = Vec::with_capacity(f.nrows());
        for (i, r) in f.rows().into_iter().enumerate() {
            let mut t = [0u32; 3];
            for (k, x) in r.iter().enumerate() {
                if *x < 0 || *x as usize >= n {
                    return Err(InputError::new_err(format!(
                        "faces[{i}] has vertex index {x}, outside 0..{n}"
                    )));
                }
                t[k] = *x as u32;
            }
            triangles.push(t);
        }
        let (normals, has_normals) = match &normals {
            Some(a) => (vec3s(a.as_array(), "normals")?, true),
            None => (vec![glam::Vec3::ZERO; n], false),
        };
        let mut mesh = phong_core::Mesh::new(positions, normals, triangles)
            .map_err(|e| InputError::new_err(format!("the mesh: {e}")))?;
        if let Some(uv) = &uvs {
            let a = uv.as_array();
            if a.nrows() != n || a.ncols() != 2 || a.iter().any(|x| !x.is_finite()) {
                return Err(InputError::new_err(format!(
                    "uvs must be ({n}, 2) finite numbers, got {:?}",
                    a.shape()
                )));
            }
            let uvs = a
                .rows()
                .into_iter()
                .map(|r| glam::Vec2::new(r[0] as f32, r[1] as f32))
                .collect();
            mesh = mesh
                .with_uvs(uvs)
                .map_err(|e| InputError::new_err(format!("uvs: {e}")))?;
        }
        let part = phong_scene::ModelPart {
            name: "mesh".into(),
            mesh,
            material: None,
            maps: Default::default(),
            has_normals,
            flat_without_normals: false,
            origin: glam::DVec3::ZERO,
            drawn: None,
            fitted: None,
        };
        let model = ModelFile::from_parts(vec![part]);
        py.detach(|| guarded(|| SceneCore::framed_model(Path::new("mesh"), Arc::new(Backing { model }), options, None)))
    }

    /// The same model viewed another way (a model's scene only).
    #[pyo3(signature = (view=None))]
    fn framed(&self, py: Python<'_>, view: Option<ViewArgs>) -> PyResult<SceneCore> {
        let Some(b) = self.backing.clone() else {
            return Err(InputError::new_err(
                "up, view, camera and two_sided apply to a model alone, not to a scene file",
            ));
        };
        let options = view.unwrap_or_default().options()?;
        py.detach(|| guarded(|| SceneCore::framed_model(&self.anchor, b, options, Some(self))))
    }

    /// A new core with the document `text` (checked with the scene reader's messages).
    fn with_json(&self, py: Python<'_>, text: &str) -> PyResult<SceneCore> {
        let doc = parse_json(text)?;
        let mut core = self.clone();
        core.camera_auto = self.camera_auto && doc.get("camera") == self.doc.get("camera");
        core.doc = Arc::new(doc);
        py.detach(|| {
            guarded(|| {
                core.build(&Settings::default()).map_err(py_err)?;
                Ok(core)
            })
        })
    }

    /// The document as JSON text.
    fn json(&self) -> String {
        self.doc.to_string()
    }

    /// The document as a TOML scene file.
    fn toml(&self) -> PyResult<String> {
        phong_scene::json_to_toml(&self.doc)
            .map(|t| t.text)
            .map_err(|e| InputError::new_err(e.to_string()))
    }

    /// The file the scene's relative paths are taken from.
    #[getter]
    fn anchor(&self) -> PathBuf {
        self.anchor.clone()
    }

    /// Whether the scene frames a model held in memory.
    #[getter]
    fn has_model(&self) -> bool {
        self.backing.is_some()
    }

    /// The number of triangles of the scene as built.
    fn triangle_count(&self, py: Python<'_>) -> PyResult<usize> {
        py.detach(|| guarded(|| Ok(self.build(&Settings::default()).map_err(py_err)?.triangle_count())))
    }
}

/// The built-in materials' names.
#[pyfunction]
pub fn materials() -> Vec<String> {
    phong_core::named_materials()
        .iter()
        .map(|m| m.name.to_string())
        .collect()
}

/// The two-dimensional array views the mesh conversion reads.
mod ndarray_view {
    pub type View2<'a> = numpy::ndarray::ArrayView2<'a, f64>;
}
