"""Render a `phong batch` jobs file on a Ray cluster with the Python module.

    pip install . ray
    python examples/batch/ray_render.py jobs.jsonl --out renders            # ray.init(): a local cluster
    python examples/batch/ray_render.py jobs.jsonl --out renders --address auto   # a running one

Each task renders a chunk of jobs with one `phong.Renderer` (one thread; models read once per
task) and writes PNGs with `phong.save_png`; complete images are skipped, so a rerun does only
what is missing. The jobs take `scene` (a file, relative to the jobs file, or a scene object),
`out`, and optionally `width`, `height`, `antialias`, `output`, `view`, `up` and `camera`.
"""

import argparse
import json
import os
import time

import ray

import phong


@ray.remote(num_cpus=1)
def render_chunk(jobs, base, out_dir):
    renderer = phong.Renderer(threads=1)
    scenes = {}
    results = []
    for line, job in jobs:
        t = time.perf_counter()
        out = os.path.join(out_dir, job["out"])
        try:
            if os.path.exists(out) and phong.is_complete_png(out):
                results.append({"line": line, "out": job["out"], "status": "skipped"})
                continue
            source = job["scene"]
            if isinstance(source, str):
                source = os.path.join(base, source)
                key = (source, job.get("view"), job.get("up"), json.dumps(job.get("camera")))
                if key not in scenes:
                    view = {k: job[k] for k in ("view", "up", "camera") if k in job}
                    scenes[key] = phong.Scene.load(source, **view)
                scene = scenes[key]
            else:
                scene = phong.Scene.from_dict(source, base=base)
            image = renderer.render(scene, output=job.get("output", "color"), width=job.get("width"),
                                    height=job.get("height"), antialias=job.get("antialias"))
            os.makedirs(os.path.dirname(out) or ".", exist_ok=True)
            phong.save_png(out, image)
            results.append({"line": line, "out": job["out"], "status": "ok",
                            "seconds": round(time.perf_counter() - t, 4)})
        except (phong.InputError, KeyError) as e:
            results.append({"line": line, "out": job.get("out", ""), "status": "failed", "message": str(e)})
    return results


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("jobs")
    p.add_argument("--out", required=True)
    p.add_argument("--address", default=None, help="a running cluster's address (default: start a local one)")
    p.add_argument("--num-cpus", type=int, default=None, help="a local cluster's CPUs")
    p.add_argument("--chunk", type=int, default=16, help="jobs per task")
    a = p.parse_args()
    base = os.path.dirname(os.path.abspath(a.jobs))
    with open(a.jobs) as f:
        jobs = [(i + 1, json.loads(line)) for i, line in enumerate(f) if line.strip() and not line.startswith("#")]
    ray.init(address=a.address, num_cpus=a.num_cpus, include_dashboard=False, log_to_driver=False)
    chunks = [jobs[i : i + a.chunk] for i in range(0, len(jobs), a.chunk)]
    results = [r for rs in ray.get([render_chunk.remote(c, base, a.out) for c in chunks]) for r in rs]
    failed = [r for r in results if r["status"] == "failed"]
    for r in failed:
        print(f"error: {a.jobs}:{r['line']}: {r['message']}")
    print(f"{len(results) - len(failed)} rendered or skipped, {len(failed)} failed")
    raise SystemExit(1 if failed else 0)


if __name__ == "__main__":
    main()
