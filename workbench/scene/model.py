"""Pure-data scene model (pbrt-v4 style: the scene is data; renderers build runtime objects).

Every vector is a tuple of floats; matrices are read-only ``numpy`` arrays.  Nothing here
renders: the only methods are geometric queries every renderer must agree on (camera rays and
projection, object bounds, light stand-ins).

Shared conventions (DESIGN.md): right-handed world, y up; images top row first; colours are
linear RGB.  Emission and light colours are *radiance-like display values*: a surface with
``emission = (1, 1, 1)`` and nothing else shows as white (1, 1, 1) in every method.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Literal, Union

import numpy as np

from ..core import transform as tf
from ..core.tol import tol

Vec3 = tuple[float, float, float]
RGB = tuple[float, float, float]


def _ro(a) -> np.ndarray:
    """A read-only float64 copy, so that frozen dataclasses stay frozen."""
    a = np.array(a, dtype=np.float64)
    a.setflags(write=False)
    return a


# --------------------------------------------------------------------------- camera
@dataclass(frozen=True)
class Camera:
    """Pinhole camera shared by every method.

    Pixel ``(i, j)`` (row ``i`` from the top, column ``j``) samples the ray through its centre.
    ``near``/``far`` are the raster clip planes; ``None`` lets the raster choose them from the
    scene's bounds.
    """

    position: Vec3
    look_at: Vec3
    up: Vec3 = (0.0, 1.0, 0.0)
    fov_y: float = 45.0
    width: int = 320
    height: int = 240
    near: float | None = None
    far: float | None = None

    @property
    def aspect(self) -> float:
        return self.width / self.height

    def with_resolution(self, width: int, height: int) -> "Camera":
        return replace(self, width=int(width), height=int(height))

    def camera_from_world(self) -> np.ndarray:
        """View matrix (4, 4); the camera looks down its -z axis (OpenGL)."""
        return tf.look_at(self.position, self.look_at, self.up)

    def clip_from_camera(self, near: float, far: float) -> np.ndarray:
        """Projection matrix (4, 4), OpenGL conventions."""
        return tf.perspective(self.fov_y, self.aspect, near, far)

    def rays(self) -> tuple[np.ndarray, np.ndarray]:
        """Primary rays through pixel centres.

        Returns
        -------
        origins : (H, W, 3) float64
        directions : (H, W, 3) float64, unit length; row 0 is the top of the image.
        """
        H, W = self.height, self.width
        th = np.tan(np.radians(self.fov_y) / 2.0)
        xs = ((np.arange(W) + 0.5) / W * 2.0 - 1.0) * th * self.aspect
        ys = (1.0 - (np.arange(H) + 0.5) / H * 2.0) * th
        d_cam = np.stack(np.broadcast_arrays(xs[None, :], ys[:, None], -np.ones((H, 1))), -1)
        world_from_camera = np.linalg.inv(self.camera_from_world())
        d = tf.normalize(d_cam @ world_from_camera[:3, :3].T)
        o = np.broadcast_to(np.asarray(self.position, dtype=np.float64), d.shape).copy()
        return o, d

    def project(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Project world points (N, 3) to continuous pixel coordinates.

        Returns ``(xy, depth)``: ``xy`` (N, 2) with x = column and y = row measured from the
        top-left corner (pixel (i, j) covers ``[j, j+1) x [i, i+1)``), and ``depth`` (N,), the
        camera-space distance along the view axis (positive in front of the camera).
        """
        p_cam = tf.transform_points(self.camera_from_world(), points)
        depth = -p_cam[:, 2]
        th = np.tan(np.radians(self.fov_y) / 2.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            ndc_x = p_cam[:, 0] / (depth * th * self.aspect)
            ndc_y = p_cam[:, 1] / (depth * th)
        xy = np.stack([(ndc_x + 1.0) / 2.0 * self.width, (1.0 - ndc_y) / 2.0 * self.height], -1)
        return xy, depth


# --------------------------------------------------------------------------- lights
@dataclass(frozen=True)
class PointLight:
    """Point light.  Received intensity ``color * intensity`` (``falloff = "none"``, as in the
    course) or ``color * intensity / r^2`` (``"inverse_square"``).  ``cosine_normal``, when set,
    weights emission by ``max(0, cosine_normal . (P - position))`` (a stand-in for one piece of an
    area light)."""

    position: Vec3
    color: RGB = (1.0, 1.0, 1.0)
    intensity: float = 1.0
    falloff: Literal["none", "inverse_square"] = "none"
    cosine_normal: Vec3 | None = None


@dataclass(frozen=True)
class DirectionalLight:
    """Light from infinitely far away; ``direction`` is the way the light travels."""

    direction: Vec3
    color: RGB = (1.0, 1.0, 1.0)
    intensity: float = 1.0


@dataclass(frozen=True, eq=False)
class AreaLight:
    """Planar convex emissive polygon (radiosity's emitter).

    It emits radiance ``color * intensity`` from its front face (normal by the right-hand rule
    of ``vertices``) and is visible in every method as a surface of that radiance.  Methods that
    only know point lights use :meth:`stand_ins`: ``stand_in x stand_in`` point lights on a grid,
    inverse-square falloff with a cosine lobe, total power matching the polygon's
    (``I = L A / pi`` split across the grid, Lambertian emitter).
    """

    vertices: np.ndarray  # (N, 3)
    color: RGB = (1.0, 1.0, 1.0)
    intensity: float = 1.0
    stand_in: int = 1

    @property
    def normal(self) -> np.ndarray:
        """Unit normal from the summed cross products (robust to collinear leading vertices)."""
        v = self.vertices
        return tf.normalize(np.cross(v[1:-1] - v[0], v[2:] - v[0]).sum(0))

    @property
    def area(self) -> float:
        v = self.vertices
        return float(0.5 * np.linalg.norm(np.cross(v[1:-1] - v[0], v[2:] - v[0]).sum(0)))

    @property
    def radiance(self) -> np.ndarray:
        return np.asarray(self.color) * self.intensity

    def stand_ins(self) -> list[PointLight]:
        v, n = self.vertices, self.stand_in
        if len(v) == 4:  # cell centres of an n x n bilinear grid on the quadrilateral
            s = (np.arange(n) + 0.5) / n
            a, b = np.meshgrid(s, s, indexing="ij")
            a, b = a.reshape(-1, 1), b.reshape(-1, 1)
            pts = (1 - a) * (1 - b) * v[0] + a * (1 - b) * v[1] + a * b * v[2] + (1 - a) * b * v[3]
        else:
            pts = v.mean(0, keepdims=True)
        I = self.intensity * self.area / np.pi / len(pts)
        nn = tuple(float(x) for x in self.normal)
        return [PointLight(tuple(float(x) for x in p), self.color, float(I), "inverse_square", nn)
                for p in pts]


Light = Union[PointLight, DirectionalLight, AreaLight]


# --------------------------------------------------------------------------- materials
Projection = Literal["uv", "planar", "cylindrical", "spherical", "solid"]


@dataclass(frozen=True)
class Texture:
    """Colour texture.  ``kind``: checker, bricks, marble, wood, grid, image.  ``projection``
    maps a surface point to (u, v): ``uv`` (mesh coordinates), ``planar`` (object-space x, y),
    ``cylindrical`` and ``spherical`` (about ``center`` with ``pole`` and ``equator`` vectors,
    the course's globe mapping, atan2 form), or ``solid`` (3D texture on object-space points).
    ``scale`` repeats the pattern (pattern periods per unit of u, v or of object space)."""

    kind: str
    projection: Projection = "uv"
    scale: float = 1.0
    colors: tuple[RGB, RGB] = ((1.0, 1.0, 1.0), (0.0, 0.0, 0.0))
    path: str | None = None
    center: Vec3 = (0.0, 0.0, 0.0)
    pole: Vec3 = (0.0, 1.0, 0.0)
    equator: Vec3 = (1.0, 0.0, 0.0)
    mortar: float = 0.08


@dataclass(frozen=True)
class Bump:
    """Bump map: the normal is perturbed by the gradient of a height field (Blinn 1978).
    ``kind``: bricks, noise, waves, image; ``strength`` scales the height."""

    kind: str
    projection: Projection = "planar"
    scale: float = 1.0
    strength: float = 1.0
    path: str | None = None
    center: Vec3 = (0.0, 0.0, 0.0)
    pole: Vec3 = (0.0, 1.0, 0.0)
    equator: Vec3 = (1.0, 0.0, 0.0)
    mortar: float = 0.08


@dataclass(frozen=True)
class Opacity:
    """Opacity map: ``kind`` constant (``value``), grid (holes where a grid is not), checker, or
    image (its alpha / luminance).  Alpha below 0.5 cuts the surface out; otherwise alpha
    blends (transparency without refraction)."""

    kind: str
    value: float = 1.0
    projection: Projection = "uv"
    scale: float = 1.0
    path: str | None = None
    width: float = 0.2
    center: Vec3 = (0.0, 0.0, 0.0)
    pole: Vec3 = (0.0, 1.0, 0.0)
    equator: Vec3 = (1.0, 0.0, 0.0)


@dataclass(frozen=True)
class Material:
    """One description used by every method (the course's photometric characteristics).

    Local model (same in GLSL and on the CPU, DESIGN.md):
    ``I = ka C Ia + sum_l S_l I_l [kd C max(N.L, 0) + ks max(R.V, 0)^n]`` with ``C`` the colour
    (times the texture), then ``+ kr I_reflected + kt I_transmitted`` in the ray tracer.
    ``absorption`` is per unit length inside a transmissive material (Beer-Lambert).
    ``environment``: raster methods reflect the scene's environment map with weight ``kr``.
    """

    name: str
    color: RGB = (0.8, 0.8, 0.8)
    ka: float = 0.1
    kd: float = 0.8
    ks: float = 0.0
    shininess: float = 32.0
    kr: float = 0.0
    kt: float = 0.0
    ior: float = 1.0
    absorption: RGB = (0.0, 0.0, 0.0)
    emission: RGB = (0.0, 0.0, 0.0)
    texture: Texture | None = None
    bump: Bump | None = None
    opacity: Opacity | None = None
    environment: bool = False

    @property
    def reflectance(self) -> np.ndarray:
        """Diffuse reflectance rho = kd * C used by radiosity (RGB)."""
        return self.kd * np.asarray(self.color)

    @property
    def is_emitter(self) -> bool:
        return max(self.emission) > 0.0


@dataclass(frozen=True)
class Environment:
    """What rays that leave the scene see, and what environment mapping reflects.
    ``kind``: ``sky`` (zenith / horizon / ground gradient with a sun spot) or ``image``
    (lat-long image at ``path``)."""

    kind: str = "sky"
    path: str | None = None
    zenith: RGB = (0.2, 0.35, 0.8)
    horizon: RGB = (0.85, 0.9, 1.0)
    ground: RGB = (0.25, 0.2, 0.15)


# --------------------------------------------------------------------------- objects
@dataclass(frozen=True, eq=False)
class SceneObject:
    """Base of all objects: a material name, ``world_from_object`` (4, 4), an optional name
    and an optional per-object raster tessellation level."""

    material: str
    world_from_object: np.ndarray = field(default_factory=lambda: _ro(np.eye(4)))
    name: str = ""
    tessellation: int | None = None

    kind = "object"


@dataclass(frozen=True, eq=False)
class Sphere(SceneObject):
    center: Vec3 = (0.0, 0.0, 0.0)
    radius: float = 1.0
    kind = "sphere"


@dataclass(frozen=True, eq=False)
class Plane(SceneObject):
    """Finite rectangle of ``size = (w, h)`` centred at ``point`` with unit ``normal``;
    ``u_axis`` orients its width (projected into the plane)."""

    point: Vec3 = (0.0, 0.0, 0.0)
    normal: Vec3 = (0.0, 1.0, 0.0)
    size: tuple[float, float] = (10.0, 10.0)
    u_axis: Vec3 = (1.0, 0.0, 0.0)
    kind = "plane"

    def frame(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Orthonormal (u, v, n) of the rectangle, right-handed with ``n`` the normal."""
        n = tf.normalize(np.asarray(self.normal))
        u_axis = np.asarray(self.u_axis, dtype=np.float64)
        u = u_axis - (u_axis @ n) * n
        if np.linalg.norm(u) <= tol.degenerate * np.linalg.norm(u_axis):   # u_axis along n
            u = np.cross(n, [1.0, 0.0, 0.0] if abs(n[0]) < 0.9 else [0.0, 0.0, 1.0])
        u = tf.normalize(u)
        return u, np.cross(n, u), n

    def corners(self) -> np.ndarray:
        """(4, 3) object-space corners, counter-clockwise seen from the normal side."""
        u, v, _ = self.frame()
        c = np.asarray(self.point)
        hw, hh = self.size[0] / 2, self.size[1] / 2
        return np.array([c - hw * u - hh * v, c + hw * u - hh * v, c + hw * u + hh * v,
                         c - hw * u + hh * v])


@dataclass(frozen=True, eq=False)
class Box(SceneObject):
    """Axis-aligned box in object space (rotate it with ``transform``)."""

    min: Vec3 = (-1.0, -1.0, -1.0)
    max: Vec3 = (1.0, 1.0, 1.0)
    kind = "box"


@dataclass(frozen=True, eq=False)
class Quadric(SceneObject):
    """General quadric ``P^T Q P = 0`` with ``P = (x, y, z, 1)`` and ``Q`` symmetric (4, 4);
    inside is ``P^T Q P < 0``.  Cut to the object-space box ``[bounds_min, bounds_max]``."""

    Q: np.ndarray = field(default_factory=lambda: _ro(np.diag([1.0, 1.0, 1.0, -1.0])))
    bounds_min: Vec3 = (-1.0, -1.0, -1.0)
    bounds_max: Vec3 = (1.0, 1.0, 1.0)
    shape: str = "general"
    kind = "quadric"


@dataclass(frozen=True, eq=False)
class Polygon(SceneObject):
    """Planar convex polygon, vertices (N, 3) counter-clockwise seen from its front."""

    vertices: np.ndarray = field(default_factory=lambda: _ro(np.zeros((3, 3))))
    kind = "polygon"

    @property
    def normal(self) -> np.ndarray:
        v = self.vertices
        return tf.normalize(np.cross(v[1:-1] - v[0], v[2:] - v[0]).sum(0))


@dataclass(frozen=True, eq=False)
class Mesh(SceneObject):
    """Triangle mesh: vertices (V, 3), faces (F, 3) int, optional per-vertex normals (V, 3) and
    uvs (V, 2).  ``source`` says where it came from (a file path or a generator).
    ``vertex_emission`` (V, 3), when set, is emitted radiance interpolated over each triangle,
    from its front side only (where its counter-clockwise winding faces, as a one-sided
    radiosity patch: its back received nothing); the hybrid method hands the radiosity
    solution to the ray tracer this way."""

    vertices: np.ndarray = field(default_factory=lambda: _ro(np.zeros((0, 3))))
    faces: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), dtype=np.int64))
    normals: np.ndarray | None = None
    uvs: np.ndarray | None = None
    source: str = ""
    vertex_emission: np.ndarray | None = None
    kind = "mesh"


@dataclass(frozen=True, eq=False)
class CSG(SceneObject):
    """Constructive solid geometry node: ``op`` of two solids (each with its own transform,
    applied after this node's)."""

    op: Literal["union", "intersection", "difference"] = "union"
    left: SceneObject | None = None
    right: SceneObject | None = None
    kind = "csg"

    def leaves(self) -> list[SceneObject]:
        out = []
        for child in (self.left, self.right):
            out.extend(child.leaves() if isinstance(child, CSG) else [child])
        return out


# --------------------------------------------------------------------------- scene
AREA_LIGHT_PREFIX = "__area_light_"
"""Material name prefix of area lights' polygons (:meth:`Scene.area_light_polygons`)."""


@dataclass(frozen=True, eq=False)
class Scene:
    """A whole scene.  ``source`` is the file it came from (for messages and relative paths)."""

    name: str
    camera: Camera
    materials: dict[str, Material]
    objects: tuple[SceneObject, ...]
    lights: tuple[Light, ...] = ()
    description: str = ""
    background: RGB = (0.0, 0.0, 0.0)
    ambient: RGB = (0.1, 0.1, 0.1)
    environment: Environment | None = None
    source: str = ""

    def point_lights(self) -> list[PointLight | DirectionalLight]:
        """Point and directional lights, area lights replaced by their stand-ins."""
        out: list[PointLight | DirectionalLight] = []
        for light in self.lights:
            out.extend(light.stand_ins() if isinstance(light, AreaLight) else [light])
        return out

    def area_light_polygons(self) -> list[tuple[int, Polygon, Material]]:
        """Every area light as the emissive polygon the methods see, the one place where an
        area light becomes a surface: ``(k, polygon, material)`` for light ``k`` of
        :attr:`lights`, the polygon's material named ``__area_light_k`` (black, no ka/kd/ks;
        ``emission`` its radiance ``color * intensity``), not part of :attr:`materials`."""
        out = []
        for k, light in enumerate(self.lights):
            if isinstance(light, AreaLight):
                name = f"{AREA_LIGHT_PREFIX}{k}"
                mat = Material(name, color=(0.0, 0.0, 0.0), ka=0.0, kd=0.0, ks=0.0,
                               emission=tuple(float(x) for x in light.radiance))
                out.append((k, Polygon(name, vertices=light.vertices, name=name), mat))
        return out

    def material_of(self, obj: SceneObject) -> Material:
        return self.materials[obj.material]

    def with_camera(self, camera: Camera) -> "Scene":
        return replace(self, camera=camera)
