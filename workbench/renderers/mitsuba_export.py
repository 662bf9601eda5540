"""Export of a workbench scene to a Mitsuba 3 scene dictionary (for ``mi.load_dict``).

Pure data: nothing here imports Mitsuba.  :func:`export_scene` returns the dictionary with
plain values (numbers, lists, nested dicts; every ``to_world`` a 4x4 nested list that the
child process turns into ``mi.ScalarTransform4f``) and writes the triangle meshes as binary
PLY files into a folder.  What the dictionary cannot express goes into ``left_out`` as
``"feature: reason"``.

Radiometry (the workbench's units, ``scene/model.py``): an emitter's ``color * intensity`` is
radiance; the local model gives a Lambertian surface lit by a point light the radiance
``kd C I cos(theta)`` (``local_model.py``: no 1/pi), so the light that produces it in a
physically based renderer, whose Lambertian BRDF is ``kd C / pi``, has ``pi`` times the
intensity.

Mapping
=======
=================== ==========================================================================
camera              ``perspective``, ``fov_axis = "y"``, ``fov = fov_y``; ``to_world`` = the
                    inverse view matrix times diag(-1, 1, -1) (Mitsuba's camera looks down +z
                    with +x to the left of the image); box pixel filter, ``hdrfilm`` linear
                    float32 RGB: each pixel is the box-filtered average over its square
polygon, plane, box triangle meshes (PLY, flat normals), from the scene's tessellation (level 1:
                    exact)
sphere              ``sphere`` with ``to_world`` = world_from_object . T(center) . S(radius)
                    when the object's transform is a similarity; tessellated otherwise
quadric, csg        tessellated (``tessellation`` level) with smooth normals
mesh                triangle mesh, its own normals or flat
blob, isosurface,   no such primitives in Mitsuba 3: their raster tessellation (marching
lathe, prism        cubes, revolved profile at the ``tessellation`` level; the prism's exact
                    triangles, flat), noted in ``left_out``; an open lathe is an open surface
hypertexture        a ``heterogeneous`` medium inside its bounding sphere (a ``sphere`` with a
                    ``null`` BSDF, ``interior`` = the medium): ``sigma_t`` a ``gridvolume`` of
                    the density (a Mitsuba ``.vol`` file, :func:`write_vol`), ``scale`` the
                    ``density`` per world length, ``albedo`` a constant or an RGB
                    ``gridvolume``, isotropic phase; the camera inside it gets it as its
                    ``medium``.  No emission (Mitsuba 3 has no emissive media): noted
(each kind)         written by its module's ``mitsuba(obj, x)`` (:mod:`workbench.scene.kinds`)
                    through :class:`ShapeWriter`
kd x color          ``diffuse`` reflectance, inside ``twosided`` (workbench surfaces are
                    two-sided)
kr                  ``conductor`` with ``material = "none"`` (perfect mirror),
                    ``specular_reflectance = kr``, inside ``twosided``
kt, ior             ``dielectric`` (``int_ior = ior``, ``ext_ior = 1``), reflectance and
                    transmittance ``kt``: with the mirror lobe this is the ray tracer's
                    ``fresnel = "exact"`` split (reflection ``kr + kt F``, transmission
                    ``kt (1 - F)``); ``thindielectric`` on open surfaces (polygon, plane)
several lobes       nested ``blendbsdf``: the sum ``sum_i lobe_i`` as a blend with weights
                    ``a_i / S`` (``a_i`` the lobe's largest albedo, ``S = sum a_i``) of the
                    lobes scaled by ``S / a_i``
opacity constant    ``mask`` with that opacity (below 0.5 the surface is cut out: not exported)
emission            ``area`` emitter of that radiance on the shape
area light          its polygon as a black diffuse mesh with an ``area`` emitter of radiance
                    ``color * intensity`` (front face, as in the workbench)
point light         ``point``, intensity ``pi I color`` (inverse square); ``falloff = "none"``
                    has no physical counterpart: ``pi I color r0^2`` (matches at distance
                    r0 from the light to the centre of the scene's bounds), noted in left_out
directional light   ``directional``, irradiance ``pi I color``
background          ``constant`` emitter of that radiance when not black (it then also lights
                    the scene, unlike the ray tracer's background: noted in left_out); option
                    ``background_light = false``: not exported (black)
integrator          ``path``, ``max_depth = -1`` (unbounded, Russian roulette from depth 5);
                    ``volpath`` (the same settings) when a participating medium is exported
=================== ==========================================================================

Left out (with the reason, per scene): textures, bump maps, opacity maps other than constant,
environment maps, the Phong lobe (ks, n), the ambient term, absorption, the constant kr/kt
split of ``fresnel = "none"``, mesh vertex emission.
"""
from __future__ import annotations

import os
from dataclasses import dataclass, field

import numpy as np

from ..core.errors import NotApplicable
from ..core.tol import tol
from ..scene import features as F
from ..scene import model as m
from ..scene.kinds import is_solid, kind_of
from ..scene.tessellate import tessellate_object
from .support import Note, Status

#: Alpha below which an opacity cuts a surface out (the workbench's rule, ``model.Opacity``).
OPACITY_CUT = 0.5
#: Near clip plane of the Mitsuba camera as a fraction of its far plane (Mitsuba needs a finite
#: clip range; the workbench's ray tracer does not clip, so this is kept tiny).
NEAR_CLIP_RATIO = 1e-6
#: Far clip plane as a multiple of the largest camera-to-scene-bound distance.
FAR_CLIP_MARGIN = 2.0
#: Mitsuba's Russian roulette starts at this path depth (its default, stated for the stats).
RR_DEPTH = 5

MODEL_NOTES = {
    F.TEXTURES: "textures not exported (uniform kd x colour used)",
    F.BUMP: "bump maps not exported (geometric normals)",
    F.ENVIRONMENT: "environment maps not exported (background colour only)",
    F.SPECULAR: "the Phong lobe (ks, n) is not mapped (no normalised Phong BSDF in Mitsuba 3)",
    F.ABSORPTION: "absorption inside dielectrics not exported (no interior medium)",
}


@dataclass
class Export:
    """Result of :func:`export_scene`.

    scene_dict : the ``mi.load_dict`` dictionary (plain data; ``to_world`` as 4x4 lists).
    left_out : :class:`..support.Note` records (deduplicated, sorted; printed ``"feature: reason"``).
    triangles : number of triangles written as meshes.
    shapes : number of shapes (meshes and spheres).
    """

    scene_dict: dict
    left_out: list[Note] = field(default_factory=list)
    triangles: int = 0
    shapes: int = 0


def rgb(c) -> dict:
    """A Mitsuba ``rgb`` value of a colour (3,)."""
    return {"type": "rgb", "value": [float(x) for x in np.asarray(c, dtype=np.float64)]}


def write_ply(path: str, positions: np.ndarray, faces: np.ndarray, normals: np.ndarray | None = None) -> None:
    """Binary little-endian PLY of a triangle mesh.

    positions : (V, 3) float; faces : (F, 3) int; normals : (V, 3) float or None.
    """
    P = np.asarray(positions, dtype=np.float32)
    cols = [("x", "<f4"), ("y", "<f4"), ("z", "<f4")]
    if normals is not None:
        cols += [("nx", "<f4"), ("ny", "<f4"), ("nz", "<f4")]
    vert = np.empty(len(P), dtype=cols)
    vert["x"], vert["y"], vert["z"] = P.T
    if normals is not None:
        N = np.asarray(normals, dtype=np.float32)
        vert["nx"], vert["ny"], vert["nz"] = N.T
    face = np.empty(len(faces), dtype=[("n", "u1"), ("i", "<i4", (3,))])
    face["n"] = 3
    face["i"] = np.asarray(faces, dtype=np.int32)
    head = ["ply", "format binary_little_endian 1.0", f"element vertex {len(P)}"]
    head += [f"property float {c}" for c, _ in cols]
    head += [f"element face {len(faces)}", "property list uchar int vertex_indices", "end_header", ""]
    with open(path, "wb") as f:
        f.write("\n".join(head).encode("ascii"))
        f.write(vert.tobytes())
        f.write(face.tobytes())


VOL_VERSION = 3
"""Mitsuba's grid volume file format version (``gridvolume`` plugin documentation)."""
VOL_FLOAT32 = 1
"""Its encoding code for float32 data (the only one it reads)."""


def write_vol(path: str, data: np.ndarray, lo, hi) -> None:
    """Mitsuba's binary grid volume (``.vol``, the ``gridvolume`` plugin's format, little
    endian): ``VOL``, version 3, encoding 1 (float32), the x, y and z resolutions and the
    channel count (int32), the bounding box (xmin, ymin, zmin, xmax, ymax, zmax as float32),
    then the values x fastest: ``data[((z yres + y) xres + x) channels + c]``.

    data : (zres, yres, xres) or (zres, yres, xres, channels) numbers (1, 3 or 6 channels).
    lo, hi : (3,) the box written in the header (Mitsuba ignores it unless ``use_grid_bbox``).
    """
    a = np.asarray(data, dtype="<f4")
    if a.ndim == 3:
        a = a[..., None]
    if a.ndim != 4 or a.shape[3] not in (1, 3, 6):
        raise ValueError(f"a grid volume is (z, y, x) or (z, y, x, 1|3|6), got shape {a.shape}")
    zres, yres, xres, ch = a.shape
    head = np.array([VOL_FLOAT32, xres, yres, zres, ch], dtype="<i4").tobytes()
    box = np.array([*lo, *hi], dtype="<f4").tobytes()
    with open(path, "wb") as f:
        f.write(b"VOL" + bytes([VOL_VERSION]) + head + box)
        f.write(np.ascontiguousarray(a).tobytes())


def camera_to_world(cam: m.Camera) -> np.ndarray:
    """Mitsuba sensor ``to_world`` (4, 4): the workbench camera (OpenGL: looks down -z, +x to the
    right) turned into Mitsuba's (looks down +z, +x to the left of the image)."""
    return np.linalg.inv(cam.camera_from_world()) @ np.diag([-1.0, 1.0, -1.0, 1.0])


def _similarity_scale(M: np.ndarray) -> float | None:
    """The uniform scale of the linear part of ``M`` (4, 4), or None if it is not a similarity."""
    A = np.asarray(M, dtype=np.float64)[:3, :3]
    G = A.T @ A
    s2 = float(np.trace(G) / 3.0)
    if s2 <= 0.0 or np.abs(G - s2 * np.eye(3)).max() > tol.symmetric * s2:
        return None
    return float(np.sqrt(s2))


def _lobes(mat: m.Material, open_surface: bool) -> list[tuple[float, dict]]:
    """(albedo, bsdf dict) of each lobe of a material, each dict at its own strength."""
    out = []
    refl = mat.kd * np.asarray(mat.color, dtype=np.float64)
    if refl.max() > 0.0:
        out.append((float(refl.max()), {"type": "twosided", "bsdf": {"type": "diffuse", "reflectance": rgb(refl)}}))
    if mat.kr > 0.0:
        out.append((float(mat.kr), {"type": "twosided", "bsdf": {
            "type": "conductor", "material": "none", "specular_reflectance": float(mat.kr)}}))
    if mat.kt > 0.0:
        out.append((float(mat.kt), {"type": "thindielectric" if open_surface else "dielectric",
                                    "int_ior": float(mat.ior), "ext_ior": 1.0,
                                    "specular_reflectance": float(mat.kt),
                                    "specular_transmittance": float(mat.kt)}))
    return out


def _scaled(lobe: dict, s: float) -> dict:
    """A copy of a lobe dict with its strength multiplied by ``s``."""
    inner = dict(lobe["bsdf"]) if lobe["type"] == "twosided" else dict(lobe)
    if inner["type"] == "diffuse":
        inner["reflectance"] = rgb(np.asarray(inner["reflectance"]["value"]) * s)
    elif inner["type"] == "conductor":
        inner["specular_reflectance"] = inner["specular_reflectance"] * s
    else:
        inner["specular_reflectance"] = inner["specular_reflectance"] * s
        inner["specular_transmittance"] = inner["specular_transmittance"] * s
    return {"type": "twosided", "bsdf": inner} if lobe["type"] == "twosided" else inner


def _blend(lobes: list[tuple[float, dict]]) -> dict:
    """The sum of the lobes as nested ``blendbsdf`` (see the module docstring)."""
    S = sum(a for a, _ in lobes)
    scaled = [(a / S, _scaled(d, S / a)) for a, d in lobes]

    def nest(items):
        if len(items) == 1:
            return items[0][1]
        p0 = items[0][0]
        rest = [(p / (1.0 - p0), d) for p, d in items[1:]]
        return {"type": "blendbsdf", "weight": float(1.0 - p0), "bsdf_0": items[0][1], "bsdf_1": nest(rest)}
    return nest(scaled)


def material_bsdf(mat: m.Material, open_surface: bool = False) -> dict:
    """The Mitsuba BSDF dict of a material (see the mapping table): diffuse + mirror + glass
    lobes summed, wrapped in a ``mask`` for a constant opacity below 1."""
    lobes = _lobes(mat, open_surface)
    if not lobes:
        bsdf = {"type": "twosided", "bsdf": {"type": "diffuse", "reflectance": rgb((0.0, 0.0, 0.0))}}
    elif len(lobes) == 1:
        bsdf = lobes[0][1]
    else:
        bsdf = _blend(lobes)
    op = mat.opacity
    if op is not None and op.kind == "constant" and op.value < 1.0:
        bsdf = {"type": "mask", "opacity": float(op.value), "bsdf": bsdf}
    return bsdf


def _material_left_out(mat: m.Material, used_in_open: bool) -> list[Note]:
    out = []
    for feat in sorted(F.material_needs(mat) & set(MODEL_NOTES)):
        out.append(Note(feat, MODEL_NOTES[feat]))
    if mat.opacity is not None and mat.opacity.kind != "constant":
        out.append(Note(F.OPACITY, f"{mat.opacity.kind} opacity maps not exported (opaque)"))
    if mat.kt > 0.0:
        out.append(Note(F.REFRACTION, "exact Fresnel split only (Mitsuba's dielectric): the ray tracer's "
                   "constant kr/kt split (fresnel = none) has no counterpart"))
        if used_in_open:
            out.append(Note(F.REFRACTION, "open surfaces with kt as Mitsuba's thindielectric "
                       "(inter-reflections inside the sheet included)"))
    if mat.environment:
        out.append(Note(F.ENVIRONMENT, MODEL_NOTES[F.ENVIRONMENT]))
    return out


def _scene_bounds(parts_pts: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    P = np.concatenate(parts_pts, 0)
    return P.min(0), P.max(0)


class ShapeWriter:
    """Adds one scene's shapes to the Mitsuba dictionary ``d``; object kinds add theirs through
    it (``mitsuba(obj, x)``, see :mod:`workbench.scene.kinds`): :meth:`tessellated` (the
    object's raster tessellation as PLY meshes), :meth:`analytic` (a Mitsuba shape dict of
    its own, e.g. ``sphere``), :meth:`similarity_scale` and :meth:`leave`; ``level`` is the
    export's tessellation level; participating media go through :meth:`write_volume` (a
    grid as a ``.vol`` file; ``volume_grid`` is the export's resolution for fields that have
    none of their own) and :meth:`medium`.  Shapes are named ``shape_00000``... in the order
    added."""

    def __init__(self, scene: m.Scene, folder: str, d: dict, level: int, left: list[Note],
                 volume_grid: int = 64):
        self.scene, self.folder, self.d, self.level, self.left = scene, folder, d, level, left
        self.volume_grid = volume_grid
        self.pts: list[np.ndarray] = []
        self.shapes = self.triangles = self.volumes = 0
        self.camera_media: list[dict] = []
        self.media_boxes: list[tuple[np.ndarray, np.ndarray]] = []
        self.media = 0

    def leave(self, feature: str, reason: str, approximated: bool = False) -> None:
        """A note for ``left_out`` (``approximated``: the feature is exported, not exactly)."""
        self.left.append(Note(feature, reason, Status.APPROXIMATED if approximated else Status.LEFT_OUT))

    def write_volume(self, data: np.ndarray, lo, hi) -> str:
        """Write a grid (``(z, y, x)`` or ``(z, y, x, channels)``, :func:`write_vol`) into the
        export's folder; returns its path (for a ``gridvolume``'s ``filename``)."""
        path = os.path.join(self.folder, f"volume_{self.volumes:05d}.vol")
        write_vol(path, data, lo, hi)
        self.volumes += 1
        return path

    def medium(self, shape: dict, medium: dict, lo: np.ndarray, hi: np.ndarray,
               around_camera: bool = False) -> dict:
        """Add a shape dict (``type``, ``to_world``, ...) that bounds the participating
        ``medium`` dict: a ``null`` BSDF (no surface), the medium as its ``interior``; ``lo, hi``
        (3,) its world bounds.  ``around_camera``: the camera is inside it (the sensor gets the
        medium).  The export then uses the ``volpath`` integrator."""
        shape = {**shape, "bsdf": {"type": "null"}, "interior": medium}
        self.d[f"shape_{self.shapes:05d}"] = shape
        self.pts.append(np.array([lo, hi], dtype=np.float64))
        self.shapes += 1
        self.media += 1
        self.media_boxes.append((np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)))
        if around_camera:
            self.camera_media.append(medium)
        return shape

    def similarity_scale(self, M: np.ndarray) -> float | None:
        """The uniform scale of the linear part of ``M`` (4, 4), or None."""
        return _similarity_scale(M)

    def _emitted(self, shape: dict, material: str) -> dict:
        mat = self.scene.materials[material]
        if mat.is_emitter:
            shape["emitter"] = {"type": "area", "radiance": rgb(np.asarray(mat.emission))}
        return shape

    def add_mesh(self, P, Fc, N, bsdf, emission=None, flat=False) -> dict:
        """A PLY triangle mesh shape (world points ``P`` (V, 3), faces ``Fc`` (F, 3), vertex
        normals ``N`` or None) with its BSDF dict and area-emitter radiance (3,) or None."""
        path = os.path.join(self.folder, f"mesh_{self.shapes:05d}.ply")
        write_ply(path, P, Fc, None if flat else N)
        shape = {"type": "ply", "filename": path, "face_normals": bool(flat), "bsdf": bsdf}
        if emission is not None:
            shape["emitter"] = {"type": "area", "radiance": rgb(emission)}
        self.d[f"shape_{self.shapes:05d}"] = shape
        self.pts.append(np.asarray(P, dtype=np.float64))
        self.shapes += 1
        self.triangles += len(Fc)
        return shape

    def tessellated(self, obj: m.SceneObject, level: int, *, flat: bool = False,
                    open_surface: bool = False) -> list[dict]:
        """The object's raster tessellation at ``level`` (its own ``tessellation`` wins), one
        PLY mesh per part with its material's BSDF (``thindielectric`` when ``open_surface``)
        and emission; ``flat``: face normals.  Notes that Mitsuba's area emitter emits from
        the front side only when the object's material emits."""
        out = []
        for part in tessellate_object(obj, level):
            pm = self.scene.materials[part.material]
            out.append(self.add_mesh(part.positions, part.faces, part.normals, material_bsdf(pm, open_surface),
                                     np.asarray(pm.emission) if pm.is_emitter else None, flat))
        if self.scene.materials[obj.material].is_emitter:
            self.leave(F.EMITTERS, "emissive surfaces emit from their front side only (Mitsuba's area "
                       "emitter); the workbench adds emission on both sides")
        return out

    def analytic(self, shape: dict, material: str, lo: np.ndarray, hi: np.ndarray) -> dict:
        """Add a Mitsuba shape dict of the kind's own (``type``, ``to_world``, ...) with the
        material's BSDF and emitter; ``lo, hi`` (3,) its world bounds (for the clip range)."""
        shape = self._emitted({**shape, "bsdf": material_bsdf(self.scene.materials[material])}, material)
        self.d[f"shape_{self.shapes:05d}"] = shape
        self.pts.append(np.array([lo, hi], dtype=np.float64))
        self.shapes += 1
        return shape


def has_light(scene: m.Scene, background_light: bool = True) -> bool:
    """Whether anything in the scene emits light (lights, emissive materials, background)."""
    return bool(scene.lights) or (background_light and max(scene.background) > 0.0) or any(
        scene.materials[o.material].is_emitter for o in scene.objects)


def export_scene(scene: m.Scene, folder: str, tessellation: int, spp: int = 16,
                 background_light: bool = True, volume_grid: int = 64) -> Export:
    """Mitsuba scene dictionary of ``scene`` (its camera and resolution), meshes written to ``folder``.

    Parameters
    ----------
    scene : the scene (camera resolution = image size).
    folder : existing folder for the PLY files (the dictionary names them by absolute path).
    tessellation : level for curved surfaces that are not analytic spheres (quadrics, CSG,
        non-uniformly scaled spheres).
    spp : the sensor's sample count (the renderer passes its own to ``mi.render``).
    background_light : export a non-black background as a ``constant`` emitter (it then lights
        the scene); False: black, as far as light is concerned.
    volume_grid : resolution of the grid that samples a participating medium's field when the
        object has no grid of its own (a hypertexture without ``grid``).

    Raises
    ------
    NotApplicable
        When nothing in the scene emits light (the image would be black).
    """
    if not has_light(scene, background_light):
        raise NotApplicable("method 'mitsuba': the scene has no light (no lights, emissive materials "
                            "or background): the image would be black")
    cam = scene.camera
    left: list[Note] = []
    d: dict = {"type": "scene",
               "integrator": {"type": "path", "max_depth": -1, "rr_depth": RR_DEPTH, "hide_emitters": False}}
    sw = ShapeWriter(scene, folder, d, tessellation, left, volume_grid)
    open_mats = {o.material for o in scene.objects if not is_solid(o)}
    for name, mat in scene.materials.items():
        if any(o.material == name for o in scene.objects):
            left.extend(_material_left_out(mat, name in open_mats))
    for obj in scene.objects:
        mat = scene.materials[obj.material]
        if mat.opacity is not None and mat.opacity.kind == "constant" and mat.opacity.value < OPACITY_CUT:
            left.append(Note(F.OPACITY, f"object {obj.name or obj.kind!r} cut out (constant opacity "
                        f"{mat.opacity.value} < {OPACITY_CUT})"))
            continue
        write = getattr(kind_of(obj), "mitsuba", None)  # optional for a plugin kind
        if write is None or write(obj, sw) is None:
            left.append(Note(kind_of(obj).FEATURE, f"{obj.kind} object kind not exported to Mitsuba 3"))
    if sw.media:  # participating media: the volumetric path tracer, with the same settings
        d["integrator"] = {**d["integrator"], "type": "volpath"}
        boxes = sw.media_boxes
        if any(np.all(a[0] < b[1]) and np.all(b[0] < a[1]) for i, a in enumerate(boxes) for b in boxes[i + 1:]):
            left.append(Note("media", "media whose bounds overlap: Mitsuba's volpath follows one medium at a "
                             "time (the last boundary crossed), not their sum"))
    # lights
    black = {"type": "diffuse", "reflectance": rgb((0.0, 0.0, 0.0))}
    for light in scene.lights:
        if isinstance(light, m.AreaLight):
            v = np.asarray(light.vertices, dtype=np.float64)
            fan = np.array([[0, i, i + 1] for i in range(1, len(v) - 1)], dtype=np.int64)
            sw.add_mesh(v, fan, None, black, light.radiance, flat=True)
    if not sw.pts:
        raise NotApplicable("method 'mitsuba': the scene has no geometry to render")
    lo, hi = _scene_bounds(sw.pts)
    centre = 0.5 * (lo + hi)
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    for k, light in enumerate(scene.lights):
        col = np.asarray(light.color, dtype=np.float64) * light.intensity * np.pi
        if isinstance(light, m.DirectionalLight):
            d[f"light_{k:03d}"] = {"type": "directional", "direction": [float(x) for x in light.direction],
                                   "irradiance": rgb(col)}
        elif isinstance(light, m.PointLight):
            p = np.asarray(light.position, dtype=np.float64)
            if light.falloff == "none":
                r0 = float(np.linalg.norm(p - centre))
                col = col * r0 * r0
                left.append(Note(F.POINT_LIGHTS, f"falloff 'none' has no physical counterpart: inverse-square "
                            f"light matching it at the centre of the scene's bounds (r0 = {r0:.4g})"))
            if light.cosine_normal is not None:
                left.append(Note(F.POINT_LIGHTS, "a point light's cosine lobe is not exported (isotropic)"))
            d[f"light_{k:03d}"] = {"type": "point", "position": [float(x) for x in p], "intensity": rgb(col)}
    if max(scene.background) > 0.0 and background_light:
        d["background"] = {"type": "constant", "radiance": rgb(scene.background)}
        left.append(Note("background", "a constant environment emitter in Mitsuba, so it also lights the "
                    "scene (the ray tracer only shows it)"))
    elif max(scene.background) > 0.0:
        left.append(Note("background", "not exported (background_light = false): rays leaving the scene see black"))
    if scene.environment is not None:
        left.append(Note(F.ENVIRONMENT, MODEL_NOTES[F.ENVIRONMENT]))
    if max(scene.ambient) > 0.0 and any(mt.ka > 0.0 for mt in scene.materials.values()):
        left.append(Note("ambient", "no ambient term in a physically based renderer (interreflection replaces it)"))
    dist = np.linalg.norm(corners - np.asarray(cam.position, dtype=np.float64), axis=1).max()
    far = float(cam.far or FAR_CLIP_MARGIN * max(dist, tol.zero))
    near = float(cam.near or far * NEAR_CLIP_RATIO)
    d["sensor"] = {"type": "perspective", "fov_axis": "y", "fov": float(cam.fov_y),
                   "to_world": camera_to_world(cam).tolist(), "near_clip": near, "far_clip": far,
                   "sampler": {"type": "independent", "sample_count": int(spp)},
                   "film": {"type": "hdrfilm", "width": int(cam.width), "height": int(cam.height),
                            "rfilter": {"type": "box"}, "pixel_format": "rgb",
                            "component_format": "float32", "sample_border": False}}
    if sw.camera_media:
        d["sensor"]["medium"] = sw.camera_media[0]
        if len(sw.camera_media) > 1:
            left.append(Note("media", f"the camera is inside {len(sw.camera_media)} media: Mitsuba's sensor "
                             "starts in one (the first); the others are missed until a ray crosses their boundary"))
    return Export(d, sorted(set(left)), sw.triangles, sw.shapes)

