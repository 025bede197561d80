//! The JSON API, in process (tower's `oneshot` on the router): every class of bad input,
//! every limit, meshes never read from disk, the probe and lobe against closed forms, many
//! clients at once.

use axum::body::Body;
use axum::extract::connect_info::MockConnectInfo;
use axum::http::{Request, StatusCode};
use phong_serve::{AppState, Backend, models::Library, router};
use serde_json::{Value, json};
use std::net::SocketAddr;
use std::sync::Arc;
use tower::ServiceExt;

fn state() -> Arc<AppState> {
    Arc::new(AppState::new(
        Backend::cpu(Some(2)).expect("threads"),
        json!({}),
        Library::default(),
    ))
}

struct Reply {
    status: StatusCode,
    kind: String,
    body: Vec<u8>,
}

impl Reply {
    fn json(&self) -> Value {
        serde_json::from_slice(&self.body)
            .unwrap_or_else(|_| panic!("JSON, got {:?}", String::from_utf8_lossy(&self.body)))
    }
}

async fn call(state: &Arc<AppState>, method: &str, uri: &str, client: &str, body: impl Into<Body>) -> Reply {
    let app = router(state.clone()).layer(MockConnectInfo(SocketAddr::from(([127, 0, 0, 1], 9))));
    let req = Request::builder()
        .method(method)
        .uri(uri)
        .header("x-phong-client", client)
        .header("content-type", "application/json")
        .body(body.into())
        .expect("request");
    let r = app.oneshot(req).await.expect("infallible");
    let status = r.status();
    let kind = r
        .headers()
        .get("content-type")
        .and_then(|v| v.to_str().ok())
        .unwrap_or("")
        .to_string();
    let body = axum::body::to_bytes(r.into_body(), usize::MAX)
        .await
        .expect("body")
        .to_vec();
    Reply { status, kind, body }
}

async fn render(state: &Arc<AppState>, scene: Value) -> Reply {
    call(state, "POST", "/api/render", "a", scene.to_string()).await
}

/// Status, error path and limit of a refused request.
fn refused(r: &Reply) -> (u16, String, String) {
    let j = r.json();
    assert!(j["error"].as_str().is_some_and(|m| !m.is_empty()), "a message: {j}");
    (
        r.status.as_u16(),
        j["path"].as_str().unwrap_or("").to_string(),
        j["limit"].as_str().unwrap_or("").to_string(),
    )
}

fn decode(png_bytes: &[u8]) -> (u32, u32, Vec<u8>) {
    let mut r = png::Decoder::new(std::io::Cursor::new(png_bytes))
        .read_info()
        .expect("png");
    let mut buf = vec![0; r.output_buffer_size().expect("size")];
    let info = r.next_frame(&mut buf).expect("frame");
    buf.truncate(info.buffer_size());
    (info.width, info.height, buf)
}

fn small_scene() -> Value {
    json!({"image": {"width": 64, "height": 48},
           "light": [{"type": "directional", "direction": [0, 0, -1]}],
           "object": [{"shape": "sphere", "material": "ruby"}]})
}

#[tokio::test]
async fn the_page_and_its_assets_are_the_binarys() {
    let st = state();
    let page = call(&st, "GET", "/", "a", Body::empty()).await;
    assert_eq!(page.status, StatusCode::OK);
    assert!(page.kind.starts_with("text/html"));
    let html = String::from_utf8(page.body).expect("utf-8");
    for label in [
        "Model",
        "Interpolation",
        "Shininess",
        "Ambient",
        "Diffuse",
        "Specular",
        "Emission",
        "Material",
        "Normalization",
        "Viewer",
        "Two-sided",
        "Output",
        "Shape",
        "Segments",
        "Antialias",
        "Encoding",
    ] {
        assert!(html.contains(&format!(">{label}</label>")), "label {label}");
    }
    assert!(
        !html.contains("http://") && !html.contains("https://"),
        "no CDN: the page works offline"
    );
    assert_eq!(
        call(&st, "GET", "/app.js", "a", Body::empty()).await.status,
        StatusCode::OK
    );
    for missing in ["/assets/", "/src/", "/../Cargo.toml", "/api/nothing"] {
        let r = call(&st, "GET", missing, "a", Body::empty()).await;
        assert_eq!(r.status, StatusCode::NOT_FOUND, "{missing}");
        assert!(r.json()["error"].is_string());
    }
}

#[tokio::test]
async fn render_answers_the_png_of_phong_render() {
    let st = state();
    let r = render(&st, small_scene()).await;
    assert_eq!(r.status, StatusCode::OK);
    assert_eq!(r.kind, "image/png");
    // A second path: the f32 renderer's image, encoded.
    let scene = phong_scene::parse_scene_json(&small_scene(), &|_: &str| Err(String::new()))
        .expect("valid")
        .scene;
    let image = phong_raster::render(&scene, &phong_raster::RenderOptions::default()).expect("render");
    let (w, h, px) = decode(&r.body);
    assert_eq!((w, h), (64, 48));
    assert_eq!(px, image.to_bytes(scene.image.encoding, false));
    // The raw form: the same pixels as RGBA.
    let raw = call(&st, "POST", "/api/render?format=rgba", "a", small_scene().to_string()).await;
    assert_eq!(raw.status, StatusCode::OK);
    assert_eq!(raw.body, image.to_bytes(scene.image.encoding, true));
    let r = call(&st, "POST", "/api/render?format=gif", "a", small_scene().to_string()).await;
    assert_eq!(refused(&r), (400, "format".into(), String::new()));
}

#[tokio::test]
async fn every_class_of_bad_input_is_a_4xx_that_says_why() {
    let st = state();
    let bad = |body: &str| {
        let st = st.clone();
        let body = body.to_string();
        async move { call(&st, "POST", "/api/render", "a", body).await }
    };
    let r = bad("{\"image\": ").await;
    assert_eq!(r.status, StatusCode::BAD_REQUEST);
    assert!(
        r.json()["error"].as_str().unwrap_or("").contains("line 1"),
        "{}",
        r.json()
    );
    assert_eq!(refused(&bad("[1, 2]").await), (400, String::new(), String::new()));
    assert_eq!(refused(&bad("1e400").await).0, 400);
    let cases = [
        (json!({"image": {"widht": 3}}), "image.widht"),
        (json!({"image": {"width": "wide"}}), "image.width"),
        (json!({"image": {"width": -3}}), "image.width"),
        (json!({"image": {"antialias": 3}}), "image.antialias"),
        (json!({"camera": {"fov": null}}), "camera.fov"),
        (json!({"camera": {"position": [0, 0]}}), "camera.position"),
        (json!({"shading": {"model": "fong"}}), "shading.model"),
        (
            json!({"light": [{"type": "directional", "direction": [0, -1, 0]}, {"type": "point", "position": [0, 1, 0], "attenuation": [0, 0, 0]}]}),
            "light[1].attenuation",
        ),
        (
            json!({"light": [{"type": "spot", "position": [0, 1, 0], "direction": [0, -1, 0]}]}),
            "light[0].cutoff",
        ),
        (
            json!({"object": [{"shape": "sphere", "material": "gould"}]}),
            "object[0].material",
        ),
        (
            json!({"object": [{"shape": "sphere", "segments": 1}]}),
            "object[0].segments",
        ),
    ];
    for (scene, path) in cases {
        let r = render(&st, scene.clone()).await;
        assert_eq!(
            refused(&r),
            (400, path.to_string(), String::new()),
            "{scene}: {}",
            r.json()
        );
    }
}

#[tokio::test]
async fn a_mesh_path_in_a_request_is_never_opened() {
    let st = state();
    let manifest = concat!(env!("CARGO_MANIFEST_DIR"), "/Cargo.toml");
    for name in [manifest, "/etc/passwd", "../../examples/models/cube.obj", "Cargo.toml"] {
        let r = render(&st, json!({"object": [{"mesh": name}]})).await;
        let (status, path, _) = refused(&r);
        assert_eq!((status, path.as_str()), (400, "object[0].mesh"), "{name}");
        assert!(r.json()["error"].as_str().unwrap_or("").contains("upload it first"));
    }
}

#[tokio::test]
async fn every_limit_answers_which_limit() {
    let st = state();
    let big = format!("{{\"pad\": \"{}\"}}", "x".repeat(phong_core::limits::SERVE_MAX_BODY));
    assert_eq!(
        refused(&call(&st, "POST", "/api/render", "a", big).await),
        (413, String::new(), "SERVE_MAX_BODY".into())
    );
    let lights: Vec<Value> = (0..17)
        .map(|_| json!({"type": "directional", "direction": [0, -1, 0]}))
        .collect();
    assert_eq!(
        refused(&render(&st, json!({"light": lights})).await),
        (413, "light[16]".into(), "SERVE_MAX_LIGHTS".into())
    );
    assert_eq!(
        refused(&render(&st, json!({"image": {"width": 4000, "height": 3000}})).await),
        (413, "image".into(), "SERVE_MAX_PIXELS".into())
    );
    assert_eq!(
        refused(&render(&st, json!({"image": {"width": 3840, "height": 2160, "antialias": 16}})).await),
        (413, "image.antialias".into(), "SERVE_MAX_SAMPLES".into())
    );
    // 4096 segments would be 1 billion teapot triangles: refused before any is built.
    assert_eq!(
        refused(&render(&st, json!({"object": [{"shape": "teapot", "segments": 4096}]})).await),
        (413, "object[0].segments".into(), "SERVE_MAX_TRIANGLES".into())
    );
    // Shapes that each pass but together do not.
    let spheres: Vec<Value> = (0..3).map(|_| json!({"shape": "sphere", "segments": 1200})).collect();
    assert_eq!(
        refused(&render(&st, json!({"object": spheres})).await),
        (413, "object[2].segments".into(), "SERVE_MAX_TRIANGLES".into())
    );
}

#[tokio::test]
async fn uploads_are_per_client_in_memory_and_capped() {
    let st = state();
    let put = |client: &'static str, name: &str, body: &str| {
        let (st, uri, body) = (st.clone(), format!("/api/models/{name}"), body.to_string());
        async move { call(&st, "PUT", &uri, client, body).await }
    };
    let obj = "mtllib t.mtl\nusemtl red\nv -1 -1 0\nv 1 -1 0\nv 0 1 0\nf 1 2 3\n";
    let r = put("a", "t.mtl", "newmtl red\nKd 1 0 0\nKa 0 0 0\n").await;
    assert_eq!(r.status, StatusCode::CREATED);
    let r = put("a", "t.obj", obj).await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.json());
    assert_eq!(r.json()["triangles"], json!(1));
    let scene = json!({"image": {"width": 32, "height": 32},
        "camera": {"position": [0, 0, 3]},
        "light": [{"type": "directional", "direction": [0, 0, -1]}],
        "shading": {"ambient": [0, 0, 0]},
        "object": [{"mesh": "t.obj"}]});
    let r = call(&st, "POST", "/api/render", "a", scene.to_string()).await;
    assert_eq!(r.status, StatusCode::OK);
    let (_, _, px) = decode(&r.body);
    // The centre is the MTL's red, lit head-on: Kd·(N·L) = (1, 0, 0).
    let c = (16 * 32 + 16) * 3;
    assert_eq!(&px[c..c + 3], &[255, 0, 0]);
    // Another client does not see it.
    let r = call(&st, "POST", "/api/render", "b", scene.to_string()).await;
    assert_eq!(refused(&r).1, "object[0].mesh");
    let list = call(&st, "GET", "/api/models", "a", Body::empty()).await.json();
    assert_eq!(list["uploads"], json!(["t.mtl", "t.obj"]));
    // Names: no paths; models, their libraries and buffers, and images only.
    for name in ["..%2Fx.obj", "x.exe", ".hidden.obj", "a%2Fb.obj"] {
        let r = put("a", name, "v 0 0 0").await;
        assert_eq!(refused(&r).0, 400, "{name}");
    }
    // A broken OBJ is refused at upload, with its line.
    let r = put("a", "bad.obj", "v 1 2\n").await;
    assert_eq!(r.status, StatusCode::BAD_REQUEST);
    assert!(
        r.json()["error"].as_str().unwrap_or("").contains("bad.obj:1:"),
        "{}",
        r.json()
    );
    // At most SERVE_MAX_UPLOADS files.
    for i in 0..phong_core::limits::SERVE_MAX_UPLOADS - 2 {
        assert_eq!(
            put("a", &format!("m{i}.mtl"), "newmtl x\n").await.status,
            StatusCode::CREATED
        );
    }
    assert_eq!(
        refused(&put("a", "one-more.mtl", "newmtl x\n").await).2,
        "SERVE_MAX_UPLOADS"
    );
    // Deleting frees a place.
    assert_eq!(
        call(&st, "DELETE", "/api/models/m0.mtl", "a", Body::empty())
            .await
            .status,
        StatusCode::NO_CONTENT
    );
    assert_eq!(put("a", "one-more.mtl", "newmtl x\n").await.status, StatusCode::CREATED);
    // Larger than SERVE_MAX_UPLOAD.
    let huge = "#".repeat(phong_core::limits::SERVE_MAX_UPLOAD + 1);
    assert_eq!(refused(&put("c", "huge.obj", &huge).await).2, "SERVE_MAX_UPLOAD");
}

fn v3(v: &Value) -> [f64; 3] {
    [0, 1, 2].map(|i| v[i].as_f64().expect("a number"))
}

#[tokio::test]
async fn the_probe_gives_the_equations_numbers() {
    let st = state();
    // A unit sphere seen head-on, a white light from the viewer: at the centre N = L = V = z,
    // so N·L = R·V = N·H = 1 and the colour is a_m·a_g + d_m + s_m (clamped).
    let scene = json!({"image": {"width": 65, "height": 65},
        "camera": {"position": [0, 0, 5], "projection": "orthographic", "height": 3},
        "shading": {"model": "phong", "clamp": false},
        "light": [{"type": "directional", "direction": [0, 0, -1]}],
        "object": [{"shape": "sphere", "segments": 256, "material": "gold"}]});
    let r = call(
        &st,
        "POST",
        "/api/probe",
        "a",
        json!({"scene": scene, "x": 32, "y": 32}).to_string(),
    )
    .await;
    assert_eq!(r.status, StatusCode::OK);
    let p = r.json();
    let hit = &p["hit"];
    let gold = phong_core::Material::named("gold").expect("gold");
    let l = &hit["lights"][0];
    for k in ["n_dot_l", "r_dot_v", "n_dot_h", "spec"] {
        assert!((l[k].as_f64().expect(k) - 1.0).abs() < 1e-4, "{k}: {}", l[k]);
    }
    let want = [0, 1, 2].map(|i| {
        let c = |c: phong_core::Color| [c.r, c.g, c.b][i] as f64;
        c(gold.ambient()) * 0.2 + c(gold.diffuse()) + c(gold.specular())
    });
    let sum = v3(&hit["sum"]);
    for i in 0..3 {
        assert!(
            (sum[i] - want[i]).abs() < 1e-3,
            "channel {i}: {} vs {}",
            sum[i],
            want[i]
        );
    }
    assert!(
        (v3(&hit["position"])[2] - 1.0).abs() < 1e-3,
        "P on the sphere's front: {}",
        hit["position"]
    );
    // The background, outside the sphere.
    let r = call(
        &st,
        "POST",
        "/api/probe",
        "a",
        json!({"scene": scene, "x": 0, "y": 0}).to_string(),
    )
    .await;
    assert!(r.json()["hit"].is_null());
    // Bad pixels.
    for (body, path) in [
        (json!({"scene": scene, "x": 65, "y": 0}), "x"),
        (json!({"scene": scene, "x": 0, "y": -1}), "y"),
        (json!({"scene": scene, "y": 0}), "x"),
        (json!({"x": 0, "y": 0}), "scene"),
    ] {
        let r = call(&st, "POST", "/api/probe", "a", body.to_string()).await;
        assert_eq!(refused(&r), (400, path.to_string(), String::new()));
    }
}

#[tokio::test]
async fn the_lobe_is_the_closed_forms() {
    let st = state();
    let r = call(&st, "GET", "/api/lobe?shininess=20&squarings=4", "a", Body::empty()).await;
    assert_eq!(r.status, StatusCode::OK);
    let d = r.json();
    let get = |k: &str| {
        d[k].as_array()
            .expect(k)
            .iter()
            .map(|v| v.as_f64().expect("number"))
            .collect::<Vec<_>>()
    };
    let (angles, phong, blinn, lyon) = (get("angles"), get("phong"), get("blinn_phong"), get("lyon"));
    for (i, a) in angles.iter().enumerate() {
        let t = a.to_radians();
        // In the plane of incidence: R·V = cos θ, and H is θ/2 from N.
        assert!((phong[i] - t.cos().max(0.0).powf(20.0)).abs() < 1e-4, "phong at {a}");
        // (At θ = −90° V is −L: no half vector, factor 0.)
        let blinn_want = if *a == -90.0 { 0.0 } else { (t / 2.0).cos().powf(20.0) };
        assert!(
            (blinn[i] - blinn_want).abs() < 1e-4,
            "blinn at {a}: {} vs {blinn_want}",
            blinn[i]
        );
        let lyon_want = if t.cos() > 0.0 {
            (1.0 - 20.0 / 16.0 * (1.0 - t.cos())).max(0.0).powi(16)
        } else {
            0.0
        };
        assert!(
            (lyon[i] - lyon_want).abs() < 1e-4,
            "lyon at {a}: {} vs {lyon_want}",
            lyon[i]
        );
    }
    for q in ["shininess=-1", "shininess=abc", "incidence=90", "squarings=2.5"] {
        let r = call(&st, "GET", &format!("/api/lobe?{q}"), "a", Body::empty()).await;
        assert_eq!(refused(&r).0, 400, "{q}");
    }
}

#[tokio::test]
async fn renders_in_flight_are_limited_per_client_and_in_all() {
    let st = state();
    // Slow frames (1920x1080, 16 samples) so that they overlap.
    let slow = json!({"image": {"width": 1920, "height": 1080, "antialias": 4},
                      "object": [{"shape": "teapot", "segments": 20}]});
    let one_client: Vec<_> = (0..10)
        .map(|_| {
            let (st, s) = (st.clone(), slow.to_string());
            tokio::spawn(async move { call(&st, "POST", "/api/render", "same", s).await })
        })
        .collect();
    let mut codes = Vec::new();
    for t in one_client {
        let r = t.await.expect("task");
        if r.status != StatusCode::OK {
            assert_eq!(refused(&r), (429, String::new(), "SERVE_RENDERS_PER_CLIENT".into()));
        }
        codes.push(r.status.as_u16());
    }
    // All ten arrive while the first renders run (a frame takes tens of milliseconds).
    let ok = codes.iter().filter(|&&c| c == 200).count();
    assert!(
        (phong_core::limits::SERVE_RENDERS_PER_CLIENT..10).contains(&ok),
        "{codes:?}"
    );
    // Many clients: past SERVE_RENDERS_TOTAL in flight, 503 naming the limit.
    let many: Vec<_> = (0..40)
        .map(|i| {
            let (st, s) = (st.clone(), slow.to_string());
            tokio::spawn(async move { call(&st, "POST", "/api/render", &format!("c{i}"), s).await })
        })
        .collect();
    let mut busy = 0;
    for t in many {
        let r = t.await.expect("task");
        if r.status != StatusCode::OK {
            assert_eq!(refused(&r), (503, String::new(), "SERVE_RENDERS_TOTAL".into()));
            busy += 1;
        }
    }
    assert!(
        (1..=40 - phong_core::limits::SERVE_RENDERS_TOTAL).contains(&busy),
        "{busy} answered busy"
    );
}

#[tokio::test]
async fn twenty_clients_at_once_all_get_frames() {
    let st = state();
    let tasks: Vec<_> = (0..20)
        .map(|i| {
            let st = st.clone();
            tokio::spawn(async move {
                let mut sizes = Vec::new();
                for k in 0..3 {
                    let scene = json!({"image": {"width": 160 + 8 * k, "height": 90},
                        "object": [{"shape": "torus", "material": "jade"}]});
                    let r = call(&st, "POST", "/api/render", &format!("client-{i}"), scene.to_string()).await;
                    assert_eq!(r.status, StatusCode::OK);
                    sizes.push(decode(&r.body).0);
                }
                sizes
            })
        })
        .collect();
    for t in tasks {
        assert_eq!(t.await.expect("task"), vec![160, 168, 176]);
    }
}

#[tokio::test]
async fn the_probe_value_is_the_rendered_pixel() {
    let st = state();
    // Every interpolation and output, one sample: the probe's bytes are the PNG's, within 1.
    for (interp, output) in [
        ("phong", "color"),
        ("gouraud", "color"),
        ("flat", "color"),
        ("phong", "specular"),
        ("gouraud", "diffuse"),
        ("flat", "normal"),
        ("phong", "normal"),
        ("phong", "depth"),
    ] {
        let scene = json!({"image": {"width": 97, "height": 61},
            "camera": {"position": [1.5, 1.2, 3.5]},
            "shading": {"model": "blinn-phong", "interpolation": interp, "output": output, "two_sided": true},
            "light": [{"type": "point", "position": [2, 2, 2], "attenuation": [1, 0.2, 0.05]},
                      {"type": "spot", "position": [-1, 3, 1], "direction": [0.3, -1, -0.2], "cutoff": 35, "exponent": 4}],
            "object": [{"shape": "torus", "segments": 24, "material": "pearl"},
                       {"shape": "plane", "position": [0, -0.6, 0], "scale": 2, "material": "cyan_plastic"}]});
        let r = render(&st, scene.clone()).await;
        assert_eq!(r.status, StatusCode::OK);
        let (w, _, px) = decode(&r.body);
        let (mut hits, mut gouraud_vertices) = (0, 0);
        for k in 0..60u32 {
            let (x, y) = ((k * 37) % 97, (k * 23) % 61);
            let p = call(
                &st,
                "POST",
                "/api/probe",
                "a",
                json!({"scene": scene, "x": x, "y": y}).to_string(),
            )
            .await
            .json();
            let i = ((y * w + x) * 3) as usize;
            for c in 0..3 {
                let v = p["value8"][c].as_i64().expect("byte");
                assert!(
                    (i64::from(px[i + c]) - v).abs() <= 1,
                    "{interp}/{output} pixel ({x}, {y}) channel {c}: image {} probe {v}",
                    px[i + c]
                );
            }
            if !p["hit"].is_null() {
                hits += 1;
                gouraud_vertices += p["hit"]["vertices"].as_array().map_or(0, Vec::len);
            }
        }
        assert!(hits > 20, "{interp}/{output}: only {hits} probes hit");
        // Gouraud lit outputs report the three vertices the pixel interpolates.
        let lit = !matches!(output, "normal" | "depth");
        assert_eq!(gouraud_vertices > 0, interp == "gouraud" && lit, "{interp}/{output}");
    }
}

#[tokio::test]
async fn fit_recovers_the_material_of_a_rendered_target() {
    use base64::Engine;
    let st = state();
    let scene = |material: Value| {
        json!({"image": {"width": 96, "height": 96},
               "light": [{"type": "point", "position": [2, 2, 3]}],
               "object": [{"shape": "sphere", "segments": 48, "material": material}]})
    };
    let truth =
        json!({"ambient": [0.1, 0.05, 0.05], "diffuse": [0.6, 0.2, 0.1], "specular": [0.5, 0.5, 0.5], "shininess": 30});
    let target = render(&st, scene(truth)).await;
    assert_eq!(target.status, StatusCode::OK);
    let b64 = base64::engine::general_purpose::STANDARD.encode(&target.body);
    let body = json!({"scene": scene(json!("jade")), "object": 0, "target": b64});
    let r = call(&st, "POST", "/api/fit", "a", body.to_string()).await;
    assert_eq!(r.status, StatusCode::OK, "{}", String::from_utf8_lossy(&r.body));
    let f = r.json();
    let d = v3(&f["material"]["diffuse"]);
    assert!((d[0] - 0.6).abs() < 0.01 && (d[1] - 0.2).abs() < 0.01, "{d:?}");
    assert!((f["material"]["shininess"].as_f64().expect("s") / 30.0 - 1.0).abs() < 0.03);
    assert!(f["psnr"].as_f64().expect("psnr") > 40.0);
    assert!(f["comparison"].as_str().is_some_and(|c| !c.is_empty()));
    // Bad targets.
    for (target, object, path) in [
        (json!("not base64!"), json!(0), "target"),
        (json!(b64), json!(3), "object"),
    ] {
        let body = json!({"scene": scene(json!("jade")), "object": object, "target": target});
        let r = call(&st, "POST", "/api/fit", "a", body.to_string()).await;
        assert_eq!(refused(&r), (400, path.to_string(), String::new()));
    }
    let mut small = scene(json!("jade"));
    small["image"]["width"] = json!(64);
    let r = call(
        &st,
        "POST",
        "/api/fit",
        "a",
        json!({"scene": small, "target": b64}).to_string(),
    )
    .await;
    let (code, path, _) = refused(&r);
    assert_eq!((code, path.as_str()), (400, "target"));
    assert!(
        r.json()["error"].as_str().unwrap_or("").contains("96x96"),
        "{}",
        r.json()
    );
}

#[tokio::test]
async fn upload_limits_per_client_and_in_all() {
    let st = state();
    // SERVE_MAX_UPLOAD_TOTAL: three files just under SERVE_MAX_UPLOAD pass the client's total.
    let big = "#".repeat(phong_core::limits::SERVE_MAX_UPLOAD - 1);
    for i in 0..2 {
        let r = call(&st, "PUT", &format!("/api/models/big{i}.mtl"), "heavy", big.clone()).await;
        assert_eq!(r.status, StatusCode::CREATED);
    }
    let r = call(&st, "PUT", "/api/models/big2.mtl", "heavy", big.clone()).await;
    assert_eq!(refused(&r), (413, String::new(), "SERVE_MAX_UPLOAD_TOTAL".into()));
    // Replacing a file counts its new size only.
    let r = call(&st, "PUT", "/api/models/big1.mtl", "heavy", "newmtl x\n").await;
    assert_eq!(r.status, StatusCode::CREATED);
    // SERVE_MAX_CLIENTS: one more client than the store holds.
    for i in 1..phong_core::limits::SERVE_MAX_CLIENTS {
        let r = call(&st, "PUT", "/api/models/a.mtl", &format!("client{i}"), "newmtl a\n").await;
        assert_eq!(r.status, StatusCode::CREATED, "client {i}");
    }
    let r = call(&st, "PUT", "/api/models/a.mtl", "one-too-many", "newmtl a\n").await;
    assert_eq!(refused(&r), (503, String::new(), "SERVE_MAX_CLIENTS".into()));
    // SERVE_MAX_FIT_BODY.
    let body = format!(
        "{{\"target\": \"{}\"}}",
        "A".repeat(phong_core::limits::SERVE_MAX_FIT_BODY)
    );
    let r = call(&st, "POST", "/api/fit", "a", body).await;
    assert_eq!(refused(&r), (413, String::new(), "SERVE_MAX_FIT_BODY".into()));
}

/// PLY, STL and glTF uploads: a model of each kind is parsed at upload and answered with the
/// scene of the model alone; a glTF finds its external buffer among the client's uploads, and
/// one whose buffer was not uploaded is refused naming it.
#[tokio::test]
async fn ply_stl_and_gltf_uploads() {
    let st = state();
    let ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
               element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    let r = call(&st, "PUT", "/api/models/t.ply", "a", ply).await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.json());
    assert_eq!(r.json()["triangles"], json!(1));
    assert_eq!(r.json()["scene"]["object"][0]["fit"], json!(true));
    let stl = "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid t\n";
    let r = call(&st, "PUT", "/api/models/t.stl", "a", stl).await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.json());
    // A glTF triangle whose positions are in q.bin.
    let mut bin = Vec::new();
    for x in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
        bin.extend_from_slice(&x.to_le_bytes());
    }
    let gltf = r#"{"asset": {"version": "2.0"}, "buffers": [{"byteLength": 36, "uri": "q.bin"}],
        "bufferViews": [{"buffer": 0, "byteLength": 36}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0,0,0], "max": [1,1,0]}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}], "scene": 0}"#;
    let r = call(&st, "PUT", "/api/models/q.gltf", "a", gltf).await;
    assert_eq!(r.status, StatusCode::BAD_REQUEST, "{}", r.json());
    assert!(
        r.json()["error"]
            .as_str()
            .unwrap_or("")
            .contains("q.bin is not uploaded"),
        "{}",
        r.json()
    );
    assert_eq!(
        call(&st, "PUT", "/api/models/q.bin", "a", bin).await.status,
        StatusCode::CREATED
    );
    let r = call(&st, "PUT", "/api/models/q.gltf", "a", gltf).await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.json());
    assert_eq!(r.json()["triangles"], json!(1));
    // The answered scene renders, the triangle drawn (two-sided: it is open).
    let mut scene = r.json()["scene"].clone();
    scene["image"] = json!({"width": 32, "height": 24});
    let r = call(&st, "POST", "/api/render", "a", scene.to_string()).await;
    assert_eq!(r.status, StatusCode::OK);
    let (_, _, px) = decode(&r.body);
    let bg = px[..3].to_vec();
    assert!(px.chunks(3).filter(|p| *p != &bg[..]).count() > 20);
}

/// A textured scene (a sphere and a floor with a diffuse and a specular map, each
/// interpolation): the probe's value is the rendered pixel, within 1/255, bilinear and
/// trilinear (the probe's derivatives are central differences of rays, the renderer's exact),
/// and with the diffuse map on a second set of coordinates (the first scaled and shifted).
#[test]
fn the_probe_samples_textures_as_the_renderer() {
    use phong_core::glam::{Mat4, Quat, Vec2, Vec3};
    use phong_core::*;
    let texels: Vec<[u16; 4]> = (0..64u32)
        .map(|i| {
            let v = |k: u32| ((i * k + 17) % 256) as u16 * 257;
            [v(37), v(91), v(53), 65535]
        })
        .collect();
    let texture = std::sync::Arc::new(Texture::new(8, 8, &texels, 8).unwrap());
    let sphere = primitives::sphere(32).transformed(&Mat4::from_translation(Vec3::new(0.0, 0.3, 0.0)));
    let floor = primitives::plane(4).transformed(&Mat4::from_scale_rotation_translation(
        Vec3::splat(2.5),
        Quat::IDENTITY,
        Vec3::new(0.0, -0.8, 0.0),
    ));
    let base = phong_scene::parse_scene(
        "[image]\nwidth = 97\nheight = 61\n[camera]\nposition = [1.5, 1.2, 3.5]\n[[light]]\ntype = \"point\"\nposition = [2.0, 2.0, 2.0]\n[[object]]\nshape = \"cube\"\n",
        std::path::Path::new("probe.toml"),
    )
    .unwrap()
    .scene;
    for (sampler, repeat, tolerance, second) in [
        (Sampler::bilinear(Wrap::Repeat), 1.0, 1, false),
        (Sampler::trilinear(Wrap::Repeat), 6.0, 1, false),
        (Sampler::trilinear(Wrap::Repeat), 2.0, 1, true),
    ] {
        for interp in [Interpolation::Phong, Interpolation::Gouraud, Interpolation::Flat] {
            let mut scene = base.clone();
            let template = scene.objects[0].clone();
            scene.objects = [sphere.clone(), floor.clone()]
                .into_iter()
                .map(|mesh| {
                    let map = |t: &std::sync::Arc<Texture>, set: u8| TextureMap {
                        texture: t.clone(),
                        sampler,
                        transform: UvTransform::scale_offset(Vec2::splat(repeat), Vec2::ZERO),
                        set,
                    };
                    let mut o = template.clone();
                    let uvs1 = if second {
                        mesh.uvs().iter().map(|uv| *uv * Vec2::new(3.0, 2.0) + 0.25).collect()
                    } else {
                        Vec::new()
                    };
                    o.mesh = mesh.with_uvs1(uvs1).unwrap();
                    o.material = Material::named("pearl").unwrap();
                    o.shading.interpolation = interp;
                    o.maps = Maps {
                        diffuse: Some(map(&texture, u8::from(second))),
                        specular: Some(map(&texture, 0)),
                        ..Maps::default()
                    };
                    o
                })
                .collect();
            let image = phong_raster::render(&scene, &Default::default()).unwrap();
            let bytes = image.to_bytes(scene.image.encoding, false);
            let mut textured = 0;
            for k in 0..120u32 {
                let (x, y) = ((k * 37) % 97, (k * 23) % 61);
                let p = phong_serve::probe::probe(&scene, x, y);
                let i = ((y * 97 + x) * 3) as usize;
                for c in 0..3 {
                    let d = (i64::from(bytes[i + c]) - i64::from(p.value8[c])).abs();
                    assert!(
                        d <= tolerance,
                        "{interp:?} {:?} ({x}, {y}) channel {c}: off by {d}",
                        sampler.mip
                    );
                }
                textured += usize::from(p.hit.as_ref().is_some_and(|h| h.texture.is_some()));
            }
            assert!(textured > 40, "{interp:?}: {textured} textured hits");
        }
    }
}

/// An OBJ uploaded with its MTL and the PNG its `map_Kd` names: the page's scene renders it
/// textured (a green map on a white material, lit head-on, makes the quad green).
#[tokio::test]
async fn uploaded_textures_are_used() {
    let st = state();
    let green = phong_core::Image::new(2, 2, [0.0, 1.0, 0.0, 1.0]).expect("image");
    let png = phong_scene::encode_png(&green, phong_core::Encoding::Linear).expect("png");
    let put = |name: &str, body: Vec<u8>| {
        let (st, uri) = (st.clone(), format!("/api/models/{name}"));
        async move { call(&st, "PUT", &uri, "a", body).await }
    };
    assert_eq!(put("g.png", png).await.status, StatusCode::CREATED);
    let mtl = "newmtl m\nKd 1 1 1\nKa 0 0 0\nmap_Kd textures\\g.png\n";
    assert_eq!(put("q.mtl", mtl.into()).await.status, StatusCode::CREATED);
    let obj = "mtllib q.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl m\nf 1/1 2/2 3/3 4/4\n";
    let r = put("q.obj", obj.into()).await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.json());
    let scene = json!({"image": {"width": 32, "height": 32},
        "camera": {"position": [0, 0, 3]},
        "light": [{"type": "directional", "direction": [0, 0, -1]}],
        "shading": {"ambient": [0, 0, 0]},
        "object": [{"mesh": "q.obj"}]});
    let r = call(&st, "POST", "/api/render", "a", scene.to_string()).await;
    assert_eq!(r.status, StatusCode::OK);
    let (_, _, px) = decode(&r.body);
    let c = (16 * 32 + 16) * 3;
    assert_eq!(&px[c..c + 3], &[0, 255, 0]);
}

/// `POST /api/shader`: the scene's GLSL with its uniforms (the material's values), the page,
/// one object's program of a scene shaded two ways; bad targets and objects are 400s naming
/// the key, what a shader cannot express a 422 saying what.
#[tokio::test]
async fn shader_export_over_the_api() {
    let st = state();
    let r = call(&st, "POST", "/api/shader?target=glsl", "a", small_scene().to_string()).await;
    assert_eq!(r.status, StatusCode::OK, "{}", String::from_utf8_lossy(&r.body));
    let j = r.json();
    assert!(j["vertex"].as_str().is_some_and(|v| v.starts_with("#version 120")));
    assert!(j["fragment"].as_str().is_some_and(|f| f.contains("gl_FragColor")));
    // Ruby's shininess, from the built-in table (0.6 × 128 in OpenGL's units).
    let s = j["uniforms"]["objects"][0]["uniforms"]["uShininess"].as_f64().unwrap();
    assert!((s - 76.8).abs() < 1e-3, "{s}");
    let page = call(&st, "POST", "/api/shader?target=html", "a", small_scene().to_string()).await;
    assert_eq!(page.status, StatusCode::OK);
    assert!(page.kind.starts_with("text/html"));
    let mut two = small_scene();
    two["object"] = json!([{"shape": "sphere"}, {"shape": "cube", "interpolation": "flat"}]);
    let r = call(&st, "POST", "/api/shader?target=glsl300es", "a", two.to_string()).await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    assert!(r.json()["error"].as_str().unwrap().contains("shaded differently"));
    let r = call(
        &st,
        "POST",
        "/api/shader?target=glsl300es&object=1",
        "a",
        two.to_string(),
    )
    .await;
    assert_eq!(r.status, StatusCode::OK);
    assert!(r.json()["vertex"].as_str().unwrap().contains("triangleCentroid"));
    for (uri, path) in [
        ("/api/shader?target=hlsl", "target"),
        ("/api/shader?target=glsl&object=x", "object"),
    ] {
        let r = call(&st, "POST", uri, "a", small_scene().to_string()).await;
        assert_eq!(refused(&r), (400, path.to_string(), String::new()), "{uri}");
    }
    let r = call(
        &st,
        "POST",
        "/api/shader?target=glsl&object=7",
        "a",
        small_scene().to_string(),
    )
    .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
}
