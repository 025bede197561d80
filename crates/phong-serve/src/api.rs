//! The routes: the page's assets and the JSON API (docs/explorer.md documents it).
//! Every error is a 4xx (or a 503 for a full server) with `{"error": ..., "path": ...,
//! "limit": ...}`; nothing a request sends makes a 500 or a panic.

use crate::models::{Library, Uploads};
use crate::probe::probe;
use crate::render::Backend;
use axum::Router;
use axum::body::Body;
use axum::extract::{ConnectInfo, Path as UrlPath, Query, State};
use axum::http::{HeaderMap, HeaderValue, StatusCode, header};
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post, put};
use phong_core::limits::{
    SERVE_MAX_BODY, SERVE_MAX_CLIENTS, SERVE_MAX_FIT_BODY, SERVE_MAX_LIGHTS, SERVE_MAX_PIXELS, SERVE_MAX_SAMPLES,
    SERVE_MAX_TRIANGLES, SERVE_MAX_UPLOAD, SERVE_RENDERS_PER_CLIENT, SERVE_RENDERS_TOTAL,
};
use phong_core::{Scene, SpecularModel, glam::Vec3, named_materials};
use serde_json::{Value, json};
use std::collections::HashMap;
use std::net::SocketAddr;
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// The server's state, shared by every request.
pub struct AppState {
    /// The renderer.
    pub backend: Backend,
    /// The scene the page opens with.
    pub initial: Value,
    /// Models loaded by the command line.
    pub library: Library,
    /// Uploads per client.
    pub uploads: Mutex<HashMap<String, Uploads>>,
    /// Renders in flight per client.
    inflight: Mutex<HashMap<String, usize>>,
    /// Frames drawn at once (the rest wait their turn, up to the in-flight limits).
    workers: tokio::sync::Semaphore,
}

impl AppState {
    /// A server rendering with `backend`, opening the page on `initial`.
    pub fn new(backend: Backend, initial: Value, library: Library) -> AppState {
        let workers = match &backend {
            Backend::Cpu { pool, .. } => pool.threads().clamp(1, 4),
            Backend::Gpu(_) => 1,
        };
        AppState {
            backend,
            initial,
            library,
            uploads: Mutex::default(),
            inflight: Mutex::default(),
            workers: tokio::sync::Semaphore::new(workers),
        }
    }
}

/// The page and the API.
pub fn router(state: Arc<AppState>) -> Router {
    Router::new()
        .route(
            "/",
            get(|| async { asset("text/html; charset=utf-8", include_str!("assets/index.html")) }),
        )
        .route(
            "/app.js",
            get(|| async { asset("text/javascript; charset=utf-8", include_str!("assets/app.js")) }),
        )
        .route(
            "/style.css",
            get(|| async { asset("text/css; charset=utf-8", include_str!("assets/style.css")) }),
        )
        .route("/api/scene", get(initial_scene))
        .route("/api/materials", get(materials))
        .route("/api/lobe", get(lobe))
        .route("/api/render", post(render))
        .route("/api/probe", post(probe_pixel))
        .route("/api/toml", post(to_toml))
        .route("/api/shader", post(shader))
        .route("/api/fit", post(fit))
        .route("/api/models", get(list_models))
        .route("/api/models/{name}", put(upload).delete(delete_model))
        .fallback(|| async { ApiError::new(StatusCode::NOT_FOUND, "no such page or API route") })
        .with_state(state)
}

fn asset(kind: &'static str, body: &'static str) -> Response {
    (
        [(header::CONTENT_TYPE, kind), (header::CACHE_CONTROL, "no-cache")],
        body,
    )
        .into_response()
}

/// An API error: its status and the JSON body that says why.
#[derive(Debug)]
pub struct ApiError {
    status: StatusCode,
    message: String,
    path: Option<String>,
    limit: Option<&'static str>,
}

impl ApiError {
    fn new(status: StatusCode, message: impl Into<String>) -> ApiError {
        ApiError {
            status,
            message: message.into(),
            path: None,
            limit: None,
        }
    }

    fn bad(message: impl Into<String>) -> ApiError {
        ApiError::new(StatusCode::BAD_REQUEST, message)
    }

    fn at(path: impl Into<String>, message: impl Into<String>) -> ApiError {
        ApiError {
            path: Some(path.into()),
            ..ApiError::bad(message)
        }
    }

    fn limit(status: StatusCode, limit: &'static str, message: impl Into<String>) -> ApiError {
        ApiError {
            limit: Some(limit),
            ..ApiError::new(status, message)
        }
    }
}

impl IntoResponse for ApiError {
    fn into_response(self) -> Response {
        let mut body = json!({"error": self.message});
        if let Some(p) = self.path {
            body["path"] = json!(p);
        }
        if let Some(l) = self.limit {
            body["limit"] = json!(l);
        }
        (self.status, axum::Json(body)).into_response()
    }
}

/// Who a request is from: the page's `X-Phong-Client` id, else the peer's address.
fn client_id(headers: &HeaderMap, peer: SocketAddr) -> String {
    headers
        .get("x-phong-client")
        .and_then(|v| v.to_str().ok())
        .filter(|v| !v.is_empty() && v.len() <= 64 && v.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'-'))
        .map_or_else(|| peer.ip().to_string(), str::to_string)
}

/// A render in flight, counted per client and in all until dropped.
struct InFlight {
    state: Arc<AppState>,
    client: String,
}

impl InFlight {
    fn start(state: &Arc<AppState>, client: &str) -> Result<InFlight, ApiError> {
        let mut map = state
            .inflight
            .lock()
            .map_err(|_| ApiError::new(StatusCode::SERVICE_UNAVAILABLE, "busy"))?;
        let total: usize = map.values().sum();
        if total >= SERVE_RENDERS_TOTAL {
            return Err(ApiError::limit(
                StatusCode::SERVICE_UNAVAILABLE,
                "SERVE_RENDERS_TOTAL",
                format!("the server is busy: {SERVE_RENDERS_TOTAL} renders in flight (SERVE_RENDERS_TOTAL); try again"),
            ));
        }
        let mine = map.entry(client.to_string()).or_default();
        if *mine >= SERVE_RENDERS_PER_CLIENT {
            return Err(ApiError::limit(
                StatusCode::TOO_MANY_REQUESTS,
                "SERVE_RENDERS_PER_CLIENT",
                format!(
                    "at most {SERVE_RENDERS_PER_CLIENT} renders in flight per client (SERVE_RENDERS_PER_CLIENT); wait for one"
                ),
            ));
        }
        *mine += 1;
        Ok(InFlight {
            state: state.clone(),
            client: client.to_string(),
        })
    }
}

impl Drop for InFlight {
    fn drop(&mut self) {
        if let Ok(mut map) = self.state.inflight.lock()
            && let Some(n) = map.get_mut(&self.client)
        {
            *n -= 1;
            if *n == 0 {
                map.remove(&self.client);
            }
        }
    }
}

/// The body, up to `limit` bytes (413 past it).
async fn read_body(body: Body, limit: usize, name: &'static str) -> Result<axum::body::Bytes, ApiError> {
    axum::body::to_bytes(body, limit).await.map_err(|_| {
        ApiError::limit(
            StatusCode::PAYLOAD_TOO_LARGE,
            name,
            format!("the request body is larger than {limit} bytes ({name}) or was cut off"),
        )
    })
}

fn parse_json(bytes: &[u8]) -> Result<Value, ApiError> {
    serde_json::from_slice(bytes).map_err(|e| {
        ApiError::bad(format!(
            "the body is not valid JSON: {e} (line {}, column {})",
            e.line(),
            e.column()
        ))
    })
}

/// Triangles of the shapes a JSON scene asks for, counted before any is built, so that a
/// huge `segments` is refused without allocating it.
fn shape_triangles(scene: &Value) -> Result<(), ApiError> {
    let mut total: u64 = 0;
    for (i, o) in scene
        .get("object")
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
        .enumerate()
    {
        let (Some(shape), seg) = (o.get("shape").and_then(Value::as_str), o.get("segments")) else {
            continue;
        };
        let n = match seg {
            Some(s) => match s.as_u64() {
                Some(n) => n,
                None => continue, // the scene reader reports a bad value
            },
            None => match shape {
                "plane" => 1,
                "teapot" => 10,
                _ => 64,
            },
        };
        total = total.saturating_add(match shape {
            "teapot" => 64 * n * n,
            "plane" => 2 * n * n,
            "cube" => 12,
            _ => n * n + 4 * n,
        });
        if total > SERVE_MAX_TRIANGLES {
            return Err(ApiError {
                path: Some(format!("object[{i}].segments")),
                ..too_many_triangles(total)
            });
        }
    }
    Ok(())
}

fn too_many_triangles(n: u64) -> ApiError {
    ApiError::limit(
        StatusCode::PAYLOAD_TOO_LARGE,
        "SERVE_MAX_TRIANGLES",
        format!("the scene has {n} triangles; this server draws at most {SERVE_MAX_TRIANGLES} (SERVE_MAX_TRIANGLES)"),
    )
}

/// Reads a JSON scene as the scene file's reader does, with `client`'s uploads for meshes,
/// and checks the server's limits.
fn scene_from_json(state: &AppState, client: &str, value: &Value) -> Result<Scene, ApiError> {
    if let Some(lights) = value.get("light").and_then(Value::as_array)
        && lights.len() > SERVE_MAX_LIGHTS
    {
        return Err(ApiError {
            path: Some(format!("light[{SERVE_MAX_LIGHTS}]")),
            ..ApiError::limit(
                StatusCode::PAYLOAD_TOO_LARGE,
                "SERVE_MAX_LIGHTS",
                format!("at most {SERVE_MAX_LIGHTS} lights (SERVE_MAX_LIGHTS)"),
            )
        });
    }
    shape_triangles(value)?;
    let lookup = |name: &str| -> Result<Vec<phong_scene::ModelPart>, String> {
        if let Some(p) = state.library.get(name) {
            return Ok((*p).clone());
        }
        let found = {
            let clients = state
                .uploads
                .lock()
                .map_err(|_| "the upload store failed".to_string())?;
            clients.get(client).and_then(|u| u.lookup(name))
        };
        match found {
            Some(Ok(p)) => Ok((*p).clone()),
            // Parsed outside the lock (this runs on a blocking thread).
            Some(Err(files)) => {
                let parts = crate::models::parse_upload(name, &files)?;
                if let Ok(mut clients) = state.uploads.lock()
                    && let Some(u) = clients.get_mut(client)
                {
                    u.remember(name, &files, &parts);
                }
                Ok((*parts).clone())
            }
            None => Err(format!(
                "no model named \"{name}\": upload it first (PUT /api/models/{name}); the server opens no file a \
                 request names"
            )),
        }
    };
    let loaded = phong_scene::parse_scene_json(value, &lookup).map_err(|e| ApiError::at(e.path, e.message))?;
    let scene = loaded.scene;
    let (w, h, s) = (
        u64::from(scene.image.width),
        u64::from(scene.image.height),
        u64::from(scene.image.samples.count()),
    );
    if w * h > SERVE_MAX_PIXELS {
        return Err(ApiError {
            path: Some("image".into()),
            ..ApiError::limit(
                StatusCode::PAYLOAD_TOO_LARGE,
                "SERVE_MAX_PIXELS",
                format!(
                    "{w}x{h} is {} pixels; this server draws at most {SERVE_MAX_PIXELS} (SERVE_MAX_PIXELS)",
                    w * h
                ),
            )
        });
    }
    if w * h * s > SERVE_MAX_SAMPLES {
        return Err(ApiError {
            path: Some("image.antialias".into()),
            ..ApiError::limit(
                StatusCode::PAYLOAD_TOO_LARGE,
                "SERVE_MAX_SAMPLES",
                format!(
                    "{w}x{h} at {s} samples is {} samples; this server draws at most {SERVE_MAX_SAMPLES} (SERVE_MAX_SAMPLES)",
                    w * h * s
                ),
            )
        });
    }
    let tris = scene.triangle_count() as u64;
    if tris > SERVE_MAX_TRIANGLES {
        return Err(too_many_triangles(tris));
    }
    Ok(scene)
}

/// Runs `job` on a blocking thread once a worker is free, counted as in flight for `client`.
async fn run_job<T: Send + 'static>(
    state: &Arc<AppState>,
    client: &str,
    job: impl FnOnce(&AppState) -> Result<T, ApiError> + Send + 'static,
) -> Result<T, ApiError> {
    let guard = InFlight::start(state, client)?;
    let _permit = state
        .workers
        .acquire()
        .await
        .map_err(|_| ApiError::new(StatusCode::SERVICE_UNAVAILABLE, "the server is shutting down"))?;
    let st = state.clone();
    let out = tokio::task::spawn_blocking(move || job(&st))
        .await
        .map_err(|_| ApiError::new(StatusCode::INTERNAL_SERVER_ERROR, "the render failed"))?;
    drop(guard);
    out
}

fn touch(state: &AppState, client: &str) {
    if let Ok(mut u) = state.uploads.lock()
        && let Some(c) = u.get_mut(client)
    {
        c.last_used = Some(Instant::now());
    }
}

async fn initial_scene(State(state): State<Arc<AppState>>) -> Response {
    axum::Json(json!({"scene": state.initial, "models": state.library.names()})).into_response()
}

async fn materials() -> Response {
    let list: Vec<Value> = named_materials()
        .iter()
        .map(|m| {
            let v = &m.material;
            let c = |c: phong_core::Color| [c.r, c.g, c.b];
            json!({"name": m.name, "ambient": c(v.ambient()), "diffuse": c(v.diffuse()),
                   "specular": c(v.specular()), "emission": c(v.emission()),
                   "shininess": v.shininess(), "alpha": v.alpha()})
        })
        .collect();
    axum::Json(list).into_response()
}

/// `POST /api/render[?format=png|rgba]`: a JSON scene to the PNG `phong render` writes for
/// it, or to its pixels as RGBA bytes (`x-phong-width` and `x-phong-height` give the size).
async fn render(
    State(state): State<Arc<AppState>>,
    ConnectInfo(peer): ConnectInfo<SocketAddr>,
    Query(q): Query<HashMap<String, String>>,
    headers: HeaderMap,
    body: Body,
) -> Result<Response, ApiError> {
    let raw = match q.get("format").map(String::as_str) {
        None | Some("png") => false,
        Some("rgba") => true,
        Some(other) => {
            return Err(ApiError::at(
                "format",
                format!("`format` is \"png\" or \"rgba\", got \"{other}\""),
            ));
        }
    };
    let client = client_id(&headers, peer);
    let bytes = read_body(body, SERVE_MAX_BODY, "SERVE_MAX_BODY").await?;
    let value = parse_json(&bytes)?;
    touch(&state, &client);
    let c = client.clone();
    let (bytes, size, ms) = run_job(&state, &client, move |st| {
        let t = Instant::now();
        let scene = scene_from_json(st, &c, &value)?;
        let bytes = st
            .backend
            .frame(&scene, raw)
            .map_err(|e| ApiError::new(StatusCode::UNPROCESSABLE_ENTITY, e))?;
        Ok((
            bytes,
            (scene.image.width, scene.image.height),
            t.elapsed().as_secs_f64() * 1e3,
        ))
    })
    .await?;
    let mut r = (StatusCode::OK, bytes).into_response();
    let h = r.headers_mut();
    let kind = if raw { "application/octet-stream" } else { "image/png" };
    h.insert(header::CONTENT_TYPE, HeaderValue::from_static(kind));
    h.insert(header::CACHE_CONTROL, HeaderValue::from_static("no-store"));
    for (k, v) in [
        ("x-phong-render-ms", format!("{ms:.2}")),
        ("x-phong-width", size.0.to_string()),
        ("x-phong-height", size.1.to_string()),
    ] {
        if let Ok(v) = HeaderValue::from_str(&v) {
            h.insert(k, v);
        }
    }
    Ok(r)
}

/// `POST /api/probe`: `{"scene": {...}, "x": X, "y": Y}` to the probe's numbers.
async fn probe_pixel(
    State(state): State<Arc<AppState>>,
    ConnectInfo(peer): ConnectInfo<SocketAddr>,
    headers: HeaderMap,
    body: Body,
) -> Result<Response, ApiError> {
    let client = client_id(&headers, peer);
    let bytes = read_body(body, SERVE_MAX_BODY, "SERVE_MAX_BODY").await?;
    let value = parse_json(&bytes)?;
    let pixel = |k: &str| -> Result<u32, ApiError> {
        value
            .get(k)
            .and_then(Value::as_u64)
            .and_then(|v| u32::try_from(v).ok())
            .ok_or_else(|| ApiError::at(k, format!("`{k}` must be a pixel coordinate (an integer >= 0)")))
    };
    let (x, y) = (pixel("x")?, pixel("y")?);
    let Some(scene_value) = value.get("scene").cloned() else {
        return Err(ApiError::at(
            "scene",
            "the probe needs `scene` (the scene JSON) and `x`, `y`",
        ));
    };
    touch(&state, &client);
    let c = client.clone();
    let out = run_job(&state, &client, move |st| {
        let scene = scene_from_json(st, &c, &scene_value)?;
        if x >= scene.image.width || y >= scene.image.height {
            return Err(ApiError::at(
                if x >= scene.image.width { "x" } else { "y" },
                format!(
                    "pixel ({x}, {y}) is outside the {}x{} image",
                    scene.image.width, scene.image.height
                ),
            ));
        }
        Ok(probe(&scene, x, y))
    })
    .await?;
    Ok(axum::Json(out).into_response())
}

/// `POST /api/fit`: `{"scene": {...}, "object": INDEX, "target": BASE64_PNG, "free":
/// "ambient,diffuse,..."}` to the fitted material, its errors, what is undetermined, and the
/// target | fit | difference picture (base64 PNG). The target has the scene's image size and
/// the scene's encoding.
async fn fit(
    State(state): State<Arc<AppState>>,
    ConnectInfo(peer): ConnectInfo<SocketAddr>,
    headers: HeaderMap,
    body: Body,
) -> Result<Response, ApiError> {
    use base64::Engine;
    let client = client_id(&headers, peer);
    let bytes = read_body(body, SERVE_MAX_FIT_BODY, "SERVE_MAX_FIT_BODY").await?;
    let value = parse_json(&bytes)?;
    let Some(scene_value) = value.get("scene").cloned() else {
        return Err(ApiError::at(
            "scene",
            "the fit needs `scene`, `target` (a base64 PNG) and `object`",
        ));
    };
    let png = value
        .get("target")
        .and_then(Value::as_str)
        .and_then(|t| {
            base64::engine::general_purpose::STANDARD
                .decode(t.trim_start_matches("data:image/png;base64,"))
                .ok()
        })
        .ok_or_else(|| ApiError::at("target", "`target` must be a PNG file in base64"))?;
    let object = match value.get("object") {
        None => 0,
        Some(v) => v
            .as_u64()
            .map(|v| v as usize)
            .ok_or_else(|| ApiError::at("object", "`object` must be an object's index"))?,
    };
    let free = match value.get("free").and_then(Value::as_str) {
        None => phong_fit::image::Free::default_set(),
        Some(f) => phong_fit::image::Free::parse(f).map_err(|e| ApiError::at("free", e.to_string()))?,
    };
    let c = client.clone();
    let out = run_job(&state, &client, move |st| {
        let scene = scene_from_json(st, &c, &scene_value)?;
        if object >= scene.objects.len() {
            return Err(ApiError::at(
                "object",
                format!("the scene has {} objects", scene.objects.len()),
            ));
        }
        let target =
            phong_fit::image::Target::decode(&png, scene.image.encoding).map_err(|e| ApiError::at("target", e))?;
        let fit = phong_fit::image::fit_image(
            &scene,
            object,
            &target,
            free,
            None,
            phong_raster::RenderOptions::default(),
        )
        .map_err(|e| match e {
            phong_fit::FitError::Input(m) => ApiError::at("target", m),
            other => ApiError::new(StatusCode::UNPROCESSABLE_ENTITY, other.to_string()),
        })?;
        let picture = phong_fit::report::comparison(&target, &fit.image, &fit.used);
        let picture = phong_scene::encode_png(&picture, scene.image.encoding)
            .map_err(|e| ApiError::new(StatusCode::UNPROCESSABLE_ENTITY, e.to_string()))?;
        let m = fit.material;
        let c3 = |c: phong_core::Color| [c.r, c.g, c.b];
        Ok(json!({
            "material": {"ambient": c3(m.ambient()), "diffuse": c3(m.diffuse()), "specular": c3(m.specular()),
                         "emission": c3(m.emission()), "shininess": m.shininess()},
            "rmse": fit.rmse, "psnr": fit.psnr, "pixels": fit.pixels,
            "nearest": {"name": fit.nearest.0, "rmse": fit.nearest.1},
            "undetermined": fit.undetermined,
            "comparison": base64::engine::general_purpose::STANDARD.encode(picture),
        }))
    })
    .await?;
    Ok(axum::Json(out).into_response())
}

/// `POST /api/toml`: the JSON scene as the TOML file `phong render` renders to the same image.
async fn to_toml(body: Body) -> Result<Response, ApiError> {
    let bytes = read_body(body, SERVE_MAX_BODY, "SERVE_MAX_BODY").await?;
    let value = parse_json(&bytes)?;
    let t = phong_scene::json_to_toml(&value).map_err(|e| ApiError::at(e.path, e.message))?;
    let text = format!(
        "# Written by phong serve; render it with: phong render scene.toml -o scene.png\n{}",
        t.text
    );
    Ok(([(header::CONTENT_TYPE, "application/toml; charset=utf-8")], text).into_response())
}

/// `POST /api/shader?target=glsl|glsl330|glsl300es|html[&object=INDEX]`: the scene's model as
/// shaders (phong-shader): for the GLSL targets `{"vertex", "fragment", "uniforms"}` (the
/// object's program where `object` is given, else the scene's, whose objects must share one),
/// for `html` the standalone WebGL2 page. What a shader cannot express is a 422 saying what.
async fn shader(
    State(state): State<Arc<AppState>>,
    ConnectInfo(peer): ConnectInfo<SocketAddr>,
    Query(q): Query<HashMap<String, String>>,
    headers: HeaderMap,
    body: Body,
) -> Result<Response, ApiError> {
    use phong_shader::Version;
    let target = q.get("target").map_or("glsl300es", String::as_str);
    let version = match target {
        "glsl" => Some(Version::Legacy120),
        "glsl330" => Some(Version::Core330),
        "glsl300es" => Some(Version::Es300),
        "html" => None,
        other => {
            return Err(ApiError::at(
                "target",
                format!("`target` is \"glsl\", \"glsl330\", \"glsl300es\" or \"html\", got \"{other}\""),
            ));
        }
    };
    let object = match q.get("object") {
        None => None,
        Some(o) => Some(
            o.parse::<usize>()
                .map_err(|_| ApiError::at("object", format!("`object` is an object's index, got \"{o}\"")))?,
        ),
    };
    let client = client_id(&headers, peer);
    let bytes = read_body(body, SERVE_MAX_BODY, "SERVE_MAX_BODY").await?;
    let value = parse_json(&bytes)?;
    touch(&state, &client);
    let c = client.clone();
    run_job(&state, &client, move |st| {
        let scene = scene_from_json(st, &c, &value)?;
        let refuse = |e: phong_shader::Unsupported| ApiError::new(StatusCode::UNPROCESSABLE_ENTITY, e.to_string());
        Ok(match version {
            None => {
                let page = phong_shader::html(&scene).map_err(refuse)?;
                ([(header::CONTENT_TYPE, "text/html; charset=utf-8")], page).into_response()
            }
            Some(v) => {
                let p = match object {
                    Some(i) => phong_shader::program_of(&scene, i, v),
                    None => phong_shader::program(&scene, v),
                }
                .map_err(refuse)?;
                axum::Json(serde_json::json!({
                    "vertex": p.vertex,
                    "fragment": p.fragment,
                    "uniforms": p.uniforms,
                }))
                .into_response()
            }
        })
    })
    .await
}

/// `GET /api/lobe?shininess=S[&incidence=DEG][&squarings=N]`: the specular factor against the
/// angle between `V` and the mirror direction `R`, in the plane of incidence, from
/// phong-core's `specular_factor`: Phong, Blinn-Phong at `s` and `4s`, and Lyon.
async fn lobe(Query(q): Query<HashMap<String, String>>) -> Result<Response, ApiError> {
    let num = |k: &str, default: f32, ok: fn(f32) -> bool, range: &str| -> Result<f32, ApiError> {
        match q.get(k) {
            None => Ok(default),
            Some(v) => v
                .parse::<f32>()
                .ok()
                .filter(|x| x.is_finite() && ok(*x))
                .ok_or_else(|| ApiError::at(k, format!("`{k}` must be {range}, got \"{v}\""))),
        }
    };
    let s = num(
        "shininess",
        32.0,
        |x| (0.0..=1e4).contains(&x),
        "a number from 0 to 10000",
    )?;
    let inc = num(
        "incidence",
        45.0,
        |x| (0.0..90.0).contains(&x),
        "an angle in [0, 90) degrees",
    )?;
    let squarings = num(
        "squarings",
        3.0,
        |x| x.fract() == 0.0 && (0.0..=16.0).contains(&x),
        "an integer from 0 to 16",
    )?;
    let n = Vec3::Y;
    let (si, ci) = inc.to_radians().sin_cos();
    let l = Vec3::new(si, ci, 0.0);
    let lyon = SpecularModel::Lyon {
        squarings: squarings as u32,
        lambda: phong_core::LyonLambda::Dot,
    };
    let (mut angles, mut phong, mut blinn, mut blinn4, mut lyon_v) = (vec![], vec![], vec![], vec![], vec![]);
    for k in -180..=180 {
        let theta = k as f32 * 0.5;
        // V: R turned by θ about z, in the plane of incidence.
        let a = (-inc + theta).to_radians();
        let v = Vec3::new(a.sin(), a.cos(), 0.0);
        angles.push(theta);
        phong.push(phong_core::specular_factor(SpecularModel::Phong, n, l, v, s));
        blinn.push(phong_core::specular_factor(SpecularModel::BlinnPhong, n, l, v, s));
        blinn4.push(phong_core::specular_factor(SpecularModel::BlinnPhong, n, l, v, 4.0 * s));
        lyon_v.push(phong_core::specular_factor(lyon, n, l, v, s));
    }
    Ok(axum::Json(
        json!({"shininess": s, "incidence": inc, "squarings": squarings, "angles": angles,
        "phong": phong, "blinn_phong": blinn, "blinn_phong_4s": blinn4, "lyon": lyon_v}),
    )
    .into_response())
}

fn valid_upload_name(name: &str) -> Result<(), ApiError> {
    let ok_chars = name.bytes().all(|b| b.is_ascii_alphanumeric() || b"._- ".contains(&b));
    let ext = name.rsplit_once('.').map(|(_, e)| e.to_ascii_lowercase());
    if name.is_empty() || name.len() > 128 || !ok_chars || name.starts_with('.') {
        return Err(ApiError::at(
            "name",
            "a model's name is 1 to 128 letters, digits, spaces, '.', '-' or '_', not starting with '.'",
        ));
    }
    if !matches!(
        ext.as_deref(),
        Some("obj" | "mtl" | "ply" | "stl" | "gltf" | "glb" | "bin" | "png" | "jpg" | "jpeg" | "tga" | "bmp")
    ) {
        return Err(ApiError::at(
            "name",
            "uploads are models (Wavefront .obj with their .mtl libraries, .gltf with their .bin buffers, .glb, .ply, .stl) \
             and their texture images (.png, .jpg, .jpeg, .tga, .bmp)",
        ));
    }
    Ok(())
}

/// `PUT /api/models/NAME`: stores an OBJ or MTL file for this client (in memory).
async fn upload(
    State(state): State<Arc<AppState>>,
    ConnectInfo(peer): ConnectInfo<SocketAddr>,
    headers: HeaderMap,
    UrlPath(name): UrlPath<String>,
    body: Body,
) -> Result<Response, ApiError> {
    valid_upload_name(&name)?;
    let client = client_id(&headers, peer);
    let bytes = read_body(body, SERVE_MAX_UPLOAD, "SERVE_MAX_UPLOAD").await?;
    let lower = name.to_ascii_lowercase();
    let is_obj = [".obj", ".ply", ".stl", ".gltf", ".glb"]
        .iter()
        .any(|e| lower.ends_with(e));
    let files = {
        let mut clients = state
            .uploads
            .lock()
            .map_err(|_| ApiError::new(StatusCode::SERVICE_UNAVAILABLE, "the upload store failed"))?;
        if !clients.contains_key(&client) && clients.len() >= SERVE_MAX_CLIENTS {
            return Err(ApiError::limit(
                StatusCode::SERVICE_UNAVAILABLE,
                "SERVE_MAX_CLIENTS",
                format!("{SERVE_MAX_CLIENTS} clients hold uploads (SERVE_MAX_CLIENTS); try again later"),
            ));
        }
        let u = clients.entry(client.clone()).or_default();
        u.last_used = Some(Instant::now());
        u.put(&name, bytes.to_vec())
            .map_err(|(limit, m)| ApiError::limit(StatusCode::PAYLOAD_TOO_LARGE, limit, m))?;
        u.lookup(&name)
    };
    let mut info = json!({"name": name});
    // An OBJ is parsed now (off the async threads), so that a broken file is reported to the
    // upload, not to a render.
    if is_obj && let Some(Err(files)) = files {
        let n = name.clone();
        let parsed = tokio::task::spawn_blocking(move || {
            let model = crate::models::parse_upload_model(&n, &files);
            (model, files)
        })
        .await
        .map_err(|_| ApiError::new(StatusCode::INTERNAL_SERVER_ERROR, "parsing the upload failed"))?;
        let mut clients = state
            .uploads
            .lock()
            .map_err(|_| ApiError::new(StatusCode::SERVICE_UNAVAILABLE, "the upload store failed"))?;
        let u = clients.entry(client.clone()).or_default();
        match parsed {
            (Ok(model), files) => {
                info["scene"] = crate::models::model_scene(&name, &model);
                let parts = std::sync::Arc::new(model.parts);
                u.remember(&name, &files, &parts);
                let tris: usize = parts.iter().map(|p| p.mesh.triangles().len()).sum();
                info["triangles"] = json!(tris);
                info["parts"] = json!(parts.len());
            }
            (Err(e), _) => {
                u.remove(&name);
                return Err(ApiError::at("file", e));
            }
        }
    }
    if let Ok(clients) = state.uploads.lock() {
        info["files"] = json!(clients.get(&client).map(Uploads::names).unwrap_or_default());
    }
    Ok((StatusCode::CREATED, axum::Json(info)).into_response())
}

async fn list_models(
    State(state): State<Arc<AppState>>,
    ConnectInfo(peer): ConnectInfo<SocketAddr>,
    headers: HeaderMap,
) -> Response {
    let client = client_id(&headers, peer);
    let mine = state
        .uploads
        .lock()
        .ok()
        .and_then(|u| u.get(&client).map(Uploads::names))
        .unwrap_or_default();
    axum::Json(json!({"server": state.library.names(), "uploads": mine})).into_response()
}

async fn delete_model(
    State(state): State<Arc<AppState>>,
    ConnectInfo(peer): ConnectInfo<SocketAddr>,
    headers: HeaderMap,
    UrlPath(name): UrlPath<String>,
) -> Result<Response, ApiError> {
    let client = client_id(&headers, peer);
    let removed = state
        .uploads
        .lock()
        .ok()
        .and_then(|mut u| u.get_mut(&client).map(|c| c.remove(&name)))
        .unwrap_or(false);
    if removed {
        Ok(StatusCode::NO_CONTENT.into_response())
    } else {
        Err(ApiError::new(
            StatusCode::NOT_FOUND,
            format!("no upload named \"{name}\""),
        ))
    }
}
