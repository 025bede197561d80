"""Thumbnails: the same 256×256 renders of the models in ../shared/models (several views each)
made four ways in one run, alternating rounds, each in a fresh process whose peak memory is
read from the kernel (ru_maxrss):

  batch     `phong batch` over a jobs file (one process, each model read once)
  renderer  a Python loop with `phong.Renderer` (threads=1 per render; scenes read once)
  process   one `phong render` process per image (a sample of the renders, its rate scaled)
  pyrender  trimesh + pyrender on OSMesa (PYOPENGL_PLATFORM=osmesa), one process

    python benches/python/thumbnails.py [--renders 1000] [--rounds 3] [--phong target/release/phong]

Prints images a second and peak memory per method and round, then the medians and ratios.
pyrender's environment needs SciPy (trimesh's smooth normals; without it a slow fallback makes
pyrender about four times slower) and networkx 3 (pyrender's pinned 2.2 does not import on
Python 3.11); see BENCHMARKS.md, "Thumbnails".
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
MODELS = ROOT.parent / "shared" / "models" / "common-3d"
VIEWS = ["front", "back", "left", "right", "top", "iso"]
SIZE = 256

# The camera directions of phong's named views (y up), for pyrender's cameras.
DIRS = {"front": (0, 0, 1), "back": (0, 0, -1), "left": (-1, 0, 0), "right": (1, 0, 0),
        "top": (0, 1, 0.001), "iso": (1, 1, 1)}


def jobs(n):
    models = sorted(MODELS.glob("*.obj"))
    out = []
    i = 0
    while len(out) < n:
        m = models[(i // len(VIEWS)) % len(models)]
        v = VIEWS[i % len(VIEWS)]
        out.append({"scene": str(m), "out": f"{m.stem}/{v}-{i}.png", "width": SIZE, "height": SIZE, "view": v,
                    "up": "y"})
        i += 1
    # Grouped by model, as a thumbnailer walks a library.
    out.sort(key=lambda j: j["scene"])
    return out


RENDERER = r'''
import json, os, sys, time, phong
jobs = json.load(open(sys.argv[1])); out = sys.argv[2]
t = time.perf_counter()
r = phong.Renderer(256, 256, threads=1)
scenes = {}
for j in jobs:
    base = scenes.get(j["scene"])
    if base is None:
        scenes.clear()
        base = scenes[j["scene"]] = phong.Scene.load(j["scene"], up="y")
    img = r.render(base.framed(view=j["view"], up="y"))
    p = os.path.join(out, j["out"]); os.makedirs(os.path.dirname(p), exist_ok=True)
    phong.save_png(p, img)
print(time.perf_counter() - t)
'''

PYRENDER = r'''
import json, os, sys, time
os.environ["PYOPENGL_PLATFORM"] = "osmesa"
import numpy as np, trimesh, pyrender, PIL.Image
DIRS = json.loads(sys.argv[3])
jobs = json.load(open(sys.argv[1])); out = sys.argv[2]
t = time.perf_counter()
r = pyrender.OffscreenRenderer(256, 256)
meshes = {}
def look_at(eye, target):
    f = target - eye; f /= np.linalg.norm(f)
    up = np.array([0, 1.0, 0]); s = np.cross(f, up); s /= np.linalg.norm(s); u = np.cross(s, f)
    m = np.eye(4); m[:3, 0] = s; m[:3, 1] = u; m[:3, 2] = -f; m[:3, 3] = eye
    return m
for j in jobs:
    if j["scene"] not in meshes:
        meshes.clear()
        tm = trimesh.load(j["scene"], force="mesh")
        b = tm.bounds
        meshes[j["scene"]] = (pyrender.Mesh.from_trimesh(tm, smooth=True), b.mean(axis=0),
                              float(np.linalg.norm(b[1] - b[0])) / 2)
    mesh, c, rad = meshes[j["scene"]]
    scene = pyrender.Scene(ambient_light=[0.2, 0.2, 0.2], bg_color=[0.1, 0.1, 0.1, 1.0])
    scene.add(mesh)
    d = np.array(DIRS[j["view"]], dtype=float); d /= np.linalg.norm(d)
    eye = c + d * rad * 2.8
    pose = look_at(eye, c)
    scene.add(pyrender.PerspectiveCamera(yfov=np.radians(45)), pose=pose)
    scene.add(pyrender.DirectionalLight(intensity=3.0), pose=pose)
    color, _ = r.render(scene)
    p = os.path.join(out, j["out"]); os.makedirs(os.path.dirname(p), exist_ok=True)
    PIL.Image.fromarray(color).save(p)
r.delete()
print(time.perf_counter() - t)
'''


def measured(cmd, env=None):
    """cmd run under a Python wrapper that reports the command's own peak RSS."""
    wrapper = ("import resource, subprocess, sys, time, json; t=time.perf_counter(); "
               "r=subprocess.run(sys.argv[1:]); w=time.perf_counter()-t; "
               "print(json.dumps([r.returncode, w, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss/1024]))")
    r = subprocess.run([sys.executable, "-c", wrapper, *cmd], capture_output=True, text=True, env=env)
    code, wall, peak = json.loads(r.stdout.strip().splitlines()[-1])
    if code != 0:
        raise SystemExit(f"{' '.join(map(str, cmd[:4]))} failed: {r.stderr[-2000:]}")
    return wall, peak


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--renders", type=int, default=1000)
    p.add_argument("--rounds", type=int, default=3)
    p.add_argument("--process-sample", type=int, default=60, help="renders of the one-process-each method")
    p.add_argument("--phong", default=str(ROOT / "target" / "release" / "phong"))
    p.add_argument("--skip", default="", help="methods to leave out, comma-separated")
    a = p.parse_args()
    skip = set(filter(None, a.skip.split(",")))
    work = Path(tempfile.mkdtemp(prefix="phong-thumbs-"))
    js = jobs(a.renders)
    (work / "jobs.json").write_text(json.dumps(js))
    (work / "jobs.jsonl").write_text("".join(json.dumps(j) + "\n" for j in js))
    results = {m: [] for m in ("batch", "renderer", "process", "pyrender") if m not in skip}
    for rnd in range(a.rounds):
        for m in results:
            out = work / f"out-{m}-{rnd}"
            if m == "batch":
                wall, peak = measured([a.phong, "batch", str(work / "jobs.jsonl"), "--out", str(out), "--threads", "2"])
                n = len(js)
            elif m == "renderer":
                wall, peak = measured([sys.executable, "-c", RENDERER, str(work / "jobs.json"), str(out)])
                n = len(js)
            elif m == "process":
                sample = js[:: max(1, len(js) // a.process_sample)][: a.process_sample]
                t = time.perf_counter()
                peak = 0
                for j in sample:
                    o = out / j["out"]
                    o.parent.mkdir(parents=True, exist_ok=True)
                    _, pk = measured([a.phong, "render", j["scene"], "-o", str(o), "--width", "256", "--height", "256",
                                      "--view", j["view"], "--up", "y"])
                    peak = max(peak, pk)
                wall, n = time.perf_counter() - t, len(sample)
            else:
                env = dict(os.environ, PYOPENGL_PLATFORM="osmesa")
                wall, peak = measured([sys.executable, "-c", PYRENDER, str(work / "jobs.json"), str(out),
                                       json.dumps(DIRS)], env=env)
                n = len(js)
            results[m].append((n / wall, peak))
            print(f"round {rnd + 1} {m:9s} {n / wall:8.1f} images/s  peak {peak:7.1f} MiB", flush=True)
    print("\nmedians:")
    med = {m: (statistics.median(r[0] for r in v), statistics.median(r[1] for r in v)) for m, v in results.items()}
    for m, (ips, mem) in med.items():
        line = f"{m:9s} {ips:8.1f} images/s  peak {mem:7.1f} MiB"
        if "pyrender" in med and m != "pyrender":
            line += f"   {ips / med['pyrender'][0]:5.1f}x pyrender's images/s, {mem / med['pyrender'][1]:.2f}x its memory"
        print(line)


if __name__ == "__main__":
    main()
