//! Models: those the operator's command loaded from disk (shared, read-only) and those
//! clients upload (OBJ with MTL, glTF with its buffers, PLY and STL files kept in memory per client, capped, dropped when idle).
//! A scene's `mesh = "NAME"` is looked up here, never on disk.

use crate::api::AppState;
use phong_core::limits::{SERVE_IDLE_SECONDS, SERVE_MAX_UPLOAD_TOTAL, SERVE_MAX_UPLOADS};
use phong_scene::{ModelFile, ModelPart};
use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Models loaded at startup, by the name the scene gives.
#[derive(Default)]
pub struct Library {
    models: HashMap<String, Arc<Vec<ModelPart>>>,
}

impl Library {
    /// Adds a model.
    pub fn insert(&mut self, name: String, parts: Vec<ModelPart>) {
        self.models.insert(name, Arc::new(parts));
    }

    /// A model's parts.
    pub fn get(&self, name: &str) -> Option<Arc<Vec<ModelPart>>> {
        self.models.get(name).cloned()
    }

    /// The names.
    pub fn names(&self) -> Vec<String> {
        let mut n: Vec<String> = self.models.keys().cloned().collect();
        n.sort();
        n
    }
}

/// One client's uploaded files and the OBJ files parsed from them.
#[derive(Default)]
pub struct Uploads {
    files: HashMap<String, Arc<Vec<u8>>>,
    parsed: HashMap<String, Arc<Vec<ModelPart>>>,
    bytes: usize,
    /// When the client last used the server.
    pub last_used: Option<Instant>,
}

impl Uploads {
    /// Stores `data` as `name`, replacing a file of that name; `Err` names the limit passed
    /// and says why.
    pub fn put(&mut self, name: &str, data: Vec<u8>) -> Result<(), (&'static str, String)> {
        let old = self.files.get(name).map_or(0, |f| f.len());
        if !self.files.contains_key(name) && self.files.len() >= SERVE_MAX_UPLOADS {
            return Err((
                "SERVE_MAX_UPLOADS",
                format!(
                    "upload limit: at most {SERVE_MAX_UPLOADS} files per client (SERVE_MAX_UPLOADS); delete one first"
                ),
            ));
        }
        if self.bytes - old + data.len() > SERVE_MAX_UPLOAD_TOTAL {
            return Err((
                "SERVE_MAX_UPLOAD_TOTAL",
                format!(
                    "upload limit: at most {} MiB of files per client (SERVE_MAX_UPLOAD_TOTAL)",
                    SERVE_MAX_UPLOAD_TOTAL >> 20
                ),
            ));
        }
        self.bytes = self.bytes - old + data.len();
        self.files.insert(name.to_string(), Arc::new(data));
        // An MTL may change any OBJ's materials: parse again on next use.
        self.parsed.clear();
        Ok(())
    }

    /// Removes a file; false when there was none.
    pub fn remove(&mut self, name: &str) -> bool {
        match self.files.remove(name) {
            Some(f) => {
                self.bytes -= f.len();
                self.parsed.clear();
                true
            }
            None => false,
        }
    }

    /// The file names.
    pub fn names(&self) -> Vec<String> {
        let mut n: Vec<String> = self.files.keys().cloned().collect();
        n.sort();
        n
    }

    /// The parts of uploaded OBJ `name` if parsed already; else its files, to parse with
    /// [`parse_upload`] outside the store's lock. `None`: no such upload.
    pub fn lookup(&self, name: &str) -> Option<Result<Arc<Vec<ModelPart>>, Files>> {
        if let Some(p) = self.parsed.get(name) {
            return Some(Ok(p.clone()));
        }
        self.files.contains_key(name).then(|| Err(Files(self.files.clone())))
    }

    /// Keeps `parts` as the parse of `name`, unless the uploads changed since `files` was taken.
    pub fn remember(&mut self, name: &str, files: &Files, parts: &Arc<Vec<ModelPart>>) {
        let same = files.0.len() == self.files.len()
            && files
                .0
                .iter()
                .all(|(k, v)| self.files.get(k).is_some_and(|f| Arc::ptr_eq(f, v)));
        if same {
            self.parsed.insert(name.to_string(), parts.clone());
        }
    }
}

/// A client's uploaded files at one moment (shared, not copied).
pub struct Files(HashMap<String, Arc<Vec<u8>>>);

/// Parses uploaded model `name` (an OBJ with its MTL libraries, a glTF with its buffers, a
/// PLY, an STL) from `files`; `Err` is the message for the scene's `mesh` key (or the upload).
pub fn parse_upload(name: &str, files: &Files) -> Result<Arc<Vec<ModelPart>>, String> {
    parse_upload_model(name, files).map(|m| Arc::new(m.parts))
}

/// [`parse_upload`] with what a glTF also holds (camera, lights, `doubleSided`), for the
/// scene of the model alone.
pub fn parse_upload_model(name: &str, files: &Files) -> Result<ModelFile, String> {
    let data = files.0.get(name).ok_or_else(|| format!("no upload named \"{name}\""))?;
    let lower = name.to_ascii_lowercase();
    // A file the model names (a glTF's buffers and images, an MTL's images) is looked up among
    // the client's uploads, by file name.
    let uploaded = |what: &'static str| {
        move |uri: &str| -> Result<Vec<u8>, String> {
            let key = uri.rsplit(['/', '\\']).next().unwrap_or(uri);
            files
                .0
                .get(key)
                .map(|f| f.to_vec())
                .ok_or_else(|| format!("{key} is not uploaded (upload it with the {what})"))
        }
    };
    let what = if lower.ends_with(".obj") { "OBJ" } else { "glTF" };
    phong_scene::ModelFile::from_bytes(Path::new(name), data, &uploaded(what)).map_err(|e| e.to_string())
}

/// Drops the uploads of clients idle for [`SERVE_IDLE_SECONDS`], every minute.
pub async fn sweep_idle(state: Arc<AppState>) {
    let mut tick = tokio::time::interval(Duration::from_secs(60));
    loop {
        tick.tick().await;
        let idle = Duration::from_secs(SERVE_IDLE_SECONDS);
        if let Ok(mut clients) = state.uploads.lock() {
            clients.retain(|_, u| u.last_used.is_some_and(|t| t.elapsed() < idle));
        }
    }
}

/// The page's scene for a model alone: `phong render MODEL`'s with the default view.
pub fn model_scene(name: &str, model: &ModelFile) -> serde_json::Value {
    phong_scene::model_scene(name, model, &phong_scene::ModelOptions::default()).0
}
