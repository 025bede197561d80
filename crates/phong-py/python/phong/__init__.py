"""phong: the Phong illumination model, exactly, and a fast headless renderer.

Render a scene file, a model (OBJ, glTF/GLB, PLY, STL) or a scene given as a ``dict`` into a
numpy array, with the same pixels as the ``phong render`` command writes to its PNG::

    import phong
    image = phong.render("model.obj", width=256, height=256)   # uint8 (256, 256, 4) RGBA
    depth = phong.render("model.obj", output="depth")           # float32 (H, W)

For many frames keep a :class:`Renderer`; edit scenes through :class:`Scene`. Errors in what
is given raise :class:`InputError` (a ``ValueError``) with the command's message, naming the
file, line, column and key. Rendering releases the GIL.
"""

from __future__ import annotations

import json
import os
from typing import Any, Iterator, Mapping, Optional, Sequence, Union

import numpy as np

from ._phong import InputError, RenderError, __version__
from ._phong import RendererCore as _RendererCore
from ._phong import SceneCore as _SceneCore
from ._phong import materials as _materials
from ._phong import is_complete_png, save_png
from ._phong import render_path as _render_path

__all__ = [
    "InputError",
    "RenderError",
    "Renderer",
    "Scene",
    "is_complete_png",
    "materials",
    "render",
    "save_png",
    "__version__",
]

PathLike = Union[str, "os.PathLike[str]"]
OUTPUTS = ("color", "ambient", "diffuse", "specular", "depth", "normal")


def materials() -> list:
    """The names of the 29 built-in materials (OpenGL's classic table), for ``material=``."""
    return list(_materials())


def _jsonable(value: Any) -> Any:
    """``value`` with numpy arrays and scalars as lists and numbers, tables as dicts."""
    if isinstance(value, _Table):
        return value.to_dict()
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, Mapping):
        return {str(k): _jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_jsonable(v) for v in value]
    return value


class _Table:
    """A table of a scene's document (``scene.camera``, ``scene.lights[0]``, ...): read and
    set its keys as attributes or items; each assignment is checked at once (``InputError``
    with the scene reader's message) and leaves the scene unchanged when refused. A key the
    scene does not set reads as ``None`` (its default applies)."""

    __slots__ = ("_scene", "_path")

    def __init__(self, scene: "Scene", path: tuple):
        object.__setattr__(self, "_scene", scene)
        object.__setattr__(self, "_path", path)

    def _value(self) -> dict:
        v: Any = self._scene.to_dict()
        for p in self._path:
            v = v[p]
        return v

    def __getattr__(self, key: str) -> Any:
        if key.startswith("_"):
            raise AttributeError(key)
        return self[key]

    def __getitem__(self, key: str) -> Any:
        v = self._value().get(key)
        if isinstance(v, dict):
            return _Table(self._scene, self._path + (key,))
        return v

    def __setattr__(self, key: str, value: Any) -> None:
        self[key] = value

    def __setitem__(self, key: str, value: Any) -> None:
        self._scene._set(self._path + (key,), value)

    def __delattr__(self, key: str) -> None:
        self._scene._set(self._path + (key,), None, delete=True)

    def __contains__(self, key: str) -> bool:
        return key in self._value()

    def __iter__(self) -> Iterator[str]:
        return iter(self._value())

    def keys(self):
        return self._value().keys()

    def to_dict(self) -> dict:
        """The table as a plain ``dict``."""
        return json.loads(json.dumps(self._value()))

    def __eq__(self, other: object) -> bool:
        if isinstance(other, _Table):
            other = other.to_dict()
        return self.to_dict() == other

    def __repr__(self) -> str:
        return f"<phong table {'.'.join(map(str, self._path))}: {self._value()!r}>"


class _Array(Sequence):
    """An array of tables (``scene.lights``, ``scene.objects``): indexable, each element a
    table; assign the whole list with ``scene.lights = [...]``."""

    def __init__(self, scene: "Scene", key: str):
        self._scene = scene
        self._key = key

    def _list(self) -> list:
        return self._scene.to_dict().get(self._key, [])

    def __len__(self) -> int:
        return len(self._list())

    def __getitem__(self, i):
        n = len(self)
        if isinstance(i, slice):
            return [self[j] for j in range(*i.indices(n))]
        if i < 0:
            i += n
        if not 0 <= i < n:
            raise IndexError(f"{self._key}[{i}]: the scene has {n}")
        return _Table(self._scene, (self._key, i))

    def __setitem__(self, i: int, value: Any) -> None:
        n = len(self)
        if i < 0:
            i += n
        if not 0 <= i < n:
            raise IndexError(f"{self._key}[{i}]: the scene has {n}")
        self._scene._set((self._key, i), value)

    def append(self, value: Mapping) -> None:
        """Adds a table at the end (checked as any assignment)."""
        self._scene._set((self._key,), self._list() + [_jsonable(value)])

    def __repr__(self) -> str:
        return f"<phong {self._key} list: {self._list()!r}>"


class Scene:
    """A scene: what ``phong render`` renders, held as its document (the scene file's schema
    as JSON, the same as ``POST /api/render`` takes) and edited through attributes::

        scene = phong.Scene.load("examples/scenes/shininess.toml")
        scene.camera.fov = 30
        scene.lights[0].color = [1, 0.9, 0.8]
        scene.objects[0].material = "gold"
        scene.objects[1].material.shininess = 64   # an inline material's field

    Each assignment is checked at once and raises :class:`InputError` with the scene
    reader's message (naming the key) when refused, leaving the scene as it was. Scenes pickle
    (for ``multiprocessing`` and Ray); a scene read from a file is read again where it is
    unpickled.
    """

    __slots__ = ("_core", "_origin")

    def __init__(self, *_: Any, **__: Any):
        raise TypeError("make a Scene with Scene.load(path), Scene.from_dict(d) or Scene.from_mesh(vertices, faces)")

    @classmethod
    def _make(cls, core: _SceneCore, origin: tuple) -> "Scene":
        s = object.__new__(cls)
        object.__setattr__(s, "_core", core)
        object.__setattr__(s, "_origin", origin)
        return s

    @classmethod
    def load(
        cls,
        path: PathLike,
        *,
        up: Optional[str] = None,
        view: Optional[str] = None,
        camera: Optional[Sequence[float]] = None,
        two_sided: Optional[bool] = None,
    ) -> "Scene":
        """Reads a scene file (``.toml``) or a model file (OBJ, glTF/GLB, PLY, STL), framed
        and lit as ``phong render MODEL`` frames it. For a model: ``up`` (``"x"``, ``"-z"``,
        ...), ``view`` (``"front"``, ``"iso"``, ...), ``camera`` (``[px, py, pz, tx, ty,
        tz]`` in the file's coordinates) and ``two_sided`` (``True``: draw back faces;
        ``False``: cull them) as the command's ``--up``, ``--view``, ``--camera``,
        ``--two-sided``/``--cull``. Until its camera is set, a model's camera is framed for
        each render's image size, as the command frames it for ``--width``/``--height``."""
        path = os.fspath(path)
        kwargs = dict(up=up, view=view, camera=_camera(camera), two_sided=two_sided)
        core = _SceneCore.load(path, kwargs)
        origin = ("file", os.path.abspath(path), kwargs) if core.has_model else ("dict", os.path.dirname(os.path.abspath(path)))
        return cls._make(core, origin)

    @classmethod
    def from_dict(cls, d: Mapping[str, Any], *, base: Optional[PathLike] = None) -> "Scene":
        """A scene from a ``dict`` in the scene file's schema (``{"camera": {...}, "light":
        [...], "object": [...]}``); mesh and texture paths relative to ``base`` (default: the
        current folder)."""
        if not isinstance(d, Mapping):
            raise InputError(f"a scene is a dict with the scene file's tables, got {type(d).__name__}")
        base = os.path.abspath(os.fspath(base) if base is not None else os.getcwd())
        core = _SceneCore.from_json(json.dumps(_jsonable(d)), base)
        return cls._make(core, ("dict", base))

    @classmethod
    def from_mesh(
        cls,
        vertices: Any,
        faces: Any,
        *,
        normals: Any = None,
        uvs: Any = None,
        material: Union[str, Mapping[str, Any], None] = None,
        up: Optional[str] = None,
        view: Optional[str] = None,
        camera: Optional[Sequence[float]] = None,
        two_sided: Optional[bool] = None,
    ) -> "Scene":
        """A model from arrays, framed and lit exactly as ``phong render MODEL`` frames a
        model file: ``vertices`` (N, 3) floats, ``faces`` (M, 3) vertex indices from 0,
        optional per-vertex ``normals`` (N, 3) and ``uvs`` (N, 2), and a ``material`` (a
        built-in name such as ``"gold"``, or a table such as ``{"diffuse": [1, 0, 0]}``). A
        ``trimesh.Trimesh``'s ``vertices`` and ``faces`` go straight in."""
        v = np.ascontiguousarray(vertices, dtype=np.float64)
        f = np.asarray(faces)
        if f.dtype.kind not in "iu":
            raise InputError(f"faces must be integer vertex indices, got dtype {f.dtype}")
        f = np.ascontiguousarray(f, dtype=np.int64)
        n = None if normals is None else np.ascontiguousarray(normals, dtype=np.float64)
        t = None if uvs is None else np.ascontiguousarray(uvs, dtype=np.float64)
        if v.ndim != 2 or f.ndim != 2:
            raise InputError(f"vertices must be (N, 3) and faces (M, 3), got {v.shape} and {f.shape}")
        kwargs = dict(up=up, view=view, camera=_camera(camera), two_sided=two_sided)
        core = _SceneCore.from_mesh(v, f, n, t, kwargs)
        scene = cls._make(core, ("mesh", v, f, n, t, kwargs))
        if material is not None:
            scene._set(("object", 0, "material"), material)
        return scene

    def framed(
        self,
        *,
        up: Optional[str] = None,
        view: Optional[str] = None,
        camera: Optional[Sequence[float]] = None,
        two_sided: Optional[bool] = None,
    ) -> "Scene":
        """The same model (read once) viewed another way: a new scene with the camera and
        lights ``Scene.load`` gives for these arguments. For a scene from a model file or
        arrays only; edits other than the camera and lights are kept."""
        kwargs = dict(up=up, view=view, camera=_camera(camera), two_sided=two_sided)
        core = self._core.framed(kwargs)
        mine = self.to_dict()
        fresh = json.loads(core.json())
        for k in ("camera", "light", "shading"):
            if k in fresh:
                mine[k] = fresh[k]
        if mine != fresh:
            core = core.with_json(json.dumps(mine))
        origin = self._origin[:-1] + (kwargs,) if self._origin[0] in ("file", "mesh") else self._origin
        return Scene._make(core, origin)

    def to_dict(self) -> dict:
        """The scene's document: the scene file's schema as a ``dict``."""
        return json.loads(self._core.json())

    def to_toml(self) -> str:
        """The scene as a TOML scene file's text (``phong render`` reads it; a model's mesh is
        named by its file name, relative to the model's folder)."""
        return self._core.toml()

    @property
    def path(self) -> str:
        """The file whose folder the scene's relative paths are taken from."""
        return os.fspath(self._core.anchor)

    @property
    def triangle_count(self) -> int:
        """The number of triangles the scene draws."""
        return self._core.triangle_count()

    def _set(self, path: tuple, value: Any, delete: bool = False) -> None:
        doc = self.to_dict()
        t: Any = doc
        for p in path[:-1]:
            if isinstance(t, dict) and p not in t:
                t[p] = {}
            t = t[p]
        if delete:
            if isinstance(t, dict):
                t.pop(path[-1], None)
        else:
            t[path[-1]] = _jsonable(value)
        core = self._core.with_json(json.dumps(doc))
        object.__setattr__(self, "_core", core)

    def __setattr__(self, key: str, value: Any) -> None:
        if key in ("camera", "image", "shading", "materials"):
            self._set((key,), value)
        elif key in ("lights", "objects"):
            self._set(({"lights": "light", "objects": "object"}[key],), [_jsonable(v) for v in value])
        else:
            raise AttributeError(f"Scene has no attribute {key!r} to set (camera, image, shading, materials, lights, objects)")

    @property
    def camera(self) -> _Table:
        """The ``[camera]`` table: ``position``, ``target``, ``up``, ``fov``, ``near``, ``far``, ``projection``, ``height``."""
        return _Table(self, ("camera",))

    @property
    def image(self) -> _Table:
        """The ``[image]`` table: ``width``, ``height``, ``background``, ``antialias``, ``encoding``."""
        return _Table(self, ("image",))

    @property
    def shading(self) -> _Table:
        """The ``[shading]`` table: ``model``, ``interpolation``, ``ambient``, ``normalization``, ..."""
        return _Table(self, ("shading",))

    @property
    def materials(self) -> _Table:
        """The ``[materials.NAME]`` tables the scene defines."""
        return _Table(self, ("materials",))

    @property
    def lights(self) -> _Array:
        """The ``[[light]]`` tables: ``type``, ``direction``/``position``, ``color``, ..."""
        return _Array(self, "light")

    @property
    def objects(self) -> _Array:
        """The ``[[object]]`` tables: ``shape`` or ``mesh``, ``material``, ``position``, ..."""
        return _Array(self, "object")

    def __reduce__(self):
        return (_restore, (self._origin, self._core.json()))

    def __repr__(self) -> str:
        d = self.to_dict()
        return f"<phong.Scene {self.path!r}: {len(d.get('object', []))} objects, {len(d.get('light', []))} lights>"


def _camera(camera: Optional[Sequence[float]]) -> Optional[list]:
    if camera is None:
        return None
    c = [float(x) for x in np.asarray(camera, dtype=np.float64).ravel()]
    if len(c) != 6:
        raise InputError(f"camera must be [px, py, pz, tx, ty, tz], got {len(c)} numbers")
    return c


def _restore(origin: tuple, doc: str) -> Scene:
    kind = origin[0]
    if kind == "file":
        core = _SceneCore.load(origin[1], origin[2])
    elif kind == "mesh":
        _, v, f, n, t, kwargs = origin
        core = _SceneCore.from_mesh(v, f, n, t, kwargs)
    else:
        return Scene._make(_SceneCore.from_json(doc, origin[1]), origin)
    if json.loads(core.json()) != json.loads(doc):
        core = core.with_json(doc)
    return Scene._make(core, origin)


def _as_scene(scene: Union[PathLike, Mapping[str, Any], Scene]) -> Scene:
    if isinstance(scene, Scene):
        return scene
    if isinstance(scene, Mapping):
        return Scene.from_dict(scene)
    if isinstance(scene, (str, os.PathLike)):
        return Scene.load(scene)
    raise TypeError(f"scene must be a path, a dict or a phong.Scene, got {type(scene).__name__}")


def render(
    scene: Union[PathLike, Mapping[str, Any], Scene],
    *,
    width: Optional[int] = None,
    height: Optional[int] = None,
    antialias: Optional[int] = None,
    output: str = "color",
    backend: str = "cpu",
    threads: Optional[int] = None,
) -> np.ndarray:
    """Renders ``scene`` (a path to a ``.toml`` scene or a model file, a ``dict`` in the scene
    schema, or a :class:`Scene`) and returns the image as a numpy array:

    - ``output="color"`` (and ``"ambient"``, ``"diffuse"``, ``"specular"``): ``uint8``
      ``(H, W, 4)`` RGBA, exactly the pixels of the PNG ``phong render`` writes for the same
      scene and flags (alpha 255 where the PNG is opaque); the background is the scene's
      ``background`` colour. ``"color"`` renders the scene as its file says (objects with an
      ``output`` of their own keep it), as ``phong render`` without ``--output``; the others
      apply to every object, as ``--output``.
    - ``output="depth"``: ``float32`` ``(H, W)``, the distance from the eye along the view axis
      in scene units (as pyrender's depth); 0 where no surface is.
    - ``output="normal"``: ``float32`` ``(H, W, 3)``, the unit surface normal in world space
      (the shading normal, as lit); 0 where no surface is.

    Depth and normals are taken at one sample per pixel (``antialias`` is ignored for them).
    ``width``, ``height`` and ``antialias`` (1, 4 or 16) override the scene; a model alone is
    framed for the size, as the command frames it. ``backend`` is ``"cpu"``, ``"gpu"`` (an
    error without an adapter) or ``"auto"``; ``threads`` the CPU's (default: all cores). The
    GIL is released while rendering. For many frames, :class:`Renderer` keeps its memory.
    """
    if output not in OUTPUTS:
        raise InputError(f"output must be one of {', '.join(OUTPUTS)}, got {output!r}")
    if isinstance(scene, (str, os.PathLike)):
        size = dict(width=width, height=height, antialias=antialias)
        return _render_path(os.fspath(scene), size, output, backend, threads)
    core = _RendererCore(width, height, antialias, threads, backend)
    return core.render(_as_scene(scene)._core, output)


class Renderer:
    """A renderer for many frames: its threads (or GPU) and working memory are kept from one
    frame to the next, and each scene it is given is built once and reused while only its
    camera, lights or image change::

        r = phong.Renderer(256, 256, threads=1)
        scene = phong.Scene.load("bunny.obj")
        for view in ("front", "left", "top", "iso"):
            rgba = r.render(scene.framed(view=view))

    ``width``, ``height`` and ``antialias`` apply to every frame (``None``: the scene's).
    """

    __slots__ = ("_core", "_paths")

    def __init__(
        self,
        width: Optional[int] = None,
        height: Optional[int] = None,
        *,
        antialias: Optional[int] = None,
        threads: Optional[int] = None,
        backend: str = "cpu",
    ):
        self._core = _RendererCore(width, height, antialias, threads, backend)
        self._paths: dict = {}

    @property
    def threads(self) -> int:
        """The threads the CPU draws each frame on."""
        return self._core.threads

    def render(
        self,
        scene: Union[PathLike, Mapping[str, Any], Scene],
        output: str = "color",
        *,
        width: Optional[int] = None,
        height: Optional[int] = None,
        antialias: Optional[int] = None,
    ) -> np.ndarray:
        """Renders ``scene`` as :func:`render` does (a path is read once and kept);
        ``width``, ``height`` and ``antialias`` override the renderer's for this frame."""
        if output not in OUTPUTS:
            raise InputError(f"output must be one of {', '.join(OUTPUTS)}, got {output!r}")
        if isinstance(scene, (str, os.PathLike)):
            key = os.path.abspath(os.fspath(scene))
            if key not in self._paths:
                if len(self._paths) >= 8:
                    self._paths.pop(next(iter(self._paths)))
                self._paths[key] = Scene.load(key)
            scene = self._paths[key]
        return self._core.render(_as_scene(scene)._core, output, width, height, antialias)
