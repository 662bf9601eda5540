"""numba kernels of the radiosity package (compiled on first use, cached on disk).

* :func:`point_polygon_ff` / :func:`analytic_matrix`: Lambert's contour formula.
* :func:`raycast_rows`: Malley's cosine-distributed rays against every triangle.
* :func:`shoot`: progressive refinement by shooting on an explicit matrix (Cohen et al. 1988).
* :func:`accumulate_items`: hemicube item buffers -> form-factor rows.

Each has a readable numpy/Python counterpart it is tested against (``tests/test_radiosity_*``).
"""
from __future__ import annotations

import numpy as np
from numba import njit, prange

from ..kernels.walks import BVH_STACK, bvh_hit

TWO_PI = 2.0 * np.pi


@njit(cache=True, forceinline=True)
def _cross(a0, a1, a2, b0, b1, b2):
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


@njit(cache=True)
def _ff_one(p, n, poly, eps, scale):
    """Form factor from the differential area at ``p`` (normal ``n``) to the front face of the
    convex polygon ``poly`` (k, 3), clipped to the half-space (x - p) . n >= 0.  ``eps``: the
    length below which a vector counts as zero; ``scale``: the coordinates' magnitude."""
    k = poly.shape[0]
    # polygon normal (Newell) and front-face test
    nx = ny = nz = 0.0
    cx = cy = cz = 0.0
    for a in range(k):
        b = (a + 1) % k
        nx += (poly[a, 1] - poly[b, 1]) * (poly[a, 2] + poly[b, 2])
        ny += (poly[a, 2] - poly[b, 2]) * (poly[a, 0] + poly[b, 0])
        nz += (poly[a, 0] - poly[b, 0]) * (poly[a, 1] + poly[b, 1])
        cx += poly[a, 0]
        cy += poly[a, 1]
        cz += poly[a, 2]
    if np.sqrt(nx * nx + ny * ny + nz * nz) <= eps * scale:      # zero area
        return 0.0
    if (p[0] - cx / k) * nx + (p[1] - cy / k) * ny + (p[2] - cz / k) * nz <= 0.0:
        return 0.0
    # clip to the hemisphere above p (Sutherland-Hodgman against one plane)
    clip = np.empty((k + 1, 3))
    m = 0
    for a in range(k):
        b = (a + 1) % k
        da = (poly[a, 0] - p[0]) * n[0] + (poly[a, 1] - p[1]) * n[1] + (poly[a, 2] - p[2]) * n[2]
        db = (poly[b, 0] - p[0]) * n[0] + (poly[b, 1] - p[1]) * n[1] + (poly[b, 2] - p[2]) * n[2]
        if da >= 0.0:
            clip[m, 0] = poly[a, 0] - p[0]
            clip[m, 1] = poly[a, 1] - p[1]
            clip[m, 2] = poly[a, 2] - p[2]
            m += 1
        if (da >= 0.0) != (db >= 0.0):
            s = da / (da - db)
            for c in range(3):
                clip[m, c] = poly[a, c] + s * (poly[b, c] - poly[a, c]) - p[c]
            m += 1
    if m < 3:
        return 0.0
    f = 0.0
    for a in range(m):
        b = (a + 1) % m
        r0 = clip[a]
        r1 = clip[b]
        l0 = np.sqrt(r0[0] ** 2 + r0[1] ** 2 + r0[2] ** 2)
        l1 = np.sqrt(r1[0] ** 2 + r1[1] ** 2 + r1[2] ** 2)
        if l0 < eps or l1 < eps:
            continue
        gx, gy, gz = _cross(r0[0], r0[1], r0[2], r1[0], r1[1], r1[2])
        g = np.sqrt(gx * gx + gy * gy + gz * gz)
        if g < eps * eps:
            continue
        cosang = (r0[0] * r1[0] + r0[1] * r1[1] + r0[2] * r1[2]) / (l0 * l1)
        gamma = np.arctan2(g / (l0 * l1), cosang)
        f += gamma * (n[0] * gx + n[1] * gy + n[2] * gz) / g
    # vertices counter-clockwise seen from the front, which faces p: the sum is negative
    return max(0.0, -f / TWO_PI)


@njit(cache=True, parallel=True)
def point_polygon_ff(points, normals, poly, zero):
    """(M,) form factors from points (M, 3) with normals (M, 3) to ``poly`` (k, 3); lengths
    below ``zero`` times the coordinates' scale count as zero."""
    out = np.zeros(points.shape[0])
    scale = 1.0
    for c in range(3):
        scale = max(scale, np.abs(poly[:, c]).max())
    eps = zero * scale
    for i in prange(points.shape[0]):
        out[i] = _ff_one(points[i], normals[i], poly, eps, scale)
    return out


@njit(cache=True, parallel=True)
def analytic_matrix(points, weights, owner, normals, flat, offsets, P, zero):
    """sum over quadrature points of patch i of weight * F_{dA -> A_j}: (P, P), not yet
    divided by A_i.  ``flat``/``offsets``: polygons' vertices concatenated."""
    F = np.zeros((P, P))
    scale = 1.0
    for c in range(3):
        scale = max(scale, np.abs(flat[:, c]).max())
    eps = zero * scale
    for j in prange(P):
        poly = flat[offsets[j]:offsets[j + 1]]
        for q in range(points.shape[0]):
            i = owner[q]
            if i == j:
                continue
            F[i, j] += weights[q] * _ff_one(points[q], normals[i], poly, eps, scale)
    return F


@njit(cache=True, parallel=True)
def raycast_rows(tris, tri_patch, first_tri, normals, bvh, bvh_tri, rays, seed, t_min, offset):
    """F (P, P) by Malley's method: for each patch, ``rays`` cosine-distributed rays from
    stratified points (an m x m jittered grid, m^2 = rays, paired with a shuffled jittered
    grid of directions); F_ij = (rays whose nearest hit is the front of j) / rays.  The
    nearest hit is the kernels' closest-hit walk of the 4-wide BVH of ``tris``
    (:func:`workbench.renderers.kernels.walks.bvh_hit`; ``bvh_tri``: the row of ``tris`` of
    each of the BVH's triangles)."""
    P = normals.shape[0]
    F = np.zeros((P, P))
    m = int(np.sqrt(rays))
    nr = m * m
    for i in prange(P):
        np.random.seed(seed + i)
        t0, t1 = first_tri[i], first_tri[i + 1]
        # triangle areas of this patch (CDF for choosing the triangle)
        cdf = np.zeros(t1 - t0 + 1)
        for k in range(t0, t1):
            ex, ey, ez = _cross(tris[k, 1, 0] - tris[k, 0, 0], tris[k, 1, 1] - tris[k, 0, 1],
                                tris[k, 1, 2] - tris[k, 0, 2], tris[k, 2, 0] - tris[k, 0, 0],
                                tris[k, 2, 1] - tris[k, 0, 1], tris[k, 2, 2] - tris[k, 0, 2])
            cdf[k - t0 + 1] = cdf[k - t0] + np.sqrt(ex * ex + ey * ey + ez * ez)
        if cdf[-1] <= 0.0:
            continue
        n = normals[i]
        # tangent frame
        if abs(n[0]) < 0.9:
            ax, ay, az = 1.0, 0.0, 0.0
        else:
            ax, ay, az = 0.0, 1.0, 0.0
        ux, uy, uz = _cross(n[0], n[1], n[2], ax, ay, az)
        lu = np.sqrt(ux * ux + uy * uy + uz * uz)
        ux, uy, uz = ux / lu, uy / lu, uz / lu
        vx, vy, vz = _cross(n[0], n[1], n[2], ux, uy, uz)
        perm = np.random.permutation(nr)
        o = np.empty(3)
        d = np.empty(3)
        stack = np.empty((BVH_STACK, 4))
        for s in range(nr):
            a = ((s // m) + np.random.random()) / m * cdf[-1]
            b = ((s % m) + np.random.random()) / m
            k = t0
            while k < t1 - 1 and cdf[k - t0 + 1] < a:
                k += 1
            w = cdf[k - t0 + 1] - cdf[k - t0]
            a = (a - cdf[k - t0]) / w if w > 0.0 else 0.0
            sa = np.sqrt(min(max(a, 0.0), 1.0))
            w0, w1, w2 = 1.0 - sa, sa * (1.0 - b), sa * b
            for c in range(3):
                o[c] = w0 * tris[k, 0, c] + w1 * tris[k, 1, c] + w2 * tris[k, 2, c] + offset * n[c]
            q = perm[s]
            r1 = ((q // m) + np.random.random()) / m
            r2 = ((q % m) + np.random.random()) / m
            rad = np.sqrt(r1)
            phi = TWO_PI * r2
            x, y, z = rad * np.cos(phi), rad * np.sin(phi), np.sqrt(max(0.0, 1.0 - r1))
            d[0] = x * ux + y * vx + z * n[0]
            d[1] = x * uy + y * vy + z * n[1]
            d[2] = x * uz + y * vz + z * n[2]
            _, hit, _, _, _, _ = bvh_hit(bvh, o[0], o[1], o[2], d[0], d[1], d[2], t_min, np.inf, np.bool_(False), stack)
            if hit >= 0:
                h = bvh_tri[hit]
                gx, gy, gz = _cross(tris[h, 1, 0] - tris[h, 0, 0], tris[h, 1, 1] - tris[h, 0, 1],
                                    tris[h, 1, 2] - tris[h, 0, 2], tris[h, 2, 0] - tris[h, 0, 0],
                                    tris[h, 2, 1] - tris[h, 0, 1], tris[h, 2, 2] - tris[h, 0, 2])
                # the counter-clockwise front faces the ray when d . (e1 x e2) < 0
                j = tri_patch[h]
                if d[0] * gx + d[1] * gy + d[2] * gz < 0.0 and j != i:
                    F[i, j] += 1.0
        for j in range(P):
            F[i, j] /= nr
    return F


@njit(cache=True)
def _unshot_ratio(B, dB, stop):
    """(every channel has ||dB_c||_inf <= stop ||B_c||_inf, max_c ||dB_c||_inf / ||B_c||_inf)
    of radiosities B and unshot radiosities dB, both (n, C)."""
    n, C = B.shape
    ok = True
    worst = 0.0
    for c in range(C):
        mb = 0.0
        md = 0.0
        for j in range(n):
            mb = max(mb, abs(B[j, c]))
            md = max(md, abs(dB[j, c]))
        r = md / mb if mb > 0.0 else 0.0
        worst = max(worst, r)
        if md > stop * mb:
            ok = False
    return ok, worst


@njit(cache=True)
def shoot(F, areas, rho, B, dB, max_shots, stop, history):
    """Progressive refinement on an explicit matrix (Cohen et al. 1988), in place.

    Repeatedly shoots the patch with the most unshot power sum_c dB_ic A_i:
    for every j, dB_j += rho_j F_ji dB_i and B_j += the same; dB_i = 0 (plus its own
    share if F_ii > 0).  Stops when max_c ||dB_c||_inf <= stop_c * ||B_c||_inf for every
    channel (``stop`` = tol (1 - q) / q) or after ``max_shots``.

    Returns the number of shots; ``history[k]`` = max_c ||dB_c||_inf / ||B_c||_inf after
    shot k.
    """
    n, C = B.shape
    for s in range(max_shots):
        best = -1.0
        i = 0
        for j in range(n):
            pw = 0.0
            for c in range(C):
                pw += dB[j, c]
            pw *= areas[j]
            if pw > best:
                best = pw
                i = j
        shot = dB[i].copy()
        for c in range(C):
            dB[i, c] = 0.0
        for j in range(n):
            f = F[j, i]
            if f != 0.0:
                for c in range(C):
                    inc = rho[j, c] * f * shot[c]
                    B[j, c] += inc
                    dB[j, c] += inc
        ok, worst = _unshot_ratio(B, dB, stop)
        history[s] = worst
        if ok:
            return s + 1
    return max_shots


@njit(cache=True)
def accumulate_items(ids, weights, out):
    """Hemicube rows from item buffers (Cohen & Greenberg 1985), in place:
    ``out[b, ids[b, y, x] - 1] += weights[y, x]`` for every pixel showing a patch (id > 0).

    ids : (K, H, W) uint32; weights : (H, W) delta form factors; out : (K, P).
    Serial: 0.2-0.4 ms for 16 hemicubes at resolution 128, not worth threads that llvmpipe's
    rasteriser wants."""
    K, H, W = ids.shape
    for b in range(K):
        for y in range(H):
            for x in range(W):
                k = ids[b, y, x]
                if k > 0:
                    out[b, k - 1] += weights[y, x]


@njit(cache=True)
def shoot_rows(rows, shooters, areas, rho, B, dB, relax, stop, history, start):
    """Progressive refinement from computed rows (Cohen et al. 1988), in place: patch
    ``shooters[s]`` = i shoots with its row ``rows[s]`` = F[i, :], receivers taking
    F_ji = F_ij A_i / A_j (reciprocity):

        dB_j += rho_j F_ji w dB_i,  B_j += the same,  dB_i -= w dB_i

    with the relaxation factor ``w = relax`` (1: plain shooting; > 1: overshooting, the
    overrelaxed Southwell iteration of Gortler et al. 1994, which leaves a negative unshot
    radiosity to be shot back later).  After each shot ``history[start + s]`` = max_c
    ||dB_c||_inf / ||B_c||_inf; stops after the shot at which every channel has
    ||dB_c||_inf <= stop ||B_c||_inf.  Returns the number of shots made.
    """
    n, C = B.shape
    shot = np.empty(C)
    for s in range(len(shooters)):
        i = shooters[s]
        for c in range(C):
            shot[c] = relax * dB[i, c]
            dB[i, c] -= shot[c]
        Ai = areas[i]
        for j in range(n):
            f = rows[s, j]
            if f != 0.0 and areas[j] > 0.0:
                f *= Ai / areas[j]
                for c in range(C):
                    inc = rho[j, c] * f * shot[c]
                    B[j, c] += inc
                    dB[j, c] += inc
        ok, worst = _unshot_ratio(B, dB, stop)
        history[start + s] = worst
        if ok:
            return s + 1
    return len(shooters)


@njit(cache=True, parallel=True)
def receiver_rows(shooters, polys, patches, samples, bvh, offset, t_edge, zero, out):
    """Ray-cast rows for progressive refinement (Wallace, Elmquist & Haines 1989): for each
    shooter i and every receiver j, the exact point-to-polygon factor F_{dA_j -> A_i} from
    j's centre (Lambert's formula, :func:`_ff_one`) times the fraction (weighted by the
    samples' weights) of segments from j's centre to i's sample points that no triangle
    blocks (the kernels' any-hit walk of the 4-wide BVH,
    :func:`workbench.renderers.kernels.walks.bvh_hit`); returned in row form
    ``out[s, j] = F_ji A_j / A_i`` (progressive refinement takes F_ji = F_ij A_i / A_j back),
    so that shooting uses the receivers' own factors (the gathering system, as the hemicube
    at j would estimate it) without reciprocity.

    ``polys = (flat, offsets)``: the patches' polygons, vertices concatenated;
    ``patches = (centres (P, 3), normals (P, 3), areas (P,))``; ``samples = (points (S, 3),
    weights (S,), first (P + 1,))``: points on each patch, already moved off it by ``offset``
    along its normal; ``bvh``: the patches' triangles (:func:`..raytrace.bvh.build_bvh4`:
    ``(node, child, leaf, first, tv4)``); ``t_edge``: the segment's ends left out, as a
    fraction of it."""
    flat, offsets = polys
    centres, normals, areas = patches
    points, sample_w, sample_first = samples
    P = centres.shape[0]
    scale = 1.0
    for c in range(3):
        scale = max(scale, np.abs(flat[:, c]).max())
    eps = zero * scale
    # one parallel loop over (shooter, receiver) pairs: one thread launch per batch
    for q in prange(len(shooters) * P):
        s, j = q // P, q % P
        i = shooters[s]
        out[s, j] = 0.0
        Ai = areas[i]
        if j == i or Ai <= 0.0 or areas[j] <= 0.0:
            continue
        f = _ff_one(centres[j], normals[j], flat[offsets[i]:offsets[i + 1]], eps, scale)
        if f <= 0.0:
            continue
        stack = np.empty((BVH_STACK, 4))
        ox = centres[j, 0] + offset * normals[j, 0]
        oy = centres[j, 1] + offset * normals[j, 1]
        oz = centres[j, 2] + offset * normals[j, 2]
        seen = 0.0
        total = 0.0
        for k in range(sample_first[i], sample_first[i + 1]):
            total += sample_w[k]
            _, tri, _, _, _, _ = bvh_hit(bvh, ox, oy, oz, points[k, 0] - ox, points[k, 1] - oy, points[k, 2] - oz,
                                   t_edge, 1.0 - t_edge, np.bool_(True), stack)
            if tri < 0:
                seen += sample_w[k]
        if total > 0.0:
            out[s, j] = f * (seen / total) * areas[j] / Ai
