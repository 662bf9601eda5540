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

from ..kernels.layout import MAX_DEPTH

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


@njit(cache=True)
def _hit(o, d, tris, t_min):
    """Nearest triangle hit by the ray (Moller & Trumbore 1997): (index or -1, front-facing)."""
    best = np.inf
    idx = -1
    front = False
    for k in range(tris.shape[0]):
        e1x = tris[k, 1, 0] - tris[k, 0, 0]
        e1y = tris[k, 1, 1] - tris[k, 0, 1]
        e1z = tris[k, 1, 2] - tris[k, 0, 2]
        e2x = tris[k, 2, 0] - tris[k, 0, 0]
        e2y = tris[k, 2, 1] - tris[k, 0, 1]
        e2z = tris[k, 2, 2] - tris[k, 0, 2]
        px, py, pz = _cross(d[0], d[1], d[2], e2x, e2y, e2z)
        det = e1x * px + e1y * py + e1z * pz
        if det == 0.0:
            continue
        inv = 1.0 / det
        tx = o[0] - tris[k, 0, 0]
        ty = o[1] - tris[k, 0, 1]
        tz = o[2] - tris[k, 0, 2]
        u = (tx * px + ty * py + tz * pz) * inv
        if u < 0.0 or u > 1.0:
            continue
        qx, qy, qz = _cross(tx, ty, tz, e1x, e1y, e1z)
        v = (d[0] * qx + d[1] * qy + d[2] * qz) * inv
        if v < 0.0 or u + v > 1.0:
            continue
        t = (e2x * qx + e2y * qy + e2z * qz) * inv
        if t > t_min and t < best:
            best = t
            idx = k
            # det = -d . (e1 x e2): the counter-clockwise front faces the ray when det > 0
            front = det > 0.0
    return idx, front


@njit(cache=True, parallel=True)
def raycast_rows(tris, tri_patch, first_tri, normals, rays, seed, t_min, offset):
    """F (P, P) by Malley's method: for each patch, ``rays`` cosine-distributed rays from
    stratified points (an m x m jittered grid, m^2 = rays, paired with a shuffled jittered
    grid of directions); F_ij = (rays whose nearest hit is the front of j) / rays."""
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
            hit, front = _hit(o, d, tris, t_min)
            if hit >= 0 and front:
                j = tri_patch[hit]
                if j != i:
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


@njit(cache=True, forceinline=True)
def _seg_blocked(tv, box, meta, ox, oy, oz, dx, dy, dz, t0, t1, stack):
    """Whether any triangle (``tv`` (T, 9), BVH ``box``/``meta`` of
    :func:`workbench.renderers.raytrace.bvh.build_bvh`) crosses the segment o + t d,
    t0 < t < t1 (Moller & Trumbore 1997 against each leaf triangle; any hit ends it)."""
    ix = 1.0 / dx if dx != 0.0 else 1e300
    iy = 1.0 / dy if dy != 0.0 else 1e300
    iz = 1.0 / dz if dz != 0.0 else 1e300
    sp = 0
    nd = 0
    while True:
        a0 = (box[nd, 0] - ox) * ix
        a1 = (box[nd, 3] - ox) * ix
        tn, tf = min(a0, a1), max(a0, a1)
        a0 = (box[nd, 1] - oy) * iy
        a1 = (box[nd, 4] - oy) * iy
        tn, tf = max(tn, min(a0, a1)), min(tf, max(a0, a1))
        a0 = (box[nd, 2] - oz) * iz
        a1 = (box[nd, 5] - oz) * iz
        tn, tf = max(tn, min(a0, a1)), min(tf, max(a0, a1))
        hit_box = tn <= tf * (1.0 + 1e-12) + 1e-300 and tf >= t0 and tn <= t1
        if hit_box and meta[nd, 1] > 0:
            for k in range(meta[nd, 0], meta[nd, 0] + meta[nd, 1]):
                e1x, e1y, e1z = tv[k, 3] - tv[k, 0], tv[k, 4] - tv[k, 1], tv[k, 5] - tv[k, 2]
                e2x, e2y, e2z = tv[k, 6] - tv[k, 0], tv[k, 7] - tv[k, 1], tv[k, 8] - tv[k, 2]
                px, py, pz = _cross(dx, dy, dz, e2x, e2y, e2z)
                det = e1x * px + e1y * py + e1z * pz
                if det == 0.0:
                    continue
                inv = 1.0 / det
                qx, qy, qz = ox - tv[k, 0], oy - tv[k, 1], oz - tv[k, 2]
                u = (qx * px + qy * py + qz * pz) * inv
                if u < 0.0 or u > 1.0:
                    continue
                rx, ry, rz = _cross(qx, qy, qz, e1x, e1y, e1z)
                v = (dx * rx + dy * ry + dz * rz) * inv
                if v < 0.0 or u + v > 1.0:
                    continue
                t = (e2x * rx + e2y * ry + e2z * rz) * inv
                if t0 < t < t1:
                    return True
            nd = -1
        elif hit_box:
            if sp < stack.shape[0]:
                stack[sp] = meta[nd, 0]
                sp += 1
            nd = nd + 1
        else:
            nd = -1
        if nd < 0:
            if sp == 0:
                return False
            sp -= 1
            nd = stack[sp]


@njit(cache=True, parallel=True)
def receiver_rows(shooters, flat, offsets, centres, normals, areas, samples, sample_w,
                  sample_first, tv, box, meta, offset, t_edge, zero, out):
    """Ray-cast rows for progressive refinement (Wallace, Elmquist & Haines 1989): for each
    shooter i and every receiver j, the exact point-to-polygon factor F_{dA_j -> A_i} from
    j's centre (Lambert's formula, :func:`_ff_one`) times the fraction (weighted by
    ``sample_w``) of segments from j's centre to i's sample points that no triangle blocks;
    returned in row form ``out[s, j] = F_ji A_j / A_i`` (progressive refinement takes
    F_ji = F_ij A_i / A_j back), so that shooting uses the receivers' own factors (the
    gathering system, as the hemicube at j would estimate it) without reciprocity.

    flat/offsets: polygons' vertices concatenated; samples (S, 3), sample_w (S,) and
    sample_first (P + 1,): points on each patch, already moved off it by ``offset`` along
    its normal; ``t_edge``: the segment's ends left out, as a fraction of it."""
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
        stack = np.empty(MAX_DEPTH + 1, dtype=np.int64)  # a pending child per level
        ox = centres[j, 0] + offset * normals[j, 0]
        oy = centres[j, 1] + offset * normals[j, 1]
        oz = centres[j, 2] + offset * normals[j, 2]
        seen = 0.0
        total = 0.0
        for k in range(sample_first[i], sample_first[i + 1]):
            total += sample_w[k]
            if not _seg_blocked(tv, box, meta, ox, oy, oz, samples[k, 0] - ox,
                                samples[k, 1] - oy, samples[k, 2] - oz, t_edge,
                                1.0 - t_edge, stack):
                seen += sample_w[k]
        if total > 0.0:
            out[s, j] = f * (seen / total) * areas[j] / Ai
