"""The one place for every tolerance of the workbench (after trimesh's ``tol``).

Epsilons that guard geometry are *relative*: they are multiplied by the magnitude of the
quantity they protect (a hit point, a scene's extent), so that a scene at scale 1e-6 and one
at 1e6 behave the same.  Renderers import ``tol`` and never write an epsilon inline.
"""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Tolerances:
    """Documented tolerances.

    Attributes
    ----------
    zero : float
        Absolute floor below which a length or determinant counts as zero (unit-free data
        such as directions and normalised vectors).
    ray_offset : float
        Relative offset of a secondary ray's origin along the surface normal:
        ``offset = ray_offset * max(1, |P|_inf)`` scaled by the scene's own size (see
        :func:`offset_scale`).  Keeps shadow and reflection rays off their own surface.
    t_min : float
        Relative minimum ray parameter accepted as a hit: ``t > t_min * scale``.
    planar : float
        Relative distance of a polygon vertex from the polygon's plane tolerated when a
        scene declares a planar polygon (fraction of the polygon's diameter).  The published
        Cornell box's red wall is 0.2 % off its plane, hence 0.5 %.
    symmetric : float
        Relative asymmetry tolerated in a quadric's 4x4 matrix, entry by entry:
        ``|Q_ij - Q_ji| <= symmetric * max(|Q_ij|, |Q_ji|)`` (both scale alike when the
        quadric is scaled, so the test does not depend on its size).
    normal_cancel : float
        An interpolated normal shorter than this (before normalisation) is treated as
        cancelled; the geometric normal is used instead.
    hemicube_near : float
        Near-plane distance of a radiosity hemicube, as a fraction of the scene's extent:
        surfaces closer than this to a patch centre are not seen (the Cornell light hangs
        0.8 mm = 1.1e-3 extents below the ceiling, hence far less).
    hemicube_flat : float
        Largest distance of a block of radiosity patches, drawn by the hemicube as one quad,
        from the patches' own triangles, as a fraction of a patch edge (a warped quad such
        as the Cornell box's red wall is drawn in smaller blocks): seen from the nearest
        other patch centre, half an edge away, it moves a surface by a fifth of a pixel of a
        resolution-128 hemicube.
    cut : float
        Relative slack of the bounds a quadric is cut to, when a ray's hit point is tested
        against them: ``cut * (|O| + |t D|)`` (infinity norms), a bound on the rounding of
        ``O + t D``, so that a ray through a point on the bounds' faces (an ellipsoid's pole)
        does not miss.
    bounds_pad : float
        Relative growth of an analytic primitive's world box in the ray tracer's acceleration
        structure: ``bounds_pad * (|box|_inf + scale)`` on every side, ``scale`` the scene's
        size and the camera's distance from the origin (100 times ``cut``: a cut quadric's hit
        may lie ``cut`` relative outside its bounds, more in world units under a stretching
        transform).  A looser box costs nothing measurable; a tight one could lose a hit.
    bump_step : float
        Finite-difference step of a bump map's height gradient, as a fraction of one pattern
        period (the step in object units is ``bump_step / scale``).
    degenerate : float
        Relative size at or below which a scene's geometry counts as degenerate (refused at
        load, or replaced by a fallback), always measured against the object's own size so
        that a scene scaled by 1e-6 or 1e6 is judged like the unscaled one:

        * a polygon whose Newell vector ``|sum (v_i - v_0) x (v_{i+1} - v_0)|`` (twice its
          area) is at most ``degenerate * d * max(d, |v|_inf)``, ``d`` its diameter (the
          ``|v|_inf`` term bounds the rounding of the vertex differences of a polygon far
          from the origin);
        * a transform whose smallest singular value is at most ``degenerate`` times its
          largest (a scale component at most ``degenerate`` times the largest);
        * a camera whose ``|look_at - position|`` is at most ``degenerate`` times the larger
          of ``|look_at|, |position|``;
        * two directions whose angle has a sine at most ``degenerate`` (camera up and view
          direction, texture pole and equator, a plane's ``u_axis`` and its normal).
    """

    zero: float = 1e-12
    ray_offset: float = 1e-7
    t_min: float = 1e-9
    planar: float = 5e-3
    symmetric: float = 1e-9
    normal_cancel: float = 1e-6
    hemicube_near: float = 1e-5
    hemicube_flat: float = 1e-3
    cut: float = 1e-9
    bounds_pad: float = 1e-7
    bump_step: float = 1e-3
    degenerate: float = 1e-9


tol = Tolerances()


def offset_scale(point_magnitude: float, scene_extent: float) -> float:
    """Length by which to push a secondary ray's origin off a surface.

    ``tol.ray_offset * max(|P|, scene_extent)``: relative to the larger of the hit point's
    magnitude (floating-point spacing grows with it) and the scene's extent (so a scene at
    1e-6 gets offsets at 1e-13, not at a fixed 1e-4 that would swallow it).
    """
    return tol.ray_offset * max(point_magnitude, scene_extent)
