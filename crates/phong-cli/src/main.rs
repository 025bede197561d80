//! `phong`: the command line. Glue only: arguments resolved once (`args`), then each
//! command in its own module; this file maps errors to exit codes.

/// mimalloc keeps freed memory for the next allocation instead of returning it to the
/// system: a model's load and its first frame allocate and free large arrays in turn, and
/// every fresh page costs a fault (BENCHMARKS.md, C12). Version 2 (the crate's `v2` feature):
/// version 3 returned more of it and took fresh pages again. Measured on x86-64 only.
#[cfg(target_arch = "x86_64")]
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

mod args;
mod batch;
mod bench;
mod fit;
mod materials;
mod render;
mod report;
mod serve;
mod shader;

use anyhow::{Result, bail};
use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

pub(crate) use args::{Backend, GpuPathArg, open_gpu};
pub(crate) use materials::fmt3;

#[derive(Parser)]
#[command(name = "phong", version, about = "Render scenes with the Phong illumination model.")]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// Where decoded textures of 16 MiB and more are kept with their mipmaps, so that the next
    /// load reads them back instead of decoding (at most 2 GiB, the least recently used
    /// removed); `off` keeps none. Default: $XDG_CACHE_HOME/phong/textures, else
    /// ~/.cache/phong/textures.
    #[arg(long, global = true, value_name = "DIR|off", env = "PHONG_TEXTURE_CACHE")]
    texture_cache: Option<PathBuf>,
}

/// The texture store `--texture-cache` names (see [`Cli::texture_cache`]).
fn texture_store(arg: Option<PathBuf>) -> Option<phong_scene::TextureStore> {
    let dir = match arg {
        Some(d) if d.as_os_str() == "off" => return None,
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => {
            let base = std::env::var_os("XDG_CACHE_HOME")
                .filter(|v| !v.is_empty())
                .map(PathBuf::from)
                .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache")))?;
            base.join("phong").join("textures")
        }
    };
    Some(phong_scene::TextureStore::in_dir(dir))
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene file (.toml) or a model (OBJ, glTF, PLY, STL) to a PNG.
    Render(render::RenderArgs),
    /// Render many scenes or views from a JSON Lines file (a shard of them on a cluster).
    Batch(batch::BatchArgs),
    /// Render a scene repeatedly and print the time per frame.
    Bench(bench::BenchArgs),
    /// Serve the live explorer in the browser (until Ctrl-C).
    Serve(serve::ServeArgs),
    /// Fit a material to a target image of a scene, or to a BRDF.
    Fit(fit::FitArgs),
    /// Write the scene's illumination model as shaders: GLSL, WGSL, a WebGL2 page, a three.js material or a BRDF Explorer file.
    Shader(shader::ShaderArgs),
    /// List the built-in materials, or show one.
    Materials {
        /// A material name (case, spaces, '-' and '_' ignored).
        name: Option<String>,
    },
}

/// An error in what the user gave (exit code 2).
#[derive(Debug)]
struct InputError(String);
impl std::fmt::Display for InputError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}
impl std::error::Error for InputError {}

fn input<T>(r: Result<T, String>) -> Result<T> {
    r.map_err(|m| InputError(m).into())
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    // A panic is a bug: one line and exit 1, not a backtrace (RUST_BACKTRACE=1 still gives one).
    if std::env::var_os("RUST_BACKTRACE").is_none() {
        std::panic::set_hook(Box::new(|info| {
            eprintln!("error: internal error (a bug in phong; please report it): {info}");
        }));
    }
    let result = match std::panic::catch_unwind(move || run(cli)) {
        Ok(r) => r,
        Err(_) => return ExitCode::from(1),
    };
    report(result)
}

fn run(cli: Cli) -> Result<()> {
    phong_scene::set_texture_store(texture_store(cli.texture_cache));
    match cli.command {
        Command::Render(args) => render::render(args),
        Command::Batch(args) => batch::batch(args),
        Command::Bench(args) => bench::bench(args),
        Command::Serve(args) => serve::serve(args),
        Command::Fit(args) => fit::fit(args),
        Command::Shader(args) => shader::shader(args),
        Command::Materials { name } => materials::materials(name.as_deref()),
    }
}

/// The exit code of a command's result, its error printed: 2 where a library says the error
/// is in the input (its `is_input`), else 1.
fn report(result: Result<()>) -> ExitCode {
    let Err(e) = result else {
        return ExitCode::SUCCESS;
    };
    eprintln!("error: {e:#}");
    let is_input = e.chain().any(|c| {
        c.is::<InputError>()
            || c.is::<phong_core::Error>()
            || c.downcast_ref::<phong_scene::Error>().is_some_and(|e| e.is_input())
            || c.downcast_ref::<phong_raster::Error>().is_some_and(|e| e.is_input())
            || c.downcast_ref::<phong_run::Error>().is_some_and(|e| e.is_input())
            || c.downcast_ref::<phong_gpu::Error>().is_some_and(|e| e.is_input())
            || c.downcast_ref::<phong_fit::FitError>().is_some_and(|e| e.is_input())
            || c.downcast_ref::<phong_serve::StartError>()
                .is_some_and(|e| e.is_input())
    });
    ExitCode::from(if is_input { 2 } else { 1 })
}

/// An error (exit 2) when `output` is one of the files read: the same path, a symlink to it, or
/// a hard link (the same device and inode).
fn refuse_overwriting(output: &std::path::Path, inputs: &[PathBuf]) -> Result<()> {
    use std::os::unix::fs::MetadataExt;
    let Ok(out) = std::fs::metadata(output) else {
        return Ok(()); // not there yet: it cannot be an input
    };
    for input in inputs {
        if let Ok(m) = std::fs::metadata(input)
            && (m.dev(), m.ino()) == (out.dev(), out.ino())
        {
            bail!(InputError(format!(
                "the output {} is the input {}: refusing to overwrite it",
                output.display(),
                input.display()
            )));
        }
    }
    Ok(())
}
