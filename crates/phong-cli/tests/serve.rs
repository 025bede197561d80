//! `phong serve` as a process: its startup errors, and a clean stop while renders are in
//! flight.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn phong() -> Command {
    Command::new(env!("CARGO_BIN_EXE_phong"))
}

/// One HTTP/1.1 request on its own connection: the status code and the body.
fn request(addr: &str, method: &str, path: &str, body: &str) -> std::io::Result<(u16, Vec<u8>)> {
    let mut s = TcpStream::connect(addr)?;
    s.set_read_timeout(Some(Duration::from_secs(60)))?;
    write!(
        s,
        "{method} {path} HTTP/1.1\r\nHost: {addr}\r\nContent-Type: application/json\r\nContent-Length: {}\r\nConnection: close\r\n\r\n{body}",
        body.len()
    )?;
    let mut out = Vec::new();
    s.read_to_end(&mut out)?;
    let text = String::from_utf8_lossy(&out);
    let code = text.split(' ').nth(1).and_then(|c| c.parse().ok()).unwrap_or(0);
    let start = out
        .windows(4)
        .position(|w| w == b"\r\n\r\n")
        .map_or(out.len(), |p| p + 4);
    Ok((code, out[start..].to_vec()))
}

/// `phong serve ARGS --port 0`, its stderr piped, and the address it prints.
fn serve(args: &[&str]) -> (std::process::Child, String) {
    let mut child = phong()
        .arg("serve")
        .args(args)
        .args(["--port", "0"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("starts");
    let mut url = String::new();
    BufReader::new(child.stdout.take().expect("stdout"))
        .read_line(&mut url)
        .expect("the URL");
    let addr = url
        .trim()
        .trim_start_matches("http://")
        .trim_end_matches('/')
        .to_string();
    (child, addr)
}

#[test]
fn a_port_in_use_is_a_clear_error() {
    let taken = std::net::TcpListener::bind("127.0.0.1:0").expect("a port");
    let port = taken.local_addr().expect("addr").port();
    let out = phong()
        .args(["serve", "--port", &port.to_string()])
        .output()
        .expect("runs");
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains(&format!("port {port} is already in use")), "{err}");
}

#[test]
fn a_bad_scene_file_is_refused_before_serving() {
    let dir = tempfile::tempdir().expect("tmp");
    let f = dir.path().join("bad.toml");
    std::fs::write(&f, "[image]\nwidth = -4\n").expect("write");
    let out = phong()
        .arg("serve")
        .arg(&f)
        .args(["--port", "0"])
        .output()
        .expect("runs");
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("bad.toml:2:9: `width`: must be from 1 to 16384, got -4"),
        "{err}"
    );
    let out = phong()
        .args(["serve", "missing.toml", "--port", "0"])
        .output()
        .expect("runs");
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn stops_cleanly_with_renders_in_flight() {
    let (mut child, addr) = serve(&["--threads", "2"]);
    // The default scene's first page load, then slow frames in flight.
    let (code, scene) = request(&addr, "GET", "/api/scene", "").expect("scene");
    assert_eq!(code, 200);
    let scene: serde_json::Value = serde_json::from_slice(&scene).expect("json");
    let mut slow = scene["scene"].clone();
    slow["image"] = serde_json::json!({"width": 3840, "height": 2160, "antialias": 4});
    let body = slow.to_string();
    let inflight: Vec<_> = (0..6)
        .map(|_| {
            let (addr, body) = (addr.clone(), body.clone());
            std::thread::spawn(move || {
                let r = request(&addr, "POST", "/api/render", &body);
                (r, Instant::now())
            })
        })
        .collect();
    std::thread::sleep(Duration::from_millis(150));
    let pid = child.id().to_string();
    assert!(
        Command::new("kill")
            .args(["-INT", &pid])
            .status()
            .expect("kill")
            .success()
    );
    let killed = Instant::now();
    let mut after = 0;
    for t in inflight {
        let (r, at) = t.join().expect("thread");
        let (code, png) = r.expect("an answer, not a dropped connection");
        assert_eq!(code, 200);
        assert!(png.starts_with(b"\x89PNG") && png.len() > 10_000, "a whole PNG");
        after += usize::from(at > killed);
    }
    assert!(after > 0, "every render finished before the signal: make them slower");
    let t0 = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().expect("wait") {
            break s;
        }
        assert!(t0.elapsed() < Duration::from_secs(30), "did not stop");
        std::thread::sleep(Duration::from_millis(20));
    };
    assert!(status.success(), "{status:?}");
    let mut err = String::new();
    child
        .stderr
        .take()
        .expect("stderr")
        .read_to_string(&mut err)
        .expect("stderr");
    assert!(err.contains("phong: stopped"), "{err}");
    // New connections are refused once it has stopped.
    assert!(TcpStream::connect(&addr).is_err());
}

#[test]
fn a_public_address_is_warned_about() {
    let mut child = phong()
        .args(["serve", "--port", "0", "--host", "0.0.0.0"])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("starts");
    let mut r = BufReader::new(child.stderr.take().expect("stderr"));
    let (mut a, mut b) = (String::new(), String::new());
    r.read_line(&mut a).expect("line 1");
    r.read_line(&mut b).expect("line 2");
    let _ = child.kill();
    let _ = child.wait();
    assert!(a.contains("serving the explorer at http://127.0.0.1:"), "{a}");
    assert!(b.contains("anyone who can reach this port can use the server"), "{b}");
}

#[test]
fn the_gpu_backend_serves_the_cpu_image() {
    let (gpu, gpu_addr) = serve(&["--backend", "gpu"]);
    let mut gpu = gpu;
    if gpu_addr.is_empty() {
        let out = gpu.wait_with_output().expect("exit");
        assert!(
            std::env::var("PHONG_REQUIRE_GPU").is_err(),
            "PHONG_REQUIRE_GPU=1 but: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        eprintln!(
            "skipped: no GPU adapter ({})",
            String::from_utf8_lossy(&out.stderr).trim()
        );
        return;
    }
    let (mut cpu, cpu_addr) = serve(&[]);
    let scene = serde_json::json!({"image": {"width": 96, "height": 64},
        "light": [{"type": "point", "position": [1, 2, 3], "attenuation": [1, 0.1, 0]}],
        "object": [{"shape": "torus", "material": "emerald"}]})
    .to_string();
    let (c1, a) = request(&gpu_addr, "POST", "/api/render?format=rgba", &scene).expect("gpu frame");
    let (c2, b) = request(&cpu_addr, "POST", "/api/render?format=rgba", &scene).expect("cpu frame");
    let _ = (gpu.kill(), cpu.kill(), gpu.wait(), cpu.wait());
    assert_eq!((c1, c2), (200, 200));
    assert_eq!(a.len(), 96 * 64 * 4);
    let worst = a.iter().zip(&b).map(|(x, y)| x.abs_diff(*y)).max().unwrap_or(0);
    assert!(worst <= 1, "the GPU's frame differs from the CPU's by {worst}/255");
}

/// A served scene file's frame is `phong render`'s PNG of that file, byte for byte.
fn served_equals_rendered(input: &str) {
    let dir = tempfile::tempdir().expect("tmp");
    let out = dir.path().join("cli.png");
    let st = phong()
        .arg("render")
        .arg(input)
        .arg("-o")
        .arg(&out)
        .output()
        .expect("render");
    assert!(st.status.success(), "{}", String::from_utf8_lossy(&st.stderr));
    let (mut child, addr) = serve(&[input]);
    let (code, body) = request(&addr, "GET", "/api/scene", "").expect("scene");
    assert_eq!(code, 200);
    let initial: serde_json::Value = serde_json::from_slice(&body).expect("json");
    assert!(!initial["models"].as_array().expect("models").is_empty(), "{initial}");
    let (code, png) = request(&addr, "POST", "/api/render", &initial["scene"].to_string()).expect("render");
    let _ = (child.kill(), child.wait());
    assert_eq!(code, 200, "{}", String::from_utf8_lossy(&png));
    assert!(
        png == std::fs::read(&out).expect("cli png"),
        "{input}: the served PNG is not phong render's"
    );
}

#[test]
fn a_served_scene_file_renders_as_phong_render_does() {
    served_equals_rendered(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/scenes/models.toml"
    ));
}

#[test]
fn a_served_model_renders_as_phong_render_does() {
    served_equals_rendered(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/scenes/assets/knot.obj"
    ));
}
