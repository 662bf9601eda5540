"""Numba drivers of the Whitted ray tracer: the shading and spawning step of a hit
(:func:`shade_hit`), the driver (:func:`render_pixels`: each pixel's whole ray tree depth
first) and the batch intersector of ``workbench.raytrace.intersect`` (:func:`trace_batch`).
Intersection is :mod:`..kernels.intersect`'s, the surface optics
:mod:`..kernels.optics`'s.

Everything is scalar code over flat arrays (:mod:`.flatten`; the geometry as the named record
:class:`..kernels.layout.Geometry`, tables with named columns, :mod:`..kernels.columns`).  The
driver runs blocks of pixels, and the batch intersector (:func:`trace_batch`) runs of chunks of
rays, as ``nogil`` tasks on ``numba.get_num_threads()`` threads (:mod:`..kernels.tasks`); each
thread has its own scratch arrays (BVH stack, CSG interval stacks, ray stack) and hands its work to
functions compiled without reference counting (:data:`..kernels.flags.NO_REFCOUNT`).  Helpers
take :data:`..kernels.flags.INLINE`: each is compiled once (and cached) and LLVM inlines it
into its callers (``docs/kernels.md``).  The kernels are compiled per set of kinds
present (:mod:`..kernels.specialise`).  ``error_model="numpy"``: float divisions follow IEEE
(no zero-divisor check and exception path on every division; the results are the same
wherever the default Python model would not raise).  ``cache=True``: compiled code is kept on
disk (``NUMBA_CACHE_DIR``), so a warm cache compiles nothing.

The readable version of the same algorithm is :mod:`.reference`; the two are tested against
each other.  Equations: see the docstrings of the reference's functions.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numba as nb
import numpy as np

from ..kernels.columns import RAY_COUNTS, Light, Mat, RayCount, Tex, WhittedOpt
from ..kernels.flags import INLINE, TASK
from ..kernels.intersect import closest, geometric_normal, object_point, scratch, surface
from ..kernels.optics import (_facing, _feeler, _ior, _light_dir, _pow, camera_ray, enter_or_leave,
                              fresnel_reflectance)
from ..kernels.shapes import _normalize
from ..kernels.tasks import run_tasks
from ..kernels.media import march
from ..kernels.textures import Textures, hit_alpha, miss_radiance, surface_maps
from .feelers import _transmittance
from .flatten import MAX_CUTOUTS
from .opacity import _past, opacity_feelers, pass_cutouts

CHUNK = 64
"""Rays of a chunk of :func:`trace_batch`."""


# ----------------------------------------------------------------------------- batch kernels
MAX_TASKS = 64
"""Tasks of a kernel call: each takes its share of the chunks of rays or blocks of pixels and
allocates its scratch arrays once (an allocation per chunk cost more than the chunk's rays).
Enough for a fair split between threads; a constant, because a kernel that asks numba for its
thread count cannot be cached."""


@nb.njit(**INLINE)
def _tasks(nchunks):
    return max(1, min(nchunks, MAX_TASKS))


def trace_batch(geo, O, D, tmin, tmax, zero, rel_eps, extent, ncancel, shadow_only,
                t_out, prim_out, ng, ns, uv, po, ev):
    """Closest hits of N rays and their surface data (``prim_out = -1``, ``t = inf`` on a miss);
    with ``shadow_only``, of the primitives that cast shadows (shadow feelers).  With ``ns`` of
    no rows (``uv``, ``po``, ``ev`` likewise: :func:`.whitted._alloc` without ``surface``),
    of the surface data only the geometric normal (``workbench.raytrace.intersect``).

    Runs of consecutive chunks of rays (:func:`trace_task`) handed out by
    :func:`..kernels.tasks.run_tasks` as :func:`render_pixels`'s: rays in image order meet the same
    nodes and triangles (every 64th chunk to a task cost the mesh's camera rays 45 % more CPU time),
    and a waiting thread sleeps (``prange``'s OpenMP workers spin: 7 % more CPU time; measured)."""
    nit = _tasks.py_func((O.shape[0] + CHUNK - 1) // CHUNK)
    run_tasks(trace_task, nit, geo, (O, D, tmin, tmax), (t_out, prim_out, ng, ns, uv, po, ev), zero, rel_eps,
              extent, ncancel, bool(shadow_only), per_thread=lambda: (scratch.py_func(),))


@nb.njit(**TASK)
def trace_task(geo, rays, hits, zero, rel_eps, extent, ncancel, shadow_only, scr, c, nit):
    """Task ``c`` of ``nit`` of :func:`trace_batch`: chunks ``c nchunks / nit`` to ``(c + 1)
    nchunks / nit - 1`` of the rays ``rays = (O, D, tmin, tmax)``, their hits to ``hits =
    (t_out, prim_out, ng, ns, uv, po, ev)``; ``scr``: :func:`scratch`, the thread's own."""
    O, D, tmin, tmax = rays
    t_out, prim_out, ng, ns, uv, po, ev = hits
    stack, st, sp_, sf, sn = scr
    n = O.shape[0]
    nchunks = (n + CHUNK - 1) // CHUNK
    for i in range(c * nchunks // nit * CHUNK, min(n, (c + 1) * nchunks // nit * CHUNK)):
        ox, oy, oz = O[i, 0], O[i, 1], O[i, 2]
        eps = rel_eps * max(max(abs(ox), abs(oy), abs(oz)), extent)
        t, k, f, tri, b1, b2, gx, gy, gz = closest(geo, ox, oy, oz, D[i, 0], D[i, 1], D[i, 2], tmin[i],
                                                   tmax[i], np.bool_(shadow_only), np.bool_(False), np.bool_(False),
                                                   zero, eps, stack, st, sp_, sf, sn)
        t_out[i], prim_out[i] = t, k
        if k < 0:
            continue
        px, py, pz = ox + t * D[i, 0], oy + t * D[i, 1], oz + t * D[i, 2]
        if ns.shape[0] == 0 and tri >= 0:  # the geometric normal alone, a triangle's from its packed group
            ng[i, 0], ng[i, 1], ng[i, 2] = gx, gy, gz
        elif ns.shape[0] == 0:
            x, y, z = object_point(geo, k, px, py, pz)
            ng[i, 0], ng[i, 1], ng[i, 2] = geometric_normal(geo, k, f, tri, x, y, z, stack)
        else:
            surface(geo, k, f, tri, b1, b2, px, py, pz, ncancel, ng, ns, uv, po, ev, i, stack)


@nb.njit(**INLINE)
def _cross(mi, front, px, py, pz, fx, fy, fz, dx, dy, dz, w0, w1, w2, gen, stk, nstk, i, off, t_min, extent,
           out, s):
    """A ray crossing the boundary of medium material ``mi``: its continuation in slot ``s`` of
    ``out`` (as a refracted child, without counting it), same direction and generation, the
    medium pushed on its stack when entering (if the stack has room), removed when leaving."""
    out_o, out_d, out_w, out_stk, out_nstk, out_kind, out_tmin, out_gen = out
    out_o[s, 0], out_o[s, 1], out_o[s, 2] = px - off * fx, py - off * fy, pz - off * fz
    out_d[s, 0], out_d[s, 1], out_d[s, 2] = dx, dy, dz
    out_w[s, 0], out_w[s, 1], out_w[s, 2] = w0, w1, w2
    for q in range(4):
        out_stk[s, q] = stk[i, q]
    out_nstk[s] = enter_or_leave(out_stk[s], nstk[i], mi, front)
    out_kind[s] = 2
    out_tmin[s] = t_min * max(max(abs(out_o[s, 0]), abs(out_o[s, 1]), abs(out_o[s, 2])), extent)
    out_gen[s] = gen


@nb.njit(**INLINE)
def shade_hit(geo, mat_of, mat_tab, lights, ambient, background, opts, rays, i, hits, contrib,
              out, s0, counts, scr):
    """Local model with shadow feelers at the hit of ray ``i``, then its reflected and refracted
    children (one step of the course's ``shade``).  Inlined into both drivers (a call with this
    many arrays cost more than the shading of a ray); the arrays come in tuples because Python
    passes a call of more than 30 arguments as ``*args``, which numba cannot inline.

    The ray is row ``i`` of ``rays = (O, D, w, depth, stk, nstk)`` and its hit row ``i`` of
    ``hits = (t, prim, ng, nsh, col, ev, vis)`` (``vis``: the lights' visibility through the
    shadow feelers, traced by the caller, or an empty table: traced here by
    :func:`_transmittance`); ``out = (out_o, out_d, out_w, out_stk, out_nstk,
    out_kind, out_tmin, out_gen)``; ``scr``: :func:`scratch`.  The local colour times the ray's weight goes to ``contrib[i]``, the
    children to slots ``s0`` (reflection) and ``s0 + 1`` (refraction) of the ``out_*`` arrays
    (``out_kind`` 0 = none, 1 reflected, 2 refracted), the counts added to ``counts[i]``:
    shadow rays, ended by depth, ended by threshold, total internal reflections, reflected and
    refracted children, escaped (missed everything).  (Added, not set: the driver sums a
    task's rays in that row, with no zeroing and summing of every ray's counts: 14 loads and
    stores a ray.)

    ``opts``: columns :class:`..kernels.columns.WhittedOpt` (a miss adds ``background`` if
    ``WhittedOpt.BACKGROUND``, else nothing here: an environment map is evaluated by the
    caller; the media around the camera are read by :func:`pixels_task`).
    """
    O, D, w, depth, stk, nstk = rays
    t, prim, ng, nsh, col, ev, vis_in = hits
    out_o, out_d, out_w, out_stk, out_nstk, out_kind, out_tmin, out_gen = out
    stack, st, sp_, sf, sn = scr
    max_depth, threshold = int(opts[WhittedOpt.GENERATIONS]), opts[WhittedOpt.THRESHOLD]
    fres = int(opts[WhittedOpt.FRESNEL])
    transmissive, blinn = opts[WhittedOpt.TRANSMISSIVE_SHADOWS] > 0.5, opts[WhittedOpt.BLINN] > 0.5
    do_shadow = opts[WhittedOpt.SHADOWS] > 0.5
    do_refl, do_refr = opts[WhittedOpt.REFLECTION] > 0.5, opts[WhittedOpt.REFRACTION] > 0.5
    ray_off, t_min = opts[WhittedOpt.RAY_OFFSET], opts[WhittedOpt.T_MIN]
    zero, extent = opts[WhittedOpt.ZERO], opts[WhittedOpt.EXTENT]
    add_bg = opts[WhittedOpt.BACKGROUND] > 0.5
    media = opts[WhittedOpt.STEP_SCALE]
    nl = lights.shape[0]
    solid = geo.solid
    out_kind[s0], out_kind[s0 + 1] = 0, 0
    k = prim[i]
    if k < 0:
        counts[i, RayCount.ESCAPED_RAYS] += 1
        for q in range(3):
            contrib[i, q] = w[i, q] * background[q] if add_bg else 0.0
        return
    mi = mat_of[k]
    dx, dy, dz = D[i, 0], D[i, 1], D[i, 2]
    px, py, pz = O[i, 0] + t[i] * dx, O[i, 1] + t[i] * dy, O[i, 2] + t[i] * dz
    # the medium the ray travelled through: Beer-Lambert absorption, or a heterogeneous
    # medium's emission-absorption march (..kernels.media)
    w0, w1, w2 = w[i, 0], w[i, 1], w[i, 2]
    mr, mg, mb = 0.0, 0.0, 0.0
    if nstk[i] > 0:
        ma = stk[i, nstk[i] - 1]
        med = int(mat_tab[ma, Mat.MEDIUM])
        if med >= 0:
            tr, mr, mg, mb = march(geo, med, O[i, 0], O[i, 1], O[i, 2], dx, dy, dz, 0.0, t[i],
                                   ambient[0], ambient[1], ambient[2], media, True, (lights, mat_of, mat_tab), scr)
            mr, mg, mb = w0 * mr, w1 * mg, w2 * mb
            w0, w1, w2 = w0 * tr, w1 * tr, w2 * tr
        else:
            w0 *= math.exp(-mat_tab[ma, Mat.ABSORPTION] * t[i])
            w1 *= math.exp(-mat_tab[ma, Mat.ABSORPTION + 1] * t[i])
            w2 *= math.exp(-mat_tab[ma, Mat.ABSORPTION + 2] * t[i])
    sx, sy, sz = -dx, -dy, -dz
    gx, gy, gz = ng[i, 0], ng[i, 1], ng[i, 2]
    nx, ny, nz = _facing(nsh, i, dx, dy, dz)
    front = gx * sx + gy * sy + gz * sz > 0.0
    # side of the surface the ray came from
    fx, fy, fz = (gx, gy, gz) if front else (-gx, -gy, -gz)
    if mat_tab[mi, Mat.MEDIUM] >= 0.0:  # a medium's boundary: straight on, same generation
        contrib[i, 0], contrib[i, 1], contrib[i, 2] = mr, mg, mb
        if max(w0, w1, w2) > threshold:
            _cross(mi, front, px, py, pz, fx, fy, fz, dx, dy, dz, w0, w1, w2, depth[i], stk, nstk, i,
                   ray_off * max(max(abs(px), abs(py), abs(pz)), extent), t_min, extent, out, s0 + 1)
        return
    if mat_tab[mi, Mat.TEXTURED] > 0.5:  # textured: the caller's colour
        cr, cg, cb = col[i, 0], col[i, 1], col[i, 2]
    else:
        cr, cg, cb = mat_tab[mi, Mat.COLOR], mat_tab[mi, Mat.COLOR + 1], mat_tab[mi, Mat.COLOR + 2]
    ka, kd, ks, shin = mat_tab[mi, Mat.KA], mat_tab[mi, Mat.KD], mat_tab[mi, Mat.KS], mat_tab[mi, Mat.SHININESS]
    # vertex emission (radiosity patches of the hybrid method) leaves the front side only: the
    # back of a one-sided patch received no light (Mesh.vertex_emission)
    er, eg, eb = (ev[i, 0], ev[i, 1], ev[i, 2]) if front else (0.0, 0.0, 0.0)
    if mat_tab[mi, Mat.FRONT_ONLY] < 0.5 or front:
        er += mat_tab[mi, Mat.EMISSION]
        eg += mat_tab[mi, Mat.EMISSION + 1]
        eb += mat_tab[mi, Mat.EMISSION + 2]
    lr = ka * cr * ambient[0] + er
    lg = ka * cg * ambient[1] + eg
    lb = ka * cb * ambient[2] + eb
    pm = max(abs(px), abs(py), abs(pz))
    off = ray_off * max(pm, extent)
    eps = off
    nshadow = 0
    for li in range(nl):
        lx, ly, lz, dist, scale = _light_dir(lights, li, px, py, pz)
        ndl = nx * lx + ny * ly + nz * lz
        if ndl <= 0.0 or scale == 0.0:
            continue
        vis = 1.0
        if do_shadow:
            nshadow += 1
            if vis_in.shape[0] > 0:  # traced by the caller (opacity maps)
                vis = vis_in[i, li]
            else:
                qx, qy, qz, tmx = _feeler(px, py, pz, gx, gy, gz, lx, ly, lz, dist, off)
                vis = _transmittance(geo, mat_of, mat_tab, qx, qy, qz, lx, ly, lz,
                                     t_min * max(pm, extent), tmx, transmissive, zero, eps,
                                     media, stack, st, sp_, sf, sn)
            if vis <= 0.0:
                continue
        spec = 0.0
        if ks > 0.0:
            if blinn:
                hx, hy, hz = _normalize(lx + sx, ly + sy, lz + sz)
                base = nx * hx + ny * hy + nz * hz
            else:
                rx, ry, rz = 2.0 * ndl * nx - lx, 2.0 * ndl * ny - ly, 2.0 * ndl * nz - lz
                base = rx * sx + ry * sy + rz * sz
            base = min(1.0, max(0.0, base))
            spec = ks * _pow(base, shin)
        f = vis * scale
        lr += lights[li, Light.POWER] * f * (kd * cr * ndl + spec)
        lg += lights[li, Light.POWER + 1] * f * (kd * cg * ndl + spec)
        lb += lights[li, Light.POWER + 2] * f * (kd * cb * ndl + spec)
    contrib[i, 0], contrib[i, 1], contrib[i, 2] = w0 * lr + mr, w1 * lg + mg, w2 * lb + mb
    counts[i, RayCount.SHADOW_RAYS] += nshadow
    # ---- reflection / transmission weights (Whitted 1980; Fresnel optional)
    kr, kt = mat_tab[mi, Mat.KR], mat_tab[mi, Mat.KT]
    if not do_refl:
        kr = 0.0
    if not do_refr:
        kt = 0.0
    if kr <= 0.0 and kt <= 0.0:
        return
    cosi = -(dx * fx + dy * fy + dz * fz)  # >= 0
    ns_ = nstk[i]
    is_solid = solid[k]
    wr, wt = kr, kt
    tx, ty, tz = dx, dy, dz
    new_n = ns_
    if kt > 0.0 and is_solid:
        # media on both sides (nested dielectrics: a small stack of materials)
        if front:
            n1 = _ior(mat_tab, stk[i], ns_)
            n2 = mat_tab[mi, Mat.IOR]
        else:
            n1 = mat_tab[mi, Mat.IOR]
            # the medium beyond: the stack without its topmost entry of this material
            j = ns_ - 1
            while j >= 0 and stk[i, j] != mi:
                j -= 1
            n2 = 1.0
            if j >= 0:
                new_n = ns_ - 1
                top_ = -1
                for q in range(ns_ - 1, -1, -1):
                    if q != j:
                        top_ = stk[i, q]
                        break
                n2 = mat_tab[top_, Mat.IOR] if top_ >= 0 else 1.0
            elif ns_ > 0:
                n2 = _ior(mat_tab, stk[i], ns_)
        eta = n1 / n2
        kk = 1.0 - eta * eta * (1.0 - cosi * cosi)
        if kk <= 0.0:  # total internal reflection (or exactly critical): all to reflection
            wr, wt = kr + kt, 0.0
            counts[i, RayCount.TOTAL_INTERNAL_REFLECTIONS] += 1
        else:
            cost = math.sqrt(kk)
            tx, ty, tz = _normalize(eta * dx + (eta * cosi - cost) * fx,
                                    eta * dy + (eta * cosi - cost) * fy,
                                    eta * dz + (eta * cosi - cost) * fz)
            if fres > 0:
                F = fresnel_reflectance(fres, n1, n2, cosi, cost)
                wr, wt = kr + kt * F, kt * (1.0 - F)
    for branch in range(2):
        kb = wr if branch == 0 else wt
        if kb <= 0.0:
            continue
        if depth[i] + 1 >= max_depth:
            counts[i, RayCount.ENDED_BY_DEPTH] += 1
            continue
        b0, b1_, b2_ = w0 * kb, w1 * kb, w2 * kb
        if max(b0, b1_, b2_) <= threshold:
            counts[i, RayCount.ENDED_BY_THRESHOLD] += 1
            continue
        s = s0 + branch
        if branch == 0:
            # R = I - 2 (I.N) N with the shading normal on the incident side
            mx, my, mz = nx, ny, nz
            dn = dx * mx + dy * my + dz * mz
            rx, ry, rz = dx - 2.0 * dn * mx, dy - 2.0 * dn * my, dz - 2.0 * dn * mz
            if rx * fx + ry * fy + rz * fz <= 0.0:  # below the surface: use Ng
                dn = dx * fx + dy * fy + dz * fz
                rx, ry, rz = dx - 2.0 * dn * fx, dy - 2.0 * dn * fy, dz - 2.0 * dn * fz
            rx, ry, rz = _normalize(rx, ry, rz)
            out_o[s, 0], out_o[s, 1], out_o[s, 2] = px + off * fx, py + off * fy, pz + off * fz
            out_d[s, 0], out_d[s, 1], out_d[s, 2] = rx, ry, rz
            for q in range(4):
                out_stk[s, q] = stk[i, q]
            out_nstk[s] = ns_
            out_kind[s] = 1
            counts[i, RayCount.REFLECTED_RAYS] += 1
        else:
            out_o[s, 0], out_o[s, 1], out_o[s, 2] = px - off * fx, py - off * fy, pz - off * fz
            out_d[s, 0], out_d[s, 1], out_d[s, 2] = tx, ty, tz
            for q in range(4):
                out_stk[s, q] = stk[i, q]
            out_nstk[s] = ns_
            if is_solid:
                if front:
                    if ns_ < 4:
                        out_stk[s, ns_] = mi
                        out_nstk[s] = ns_ + 1
                elif new_n < ns_:
                    # remove the topmost entry of this material
                    j = ns_ - 1
                    while stk[i, j] != mi:
                        j -= 1
                    q2 = 0
                    for q in range(ns_):
                        if q != j:
                            out_stk[s, q2] = stk[i, q]
                            q2 += 1
                    out_nstk[s] = ns_ - 1
            out_kind[s] = 2
            counts[i, RayCount.REFRACTED_RAYS] += 1
        out_w[s, 0], out_w[s, 1], out_w[s, 2] = b0, b1_, b2_
        out_tmin[s] = t_min * max(max(abs(out_o[s, 0]), abs(out_o[s, 1]), abs(out_o[s, 2])), extent)
        out_gen[s] = depth[i] + 1


# ----------------------------------------------------------------------------- fused path
PIXEL_BLOCK = 64


class Shading(NamedTuple):
    """What the fused driver shades with besides the geometry (``P`` primitive rows, ``M``
    materials, ``L`` lights)."""

    mat_of: np.ndarray      # (P,) int64 material row of each primitive row
    mat_tab: np.ndarray     # (M, MAT_COLS) material table (columns ``kernels.columns.Mat``)
    maps: Textures          # texture maps and environment (``kernels.textures.Textures``)
    lights: np.ndarray      # (L, LIGHT_COLS) point and directional lights (``kernels.columns.Light``)
    ambient: np.ndarray     # (3,) ambient light
    background: np.ndarray  # (3,) colour of a ray that leaves the scene (no environment)
    opts: np.ndarray        # option vector (``kernels.columns.WhittedOpt``)


class Pixels(NamedTuple):
    """The fused driver's primary rays and outputs for ``n`` pixels of ``spp`` samples."""

    O: np.ndarray           # (n spp, 3) primary ray origins, or (0, 3): the camera's centre rays
    D: np.ndarray           # (n spp, 3) their directions
    fwd: np.ndarray         # (3,) unit view axis (depth along it)
    cam: np.ndarray         # (16,) camera frame (``whitted.camera_frame``)
    image: np.ndarray       # (n, 3) float32 out: mean colour of each pixel's samples
    depth_map: np.ndarray   # (n,) float32 out: camera-space depth of the first sample's primary hit


def stack_rows(generations: int, opacity: bool) -> int:
    """Pending rays a task's stack may hold: a ray popped pushes at most two children, and with
    opacity maps also its straight continuation (at most :data:`.flatten.MAX_CUTOUTS` along a
    path), so a path of ``g`` rays leaves at most ``2 g`` pending."""
    return 2 * (generations + (MAX_CUTOUTS if opacity else 0)) + 4


def render_pixels(geo, shading, pixels, spp, first, ncancel, counts):
    """Whole ray trees of every pixel (the fused path): each pixel's ``spp`` primary rays
    (``pixels.O, pixels.D`` rows ``p spp ... p spp + spp - 1``; with ``O`` empty and
    ``spp = 1``, the centre ray of image pixel ``first + p`` of the camera ``pixels.cam``, see
    ``whitted.camera_frame``) and their reflected, refracted and (through opacity maps)
    straight-on descendants are traced depth first (:func:`pixels_task`), so no array crosses
    back to Python between ray generations.  ``geo``: :class:`..kernels.layout.Geometry`;
    ``shading``: :class:`Shading`; ``pixels``: :class:`Pixels`.

    Writes ``image[p]`` (mean over the samples), ``depth_map[p]`` (camera-space depth of the
    first sample's primary hit, ``fwd`` the unit view axis, ``inf`` on a miss) and adds the
    ray counts of :func:`shade_hit` to ``counts`` (``RAY_COUNTS``,).  The pixels, in blocks of
    ``PIXEL_BLOCK``, are cut into ``MAX_TASKS`` runs of consecutive blocks (:func:`pixels_task`),
    which :func:`..kernels.tasks.run_tasks` hands out in turn to whichever thread is free: the
    expensive parts of the image are shared out as the threads finish their runs, and each run
    covers a compact part of the image, whose rays meet the same nodes and triangles (a mesh's
    tree does not fit in the cache: blocks dealt in a scrambled order, each far from the
    last, cost the 81,920-triangle mesh's trace about 20 % more CPU time, measured).
    """
    nblocks = (pixels.image.shape[0] + PIXEL_BLOCK - 1) // PIXEL_BLOCK
    nit = max(1, min(nblocks, MAX_TASKS))
    part = np.zeros((nit, 8), np.int64)  # a row per task (8: rows a cache line apart)
    opacity = bool(shading.maps.opacity[:, Tex.KIND].any())
    cap = stack_rows(int(shading.opts[WhittedOpt.GENERATIONS]), opacity)
    lights = shading.lights.shape[0] if opacity and shading.opts[WhittedOpt.SHADOWS] > 0.5 else 0
    # each thread's arrays made by numpy here (``scratch.py_func``: the kernel's own Python code):
    # no dispatcher of theirs to load from numba's cache at start-up
    run_tasks(pixels_task, nit, geo, shading, pixels, spp, first, ncancel, part,
              per_thread=lambda: (scratch.py_func(), ray_stack(cap, lights)))
    counts += part[:, :RAY_COUNTS].sum(axis=0)


def ray_stack(cap, lights=0):
    """Work arrays of :func:`pixels_task`: ``cap`` pending rays (origin, direction, weight,
    media stack and its size, kind, tmin, generation, continuations on the path), then the
    current ray and its hit (one row each: origin, direction, weight, media stack and size,
    generation, t, primitive, normals, uv, object-space point, emission, colour, contribution,
    the task's ray counts (summed here, written to ``part`` once: the threads' count rows share
    cache lines)), the lights' visibility through opacity maps (``(1, lights)``, or no row:
    :func:`shade_hit` traces the shadow feelers itself), the radiance of a miss, and a feeler
    hit's object-space point and uv, and the directions of a block's camera rays."""
    return (np.empty((cap, 3)), np.empty((cap, 3)), np.empty((cap, 3)), np.zeros((cap, 4), np.int64),
            np.zeros(cap, np.int64), np.zeros(cap, np.int64), np.empty(cap), np.zeros(cap, np.int64),
            np.empty((1, 3)), np.empty((1, 3)), np.empty((1, 3)), np.zeros((1, 4), np.int64),
            np.zeros(1, np.int64), np.zeros(1, np.int64), np.empty(1), np.empty(1, np.int64),
            np.empty((1, 3)), np.empty((1, 3)), np.empty((1, 2)), np.empty((1, 3)), np.empty((1, 3)),
            np.zeros((1, 3)), np.empty((1, 3)), np.zeros((1, RAY_COUNTS), np.int64),
            np.ones((1 if lights else 0, max(lights, 1))), np.zeros(cap, np.int64), np.empty(3),
            np.empty((1, 3)), np.zeros((1, 2)), np.empty((PIXEL_BLOCK, 3)))


@nb.njit(**TASK)
def pixels_task(geo, shading, pixels, spp, first, ncancel, part, scr, bufs, c, nit):
    """Task ``c`` of ``nit`` of :func:`render_pixels`: pixel blocks ``c nblocks / nit`` to
    ``(c + 1) nblocks / nit - 1`` in order, each primary ray and its descendants depth
    first with an explicit stack of pending rays (the course's ``raytrace`` recursion), shaded
    by :func:`shade_hit`; colours, bumped normals, opacity and the environment from the maps
    (:mod:`..kernels.textures`).  A surface of opacity ``alpha`` (an opacity map) is shaded
    with the ray's weight times ``alpha`` and lets the ray go on straight through with the
    rest (``reference.raytrace``); one cut out (alpha below 0.5) is passed through.  Adds the
    ray counts to ``part[c]`` (``RAY_COUNTS``,).  ``scr``: :func:`scratch`; ``bufs``:
    :func:`ray_stack`, the thread's own (made by the caller: this kernel allocates nothing, so
    it is compiled without reference counting)."""
    mat_of, mat_tab, maps, lights, ambient, background, opts = shading
    O, D, fwd, cam, image, depth_map = pixels
    zero, rel_eps, extent = opts[WhittedOpt.ZERO], opts[WhittedOpt.RAY_OFFSET], opts[WhittedOpt.EXTENT]
    stack, st, sp_, sf, sn = scr
    (r_o, r_d, r_w, r_stk, r_n, r_kind, r_tmin, r_gen, c_o, c_d, c_w, c_stk, c_n, c_gen, h_t, h_p,
     h_ng, h_ns, h_uv, h_po, h_ev, h_col, contrib, cnt, h_vis, r_hop, h_bg, f_po, f_uv, b_d) = bufs
    row = 0  # the current ray's row
    cur = (c_o, c_d, c_w, c_gen, c_stk, c_n)
    hits = (h_t, h_p, h_ng, h_ns, h_col, h_ev, h_vis)
    surf = (h_ng, h_ns, h_uv, h_po, h_ev)
    pending = (r_o, r_d, r_w, r_stk, r_n, r_kind, r_tmin, r_gen)
    npix = image.shape[0]
    nblocks = (npix + PIXEL_BLOCK - 1) // PIXEL_BLOCK
    counts = part[c]
    width = max(1, int(cam[14]))
    for b in range(c * nblocks // nit, (c + 1) * nblocks // nit):
        if O.shape[0] == 0:
            # the block's camera rays made together, before its trees: their square roots and
            # divisions overlap, where each one headed the dependent chain of its pixel's tree.
            # Image row and column of the block's first pixel, then stepped: no division a pixel
            row_i, col_j = (first + b * PIXEL_BLOCK) // width, (first + b * PIXEL_BLOCK) % width
            for p in range(b * PIXEL_BLOCK, min(npix, (b + 1) * PIXEL_BLOCK)):
                camera_ray(cam, row_i, col_j, b_d, p - b * PIXEL_BLOCK)
                col_j += 1
                if col_j == width:
                    row_i, col_j = row_i + 1, 0
        for p in range(b * PIXEL_BLOCK, min(npix, (b + 1) * PIXEL_BLOCK)):
            ar, ag, ab = 0.0, 0.0, 0.0
            for s in range(spp):
                i = p * spp + s
                if O.shape[0] > 0:
                    for q in range(3):
                        r_o[0, q], r_d[0, q] = O[i, q], D[i, q]
                else:
                    for q in range(3):
                        r_o[0, q], r_d[0, q] = cam[q], b_d[p - b * PIXEL_BLOCK, q]
                for q in range(3):
                    r_w[0, q] = 1.0
                r_n[0], r_tmin[0], r_gen[0], r_hop[0] = int(opts[WhittedOpt.N_MEDIA]), 0.0, 0, 0  # the media around the camera
                for q in range(4):
                    r_stk[0, q] = int(opts[WhittedOpt.MEDIA + q])
                top = 1
                primary = True
                while top > 0:
                    top -= 1
                    for q in range(3):
                        c_o[0, q], c_d[0, q], c_w[0, q] = r_o[top, q], r_d[top, q], r_w[top, q]
                    for q in range(4):
                        c_stk[0, q] = r_stk[top, q]
                    c_n[0], c_gen[0] = r_n[top], r_gen[top]
                    hop = r_hop[top]
                    ox, oy, oz = c_o[0, 0], c_o[0, 1], c_o[0, 2]
                    dx, dy, dz = c_d[0, 0], c_d[0, 1], c_d[0, 2]
                    eps = rel_eps * max(max(abs(ox), abs(oy), abs(oz)), extent)
                    t, k, f, tri, b1, b2, _, _, _ = closest(geo, ox, oy, oz, dx, dy, dz, r_tmin[top], np.inf,
                                                   np.bool_(False), np.bool_(False), np.bool_(True), zero, eps,
                                                   stack, st, sp_, sf, sn)
                    a = 1.0
                    if k >= 0:
                        surface(geo, k, f, tri, b1, b2, ox + t * dx, oy + t * dy, oz + t * dz, ncancel,
                                h_ng, h_ns, h_uv, h_po, h_ev, 0, stack)
                        a = hit_alpha(maps, mat_tab, mat_of[k], k, h_po, h_uv)
                        if a <= 0.0:  # cut out by an opacity map: on to the next surface
                            t, k, a = pass_cutouts(geo, shading, ox, oy, oz, dx, dy, dz, t, ncancel, surf, scr)
                    h_t[0], h_p[0] = t, k
                    if primary and s == 0:
                        depth_map[p] = t * (dx * fwd[0] + dy * fwd[1] + dz * fwd[2]) if k >= 0 else np.inf
                    primary = False
                    base = top
                    if k >= 0:
                        surface_maps(maps, mat_tab, mat_of[k], k, geo.xf, h_po, h_uv, h_ns, h_col)
                        if a < 1.0 and hop < MAX_CUTOUTS:  # alpha blending: the ray also goes on
                            for q in range(3):
                                r_o[base, q], r_d[base, q], r_w[base, q] = c_o[0, q], c_d[0, q], c_w[0, q] * (1.0 - a)
                                c_w[0, q] *= a
                            for q in range(4):
                                r_stk[base, q] = c_stk[0, q]
                            r_n[base], r_gen[base], r_hop[base] = c_n[0], c_gen[0], hop + 1
                            r_tmin[base] = _past(ox, oy, oz, dx, dy, dz, t, rel_eps, extent)
                            base += 1
                        opacity_feelers(geo, shading, ox, oy, oz, dx, dy, dz, t, h_ng, h_ns, h_vis, (f_po, f_uv), scr)
                    else:
                        miss_radiance(maps, dx, dy, dz, background, h_bg)
                    shade_hit(geo, mat_of, mat_tab, lights, ambient, h_bg, opts, cur, row, hits,
                              contrib, pending, base, cnt, scr)
                    ar += contrib[0, 0]
                    ag += contrib[0, 1]
                    ab += contrib[0, 2]
                    # keep the children that exist on the stack
                    r_hop[base], r_hop[base + 1] = hop, hop
                    top = base
                    if r_kind[top] != 0:
                        top += 1
                        if r_kind[top] != 0:
                            top += 1
                    elif r_kind[top + 1] != 0:
                        for q in range(3):
                            r_o[top, q], r_d[top, q], r_w[top, q] = r_o[top + 1, q], r_d[top + 1, q], r_w[top + 1, q]
                        for q in range(4):
                            r_stk[top, q] = r_stk[top + 1, q]
                        r_n[top], r_tmin[top], r_gen[top] = r_n[top + 1], r_tmin[top + 1], r_gen[top + 1]
                        top += 1
            image[p, 0], image[p, 1], image[p, 2] = ar / spp, ag / spp, ab / spp
    for q in range(RAY_COUNTS):
        counts[q] += cnt[0, q]
        cnt[0, q] = 0
