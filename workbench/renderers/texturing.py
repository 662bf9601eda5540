"""Texture evaluation, the readable numpy REFERENCE (every method textures exactly like this).

The GLSL in ``shaders/include/texturing.glsl`` mirrors these functions line by line and is tested
against them at a few pixels; the ray tracer imports this module directly.  Everything is
vectorised over ``N`` points: arrays are ``(N, 3)`` object-space points and normals (and
``(N, 2)`` uvs when a mesh has them), colours are linear RGB float64.

Projections (course, "Plaquage de textures"), from an object-space point ``P`` to ``(u, v)``,
with ``d = P - center``, ``Sp`` the pole and ``Se`` the equator made orthogonal to it, and
``W = Sp x Se`` (so that ``(Se, W, Sp)`` is a right-handed frame):

* ``planar``: projection along the pole, ``u = d.Se``, ``v = d.W`` (object units).  With
  ``pole = z`` and ``equator = x`` this is the object's ``(x, y)``; with the default
  ``pole = y`` it is the ``(x, -z)`` of a floor.
* ``cylindrical``: ``u`` the longitude below, ``v = d.Sp`` (height along the axis, object units).
* ``spherical`` (the course's globe mapping with its errata fixed, DESIGN.md #4):
  ``v = phi / pi`` with ``phi = atan2(|d x Sp|, -d.Sp)`` (the course's ``arccos(-N.Sp)``: 0 at
  the ``-Sp`` pole, 1 at ``+Sp``), and
  ``u = atan2(-d.W, -d.Se) / 2pi`` wrapped to ``[0, 1)``: the longitude, 0 at ``-Se``, 0.5 at
  ``+Se`` (the prime meridian, the middle of a lat-long image), increasing eastward
  (counter-clockwise seen from the ``+Sp`` pole, as POV-Ray's ``map_type 1`` and every
  lat-long image: seen from outside, east is to the right).  The course's
  ``arccos(-Se.N / sin phi) / 2pi`` with ``u = theta`` when ``(Sp x Se).N > 0`` and ``1 - theta``
  otherwise runs clockwise in a right-handed frame (DESIGN errata 8: lat-long images come out
  mirrored); the atan2 form is also exact at the seam and defined at the poles (``u = 0``).
* ``uv``: the mesh's coordinates; objects without uvs (``uv=None``) fall back to the spherical
  mapping about ``center``, which is also how the tessellator parametrises spheres.
* ``solid``: the pattern is a function of the 3D point ``scale * d`` itself (Peachey 1985,
  Perlin 1985).

``scale`` repeats the pattern: the pattern is evaluated at ``s = scale * (u, v)`` (pattern
periods per unit of u, v or object space).  Procedural patterns, with ``fract(x) = x - floor(x)``:

* ``checker``: ``colors[0]`` where ``floor(s_u) + floor(s_v)`` (``+ floor(s_z)``, solid) is
  even, ``colors[1]`` otherwise.
* ``bricks``: bricks 1 x 0.5 pattern units, every other row shifted by half a brick, mortar
  lines of width ``mortar`` (pattern units) in ``colors[1]``, bricks in ``colors[0]``.
  Solid bricks use ``(x + z, y)``.
* ``grid``: lines of width ``mortar`` in ``colors[1]`` where ``fract(s_u)`` or ``fract(s_v)``
  is below it, ``colors[0]`` elsewhere.
* ``marble``: ``t = 0.5 + 0.5 sin(2 pi (s_x + 2 turbulence(s)))`` (Perlin 1985),
  ``mix(colors[0], colors[1], t)``.
* ``wood``: rings about the pole axis, ``t = fract(4 (r + 0.3 fbm(s)))`` with ``r`` the
  distance to the axis in pattern units; ``mix(colors[0], colors[1], smoothstep)``.
* ``image``: bilinear lookup at texel centres, repeat wrapping, ``v = 0`` at the image's
  bottom row (OpenGL's convention).

Noise: value noise on the integer lattice with a 32-bit integer hash (lowbias32, C. Wellons
2018), quintic interpolation, so that GLSL (``uint`` arithmetic) and numpy agree bit for bit on
lattice values.  ``fbm`` and ``turbulence`` sum 4 octaves.

The final surface colour is ``material.color * texture`` (the ``C`` of the local model).
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np

from ..core.errors import WorkbenchError
from ..core.imageio import load_image_linear
from ..core.noise import value_noise
from ..core.tol import tol
from ..core.transform import normalize
from ..scene.model import Environment, Material

TWO_PI = 2.0 * np.pi
OCTAVES = 4


# --------------------------------------------------------------------------- projections
def frame(pole, equator) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(Sp, Se, W)``: unit pole, equator made orthogonal to the pole, ``W = Sp x Se``."""
    sp = normalize(np.asarray(pole, dtype=np.float64))
    se = np.asarray(equator, dtype=np.float64)
    se = normalize(se - (se @ sp) * sp)
    return sp, se, np.cross(sp, se)


def _wrap01(u: np.ndarray) -> np.ndarray:
    """``u - floor(u)`` forced into ``[0, 1)`` (rounding can give exactly 1)."""
    u = u - np.floor(u)
    return np.where(u >= 1.0, 0.0, u)


def longitude(d: np.ndarray, sp, se, w) -> np.ndarray:
    """``u = atan2(-d.W, -d.Se) / 2pi`` wrapped to [0, 1), increasing eastward (counter-clockwise
    seen from the pole, DESIGN errata 8); 0 on the axis (no NaN).  (N,)"""
    x, y = -(d @ se), -(d @ w)
    on_axis = x * x + y * y <= tol.zero * tol.zero * np.maximum(1.0, np.sum(d * d, -1))
    u = np.arctan2(np.where(on_axis, 0.0, y), np.where(on_axis, 1.0, x)) / TWO_PI
    return _wrap01(u)


def project(m, P: np.ndarray, uv: np.ndarray | None = None) -> np.ndarray:
    """Texture coordinates ``(u, v)`` (N, 2) of object-space points ``P`` (N, 3) under the
    mapping ``m`` (a Texture, Bump or Opacity), before ``scale``; ``solid`` returns nothing
    here (see :func:`pattern_coords`)."""
    d = np.asarray(P, dtype=np.float64) - np.asarray(m.center, dtype=np.float64)
    sp, se, w = frame(m.pole, m.equator)
    proj = m.projection
    if proj == "uv" and uv is not None:
        return np.asarray(uv, dtype=np.float64)
    if proj == "planar":
        return np.stack([d @ se, d @ w], -1)
    if proj == "cylindrical":
        return np.stack([longitude(d, sp, se, w), d @ sp], -1)
    if proj in ("spherical", "uv"):
        h = d @ sp
        rho = np.linalg.norm(d - h[:, None] * sp, axis=-1)
        phi = np.arctan2(rho, -h)
        return np.stack([longitude(d, sp, se, w), phi / np.pi], -1)
    raise WorkbenchError(f"unknown texture projection {proj!r}")


def pattern_coords(m, P: np.ndarray, uv: np.ndarray | None = None) -> np.ndarray:
    """Pattern-space coordinates ``s``: (N, 2) ``scale * (u, v)``, or (N, 3) ``scale * (P -
    center)`` for the ``solid`` projection."""
    if m.projection == "solid":
        return m.scale * (np.asarray(P, dtype=np.float64) - np.asarray(m.center, dtype=np.float64))
    return m.scale * project(m, P, uv)


# --------------------------------------------------------------------------- noise
def fbm(p: np.ndarray) -> np.ndarray:
    """Fractal sum ``sum_k noise(2^k p) / 2^(k+1)``, k < 4, centred: in about [-0.5, 0.5]. (N,)"""
    out = np.zeros(len(p))
    for k in range(OCTAVES):
        out += (value_noise(p * 2.0 ** k) - 0.5) / 2.0 ** k
    return out


def turbulence(p: np.ndarray) -> np.ndarray:
    """Perlin's turbulence ``sum_k |2 noise(2^k p) - 1| / 2^(k+1)``, in [0, 1). (N,)"""
    out = np.zeros(len(p))
    for k in range(OCTAVES):
        out += np.abs(2.0 * value_noise(p * 2.0 ** k) - 1.0) / 2.0 ** (k + 1)
    return out


def _lift3(s: np.ndarray) -> np.ndarray:
    """2D pattern coordinates as 3D points (z = 0) for the noise."""
    return s if s.shape[1] == 3 else np.concatenate([s, np.zeros((len(s), 1))], 1)


# --------------------------------------------------------------------------- patterns
def smoothstep(e0, e1, x):
    t = np.clip((x - e0) / (e1 - e0), 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


def _brick_uv(s: np.ndarray) -> np.ndarray:
    """Solid bricks are laid on ``(x + z, y)``; 2D ones on ``(u, v)``."""
    return np.stack([s[:, 0] + s[:, 2], s[:, 1]], -1) if s.shape[1] == 3 else s


def mortar_distance(s: np.ndarray) -> np.ndarray:
    """Distance (pattern units) from ``s`` to the nearest mortar line centre of the brick
    layout (bricks 1 x 0.5, odd rows shifted by 0.5). (N,)"""
    b = _brick_uv(s)
    row = np.floor(b[:, 1] / 0.5)
    x = b[:, 0] + 0.5 * (row - 2.0 * np.floor(row / 2.0))
    fx, fy = x - np.floor(x), b[:, 1] / 0.5 - row
    return np.minimum(np.minimum(fx, 1.0 - fx), 0.5 * np.minimum(fy, 1.0 - fy))


def pattern_value(kind: str, s: np.ndarray, width: float) -> np.ndarray:
    """Scalar pattern in [0, 1] at pattern coordinates ``s`` (N, 2|3): the blend weight of
    ``colors[1]`` (checker, bricks' mortar, grid lines, marble veins, wood rings). (N,)"""
    if kind == "checker":
        parity = np.floor(s).sum(-1)
        return parity - 2.0 * np.floor(parity / 2.0)
    if kind == "bricks":
        return (mortar_distance(s) < 0.5 * width).astype(np.float64)
    if kind == "grid":
        f = s[:, :2] - np.floor(s[:, :2])
        return (np.minimum(f[:, 0], f[:, 1]) < width).astype(np.float64)
    p = _lift3(s)
    if kind == "marble":
        return 0.5 + 0.5 * np.sin(TWO_PI * (p[:, 0] + 2.0 * turbulence(p)))
    if kind == "wood":
        r = np.hypot(p[:, 0], p[:, 2]) if s.shape[1] == 3 else np.hypot(p[:, 0], p[:, 1])
        t = 4.0 * (r + 0.3 * fbm(p))
        return smoothstep(0.0, 0.8, t - np.floor(t))
    raise WorkbenchError(f"unknown procedural texture {kind!r}")


@lru_cache(maxsize=16)
def image(path: str, data: bool = False) -> np.ndarray:
    """A texture image, RGBA float32 (H, W, 4), top row first (cached by path and ``data``):
    colour maps sRGB-decoded to linear; ``data`` maps (bump heights, opacity) as stored, v / 255."""
    try:
        img = load_image_linear(path, data=data)
    except OSError as e:
        raise WorkbenchError(f"cannot read texture image {path}: {e}") from None
    img.setflags(write=False)
    return img


@lru_cache(maxsize=16)
def has_alpha(path: str) -> bool:
    """Whether an opacity image's alpha channel is used (some pixel below 1), else its
    luminance is."""
    return bool(image(path, data=True)[..., 3].min() < 1.0)


def sample_image(img: np.ndarray, uv: np.ndarray, wrap_v: bool = True) -> np.ndarray:
    """Bilinear lookup (GL_LINEAR, texel centres, repeat in u; repeat or clamp in v) of an
    (H, W, C) image, ``v = 0`` at the bottom row.  Returns (N, C)."""
    H, W = img.shape[:2]
    x = uv[:, 0] * W - 0.5
    y = (1.0 - uv[:, 1]) * H - 0.5  # row measured from the top
    if not wrap_v:
        y = np.clip(y, 0.0, H - 1.0)
    x0, y0 = np.floor(x), np.floor(y)
    fx, fy = (x - x0)[:, None], (y - y0)[:, None]
    x0, y0 = x0.astype(np.int64), y0.astype(np.int64)
    xs0, xs1 = np.mod(x0, W), np.mod(x0 + 1, W)
    if wrap_v:
        ys0, ys1 = np.mod(y0, H), np.mod(y0 + 1, H)
    else:
        ys0, ys1 = np.clip(y0, 0, H - 1), np.clip(y0 + 1, 0, H - 1)
    a = img[ys0, xs0] * (1 - fx) + img[ys0, xs1] * fx
    b = img[ys1, xs0] * (1 - fx) + img[ys1, xs1] * fx
    return (a * (1 - fy) + b * fy).astype(np.float64)


def texture_color(tex, P: np.ndarray, uv: np.ndarray | None = None) -> np.ndarray:
    """The texture's RGB at object-space points P (N, 3) (before the material colour). (N, 3)"""
    if tex.kind == "image":
        return sample_image(image(tex.path), project(tex, P, uv) * tex.scale)[:, :3]
    t = pattern_value(tex.kind, pattern_coords(tex, P, uv), tex.mortar)[:, None]
    c0, c1 = (np.asarray(c, dtype=np.float64) for c in tex.colors)
    return c0 * (1.0 - t) + c1 * t


def surface_color(material: Material, P_obj: np.ndarray, N_obj: np.ndarray,
                  uv: np.ndarray | None = None) -> np.ndarray:
    """``C`` of the local model: the material colour times its texture, (N, 3).

    Parameters
    ----------
    P_obj : (N, 3) object-space points; N_obj : (N, 3) object-space normals (unused by the
    colour projections, which map points; kept so every texturing call has one signature);
    uv : (N, 2) mesh uvs or None.
    """
    P = np.asarray(P_obj, dtype=np.float64)
    col = np.broadcast_to(np.asarray(material.color, dtype=np.float64), P.shape)
    if material.texture is None:
        return col.copy()
    return col * texture_color(material.texture, P, uv)


# --------------------------------------------------------------------------- bump
def height(bump, P: np.ndarray, uv: np.ndarray | None = None) -> np.ndarray:
    """Height field in [0, 1] of a bump map at object-space points (N,).

    ``bricks``: 1 on bricks, 0 in the mortar, smooth over half the mortar width;
    ``noise``: ``0.5 + fbm(s)``; ``waves``: ``0.5 + 0.25 (sin 2pi s_u + sin 2pi s_v)``;
    ``image``: the image's luminance (Rec. 709 weights)."""
    if bump.kind == "image":
        rgb = sample_image(image(bump.path, data=True), project(bump, P, uv) * bump.scale)[:, :3]
        return rgb @ np.array([0.2126, 0.7152, 0.0722])
    s = pattern_coords(bump, P, uv)
    if bump.kind == "bricks":
        h_w = 0.5 * bump.mortar
        return smoothstep(0.5 * h_w, 1.5 * h_w, mortar_distance(s))
    if bump.kind == "noise":
        return 0.5 + fbm(_lift3(s))
    if bump.kind == "waves":
        return 0.5 + 0.25 * (np.sin(TWO_PI * s[:, 0]) + np.sin(TWO_PI * s[:, 1]))
    raise WorkbenchError(f"unknown bump map {bump.kind!r}")


def height_gradient(bump, P: np.ndarray, uv: np.ndarray | None = None) -> np.ndarray:
    """Object-space gradient of the displacement ``d = strength * h / scale`` (object units),
    by forward differences of step ``tol.bump_step / scale`` along the object axes (4 height
    evaluations per point instead of 6 for central ones; the step is a thousandth of a
    pattern period, so the O(step) error is far below what shading shows). (N, 3)"""
    P = np.asarray(P, dtype=np.float64)
    delta = tol.bump_step / bump.scale
    h0 = height(bump, P, uv)
    g = np.empty_like(P)
    for k in range(3):
        e = np.zeros(3)
        e[k] = delta
        g[:, k] = (height(bump, P + e, uv) - h0) / delta
    return g * (bump.strength / bump.scale)


def bump_normal(material: Material, P_obj: np.ndarray, N_obj: np.ndarray, N_world: np.ndarray,
                world_from_object: np.ndarray, uv: np.ndarray | None = None) -> np.ndarray:
    """Perturbed world-space unit normals (N, 3) (Blinn 1978, in the surface-gradient form of
    Mikkelsen 2010): the surface is displaced by ``d = strength * h / scale`` along its normal,
    and ``N' = normalize(N - (grad d - (grad d . N) N))`` with ``grad d`` taken in world space
    (``M^-T`` times the object-space gradient, ``M`` the linear part of ``world_from_object``).

    The ``uv`` projection needs surface tangents this reference does not have: a bump with
    ``projection = "uv"`` on an object without uvs uses the spherical fallback; with mesh uvs
    it is a constant height (no perturbation).  Returns ``N_world`` normalised when the
    material has no bump.
    """
    Nw = normalize(np.asarray(N_world, dtype=np.float64))
    bump = material.bump
    if bump is None or (bump.projection == "uv" and uv is not None):
        return Nw
    g_obj = height_gradient(bump, P_obj, None)
    M = np.asarray(world_from_object, dtype=np.float64)[:3, :3]
    g = g_obj @ np.linalg.inv(M)  # row-vector form of M^-T g
    g_t = g - np.sum(g * Nw, -1, keepdims=True) * Nw
    Np = normalize(Nw - g_t)
    return np.where(np.sum(Np * Np, -1, keepdims=True) > 0.0, Np, Nw)


# --------------------------------------------------------------------------- opacity
def alpha(material: Material, P_obj: np.ndarray, N_obj: np.ndarray,
          uv: np.ndarray | None = None) -> np.ndarray:
    """Opacity in [0, 1] (N,).  Below 0.5 the surface is cut out; otherwise alpha blends.

    ``constant``: ``value``; ``grid``: 1 on grid lines of width ``width`` (pattern units),
    0 in the holes; ``checker``: 1 on even squares, 0 on odd; ``image``: the image's alpha
    channel, or its luminance when the image is fully opaque.  1 without an opacity map."""
    P = np.asarray(P_obj, dtype=np.float64)
    op = material.opacity
    if op is None:
        return np.ones(len(P))
    if op.kind == "constant":
        return np.full(len(P), op.value)
    if op.kind == "image":
        img = image(op.path, data=True)
        rgba = sample_image(img, project(op, P, uv) * op.scale)
        if has_alpha(op.path):
            return rgba[:, 3]
        return rgba[:, :3] @ np.array([0.2126, 0.7152, 0.0722])
    s = pattern_coords(op, P, uv)
    if op.kind == "grid":
        return pattern_value("grid", s, op.width)
    if op.kind == "checker":
        return 1.0 - pattern_value("checker", s, op.width)
    raise WorkbenchError(f"unknown opacity map {op.kind!r}")


# --------------------------------------------------------------------------- environment
def latlong_uv(directions: np.ndarray) -> np.ndarray:
    """Lat-long coordinates of unit directions (N, 3): ``u = 0.5 + atan2(x, -z) / 2pi``
    (u = 0.5 looking down -z), ``v = 0.5 + asin(y) / pi`` (v = 1 straight up). (N, 2)"""
    d = normalize(directions)
    horiz = d[:, 0] ** 2 + d[:, 2] ** 2 <= tol.zero * tol.zero
    u = 0.5 + np.arctan2(np.where(horiz, 0.0, d[:, 0]), np.where(horiz, 1.0, -d[:, 2])) / TWO_PI
    v = 0.5 + np.arcsin(np.clip(d[:, 1], -1.0, 1.0)) / np.pi
    return np.stack([_wrap01(u), v], -1)


def environment(env: Environment | None, directions: np.ndarray) -> np.ndarray:
    """Radiance seen in world directions (N, 3).  ``sky``: with ``y`` the direction's up
    component, ``mix(horizon, zenith, y)`` above the horizon and ``mix(horizon, ground,
    min(1, 4 |y|))`` below it; ``image``: bilinear lookup in a lat-long image (see
    :func:`latlong_uv`).  ``None`` means the default sky."""
    env = env or Environment()
    d = normalize(directions)
    if env.kind == "image":
        return sample_image(image(env.path), latlong_uv(d), wrap_v=False)[:, :3]
    y = d[:, 1:2]
    hz, zn, gr = (np.asarray(c, dtype=np.float64) for c in (env.horizon, env.zenith, env.ground))
    up = hz + (zn - hz) * np.clip(y, 0.0, 1.0)
    down = hz + (gr - hz) * np.clip(-4.0 * y, 0.0, 1.0)
    return np.where(y >= 0.0, up, down)
