//! `phong serve`: arguments, and the server until Ctrl-C or SIGTERM.

use crate::{Backend, GpuPathArg, open_gpu};
use anyhow::{Context, Result};
use std::path::PathBuf;

#[derive(clap::Args)]
pub(crate) struct ServeArgs {
    /// Scene file (.toml) or model (.obj, .gltf, .glb, .ply, .stl) to open; the default scene without one.
    input: Option<PathBuf>,
    /// Port to listen on.
    #[arg(long, default_value_t = 8080)]
    port: u16,
    /// Address to listen on (loopback unless you say otherwise).
    #[arg(long, default_value = "127.0.0.1")]
    host: std::net::IpAddr,
    /// Renderer.
    #[arg(long, value_enum, default_value_t = Backend::Cpu)]
    backend: Backend,
    /// Rendering threads for the CPU backend (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// Open the page in the default browser.
    #[arg(long)]
    open: bool,
    /// How a model alone is viewed.
    #[command(flatten)]
    view: crate::args::ViewArgs,
}

/// `phong serve`: the explorer until Ctrl-C.
pub(crate) fn serve(a: ServeArgs) -> Result<()> {
    crate::args::threads_flag(a.threads)?;
    let (scene, library) = phong_serve::initial_scene(a.input.as_deref(), &a.view.options(None)?)?;
    let gpu = open_gpu(a.backend, GpuPathArg::Auto)?;
    let backend = match gpu {
        Some(g) => phong_serve::Backend::Gpu(Box::new(std::sync::Mutex::new(g))),
        None => phong_serve::Backend::cpu(a.threads).map_err(|e| anyhow::anyhow!(e))?,
    };
    // The runtime starts its workers when it first runs, and panics where the system refuses
    // them (a process's or container's thread limit): a thread is asked for first.
    std::thread::Builder::new()
        .spawn(|| ())
        .map(|t| t.join())
        .context("starting the server's threads")?
        .map_err(|_| anyhow::anyhow!("starting the server's threads"))?;
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .context("starting the server's runtime")?;
    runtime.block_on(async move {
        let addr = std::net::SocketAddr::new(a.host, a.port);
        let listener = phong_serve::bind(addr).await?;
        let local = listener.local_addr().context("the listening address")?;
        let shown = if a.host.is_unspecified() {
            std::net::SocketAddr::new(std::net::Ipv4Addr::LOCALHOST.into(), local.port())
        } else {
            local
        };
        let url = format!("http://{shown}/");
        eprintln!(
            "phong: serving the explorer at {url} (backend {}); Ctrl-C stops",
            backend.describe()
        );
        if !a.host.is_loopback() {
            eprintln!(
                "phong: warning: listening on {}: anyone who can reach this port can use the server and its CPU",
                a.host
            );
        }
        println!("{url}");
        if a.open
            && let Err(e) = std::process::Command::new("xdg-open").arg(&url).spawn()
        {
            eprintln!("phong: could not open a browser ({e}); open {url} yourself");
        }
        let state = std::sync::Arc::new(phong_serve::AppState::new(backend, scene, library));
        // Ctrl-C (SIGINT) or SIGTERM: stop taking connections, finish the renders in flight.
        let shutdown = async {
            let mut term = tokio::signal::unix::signal(tokio::signal::unix::SignalKind::terminate()).ok();
            let term = async {
                match term.as_mut() {
                    Some(t) => {
                        t.recv().await;
                    }
                    None => std::future::pending().await,
                }
            };
            tokio::select! {
                _ = tokio::signal::ctrl_c() => {}
                _ = term => {}
            }
            eprintln!("phong: stopping (renders in flight finish first)");
        };
        phong_serve::serve(listener, state, shutdown).await.context("serving")?;
        eprintln!("phong: stopped");
        Ok::<(), anyhow::Error>(())
    })
}
