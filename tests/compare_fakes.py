"""Tiny stand-in renderers for the compare / study / stress tests, so that those run whatever
methods have landed.  ``install(monkeypatch)`` registers them in place of the real ones.

* ``facets``: a sphere scene flat-shaded on a latitude-longitude tessellation of ``n`` bands:
  the exact sphere silhouette, but each pixel shaded with its facet's normal (the direction of
  the facet's centre).  Theory: the shading error falls like the facet's angular size, 1/n.
* ``never``: raises ``NotApplicable`` for every scene.
* ``broken``: the facets, but a bug (``RuntimeError``) at ``n = 64``: a method's failure.
"""
from __future__ import annotations

import numpy as np

from workbench.core.errors import NotApplicable
from workbench.renderers import base
from workbench.renderers.base import Knob, Option, RenderResult
from workbench.renderers.local_model import shade
from workbench.renderers.support import Note, declare


def sphere_scene(width=48, height=36, shininess=20.0):
    from workbench.scene.io import scene_from_dict
    return scene_from_dict({
        "scene": {"name": "ball", "background": [0.1, 0.1, 0.1], "ambient": [0.2, 0.2, 0.2]},
        "camera": {"position": [0, 0, -4], "look_at": [0, 0, 0], "fov_y": 40, "resolution": [width, height]},
        "lights": [{"type": "point", "position": [-3, 4, -4], "intensity": 0.9}],
        "materials": {"m": {"color": [0.8, 0.4, 0.2], "ka": 0.3, "kd": 0.7, "ks": 0.4, "shininess": shininess}},
        "objects": [{"type": "sphere", "material": "m", "center": [0, 0, 0], "radius": 1.0}]})


class Facets:
    name = "facets"
    support = declare(left_out={"shadows": "not computed by this fake"})
    knob = Knob("n", (4, 8, 16, 32, 64), 8, "latitude bands")
    options = {"n": Option(int, 8, "latitude bands")}
    memory_options = ("n",)

    def estimate_bytes(self, scene, width, height, n=8):
        return 1024 * width * height + 2 ** 20   # rays, hits and image, float64

    def render(self, scene, width, height, n=8):
        from workbench.compare.analytic import ray_sphere
        obj = scene.objects[0]
        mat = scene.material_of(obj)
        o, d = (a.reshape(-1, 3) for a in scene.camera.rays())
        t = ray_sphere(o, d, obj.center, obj.radius)
        hit = np.isfinite(t)
        P = o[hit] + t[hit, None] * d[hit]
        Nn = (P - np.asarray(obj.center)) / obj.radius
        theta = np.arccos(np.clip(Nn[:, 1], -1, 1))
        phi = np.arctan2(Nn[:, 2], Nn[:, 0])
        th_c = (np.floor(theta / np.pi * n) + 0.5) * np.pi / n
        ph_c = (np.floor((phi + np.pi) / (2 * np.pi) * 2 * n) + 0.5) * np.pi / n - np.pi
        N = np.stack([np.sin(th_c) * np.cos(ph_c), np.cos(th_c), np.sin(th_c) * np.sin(ph_c)], -1)
        img = np.broadcast_to(np.asarray(scene.background), (len(t), 3)).copy()
        img[hit] = shade(P, N, -d[hit], np.asarray(mat.color), mat, scene.point_lights(), scene.ambient)
        return RenderResult(self.name, img.reshape(height, width, 3), timings={"compile": 0.0},
                            stats={"facets": 2 * n * n}, features_used=["spheres", "point_lights"],
                            left_out=[Note("shadows", "not computed by this fake")])


class Never:
    name = "never"
    support = declare()
    knob = Knob("q", (1, 2), 1)
    options = {"q": Option(int, 1)}
    memory_options = ("q",)

    def estimate_bytes(self, scene, width, height, q=1):
        return 1

    def render(self, scene, width, height, q=1):
        raise NotApplicable("this fake applies to no scene")


class Broken(Facets):
    name = "broken"

    def render(self, scene, width, height, n=8):
        if n == 64:
            raise RuntimeError("a bug of this fake at n = 64")
        return super().render(scene, width, height, n=n)


FAKES = {"facets": "compare_fakes:Facets", "never": "compare_fakes:Never"}
BROKEN = {"broken": "compare_fakes:Broken"}
"""Registered only by the tests that want a failing method (``install(monkeypatch, BROKEN)``)."""


def install(monkeypatch, extra: dict | None = None):
    """Register only the fakes (plus ``extra`` name -> "module:Class")."""
    reg = dict(FAKES, **(extra or {}))
    monkeypatch.setattr(base, "BUILTIN", reg)
    monkeypatch.setattr(base, "_instances", {})
    return reg
