"""phong's Python module against the `phong` command, closed forms and trimesh."""

import json
import os
import pickle
import threading

import numpy as np
import pytest

import phong
from conftest import EXAMPLES, MODELS, read_png, run_phong

SCENES = sorted(EXAMPLES.glob("*.toml"))


@pytest.mark.parametrize("scene", SCENES, ids=[s.stem for s in SCENES])
def test_every_example_scene_is_the_commands_png(scene, tmp_path):
    out = tmp_path / "out.png"
    run_phong("render", scene, "-o", out)
    expected = read_png(out)
    got = phong.render(scene)
    assert got.dtype == np.uint8 and got.shape == expected.shape
    assert np.array_equal(got, expected), f"{int((got != expected).any(axis=2).sum())} pixels differ"
    # The same scene as a Scene, and as its dict (paths relative to its folder).
    assert np.array_equal(phong.render(phong.Scene.load(scene)), expected)
    d = phong.Scene.load(scene).to_dict()
    assert np.array_equal(phong.render(phong.Scene.from_dict(d, base=scene.parent)), expected)


def test_flags_are_the_commands(tmp_path):
    scene = EXAMPLES / "shininess.toml"
    out = tmp_path / "out.png"
    run_phong("render", scene, "-o", out, "--width", 200, "--height", 90, "--antialias", 1, "--output", "specular")
    got = phong.render(scene, width=200, height=90, antialias=1, output="specular")
    assert np.array_equal(got, read_png(out))
    got = phong.Renderer(200, 90, antialias=1).render(phong.Scene.load(scene), output="specular")
    assert np.array_equal(got, read_png(out))


def sphere_scene(projection="orthographic"):
    return {
        "image": {"width": 101, "height": 101, "antialias": 1},
        "camera": {"projection": projection, "position": [0, 0, 5], "target": [0, 0, 0], "height": 2.5,
                   "near": 1, "far": 10, "fov": 30},
        "light": [{"type": "directional", "direction": [0, 0, -1]}],
        "object": [{"shape": "sphere", "segments": 256, "material": "gold"}],
    }


def pixel_xy(w, h, half_height):
    """World x, y of each pixel centre in the orthographic view (y up)."""
    xs = ((np.arange(w) + 0.5) / w * 2 - 1) * half_height * w / h
    ys = (1 - (np.arange(h) + 0.5) / h * 2) * half_height
    return np.meshgrid(xs, ys)


def test_depth_and_normals_of_a_sphere_are_the_closed_forms():
    s = sphere_scene()
    depth = phong.render(s, output="depth")
    normal = phong.render(s, output="normal")
    assert depth.dtype == np.float32 and depth.shape == (101, 101)
    assert normal.dtype == np.float32 and normal.shape == (101, 101, 3)
    x, y = pixel_xy(101, 101, 1.25)
    r2 = x * x + y * y
    inside = r2 < 0.97  # away from the silhouette, where the tessellation differs most
    outside = r2 > 1.03
    z = np.sqrt(np.clip(1 - r2, 0, 1))
    assert np.abs(depth[inside] - (5 - z[inside])).max() < 2e-3
    assert (depth[outside] == 0).all()
    true_n = np.stack([x, y, z], axis=2)
    assert np.abs(normal[inside] - true_n[inside]).max() < 2e-3
    assert (normal[outside] == 0).all()
    assert np.allclose(np.linalg.norm(normal[inside], axis=1), 1, atol=1e-5)


def test_perspective_depth_is_along_the_view_axis():
    s = sphere_scene("perspective")
    depth = phong.render(s, output="depth")
    # The centre pixel sees the sphere's nearest point, 4 units from the eye.
    assert abs(depth[50, 50] - 4.0) < 1e-3
    # Off-centre: depth (along the axis), not the distance along the ray: z = 5 - sqrt(1 - r²)
    # at the point the pixel's ray meets, which is never below the centre's.
    assert (depth[depth > 0] >= 4.0 - 1e-4).all()


def test_a_trimesh_mesh_from_arrays_is_its_obj_file(tmp_path):
    if not (MODELS / "common-3d" / "suzanne.obj").exists():
        if os.environ.get("PHONG_REQUIRE_MODELS") == "1":
            pytest.fail("PHONG_REQUIRE_MODELS=1 and ../shared/models is missing")
        pytest.skip("../shared/models is missing")
    trimesh = pytest.importorskip("trimesh")
    mesh = trimesh.load(MODELS / "common-3d" / "suzanne.obj", force="mesh", process=False)
    path = tmp_path / "mesh.obj"
    path.write_text(trimesh.exchange.obj.export_obj(mesh, include_normals=False, include_texture=False))
    from_file = phong.render(path, width=160, height=120)
    from_arrays = phong.render(phong.Scene.from_mesh(mesh.vertices, mesh.faces), width=160, height=120)
    assert np.array_equal(from_arrays, from_file)
    # float32 vertices and uint32 faces go in as well.
    f32 = phong.Scene.from_mesh(mesh.vertices.astype(np.float32), mesh.faces.astype(np.uint32))
    assert phong.render(f32, width=40, height=30).shape == (30, 40, 4)


def test_a_material_given_to_a_mesh():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], dtype=np.float64)
    f = np.array([[0, 1, 2]])
    red = phong.render(phong.Scene.from_mesh(v, f, material={"diffuse": [1, 0, 0], "ambient": [0, 0, 0]}),
                       width=32, height=32, antialias=1)
    centre = red[16, 12]
    assert centre[0] > 0 and centre[1] == centre[2] == 0


def test_errors_are_the_commands_messages(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text('[camera]\nfov = 200\n')
    r = run_phong("render", bad, "-o", tmp_path / "x.png", check=False)
    assert r.returncode == 2
    with pytest.raises(phong.InputError) as e:
        phong.render(bad)
    assert isinstance(e.value, ValueError)
    assert str(e.value) == r.stderr.strip().removeprefix("error: ")
    assert "bad.toml:2:7" in str(e.value) and "fov" in str(e.value)
    with pytest.raises(phong.InputError, match="missing.obj"):
        phong.render(tmp_path / "missing.obj")
    with pytest.raises(phong.InputError, match=r"light\[0\]\.type"):
        phong.render({"light": [{"type": "laser"}]})
    with pytest.raises(phong.InputError, match="width must be from 1"):
        phong.render(EXAMPLES / "terms.toml", width=0)
    with pytest.raises(phong.InputError, match="output must be"):
        phong.render(EXAMPLES / "terms.toml", output="albedo")
    with pytest.raises(phong.InputError, match="antialias"):
        phong.render(EXAMPLES / "terms.toml", antialias=3)
    with pytest.raises(phong.InputError, match="not finite"):
        phong.Scene.from_mesh([[0, 0, 0], [1, 0, 0], [np.nan, 1, 0]], [[0, 1, 2]])
    with pytest.raises(phong.InputError, match="outside"):
        phong.Scene.from_mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 3]])
    with pytest.raises(TypeError):
        phong.render(42)


def test_assignments_are_checked_and_a_refused_one_changes_nothing():
    scene = phong.Scene.load(EXAMPLES / "shininess.toml")
    before = scene.to_dict()
    with pytest.raises(phong.InputError, match="projection"):
        scene.camera.projection = "fisheye"
    with pytest.raises(phong.InputError, match=r"light\[0\]\.color"):
        scene.lights[0].color = [1, 2]
    with pytest.raises(phong.InputError, match="material"):
        scene.objects[0].material = "unobtainium"
    assert scene.to_dict() == before
    scene.camera.fov = 30
    scene.objects[0].material = "gold"
    scene.lights[0].color = np.array([1.0, 0.5, 0.25])
    d = scene.to_dict()
    assert d["camera"]["fov"] == 30 and d["object"][0]["material"] == "gold"
    assert d["light"][0]["color"] == [1.0, 0.5, 0.25]
    assert scene.camera.fov == 30 and scene.camera.nonexistent is None
    # The edited scene renders as its TOML text does through the command.
    toml = scene.to_toml()
    assert "fov = 30" in toml


def test_an_edited_scene_renders_as_its_toml_file(tmp_path):
    scene = phong.Scene.load(EXAMPLES / "shininess.toml")
    scene.camera.fov = 35
    scene.shading.model = "phong"
    path = EXAMPLES.parent / "scenes" / "_edited_for_test.toml"
    out = tmp_path / "o.png"
    try:
        path.write_text(scene.to_toml())
        run_phong("render", path, "-o", out, "--width", 160, "--height", 120)
    finally:
        path.unlink(missing_ok=True)
    assert np.array_equal(phong.render(scene, width=160, height=120), read_png(out))


def test_scenes_pickle():
    scene = phong.Scene.load(EXAMPLES / "shininess.toml")
    scene.camera.fov = 40
    again = pickle.loads(pickle.dumps(scene))
    assert again.to_dict() == scene.to_dict()
    assert np.array_equal(phong.render(again, width=80, height=60), phong.render(scene, width=80, height=60))
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=np.float64)
    f = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    m = phong.Scene.from_mesh(v, f, material="jade")
    again = pickle.loads(pickle.dumps(m))
    assert np.array_equal(phong.render(again, width=64, height=48), phong.render(m, width=64, height=48))


def test_the_gil_is_released_while_rendering():
    scene = phong.Scene.from_dict(sphere_scene())
    r = phong.Renderer(1600, 1600, antialias=16, threads=1)
    done = threading.Event()
    ticks = 0

    def work():
        r.render(scene)
        done.set()

    t = threading.Thread(target=work)
    t.start()
    # While the other thread renders (hundreds of milliseconds), this one keeps running Python.
    while not done.is_set():
        ticks += 1
    t.join()
    assert ticks > 10_000, f"the main thread ran {ticks} times during the render"


def rss_kib():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * 4


def test_a_long_loop_does_not_grow_memory():
    """10,000 renders (colour and depth alternating, the camera moving): after a warm-up the
    process does not grow (a leak of 2 KiB a frame would add 16 MiB)."""
    d = sphere_scene("perspective")
    d["object"][0]["segments"] = 128
    scene = phong.Scene.from_dict(d)
    r = phong.Renderer(32, 32, threads=1)

    def frames(n, offset):
        for i in range(offset, offset + n):
            img = r.render(scene, output="depth" if i % 3 == 0 else "color")
            if i % 100 == 0:
                scene.camera.position = [np.sin(i), 0.5, 5]
        return img

    frames(2000, 0)
    start = rss_kib()
    img = frames(8000, 2000)
    grown = rss_kib() - start
    assert grown < 16 * 1024, f"the process grew by {grown} KiB over 8,000 renders"
    assert img.shape[:2] == (32, 32)


def test_a_renderer_reuses_a_scene_while_only_its_camera_changes():
    scene = phong.Scene.from_dict(sphere_scene("perspective"))
    r = phong.Renderer(80, 80, antialias=1)
    first = r.render(scene)
    scene.camera.position = [0, 3, 4]
    moved = r.render(scene)
    fresh = phong.render(phong.Scene.from_dict(scene.to_dict()), width=80, height=80, antialias=1)
    assert np.array_equal(moved, fresh)
    assert not np.array_equal(first, moved)


def test_views_of_a_model_read_once_are_the_commands(tmp_path):
    objs = sorted(EXAMPLES.glob("**/*.obj"))
    if not objs:
        pytest.skip("no example model")
    path = objs[0]
    scene = phong.Scene.load(path)
    r = phong.Renderer(96, 72)
    for view in ("front", "top", "iso"):
        out = tmp_path / f"{view}.png"
        run_phong("render", path, "-o", out, "--width", 96, "--height", 72, "--view", view)
        assert np.array_equal(r.render(scene.framed(view=view)), read_png(out)), view


def test_help_is_useful():
    assert "numpy array" in phong.render.__doc__
    assert "InputError" in phong.__doc__
    assert len(phong.materials()) == 29 and "gold" in [m.lower() for m in phong.materials()]
