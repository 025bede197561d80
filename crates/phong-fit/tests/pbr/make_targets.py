"""Targets from a physically based renderer for `phong fit` (tests/fit.rs, `pbr_targets`).

Mitsuba 3 (`pip install mitsuba`, its CPU `scalar_rgb` variant) renders each scene of this
folder: the same mesh, camera and point lights as the TOML beside it, direct lighting only
(no ambient), a box filter, and a rough plastic or conductor BSDF. The image is written as an
8-bit PNG in linear encoding (values past 1 clipped at 255, as a camera would), the form
`phong fit --target` reads. Run from this folder: `python make_targets.py`.
"""

import math
import numpy as np
import mitsuba as mi

mi.set_variant("scalar_rgb")

W, H, SPP = 160, 120, 256
EYE, TARGET, FOV = [0.0, 0.0, 4.0], [0.0, 0.0, 0.0], 40.0

# (name, mesh, BSDF, lights as (position, intensity))
ONE = [([2.5, 2.5, 3.0], 14.0)]
TWO = [([2.5, 2.5, 3.0], 12.0), ([-3.0, 0.5, 2.0], 6.0)]
SCENES = [
    ("plastic_ggx_015", "sphere", {"type": "roughplastic", "distribution": "ggx", "alpha": 0.15,
                                    "diffuse_reflectance": {"type": "rgb", "value": [0.6, 0.15, 0.1]}}, ONE),
    ("plastic_beckmann_030", "sphere", {"type": "roughplastic", "distribution": "beckmann", "alpha": 0.3,
                                         "diffuse_reflectance": {"type": "rgb", "value": [0.1, 0.3, 0.6]}}, TWO),
    ("gold_ggx_020", "sphere", {"type": "roughconductor", "material": "Au", "distribution": "ggx",
                                 "alpha": 0.2}, ONE),
    ("torus_plastic_ggx_020", "torus", {"type": "roughplastic", "distribution": "ggx", "alpha": 0.2,
                                         "diffuse_reflectance": {"type": "rgb", "value": [0.2, 0.5, 0.2]}}, TWO),
]


def torus_obj(path, radius=1.0, tube=0.4, n=64, m=32):
    """A torus about the z axis, tilted by the scene's rotation in the TOML: written plain."""
    vs, fs = [], []
    for i in range(n):
        a = 2 * math.pi * i / n
        for j in range(m):
            b = 2 * math.pi * j / m
            r = radius + tube * math.cos(b)
            # Tilted 60 degrees about x so that it shadows itself from the lights.
            x, y, z = r * math.cos(a), r * math.sin(a), tube * math.sin(b)
            c, s = math.cos(math.radians(60)), math.sin(math.radians(60))
            vs.append((x, y * c - z * s, y * s + z * c))
    for i in range(n):
        for j in range(m):
            p = lambda i, j: (i % n) * m + (j % m) + 1
            fs.append((p(i, j), p(i + 1, j), p(i + 1, j + 1)))
            fs.append((p(i, j), p(i + 1, j + 1), p(i, j + 1)))
    with open(path, "w") as f:
        f.writelines(f"v {x:.5f} {y:.5f} {z:.5f}\n" for x, y, z in vs)
        f.writelines(f"f {a} {b} {c}\n" for a, b, c in fs)


def render(name, mesh, bsdf, lights):
    shape = ({"type": "sphere", "radius": 1.0} if mesh == "sphere"
             else {"type": "obj", "filename": "torus.obj", "face_normals": False})
    scene = {
        "type": "scene",
        "integrator": {"type": "direct", "emitter_samples": 4, "bsdf_samples": 0},
        "sensor": {
            "type": "perspective", "fov": FOV, "fov_axis": "y",
            "to_world": mi.ScalarTransform4f().look_at(origin=EYE, target=TARGET, up=[0, 1, 0]),
            "film": {"type": "hdrfilm", "width": W, "height": H, "rfilter": {"type": "box"}},
            "sampler": {"type": "independent", "sample_count": SPP},
        },
        "shape": {**shape, "bsdf": bsdf},
    }
    for k, (p, i) in enumerate(lights):
        scene[f"light{k}"] = {"type": "point", "position": p, "intensity": {"type": "rgb", "value": [i] * 3}}
    img = np.array(mi.render(mi.load_dict(scene)))[:, :, :3]
    png = np.clip(np.round(img * 255.0), 0, 255).astype(np.uint8)
    mi.util.write_bitmap(f"{name}.png", png, write_async=False)
    return img


if __name__ == "__main__":
    torus_obj("torus.obj")
    for s in SCENES:
        img = render(*s)
        print(s[0], "max", img.max(), "clipped", (img >= 254.5 / 255).mean())
