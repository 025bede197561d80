"""`phong batch` under the schedulers of examples/batch: a real one-node Slurm cluster (job
arrays through sbatch), a local Ray cluster, and the Kubernetes Indexed Job's command with each
completion index. PHONG_REQUIRE_SLURM=1 / PHONG_REQUIRE_RAY=1 turn a missing scheduler into a
failure instead of a skip."""

import json
import os
import shutil
import subprocess
import sys

import numpy as np
import pytest

import phong
from conftest import EXAMPLES, ROOT, phong_bin, read_png, run_phong

BATCH = ROOT / "examples" / "batch"


def require(var, why):
    if os.environ.get(var) == "1":
        pytest.fail(f"{var}=1 and {why}")
    pytest.skip(why)


def write_jobs(tmp_path, n_views=4):
    """Jobs over a model's views and two example scenes; their `phong render` equivalents."""
    model = tmp_path / "tetra.obj"
    model.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n")
    jobs, renders = [], []
    views = ["front", "back", "left", "right", "top", "bottom", "iso"][:n_views]
    for v in views:
        jobs.append({"scene": "tetra.obj", "out": f"tetra/{v}.png", "width": 48, "height": 36, "view": v})
        renders.append((f"tetra/{v}.png", [model, "--width", 48, "--height", 36, "--view", v]))
    for name in ("shininess", "terms"):
        scene = EXAMPLES / f"{name}.toml"
        jobs.append({"scene": str(scene), "out": f"{name}.png", "width": 120, "height": 40})
        renders.append((f"{name}.png", [scene, "--width", 120, "--height", 40]))
    path = tmp_path / "jobs.jsonl"
    path.write_text("".join(json.dumps(j) + "\n" for j in jobs))
    return path, renders


def check_outputs(tmp_path, out, renders, exact_bytes=True):
    written = sorted(p.relative_to(out).as_posix() for p in out.rglob("*.png"))
    assert written == sorted(name for name, _ in renders), written
    for name, args in renders:
        single = tmp_path / "single.png"
        run_phong("render", *args, "-o", single)
        if exact_bytes:
            assert (out / name).read_bytes() == single.read_bytes(), name
        else:
            assert np.array_equal(read_png(out / name), read_png(single)), name


def test_slurm_job_array(tmp_path):
    if shutil.which("sbatch") is None:
        require("PHONG_REQUIRE_SLURM", "Slurm is not installed (.ci/slurm-up starts a one-node cluster)")
    if subprocess.run(["sinfo", "-h"], capture_output=True).returncode != 0:
        require("PHONG_REQUIRE_SLURM", "no Slurm controller answers (.ci/slurm-up starts one)")
    jobs, renders = write_jobs(tmp_path)
    out = tmp_path / "out"
    env = dict(os.environ, JOBS=str(jobs), OUT=str(out), PHONG=os.path.abspath(phong_bin()))
    r = subprocess.run(
        ["sbatch", "--wait", "--array=0-2", f"--chdir={tmp_path}", f"--output={tmp_path}/slurm-%A_%a.log",
         "--export=ALL", str(BATCH / "slurm.sh")],
        env=env, capture_output=True, text=True, timeout=300,
    )
    logs = "".join(p.read_text() for p in tmp_path.glob("slurm-*.log"))
    assert r.returncode == 0, f"{r.stdout}{r.stderr}{logs}"
    check_outputs(tmp_path, out, renders)
    lines = []
    for i in range(3):
        for l in (out / f"results-{i}-of-3.jsonl").read_text().splitlines():
            rec = json.loads(l)
            assert rec["status"] == "ok" and rec["line"] % 3 == i, rec
            lines.append(rec["line"])
    assert sorted(lines) == list(range(1, len(renders) + 1))
    # The same array again: everything is skipped.
    r = subprocess.run(
        ["sbatch", "--wait", "--array=0-2", f"--chdir={tmp_path}", f"--output={tmp_path}/again-%A_%a.log",
         "--export=ALL", str(BATCH / "slurm.sh")],
        env=env, capture_output=True, text=True, timeout=300,
    )
    assert r.returncode == 0, r.stderr
    for i in range(3):
        assert all(json.loads(l)["status"] == "skipped" for l in (out / f"results-{i}-of-3.jsonl").read_text().splitlines())


def test_kubernetes_indexed_job_command(tmp_path):
    """The manifest's container command, run with each completion index as Kubernetes runs it."""
    text = (BATCH / "k8s-indexed-job.yaml").read_text()
    completions = int(next(l.split(":")[1] for l in text.splitlines() if l.strip().startswith("completions:")))
    line = next(l for l in text.splitlines() if l.strip().startswith("command:"))
    command = json.loads(line.split("command:", 1)[1].strip())
    assert command[:2] == ["phong", "batch"] and "--shards" in command
    assert command[command.index("--shards") + 1] == str(completions)
    jobs, renders = write_jobs(tmp_path)
    out = tmp_path / "out"
    data = {"/data/jobs.jsonl": str(jobs), "/data/renders": str(out)}
    args = [data.get(a, a) for a in command[1:]]
    for i in range(completions):
        env = dict(os.environ, JOB_COMPLETION_INDEX=str(i))
        r = subprocess.run([phong_bin(), *args], env=env, capture_output=True, text=True)
        assert r.returncode == 0, r.stderr
    check_outputs(tmp_path, out, renders)


def test_ray_example_on_a_local_cluster(tmp_path):
    try:
        import ray  # noqa: F401
    except ImportError:
        require("PHONG_REQUIRE_RAY", "ray is not installed (pip install ray)")
    jobs, renders = write_jobs(tmp_path, n_views=7)
    out = tmp_path / "out"
    r = subprocess.run(
        [sys.executable, str(BATCH / "ray_render.py"), str(jobs), "--out", str(out), "--num-cpus", "2", "--chunk", "3"],
        capture_output=True, text=True, timeout=600, env=dict(os.environ, RAY_USAGE_STATS_ENABLED="0"),
    )
    assert r.returncode == 0, r.stdout + r.stderr
    # phong.save_png writes the command's PNG for these linear scenes, byte for byte.
    check_outputs(tmp_path, out, renders, exact_bytes=True)
