"""The local lighting model, written once (readable numpy reference).

Course, "Modèles d'éclairage": ambient + Lambert diffuse ``I_i k_d (L.N)`` + Phong specular
``I_i k_s (R.S)^n``.  Every method uses exactly this (the GLSL in ``shaders/include/lighting.glsl``
and the ray tracer's kernels are tested against this function)::

    I = E + ka C Ia + sum_l V_l I_l(P) [ kd C max(N.L_l, 0) + ks spec_l ]
    spec_l = max(R_l.S, 0)^n   (Phong,  R_l = 2 (N.L_l) N - L_l)
           = max(N.H_l, 0)^n   (Blinn,  H_l = normalize(L_l + S))
    spec_l = 0 where N.L_l <= 0; and x^0 = 1 (GLSL leaves pow(0, 0) undefined: we define it).

``C`` is the material colour times the texture, ``E`` the emission, ``Ia`` the scene's ambient,
``S`` the unit vector towards the viewer, ``V_l`` the light's visibility (shadow feeler; 1 in the
raster methods).  Received intensity ``I_l(P)``: ``color * intensity``, divided by ``r^2`` with
``falloff = "inverse_square"``, times ``max(0, n_l . (P - p_l) / r)`` for an area light's stand-in
(Lambertian emitter).  The shading normal faces the viewer (two-sided surfaces).
"""
from __future__ import annotations

import numpy as np

from ..core.transform import normalize
from ..scene.model import DirectionalLight, Material


def light_incidence(light, P: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Direction to the light, received intensity and distance at points ``P``.

    Parameters
    ----------
    light : PointLight | DirectionalLight
    P : (N, 3) points.

    Returns
    -------
    L : (N, 3) unit vectors towards the light.
    I : (N, 3) received RGB intensity.
    dist : (N,) distance to the light (inf for a directional light).
    """
    col = np.asarray(light.color, dtype=np.float64) * light.intensity
    if isinstance(light, DirectionalLight):
        L = np.broadcast_to(-np.asarray(light.direction, dtype=np.float64), P.shape)
        return L, np.broadcast_to(col, P.shape), np.full(len(P), np.inf)
    d = np.asarray(light.position, dtype=np.float64) - P
    r = np.linalg.norm(d, axis=-1)
    L = normalize(d)
    scale = np.ones(len(P))
    if light.falloff == "inverse_square":
        scale = 1.0 / np.maximum(r * r, 1e-300)
    if light.cosine_normal is not None:
        scale = scale * np.maximum(0.0, -(L @ np.asarray(light.cosine_normal, dtype=np.float64)))
    return L, col * scale[:, None], r


def specular_term(N, L, S, shininess: float, blinn: bool = False) -> np.ndarray:
    """``max(R.S, 0)^n`` (or Blinn's ``max(N.H, 0)^n``), 0 where ``N.L <= 0``, ``x^0 = 1``.
    Shapes: N, L, S (N, 3) unit vectors; returns (N,)."""
    ndl = np.sum(N * L, -1)
    if blinn:
        base = np.sum(N * normalize(L + S), -1)
    else:
        R = 2.0 * ndl[:, None] * N - L
        base = np.sum(R * S, -1)
    base = np.clip(base, 0.0, 1.0)
    spec = np.ones_like(base) if shininess == 0 else base ** shininess
    return np.where(ndl > 0.0, spec, 0.0)


def shade(P: np.ndarray, N: np.ndarray, S: np.ndarray, color: np.ndarray, mat: Material,
          lights, ambient, visibility: np.ndarray | None = None, blinn: bool = False) -> np.ndarray:
    """Evaluate the local model at points.

    Parameters
    ----------
    P : (N, 3) points; N : (N, 3) unit normals; S : (N, 3) unit vectors towards the viewer.
    color : (N, 3) or (3,) material colour times texture.
    mat : the material (ka, kd, ks, shininess, emission).
    lights : sequence of PointLight / DirectionalLight (area lights already replaced by stand-ins).
    ambient : (3,) the scene's ambient intensity Ia.
    visibility : (L, N) shadow-feeler transmittance per light (RGB-free), 1 when None.

    Returns
    -------
    (N, 3) float64 linear RGB.
    """
    P = np.asarray(P, dtype=np.float64)
    N = normalize(N)
    S = normalize(S)
    flip = np.sum(N * S, -1) < 0.0
    N = np.where(flip[:, None], -N, N)
    C = np.broadcast_to(np.asarray(color, dtype=np.float64), P.shape)
    out = mat.ka * C * np.asarray(ambient, dtype=np.float64) + np.asarray(mat.emission)
    for i, light in enumerate(lights):
        L, I, _ = light_incidence(light, P)
        ndl = np.maximum(np.sum(N * L, -1), 0.0)
        term = mat.kd * C * ndl[:, None]
        if mat.ks > 0.0:
            term = term + mat.ks * specular_term(N, L, S, mat.shininess, blinn)[:, None]
        if visibility is not None:
            term = term * visibility[i][:, None]
        out = out + I * term
    return out
