//! `phong fit`: arguments, the two fits, what they print and write.

use crate::{InputError, fmt3, input, refuse_overwriting};
use anyhow::{Context, Result, bail};
use phong_core::Material;
use phong_raster::RenderOptions;
use phong_scene::{MODELS, apply_model, parse_choice};
use std::path::PathBuf;
use std::time::Instant;

#[derive(clap::Args)]
pub(crate) struct FitArgs {
    /// The scene (.toml or .obj) the target image shows; not with --brdf.
    scene: Option<PathBuf>,
    /// The target image (PNG, the scene's size).
    #[arg(long, value_name = "TARGET.png")]
    target: Option<PathBuf>,
    /// A reflectance instead of an image: ggx:alpha=A,f0=F,kd=K | beckmann:... |
    /// ward:alpha=A,ks=S,kd=K | merl:FILE.binary (a colour is one number or r/g/b).
    #[arg(long, value_name = "SPEC")]
    brdf: Option<String>,
    /// The object to fit (name or index; needed when the scene has several).
    #[arg(long, value_name = "NAME|INDEX")]
    object: Option<String>,
    /// Parameters to fit: ambient, diffuse, specular, shininess, emission.
    #[arg(long, default_value = "ambient,diffuse,specular,shininess")]
    free: String,
    /// Shading model of the fitted object (image) or of the fit (BRDF: phong or blinn-phong).
    #[arg(long)]
    model: Option<String>,
    /// Only pixels where this PNG is bright (> 50%) are fitted.
    #[arg(long, value_name = "MASK.png")]
    mask: Option<PathBuf>,
    /// How the target's values are encoded (default: the scene's encoding).
    #[arg(long, value_name = "linear|srgb")]
    target_encoding: Option<String>,
    /// Write the fitted material here as a `[materials.NAME]` block (else it is printed).
    #[arg(short = 'o', long = "out", value_name = "FITTED.toml")]
    output: Option<PathBuf>,
    /// Also write it as an MTL entry.
    #[arg(long, value_name = "FITTED.mtl")]
    mtl: Option<PathBuf>,
    /// Write target | fit | difference and the error against the exponent (PNG) here.
    #[arg(long, value_name = "DIR")]
    report: Option<PathBuf>,
    /// The fitted material's name.
    #[arg(long, default_value = "fitted")]
    name: String,
    /// Rendering threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
}

/// `phong fit`: the material, its errors and what the target leaves undetermined.
pub(crate) fn fit(a: FitArgs) -> Result<()> {
    let name_ok = !a.name.is_empty()
        && a.name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
    if !name_ok {
        bail!(InputError(format!(
            "--name must be letters, digits, '-' or '_', got \"{}\"",
            a.name
        )));
    }
    if let Some(dir) = &a.report
        && dir.exists()
        && !dir.is_dir()
    {
        bail!(InputError(format!("--report {}: not a directory", dir.display())));
    }
    let (material, comment) = match (&a.brdf, &a.scene) {
        (Some(_), Some(_)) => bail!(InputError("give a scene and --target, or --brdf, not both".into())),
        (None, None) => bail!(InputError(
            "phong fit needs SCENE.toml --target TARGET.png, or --brdf SPEC".into()
        )),
        (Some(spec), None) => fit_brdf(&a, spec)?,
        (None, Some(scene)) => fit_image(&a, scene)?,
    };
    let block = format!("{comment}{}", phong_fit::toml_block(&a.name, &material));
    match &a.output {
        Some(p) => {
            phong_scene::write_file(p, block.as_bytes())?;
            println!("wrote {}", p.display());
        }
        None => print!("\n{block}"),
    }
    if let Some(p) = &a.mtl {
        phong_scene::write_file(p, phong_fit::mtl_entry(&a.name, &material).as_bytes())?;
        println!("wrote {}", p.display());
    }
    Ok(())
}

/// [`refuse_overwriting`] for each of the fit's output files.
fn refuse_overwriting_outputs(a: &FitArgs, inputs: &[PathBuf]) -> Result<()> {
    for out in [&a.output, &a.mtl].into_iter().flatten() {
        refuse_overwriting(out, inputs)?;
    }
    Ok(())
}

fn print_material(m: &Material) {
    println!("  ambient   {}", fmt3(m.ambient()));
    println!("  diffuse   {}", fmt3(m.diffuse()));
    println!("  specular  {}", fmt3(m.specular()));
    println!("  emission  {}", fmt3(m.emission()));
    println!("  shininess {:.4}", m.shininess());
}

fn report_dir(a: &FitArgs) -> Result<Option<&std::path::Path>> {
    if let Some(dir) = &a.report {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    Ok(a.report.as_deref())
}

fn fit_image(a: &FitArgs, scene_path: &std::path::Path) -> Result<(Material, String)> {
    let Some(target_path) = &a.target else {
        bail!(InputError("phong fit SCENE needs --target TARGET.png".into()));
    };
    crate::args::threads_flag(a.threads)?;
    let free = phong_fit::image::Free::parse(&a.free)?;
    let loaded = phong_scene::load(scene_path)?;
    for w in &loaded.warnings {
        eprintln!("warning: {w}");
    }
    let inputs: Vec<PathBuf> = loaded
        .sources
        .iter()
        .chain([target_path])
        .chain(&a.mask)
        .cloned()
        .collect();
    refuse_overwriting_outputs(a, &inputs)?;
    let mut scene = loaded.scene;
    let object = phong_fit::image::find_object(&scene, a.object.as_deref())?;
    if let Some(m) = &a.model {
        let model = input(parse_choice("--model", m, MODELS))?;
        apply_model(
            &mut scene.objects[object].shading.options,
            model,
            (3, phong_core::LyonLambda::Dot),
        );
    }
    let encoding = match a.target_encoding.as_deref() {
        None => scene.image.encoding,
        Some("linear") => phong_core::Encoding::Linear,
        Some("srgb") => phong_core::Encoding::Srgb,
        Some(o) => bail!(InputError(format!(
            "--target-encoding must be linear or srgb, got \"{o}\""
        ))),
    };
    let target = phong_fit::image::Target::read(target_path, encoding)?;
    let mask = match &a.mask {
        Some(p) => {
            let m = phong_fit::image::Target::read(p, phong_core::Encoding::Linear)?;
            if (m.width, m.height) != (target.width, target.height) {
                bail!(InputError(format!(
                    "--mask {} is {}x{}, the target {}x{}",
                    p.display(),
                    m.width,
                    m.height,
                    target.width,
                    target.height
                )));
            }
            Some(
                m.rgb
                    .iter()
                    .map(|p| p.iter().cloned().fold(0.0, f32::max) > 0.5)
                    .collect::<Vec<_>>(),
            )
        }
        None => None,
    };
    let t0 = Instant::now();
    let options = RenderOptions {
        threads: a.threads,
        ..RenderOptions::default()
    };
    let fit = phong_fit::image::fit_image(&scene, object, &target, free, mask.as_deref(), options)?;
    let elapsed = t0.elapsed();
    println!(
        "phong fit: object {object} ({}), {} pixels, {} exponents tried, {:.0} ms",
        scene.objects[object].name,
        fit.pixels,
        fit.curve.len(),
        elapsed.as_secs_f64() * 1e3
    );
    print_material(&fit.material);
    println!(
        "  rmse {:.5} (linear colour, fitted pixels), psnr {:.2} dB",
        fit.rmse, fit.psnr
    );
    for n in &fit.notes {
        println!("  note: {n}");
    }
    println!(
        "  nearest classic material: {} (rmse {:.5})",
        fit.nearest.0, fit.nearest.1
    );
    for u in &fit.undetermined {
        println!("  undetermined: {u}");
    }
    if let Some(dir) = report_dir(a)? {
        // The yardstick: the model's best material by brute force over the exponent.
        let options = RenderOptions {
            threads: a.threads,
            ..RenderOptions::default()
        };
        let best = phong_fit::image::best_by_search(&scene, object, &target, free, mask.as_deref(), options)?;
        println!(
            "  brute-force best of this model: psnr {:.2} dB at s = {:.1} (400 exponents, exact colours); the fit is {:+.2} dB from it",
            best.psnr,
            best.shininess,
            fit.psnr - best.psnr
        );
        phong_fit::report::write(
            &dir.join("comparison.png"),
            &phong_fit::report::comparison(&target, &fit.image, &fit.used),
        )?;
        phong_fit::report::write(
            &dir.join("error.png"),
            &phong_fit::report::error_plot(&fit.curve, fit.material.shininess(), "RMSE against the exponent s"),
        )?;
        println!(
            "wrote {}/comparison.png (target | fit | 4x difference) and error.png",
            dir.display()
        );
    }
    let comment = format!(
        "# phong fit of {} to {}: rmse {:.5}, psnr {:.2} dB\n",
        scene_path.display(),
        target_path.display(),
        fit.rmse,
        fit.psnr
    );
    Ok((fit.material, comment))
}

fn fit_brdf(a: &FitArgs, spec: &str) -> Result<(Material, String)> {
    if a.target.is_some() || a.object.is_some() || a.mask.is_some() {
        bail!(InputError(
            "--brdf fits a reflectance: --target, --object and --mask are for images".into()
        ));
    }
    let model = match a.model.as_deref().unwrap_or("blinn-phong") {
        "phong" => phong_core::SpecularModel::Phong,
        "blinn-phong" => phong_core::SpecularModel::BlinnPhong,
        o => bail!(InputError(format!(
            "--model for a BRDF fit is phong or blinn-phong, got \"{o}\""
        ))),
    };
    if let Some(f) = spec.strip_prefix("merl:") {
        refuse_overwriting_outputs(a, &[PathBuf::from(f)])?;
    }
    let brdf = phong_fit::brdf::Brdf::parse(spec)?;
    let t0 = Instant::now();
    let fit = phong_fit::brdf::fit_brdf(&brdf, model)?;
    let norm = if model == phong_core::SpecularModel::Phong {
        "phong"
    } else {
        "blinn-phong"
    };
    println!(
        "phong fit: {spec}, {} samples, {} exponents tried, {:.0} ms",
        fit.samples,
        fit.curve.len(),
        t0.elapsed().as_secs_f64() * 1e3
    );
    print_material(&fit.material);
    println!(
        "  rmse {:.5} (cosine-weighted f·cos θ), for model = \"{}\", normalization = \"{norm}\"",
        fit.rmse,
        a.model.as_deref().unwrap_or("blinn-phong")
    );
    let mut table = String::from("  error by incident angle:\n");
    for (lo, hi, e, n) in &fit.by_incidence {
        table.push_str(&format!("    {lo:>4.0}-{hi:<3.0} deg  rmse {e:.5}  ({n} samples)\n"));
    }
    print!("{table}");
    if let Some(dir) = report_dir(a)? {
        let phong = |l: [f64; 3], v: [f64; 3]| phong_fit::brdf::fitted_lobe(&fit, l, v);
        let target = |l: [f64; 3], v: [f64; 3]| brdf.eval(l, v).map(|f| f[1] * l[2]);
        phong_fit::report::write(&dir.join("lobes.png"), &phong_fit::report::lobe_plot(target, phong))?;
        phong_scene::write_file(&dir.join("errors.txt"), table.as_bytes())?;
        phong_fit::report::write(
            &dir.join("error.png"),
            &phong_fit::report::error_plot(&fit.curve, fit.material.shininess(), "RMSE against the exponent s"),
        )?;
        println!(
            "wrote {}/lobes.png (polar, green channel: target orange, fit blue), error.png and errors.txt",
            dir.display()
        );
    }
    let comment = format!(
        "# phong fit of {spec}: rmse {:.5}; render with [shading] model = \"{}\", normalization = \"{norm}\"\n",
        fit.rmse,
        a.model.as_deref().unwrap_or("blinn-phong")
    );
    Ok((fit.material, comment))
}
