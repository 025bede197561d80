#!/usr/bin/env python3
"""Spot (Keenan Crane, public domain) subdivided twice into 93,696 triangles, for the textured
model benchmark: writes OUT/spot_100k.obj with its texture (`map_Kd`) and OUT/spot_100k_plain.obj,
the same mesh with the same material and no map; and for each a scene, OUT/NAME_1.toml, of the
sphere benchmark's form (1920×1080, one sample a pixel, one attenuated point light,
Blinn-Phong).

    benches/models/spot_100k.py ../shared/models/spot OUT

Each triangle becomes four by its edges' midpoints (positions, texture coordinates and the
original mesh's area-weighted vertex normals interpolated): the surface and its shading are the
original's, with 16 times the triangles."""
import math
import os
import sys


def read(path):
    vs, vts, faces = [], [], []
    for line in open(path):
        t = line.split()
        if not t:
            continue
        if t[0] == "v":
            vs.append(tuple(map(float, t[1:4])))
        elif t[0] == "vt":
            vts.append(tuple(map(float, t[1:3])))
        elif t[0] == "f":
            corners = [tuple(int(i) - 1 for i in c.split("/")[:2]) for c in t[1:]]
            for k in range(1, len(corners) - 1):
                faces.append((corners[0], corners[k], corners[k + 1]))
    return vs, vts, faces


def normals(vs, faces):
    n = [[0.0, 0.0, 0.0] for _ in vs]
    for f in faces:
        a, b, c = (vs[i] for i, _ in f)
        u = [b[k] - a[k] for k in range(3)]
        v = [c[k] - a[k] for k in range(3)]
        cross = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
        for i, _ in f:
            for k in range(3):
                n[i][k] += cross[k]
    return [tuple(x / (math.sqrt(sum(y * y for y in m)) or 1.0) for x in m) for m in n]


def subdivide(vs, vns, vts, faces):
    """One split of every triangle into four; vertices and coordinates shared along edges."""
    vs, vns, vts = list(vs), list(vns), list(vts)
    vmid, tmid = {}, {}

    def mid(store, table, i, j):
        key = (min(i, j), max(i, j))
        if key not in table:
            m = tuple((a + b) / 2 for a, b in zip(store[i], store[j]))
            table[key] = len(store)
            store.append(m)
        return table[key]

    out = []
    for (a, ta), (b, tb), (c, tc) in faces:
        ab, bc, ca = (mid(vs, vmid, i, j) for i, j in ((a, b), (b, c), (c, a)))
        while len(vns) < len(vs):
            vns.append(None)
        for (i, j), m in zip(((a, b), (b, c), (c, a)), (ab, bc, ca)):
            if vns[m] is None:
                s = [x + y for x, y in zip(vns[i], vns[j])]
                length = math.sqrt(sum(x * x for x in s)) or 1.0
                vns[m] = tuple(x / length for x in s)
        tab, tbc, tca = (mid(vts, tmid, i, j) for i, j in ((ta, tb), (tb, tc), (tc, ta)))
        out += [
            ((a, ta), (ab, tab), (ca, tca)),
            ((ab, tab), (b, tb), (bc, tbc)),
            ((ca, tca), (bc, tbc), (c, tc)),
            ((ab, tab), (bc, tbc), (ca, tca)),
        ]
    return vs, vns, vts, out


def write(path, mtl, vs, vns, vts, faces):
    with open(path, "w") as f:
        f.write(f"mtllib {mtl}\nusemtl spot\n")
        f.writelines(f"v {x:.7g} {y:.7g} {z:.7g}\n" for x, y, z in vs)
        f.writelines(f"vt {u:.7g} {v:.7g}\n" for u, v in vts)
        f.writelines(f"vn {x:.7g} {y:.7g} {z:.7g}\n" for x, y, z in vns)
        f.writelines(
            "f " + " ".join(f"{i + 1}/{t + 1}/{i + 1}" for i, t in tri) + "\n" for tri in faces
        )


SCENE = """[image]
width = 1920
height = 1080
antialias = 1

[camera]
position = [0.0, 0.4, 2.6]
fov = 45.0

[shading]
model = "blinn-phong"
interpolation = "phong"

[[light]]
type = "point"
position = [-2.0, 2.0, 3.0]
color = [1.0, 0.9, 0.8]
attenuation = [1.0, 0.05, 0.02]

[[object]]
mesh = "{mesh}"
fit = true
rotation = [0.0, 150.0, 0.0]
"""


def main():
    spot, out = sys.argv[1], sys.argv[2]
    os.makedirs(out, exist_ok=True)
    vs, vts, faces = read(os.path.join(spot, "spot_triangulated.obj"))
    vns = normals(vs, faces)
    for _ in range(2):
        vs, vns, vts, faces = subdivide(vs, vns, vts, faces)
    texture = os.path.abspath(os.path.join(spot, "spot_texture.png"))
    material = "newmtl spot\nKa 1 1 1\nKd 1 1 1\nKs 0.3 0.3 0.3\nNs 32\n"
    for name, extra in (("spot_100k", f"map_Kd {texture}\n"), ("spot_100k_plain", "")):
        with open(os.path.join(out, name + ".mtl"), "w") as f:
            f.write(material + extra)
        write(os.path.join(out, name + ".obj"), name + ".mtl", vs, vns, vts, faces)
        with open(os.path.join(out, name + "_1.toml"), "w") as f:
            f.write(SCENE.format(mesh=name + ".obj"))
    print(f"{len(faces)} triangles, {len(vs)} vertices into {out}")


if __name__ == "__main__":
    main()
