"""Readable twin of the path tracer's kernel (:mod:`.kernels`), one path at a time, for a few
pixels: the same estimator (Kajiya 1986; next-event estimation with multiple importance
sampling, Veach 1997; the lobes, the energy scaling, the Fresnel split and Russian roulette of
the kernel's docstring), on the ray tracer's readable intersection
(:func:`..raytrace.reference.closest`) rather than the numba kernels, with numpy's random
numbers: the two agree in expectation, which the tests check against both noise estimates.

Covered: plain colours (no textures), emissive analytic surfaces and area lights (emissive
meshes are refused), point and directional lights, mirrors and dielectrics with nested media;
the ``transport`` modes (``full``, ``diffuse``, ``eye_specular``) and ``pixel_filter`` (``box``,
``center``) of the kernel's docstring.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...core.errors import WorkbenchError
from ...core.tol import tol
from ...scene import model as m
from ...scene.kinds import MESH
from .. import local_model
from ..kernels.columns import Mat
from ..raytrace import reference as rt
from ..raytrace.flatten import flatten
from ..raytrace.whitted import camera_frame
from .emitters import build_emitters
from .session import FRESNEL, MIS, PIXEL_FILTER, TRANSPORT


@dataclass
class Options:
    seed: int = 0
    fresnel: str = "none"
    rr_start: int = 3
    max_bounces: int = 1000
    mis: str = "power"
    transport: str = "full"
    pixel_filter: str = "box"


class Tracer:
    """The scene made ready: the ray tracer's reference context, the emitter table and the
    light-strategy density of each object (by the ray tracer's object index)."""

    def __init__(self, scene: m.Scene, width: int, height: int, options: Options):
        self.scene = scene.with_camera(scene.camera.with_resolution(width, height))
        self.o = options
        if options.fresnel not in FRESNEL or options.mis not in MIS:
            raise WorkbenchError(f"pathtrace reference: bad fresnel {options.fresnel!r} or mis {options.mis!r}")
        if options.transport not in TRANSPORT or options.pixel_filter not in PIXEL_FILTER:
            raise WorkbenchError(f"pathtrace reference: bad transport {options.transport!r} or pixel_filter "
                                 f"{options.pixel_filter!r}")
        self.full = options.transport == "full"
        self.ctx = rt.Context(self.scene, fresnel=options.fresnel)
        sd = flatten(self.scene, prepared=self.ctx.prepared)
        emission = sd.mat_tab[:, Mat.EMISSION:Mat.EMISSION + 3]
        if (sd.tri_e > 0).any() or any(emission[sd.mat[k]].max() > 0 for k in np.flatnonzero(sd.ptype == MESH)):
            raise WorkbenchError("pathtrace reference: emissive meshes are not covered")
        self.em = build_emitters(sd)
        self.em_material = [sd.materials[sd.mat[k]] for k in self.em.prim]
        self.density = {}  # object index -> light-strategy density per unit area
        for k in np.flatnonzero(sd.top):
            self.density[int(sd.obj[k])] = float(self.em.lpdf_prim[k])
        # diffuse transport: surfaces are the only emitters (radiosity's physics)
        self.lights = [lt for lt in scene.lights if not isinstance(lt, m.AreaLight)] if self.full else []
        self.cam = camera_frame(self.scene.camera, width, height)
        self.beta = MIS[options.mis]
        self.media0 = list(self.ctx.prepared.camera_media)
        if options.transport == "diffuse":
            self.media0 = []

    def camera_ray(self, i, j, u, v):
        """Direction through image-plane point ``(j + u, i + v)`` (as ``kernels.camera_ray_at``)."""
        c = self.cam
        x = ((j + u) / c[14] * 2.0 - 1.0) * c[12] * c[13]
        y = (1.0 - (i + v) / c[15] * 2.0) * c[12]
        R = c[3:12].reshape(3, 3)  # columns r, u, -f
        d = x * R[:, 0] + y * R[:, 1] - R[:, 2]
        return d / np.linalg.norm(d)

    def mis(self, pa, pb):
        a, b = pa ** self.beta, pb ** self.beta
        return a / (a + b) if a > 0 else 0.0

    def specular_here(self, mat: m.Material, eye: bool) -> bool:
        """Does this hit keep its delta lobes (``full``; ``eye_specular`` along the eye path)?"""
        return self.full or (self.o.transport == "eye_specular" and eye and (mat.kr > 0 or mat.kt > 0))

    def lobes(self, mat: m.Material, eye: bool = True):
        """Weights ``(a_d (3,), a_s, a_r, a_t)`` scaled by ``1 / max(1, kd max(C) + ks + kr + kt)``
        (``ks`` is 0 unless ``full``; ``ks, kr, kt`` are 0 where :meth:`specular_here` is not)."""
        C = np.asarray(mat.color, dtype=np.float64)
        ks = mat.ks if self.full else 0.0
        kr, kt = (mat.kr, mat.kt) if self.specular_here(mat, eye) else (0.0, 0.0)
        total = mat.kd * C.max() + ks + kr + kt
        s = 1.0 / total if total > 1.0 else 1.0
        return mat.kd * C * s, ks * s, kr * s, kt * s

    def phong(self, n, R, w):
        """Normalised Phong lobe value per unit ks and its sampling density (Lafortune & Willems 1994)."""
        ca = R @ w
        if ca <= 0:
            return 0.0, 0.0
        c = ca ** n if n > 0 else 1.0
        return (n + 2) / (2 * np.pi) * c, (n + 1) / (2 * np.pi) * c

    def radiance(self, O, D, rng) -> np.ndarray:
        """One path's radiance estimate (3,) from ``O`` along unit ``D``."""
        beta = np.ones(3)
        L = np.zeros(3)
        delta_before, pdf_prev, tmin = True, 0.0, 0.0
        eye = True  # only the camera and delta bounces so far
        media = list(self.media0)
        for bounce in range(self.o.max_bounces):
            hit = rt.closest(self.ctx, O, D, tmin)
            if hit is None:
                if self.full or eye:  # diffuse transport: the background lights nothing
                    L = L + beta * np.asarray(self.scene.background, dtype=np.float64)
                return L
            if media:
                beta = beta * np.exp(-np.asarray(media[-1].absorption) * hit.t)
            mat, P = hit.material, hit.P
            cos_g = -(hit.Ng @ D)
            front = cos_g > 0
            Nf = hit.Ng if front else -hit.Ng
            Ns = hit.Ns if hit.Ns @ D <= 0 else -hit.Ns
            if not self.specular_here(mat, eye) and not self.full and not front:
                if not eye:
                    return L  # one-sided: a back face is black (radiosity's form factors)
                front, Nf = True, hit.Ng  # the eye sees the front's radiance on a back face
                Ns = hit.Ns if hit.Ns @ hit.Ng >= 0 else -hit.Ns
            Le = np.asarray(hit.emission, dtype=np.float64) * np.ones(3) if self.full else np.zeros(3)
            if front or (self.full and not mat.name.startswith("__area_light")):
                Le = Le + np.asarray(mat.emission)
            if Le.max() > 0:
                w = 1.0
                dens = self.density.get(hit.item.index, 0.0)
                if not delta_before and dens > 0 and cos_g != 0:
                    w = self.mis(pdf_prev, dens * hit.t ** 2 / abs(cos_g))
                L = L + beta * Le * w
            a_d, a_s, a_r, a_t = self.lobes(mat, eye)
            m_d = a_d.max()
            m_nd = m_d + a_s
            R = D + 2 * (-(D @ Ns)) * Ns
            if R @ Nf <= 0:
                R = D + 2 * (-(D @ Nf)) * Nf
            R = R / np.linalg.norm(R)
            T, new_media = D, media
            if a_t > 0 and hit.solid:
                if front:
                    n1, n2, new_media = (media[-1].ior if media else 1.0), mat.ior, media + [mat]
                else:
                    n1, new_media = mat.ior, rt._media_after_exit(media, mat)
                    n2 = new_media[-1].ior if new_media else 1.0
                T, cosi, cost = rt.refraction(D, Nf, n1, n2)
                if T is None:
                    a_r, a_t, T = a_r + a_t, 0.0, D
                elif self.o.fresnel != "none":
                    F = rt.fresnel(self.o.fresnel, n1, n2, cosi, cost)
                    a_r, a_t = a_r + a_t * F, a_t * (1 - F)
            lobes = m_nd + a_r + a_t
            if lobes <= 0:
                return L
            P_nd = m_nd / lobes
            off = tol.ray_offset * max(float(np.abs(P).max()), self.ctx.extent)

            def f_and_pdf(w):
                fs, ps = self.phong(mat.shininess, R, w)
                return a_d / np.pi + a_s * fs, P_nd * (m_d * (Ns @ w) / np.pi + a_s * ps) / m_nd

            if m_nd > 0:
                L = L + beta * self.next_event(P, hit, Ns, Nf, f_and_pdf, rng)
            if bounce + 1 >= self.o.rr_start:
                q = min(0.95, beta.max())
                if rng.random() >= q:
                    return L
                beta = beta / q
            u = rng.random() * lobes
            if u < m_nd:
                if rng.random() * m_nd < m_d:
                    w = _around(Ns, np.sqrt(rng.random()), 2 * np.pi * rng.random())
                else:
                    w = _around(R, rng.random() ** (1 / (mat.shininess + 1)), 2 * np.pi * rng.random())
                if Ns @ w <= 0 or Nf @ w <= 0:
                    return L
                f, pdf = f_and_pdf(w)
                beta = beta * f * (Ns @ w) / pdf
                delta_before, pdf_prev, eye = False, pdf, False
                O, D = P + off * Nf, w
            elif u < m_nd + a_r:
                beta = beta * lobes
                delta_before = True
                O, D = P + off * Nf, R
            else:
                beta = beta * lobes
                delta_before = True
                O, D = P - off * Nf, T
                if hit.solid:
                    media = new_media[:4]
            tmin = tol.t_min * max(float(np.abs(P).max()), self.ctx.extent)
        return L

    def next_event(self, P, hit, Ns, Nf, f_and_pdf, rng) -> np.ndarray:
        """Light from one emitter-triangle point (MIS) and from every point / directional light."""
        out = np.zeros(3)
        em = self.em
        if len(em.cdf):
            e = int(np.searchsorted(em.cdf, rng.random(), side="right"))
            e = min(e, len(em.cdf) - 1)
            su, u2 = np.sqrt(rng.random()), rng.random()
            V = em.tri[e].reshape(3, 3)
            Q = (1 - su) * V[0] + su * (1 - u2) * V[1] + su * u2 * V[2]
            v = Q - P
            dist = np.linalg.norm(v)
            l = v / dist
            cos_l = -(l @ em.normal[e])
            mat = self.em_material[e]
            two_sided = self.full and not mat.name.startswith("__area_light")
            Le = np.asarray(mat.emission) if (cos_l > 0 or two_sided) else np.zeros(3)
            cos_s = Ns @ l
            if Le.max() > 0 and cos_s > 0 and cos_l != 0 and Nf @ l > 0:
                f, p_b = f_and_pdf(l)
                p_l = em.lpdf_prim[em.prim[e]] * dist * dist / abs(cos_l)
                if p_l > 0 and self.visible(P, hit.Ng, l, dist, Q):
                    out += f * Le * cos_s * self.mis(p_l, p_b) / p_l
        for light in self.lights:
            lvec, I, dist = local_model.light_incidence(light, P[None])
            l = lvec[0]
            cos_s = Ns @ l
            if cos_s <= 0 or not I[0].any() or Nf @ l <= 0:
                continue
            if self.visible(P, hit.Ng, l, dist[0]):
                f, _ = f_and_pdf(l)
                out += f * np.pi * I[0] * cos_s   # irradiance pi I S cos (the kernel's convention)
        return out

    def visible(self, P, Ng, l, dist, target=None) -> bool:
        """Nothing (area lights included) between ``P`` and the point at ``dist`` along ``l``; for
        a point ``target`` of an area light, the feeler aims from its pushed origin at it (along
        ``l`` it would meet a light seen at a grazing angle before its 2 ``off`` margin)."""
        off = self.ctx.offset(P)
        side = 1.0 if Ng @ l >= 0 else -1.0
        S = P + side * off * Ng
        if target is not None:
            w = target - S
            dist = float(np.linalg.norm(w))
            if dist <= 2 * off:
                return True
            l = w / dist
        tmax = dist - 2 * off if np.isfinite(dist) else np.inf
        tmin = tol.t_min * max(float(np.abs(P).max()), self.ctx.extent)
        return rt.closest(self.ctx, S, l, tmin, tmax) is None


def _around(n, cos_t, phi):
    """Unit direction at polar angle ``acos(cos_t)``, azimuth ``phi`` about unit ``n``."""
    a = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    t = np.cross(n, a)
    t /= np.linalg.norm(t)
    b = np.cross(n, t)
    s = np.sqrt(max(0.0, 1 - cos_t * cos_t))
    return s * np.cos(phi) * t + s * np.sin(phi) * b + cos_t * n


def render_pixels(scene: m.Scene, width: int, height: int, pixels, spp: int, **options):
    """Mean radiance and its standard error at a few pixels.

    Parameters
    ----------
    pixels : sequence of (row, column).  spp : samples per pixel (>= 2).
    options : fields of :class:`Options`.

    Returns
    -------
    mean, std_error : (n, 3) float64.
    """
    tr = Tracer(scene, width, height, Options(**options))
    rng = np.random.default_rng(tr.o.seed)
    pos = np.asarray(scene.camera.position, dtype=np.float64)
    mean, se = np.zeros((len(pixels), 3)), np.zeros((len(pixels), 3))
    for q, (i, j) in enumerate(pixels):
        centre = tr.o.pixel_filter == "center"
        S = np.array([tr.radiance(pos, tr.camera_ray(i, j, *((0.5, 0.5) if centre else rng.random(2))), rng)
                      for _ in range(spp)])
        mean[q] = S.mean(0)
        se[q] = S.std(0, ddof=1) / np.sqrt(spp)
    return mean, se
