//! `phong shader`: the scene's illumination model as shaders (phong-shader).

use crate::args::{RunArgs, ShadingArgs};
use crate::{InputError, refuse_overwriting};
use anyhow::{Result, bail};
use phong_shader::{Version, html, program, program_of, threejs};
use std::path::PathBuf;

/// What `phong shader` writes.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum Target {
    /// A vertex/fragment pair in GLSL 1.20 (the course's form), with its uniforms as JSON.
    Glsl,
    /// The pair in GLSL 3.30 core.
    Glsl330,
    /// The pair in GLSL ES 3.00 (WebGL2).
    Glsl300es,
    /// One standalone WebGL2 page drawing the scene with the shaders.
    Html,
    /// One WGSL module (`vs_main`, `fs_main`) for WebGPU, with its uniforms as JSON.
    Wgsl,
    /// A BRDF Explorer analytic file (`.brdf`) of one object's material under its model.
    Brdf,
    /// A three.js module (`phong-material.js`: `phongMaterial(THREE, i)`) and an example page
    /// (`index.html`), written into the folder `-o` names.
    Threejs,
}

#[derive(clap::Args)]
pub struct ShaderArgs {
    #[command(flatten)]
    pub run: RunArgs,
    /// What to write.
    #[arg(long, value_enum, default_value = "glsl")]
    pub target: Target,
    /// Output: the page for `html`; the folder for `threejs`; for the GLSL targets a stem,
    /// written as STEM.vert, STEM.frag and STEM.json (the uniforms' values). Default:
    /// standard output.
    #[arg(short = 'o', long = "out")]
    pub output: Option<PathBuf>,
    /// The object whose shaders to write (its name or index): for the GLSL targets where the
    /// scene's objects are shaded differently, and for `brdf` (default: the first).
    #[arg(long, value_name = "NAME|INDEX")]
    pub object: Option<String>,
    #[command(flatten)]
    pub shading: ShadingArgs,
}

/// Writes the shaders of `a.run.input`'s scene.
pub fn shader(a: ShaderArgs) -> Result<()> {
    let job = a.run.resolve(Some(&a.shading))?;
    let unsupported = |e: phong_shader::Unsupported| InputError(format!("{}: cannot export: {e}", job.input.display()));
    let files: Vec<(Option<PathBuf>, String)> = match a.target {
        Target::Html => vec![(a.output.clone(), html(&job.scene).map_err(unsupported)?)],
        Target::Wgsl => {
            let index = a.object.as_deref().map(|o| object_index(&job.scene, o)).transpose()?;
            let module = phong_shader::wgsl(&job.scene, index).map_err(unsupported)?;
            let values = match index {
                Some(i) => program_of(&job.scene, i, Version::Es300),
                None => program(&job.scene, Version::Es300),
            }
            .map_err(unsupported)?
            .uniforms;
            let json = serde_json::to_string_pretty(&values)? + "\n";
            match &a.output {
                None => vec![(None, module)],
                Some(stem) => vec![
                    (Some(stem.with_extension("wgsl")), module),
                    (Some(stem.with_extension("json")), json),
                ],
            }
        }
        Target::Brdf => {
            let index = object_index(&job.scene, a.object.as_deref().unwrap_or("0"))?;
            vec![(
                a.output.clone(),
                phong_shader::brdf(&job.scene, index).map_err(unsupported)?,
            )]
        }
        Target::Threejs => {
            let Some(dir) = &a.output else {
                bail!(InputError(
                    "--target threejs writes a folder: name it with -o DIR".into()
                ));
            };
            let (module, page) = threejs(&job.scene).map_err(unsupported)?;
            std::fs::create_dir_all(dir)
                .map_err(|e| InputError(format!("cannot create the folder {}: {e}", dir.display())))?;
            vec![
                (Some(dir.join("phong-material.js")), module),
                (Some(dir.join("index.html")), page),
            ]
        }
        t => {
            let version = match t {
                Target::Glsl => Version::Legacy120,
                Target::Glsl330 => Version::Core330,
                _ => Version::Es300,
            };
            let p = match &a.object {
                None => program(&job.scene, version),
                Some(o) => {
                    let index = object_index(&job.scene, o)?;
                    program_of(&job.scene, index, version)
                }
            }
            .map_err(unsupported)?;
            let json = serde_json::to_string_pretty(&p.uniforms)? + "\n";
            match &a.output {
                None => vec![(
                    None,
                    format!(
                        "// ---- vertex shader ----\n{}\n// ---- fragment shader ----\n{}\n// ---- uniforms (JSON) ----\n{json}",
                        p.vertex, p.fragment
                    ),
                )],
                Some(stem) => ["vert", "frag", "json"]
                    .into_iter()
                    .zip([p.vertex, p.fragment, json])
                    .map(|(ext, text)| (Some(stem.with_extension(ext)), text))
                    .collect(),
            }
        }
    };
    for (path, text) in files {
        match path {
            None => print!("{text}"),
            Some(p) => {
                if p.as_os_str().is_empty() {
                    bail!(InputError("an empty output path".into()));
                }
                if p.is_dir() {
                    bail!(InputError(format!("output {} is a folder: name a file", p.display())));
                }
                refuse_overwriting(&p, &job.sources)?;
                phong_scene::write_file(&p, text.as_bytes())?;
            }
        }
    }
    Ok(())
}

/// The index of the object `o` names (its index or its name).
fn object_index(scene: &phong_core::Scene, o: &str) -> Result<usize> {
    let objects = &scene.objects;
    o.parse::<usize>()
        .ok()
        .filter(|&i| i < objects.len())
        .or_else(|| objects.iter().position(|x| x.name == *o))
        .ok_or_else(|| {
            let names: Vec<_> = objects.iter().map(|x| format!("`{}`", x.name)).collect();
            InputError(format!(
                "--object {o}: no such object (the scene's: {}, or an index below {})",
                names.join(", "),
                objects.len()
            ))
            .into()
        })
}
