//! `phong batch` as a user runs it: every image the same file as `phong render`'s, shards
//! that partition the jobs, resumption, and bad jobs reported without stopping the others.

use serde_json::{Value, json};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn phong(args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_phong"));
    c.args(args).current_dir(root());
    for k in [
        "SLURM_ARRAY_TASK_ID",
        "SLURM_ARRAY_TASK_COUNT",
        "SLURM_ARRAY_TASK_MIN",
        "JOB_COMPLETION_INDEX",
    ] {
        c.env_remove(k);
    }
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().expect("run phong")
}

fn s(p: &Path) -> &str {
    p.to_str().expect("a UTF-8 path")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A jobs file in `dir` with these lines; a small OBJ model beside it.
fn jobs_file(dir: &Path, lines: &[Value]) -> PathBuf {
    std::fs::write(
        dir.join("tetra.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n",
    )
    .expect("write model");
    let text: String = lines.iter().map(|l| format!("{l}\n")).collect();
    let path = dir.join("jobs.jsonl");
    std::fs::write(&path, text).expect("write jobs");
    std::fs::write(dir.join("scene.toml"), scene_toml("blinn-phong", "0.3")).expect("write scene");
    path
}

/// A scene file with a mesh, two shapes and a `[shading]` table.
fn scene_toml(model: &str, ambient: &str) -> String {
    format!(
        "[shading]\nmodel = \"{model}\"\nambient = [{ambient}, {ambient}, {ambient}]\n\
         [[light]]\ntype = \"directional\"\ndirection = [-1, -1, -1]\n\
         [[object]]\nshape = \"sphere\"\nmaterial = \"gold\"\nposition = [-1.2, 0, 0]\n\
         [[object]]\nmesh = \"tetra.obj\"\nmaterial = \"jade\"\nposition = [1, 0, 0]\n"
    )
}

fn results(dir: &Path, name: &str) -> Vec<Value> {
    std::fs::read_to_string(dir.join(name))
        .expect("results file")
        .lines()
        .map(|l| serde_json::from_str(l).expect("a JSON line"))
        .collect()
}

/// The varied jobs most tests use: a model's views, a scene file with overrides, an inline
/// scene.
fn sample_jobs() -> Vec<Value> {
    vec![
        json!({"scene": "tetra.obj", "out": "t/front.png", "width": 64, "height": 48, "view": "front"}),
        json!({"scene": "tetra.obj", "out": "t/iso.png", "width": 64, "height": 48, "view": "iso", "antialias": 1}),
        json!({"scene": "tetra.obj", "out": "t/cam.png", "width": 40, "height": 40, "camera": [3, 2, 4, 0.25, 0.25, 0.25], "up": "y"}),
        json!({"scene": "tetra.obj", "out": "t/gold.png", "width": 40, "height": 30, "material": "gold", "model": "phong"}),
        json!({"scene": "scene.toml", "out": "shin.png", "width": 160, "height": 60, "output": "specular",
               "shading": {"model": "phong", "ambient": [0.1, 0.1, 0.1]}}),
        json!({"scene": {"object": [{"shape": "sphere", "material": "jade"}],
                         "light": [{"type": "point", "position": [2, 2, 2]}]},
               "out": "inline.png", "width": 32, "height": 32}),
    ]
}

/// The `phong render` command line equivalent to each sample job, run in `dir`.
fn render_equivalents(dir: &Path) -> Vec<(String, Vec<String>)> {
    let t = s(&dir.join("tetra.obj")).to_string();
    let scene = dir.join("inline.toml");
    std::fs::write(
        &scene,
        "[[object]]\nshape = \"sphere\"\nmaterial = \"jade\"\n[[light]]\ntype = \"point\"\nposition = [2, 2, 2]\n",
    )
    .expect("write scene");
    // `shading` merged over scene.toml's own [shading].
    let merged = dir.join("merged.toml");
    std::fs::write(&merged, scene_toml("phong", "0.1")).expect("write merged");
    let v = |a: &[&str]| a.iter().map(|x| x.to_string()).collect::<Vec<_>>();
    vec![
        (
            "t/front.png".into(),
            v(&[&t, "--width", "64", "--height", "48", "--view", "front"]),
        ),
        (
            "t/iso.png".into(),
            v(&[
                &t,
                "--width",
                "64",
                "--height",
                "48",
                "--view",
                "iso",
                "--antialias",
                "1",
            ]),
        ),
        (
            "t/cam.png".into(),
            v(&[
                &t,
                "--width",
                "40",
                "--height",
                "40",
                "--camera",
                "3,2,4,0.25,0.25,0.25",
                "--up",
                "y",
            ]),
        ),
        (
            "shin.png".into(),
            v(&[s(&merged), "--width", "160", "--height", "60", "--output", "specular"]),
        ),
        ("inline.png".into(), v(&[s(&scene), "--width", "32", "--height", "32"])),
    ]
}

#[test]
fn every_image_is_the_file_phong_render_writes() {
    let dir = tempfile::tempdir().expect("tempdir");
    let jobs = jobs_file(dir.path(), &sample_jobs());
    let out = dir.path().join("out");
    let o = phong(&["batch", s(&jobs), "--out", s(&out)], &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    for (name, args) in render_equivalents(dir.path()) {
        let single = dir.path().join("single.png");
        let mut a: Vec<&str> = vec!["render"];
        a.extend(args.iter().map(String::as_str));
        a.extend(["-o", s(&single)]);
        let r = phong(&a, &[]);
        assert!(r.status.success(), "{:?}: {}", a, stderr(&r));
        let expected = std::fs::read(&single).expect("single render");
        let got = std::fs::read(out.join(&name)).unwrap_or_else(|_| panic!("{name} written"));
        assert!(got == expected, "{name} differs from `phong {}`", a.join(" "));
    }
    let r = results(&out, "results-0-of-1.jsonl");
    assert_eq!(r.len(), 6);
    for (i, line) in r.iter().enumerate() {
        assert_eq!(line["line"], json!(i + 1));
        assert_eq!(line["status"], json!("ok"), "{line}");
        assert!(line["seconds"].as_f64().is_some_and(|t| t >= 0.0));
    }
    // No temporary file is left.
    let leftovers: Vec<_> = walk(&out).into_iter().filter(|p| s(p).ends_with(".tmp")).collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}

fn walk(dir: &Path) -> Vec<PathBuf> {
    let mut v = Vec::new();
    for e in std::fs::read_dir(dir).expect("read dir").flatten() {
        let p = e.path();
        if p.is_dir() {
            v.extend(walk(&p));
        } else {
            v.push(p);
        }
    }
    v
}

#[test]
fn shards_partition_the_jobs_by_line_number() {
    let dir = tempfile::tempdir().expect("tempdir");
    let jobs = jobs_file(dir.path(), &sample_jobs());
    let out = dir.path().join("out");
    // --shard I/N, Slurm's array variables (ids from 1), Kubernetes' completion index.
    type Env<'a> = Vec<(&'a str, &'a str)>;
    let runs: [(&[&str], Env); 3] = [
        (&["--shard", "0/3"], vec![]),
        (
            &[],
            vec![
                ("SLURM_ARRAY_TASK_ID", "2"),
                ("SLURM_ARRAY_TASK_COUNT", "3"),
                ("SLURM_ARRAY_TASK_MIN", "1"),
            ],
        ),
        (&["--shards", "3"], vec![("JOB_COMPLETION_INDEX", "2")]),
    ];
    for (flags, env) in &runs {
        let mut a = vec!["batch", s(&jobs), "--out", s(&out)];
        a.extend(flags.iter());
        let o = phong(&a, env);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let mut seen = Vec::new();
    for i in 0..3 {
        let r = results(&out, &format!("results-{i}-of-3.jsonl"));
        for line in &r {
            let n = line["line"].as_u64().expect("a line number");
            assert_eq!(n % 3, i, "shard {i} took line {n}");
            seen.push(n);
        }
    }
    seen.sort();
    assert_eq!(seen, [1, 2, 3, 4, 5, 6], "every job once");
    assert_eq!(walk(&out).iter().filter(|p| s(p).ends_with(".png")).count(), 6);
    // A shard outside its count, and a completion index without --shards, are refused.
    let o = phong(&["batch", s(&jobs), "--out", s(&out), "--shard", "3/3"], &[]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let o = phong(&["batch", s(&jobs), "--out", s(&out)], &[("JOB_COMPLETION_INDEX", "0")]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("--shards"), "{}", stderr(&o));
}

#[test]
fn a_rerun_renders_only_what_is_missing_or_incomplete() {
    let dir = tempfile::tempdir().expect("tempdir");
    let jobs = jobs_file(dir.path(), &sample_jobs());
    let out = dir.path().join("out");
    let run = || {
        let o = phong(&["batch", s(&jobs), "--out", s(&out)], &[]);
        assert!(o.status.success(), "{}", stderr(&o));
        results(&out, "results-0-of-1.jsonl")
    };
    run();
    let iso = std::fs::read(out.join("t/iso.png")).expect("iso");
    std::fs::remove_file(out.join("t/front.png")).expect("remove");
    // A file cut short, as by a crash of another writer.
    std::fs::write(out.join("inline.png"), &iso[..iso.len() / 2]).expect("truncate");
    let r = run();
    let status: Vec<&str> = r.iter().map(|l| l["status"].as_str().expect("status")).collect();
    assert_eq!(status, ["ok", "skipped", "skipped", "skipped", "skipped", "ok"]);
    assert!(phong_png(&out.join("inline.png")));
    let o = phong(&["batch", s(&jobs), "--out", s(&out), "--force"], &[]);
    assert!(o.status.success());
    assert!(
        results(&out, "results-0-of-1.jsonl")
            .iter()
            .all(|l| l["status"] == "ok")
    );
}

fn phong_png(p: &Path) -> bool {
    let dec = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(p).expect("open")));
    let Ok(mut r) = dec.read_info() else {
        return false;
    };
    let mut buf = vec![0; r.output_buffer_size().expect("size")];
    r.next_frame(&mut buf).is_ok()
}

#[test]
fn bad_jobs_are_reported_by_line_and_key_and_the_others_rendered() {
    let dir = tempfile::tempdir().expect("tempdir");
    let lines = vec![
        json!({"scene": "tetra.obj", "out": "good.png", "width": 16, "height": 16}),
        json!({"scene": "tetra.obj", "out": "a.png", "widht": 16}),
        json!({"scene": "missing.obj", "out": "b.png"}),
        json!({"scene": {"object": [{"shape": "sphere", "material": "unobtainium"}]}, "out": "c.png"}),
        json!({"scene": "tetra.obj", "out": "../escape.png"}),
        json!({"scene": "tetra.obj", "out": "good.png"}),
        json!({"scene": "tetra.obj", "out": "d.png", "width": 0}),
        json!({"scene": {"light": [{"type": "laser"}]}, "out": "e.png"}),
        json!({"scene": "tetra.obj", "out": "f.png", "camera": [1, 2]}),
        json!({"scene": s(&root().join("examples/scenes/terms.toml")), "out": "g.png", "view": "top"}),
        json!({"scene": "tetra.obj", "out": "h.png", "shading": {"model": "glossy"}}),
    ];
    let jobs = jobs_file(dir.path(), &lines);
    let mut text = std::fs::read_to_string(&jobs).expect("read");
    text.push_str("{not json\n");
    std::fs::write(&jobs, text).expect("write");
    let out = dir.path().join("out");
    let o = phong(&["batch", s(&jobs), "--out", s(&out)], &[]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let r = results(&out, "results-0-of-1.jsonl");
    let msg = |line: usize| -> String {
        let l = &r[line - 1];
        assert_eq!(
            l["status"],
            json!(if line == 1 { "ok" } else { "failed" }),
            "line {line}: {l}"
        );
        l["message"].as_str().expect("message").to_string()
    };
    let jobs_name = s(&jobs);
    let expect = [
        (2, "`widht`: not a job key"),
        (3, "missing.obj"),
        (4, "`scene.object[0].material`: unknown material \"unobtainium\""),
        (5, "`out`: must be a relative path"),
        (6, "`out`: \"good.png\" is also line 1's output"),
        (7, "`width`: must be a whole number from 1 to"),
        (8, "`scene.light[0].type`"),
        (9, "`camera`: must be [px, py, pz, tx, ty, tz]"),
        (10, "`view`: applies to a model file alone"),
        (11, "`shading.model`"),
        (12, "not JSON"),
    ];
    assert!(msg(1).is_empty());
    for (line, text) in expect {
        let m = msg(line);
        assert!(m.starts_with(&format!("{jobs_name}:{line}: ")), "line {line}: {m}");
        assert!(m.contains(text), "line {line}: {m:?} should say {text:?}");
    }
    assert!(out.join("good.png").exists());
    assert!(!dir.path().join("escape.png").exists());
    let written: Vec<_> = walk(&out).into_iter().filter(|p| s(p).ends_with(".png")).collect();
    assert_eq!(written.len(), 1, "{written:?}");
}

#[test]
fn a_missing_jobs_file_is_an_input_error() {
    let dir = tempfile::tempdir().expect("tempdir");
    let o = phong(
        &["batch", s(&dir.path().join("none.jsonl")), "--out", s(dir.path())],
        &[],
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("none.jsonl"), "{}", stderr(&o));
}
