//! Scenes whose objects are built once: a document's objects (meshes read, normals and
//! tangents computed, textures decoded) depend on neither its camera, nor its lights, nor its
//! image, so many views of one model build them once and read only those tables again.

use crate::{Error, Models, Settings, Source};
use phong_scene::MeshLookup;
use serde_json::{Map, Value};
use std::path::Path;
use std::sync::Mutex;

/// The objects of the last few documents built, by document less its camera, lights and image.
pub struct Built {
    kept: Mutex<Vec<(Value, phong_core::Scene)>>,
    capacity: usize,
}

impl Built {
    /// A cache of `capacity` scenes (at least one).
    pub fn new(capacity: usize) -> Built {
        Built {
            kept: Mutex::new(Vec::new()),
            capacity: capacity.max(1),
        }
    }

    /// The scene of `doc` (as [`crate::load`] reads a [`Source::Document`]) with `settings`
    /// applied: its objects from this cache where an earlier document differed only in its
    /// camera, lights or image, those tables read alone.
    pub fn load(
        &self,
        doc: &Value,
        anchor: &Path,
        meshes: Option<&MeshLookup>,
        settings: &Settings,
        models: &Models,
    ) -> Result<phong_core::Scene, Error> {
        let mut key = doc.clone();
        if let Value::Object(o) = &mut key {
            for k in ["camera", "light", "image"] {
                o.remove(k);
            }
        }
        let mut doc = doc.clone();
        crate::merge_tables(&mut doc, &settings.tables).map_err(|error| Error::Json {
            what: anchor.display().to_string(),
            error,
        })?;
        let cached = {
            let kept = self.kept.lock().expect("not poisoned");
            kept.iter().find(|(k, _)| *k == key).map(|(_, s)| s.clone())
        };
        let mut scene = match cached {
            Some(s) if settings.tables.is_empty() => s,
            _ => {
                let source = Source::Document {
                    scene: &doc,
                    anchor,
                    meshes,
                };
                let plain = Settings {
                    tables: Map::new(),
                    ..Settings::default()
                };
                let scene = crate::load(source, &plain, models, "")?.scene;
                if settings.tables.is_empty() {
                    let mut kept = self.kept.lock().expect("not poisoned");
                    if kept.len() >= self.capacity {
                        kept.remove(0);
                    }
                    kept.push((key, scene.clone()));
                }
                scene
            }
        };
        // The camera, lights and image alone (no objects), with the size and samples asked for.
        let mut mini = Map::new();
        for k in ["image", "camera", "light", "shading"] {
            if let Some(v) = doc.get(k) {
                mini.insert(k.into(), v.clone());
            }
        }
        let mini = Value::Object(mini);
        let source = Source::Document {
            scene: &mini,
            anchor,
            meshes: None,
        };
        let small = crate::load(
            source,
            &Settings {
                tables: Map::new(),
                ..settings.clone()
            },
            models,
            "width, height, antialias",
        )?;
        scene.image = small.scene.image;
        scene.camera = small.scene.camera;
        scene.lighting = small.scene.lighting;
        settings.overrides.apply_to_scene(&mut scene);
        Ok(scene)
    }
}
