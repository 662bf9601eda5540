"""Numba kernels of the path tracer: unbiased Monte Carlo estimation of the rendering equation
(Kajiya, "The rendering equation", SIGGRAPH 1986) on the ray tracer's arrays, BVH and
intersection kernels (:func:`..kernels.intersect.closest`, :func:`..kernels.intersect.surface`).

One path per sample, from the camera (uniform jitter in the pixel: the box-filtered pixel):

* at each hit, emission ``L_e`` (front face only for area lights) is added with the path
  throughput ``beta``, weighted by multiple importance sampling against the light strategy
  (power heuristic, Veach & Guibas 1995; Veach 1997 ch. 9) unless the previous bounce was a
  delta lobe or the camera;
* the surface is a mixture of lobes with weights ``a_d = kd C`` (Lambert, ``a_d / pi``),
  ``a_s = ks`` (normalised modified Phong, ``ks (n + 2) / (2 pi) cos^n alpha``; Lafortune &
  Willems 1994), ``a_r`` (mirror) and ``a_t`` (transmission: refraction through solids, straight
  through thin sheets), from ``kr, kt`` with the ray tracer's Fresnel option; all scaled by
  ``1 / max(1, kd max(C) + ks + kr + kt)`` so that no surface reflects more than it receives;
* next-event estimation at non-delta vertices: one emitter triangle point
  (:mod:`.emitters`, MIS with the BSDF strategy; the shadow feeler aims from its origin, pushed
  off the surface, at that point, and stops ``2 off`` short of it) and every point /
  directional light (delta lights: no MIS; a light of value ``I`` gives the irradiance
  ``pi I S cos`` with ``S`` its falloff and spot factor, so that a Lambertian surface reflects
  ``kd C I S cos``: the course's diffuse term, and the convention of the area lights' point
  stand-ins);
* the next direction: a lobe chosen with probability proportional to its weight, then for the
  non-delta pair the one-sample mixture of the cosine and Phong densities;
* Russian roulette from the ``rr_start``-th bounce on: survive with
  ``q = min(0.95, max(beta))``, ``beta /= q``; a path stops for good at ``max_bounces``
  (``0.95^k``: unreachable in practice, a guard against endless loops).

Transport (``opts[PathOpt.TRANSPORT]``), for the matched references of other methods (DESIGN.md, "Ground
truth and the error split"):

* ``full`` (0): all of the above;
* ``diffuse`` (1): exactly what radiosity computes (``radiosity.patches``, ``.hemicube``): every
  surface is Lambertian with reflectance ``kd C`` (``ks, kr, kt`` ignored: opaque, no Phong
  lobe, no mirror, no glass; plain colours, no textures), scaled only where ``kd max(C) > 1``;
  only surfaces emit (area lights, ``emission``; point and directional lights, vertex emission
  and the background light nothing: a camera ray that escapes still sees the background, as
  radiosity's display clears to it); every surface is one-sided, as the form factors see it:
  its back neither emits nor reflects (a black occluder), except where the camera sees a back
  face, which radiosity's display draws with its front's value: the Lambertian front radiance,
  the same in every direction, is estimated there (the path leaves from the front side);
* ``eye_specular`` (2): the hybrid method's physics (``radiosity.hybrid``): along the eye path
  (the camera, then only delta bounces) a surface with ``kr > 0`` or ``kt > 0`` keeps its mirror
  and transmission lobes (Fresnel split, media, absorption as ``full``) and its Lambertian
  ``kd C``, weights scaled by ``1 / max(1, kd max(C) + kr + kt)``; ``ks`` is ignored (the hybrid's
  highlights come from the ray tracer's point-light stand-ins, not from the diffuse solution:
  that difference is missing physics); from the first non-delta bounce on, ``diffuse`` transport
  (no caustics: a mirror or glass surface is Lambertian ``kd C`` there).

Pixel filter (``opts[PathOpt.PIXEL_FILTER]``): 0 box (uniform jitter over the pixel's square: the workbench's ideal
image), 1 centre (every sample through the pixel's centre: the point-sampled image of the
raster and radiosity methods; the estimate converges to the radiance seen at the centre).

Random numbers: a counter-based hash (SplitMix64's finaliser) of (seed, pixel, sample index,
dimension), so an image depends on the seed only, not on how the threads share the work, and
more samples continue a sequence (:class:`..pathtrace.session.PathTraceSession`).

The readable twin of this estimator is :mod:`.reference`; the two are tested against each other.
"""
from __future__ import annotations

import math

import numba as nb
import numpy as np
from numba.extending import overload

from ..kernels.columns import PATH_COUNTS, Light, Mat, PathCount, PathOpt
from ..kernels.rng import path_key, rand
from .media import shadow_gate, vertex_gate
from .sampling import mis_weight, sample_emitter
from ..kernels.tasks import run_tasks
from ..kernels.flags import INLINE, NO_REFCOUNT, TASK
from ..kernels.intersect import closest, scratch, surface
from ..kernels.media import track
from ..kernels.optics import _feeler, _light_dir, enter_or_leave, fresnel_reflectance
from ..kernels.textures import checker_color
from ..kernels.shapes import _normalize
from ..kernels.specialise import has
from ..kernels.walks import bvh_hit
from ..raytrace.kernels import MAX_TASKS

BLOCK = 32
"""Pixels per work item of :func:`render_samples`."""
INV_PI = 1.0 / math.pi
INV_2PI = 0.5 / math.pi
JITTER_U, JITTER_V = np.int64(0), np.int64(1)
"""The random dimensions of the pixel jitter, as int64 (not literals: see ``kernels.walks.LANE``)."""
@nb.njit(**INLINE)
def _frame(nx, ny, nz):
    """Two unit tangents completing ``n`` (Duff et al., "Building an orthonormal basis,
    revisited", JCGT 2017)."""
    s = 1.0 if nz >= 0.0 else -1.0
    a = -1.0 / (s + nz)
    b = nx * ny * a
    return 1.0 + s * nx * nx * a, s * b, -s * nx, b, s + ny * ny * a, -ny


@nb.njit(**INLINE)
def _around(nx, ny, nz, cos_t, phi):
    """Unit direction at polar angle ``acos(cos_t)`` and azimuth ``phi`` about ``n``."""
    tx, ty, tz, bx, by, bz = _frame(nx, ny, nz)
    sin_t = math.sqrt(max(0.0, 1.0 - cos_t * cos_t))
    c, s = math.cos(phi) * sin_t, math.sin(phi) * sin_t
    return c * tx + s * bx + cos_t * nx, c * ty + s * by + cos_t * ny, c * tz + s * bz + cos_t * nz


@nb.njit(**INLINE)
def camera_ray_at(cam, i, j, u, v):
    """Unit direction of the ray through point ``(j + u, i + v)`` of the image plane (pixel
    ``(i, j)``, ``u, v`` in [0, 1); ``u = v = 1/2`` is :func:`..kernels.optics.camera_ray`'s
    centre ray) of the camera ``cam`` (``raytrace.whitted.camera_frame``)."""
    x = ((j + u) / cam[14] * 2.0 - 1.0) * cam[12] * cam[13]
    y = (1.0 - (i + v) / cam[15] * 2.0) * cam[12]
    return _normalize(x * cam[3] + y * cam[4] - cam[5], x * cam[6] + y * cam[7] - cam[8],
                 x * cam[9] + y * cam[10] - cam[11])


@nb.njit(**INLINE)
def phong_lobe(ks, shin, rx, ry, rz, wx, wy, wz):
    """``(ks cos^n alpha (n + 2) / (2 pi), cos^n alpha (n + 1) / (2 pi))``: the normalised Phong
    lobe's value and its sampling density, ``alpha`` the angle between ``w`` and the mirror
    direction ``r`` (Lafortune & Willems 1994); 0 beyond 90 degrees, and where ``ks = 0``."""
    ca = rx * wx + ry * wy + rz * wz
    if ca <= 0.0 or ks <= 0.0:
        return 0.0, 0.0
    c = ca ** shin if shin > 0.0 else 1.0
    return ks * (shin + 2.0) * INV_2PI * c, (shin + 1.0) * INV_2PI * c


def hit_rows():
    """One row per hit record of :func:`..kernels.intersect.surface`: geometric normal, shading
    normal, uv, object-space point, vertex emission; then the media stack (4)."""
    return (np.empty((1, 3)), np.empty((1, 3)), np.empty((1, 2)), np.empty((1, 3)), np.empty((1, 3)),
            np.zeros(4, np.int64))


def render_samples(geo, shading, emitters, cam, opts, seed, s0, nsamp, sums, sumsq, counts):
    """Add samples ``s0 .. s0 + nsamp - 1`` of every pixel to its running sums.

    Parameters
    ----------
    geo : the ray tracer's geometry tuple (``SceneData.kernel_args()``).
    shading : ``(mat_of (P,), mat_tab (M, MAT_COLS), tex_tab (M, TEX_COLS), lights (L, LIGHT_COLS))`` (the
        columns of :mod:`..kernels.columns`): the
        flattened materials, the fused checker table (``raytrace.whitted.fused_textures``) and the
        point / directional lights (``flatten.light_rows``, area lights excluded).
    emitters : :meth:`.emitters.Emitters.arrays`.
    cam : (16,) ``raytrace.whitted.camera_frame``.
    opts : (PATH_OPTS,) float64, the columns of :class:`..kernels.columns.PathOpt`: fresnel (0
        none, 1 Schlick, 2 exact), tol.ray_offset, tol.t_min, tol.zero, extent,
        tol.normal_cancel, rr_start, max_bounces, textures on, MIS exponent, background RGB
        (3), media around the camera (count, then 4 material rows), transport (0 full, 1
        diffuse, 2 eye_specular: see the module docstring), pixel filter (0 box: uniform
        jitter in the pixel, 1 centre: every sample through the pixel's centre), heterogeneous
        media present.
    seed, s0, nsamp : int.
    sums, sumsq : (H*W, 3) float64, updated: sum and sum of squares of the sample radiances.
    counts : (PATH_COUNTS,) int64, updated (see ``PATH_COUNTS``).
    """
    nblocks = (sums.shape[0] + BLOCK - 1) // BLOCK
    nit = max(1, min(nblocks, MAX_TASKS))
    part = np.zeros((nit, 8), np.int64)
    run_tasks(samples_task, nit, geo, shading, emitters, cam, opts, seed, s0, nsamp, sums, sumsq, part,
              per_thread=lambda: (scratch.py_func(), hit_rows()))  # numpy's arrays: no dispatcher to load
    counts += part[:, :PATH_COUNTS].sum(axis=0)


@nb.njit(**TASK)
def samples_task(geo, shading, emitters, cam, opts, seed, s0, nsamp, sums, sumsq, part, scr, rows, c, nit):
    """Task ``c`` of ``nit`` of :func:`render_samples`: pixel blocks ``c, c + nit, ...``, each
    sample's path in turn; its counts go to ``part[c]``.  ``scr``: :func:`scratch`, ``rows``:
    :func:`hit_rows`, the thread's own (made by the caller: this kernel allocates nothing)."""
    width = int(cam[14])
    centre = opts[PathOpt.PIXEL_FILTER] > 0.5
    npix = sums.shape[0]
    nblocks = (npix + BLOCK - 1) // BLOCK
    counts = part[c]
    for blk in range(c, nblocks, nit):
        for p in range(blk * BLOCK, min(npix, (blk + 1) * BLOCK)):
            i, j = p // width, p % width
            for s in range(s0, s0 + nsamp):
                key = path_key(seed, p, s)
                if centre:
                    dx, dy, dz = camera_ray_at(cam, i, j, 0.5, 0.5)
                else:
                    dx, dy, dz = camera_ray_at(cam, i, j, rand(key, JITTER_U), rand(key, JITTER_V))
                r, g, b = trace_path(geo, shading, emitters, opts, key, cam[0], cam[1], cam[2], dx, dy, dz,
                                     counts, scr, rows)
                if not (math.isfinite(r) and math.isfinite(g) and math.isfinite(b)):
                    counts[PathCount.NONFINITE_SAMPLES] += 1
                    r, g, b = 0.0, 0.0, 0.0
                sums[p, 0] += r
                sums[p, 1] += g
                sums[p, 2] += b
                sumsq[p, 0] += r * r
                sumsq[p, 1] += g * g
                sumsq[p, 2] += b * b


@nb.njit(**NO_REFCOUNT)
def cast_all(geo, ox, oy, oz, dx, dy, dz, tmin, tmax, any_hit, zero, eps, scr):
    """:func:`..kernels.intersect.closest` over every primitive (area lights included), compiled
    once here (not inlined: its call sites share one copy)."""
    stack, st, sp_, sf, sn = scr
    t, k, f, tri, b1, b2, _, _, _ = closest(geo, ox, oy, oz, dx, dy, dz, tmin, tmax, np.bool_(False),
                                            np.bool_(any_hit), np.bool_(False), zero, eps, stack, st, sp_, sf, sn)
    return t, k, f, tri, b1, b2


def cast(geo, bvh, tri_prim, ox, oy, oz, dx, dy, dz, tmin, tmax, any_hit, zero, eps, scr):
    """The hit of every ray of a path (camera, extension and shadow rays), as
    :func:`..kernels.intersect.closest` returns it.  For a scene of triangles only (no
    top-level analytic row: the kind marker has ``triangles`` and not ``analytic``, as the
    Cornell box once its polygons and area light are triangles, :mod:`.geometry`): straight to
    :func:`..kernels.walks.bvh_hit`, which is all ``closest`` would do; the call then passes
    the BVH's five arrays instead of the geometry record, and ``closest`` is never compiled."""
    raise TypeError("cast is callable from numba-compiled code only")


@overload(cast, jit_options=INLINE)
def _cast(geo, bvh, tri_prim, ox, oy, oz, dx, dy, dz, tmin, tmax, any_hit, zero, eps, scr):
    kinds = geo.types[-1]  # geo.kinds' type
    if has(kinds, "triangles") and not has(kinds, "analytic"):
        def impl(geo, bvh, tri_prim, ox, oy, oz, dx, dy, dz, tmin, tmax, any_hit, zero, eps, scr):
            t, tri, b1, b2, _, _ = bvh_hit(bvh, ox, oy, oz, dx, dy, dz, tmin, tmax, any_hit, scr[0])
            if tri < 0:
                return np.inf, -1, 0, -1, 0.0, 0.0
            return t, tri_prim[tri], 0, tri, b1, b2
        return impl

    def impl(geo, bvh, tri_prim, ox, oy, oz, dx, dy, dz, tmin, tmax, any_hit, zero, eps, scr):
        return cast_all(geo, ox, oy, oz, dx, dy, dz, tmin, tmax, any_hit, zero, eps, scr)
    return impl


@nb.njit(**NO_REFCOUNT)
def trace_path(geo, shading, emitters, opts, key, ox, oy, oz, dx, dy, dz, counts, scr, rows):
    """Radiance (RGB) carried along one path from ``o`` in direction ``d`` (unit): see the
    module docstring.  Random dimensions: 0, 1 pixel jitter; then 8 per bounce."""
    mat_of, mat_tab, tex_tab, lights = shading
    em_cdf, lpdf_prim, lpdf_tri = emitters[4], emitters[5], emitters[6]
    solid = geo.solid
    tri_e = geo.tri_e
    tri_prim = geo.tri_prim
    bvh = (geo.bvh_node, geo.bvh_child, geo.bvh_leaf, geo.bvh_first, geo.bvh_tv4)
    h_ng, h_ns, h_uv, h_po, h_ev, stk = rows
    fres = int(opts[PathOpt.FRESNEL])
    ray_off, t_min, zero = opts[PathOpt.RAY_OFFSET], opts[PathOpt.T_MIN], opts[PathOpt.ZERO]
    extent, ncancel = opts[PathOpt.EXTENT], opts[PathOpt.NORMAL_CANCEL]
    rr_start, max_bounces = int(opts[PathOpt.RR_START]), int(opts[PathOpt.MAX_BOUNCES])
    use_tex, beta_mis = opts[PathOpt.TEXTURED] > 0.5, opts[PathOpt.MIS_BETA]
    nstk = int(opts[PathOpt.N_MEDIA])
    transport = int(opts[PathOpt.TRANSPORT])
    has_media = opts[PathOpt.HAS_MEDIA] > 0.5
    mdim = np.int64(1 << 40)               # the media's random dimensions (..kernels.media)
    t_acc = 0.0                            # distance since the last vertex, across media boundaries
    for q in range(4):
        stk[q] = int(opts[PathOpt.MEDIA + q])
    n_em = em_cdf.shape[0]
    nl = lights.shape[0]
    br, bg_, bb = 1.0, 1.0, 1.0           # path throughput beta
    Lr, Lg, Lb = 0.0, 0.0, 0.0
    delta_before = True                    # camera or a delta lobe before this hit: no MIS
    eye = True                             # only the camera and delta lobes before this hit
    pdf_prev = 0.0                         # solid-angle density of the BSDF sample that led here
    tmin = 0.0
    counts[PathCount.CAMERA_RAYS] += 1
    for bounce in range(max_bounces):
        dim = 2 + 8 * bounce
        eps = ray_off * max(max(abs(ox), abs(oy), abs(oz)), extent)
        t, k, f, tri, b1, b2 = cast(geo, bvh, tri_prim, ox, oy, oz, dx, dy, dz, tmin, np.inf, np.bool_(False), zero, eps, scr)
        if k < 0:
            counts[PathCount.ESCAPED_PATHS] += 1
            if transport == 0 or eye:  # diffuse transport: the background is seen, it lights nothing
                Lr += br * opts[PathOpt.BACKGROUND]
                Lg += bg_ * opts[PathOpt.BACKGROUND + 1]
                Lb += bb * opts[PathOpt.BACKGROUND + 2]
            return Lr, Lg, Lb
        if nstk > 0:  # the medium the segment crossed: Beer-Lambert, or delta tracking
            ma = stk[nstk - 1]
            med = int(mat_tab[ma, Mat.MEDIUM])
            if med >= 0:
                tc, a0, a1, a2, e0, e1, e2, mdim = track(geo, med, ox, oy, oz, dx, dy, dz, 0.0, t, key, mdim)
                if tc < np.inf:  # a real collision: the absorbed share emits, the rest scatters
                    Lr, Lg, Lb = Lr + br * (1.0 - a0) * e0, Lg + bg_ * (1.0 - a1) * e1, Lb + bb * (1.0 - a2) * e2
                    br, bg_, bb = br * a0, bg_ * a1, bb * a2
                    q_rr = min(0.95, max(br, bg_, bb))
                    if q_rr <= 0.0 or rand(key, dim + 5) >= q_rr:
                        counts[PathCount.ENDED_BY_ROULETTE] += 1
                        return Lr, Lg, Lb
                    br, bg_, bb = br / q_rr, bg_ / q_rr, bb / q_rr
                    ox, oy, oz = ox + tc * dx, oy + tc * dy, oz + tc * dz
                    sr, sg, sb, dx, dy, dz, mdim = vertex_gate(geo, shading, emitters, opts, key, dim, mdim,
                                                                 ox, oy, oz, br, bg_, bb, counts, scr)
                    Lr, Lg, Lb = Lr + sr, Lg + sg, Lb + sb
                    delta_before, pdf_prev, eye, tmin, t_acc = False, 0.25 / math.pi, False, 0.0, 0.0
                    counts[PathCount.EXTENSION_RAYS] += 1
                    continue
            else:
                br *= math.exp(-mat_tab[ma, Mat.ABSORPTION] * t)
                bg_ *= math.exp(-mat_tab[ma, Mat.ABSORPTION + 1] * t)
                bb *= math.exp(-mat_tab[ma, Mat.ABSORPTION + 2] * t)
        px, py, pz = ox + t * dx, oy + t * dy, oz + t * dz
        surface(geo, k, f, tri, b1, b2, px, py, pz, ncancel, h_ng, h_ns, h_uv, h_po, h_ev, 0, scr[0])
        mi = mat_of[k]
        gx, gy, gz = h_ng[0, 0], h_ng[0, 1], h_ng[0, 2]
        cos_g = -(gx * dx + gy * dy + gz * dz)
        front = cos_g > 0.0
        fx, fy, fz = (gx, gy, gz) if front else (-gx, -gy, -gz)   # geometric normal, incident side
        if mat_tab[mi, Mat.MEDIUM] >= 0.0:  # a medium's boundary: on through it, not a vertex
            nstk = enter_or_leave(stk, nstk, mi, front)
            off = ray_off * max(max(abs(px), abs(py), abs(pz)), extent)
            ox, oy, oz = px - off * fx, py - off * fy, pz - off * fz
            tmin, t_acc = t_min * max(max(abs(ox), abs(oy), abs(oz)), extent), t_acc + t
            continue
        nx, ny, nz = h_ns[0, 0], h_ns[0, 1], h_ns[0, 2]
        if nx * dx + ny * dy + nz * dz > 0.0:
            nx, ny, nz = -nx, -ny, -nz                              # shading normal, incident side
        kd, ks, shin = mat_tab[mi, Mat.KD], mat_tab[mi, Mat.KS], mat_tab[mi, Mat.SHININESS]
        kr, kt = mat_tab[mi, Mat.KR], mat_tab[mi, Mat.KT]
        if transport > 0:
            if transport == 2 and eye and (kr > 0.0 or kt > 0.0):
                ks = 0.0                   # eye-path mirror / glass: its delta lobes and kd C
            else:
                ks, kr, kt = 0.0, 0.0, 0.0  # Lambertian kd C, one-sided
                if not front:
                    if not eye:
                        return Lr, Lg, Lb  # a back face is black to the form factors
                    # the eye sees a back face with its front's (view-independent) radiance
                    front = True
                    fx, fy, fz = gx, gy, gz
                    if nx * gx + ny * gy + nz * gz < 0.0:
                        nx, ny, nz = -nx, -ny, -nz
        # ---- emission
        er, eg, eb = 0.0, 0.0, 0.0
        if transport == 0:
            er, eg, eb = h_ev[0, 0], h_ev[0, 1], h_ev[0, 2]
        if front or (transport == 0 and mat_tab[mi, Mat.FRONT_ONLY] < 0.5):
            er += mat_tab[mi, Mat.EMISSION]
            eg += mat_tab[mi, Mat.EMISSION + 1]
            eb += mat_tab[mi, Mat.EMISSION + 2]
        if er > 0.0 or eg > 0.0 or eb > 0.0:
            w = 1.0
            if not delta_before:
                dens = lpdf_tri[tri] if tri >= 0 else lpdf_prim[k]
                if dens > 0.0 and cos_g != 0.0:
                    w = mis_weight(pdf_prev, dens * (t_acc + t) ** 2 / abs(cos_g), beta_mis)
            Lr += br * er * w
            Lg += bg_ * eg * w
            Lb += bb * eb * w
        # ---- lobes
        cr, cg, cb = mat_tab[mi, Mat.COLOR], mat_tab[mi, Mat.COLOR + 1], mat_tab[mi, Mat.COLOR + 2]
        if use_tex and mat_tab[mi, Mat.TEXTURED] > 0.5:
            tr_, tg_, tb_ = checker_color(tex_tab, mi, h_po[0, 0], h_po[0, 1], h_po[0, 2])
            cr, cg, cb = cr * tr_, cg * tg_, cb * tb_
        total = kd * max(cr, cg, cb) + ks + kr + kt
        scale = 1.0 / total if total > 1.0 else 1.0
        adr, adg, adb = kd * cr * scale, kd * cg * scale, kd * cb * scale
        a_s = ks * scale
        a_r, a_t = kr * scale, kt * scale
        m_d = max(adr, adg, adb)
        m_nd = m_d + a_s
        # mirror direction of the incident ray about the shading normal (Phong lobe axis)
        cosi = -(dx * nx + dy * ny + dz * nz)
        rx, ry, rz = dx + 2.0 * cosi * nx, dy + 2.0 * cosi * ny, dz + 2.0 * cosi * nz
        if rx * fx + ry * fy + rz * fz <= 0.0:  # below the surface: about the geometric normal
            cg_ = -(dx * fx + dy * fy + dz * fz)
            rx, ry, rz = dx + 2.0 * cg_ * fx, dy + 2.0 * cg_ * fy, dz + 2.0 * cg_ * fz
        rx, ry, rz = _normalize(rx, ry, rz)
        # refraction geometry and the Fresnel split of kr, kt (as the ray tracer's shade_hit)
        tx, ty, tz = dx, dy, dz
        if a_t > 0.0 and solid[k]:
            cf = -(dx * fx + dy * fy + dz * fz)
            if front:
                n1 = mat_tab[stk[nstk - 1], Mat.IOR] if nstk > 0 else 1.0
                n2 = mat_tab[mi, Mat.IOR]
            else:
                n1 = mat_tab[mi, Mat.IOR]
                jj = nstk - 1
                while jj >= 0 and stk[jj] != mi:
                    jj -= 1
                n2 = 1.0
                if jj >= 0:
                    top_ = -1
                    for q in range(nstk - 1, -1, -1):
                        if q != jj:
                            top_ = stk[q]
                            break
                    n2 = mat_tab[top_, Mat.IOR] if top_ >= 0 else 1.0
                elif nstk > 0:
                    n2 = mat_tab[stk[nstk - 1], Mat.IOR]
            eta = n1 / n2
            kk = 1.0 - eta * eta * (1.0 - cf * cf)
            if kk <= 0.0:  # total internal reflection: the transmitted share is reflected
                a_r, a_t = a_r + a_t, 0.0
            else:
                cost = math.sqrt(kk)
                tx, ty, tz = _normalize(eta * dx + (eta * cf - cost) * fx, eta * dy + (eta * cf - cost) * fy,
                                   eta * dz + (eta * cf - cost) * fz)
                if fres > 0:
                    F = fresnel_reflectance(fres, n1, n2, cf, cost)
                    a_r, a_t = a_r + a_t * F, a_t * (1.0 - F)
        lobes = m_nd + a_r + a_t
        if lobes <= 0.0:
            return Lr, Lg, Lb
        P_nd = m_nd / lobes
        pm = max(abs(px), abs(py), abs(pz))
        off = ray_off * max(pm, extent)
        tmin_here = t_min * max(pm, extent)
        # ---- next-event estimation at a non-delta surface
        if m_nd > 0.0:
            if n_em > 0:
                qx, qy, qz, lx, ly, lz, dist, cos_l, ler, leg, leb, p_l = sample_emitter(
                    emitters, mat_of, mat_tab, tri_e, key, dim, px, py, pz, transport)
                if dist > 0.0:
                    cos_s = nx * lx + ny * ly + nz * lz
                    if ((ler > 0.0 or leg > 0.0 or leb > 0.0) and cos_s > 0.0 and cos_l != 0.0
                            and fx * lx + fy * ly + fz * lz > 0.0):
                        fs, ps = phong_lobe(a_s, shin, rx, ry, rz, lx, ly, lz)
                        p_b = P_nd * (m_d * cos_s * INV_PI + a_s * ps) / m_nd
                        if p_l > 0.0:
                            # the feeler aims from its pushed origin at q itself: along l it would
                            # meet the light's plane up to off / |cos_l| short of q, past its 2 off
                            # margin where |cos_l| < 1/2 (a light seen at a grazing angle shadowed
                            # its own sample)
                            sx_, sy_, sz_, _ = _feeler(px, py, pz, gx, gy, gz, lx, ly, lz, dist, off)
                            wx, wy, wz = qx - sx_, qy - sy_, qz - sz_
                            wd = math.sqrt(wx * wx + wy * wy + wz * wz)
                            vis = 0.0
                            counts[PathCount.SHADOW_RAYS] += 1
                            if wd > 2.0 * off and has_media:
                                vis, mdim = shadow_gate(geo, mat_of, mat_tab, sx_, sy_, sz_, wx / wd, wy / wd,
                                                                 wz / wd, tmin_here, wd - 2.0 * off, zero, off, key,
                                                                 mdim, scr)
                            elif wd > 2.0 * off:
                                _, kb, _, _, _, _ = cast(geo, bvh, tri_prim, sx_, sy_, sz_, wx / wd,
                                                         wy / wd, wz / wd, tmin_here, wd - 2.0 * off,
                                                         np.bool_(True), zero, off, scr)
                                vis = 1.0 if kb < 0 else 0.0
                            if vis > 0.0:
                                wl = vis * mis_weight(p_l, p_b, beta_mis) * cos_s / p_l
                                Lr += br * (adr * INV_PI + fs) * ler * wl
                                Lg += bg_ * (adg * INV_PI + fs) * leg * wl
                                Lb += bb * (adb * INV_PI + fs) * leb * wl
            for li in range(nl):
                lx, ly, lz, dist, sc = _light_dir(lights, li, px, py, pz)
                cos_s = nx * lx + ny * ly + nz * lz
                if cos_s <= 0.0 or sc == 0.0 or fx * lx + fy * ly + fz * lz <= 0.0:
                    continue
                sx_, sy_, sz_, tmx = _feeler(px, py, pz, gx, gy, gz, lx, ly, lz, dist, off)
                counts[PathCount.SHADOW_RAYS] += 1
                if has_media:
                    vis, mdim = shadow_gate(geo, mat_of, mat_tab, sx_, sy_, sz_, lx, ly, lz, tmin_here, tmx,
                                                     zero, off, key, mdim, scr)
                else:
                    _, kb, _, _, _, _ = cast(geo, bvh, tri_prim, sx_, sy_, sz_, lx, ly, lz, tmin_here, tmx, np.bool_(True), zero, off, scr)
                    vis = 1.0 if kb < 0 else 0.0
                if vis <= 0.0:
                    continue
                fs, _ = phong_lobe(a_s, shin, rx, ry, rz, lx, ly, lz)
                e_ = math.pi * sc * cos_s * vis  # irradiance per unit light value
                Lr += br * (adr * INV_PI + fs) * lights[li, Light.POWER] * e_
                Lg += bg_ * (adg * INV_PI + fs) * lights[li, Light.POWER + 1] * e_
                Lb += bb * (adb * INV_PI + fs) * lights[li, Light.POWER + 2] * e_
        # ---- Russian roulette
        if bounce + 1 >= rr_start:
            q_rr = min(0.95, max(br, bg_, bb))
            if rand(key, dim + 3) >= q_rr:
                counts[PathCount.ENDED_BY_ROULETTE] += 1
                return Lr, Lg, Lb
            br, bg_, bb = br / q_rr, bg_ / q_rr, bb / q_rr
        # ---- next direction
        u = rand(key, dim + 4) * lobes
        if u < m_nd:
            if rand(key, dim + 5) * m_nd < m_d:   # cosine-weighted hemisphere about n
                ct = math.sqrt(rand(key, dim + 6))
                wx, wy, wz = _around(nx, ny, nz, ct, 2.0 * math.pi * rand(key, dim + 7))
            else:                                  # cos^n alpha about the mirror direction
                ct = rand(key, dim + 6) ** (1.0 / (shin + 1.0))
                wx, wy, wz = _around(rx, ry, rz, ct, 2.0 * math.pi * rand(key, dim + 7))
            cos_s = nx * wx + ny * wy + nz * wz
            if cos_s <= 0.0 or fx * wx + fy * wy + fz * wz <= 0.0:
                return Lr, Lg, Lb
            fs, ps = phong_lobe(a_s, shin, rx, ry, rz, wx, wy, wz)
            pdf = P_nd * (m_d * cos_s * INV_PI + a_s * ps) / m_nd
            if not pdf > 0.0:
                return Lr, Lg, Lb
            br *= (adr * INV_PI + fs) * cos_s / pdf
            bg_ *= (adg * INV_PI + fs) * cos_s / pdf
            bb *= (adb * INV_PI + fs) * cos_s / pdf
            delta_before, pdf_prev, eye = False, pdf, False
            ox, oy, oz = px + off * fx, py + off * fy, pz + off * fz
            dx, dy, dz = wx, wy, wz
        elif u < m_nd + a_r:                        # mirror: R = I - 2 (I.N) N
            gain = lobes
            br, bg_, bb = br * gain, bg_ * gain, bb * gain
            delta_before = True
            ox, oy, oz = px + off * fx, py + off * fy, pz + off * fz
            dx, dy, dz = rx, ry, rz
        else:                                       # transmission
            gain = lobes
            br, bg_, bb = br * gain, bg_ * gain, bb * gain
            delta_before = True
            ox, oy, oz = px - off * fx, py - off * fy, pz - off * fz
            dx, dy, dz = tx, ty, tz
            if solid[k]:  # into the solid through its front, out of it through its back
                nstk = enter_or_leave(stk, nstk, mi, front)
        tmin, t_acc = tmin_here, 0.0
        counts[PathCount.EXTENSION_RAYS] += 1
    counts[PathCount.ENDED_BY_BOUNCE_CAP] += 1
    return Lr, Lg, Lb
