//! # phong-serve
//!
//! `phong serve`: a live explorer of the Phong model in the browser. The page (HTML, CSS and
//! JavaScript embedded in the binary) sends scenes as JSON with the scene file's schema; the
//! server renders them with phong's own renderers and answers PNG files, and probes any pixel
//! with phong-core's `shade`.
//!
//! Files: [`api`] (the routes, limits and errors), [`render`] (frames off the async threads),
//! [`probe`] (the numbers at a pixel), [`models`] (uploaded OBJ/MTL files, in memory).

pub mod api;
pub mod models;
pub mod probe;
pub mod render;

use std::net::SocketAddr;
use std::path::Path;

pub use api::{AppState, router};
pub use render::Backend;

/// The scene the page opens with when no file is given: a teapot over a plane, one point
/// light and one directional light.
pub const DEFAULT_SCENE: &str = include_str!("default.toml");

/// Why the server could not start.
#[derive(Debug, thiserror::Error)]
pub enum StartError {
    /// The scene or model given on the command line.
    #[error(transparent)]
    Input(#[from] phong_scene::Error),
    /// Something else the user gave (the port is taken, a bad address).
    #[error("{0}")]
    Usage(String),
    /// The system failed (the runtime, the renderer).
    #[error("{0}")]
    System(String),
}

impl StartError {
    /// Whether the error is in what the user gave (the file, the address).
    pub fn is_input(&self) -> bool {
        matches!(self, StartError::Input(_) | StartError::Usage(_))
    }
}

/// The initial scene for `file` (a scene `.toml`, a model `.obj`, or the default scene), as
/// JSON, and the models it names, loaded from disk by the operator's command (requests never
/// name files).
pub fn initial_scene(
    file: Option<&Path>,
    view: &phong_scene::ModelOptions,
) -> Result<(serde_json::Value, models::Library), StartError> {
    let mut library = models::Library::default();
    let is_obj = file.is_some_and(phong_scene::is_model_path);
    let json = match file {
        None => toml_to_json(DEFAULT_SCENE, Path::new("default.toml"))?,
        Some(f) if is_obj => {
            let model = phong_scene::ModelFile::read(f)?;
            for w in &model.warnings {
                eprintln!("warning: {w}");
            }
            let name = f
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default();
            let (scene, _) = phong_scene::model_scene(&name, &model, view);
            library.insert(name, model.parts);
            scene
        }
        Some(f) => {
            let src = phong_scene::read_text(f, phong_core::limits::MAX_SCENE_BYTES, "scene file (MAX_SCENE_BYTES)")?;
            // Validate as `phong render` would (meshes from disk), then keep the meshes.
            let loaded = phong_scene::parse_scene(&src, f)?;
            for w in &loaded.warnings {
                eprintln!("warning: {w}");
            }
            let json = toml_to_json(&src, f)?;
            let dir = f.parent().unwrap_or(Path::new(""));
            for o in json.get("object").and_then(|o| o.as_array()).into_iter().flatten() {
                if let Some(m) = o.get("mesh").and_then(|m| m.as_str()) {
                    let model = phong_scene::ModelFile::read(&dir.join(m))?;
                    library.insert(m.to_string(), model.parts);
                }
            }
            json
        }
    };
    Ok((json, library))
}

fn toml_to_json(src: &str, path: &Path) -> Result<serde_json::Value, StartError> {
    phong_scene::toml_to_json(src, path).map_err(|e| StartError::Usage(e.to_string()))
}

/// Binds `addr` (a clear error naming the port when it is taken).
pub async fn bind(addr: SocketAddr) -> Result<tokio::net::TcpListener, StartError> {
    tokio::net::TcpListener::bind(addr).await.map_err(|e| {
        if e.kind() == std::io::ErrorKind::AddrInUse {
            StartError::Usage(format!(
                "port {} is already in use on {}; choose another with --port",
                addr.port(),
                addr.ip()
            ))
        } else {
            StartError::Usage(format!("cannot listen on {addr}: {e}"))
        }
    })
}

/// Serves `state` on `listener` until `shutdown` completes; renders in flight finish first.
pub async fn serve(
    listener: tokio::net::TcpListener,
    state: std::sync::Arc<AppState>,
    shutdown: impl std::future::Future<Output = ()> + Send + 'static,
) -> std::io::Result<()> {
    let sweeper = tokio::spawn(models::sweep_idle(state.clone()));
    let app = router(state).into_make_service_with_connect_info::<SocketAddr>();
    let out = axum::serve(listener, app).with_graceful_shutdown(shutdown).await;
    sweeper.abort();
    out
}
