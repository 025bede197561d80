//! `phong batch`: many renders from a JSON Lines file in one process, a shard of them for a
//! cluster's array job, resumable (complete outputs are skipped), each job's outcome in
//! `DIR/results-I-of-N.jsonl`.

use crate::InputError;
use crate::args::{Backend, GpuPathArg};
use anyhow::{Context, Result, bail};
use indicatif::{ProgressBar, ProgressStyle};
use phong_raster::{RenderOptions, Renderer};
use phong_run::{Models, Settings, Source};
use rayon::prelude::*;
use serde_json::{Map, Value, json};
use std::io::{BufRead, IsTerminal, Write};
use std::path::{Component, Path, PathBuf};
use std::sync::Mutex;
use std::time::Instant;

#[derive(clap::Args)]
pub struct BatchArgs {
    /// The jobs: one JSON object a line (`{"scene": "model.obj", "out": "a.png", ...}`; see
    /// docs/batch.md).
    pub jobs: PathBuf,
    /// The folder the images (and the results file) are written to.
    #[arg(long = "out", value_name = "DIR")]
    pub out: PathBuf,
    /// This process's share: the jobs whose line number ≡ I (mod N). Default: Slurm's
    /// SLURM_ARRAY_TASK_ID/SLURM_ARRAY_TASK_COUNT, or Kubernetes' JOB_COMPLETION_INDEX with
    /// --shards, else every job.
    #[arg(long, value_name = "I/N")]
    pub shard: Option<String>,
    /// The number of shards N where JOB_COMPLETION_INDEX (a Kubernetes Indexed Job) gives I.
    #[arg(long, value_name = "N")]
    pub shards: Option<usize>,
    /// Threads (default: all cores); jobs run side by side on them.
    #[arg(long)]
    pub threads: Option<usize>,
    /// Renderer.
    #[arg(long, value_enum, default_value_t = Backend::Cpu)]
    pub backend: Backend,
    /// Render every job, even where a complete output exists.
    #[arg(long)]
    pub force: bool,
    /// Without a terminal, a progress line every N jobs.
    #[arg(long, value_name = "N", default_value_t = 100)]
    pub progress_every: usize,
}

/// The keys a job line takes.
const KEYS: [&str; 15] = [
    "scene",
    "out",
    "width",
    "height",
    "antialias",
    "output",
    "model",
    "interpolation",
    "view",
    "camera",
    "up",
    "image",
    "shading",
    "light",
    "material",
];

/// A job line read: where its scene is, where it goes, and its settings.
struct Job {
    line: usize,
    out: String,
    scene: JobScene,
    settings: Settings,
}

enum JobScene {
    File(PathBuf),
    Inline(Value),
}

/// What happened to one job.
struct Outcome {
    line: usize,
    out: String,
    status: &'static str,
    seconds: f64,
    message: String,
    input: bool,
}

impl Outcome {
    fn json(&self) -> String {
        json!({"line": self.line, "out": self.out, "status": self.status,
               "seconds": (self.seconds * 1e4).round() / 1e4, "message": self.message})
        .to_string()
    }
}

/// This process's shard `(I, N)`.
fn shard(a: &BatchArgs) -> Result<(usize, usize)> {
    let env = |k: &str| std::env::var(k).ok().filter(|v| !v.is_empty());
    let parse = |what: &str, v: &str| -> Result<usize> {
        v.trim()
            .parse::<usize>()
            .map_err(|_| InputError(format!("{what} must be a whole number, got {v:?}")).into())
    };
    let (i, n) = if let Some(s) = &a.shard {
        let (i, n) = s
            .split_once('/')
            .ok_or_else(|| InputError(format!("--shard must be I/N (0 <= I < N), got {s:?}")))?;
        (parse("--shard's I", i)?, parse("--shard's N", n)?)
    } else if let (Some(id), Some(count)) = (env("SLURM_ARRAY_TASK_ID"), env("SLURM_ARRAY_TASK_COUNT")) {
        let min = env("SLURM_ARRAY_TASK_MIN").map_or(Ok(0), |m| parse("SLURM_ARRAY_TASK_MIN", &m))?;
        let id = parse("SLURM_ARRAY_TASK_ID", &id)?;
        let step = env("SLURM_ARRAY_TASK_STEP").map_or(Ok(1), |m| parse("SLURM_ARRAY_TASK_STEP", &m))?;
        (
            id.saturating_sub(min) / step.max(1),
            parse("SLURM_ARRAY_TASK_COUNT", &count)?,
        )
    } else if let Some(index) = env("JOB_COMPLETION_INDEX") {
        let n = a.shards.ok_or_else(|| {
            InputError(
                "JOB_COMPLETION_INDEX is set (a Kubernetes Indexed Job): give --shards N, the Job's completions".into(),
            )
        })?;
        (parse("JOB_COMPLETION_INDEX", &index)?, n)
    } else {
        (0, a.shards.unwrap_or(1))
    };
    if n == 0 || i >= n {
        bail!(InputError(format!(
            "the shard must be I/N with 0 <= I < N, got {i}/{n}"
        )));
    }
    Ok((i, n))
}

/// A number key of a job line, checked to lie in `lo..=hi`.
fn int_key(o: &Map<String, Value>, key: &str, lo: u64, hi: u64) -> Result<Option<u32>, String> {
    match o.get(key) {
        None | Some(Value::Null) => Ok(None),
        Some(v) => match v.as_u64().filter(|n| (lo..=hi).contains(n)) {
            Some(n) => Ok(Some(n as u32)),
            None => Err(format!("`{key}`: must be a whole number from {lo} to {hi}, got {v}")),
        },
    }
}

/// A string key of a job line.
fn str_key<'a>(o: &'a Map<String, Value>, key: &str) -> Result<Option<&'a str>, String> {
    match o.get(key) {
        None | Some(Value::Null) => Ok(None),
        Some(Value::String(s)) => Ok(Some(s)),
        Some(v) => Err(format!("`{key}`: must be a string, got {v}")),
    }
}

/// Reads one job line (its errors name the key).
fn job(line: usize, text: &str, base: &Path) -> Result<Job, String> {
    let value: Value = serde_json::from_str(text).map_err(|e| format!("not JSON: {e}"))?;
    let Value::Object(o) = value else {
        return Err("a job is a JSON object ({\"scene\": ..., \"out\": ...})".into());
    };
    if let Some(k) = o.keys().find(|k| !KEYS.contains(&k.as_str())) {
        return Err(format!("`{k}`: not a job key (the keys are {})", KEYS.join(", ")));
    }
    let out = str_key(&o, "out")?.ok_or("`out`: missing (the output file's name under --out)")?;
    check_out(out)?;
    let scene = match o.get("scene") {
        None | Some(Value::Null) => return Err("`scene`: missing (a scene or model file, or a scene object)".into()),
        Some(Value::String(s)) if s.is_empty() => return Err("`scene`: an empty path".into()),
        Some(Value::String(s)) => JobScene::File(base.join(s)),
        Some(v @ Value::Object(_)) => JobScene::Inline(v.clone()),
        Some(v) => return Err(format!("`scene`: must be a file's path or a scene object, got {v}")),
    };
    let max = u64::from(phong_core::limits::MAX_IMAGE_DIMENSION);
    let mut settings = Settings {
        width: int_key(&o, "width", 1, max)?,
        height: int_key(&o, "height", 1, max)?,
        ..Settings::default()
    };
    if let Some(n) = int_key(&o, "antialias", 1, 16)? {
        settings.samples =
            Some(phong_core::Samples::from_count(n).map_err(|_| format!("`antialias`: must be 1, 4 or 16, got {n}"))?);
    }
    fn choice<T: Copy>(o: &Map<String, Value>, key: &str, table: &[(&str, T)]) -> Result<Option<T>, String> {
        str_key(o, key)?
            .map(|v| phong_scene::parse_choice(&format!("`{key}`"), v, table))
            .transpose()
    }
    settings.overrides = phong_scene::Overrides {
        model: choice(&o, "model", phong_scene::MODELS)?,
        interpolation: choice(&o, "interpolation", phong_scene::INTERPOLATIONS)?,
        output: choice(&o, "output", phong_scene::OUTPUTS)?,
    };
    let is_model = matches!(&scene, JobScene::File(p) if phong_scene::is_model_path(p));
    let camera_table = matches!(o.get("camera"), Some(Value::Object(_)));
    let model_keys = ["view", "up"].into_iter().chain((!camera_table).then_some("camera"));
    if !is_model && let Some(k) = model_keys.into_iter().find(|k| o.contains_key(*k)) {
        return Err(format!(
            "`{k}`: applies to a model file alone; this job's scene is a scene file or object \
             (give `camera` as a table to set its camera)"
        ));
    }
    let camera = match o.get("camera") {
        None | Some(Value::Null) | Some(Value::Object(_)) => None,
        Some(v) => Some(camera(v)?),
    };
    let quoted = |k: &str| format!("`{k}`");
    settings.view = phong_run::view_options(str_key(&o, "up")?, str_key(&o, "view")?, camera, None, quoted)?;
    for k in ["image", "shading", "light", "material"] {
        if let Some(v) = o.get(k) {
            settings.tables.insert(k.to_string(), v.clone());
        }
    }
    if camera_table {
        settings.tables.insert("camera".into(), o["camera"].clone());
    }
    Ok(Job {
        line,
        out: out.to_string(),
        scene,
        settings,
    })
}

/// A model's camera: `[px, py, pz, tx, ty, tz]`, six numbers (checked further by
/// [`phong_run::view_options`]).
fn camera(v: &Value) -> Result<[f64; 6], String> {
    let n: Option<Vec<f64>> = v
        .as_array()
        .filter(|a| a.len() == 6)
        .and_then(|a| a.iter().map(Value::as_f64).collect());
    n.and_then(|n| n.try_into().ok()).ok_or_else(|| {
        format!("`camera`: must be [px, py, pz, tx, ty, tz] (position, target), six finite numbers, got {v}")
    })
}

/// An output name: a relative `.png` path that stays under the output folder.
fn check_out(out: &str) -> Result<(), String> {
    let p = Path::new(out);
    if out.is_empty() || !p.components().all(|c| matches!(c, Component::Normal(_))) {
        return Err(format!(
            "`out`: must be a relative path under --out without `..`, got {out:?}"
        ));
    }
    if !p.extension().is_some_and(|e| e.eq_ignore_ascii_case("png")) {
        return Err(format!("`out`: must be a .png file, got {out:?}"));
    }
    Ok(())
}

/// This shard's jobs of the jobs file, each read or the outcome of its failure (every line is
/// read: an output is checked against every shard's).
fn read_jobs(a: &BatchArgs, index: usize, count: usize) -> Result<Vec<Result<Job, Outcome>>> {
    let file =
        std::fs::File::open(&a.jobs).map_err(|e| InputError(format!("cannot read {}: {e}", a.jobs.display())))?;
    if !file.metadata().is_ok_and(|m| m.is_file()) {
        bail!(InputError(format!("{}: not a regular file", a.jobs.display())));
    }
    let base = a.jobs.parent().unwrap_or(Path::new("")).to_path_buf();
    let name = a.jobs.display().to_string();
    // Every line is read (outputs are checked for duplicates across all shards); only this
    // shard's are parsed whole.
    let mut jobs: Vec<Result<Job, Outcome>> = Vec::new();
    let mut outs: std::collections::HashMap<String, usize> = Default::default();
    let reader = std::io::BufReader::new(file);
    for (i, text) in reader.split(b'\n').enumerate() {
        let line = i + 1;
        let text = text.with_context(|| format!("reading {}", a.jobs.display()))?;
        let text = String::from_utf8_lossy(&text);
        let text = text.trim();
        if text.is_empty() || text.starts_with('#') {
            continue;
        }
        let mine = line % count == index;
        let parsed = if mine {
            job(line, text, &base)
        } else {
            // Another shard's job: only its output, for the duplicate check.
            serde_json::from_str::<Value>(text)
                .ok()
                .and_then(|v| v.get("out").and_then(Value::as_str).map(str::to_string))
                .map(|out| Job {
                    line,
                    out,
                    scene: JobScene::Inline(Value::Null),
                    settings: Settings::default(),
                })
                .ok_or_else(String::new)
        };
        let parsed = parsed.and_then(|j| match outs.get(&j.out) {
            Some(first) => Err(format!("`out`: {:?} is also line {first}'s output", j.out)),
            None => {
                outs.insert(j.out.clone(), line);
                Ok(j)
            }
        });
        if !mine {
            continue;
        }
        jobs.push(parsed.map_err(|message| {
            Outcome {
                line,
                out: serde_json::from_str::<Value>(text)
                    .ok()
                    .and_then(|v| v.get("out").and_then(Value::as_str).map(str::to_string))
                    .unwrap_or_default(),
                status: "failed",
                seconds: 0.0,
                message: format!("{name}:{line}: {message}"),
                input: true,
            }
        }));
    }
    Ok(jobs)
}

/// Runs `phong batch`.
pub fn batch(a: BatchArgs) -> Result<()> {
    let (index, count) = shard(&a)?;
    crate::args::threads_flag(a.threads)?;
    let jobs = read_jobs(&a, index, count)?;
    let name = a.jobs.display().to_string();
    std::fs::create_dir_all(&a.out).with_context(|| format!("creating {}", a.out.display()))?;
    // Each model file is read once: kept from its first job to its last.
    let models = Models::new();
    let mut uses: std::collections::HashMap<PathBuf, usize> = Default::default();
    for j in jobs.iter().flatten() {
        if let JobScene::File(p) = &j.scene
            && phong_scene::is_model_path(p)
        {
            *uses.entry(p.clone()).or_default() += 1;
        }
    }
    for (p, n) in &uses {
        models.expect(p, *n);
    }
    let gpu = crate::open_gpu(a.backend, GpuPathArg::Auto)?;
    let pool = phong_run::Pool::new(a.threads)?;
    // Jobs run in line order on the pool's threads: a few documents' objects at a time.
    let shared = Shared {
        models,
        built: phong_run::Built::new(2 * pool.threads()),
        gpu: gpu.as_ref(),
    };
    let results_name = format!("results-{index}-of-{count}.jsonl");
    let results_path = a.out.join(&results_name);
    let tmp_path = a.out.join(format!(".{results_name}.{}.tmp", std::process::id()));
    let results =
        Mutex::new(std::fs::File::create(&tmp_path).with_context(|| format!("creating {}", tmp_path.display()))?);
    let total = jobs.len() as u64;
    let bar = if std::io::stderr().is_terminal() {
        let b = ProgressBar::new(total);
        b.set_style(ProgressStyle::with_template("{bar:40} {pos}/{len} {elapsed} eta {eta}").expect("valid template"));
        b
    } else {
        ProgressBar::hidden()
    };
    let done = std::sync::atomic::AtomicU64::new(0);
    let failed = std::sync::atomic::AtomicU64::new(0);
    let start = Instant::now();
    let every = a.progress_every.max(1) as u64;
    let outcomes: Vec<Outcome> = pool.install(|| {
        jobs.into_par_iter()
            .map_init(Renderer::new, |renderer, j| {
                let outcome = match j {
                    Err(o) => o,
                    Ok(j) => run_job(&j, &a, &name, &shared, renderer),
                };
                if outcome.status == "failed" {
                    failed.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    eprintln!("error: {}", outcome.message);
                }
                {
                    let mut f = results.lock().expect("not poisoned");
                    let _ = writeln!(f, "{}", outcome.json());
                }
                let n = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                bar.set_position(n);
                if bar.is_hidden() && (n.is_multiple_of(every) || n == total) {
                    eprintln!(
                        "phong batch: {n}/{total} jobs, {} failed, {:.1}s",
                        failed.load(std::sync::atomic::Ordering::Relaxed),
                        start.elapsed().as_secs_f64()
                    );
                }
                outcome
            })
            .collect()
    });
    bar.finish_and_clear();
    // The results in line order, written whole then renamed over the last run's.
    let mut text = String::new();
    for o in &outcomes {
        text.push_str(&o.json());
        text.push('\n');
    }
    drop(results);
    phong_scene::write_file(&results_path, text.as_bytes())?;
    let _ = std::fs::remove_file(&tmp_path);
    let count_of = |s: &str| outcomes.iter().filter(|o| o.status == s).count();
    eprintln!(
        "phong batch: shard {index}/{count}: {} ok, {} skipped, {} failed in {:.2}s; results in {}",
        count_of("ok"),
        count_of("skipped"),
        count_of("failed"),
        start.elapsed().as_secs_f64(),
        results_path.display()
    );
    let failures: Vec<&Outcome> = outcomes.iter().filter(|o| o.status == "failed").collect();
    if failures.is_empty() {
        Ok(())
    } else if failures.iter().all(|o| o.input) {
        bail!(InputError(format!(
            "{} of {} jobs failed (see {})",
            failures.len(),
            outcomes.len(),
            results_path.display()
        )))
    } else {
        bail!(
            "{} of {} jobs failed (see {})",
            failures.len(),
            outcomes.len(),
            results_path.display()
        )
    }
}

/// Renders one job (or skips it where its output is complete).
/// What every job of a run shares: models read once, objects built once, the GPU.
struct Shared<'a> {
    models: Models,
    built: phong_run::Built,
    gpu: Option<&'a phong_gpu::Gpu>,
}

fn run_job(j: &Job, a: &BatchArgs, name: &str, shared: &Shared, renderer: &mut Renderer) -> Outcome {
    let Shared { models, built, gpu } = shared;
    let t = Instant::now();
    let path = a.out.join(&j.out);
    let outcome = |status, message: String, input| Outcome {
        line: j.line,
        out: j.out.clone(),
        status,
        seconds: t.elapsed().as_secs_f64(),
        message,
        input,
    };
    if !a.force && phong_scene::is_complete_png(&path) {
        return outcome("skipped", "a complete output exists".into(), false);
    }
    let anchor = Path::new(name).with_file_name("scene.json");
    let source = match &j.scene {
        JobScene::File(p) => Source::Path(p),
        JobScene::Inline(v) => Source::Document {
            scene: v,
            anchor: &anchor,
            meshes: None,
        },
    };
    let result = (|| -> Result<(), phong_run::Error> {
        let loaded = phong_run::load_viewed(source, &j.settings, models, built, "width, height, antialias")?;
        for w in &loaded.warnings {
            eprintln!("warning: {name}:{}: {w}", j.line);
        }
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir).map_err(|source| phong_scene::Error::Write {
                path: dir.to_path_buf(),
                source,
            })?;
        }
        let options = RenderOptions::default();
        let backend = match gpu {
            Some(g) => phong_run::Backend::Gpu(g),
            None => phong_run::Backend::Cpu(&options),
        };
        let (picture, _) = phong_run::draw(&loaded.scene, backend, renderer)?;
        picture.write_png(&path)
    })();
    match result {
        Ok(()) => outcome("ok", String::new(), false),
        Err(e) => {
            let input = e.is_input();
            let message = match (&e, &j.scene) {
                (phong_run::Error::Json { error, .. }, JobScene::Inline(_)) => {
                    let at = if error.path.is_empty() {
                        "`scene`".to_string()
                    } else {
                        format!("`scene.{}`", error.path)
                    };
                    format!("{name}:{}: {at}: {}", j.line, error.message)
                }
                _ => format!("{name}:{}: {}", j.line, phong_run::message(&e)),
            };
            outcome("failed", message, input)
        }
    }
}
