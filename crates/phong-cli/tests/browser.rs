//! `phong serve` in a real browser: Debian's chromium driven through chromedriver (WebDriver),
//! headless, against the `phong` binary as a user starts it. Skipped with a printed reason
//! where chromium or chromedriver is missing; a failure under `PHONG_REQUIRE_BROWSER=1`.
//! A failing step saves a screenshot under the target directory's `tmp/browser-failures/`.

use anyhow::{Context, Result, anyhow, bail, ensure};
use base64::Engine;
use fantoccini::actions::{InputSource, MOUSE_BUTTON_LEFT, MouseActions, PointerAction};
use fantoccini::{Client, ClientBuilder, Locator};
use glam::{Vec3, Vec4Swizzles};
use serde_json::{Value, json};
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::Mutex;
use std::time::{Duration, Instant};

const CHROMIUM: &str = "/usr/bin/chromium";
const CHROMEDRIVER: &str = "/usr/bin/chromedriver";

/// One browser at a time: CI has two cores.
static BROWSER: Mutex<()> = Mutex::new(());

fn browser_available() -> bool {
    let ok = Path::new(CHROMIUM).exists() && Path::new(CHROMEDRIVER).exists();
    if !ok {
        if std::env::var("PHONG_REQUIRE_BROWSER").is_ok_and(|v| v == "1") {
            panic!("PHONG_REQUIRE_BROWSER=1 but {CHROMIUM} or {CHROMEDRIVER} is not installed");
        }
        eprintln!("skipped: {CHROMIUM} and {CHROMEDRIVER} are needed (apt-get install chromium chromium-driver)");
    }
    ok
}

/// A child process killed when dropped.
struct Proc(Child);
impl Drop for Proc {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// `phong serve` (extra arguments `args`) and its URL.
fn start_server(args: &[&str]) -> (Proc, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_phong"))
        .args(["serve", "--port", "0", "--threads", "2"])
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("phong serve starts");
    let mut line = String::new();
    BufReader::new(child.stdout.take().expect("stdout"))
        .read_line(&mut line)
        .expect("the URL line");
    (Proc(child), line.trim().to_string())
}

fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0")
        .and_then(|l| l.local_addr())
        .map(|a| a.port())
        .expect("a free port")
}

/// A page open in the browser, with its server and driver.
struct Page {
    client: Client,
    url: String,
    name: &'static str,
    _server: Proc,
    _driver: Proc,
    _profile: tempfile::TempDir,
}

async fn open(name: &'static str, query: &str, server_args: &[&str]) -> Result<Page> {
    open_sized(name, query, server_args, (1400, 1000)).await
}

async fn open_sized(name: &'static str, query: &str, server_args: &[&str], window: (u32, u32)) -> Result<Page> {
    let (server, url) = start_server(server_args);
    let (client, driver, profile) = browser(window).await?;
    client.goto(&format!("{url}{query}")).await?;
    let s = Page {
        client,
        url,
        name,
        _server: server,
        _driver: driver,
        _profile: profile,
    };
    s.idle().await?;
    s.js("window.phong.keepPng = true; window.phong.rerender(); return true;")
        .await?;
    s.idle().await?;
    Ok(s)
}

/// A headless chromium under chromedriver, its window `window` pixels.
async fn browser(window: (u32, u32)) -> Result<(Client, Proc, tempfile::TempDir)> {
    let port = free_port();
    let driver = Proc(
        Command::new(CHROMEDRIVER)
            .arg(format!("--port={port}"))
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .context("chromedriver starts")?,
    );
    let t0 = Instant::now();
    while std::net::TcpStream::connect(("127.0.0.1", port)).is_err() {
        ensure!(t0.elapsed() < Duration::from_secs(20), "chromedriver did not listen");
        std::thread::sleep(Duration::from_millis(50));
    }
    let profile = tempfile::tempdir()?;
    let mut caps = serde_json::Map::new();
    caps.insert(
        "goog:chromeOptions".into(),
        json!({"binary": CHROMIUM, "args": [
            "--headless=new", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
            "--disable-component-update", "--no-first-run", "--disable-quic", "--disable-sync",
            format!("--user-data-dir={}", profile.path().display()), format!("--window-size={},{}", window.0, window.1)]}),
    );
    let client = ClientBuilder::new(hyper_util::client::legacy::connect::HttpConnector::new())
        .capabilities(caps)
        .connect(&format!("http://127.0.0.1:{port}"))
        .await
        .map_err(|e| anyhow!("WebDriver: {e}"))?;
    Ok((client, driver, profile))
}

impl Page {
    async fn js(&self, script: &str) -> Result<Value> {
        Ok(self.client.execute(script, vec![]).await?)
    }

    /// Waits until the page has no frame in flight or due.
    async fn idle(&self) -> Result<()> {
        let t0 = Instant::now();
        loop {
            if self
                .js("return !!(window.phong && window.phong.idle && window.phong.idle());")
                .await?
                == json!(true)
            {
                return Ok(());
            }
            ensure!(t0.elapsed() < Duration::from_secs(30), "the page did not settle");
            tokio::time::sleep(Duration::from_millis(40)).await;
        }
    }

    /// The control whose visible label is `label` (its accessible name).
    async fn control(&self, label: &str) -> Result<fantoccini::elements::Element> {
        let l = self
            .client
            .find(Locator::XPath(&format!("//label[normalize-space(.)='{label}']")))
            .await
            .with_context(|| format!("a label \"{label}\""))?;
        let id = l
            .attr("for")
            .await?
            .with_context(|| format!("label \"{label}\" names its control"))?;
        Ok(self.client.find(Locator::Id(&id)).await?)
    }

    /// The last frame the page showed, as PNG bytes.
    async fn png(&self) -> Result<Vec<u8>> {
        let b64 = self.js("return window.phong.lastPng;").await?;
        let b64 = b64.as_str().context("a frame was shown")?;
        Ok(base64::engine::general_purpose::STANDARD.decode(b64)?)
    }

    /// Sets a range or colour input as dragging or picking does (`input` events).
    async fn set_input(&self, label: &str, value: &str) -> Result<()> {
        let el = self.control(label).await?;
        let id = el.attr("id").await?.context("an id")?;
        self.js(&format!(
            "const e = document.getElementById('{id}'); e.value = '{value}'; e.dispatchEvent(new Event('input', {{bubbles: true}})); return true;"
        ))
        .await?;
        Ok(())
    }

    async fn type_into(&self, label: &str, text: &str) -> Result<()> {
        let el = self.control(label).await?;
        el.clear().await?;
        el.send_keys(&format!("{text}\u{E004}")).await?; // Tab: `change` fires
        Ok(())
    }

    /// A pointer gesture as a user makes it: press at `at` from `element`'s centre, move by
    /// each of `moves` (`ms` milliseconds each), release. No moves: a click.
    async fn gesture(
        &self,
        element: fantoccini::elements::Element,
        at: (f64, f64),
        moves: &[(f64, f64)],
        ms: u64,
    ) -> Result<()> {
        let mut g = MouseActions::new("mouse".into())
            .then(PointerAction::MoveToElement {
                element,
                duration: None,
                x: at.0,
                y: at.1,
            })
            .then(PointerAction::Down {
                button: MOUSE_BUTTON_LEFT,
            });
        for &(x, y) in moves {
            g = g.then(PointerAction::MoveBy {
                duration: Some(Duration::from_millis(ms)),
                x,
                y,
            });
        }
        g = g.then(PointerAction::Up {
            button: MOUSE_BUTTON_LEFT,
        });
        Ok(self.client.perform_actions(g).await?)
    }

    async fn shot(&self, file: &Path) {
        if let Ok(png) = self.client.screenshot().await {
            let _ = std::fs::create_dir_all(file.parent().unwrap_or(Path::new(".")));
            let _ = std::fs::write(file, png);
        }
    }

    /// Runs a step; on failure saves a screenshot and fails the test with the step's name.
    async fn step<T>(&self, what: &str, f: impl std::future::Future<Output = Result<T>>) -> T {
        match f.await {
            Ok(v) => v,
            Err(e) => {
                let file = failures_dir().join(format!("{}-{}.png", self.name, what.replace(' ', "_")));
                self.shot(&file).await;
                panic!("{}: {what}: {e:#} (screenshot: {})", self.name, file.display());
            }
        }
    }
}

fn failures_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("browser-failures")
}

fn decode(png_bytes: &[u8]) -> Result<(u32, u32, Vec<u8>, usize)> {
    let dec = png::Decoder::new(std::io::Cursor::new(png_bytes));
    let mut r = dec.read_info()?;
    let mut buf = vec![0; r.output_buffer_size().context("size")?];
    let info = r.next_frame(&mut buf)?;
    buf.truncate(info.buffer_size());
    Ok((info.width, info.height, buf, info.color_type.samples()))
}

fn run<F: std::future::Future<Output = ()>>(f: F) {
    let _one = BROWSER.lock().unwrap_or_else(|e| e.into_inner());
    tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .expect("runtime")
        .block_on(f);
}

#[test]
fn every_control_changes_the_image() {
    if !browser_available() {
        return;
    }
    run(async {
        let s = open("controls", "?size=320x180", &[]).await.expect("the page opens");
        s.step("the page shows an image", async {
            let (w, h, ..) = decode(&s.png().await?)?;
            ensure!((w, h) == (320, 180), "frame {w}x{h}");
            let shown = s.js("return document.getElementById('frame').width;").await?;
            ensure!(shown == json!(320), "the canvas shows the frame: width {shown}");
            // The canvas holds the PNG's pixels.
            let canvas = s
                .js("const c = document.getElementById('frame'); return Array.from(c.getContext('2d').getImageData(0, 0, c.width, c.height).data);")
                .await?;
            let (_, _, px, n) = decode(&s.png().await?)?;
            let canvas: Vec<u8> = canvas.as_array().context("pixels")?.iter().map(|v| v.as_u64().unwrap_or(0) as u8).collect();
            ensure!(canvas.chunks(4).zip(px.chunks(n)).all(|(c, p)| c[..3] == p[..3]), "the canvas is not the PNG");
            Ok(())
        })
        .await;
        // (label, how to change it): each must change the picture.
        enum How {
            Select(&'static str),
            Input(&'static str),
            Click,
        }
        let changes = [
            ("Model", How::Select("blinn-phong")),
            ("Interpolation", How::Select("gouraud")),
            ("Interpolation", How::Select("flat")),
            ("Interpolation", How::Select("phong")),
            ("Shininess", How::Input("300")),
            ("Ambient", How::Input("#ff0000")),
            ("Diffuse", How::Input("#00ff00")),
            ("Specular", How::Input("#0000ff")),
            ("Emission", How::Input("#202000")),
            ("Material", How::Select("ruby")),
            ("Normalization", How::Select("phong")),
            ("Viewer", How::Select("infinite")),
            ("Output", How::Select("normal")),
            ("Output", How::Select("color")),
            ("Segments", How::Input("4")),
            ("Shape", How::Select("torus")),
            ("Antialias", How::Select("1")),
            ("Encoding", How::Select("srgb")),
            ("Light 1 type", How::Select("spot")),
            ("Light 1 per-term colours", How::Click),
            ("Light 1 diffuse", How::Input("#ff8000")),
            ("Add light", How::Click),
            ("Remove light", How::Click),
            ("Remove light", How::Click),
            ("Two-sided", How::Click),
        ];
        for (label, how) in changes {
            if label == "Two-sided" {
                // Two-sided shows where back faces are seen: a plane from below.
                s.step("a plane seen from below", async {
                    s.control("Shape").await?.select_by_value("plane").await?;
                    s.idle().await?;
                    s.js("const sc = window.phong.state.scene; sc.light = [{type: 'directional', direction: [0, 1, 0]}]; \
                          sc.camera.position = [0.5, -3, 3]; window.phong.rerender(); return true;")
                        .await?;
                    s.idle().await
                })
                .await;
            }
            if label == "Light 1 per-term colours" {
                // The same light in per-term form: the picture stays, the terms' inputs appear.
                s.step("per-term colours", async {
                    let before = s.png().await?;
                    s.control(label).await?.click().await?;
                    s.idle().await?;
                    for k in ["ambient", "diffuse", "specular"] {
                        s.control(&format!("Light 1 {k}")).await?;
                    }
                    ensure!(s.png().await? == before, "the same light changed the picture");
                    Ok(())
                })
                .await;
                continue;
            }
            let before = s.step("a frame before", s.png()).await;
            s.step(&format!("change {label}"), async {
                match how {
                    How::Select(v) => s.control(label).await?.select_by_value(v).await?,
                    How::Input(v) => s.set_input(label, v).await?,
                    How::Click => {
                        let el = match s.control(label).await {
                            Ok(e) => e,
                            Err(_) => {
                                s.client
                                    .find(Locator::XPath(&format!("//button[normalize-space(.)='{label}']")))
                                    .await?
                            }
                        };
                        el.click().await?
                    }
                }
                s.idle().await?;
                let after = s.png().await?;
                ensure!(after != before, "the image did not change");
                let err = s.js("return document.getElementById('error').textContent;").await?;
                ensure!(err == json!(""), "an error is shown: {err}");
                Ok(())
            })
            .await;
        }
    });
}

/// The highlight: the centroid of the pixels within 5% of the brightest.
fn brightest(png: &[u8]) -> Result<(f64, f64)> {
    let (w, _, px, n) = decode(png)?;
    let lum = |p: &[u8]| u32::from(p[0]) + u32::from(p[1]) + u32::from(p[2]);
    let max = px.chunks(n).map(lum).max().unwrap_or(0);
    let (mut sx, mut sy, mut count) = (0.0, 0.0, 0.0);
    for (i, p) in px.chunks(n).enumerate() {
        if lum(p) * 100 >= max * 95 {
            sx += f64::from(i as u32 % w);
            sy += f64::from(i as u32 / w);
            count += 1.0;
        }
    }
    Ok((sx / count, sy / count))
}

#[test]
fn dragging_a_light_moves_the_highlight() {
    if !browser_available() {
        return;
    }
    run(async {
        let s = open("drag", "?size=480x270", &[]).await.expect("the page opens");
        s.step("a sphere under one point light", async {
            s.control("Shape").await?.select_by_value("sphere").await?;
            s.idle().await?;
            s.client
                .find(Locator::XPath("//button[normalize-space(.)='Remove light']"))
                .await?
                .click()
                .await?;
            s.idle().await?;
            s.type_into("Light 1 position", "1.2, 1.6, 1.6").await?;
            s.idle().await
        })
        .await;
        let before = s.step("the highlight", async { brightest(&s.png().await?) }).await;
        s.step("drag the light's marker", async {
            let marker = s.client.find(Locator::Css("#markers [data-light='0'] circle")).await?;
            s.gesture(marker, (0.0, 0.0), &[(-12.0, 6.0); 12], 20).await?;
            s.idle().await
        })
        .await;
        s.step("the highlight moved with the light", async {
            let after = brightest(&s.png().await?)?;
            let moved = (after.0 - before.0).hypot(after.1 - before.1);
            ensure!(moved > 10.0, "highlight at {before:?} then {after:?}");
            ensure!(
                after.0 < before.0,
                "the light moved left, the highlight did not: {before:?} {after:?}"
            );
            let pos = s.js("return window.phong.state.scene.light[0].position;").await?;
            ensure!(pos[0].as_f64().unwrap_or(9.0) < 1.2, "light position {pos}");
            Ok(())
        })
        .await;
        s.step("orbit by dragging the image", async {
            let before = s.js("return window.phong.state.scene.camera.position;").await?;
            let png0 = s.png().await?;
            let frame = s.client.find(Locator::Id("frame")).await?;
            s.gesture(frame, (-150.0, -80.0), &[(60.0, 0.0)], 100).await?;
            s.idle().await?;
            let after = s.js("return window.phong.state.scene.camera.position;").await?;
            ensure!(after != before, "camera did not move");
            ensure!(s.png().await? != png0, "image did not change");
            Ok(())
        })
        .await;
    });
}

/// The page's Terms images, as RGBA bytes read back by a canvas.
async fn term_pixels(s: &Page) -> Result<Vec<Vec<u8>>> {
    let v = s
        .js(r#"
        return ['term-ambient', 'term-diffuse', 'term-specular', 'term-total'].map((id) => {
          const img = document.getElementById(id);
          const c = document.createElement('canvas');
          c.width = img.naturalWidth; c.height = img.naturalHeight;
          const ctx = c.getContext('2d');
          ctx.drawImage(img, 0, 0);
          return Array.from(ctx.getImageData(0, 0, c.width, c.height).data);
        });"#)
        .await?;
    let arr = v.as_array().context("four images")?;
    Ok(arr
        .iter()
        .map(|a| {
            a.as_array()
                .map(|a| a.iter().map(|x| x.as_u64().unwrap_or(0) as u8).collect())
                .unwrap_or_default()
        })
        .collect())
}

#[test]
fn terms_add_up_to_the_total() {
    if !browser_available() {
        return;
    }
    run(async {
        let s = open("terms", "?size=320x180", &[]).await.expect("the page opens");
        s.step("open Terms", async {
            // One sample: an edge pixel averaging a clamped colour would not add up.
            s.control("Antialias").await?.select_by_value("1").await?;
            s.idle().await?;
            s.client
                .find(Locator::XPath("//button[normalize-space(.)='Terms']"))
                .await?
                .click()
                .await?;
            s.idle().await
        })
        .await;
        s.step("ambient + diffuse + specular = total where nothing clamps", async {
            let px = term_pixels(&s).await?;
            ensure!(
                px.len() == 4 && px.iter().all(|p| p.len() == px[0].len() && !p.is_empty()),
                "four images"
            );
            let (mut checked, mut worst) = (0, 0i32);
            for i in (0..px[0].len()).step_by(4) {
                for k in 0..3 {
                    let (a, d, sp, t) = (px[0][i + k], px[1][i + k], px[2][i + k], px[3][i + k]);
                    // The terms and total are each rounded to 8 bits: the sum is within 2.
                    if t < 250 && a < 255 && d < 255 && sp < 255 {
                        let e = (i32::from(a) + i32::from(d) + i32::from(sp) - i32::from(t)).abs();
                        worst = worst.max(e);
                        checked += 1;
                    }
                }
            }
            ensure!(checked > 10_000, "only {checked} channels checked");
            ensure!(worst <= 2, "a channel's terms differ from its total by {worst}/255");
            // The terms are not trivially zero: diffuse and specular carry light.
            let sum = |p: &Vec<u8>| p.iter().map(|&x| u64::from(x)).sum::<u64>();
            ensure!(
                sum(&px[1]) > sum(&px[0]) && sum(&px[2]) > 0,
                "diffuse and specular are lit"
            );
            Ok(())
        })
        .await;
        s.step("the terms follow the controls", async {
            let before = term_pixels(&s).await?;
            s.control("Specular").await?;
            s.set_input("Specular", "#000000").await?;
            s.idle().await?;
            let after = term_pixels(&s).await?;
            ensure!(after[2].chunks(4).all(|p| p[..3] == [0, 0, 0]), "no specular left");
            ensure!(after[3] != before[3], "total changed");
            Ok(())
        })
        .await;
        s.step("Compare and Lobe views draw", async {
            s.client
                .find(Locator::XPath("//button[normalize-space(.)='Compare']"))
                .await?
                .click()
                .await?;
            s.idle().await?;
            let legend = s
                .js("return document.getElementById('compare-legend').textContent;")
                .await?;
            ensure!(
                legend.as_str().unwrap_or("").contains("Blinn-Phong at 4s"),
                "legend {legend}"
            );
            s.control("Difference").await?.click().await?;
            s.idle().await?;
            let legend = s
                .js("return document.getElementById('compare-legend').textContent;")
                .await?;
            ensure!(
                legend.as_str().unwrap_or("").contains("largest difference"),
                "legend {legend}"
            );
            s.client
                .find(Locator::XPath("//button[normalize-space(.)='Lobe']"))
                .await?
                .click()
                .await?;
            s.idle().await?;
            let lobe = s.js("return window.phong.lobe;").await?;
            // Phong's lobe in the plane of incidence is cos(θ)^s (here s = 51.2, gold).
            let s_ = lobe["shininess"].as_f64().context("shininess")?;
            for (a, v) in lobe["angles"]
                .as_array()
                .context("angles")?
                .iter()
                .zip(lobe["phong"].as_array().context("phong")?)
            {
                let (a, v) = (a.as_f64().unwrap_or(0.0), v.as_f64().unwrap_or(0.0));
                let want = a.to_radians().cos().max(0.0).powf(s_);
                ensure!((v - want).abs() < 1e-4, "phong lobe at {a}°: {v} vs cos^s {want}");
            }
            Ok(())
        })
        .await;
    });
}

#[test]
fn probe_agrees_with_phong_core_and_the_pixel() {
    if !browser_available() {
        return;
    }
    run(async {
        let s = open("probe", "?size=320x180", &[]).await.expect("the page opens");
        s.step("one sample per pixel", async {
            s.control("Antialias").await?.select_by_value("1").await?;
            s.idle().await
        })
        .await;
        let p = s
            .step("click a pixel of the teapot", async {
                let frame = s.client.find(Locator::Id("frame")).await?;
                let (_, _, w, h) = frame.rectangle().await?;
                // 10 pixels right of the image's centre, in CSS pixels of the shown image.
                s.gesture(frame, (10.0 * w / 320.0, 0.0), &[], 0).await?;
                let t0 = Instant::now();
                loop {
                    let p = s.js("return window.phong.probe || null;").await?;
                    if !p.is_null() {
                        let eq = s
                            .js("return document.getElementById('probe-equation').textContent;")
                            .await?;
                        ensure!(
                            eq.as_str().unwrap_or("").contains("c = e_m + a_m·a_g"),
                            "equation shown: {eq}"
                        );
                        let _ = h;
                        return Ok(p);
                    }
                    ensure!(t0.elapsed() < Duration::from_secs(10), "no probe answer");
                    tokio::time::sleep(Duration::from_millis(50)).await;
                }
            })
            .await;
        let scene_json = s
            .step("the shown scene", s.js("return window.phong.state.shown;"))
            .await;
        let png_bytes = s.step("the shown frame", s.png()).await;
        s.step("the probe's numbers are phong-core's", async {
            let (x, y) = (
                p["x"].as_u64().context("x")? as u32,
                p["y"].as_u64().context("y")? as u32,
            );
            ensure!((155..=175).contains(&x) && (80..=100).contains(&y), "pixel ({x}, {y})");
            let hit = &p["hit"];
            ensure!(hit["name"] == json!("teapot"), "hit {hit}");
            // The pixel the page shows, within 1/255 of the probe's value.
            let (w, _, px, n) = decode(&png_bytes)?;
            let i = ((y * w + x) as usize) * n;
            for k in 0..3 {
                let v = p["value8"][k].as_i64().context("value8")?;
                ensure!(
                    (i64::from(px[i + k]) - v).abs() <= 1,
                    "channel {k}: pixel {} vs probe {v}",
                    px[i + k]
                );
            }
            // The shaded point projects to the pixel's centre.
            let scene = phong_scene::parse_scene_json(&scene_json, &|_: &str| Err("no meshes".to_string()))
                .map_err(|e| anyhow!("{e}"))?
                .scene;
            let v3 = |v: &Value| -> Result<Vec3> {
                Ok(Vec3::new(
                    v[0].as_f64().context("x")? as f32,
                    v[1].as_f64().context("y")? as f32,
                    v[2].as_f64().context("z")? as f32,
                ))
            };
            let pos = v3(&hit["position"])?;
            let clip = scene.camera.clip_from_world(320.0 / 180.0) * pos.extend(1.0);
            let ndc = clip.xy() / clip.w;
            let (sx, sy) = ((ndc.x + 1.0) * 160.0, (1.0 - ndc.y) * 90.0);
            ensure!(
                (sx - (x as f32 + 0.5)).abs() < 0.01 && (sy - (y as f32 + 0.5)).abs() < 0.01,
                "P projects to ({sx}, {sy})"
            );
            // shade() at the probe's point and normal gives the probe's terms.
            let obj = &scene.objects[hit["object"].as_u64().context("object")? as usize];
            let normal = v3(&hit["normal"])?;
            let view = scene.camera.view(obj.shading.viewer);
            let sh = phong_core::shade(
                &phong_core::SurfacePoint { position: pos, normal },
                &view,
                &obj.material,
                &scene.lighting,
                &obj.shading.options,
            );
            for (key, c) in [
                ("ambient", sh.ambient),
                ("diffuse", sh.diffuse),
                ("specular", sh.specular),
                ("color", sh.color),
            ] {
                let got = v3(&hit[key])?;
                ensure!(
                    (got - Vec3::new(c.r, c.g, c.b)).abs().max_element() < 1e-5,
                    "{key}: {got} vs shade {c:?}"
                );
            }
            // Per light: N·L from the scene's own light, and the terms sum to the totals.
            let n = normal.normalize();
            let mut diffuse = Vec3::ZERO;
            for (l, light) in hit["lights"]
                .as_array()
                .context("lights")?
                .iter()
                .zip(scene.lighting.lights())
            {
                let to_light = light.incidence(pos).to_light;
                let ndl = l["n_dot_l"].as_f64().context("n_dot_l")? as f32;
                ensure!((ndl - n.dot(to_light)).abs() < 1e-5, "N·L {ndl} vs {}", n.dot(to_light));
                diffuse += v3(&l["diffuse"])?;
            }
            ensure!(
                (diffuse - v3(&hit["diffuse"])?).abs().max_element() < 1e-5,
                "per-light diffuse sums"
            );
            Ok(())
        })
        .await;
    });
}

#[test]
fn downloaded_toml_renders_the_page_image_byte_for_byte() {
    if !browser_available() {
        return;
    }
    run(async {
        let s = open("toml", "?size=400x240", &[]).await.expect("the page opens");
        s.step("change a few things", async {
            s.control("Material").await?.select_by_value("polished_bronze").await?;
            s.idle().await?;
            s.control("Model").await?.select_by_value("blinn-phong").await?;
            s.idle().await?;
            s.set_input("Shininess", "500").await?;
            s.idle().await?;
            s.client
                .find(Locator::XPath("//button[normalize-space(.)='Add light']"))
                .await?
                .click()
                .await?;
            s.idle().await?;
            let frame = s.client.find(Locator::Id("frame")).await?;
            s.gesture(frame, (0.0, 0.0), &[(40.0, 15.0)], 100).await?;
            s.idle().await
        })
        .await;
        let dir = tempfile::tempdir().expect("tmp");
        s.step("render the TOML with phong render", async {
            s.client
                .find(Locator::XPath("//button[normalize-space(.)='Download TOML']"))
                .await?
                .click()
                .await?;
            let t0 = Instant::now();
            let toml = loop {
                let t = s.js("return window.phong.lastToml || null;").await?;
                if let Some(t) = t.as_str() {
                    break t.to_string();
                }
                ensure!(t0.elapsed() < Duration::from_secs(10), "no TOML");
                tokio::time::sleep(Duration::from_millis(50)).await;
            };
            let file = dir.path().join("scene.toml");
            std::fs::write(&file, &toml)?;
            let out = dir.path().join("out.png");
            let st = Command::new(env!("CARGO_BIN_EXE_phong"))
                .arg("render")
                .arg(&file)
                .arg("-o")
                .arg(&out)
                .output()?;
            ensure!(
                st.status.success(),
                "phong render: {}",
                String::from_utf8_lossy(&st.stderr)
            );
            let page = s.png().await?;
            let cli = std::fs::read(&out)?;
            ensure!(
                page == cli,
                "the page's PNG ({} bytes) is not phong render's ({} bytes)",
                page.len(),
                cli.len()
            );
            ensure!(
                toml.contains("shininess = 31.62") && toml.contains("model = \"blinn-phong\""),
                "{toml}"
            );
            Ok(())
        })
        .await;
        s.step("the URL reproduces the view", async {
            let before = s.png().await?;
            let href = s.js("return location.href;").await?;
            s.client.goto(href.as_str().context("href")?).await?;
            s.idle().await?;
            s.js("window.phong.keepPng = true; window.phong.rerender(); return true;")
                .await?;
            s.idle().await?;
            ensure!(s.png().await? == before, "the link shows another image");
            Ok(())
        })
        .await;
    });
}

#[test]
fn loading_an_obj_renders_it() {
    if !browser_available() {
        return;
    }
    let dir = tempfile::tempdir().expect("tmp");
    let obj = dir.path().join("box.obj");
    let mtl = dir.path().join("box.mtl");
    let mut text = String::from("mtllib box.mtl\nusemtl red\n");
    for z in [-1, 1] {
        for y in [-1, 1] {
            for x in [-1, 1] {
                text.push_str(&format!("v {x} {y} {z}\n"));
            }
        }
    }
    text.push_str("f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n");
    std::fs::write(&obj, text).expect("obj");
    std::fs::write(&mtl, "newmtl red\nKa 0.2 0 0\nKd 0.9 0 0\nKs 0.5 0.5 0.5\nNs 40\n").expect("mtl");
    run(async {
        let s = open("obj", "?size=320x180", &[]).await.expect("the page opens");
        s.step("load box.obj and box.mtl", async {
            let input = s.client.find(Locator::Id("load-model")).await?;
            input
                .send_keys(&format!("{}\n{}", obj.display(), mtl.display()))
                .await?;
            let t0 = Instant::now();
            loop {
                let st = s.js("return window.phong.loaded || null;").await?;
                if st["name"] == json!("box.obj") {
                    ensure!(st["triangles"] == json!(12), "loaded {st}");
                    break;
                }
                let e = s.js("return document.getElementById('error').textContent;").await?;
                ensure!(t0.elapsed() < Duration::from_secs(10), "not loaded: {e}");
                tokio::time::sleep(Duration::from_millis(50)).await;
            }
            s.idle().await?;
            let (_, _, px, n) = decode(&s.png().await?)?;
            let red = px.chunks(n).filter(|p| p[0] > 60 && p[1] < 30 && p[2] < 30).count();
            ensure!(red > 2000, "only {red} red pixels");
            let shapes = s
                .js("return [...document.getElementById('shape').options].map(o => o.value);")
                .await?;
            ensure!(
                shapes.as_array().is_some_and(|a| a.contains(&json!("box.obj"))),
                "Shape lists it: {shapes}"
            );
            Ok(())
        })
        .await;
        s.step("drop an OBJ on the viewport", async {
            // A drop event carrying a file, as dragging one from a file manager gives.
            s.js(r#"
                const obj = 'v -1 -1 0\nv 1 -1 0\nv 0 1 0\nf 1 2 3\n';
                const dt = new DataTransfer();
                dt.items.add(new File([obj], 'tri.obj'));
                document.getElementById('viewport').dispatchEvent(new DragEvent('drop', {dataTransfer: dt, bubbles: true}));
                return true;"#)
                .await?;
            let t0 = Instant::now();
            loop {
                let st = s.js("return window.phong.loaded || null;").await?;
                if st["name"] == json!("tri.obj") {
                    ensure!(st["triangles"] == json!(1), "loaded {st}");
                    break;
                }
                ensure!(t0.elapsed() < Duration::from_secs(10), "the dropped model did not load");
                tokio::time::sleep(Duration::from_millis(50)).await;
            }
            s.idle().await
        })
        .await;
        s.step("a textured OBJ: the probe shows its texels", async {
            let dir = obj.parent().context("dir")?;
            std::fs::write(
                dir.join("quad.obj"),
                "mtllib quad.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl t\nf 1/1 2/2 3/3 4/4\n",
            )?;
            std::fs::write(dir.join("quad.mtl"), "newmtl t\nKa 1 1 1\nKd 1 1 1\nmap_Kd green.png\n")?;
            let f = std::fs::File::create(dir.join("green.png"))?;
            let mut e = png::Encoder::new(std::io::BufWriter::new(f), 2, 2);
            e.set_color(png::ColorType::Rgb);
            e.write_header()?.write_image_data(&[0, 200, 0].repeat(4))?;
            s.client
                .find(Locator::Id("load-model"))
                .await?
                .send_keys(&format!(
                    "{}\n{}\n{}",
                    dir.join("quad.obj").display(),
                    dir.join("quad.mtl").display(),
                    dir.join("green.png").display()
                ))
                .await?;
            let t0 = Instant::now();
            while s.js("return (window.phong.loaded || {}).name || null;").await? != json!("quad.obj") {
                ensure!(t0.elapsed() < Duration::from_secs(10), "quad.obj not loaded");
                tokio::time::sleep(Duration::from_millis(50)).await;
            }
            s.idle().await?;
            s.js("window.phong.probe = null; return true;").await?;
            let frame = s.client.find(Locator::Id("frame")).await?;
            // Beside the centre, where the headlight's marker is.
            s.gesture(frame, (25.0, 20.0), &[], 0).await?;
            let t0 = Instant::now();
            loop {
                let p = s.js("return window.phong.probe || null;").await?;
                if !p.is_null() {
                    let t = &p["hit"]["texture"];
                    ensure!(t["diffuse"][1].as_f64().is_some_and(|g| (g - 200.0 / 255.0).abs() < 1e-3), "texels {t}");
                    let body = s.js("return document.getElementById('probe-body').textContent;").await?;
                    let body = body.as_str().unwrap_or("");
                    ensure!(body.contains("TKd") && body.contains("uv"), "the panel shows the texels: {body}");
                    return Ok(());
                }
                ensure!(t0.elapsed() < Duration::from_secs(10), "no probe answer");
                tokio::time::sleep(Duration::from_millis(50)).await;
            }
        })
        .await;
        s.step("a broken OBJ says why", async {
            let bad = obj.with_file_name("bad.obj");
            std::fs::write(&bad, "v 1 2\nf 1 2 3\n")?;
            s.client
                .find(Locator::Id("load-model"))
                .await?
                .send_keys(&bad.display().to_string())
                .await?;
            let t0 = Instant::now();
            loop {
                let e = s
                    .js("return document.querySelector('.err[data-for=\"load-model\"]').textContent;")
                    .await?;
                if e.as_str().unwrap_or("").contains("bad.obj") {
                    ensure!(
                        e.as_str().unwrap_or("").contains(":1:"),
                        "the message names the line: {e}"
                    );
                    return Ok(());
                }
                ensure!(t0.elapsed() < Duration::from_secs(10), "no error shown");
                tokio::time::sleep(Duration::from_millis(50)).await;
            }
        })
        .await;
    });
}

#[test]
fn bad_values_are_explained_next_to_their_control() {
    if !browser_available() {
        return;
    }
    run(async {
        let s = open("errors", "?size=320x180", &[]).await.expect("the page opens");
        let slot = |id: &'static str| {
            let s = &s;
            async move {
                let v = s
                    .js(&format!(
                        "return document.querySelector('.err[data-for=\"{id}\"]').textContent;"
                    ))
                    .await?;
                Ok::<String, anyhow::Error>(v.as_str().unwrap_or("").to_string())
            }
        };
        s.step("a position that is not 3 numbers", async {
            s.type_into("Light 1 position", "1, two, 3").await?;
            s.idle().await?;
            let m = slot("light-1-position").await?;
            ensure!(m.contains("expected 3 numbers"), "message: {m:?}");
            Ok(())
        })
        .await;
        s.step("an attenuation the model refuses", async {
            s.type_into("Light 1 attenuation", "0, 0, 0").await?;
            s.idle().await?;
            let m = slot("light-1-attenuation").await?;
            ensure!(m.contains("constant"), "message: {m:?}");
            let e = s.js("return document.getElementById('error').textContent;").await?;
            ensure!(
                e.as_str().unwrap_or("").starts_with("light[0].attenuation"),
                "error line: {e}"
            );
            s.type_into("Light 1 attenuation", "1, 0, 0").await?;
            s.idle().await?;
            ensure!(slot("light-1-attenuation").await?.is_empty(), "the message clears");
            Ok(())
        })
        .await;
        s.step("opengl with normalization", async {
            s.control("Normalization").await?.select_by_value("phong").await?;
            s.idle().await?;
            s.control("Model").await?.select_by_value("opengl").await?;
            s.idle().await?;
            let m = slot("normalization").await?;
            ensure!(m.contains("no normalization"), "message: {m:?}");
            Ok(())
        })
        .await;
        let _ = &s.url;
    });
}

#[test]
fn fitting_a_target_image_in_the_page() {
    if !browser_available() {
        return;
    }
    let dir = tempfile::tempdir().expect("tmp");
    run(async {
        let s = open("fit", "?size=240x160", &[]).await.expect("the page opens");
        let ruby = phong_core::Material::named("ruby").expect("ruby");
        let target = dir.path().join("target.png");
        s.step("a target: the scene with ruby", async {
            s.control("Material").await?.select_by_value("ruby").await?;
            s.idle().await?;
            std::fs::write(&target, s.png().await?)?;
            s.control("Material").await?.select_by_value("jade").await?;
            s.idle().await
        })
        .await;
        s.step("fit and apply", async {
            s.client
                .find(Locator::XPath("//button[normalize-space(.)='Fit']"))
                .await?
                .click()
                .await?;
            s.client
                .find(Locator::Id("fit-target"))
                .await?
                .send_keys(&target.display().to_string())
                .await?;
            s.client.find(Locator::Id("fit-run")).await?.click().await?;
            let t0 = Instant::now();
            while s.js("return window.phong.fit || null;").await?.is_null() {
                let e = s
                    .js("return document.querySelector('.err[data-for=\"fit-target\"]').textContent;")
                    .await?;
                ensure!(t0.elapsed() < Duration::from_secs(20), "no fit: {e}");
                tokio::time::sleep(Duration::from_millis(50)).await;
            }
            let text = s
                .js("return document.getElementById('fit-result').textContent;")
                .await?;
            ensure!(text.as_str().unwrap_or("").contains("psnr"), "{text}");
            s.client.find(Locator::Id("fit-apply")).await?.click().await?;
            s.idle().await?;
            let m = s.js("return window.phong.state.scene.object[0].material;").await?;
            let d = m["diffuse"].as_array().context("diffuse")?;
            for (k, want) in [ruby.diffuse().r, ruby.diffuse().g, ruby.diffuse().b]
                .iter()
                .enumerate()
            {
                let got = d[k].as_f64().context("number")?;
                ensure!(
                    (got - f64::from(*want)).abs() < 0.02,
                    "diffuse[{k}] {got} vs ruby's {want}"
                );
            }
            let sh = m["shininess"].as_f64().context("shininess")?;
            ensure!((sh / f64::from(ruby.shininess()) - 1.0).abs() < 0.05, "shininess {sh}");
            Ok(())
        })
        .await;
    });
}

/// README's picture of the page: the default scene with a probed pixel, saved as
/// `$PHONG_SCREENSHOT_DIR/explorer.png`.
#[test]
#[ignore = "writes README's screenshot: PHONG_SCREENSHOT_DIR=docs/images cargo test -p phong-cli --test browser readme -- --ignored"]
fn readme_screenshot() {
    if !browser_available() {
        return;
    }
    let dir = std::env::var("PHONG_SCREENSHOT_DIR").unwrap_or_else(|_| env!("CARGO_TARGET_TMPDIR").to_string());
    run(async {
        let s = open_sized("readme", "", &[], (1500, 1500))
            .await
            .expect("the page opens");
        s.step("probe the teapot", async {
            let frame = s.client.find(Locator::Id("frame")).await?;
            s.gesture(frame, (30.0, -40.0), &[], 0).await?;
            let t0 = Instant::now();
            while s.js("return window.phong.probe || null;").await?.is_null() {
                ensure!(t0.elapsed() < Duration::from_secs(10), "no probe answer");
                tokio::time::sleep(Duration::from_millis(50)).await;
            }
            s.idle().await
        })
        .await;
        s.shot(&Path::new(&dir).join("explorer.png")).await;
    });
}

/// The latency benchmark (BENCHMARKS.md): drag the Shininess slider for `PHONG_BENCH_MOVES`
/// moves at 1280x720 and print the median and 95th percentile from input to painted frame.
#[test]
#[ignore = "a benchmark: cargo test --release -p phong-cli --test browser -- --ignored --nocapture"]
fn bench_slider_latency() {
    if !browser_available() {
        return;
    }
    run(async {
        // A window wide enough to show the 1280x720 frame at its own size beside the panel.
        let query = format!(
            "?size=1280x720{}",
            std::env::var("PHONG_BENCH_QUERY").unwrap_or_default()
        );
        let s = open_sized("bench", &query, &[], (1720, 1100))
            .await
            .expect("the page opens");
        let moves: usize = std::env::var("PHONG_BENCH_MOVES")
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(120);
        s.step("drag the slider", async {
            s.js("window.phong.keepPng = false; window.phong.frames.length = 0; return true;").await?;
            let slider = s.control("Shininess").await?;
            s.gesture(slider, (-40.0, 0.0), &(0..moves).map(|i| { let dx = if (i / 40) % 2 == 0 { 2.0 } else { -2.0 }; (dx, 0.0) }).collect::<Vec<_>>(), 16).await?;
            s.idle().await?;
            let frames = s.js("return window.phong.frames;").await?;
            let mut ms: Vec<f64> = frames
                .as_array()
                .context("frames")?
                .iter()
                .filter(|f| f["preview"] == json!(true))
                .filter_map(|f| f["ms"].as_f64())
                .collect();
            let mut render: Vec<f64> = frames
                .as_array()
                .context("frames")?
                .iter()
                .filter(|f| f["preview"] == json!(true))
                .filter_map(|f| f["render_ms"].as_f64())
                .collect();
            if ms.is_empty() {
                bail!("no frames");
            }
            for k in ["wait", "response", "body", "decode", "paint", "bytes"] {
                let mut v: Vec<f64> = frames
                    .as_array()
                    .context("frames")?
                    .iter()
                    .filter(|f| f["preview"] == json!(true))
                    .filter_map(|f| f[k].as_f64())
                    .collect();
                v.sort_by(f64::total_cmp);
                if !v.is_empty() {
                    println!("  {k}: median {:.1}", v[v.len() / 2]);
                }
            }
            ms.sort_by(f64::total_cmp);
            render.sort_by(f64::total_cmp);
            let q = |v: &[f64], p: f64| v[((v.len() - 1) as f64 * p).round() as usize];
            println!(
                "phong serve latency, 1280x720 ({query}), preview frames of {}x{} while dragging: frames={} median={:.1}ms p95={:.1}ms max={:.1}ms (server parse+render median={:.1}ms)",
                frames[0]["w"],
                frames[0]["h"],
                ms.len(),
                q(&ms, 0.5),
                q(&ms, 0.95),
                q(&ms, 1.0),
                q(&render, 0.5)
            );
            Ok(())
        })
        .await;
    });
}

/// Scenes over the model's options, each drawn by `phong shader --target html` in chromium's
/// WebGL2 and by `phong render` at one sample: the canvas's pixels within 2/255 of phong's on
/// at least 99.5% of the pixels (where they differ: triangle edges, which WebGL's rasteriser
/// and phong's decide by their own rules).
#[test]
fn exported_html_draws_phongs_pixels() {
    if !browser_available() {
        return;
    }
    let dir = tempfile::tempdir().expect("tempdir");
    let lights = [
        "[[light]]\ntype = \"directional\"\ndirection = [-1.0, -1.0, -1.5]\n",
        "[[light]]\ntype = \"point\"\nposition = [2.0, 2.0, 3.0]\nattenuation = [1.0, 0.05, 0.01]\n\
         [[light]]\ntype = \"directional\"\ndirection = [1.0, 0.2, -1.0]\ncolor = [0.3, 0.3, 0.5]\n",
        "[[light]]\ntype = \"spot\"\nposition = [0.0, 3.0, 3.0]\ndirection = [0.0, -1.0, -1.0]\ncutoff = 30.0\nexponent = 4.0\n",
    ];
    let cameras = [
        "[camera]\nposition = [0.5, 1.0, 4.0]\ntarget = [0.0, 0.0, 0.0]\nfov = 45.0\n",
        "[camera]\nprojection = \"orthographic\"\nposition = [0.0, 0.0, 10.0]\nheight = 3.2\n",
    ];
    let shadings = [
        "model = \"phong\"",
        "model = \"blinn-phong\"\ninterpolation = \"gouraud\"",
        "model = \"lambert\"",
        "model = \"phong-lyon\"",
        "model = \"blinn-phong\"\nnormalization = \"blinn-phong\"",
        "model = \"phong\"\noutput = \"specular\"",
        "model = \"opengl\"\ntwo_sided = true",
        "model = \"blinn-phong\"\ninterpolation = \"flat\"\ntwo_sided = true",
    ];
    let mut scenes = Vec::new();
    for (k, shading) in shadings.iter().enumerate() {
        let light = lights[k % lights.len()];
        let camera = cameras[k % cameras.len()];
        let encoding = if k % 2 == 0 { "linear" } else { "srgb" };
        let text = format!(
            "[image]\nwidth = 160\nheight = 120\nbackground = [0.05, 0.05, 0.07]\nencoding = \"{encoding}\"\n\n{camera}\n\
             [shading]\n{shading}\nambient = [0.2, 0.2, 0.2]\n\n{light}\n\
             [[object]]\nshape = \"sphere\"\nmaterial = {{ paint = [0.2, 0.35, 0.7], shininess = 30.0 }}\nposition = [-0.6, 0.0, 0.0]\nscale = 0.8\n\n\
             [[object]]\nshape = \"torus\"\nmaterial = \"gold\"\nposition = [0.8, 0.0, -0.5]\nrotation = [60.0, 0.0, 0.0]\nscale = 0.6\n\n\
             [[label]]\ntext = \"k = {k}\"\nposition = [0.0, -1.0, 1.0]\n"
        );
        let path = dir.path().join(format!("scene{k}.toml"));
        std::fs::write(&path, text).unwrap();
        scenes.push(path);
    }
    // Random scenes over every model, interpolation, light kind and option (a fixed seed: the
    // same scenes every run), objects with their own overrides.
    let mut seed = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move |n: u64| {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed % n
    };
    let pick = |k: u64, xs: &[&'static str]| xs[k as usize % xs.len()];
    for r in 0..12 {
        let model = pick(next(5), &["phong", "blinn-phong", "lambert", "phong-lyon", "opengl"]);
        // OpenGL's model has no normalisation, always gates and clamps (the scene reader
        // refuses the others).
        let normalization = match model {
            "opengl" => "none",
            _ => pick(next(4), &["none", "phong", "blinn-phong", "blinn-phong-exact"]),
        };
        let mut t = format!(
            "[image]\nwidth = 160\nheight = 120\nbackground = [0.1, 0.05, 0.02]\nencoding = \"{}\"\n\n{}\n\
             [shading]\nmodel = \"{}\"\ninterpolation = \"{}\"\nnormalization = \"{}\"\nviewer = \"{}\"\n\
             two_sided = {}\ngate_specular = {}\nclamp = {}\noutput = \"{}\"\nlyon_squarings = {}\nlyon_lambda = \"{}\"\n\
             ambient = [{}, 0.1, 0.2]\n\n",
            pick(next(2), &["linear", "srgb"]),
            cameras[next(2) as usize],
            model,
            pick(next(3), &["phong", "gouraud", "flat"]),
            normalization,
            pick(next(2), &["local", "infinite"]),
            next(2) == 0,
            model == "opengl" || next(3) != 0,
            model == "opengl" || next(3) != 0,
            pick(next(6), &["color", "color", "color", "ambient", "diffuse", "specular"]),
            1 + next(4),
            pick(next(2), &["dot", "difference"]),
            next(4) as f32 / 10.0,
        );
        for _ in 0..1 + next(4) {
            let c = |k: u64| format!("[{:.2}, {:.2}, {:.2}]", k as f32 / 10.0, (10 - k) as f32 / 10.0, 0.8);
            t += &match next(3) {
                0 => format!(
                    "[[light]]\ntype = \"directional\"\ndirection = [{}, -1.0, -1.0]\ncolor = {}\n",
                    next(5) as f32 - 2.0,
                    c(next(10))
                ),
                1 => format!(
                    "[[light]]\ntype = \"point\"\nposition = [{}, 2.0, 3.0]\nattenuation = [1.0, {}, {}]\nambient = {}\ndiffuse = {}\nspecular = {}\n",
                    next(5) as f32 - 2.0,
                    next(3) as f32 / 10.0,
                    next(3) as f32 / 20.0,
                    c(next(3)),
                    c(next(10)),
                    c(next(10))
                ),
                _ => format!(
                    "[[light]]\ntype = \"spot\"\nposition = [0.0, 3.0, 3.0]\ndirection = [{}, -1.0, -1.0]\ncutoff = {}\nexponent = {}\n",
                    next(3) as f32 * 0.2 - 0.2,
                    pick(next(4), &["15.0", "30.0", "60.0", "90.0"]),
                    next(20)
                ),
            };
        }
        for k in 0..1 + next(3) {
            let shape = pick(next(5), &["sphere", "torus", "cube", "teapot", "cone"]);
            let material = match next(3) {
                0 => format!(
                    "\"{}\"",
                    pick(next(6), &["gold", "ruby", "jade", "chrome", "pearl", "obsidian"])
                ),
                _ => format!(
                    "{{ ambient = [0.2, 0.1, 0.1], diffuse = [{:.2}, 0.5, 0.3], specular = [0.8, 0.8, {:.2}], emission = [0.0, {:.2}, 0.0], shininess = {} }}",
                    next(10) as f32 / 10.0,
                    next(10) as f32 / 10.0,
                    next(3) as f32 / 20.0,
                    pick(next(5), &["0.0", "1.0", "10.0", "64.0", "200.0"])
                ),
            };
            let own = match next(4) {
                0 => format!(
                    "model = \"{}\"\n",
                    pick(next(5), &["phong", "blinn-phong", "lambert", "phong-lyon", "opengl"])
                ),
                1 => format!("interpolation = \"{}\"\n", pick(next(3), &["phong", "gouraud", "flat"])),
                _ => String::new(),
            };
            t += &format!(
                "[[object]]\nshape = \"{shape}\"\nmaterial = {material}\nposition = [{}, {}, 0.0]\nrotation = [{}, {}, 0.0]\nscale = 0.6\n{own}\n",
                k as f32 * 1.1 - 1.1,
                next(3) as f32 * 0.3 - 0.3,
                next(90),
                next(90)
            );
        }
        let path = dir.path().join(format!("random{r}.toml"));
        std::fs::write(&path, t).unwrap();
        scenes.push(path);
    }
    // Textured: a checker (magnified, bilinear, repeated) as diffuse and specular maps, and
    // waves (minified, trilinear mipmaps) on a torus; each interpolation.
    let image = |name: &str, size: u32, f: &dyn Fn(u32, u32) -> [u8; 4]| {
        let mut bytes = Vec::new();
        {
            let mut e = png::Encoder::new(&mut bytes, size, size);
            e.set_color(png::ColorType::Rgba);
            e.set_depth(png::BitDepth::Eight);
            let mut w = e.write_header().unwrap();
            let data: Vec<u8> = (0..size * size).flat_map(|i| f(i % size, i / size)).collect();
            w.write_image_data(&data).unwrap();
        }
        std::fs::write(dir.path().join(name), bytes).unwrap();
    };
    image("checker.png", 8, &|x, y| {
        if (x + y) % 2 == 0 {
            [230, 200, 40, 255]
        } else {
            [30, 60, 200, 255]
        }
    });
    // Waves of a few periods across the image: a picture's content, not noise at the texel
    // frequency (whose minified texels would differ by each implementation's level of detail).
    image("waves.png", 64, &|x, y| {
        let (u, v) = (
            x as f32 / 64.0 * std::f32::consts::TAU,
            y as f32 / 64.0 * std::f32::consts::TAU,
        );
        let c = |t: f32| (127.5 + 127.5 * t.sin()) as u8;
        [c(3.0 * u), c(2.0 * v + 1.0), c(u + v), 255]
    });
    for (k, interp) in ["phong", "gouraud", "flat"].into_iter().enumerate() {
        let text = format!(
            "[image]\nwidth = 160\nheight = 120\nbackground = [0.05, 0.05, 0.07]\nencoding = \"{}\"\n\n{}\n\
             [shading]\nmodel = \"phong\"\ninterpolation = \"{interp}\"\n\n{}\n\
             [[object]]\nshape = \"plane\"\nposition = [0.0, -1.0, 0.0]\nscale = 3.0\n\
             material = {{ diffuse = [1, 1, 1], specular = [0.5, 0.5, 0.5], shininess = 20.0, diffuse_map = \"checker.png\", filter = \"bilinear\", uv_scale = [2.0, 2.0] }}\n\n\
             [[object]]\nshape = \"sphere\"\nposition = [-0.6, 0.0, 0.0]\nscale = 0.8\n\
             material = {{ diffuse = [1, 1, 1], specular = [1, 1, 1], shininess = 30.0, diffuse_map = \"checker.png\", specular_map = \"checker.png\", filter = \"bilinear\" }}\n\n\
             [[object]]\nshape = \"torus\"\nposition = [0.8, 0.0, -0.5]\nrotation = [60.0, 0.0, 0.0]\nscale = 0.6\n\
             material = {{ diffuse = [1, 1, 1], diffuse_map = \"waves.png\", uv_scale = [4.0, 1.0] }}\n",
            if k == 1 { "srgb" } else { "linear" },
            cameras[k % 2],
            lights[k % lights.len()],
        );
        let path = dir.path().join(format!("textured-{interp}.toml"));
        std::fs::write(&path, text).unwrap();
        scenes.push(path);
    }
    // Every example scene the export can draw (all but the textured one): objects shaded
    // differently each drawn with its own program, flat objects, labels.
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenes");
    for e in std::fs::read_dir(&examples).unwrap().flatten() {
        let p = e.path();
        if p.extension().is_some_and(|x| x == "toml") && !p.ends_with("textures.toml") {
            scenes.push(p);
        }
    }
    let out = dir.path().to_path_buf();
    run(async move {
        let (client, _driver, _profile) = browser((400, 400)).await.expect("browser");
        for scene in &scenes {
            let stem = scene.file_stem().unwrap().to_string_lossy().into_owned();
            let html = out.join(format!("{stem}.html"));
            let png = out.join(format!("{stem}.png"));
            let phong = |args: &[&str]| {
                let out = Command::new(env!("CARGO_BIN_EXE_phong"))
                    .args(args)
                    .output()
                    .expect("phong runs");
                assert!(
                    out.status.success(),
                    "{args:?}: {}",
                    String::from_utf8_lossy(&out.stderr)
                );
            };
            let (s, h, p) = (scene.to_str().unwrap(), html.to_str().unwrap(), png.to_str().unwrap());
            phong(&["shader", s, "--target", "html", "-o", h]);
            phong(&["render", s, "-o", p, "--antialias", "1"]);
            client.goto(&format!("file://{h}")).await.expect("page");
            let got = client
                .execute(
                    "if (window.phongError) return 'error: ' + window.phongError; \
                     return document.getElementById('phong').toDataURL('image/png');",
                    vec![],
                )
                .await
                .expect("canvas");
            let url = got.as_str().expect("a string").to_string();
            assert!(url.starts_with("data:image/png;base64,"), "{}: {url}", scene.display());
            let bytes = base64::engine::general_purpose::STANDARD
                .decode(&url["data:image/png;base64,".len()..])
                .unwrap();
            let (w, hh, web, wc) = decode(&bytes).unwrap();
            let (pw, ph, ours, oc) = decode(&std::fs::read(&png).unwrap()).unwrap();
            assert_eq!((w, hh), (pw, ph), "{}", scene.display());
            let (mut off, mut worst, mut at) = (0usize, 0u8, (0, 0));
            for i in 0..(w * hh) as usize {
                let d = (0..3)
                    .map(|c| web[i * wc + c].abs_diff(ours[i * oc + c]))
                    .max()
                    .unwrap();
                if d > 2 {
                    off += 1;
                }
                if d > worst {
                    worst = d;
                    at = (i as u32 % w, i as u32 / w);
                }
            }
            let share = off as f64 / f64::from(w * hh);
            assert!(
                share <= 0.005,
                "{}: {:.2}% of pixels differ by more than 2/255 (worst {worst} at {at:?}); edges differ by \
                 each rasteriser's rule, more than that is the shaders'",
                scene.display(),
                share * 100.0
            );
            eprintln!("{}: {off} pixels past 2/255, worst {worst} at {at:?}", scene.display());
        }
        client.close().await.expect("close");
    });
}

/// The explorer's Shader view: the selected object's GLSL (1.20 by default, then ES 3.00), and
/// the page the export writes, run in the browser's WebGL2 beside phong's image at the size
/// the view shows it: at most 0.5% of the pixels differ by more than 2/255, for the default
/// scene and with every model of the Model menu.
#[test]
fn shader_view_runs_the_exported_glsl_beside_phong() {
    if !browser_available() {
        return;
    }
    run(async {
        let s = open("shader", "", &[]).await.expect("the page opens");
        s.step("open Shader", async {
            s.client
                .find(Locator::XPath("//button[normalize-space(.)='Shader']"))
                .await?
                .click()
                .await?;
            s.idle().await
        })
        .await;
        for model in ["blinn-phong", "phong", "lambert", "phong-lyon", "opengl"] {
            s.step(&format!("model {model}: WebGL2 within 2/255 of phong"), async {
                s.control("Model").await?.select_by_value(model).await?;
                s.idle().await?;
                let d = s.js("return window.phong.shaderDifference;").await?;
                let (w, h, off) = (d["width"].as_u64().unwrap_or(0), d["height"].as_u64().unwrap_or(0), d["off"].as_u64().unwrap_or(u64::MAX));
                ensure!(w >= 200 && h >= 100, "the images are {w}x{h}");
                ensure!(off * 200 <= w * h, "{off} of {} pixels differ by more than 2/255", w * h);
                // Drawn at the size shown (device pixels), not stretched.
                let shown = s
                    .js("const i = document.getElementById('shader-phong'); return [i.naturalWidth, Math.round(i.clientWidth * devicePixelRatio)];")
                    .await?;
                let (natural, css) = (shown[0].as_i64().unwrap_or(0), shown[1].as_i64().unwrap_or(0));
                ensure!((natural - css).abs() <= 2, "phong's image is {natural} pixels wide, shown at {css}");
                let vertex = s.js("return document.getElementById('shader-vertex').textContent;").await?;
                ensure!(vertex.as_str().is_some_and(|v| v.starts_with("#version 120")), "{vertex}");
                Ok(())
            })
            .await;
        }
        s.step("GLSL ES 3.00", async {
            s.client
                .find(Locator::Id("shader-target"))
                .await?
                .select_by_value("glsl300es")
                .await?;
            s.idle().await?;
            let fragment = s
                .js("return document.getElementById('shader-fragment').textContent;")
                .await?;
            ensure!(
                fragment
                    .as_str()
                    .is_some_and(|f| f.starts_with("#version 300 es") && f.contains("shadePoint")),
                "{fragment}"
            );
            Ok(())
        })
        .await;
    });
}

/// three.js 0.187.0 (pinned: the check must not move with three's releases), vendored from
/// the npm registry into the target folder (once), for the threejs
/// target's example page; `None` (skipped) where npm is missing, a failure under
/// PHONG_REQUIRE_BROWSER=1.
fn vendored_three() -> Option<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("three-0.187.0");
    let build = dir.join("package/build");
    if build.join("three.module.js").exists() {
        return Some(build);
    }
    std::fs::create_dir_all(&dir).ok()?;
    let packed = Command::new("npm")
        .args(["pack", "three@0.187.0", "--silent"])
        .current_dir(&dir)
        .output();
    let name = match packed {
        Ok(o) if o.status.success() => String::from_utf8_lossy(&o.stdout).trim().to_string(),
        other => {
            if std::env::var("PHONG_REQUIRE_BROWSER").is_ok_and(|v| v == "1") {
                panic!("PHONG_REQUIRE_BROWSER=1 but `npm pack three` failed: {other:?}");
            }
            eprintln!("skipped: `npm pack three` failed (apt-get install npm)");
            return None;
        }
    };
    let ok = Command::new("tar")
        .args(["xzf", &name])
        .current_dir(&dir)
        .status()
        .is_ok_and(|s| s.success());
    (ok && build.join("three.module.js").exists()).then_some(build)
}

/// `phong shader --target threejs`: the example page, with three.js from the npm registry
/// beside it and served over HTTP as a user would, draws phong's pixels: at most 0.5% of them
/// past 2/255, for each interpolation and light kind, both viewers.
#[test]
fn exported_threejs_material_draws_phongs_pixels() {
    if !browser_available() {
        return;
    }
    let Some(three) = vendored_three() else { return };
    let dir = tempfile::tempdir().expect("tempdir");
    let scenes = [
        (
            "phong",
            "[[light]]\ntype = \"point\"\nposition = [2.0, 2.0, 3.0]\nattenuation = [1.0, 0.05, 0.01]\n",
            "fov = 45.0",
        ),
        (
            "gouraud",
            "[[light]]\ntype = \"spot\"\nposition = [0.0, 3.0, 3.0]\ndirection = [0.0, -1.0, -1.0]\ncutoff = 30.0\nexponent = 4.0\n",
            "fov = 45.0",
        ),
        (
            "flat",
            "[[light]]\ntype = \"directional\"\ndirection = [-1.0, -1.0, -1.5]\n",
            "projection = \"orthographic\"\nheight = 3.2",
        ),
    ];
    let mut pages = Vec::new();
    for (interp, light, camera) in scenes {
        let text = format!(
            "[image]\nwidth = 200\nheight = 150\nbackground = [0.05, 0.05, 0.07]\n\n\
             [camera]\nposition = [0.5, 1.0, 4.0]\ntarget = [0.0, 0.0, 0.0]\n{camera}\n\n\
             [shading]\nmodel = \"phong\"\ninterpolation = \"{interp}\"\n\n{light}\n\
             [[object]]\nshape = \"sphere\"\nmaterial = \"gold\"\nposition = [-0.6, 0.0, 0.0]\nscale = 0.8\n\n\
             [[object]]\nshape = \"torus\"\nmaterial = \"jade\"\nposition = [0.8, 0.0, -0.5]\nrotation = [60.0, 0.0, 0.0]\nscale = 0.6\n"
        );
        let scene = dir.path().join(format!("{interp}.toml"));
        std::fs::write(&scene, text).unwrap();
        let site = dir.path().join(interp);
        let png = dir.path().join(format!("{interp}.png"));
        for args in [
            vec![
                "shader",
                scene.to_str().unwrap(),
                "--target",
                "threejs",
                "-o",
                site.to_str().unwrap(),
            ],
            vec![
                "render",
                scene.to_str().unwrap(),
                "-o",
                png.to_str().unwrap(),
                "--antialias",
                "1",
            ],
        ] {
            let o = Command::new(env!("CARGO_BIN_EXE_phong")).args(&args).output().unwrap();
            assert!(o.status.success(), "{args:?}: {}", String::from_utf8_lossy(&o.stderr));
        }
        for f in ["three.module.js", "three.core.js"] {
            if three.join(f).exists() {
                std::fs::copy(three.join(f), site.join(f)).unwrap();
            }
        }
        pages.push((interp, png));
    }
    let port = free_port();
    let _server = Proc(
        Command::new("python3")
            .args(["-m", "http.server", &port.to_string(), "--bind", "127.0.0.1"])
            .current_dir(dir.path())
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("python3 -m http.server"),
    );
    let t0 = Instant::now();
    while std::net::TcpStream::connect(("127.0.0.1", port)).is_err() {
        assert!(t0.elapsed() < Duration::from_secs(20), "the HTTP server did not listen");
        std::thread::sleep(Duration::from_millis(50));
    }
    run(async move {
        let (client, _driver, _profile) = browser((400, 400)).await.expect("browser");
        for (interp, png) in &pages {
            client
                .goto(&format!("http://127.0.0.1:{port}/{interp}/"))
                .await
                .expect("page");
            let t0 = Instant::now();
            let url = loop {
                let v = client
                    .execute(
                        "if (window.phongError) return 'error: ' + window.phongError; \
                         return window.phongDone ? document.getElementById('phong').toDataURL('image/png') : null;",
                        vec![],
                    )
                    .await
                    .expect("script");
                if let Some(s) = v.as_str() {
                    break s.to_string();
                }
                assert!(
                    t0.elapsed() < Duration::from_secs(30),
                    "{interp}: the page did not draw"
                );
                tokio::time::sleep(Duration::from_millis(100)).await;
            };
            assert!(url.starts_with("data:image/png;base64,"), "{interp}: {url}");
            let bytes = base64::engine::general_purpose::STANDARD
                .decode(&url["data:image/png;base64,".len()..])
                .unwrap();
            let (w, h, web, wc) = decode(&bytes).unwrap();
            let (pw, ph, ours, oc) = decode(&std::fs::read(png).unwrap()).unwrap();
            assert_eq!((w, h), (pw, ph), "{interp}");
            let off = (0..(w * h) as usize)
                .filter(|&i| (0..3).any(|c| web[i * wc + c].abs_diff(ours[i * oc + c]) > 2))
                .count();
            eprintln!("three.js {interp}: {off} pixels past 2/255");
            assert!(
                off * 200 <= (w * h) as usize,
                "three.js {interp}: {off} of {} pixels past 2/255",
                w * h
            );
        }
        client.close().await.expect("close");
    });
}

/// `phong shader --target brdf`: the `.brdf` file's shader, compiled in the browser's WebGL2
/// with its parameters as BRDF Explorer declares them (uniforms of their names), evaluated on
/// a 32×32 grid of light and view directions (given as the vertex attributes of one point a
/// pixel, passed on as `flat` varyings, so that both sides evaluate the same vectors; the
/// result's exact float bits read back through an integer target), equals phong-core's
/// `shade` for the material: `(diffuse + specular) / (N·L)` under a white light, within 1e-4
/// (relative above 1), for each model and normalisation.
#[test]
fn brdf_file_evaluates_to_shade_in_webgl() {
    if !browser_available() {
        return;
    }
    let dir = tempfile::tempdir().expect("tempdir");
    let cases = [
        ("phong", "none", "gold"),
        ("blinn-phong", "none", "ruby"),
        ("lambert", "none", "jade"),
        ("phong-lyon", "none", "chrome"),
        ("blinn-phong", "blinn-phong-exact", "pewter"),
        ("phong", "phong", "emerald"),
    ];
    let mut files = Vec::new();
    for (k, (model, norm, material)) in cases.iter().enumerate() {
        let toml = dir.path().join(format!("b{k}.toml"));
        std::fs::write(
            &toml,
            format!(
                "[shading]\nmodel = \"{model}\"\nnormalization = \"{norm}\"\n[[light]]\ntype = \"directional\"\n\
                 direction = [0, 0, -1]\n[[object]]\nshape = \"sphere\"\nmaterial = \"{material}\"\n"
            ),
        )
        .unwrap();
        let out = dir.path().join(format!("b{k}.brdf"));
        let o = Command::new(env!("CARGO_BIN_EXE_phong"))
            .args([
                "shader",
                toml.to_str().unwrap(),
                "--target",
                "brdf",
                "-o",
                out.to_str().unwrap(),
            ])
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let scene = phong_scene::load(&toml).expect("the scene").scene;
        files.push((std::fs::read_to_string(&out).unwrap(), scene.objects[0].clone()));
    }
    const N: u32 = 32;
    let directions = |x: u32, y: u32| {
        let tl = (x as f32 + 0.5) / N as f32 * 1.4835298;
        let tv = (y as f32 + 0.5) / N as f32 * 1.4835298;
        let pv = ((x * 7 + y * 3) % N) as f32 / N as f32 * std::f32::consts::TAU;
        (
            Vec3::new(tl.sin(), 0.0, tl.cos()),
            Vec3::new(tv.sin() * pv.cos(), tv.sin() * pv.sin(), tv.cos()),
        )
    };
    let page = dir.path().join("brdf.html");
    std::fs::write(&page, "<!doctype html><canvas id=c width=32 height=32></canvas>").unwrap();
    run(async move {
        let (client, _driver, _profile) = browser((400, 400)).await.expect("browser");
        client.goto(&format!("file://{}", page.display())).await.expect("page");
        for (text, object) in &files {
            let block = |name: &str| {
                let start = text.find(&format!("::begin {name}\n")).unwrap() + 8 + name.len();
                text[start..text.find(&format!("::end {name}")).unwrap()].to_string()
            };
            // Parameters as BRDF Explorer declares them: `uniform` of the type, set to the
            // default.
            let mut decls = String::new();
            let mut sets = String::new();
            for l in block("parameters").lines().filter(|l| !l.trim().is_empty()) {
                let w: Vec<&str> = l.split_whitespace().collect();
                match w[0] {
                    "color" => {
                        decls += &format!("uniform vec3 {};\n", w[1]);
                        sets += &format!(
                            "gl.uniform3f(gl.getUniformLocation(p, '{}'), {}, {}, {});",
                            w[1], w[2], w[3], w[4]
                        );
                    }
                    "float" => {
                        decls += &format!("uniform float {};\n", w[1]);
                        sets += &format!("gl.uniform1f(gl.getUniformLocation(p, '{}'), {});", w[1], w[4]);
                    }
                    other => panic!("parameter type {other}"),
                }
            }
            let fragment = format!(
                "#version 300 es\nprecision highp float;\nprecision highp int;\nprecision highp sampler2D;\n{decls}\
                 flat in vec3 vL, vV;\nout uvec4 o;\n{}\n\
                 void main() {{\n  vec3 L = vL, V = vV;\n\
                 vec3 f = BRDF(L, V, vec3(0.0, 0.0, 1.0), vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0));\n\
                 o = uvec4(floatBitsToUint(f.r), floatBitsToUint(f.g), floatBitsToUint(f.b), 0u);\n}}\n",
                block("shader")
            );
            let script = format!(
                "const gl = document.getElementById('c').getContext('webgl2');\n\
                 const sh = (t, s) => {{ const x = gl.createShader(t); gl.shaderSource(x, s); gl.compileShader(x);\n\
                   if (!gl.getShaderParameter(x, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(x)); return x; }};\n\
                 const p = gl.createProgram();\n\
                 gl.attachShader(p, sh(gl.VERTEX_SHADER, '#version 300 es\\nin vec3 aL, aV;\\nflat out vec3 vL, vV;\\nvoid main() {{ int x = gl_VertexID % 32, y = gl_VertexID / 32; vL = aL; vV = aV; gl_PointSize = 1.0; gl_Position = vec4((float(x) + 0.5) / 16.0 - 1.0, (float(y) + 0.5) / 16.0 - 1.0, 0.0, 1.0); }}'));\n\
                 gl.attachShader(p, sh(gl.FRAGMENT_SHADER, arguments[0]));\n\
                 gl.linkProgram(p); gl.useProgram(p); {sets}\n\
                 [arguments[1], arguments[2]].forEach((d, k) => {{ const loc = gl.getAttribLocation(p, k ? 'aV' : 'aL');\n\
                   gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer()); gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(d), gl.STATIC_DRAW);\n\
                   gl.enableVertexAttribArray(loc); gl.vertexAttribPointer(loc, 3, gl.FLOAT, false, 0, 0); }});\n\
                 const rb = gl.createRenderbuffer(); gl.bindRenderbuffer(gl.RENDERBUFFER, rb);\n\
                 gl.renderbufferStorage(gl.RENDERBUFFER, gl.RGBA32UI, 32, 32);\n\
                 const fb = gl.createFramebuffer(); gl.bindFramebuffer(gl.FRAMEBUFFER, fb);\n\
                 gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.RENDERBUFFER, rb);\n\
                 gl.viewport(0, 0, 32, 32); gl.drawArrays(gl.POINTS, 0, 32 * 32);\n\
                 const out = new Uint32Array(32 * 32 * 4); gl.readPixels(0, 0, 32, 32, gl.RGBA_INTEGER, gl.UNSIGNED_INT, out);\n\
                 const err = gl.getError(); if (err !== 0) throw new Error('GL error ' + err); return Array.from(out);"
            );
            let (mut ls, mut vs) = (Vec::new(), Vec::new());
            for y in 0..N {
                for x in 0..N {
                    let (l, v) = directions(x, y);
                    ls.extend([l.x, l.y, l.z]);
                    vs.extend([v.x, v.y, v.z]);
                }
            }
            let got = client
                .execute(&script, vec![json!(fragment), json!(ls), json!(vs)])
                .await
                .expect("the BRDF runs");
            let bits: Vec<u32> = got
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_u64().unwrap() as u32)
                .collect();
            let light = |l: Vec3| {
                let white = phong_core::Color::WHITE;
                let c = phong_core::LightColor::new(phong_core::Color::BLACK, white, white).unwrap();
                phong_core::Lighting::new(
                    phong_core::Color::BLACK,
                    vec![phong_core::Light::directional(-l, c).unwrap()],
                )
                .unwrap()
            };
            let mut worst = 0.0f32;
            for y in 0..N {
                for x in 0..N {
                    let (l, v) = directions(x, y);
                    let s = phong_core::shade(
                        &phong_core::SurfacePoint {
                            position: Vec3::ZERO,
                            normal: Vec3::Z,
                        },
                        &phong_core::View::Infinite { to_viewer: v },
                        &object.material,
                        &light(l),
                        &object.shading.options,
                    );
                    let want = (s.diffuse + s.specular) * (1.0 / l.z);
                    let i = ((y * N + x) * 4) as usize;
                    for (k, w) in want.to_array().into_iter().enumerate() {
                        let g = f32::from_bits(bits[i + k]);
                        let e = (g - w).abs() / w.abs().max(1.0);
                        worst = worst.max(e);
                        assert!(
                            e <= 1e-4,
                            "{}: L {l} V {v} channel {k}: BRDF {g}, shade {w}",
                            object.name
                        );
                    }
                }
            }
            eprintln!("brdf {:?}: worst {worst:e}", object.shading.options.specular);
        }
        client.close().await.expect("close");
    });
}

/// Every view draws its pictures at the width it shows them (device pixels), not at the
/// hidden Render view's size, and again after the window changes; the Terms images add up to
/// the total at that size.
#[test]
fn every_view_draws_at_the_size_it_shows() {
    if !browser_available() {
        return;
    }
    run(async {
        let s = open("sizes", "", &[]).await.expect("the page opens");
        s.step("one sample a pixel", async {
            s.control("Antialias").await?.select_by_value("1").await?;
            s.idle().await
        })
        .await;
        // Each view's pictures: [drawn width, shown width in device pixels].
        let measure = r#"
            const dpr = window.devicePixelRatio || 1;
            const shown = (e) => Math.round(e.clientWidth * dpr);
            const ids = {
              render: ['frame'], terms: ['term-ambient', 'term-diffuse', 'term-specular', 'term-total'],
              compare: ['compare-canvas'], shader: ['shader-phong'] }[arguments[0]];
            return ids.map((id) => {
              const e = document.getElementById(id);
              return [e.naturalWidth !== undefined ? e.naturalWidth : e.width, shown(e)];
            });"#;
        for (window, views) in [
            ((1400, 1000), ["Render", "Terms", "Compare", "Shader"]),
            ((900, 800), ["Terms", "Compare", "Render", "Shader"]),
        ] {
            s.client
                .set_window_size(window.0, window.1)
                .await
                .expect("the window resizes");
            for view in views {
                s.step(&format!("{view} at {window:?}"), async {
                    s.client
                        .find(Locator::XPath(&format!("//button[normalize-space(.)='{view}']")))
                        .await?
                        .click()
                        .await?;
                    s.idle().await?;
                    let sizes = s.client.execute(measure, vec![json!(view.to_lowercase())]).await?;
                    for pair in sizes.as_array().context("sizes")? {
                        let (drawn, shown) = (pair[0].as_i64().unwrap_or(0), pair[1].as_i64().unwrap_or(0));
                        ensure!(shown > 100, "{view}: shown {shown} pixels wide");
                        ensure!(
                            (drawn - shown).abs() <= 2,
                            "{view}: drawn {drawn} pixels wide, shown at {shown}"
                        );
                    }
                    if view == "Terms" {
                        let px = term_pixels(&s).await?;
                        let (mut worst, mut checked) = (0i32, 0);
                        for i in (0..px[0].len()).step_by(4) {
                            for k in 0..3 {
                                let (a, d, sp, t) = (px[0][i + k], px[1][i + k], px[2][i + k], px[3][i + k]);
                                if t < 250 && a < 255 && d < 255 && sp < 255 {
                                    worst =
                                        worst.max((i32::from(a) + i32::from(d) + i32::from(sp) - i32::from(t)).abs());
                                    checked += 1;
                                }
                            }
                        }
                        ensure!(
                            checked > 10_000 && worst <= 2,
                            "terms add up within {worst} over {checked} channels"
                        );
                    }
                    Ok(())
                })
                .await;
            }
        }
    });
}
