"""pyrender's PBR raster as an outside reference (method ``pyrender``).

Why pyrender2 (``import pyrender``): the last pyrender release (0.1.45) pins PyOpenGL 3.1.0
(too old for OSMesa) and uses ``np.infty`` (gone in numpy 2); the pyrender2 fork fixes both and
keeps pyrender's API and shaders.

Isolation: PyOpenGL picks one platform per process and EGL contexts are current per thread.
pyrender therefore runs in one persistent worker thread of this process (its EGL context is
never current on the thread that draws with moderngl), or, with ``isolate = true`` (and
always when ``PYOPENGL_PLATFORM`` was set to something other than egl/osmesa, e.g. by a GLX
UI), in a child process.

Mapping of our materials to pyrender's metallic-roughness model (glTF 2.0), and of lights:

=================== ===========================================================================
baseColorFactor     ``kd * color``; textures with a 2D projection are baked by :mod:`.texturing`
                    into a 1024^2 baseColorTexture over the part's (u, v) range; solid
                    textures are evaluated at the vertices and passed as vertex colours
                    (COLOR_0); pyrender multiplies either with the base colour
metallicFactor      ``kr`` (mirror-like materials become metals; pyrender has no mirror
                    reflection, and no environment map, so they look dark where we reflect)
roughnessFactor     from the Phong exponent: ``alpha = sqrt(2 / (n + 2))`` (Blinn-Phong to
                    Beckmann equivalence, Walter et al. 2007), roughness = ``sqrt(alpha)``
                    (glTF's alpha = roughness^2); 1 when ``ks = 0``
emissiveFactor      ``sqrt(emission)``: pyrender's shader multiplies the emissive factor twice
alpha               opacity ``constant`` -> BLEND with base alpha ``value``; other opacity
                    maps are left out
point light         pyrender always divides by r^2: intensity ``pi * I`` for inverse-square
                    lights, ``pi * I * r0^2`` for our unattenuated ones (r0: distance from the
                    light to the scene's centre: the mean of the world bounding-box
                    centres of the tessellated objects); the factor pi because pyrender's Lambert lobe
                    is ``c_diff / pi``.  An area light's stand-ins become such point lights
                    (their cosine lobe is dropped) and the emitter is drawn as an emissive polygon
directional light   intensity ``pi * I``
ambient             ``Ia * mean(ka) / mean(kd)`` over the scene's materials (pyrender adds
                    ``base_color * ambient_light``; one ambient for all materials)
=================== ===========================================================================

pyrender encodes its output with a 1/2.2 power; we decode with 2.2 to a linear float image.
The specular lobes differ by construction (GGX/Smith/Schlick against Phong): the reference is
for the overall look and the run time, not for a pixel-exact match.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import time

import numpy as np

from ..core.errors import WorkbenchError
from ..core.tol import tol
from ..scene import features as ft
from ..scene.model import AreaLight, DirectionalLight, Scene
from ..scene.prepared import prepare
from ..scene.tessellate import DEFAULT_LEVEL, MAX_LEVEL, tessellate_scene
from .estimates import raster_bytes
from . import support as sp
from .support import Note, Status
from . import gl
from . import texturing as tx
from .base import Knob, Option, RenderResult

_WORKER = None
_RENDERERS: dict = {}


SUPPORT = sp.declare(
    approximated={**{f: "drawn as its tessellation (the tessellation knob)"
                     for f in (ft.SPHERES, ft.QUADRICS, ft.CSG, ft.BLOBS, ft.ISOSURFACES, ft.LATHES)},
                  ft.SPECULAR: "glTF metallic-roughness lobe, roughness from the Phong exponent",
                  ft.AREA_LIGHTS: "stand-ins as point lights without their cosine lobe",
                  ft.OPACITY: "constant opacity as alpha; opacity maps not mapped"},
    left_out={ft.SHADOWS: "shadow maps not enabled (the local models have none)",
              ft.REFLECTION: "no mirror reflection in pyrender (kr mapped to metalness)",
              ft.REFRACTION: "no refraction in pyrender", ft.ABSORPTION: "no refraction in pyrender",
              ft.BUMP: "bump maps not mapped", ft.ENVIRONMENT: "no environment map in pyrender",
              ft.HYPERTEXTURES: "pyrender draws surface meshes only: a participating medium has none, "
                                "so it is not drawn",
              ft.TEXELS: "pyrender draws the fur's base only (no texel model)"})
"""pyrender's support table (:mod:`.support`)."""


def roughness_from_shininess(n: float, ks: float) -> float:
    """glTF roughness of a Phong lobe of exponent ``n`` (1 without specular)."""
    if ks <= 0.0:
        return 1.0
    return float(np.sqrt(np.sqrt(2.0 / (n + 2.0))))


def build_scene(scene: Scene, level: int):
    """A ``pyrender.Scene`` (meshes, lights, camera) for our scene; returns (scene, left_out
    notes)."""
    import pyrender
    left_out = []
    mats = scene.materials
    kas = [m.ka for m in mats.values()]
    kds = [m.kd for m in mats.values()]
    ambient = np.asarray(scene.ambient) * (np.mean(kas) / max(np.mean(kds), tol.zero))
    # pyrender clears with its colour as is and we decode its output with a 2.2 power
    bg = tuple(float(c) ** (1.0 / 2.2) for c in scene.background)
    ps = pyrender.Scene(ambient_light=ambient, bg_color=(*bg, 1.0))
    centres = []  # world bounding-box centre of every tessellated part, (3,) each
    for part in tessellate_scene(scene, level):
        centres.append(0.5 * (part.positions.min(0) + part.positions.max(0)))
        mat = mats[part.material]
        alpha = 1.0
        if mat.opacity is not None:
            if mat.opacity.kind == "constant":
                alpha = mat.opacity.value
            else:
                left_out.append(Note(ft.OPACITY, f"{mat.opacity.kind} opacity map of {part.material!r} not mapped"))
        pm = pyrender.MetallicRoughnessMaterial(
            baseColorFactor=(*(mat.kd * np.asarray(mat.color)), alpha),
            metallicFactor=float(mat.kr), roughnessFactor=roughness_from_shininess(mat.shininess, mat.ks),
            emissiveFactor=tuple(np.sqrt(np.asarray(mat.emission))), doubleSided=True,
            alphaMode="BLEND" if alpha < 1.0 else "OPAQUE")
        colors, uv = None, None
        if mat.texture is not None and mat.texture.projection != "solid":
            pm.baseColorTexture, uv = _baked_texture(mat.texture, part)
        elif mat.texture is not None:
            colors = tx.texture_color(mat.texture, part.obj_positions, part.uvs)
            colors = np.clip(np.concatenate([colors, np.ones((len(colors), 1))], 1), 0.0, 1.0)
        ps.add(pyrender.Mesh([pyrender.Primitive(positions=part.positions.astype(np.float32),
                                                 normals=part.normals.astype(np.float32),
                                                 indices=part.faces.astype(np.uint32),
                                                 texcoord_0=None if uv is None else uv.astype(np.float32),
                                                 color_0=None if colors is None else colors.astype(np.float32),
                                                 material=pm)]))
    for light in scene.lights:
        if isinstance(light, AreaLight):
            v = np.asarray(light.vertices)
            faces = np.array([[0, i, i + 1] for i in range(1, len(v) - 1)], dtype=np.uint32)
            em = pyrender.MetallicRoughnessMaterial(baseColorFactor=(0.0, 0.0, 0.0, 1.0),
                                                    emissiveFactor=tuple(np.sqrt(light.radiance)),
                                                    doubleSided=True)
            n = np.tile(light.normal, (len(v), 1))
            ps.add(pyrender.Mesh([pyrender.Primitive(positions=v.astype(np.float32), normals=n.astype(np.float32),
                                                     indices=faces, material=em)]))
    centre = np.mean(centres, 0) if centres else np.zeros(3)
    for light in scene.point_lights():
        col = np.asarray(light.color, dtype=np.float64)
        if isinstance(light, DirectionalLight):
            pose = _pose_looking(np.zeros(3), np.asarray(light.direction))
            ps.add(pyrender.DirectionalLight(color=col, intensity=np.pi * light.intensity), pose=pose)
        else:
            p = np.asarray(light.position)
            scale = 1.0 if light.falloff == "inverse_square" else float(np.sum((p - centre) ** 2))
            pose = np.eye(4)
            pose[:3, 3] = p
            ps.add(pyrender.PointLight(color=col, intensity=np.pi * light.intensity * scale), pose=pose)
    if any(isinstance(light, AreaLight) for light in scene.lights):
        left_out.append(Note(ft.AREA_LIGHTS, SUPPORT[ft.AREA_LIGHTS].reason, Status.APPROXIMATED))
    return ps, left_out


BAKE_SIZE = 1024


def _baked_texture(tex, part):
    """A 2D-projected texture baked into a ``BAKE_SIZE``^2 image over the part's range of
    pattern coordinates, and the vertices' coordinates in it (V, 2).  Triangles across a
    cylindrical or spherical seam interpolate through the whole image (a thin smeared strip)."""
    import pyrender
    s = tx.project(tex, part.obj_positions, part.uvs) * tex.scale
    lo, hi = s.min(0), s.max(0)
    span = np.maximum(hi - lo, tol.zero)
    g = (np.arange(BAKE_SIZE) + 0.5) / BAKE_SIZE
    U, V = np.meshgrid(lo[0] + g * span[0], lo[1] + g[::-1] * span[1])  # row 0 = top = v max
    grid = np.stack([U.ravel(), V.ravel()], -1)
    if tex.kind == "image":
        rgb = tx.sample_image(tx.image(tex.path), grid)[:, :3]
    else:
        t = tx.pattern_value(tex.kind, grid, tex.mortar)[:, None]
        c0, c1 = (np.asarray(c, dtype=np.float64) for c in tex.colors)
        rgb = c0 * (1.0 - t) + c1 * t
    from ..core.imageio import to_srgb8  # pyrender decodes base colour textures from sRGB
    img = to_srgb8(rgb.reshape(BAKE_SIZE, BAKE_SIZE, 3))
    texture = pyrender.Texture(source=img, source_channels="RGB")
    return texture, (s - lo) / span


def _pose_looking(position: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """Pose (4, 4) of a pyrender light/camera at ``position`` whose -z axis is ``direction``."""
    f = direction / np.linalg.norm(direction)
    up = np.array([0.0, 1.0, 0.0]) if abs(f[1]) < 0.99 else np.array([1.0, 0.0, 0.0])
    r = np.cross(f, up)
    r /= np.linalg.norm(r)
    u = np.cross(r, f)
    pose = np.eye(4)
    pose[:3, 0], pose[:3, 1], pose[:3, 2], pose[:3, 3] = r, u, -f, position
    return pose


def _render_here(scene: Scene, width: int, height: int, level: int, frames: int = 1) -> dict:
    """Build and render in the calling thread; ``frames`` > 1 times repeated frames."""
    import pyrender
    t0 = time.perf_counter()
    ps, left_out = build_scene(scene, level)
    prepared = prepare(scene)
    near, far = prepared.near, prepared.far
    cam = scene.camera
    pc = pyrender.PerspectiveCamera(yfov=np.radians(cam.fov_y), aspectRatio=width / height, znear=near, zfar=far)
    ps.add(pc, pose=np.linalg.inv(cam.camera_from_world()))
    t_build = time.perf_counter() - t0
    # one offscreen renderer, resized (deleting one of several would end their shared EGL display)
    r = _RENDERERS.get("r")
    if r is None:
        r = _RENDERERS["r"] = gl.pyrender_offscreen(width, height)
    r.viewport_width, r.viewport_height = width, height
    flags = pyrender.RenderFlags.SKIP_CULL_FACES
    t0 = time.perf_counter()
    color, depth = r.render(ps, flags=flags)  # first frame: shader compile and upload
    t_first = time.perf_counter() - t0
    times = []
    for _ in range(frames - 1):
        t0 = time.perf_counter()
        color, depth = r.render(ps, flags=flags)
        times.append(time.perf_counter() - t0)
    image = (np.asarray(color[..., :3], dtype=np.float64) / 255.0) ** 2.2
    depth = np.where(depth > 0, depth, np.inf)
    return {"image": image.astype(np.float32), "depth": depth.astype(np.float32), "left_out": left_out,
            "build": t_build, "first_frame": t_first, "frame_times": times,
            "gl_renderer": _gl_renderer_string(), "near": float(near), "far": float(far)}


def _gl_renderer_string() -> str:
    from OpenGL import GL
    return GL.glGetString(GL.GL_RENDERER).decode() + f" (pyrender, PyOpenGL {os.environ.get('PYOPENGL_PLATFORM')})"


def _must_isolate() -> bool:
    plat = os.environ.get("PYOPENGL_PLATFORM")
    return plat is not None and plat not in ("egl", "osmesa")


class _Worker:
    """One daemon thread owning pyrender's EGL context; jobs run there in order.  At exit the
    offscreen renderers are deleted in that thread (before the interpreter tears down)."""

    def __init__(self):
        import atexit
        import queue
        import threading
        self.jobs: queue.Queue = queue.Queue()
        self.thread = threading.Thread(target=self._loop, name="pyrender", daemon=True)
        self.thread.start()
        atexit.register(self.stop)

    def _loop(self):
        while True:
            job = self.jobs.get()
            if job is None:
                for r in _RENDERERS.values():
                    try:
                        r.delete()
                    except Exception:  # the EGL display may already be gone at exit: nothing to free
                        pass
                _RENDERERS.clear()
                return
            fn, args, box, done = job
            try:
                box.append((True, fn(*args)))
            except BaseException as e:  # handed back to the caller's thread
                box.append((False, e))
            done.set()

    def run(self, fn, *args):
        import threading
        box, done = [], threading.Event()
        self.jobs.put((fn, args, box, done))
        done.wait()
        ok, value = box[0]
        if not ok:
            raise value
        return value

    def stop(self):
        self.jobs.put(None)
        self.thread.join(timeout=10)


def _in_worker(fn, *args):
    global _WORKER
    if _WORKER is None:
        gl.pyrender_platform()
        _WORKER = _Worker()
    return _WORKER.run(fn, *args)


def _child(scene_source: str, width: int, height: int, level: int, frames: int) -> dict:
    """Run :func:`_child_main` in a fresh interpreter; the scene is reloaded from its file and
    the results come back through files in a temporary folder."""
    import tempfile
    if not scene_source or not os.path.isfile(scene_source):
        raise WorkbenchError("pyrender in a child process needs a scene loaded from a file")
    env = dict(os.environ)
    env["PYOPENGL_PLATFORM"] = "egl"
    code = ("import sys; from workbench.renderers.reference import _child_main; "
            "_child_main(sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4]), int(sys.argv[5]), sys.argv[6])")
    with tempfile.TemporaryDirectory(prefix="pyrender-") as d:
        out = subprocess.run([sys.executable, "-c", code, scene_source, str(width), str(height), str(level),
                              str(frames), d], capture_output=True, env=env, timeout=600)
        if out.returncode != 0 or not os.path.isfile(os.path.join(d, "result.json")):
            raise WorkbenchError(f"pyrender child process failed: {out.stderr.decode()[-2000:]}")
        with open(os.path.join(d, "result.json"), encoding="utf-8") as f:
            res = json.load(f)
        res["left_out"] = [Note.from_dict(n) for n in res["left_out"]]
        res["image"] = np.load(os.path.join(d, "image.npy"))
        res["depth"] = np.load(os.path.join(d, "depth.npy"))
    return res


def _child_main(source: str, width: int, height: int, level: int, frames: int, out_dir: str) -> None:
    from ..scene.io import load_scene
    scene = load_scene(source)
    scene = scene.with_camera(scene.camera.with_resolution(width, height))
    res = _render_here(scene, width, height, level, frames)
    res["left_out"] = [n.as_dict() for n in res["left_out"]]
    np.save(os.path.join(out_dir, "image.npy"), res.pop("image"))
    np.save(os.path.join(out_dir, "depth.npy"), res.pop("depth"))
    with open(os.path.join(out_dir, "result.json"), "w", encoding="utf-8") as f:
        json.dump(res, f)
    for r in _RENDERERS.values():
        r.delete()
    _RENDERERS.clear()


def frame_time_in_child(scene_name: str, width: int, height: int, frames: int = 10) -> dict:
    """pyrender's frame time on a bundled scene, measured in a child process (benchmark):
    build seconds, first frame (compile + upload) and the median of the following frames."""
    from ..scene.library import resolve
    res = _child(str(resolve(scene_name)), width, height, DEFAULT_LEVEL, frames)
    ft_ = res["frame_times"]
    return {"build_seconds": round(res["build"], 4), "first_frame_seconds": round(res["first_frame"], 4),
            "frame_seconds_median": round(float(np.median(ft_)), 5) if ft_ else None,
            "fps": round(1.0 / float(np.median(ft_)), 1) if ft_ else None, "gl_renderer": res["gl_renderer"]}


_BYTES_PER_TRIANGLE = 2048
"""A triangle in trimesh, pyrender's primitive and its GL buffers."""
_BYTES_PER_PIXEL = 256
"""pyrender's colour and depth renderbuffers, read-backs, float conversions."""
_FIXED_BYTES = 128 * 2 ** 20
"""EGL context, pyrender's shaders and scene objects."""
_BYTES_PER_BAKED_TEXEL = 256
"""Texture baking's float64 temporaries, one bake at a time (164 MB measured for 1024^2)."""


class PyrenderRenderer:
    """The registered ``pyrender`` method (see the module docstring for the mapping)."""

    name = "pyrender"
    ui_kind = "child"
    support = SUPPORT
    knob = Knob("tessellation", (1, 2, 3, 4, 6, 8, 12, 16), DEFAULT_LEVEL,
                "tessellation level of analytic primitives (as the raster methods)")
    options = {
        "tessellation": Option(int, DEFAULT_LEVEL, "tessellation level >= 1"),
        "isolate": Option(bool, False, "render in a child process (needed beside a GLX UI)"),
    }

    memory_options = ("tessellation",)

    def estimate_bytes(self, scene: Scene, width: int, height: int, *, tessellation: int = DEFAULT_LEVEL,
                       isolate: bool = False) -> int:
        """Triangles (:func:`.estimates.triangle_bound`: pyrender's meshes and GL buffers) and
        pixels (its multisampled framebuffer and read-backs), in this process or the child."""
        if not 1 <= tessellation <= MAX_LEVEL:
            raise WorkbenchError(f"method 'pyrender': tessellation must be within 1..{MAX_LEVEL}, got {tessellation}")
        baked = any(mt.texture is not None and mt.texture.projection != "solid"
                    for mt in scene.materials.values())
        return (raster_bytes(scene, width, height, tessellation, _BYTES_PER_TRIANGLE, _BYTES_PER_PIXEL,
                             _FIXED_BYTES) + baked * _BYTES_PER_BAKED_TEXEL * BAKE_SIZE ** 2)

    def render(self, scene: Scene, width: int, height: int, *, tessellation: int = DEFAULT_LEVEL,
               isolate: bool = False) -> RenderResult:
        if not 1 <= tessellation <= MAX_LEVEL:
            raise WorkbenchError(f"method 'pyrender': tessellation must be within 1..{MAX_LEVEL}, got {tessellation}")
        if isolate or _must_isolate():
            res = _child(scene.source, width, height, tessellation, 1)
        else:
            res = _in_worker(_render_here, scene, width, height, tessellation)
        needs = ft.scene_needs(scene)
        left = list(res["left_out"]) + sp.notes(self.support, needs)
        used = sp.used(needs, left)
        timings = {"build": res["build"], "draw": res["first_frame"], "compile": 0.0}
        stats = {"gl_renderer": res["gl_renderer"], "isolated": bool(isolate or _must_isolate()),
                 "near": res["near"], "far": res["far"]}
        return RenderResult(self.name, res["image"], timings, stats, used, left, depth=res["depth"])
