"""blob (metaballs): one component is a sphere of radius r sqrt(1 - sqrt(T/s)); the numba twin
agrees with the readable one; crossings alternate; scale invariance; marching cubes."""
from __future__ import annotations

import math

import numpy as np
import pytest

from kind_checks import SCALES, assert_alternates, mesh_volume, scratch, table, welded_edge_uses
from kernel_twins import Twins
from workbench.core.errors import WorkbenchError
from workbench.scene.kinds import blob as B
from workbench.scene.kinds import blob_kernels

BK = Twins(blob_kernels)
"""The kind's kernels callable from Python (``kernel_twins.Twins``)."""

REL = 1e-9


def _one(center=(0.0, 0.0, 5.0), r=2.0, s=1.0, T=0.25, scale=1.0):
    comp = np.array([[*(scale * np.asarray(center)), scale * r, s]])
    return B.Blob(material="m", components=comp, threshold=T)


def _numba(b, O, D, tmin=-np.inf, tmax=np.inf, cap=16):
    head, aux = B.params(b, 0)
    par = table(head)
    out = np.zeros(cap)
    n = BK.blob_crossings(par, 0, aux, *map(float, O), *map(float, D), tmin, tmax, out, cap)
    return par, aux, out[:n]


TWO = B.Blob(material="m", threshold=0.3, components=np.array(
    [[0.0, 0.0, 0.0, 1.0, 1.0], [1.2, 0.0, 0.0, 1.0, 1.0], [0.6, 0.8, 0.0, 0.7, -0.5]]))


@pytest.mark.parametrize("s, T", [(1.0, 0.25), (2.0, 0.5), (1.0, 0.01), (3.0, 2.9)])
def test_one_component_is_a_sphere(s, T):
    r = 2.0
    R = r * math.sqrt(1.0 - math.sqrt(T / s))
    c = np.array([0.3, -0.2, 5.0])
    b = _one(c, r, s, T)
    for off in (0.0, 0.3 * R, 0.9 * R):
        O = np.array([c[0] + off, c[1], -1.0])
        D = np.array([0.0, 0.0, 2.0])
        half = math.sqrt(R * R - off * off)
        want = [(c[2] - half - O[2]) / 2.0, (c[2] + half - O[2]) / 2.0]
        got = [t for t, _ in B.crossings(b, O, D)]
        _, _, nb_got = _numba(b, O, D)
        assert np.allclose(got, want, rtol=REL, atol=0) and np.allclose(nb_got, want, rtol=REL, atol=0)
        t, n = B.intersect(b, O, D)
        P = O + t * D
        assert np.allclose(n, (P - c) / R, rtol=0, atol=REL)
        head, aux = B.params(b, 0)
        nn = np.array(BK.normal(table(head), 0, aux, 0, *P, scratch()[2]))
        assert np.allclose(nn / np.linalg.norm(nn), n, rtol=0, atol=1e-12)


def test_scale_invariance():
    O, D = np.array([0.4, 0.1, -3.0]), np.array([0.05, 0.02, 1.0])
    base = [t for t, _ in B.crossings(TWO, O, D)]
    assert len(base) >= 2
    for k in SCALES:
        b = B.Blob(material="m", threshold=TWO.threshold,
                   components=TWO.components * [k, k, k, k, 1.0])
        got = [t for t, _ in B.crossings(b, k * O, D)]
        _, _, nb_got = _numba(b, k * O, D)
        assert np.allclose(np.array(got) / k, base, rtol=REL, atol=0)
        assert np.allclose(nb_got / k, base, rtol=REL, atol=0)


def test_numba_twin_agrees_and_crossings_alternate():
    rng = np.random.default_rng(5)
    head, aux = B.params(TWO, 0)
    par = table(head)
    hit = 0
    for _ in range(300):
        O = rng.normal(size=3) * 3
        D = rng.normal(size=3) * 0.6 + [0.6, 0.2, 0.0] - O      # aimed near the blob
        ref = B.crossings(TWO, O, D)
        _, _, got = _numba(TWO, O, D)
        assert len(got) == len(ref)
        assert np.allclose(got, [t for t, _ in ref], rtol=1e-12, atol=1e-12)
        assert_alternates(ref, lambda t: bool(B.inside(TWO, O + t * D)))
        assert all(BK.inside(par, 0, aux, *(O + t * D), scratch()[2]) == B.inside(TWO, O + t * D)
                   for t in rng.uniform(-5, 5, 4))
        hit += bool(ref)
        for t, _ in ref:      # the field is the threshold on the surface
            assert abs(B.field_value(TWO, O + t * D) - TWO.threshold) < 1e-12
    assert hit > 150


def test_first_hit_after_tmin_from_inside():
    b = _one((0.0, 0.0, 0.0), 2.0, 1.0, 0.25)
    R = 2.0 * math.sqrt(0.5)
    _, _, got = _numba(b, np.zeros(3), np.array([1.0, 0.0, 0.0]), 0.0, np.inf, 1)
    assert got.tolist() == pytest.approx([R], rel=REL)
    t, n = B.intersect(b, np.zeros(3), np.array([1.0, 0.0, 0.0]))
    assert t == pytest.approx(R, rel=REL) and np.allclose(n, [1, 0, 0], atol=REL)


def test_marching_cubes_mesh_of_one_component():
    R = 2.0 * math.sqrt(0.5)
    b = _one((1.0, 2.0, 3.0), 2.0, 1.0, 0.25)
    P, N, F = B.mesh(b, 24)
    assert (welded_edge_uses(P, F) == 2).all()
    vol = mesh_volume(P, F)
    assert 0.97 * 4 / 3 * math.pi * R ** 3 < vol < 4 / 3 * math.pi * R ** 3
    rad = np.linalg.norm(P - [1, 2, 3], axis=1)
    h = 4.0 / 24
    assert np.abs(rad - R).max() < 0.1 * h
    assert np.allclose(N, (P - [1, 2, 3]) / rad[:, None], atol=1e-9)


def test_marching_cubes_vertices_on_the_surface_and_chord_error_falls_with_resolution():
    """Each vertex is moved along its edge onto the level set (``marching_cubes.edge_roots``:
    the field there is the threshold to 1e-6, where linear interpolation left 0.04 at 16
    cells); what is left is the chord error at the triangles' centroids, of order h^2."""
    errs = []
    for res in (16, 32, 64):
        P, _, F = B.mesh(TWO, res)
        assert np.abs(B.field_value(TWO, P) - TWO.threshold).max() <= 1e-6
        errs.append(np.abs(B.field_value(TWO, P[F].mean(1)) - TWO.threshold).max())
    assert errs[0] > 2.5 * errs[1] > 2.5 * 2.5 * errs[2], errs


@pytest.mark.parametrize("table_, key", [
    ({"threshold": 0.0, "components": [{"center": [0, 0, 0], "radius": 1}]}, "o.threshold"),
    ({"threshold": 0.5, "components": []}, "o.components"),
    ({"threshold": 0.5, "components": [{"center": [0, 0], "radius": 1}]}, "o.components[0].center"),
    ({"threshold": 0.5, "components": [{"center": [0, 0, 0], "radius": -1}]}, "o.components[0].radius"),
    ({"threshold": 0.5, "components": [{"center": [0, 0, 0], "radius": 1, "strength": -1}]}, "o.components"),
    ({"threshold": 0.5, "components": [{"center": [0, 0, 0], "radius": 1, "colour": 1}]}, "o.components[0].colour"),
])
def test_bad_tables_fail_in_one_line(table_, key):
    with pytest.raises(WorkbenchError) as e:
        B.read(table_, "o", {"material": "m"})
    msg = str(e.value)
    assert msg.startswith(key + ":") and "\n" not in msg


def test_parse_hands_the_error_to_the_scene_reader():
    class Ctx:
        def fail(self, where, msg):
            raise WorkbenchError(f"scene.toml: {where}: {msg}")
    with pytest.raises(WorkbenchError, match=r"^scene.toml: o.threshold: missing required key$"):
        B.parse(Ctx(), {"components": [{"center": [0, 0, 0], "radius": 1}]}, "o", {"material": "m"})
