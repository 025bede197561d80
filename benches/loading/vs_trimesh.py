#!/usr/bin/env python3
"""Model loading against trimesh: the bunny and Nefertiti written by trimesh as OBJ, binary PLY,
ASCII PLY, binary STL and GLB, then each loaded by `trimesh.load(path, force="mesh")` and by
`phong render PATH -v` (its `load=` figure), alternating, best of ROUNDS for each. Process
start-up is excluded on both sides. Prints one row per file and the ratio trimesh / phong.
PHONG may name several binaries, comma-separated (a change and its base): each is timed in
turn in every round, the ratio is the first's.

    benches/loading/vs_trimesh.py PHONG[,PHONG...] [SHARED_MODELS] [ROUNDS]
"""
import os
import re
import subprocess
import sys
import time

import trimesh

phongs = sys.argv[1].split(",")
shared = sys.argv[2] if len(sys.argv) > 2 else "../shared/models"
rounds = int(sys.argv[3]) if len(sys.argv) > 3 else 3
out = "target/bench-loading"
os.makedirs(out, exist_ok=True)

files = []
for name in ["stanford-bunny", "nefertiti"]:
    src = os.path.join(shared, "common-3d", name + ".obj")
    files.append(src)
    mesh = None
    for ext, kw in [("ply", {"encoding": "binary"}), ("ascii.ply", {"encoding": "ascii"}),
                    ("stl", {}), ("glb", {})]:
        path = os.path.join(out, f"{name}.{ext}")
        if not os.path.exists(path):
            mesh = mesh or trimesh.load(src, force="mesh", process=False)
            file_type = "ply" if ext.endswith("ply") else ext
            data = mesh.export(file_type=file_type, **kw)
            with open(path, "wb") as f:
                f.write(data if isinstance(data, bytes) else data.encode())
        files.append(path)


def phong_ms(phong, path):
    r = subprocess.run([phong, "render", path, "-o", os.path.join(out, "x.png"), "--width", "16",
                        "--height", "16", "-v"], capture_output=True, text=True, check=True)
    return float(re.search(r"load=([0-9.]+)ms", r.stderr).group(1))


def trimesh_ms(path):
    t = time.perf_counter()
    trimesh.load(path, force="mesh")
    return (time.perf_counter() - t) * 1e3


others = "".join(f" {'phong ms (' + str(i + 1) + ')':>14}" for i in range(1, len(phongs)))
print(f"{'file':28} {'MB':>6} {'trimesh ms':>10} {'phong ms':>9}{others} {'ratio':>6}")
for path in files:
    tm, ph = [], [[] for _ in phongs]
    for _ in range(rounds):
        tm.append(trimesh_ms(path))
        for times, phong in zip(ph, phongs):
            times.append(phong_ms(phong, path))
    mb = os.path.getsize(path) / 1e6
    rest = "".join(f" {min(t):14.1f}" for t in ph[1:])
    print(f"{os.path.basename(path):28} {mb:6.1f} {min(tm):10.1f} {min(ph[0]):9.1f}{rest} {min(tm) / min(ph[0]):6.1f}")
