"""The new kinds side by side in one primitive table, as the ray tracer will hold them: one
parameter table, one shared aux array (each row its own offset), one numba dispatch over
``ptype`` through the kinds' shared entry-point signatures.  The nearest hit over the table
matches the nearest of the readable twins, and each kind's events over the whole line match
its readable crossings."""
from __future__ import annotations

import numba as nb
import numpy as np

from kind_checks import NPAR, scratch
from kernel_twins import Twins
from workbench.scene.kinds import (blob, blob_kernels, isosurface, isosurface_kernels, lathe, lathe_kernels, prism,
                                   prism_kernels)

COMMON = {"material": "m"}
OBJECTS = [
    blob.read({"threshold": 0.3, "components": [{"center": [0, 0, 0], "radius": 1.0},
                                                {"center": [1.2, 0, 0], "radius": 1.0}]}, "b", COMMON),
    isosurface.read({"function": "(sqrt((x-4)^2 + z^2) - 1)^2 + y^2", "threshold": 0.09, "max_gradient": 5.0,
                     "bounds": {"min": [2.5, -0.5, -1.5], "max": [5.5, 0.5, 1.5]}}, "i", COMMON),
    lathe.read({"points": [[0, -1], [0.8, -1], [0.5, 0], [0.8, 1], [0, 1]]}, "l", COMMON),
    prism.read({"polygon": [[0, 0], [2, 0], [2, 2], [1, 1], [0, 2]], "heights": [-3, -2]}, "p", COMMON),
]
PLACE = [np.zeros(3), np.zeros(3), np.array([-3.0, 0.0, 0.0]), np.zeros(3)]   # lathe moved by its rays


@nb.njit(cache=True)
def _first(ptype, par, aux, ox, oy, oz, dx, dy, dz, out_t, out_f, stack):
    best, bk, bf = np.inf, -1, 0
    for k in range(ptype.shape[0]):
        kind = ptype[k]
        if kind == blob.PTYPE:
            t, f = blob_kernels.first(par, k, aux, ox, oy, oz, dx, dy, dz, 0.0, best, out_t, out_f, stack)
        elif kind == isosurface.PTYPE:
            t, f = isosurface_kernels.first(par, k, aux, ox, oy, oz, dx, dy, dz, 0.0, best, out_t, out_f, stack)
        elif kind == lathe.PTYPE:
            t, f = lathe_kernels.first(par, k, aux, ox + 3.0, oy, oz, dx, dy, dz, 0.0, best, out_t, out_f, stack)
        else:
            t, f = prism_kernels.first(par, k, aux, ox, oy, oz, dx, dy, dz, 0.0, best, out_t, out_f, stack)
        if t < best:
            best, bk, bf = t, k, f
    return best, bk, bf


def _table():
    ptype, rows, aux = [], [], []
    off = 0
    for obj in OBJECTS:
        mod = {"blob": blob, "isosurface": isosurface, "lathe": lathe, "prism": prism}[obj.kind]
        head, a = mod.params(obj, off)
        row = np.zeros(NPAR)
        row[:len(head)] = head
        ptype.append(mod.PTYPE)
        rows.append(row)
        aux.append(a)
        off += len(a)
    return np.array(ptype), np.array(rows), np.concatenate(aux)


def test_nearest_hit_over_a_mixed_table():
    ptype, par, aux = _table()
    assert len(set(ptype.tolist())) == 4
    rng = np.random.default_rng(9)
    mods = [blob, isosurface, lathe, prism]
    seen = set()
    for _ in range(200):
        O = rng.normal(size=3) * 2 + [0.5, 4.0, 0.0]
        D = rng.uniform([-4, -3, -1.5], [5.5, 1, 1.5]) - O
        want = min((mod.intersect(obj, O - place, D)[0], k)
                   for k, (mod, obj, place) in enumerate(zip(mods, OBJECTS, PLACE)))
        t, k, _ = _first(ptype, par, aux, *O, *D, *scratch())
        if want[0] == np.inf:
            assert t == np.inf
            continue
        assert k == want[1] and abs(t - want[0]) <= 1e-12 * want[0]
        seen.add(k)
    assert seen == {0, 1, 2, 3}


def test_events_of_each_row_match_the_readable_crossings():
    ptype, par, aux = _table()
    rng = np.random.default_rng(10)
    events = [Twins(m).events for m in (blob_kernels, isosurface_kernels, lathe_kernels, prism_kernels)]
    mods = [blob, isosurface, lathe, prism]
    for k, obj in enumerate(OBJECTS):
        for _ in range(20):
            O = rng.normal(size=3) * 3
            lo, hi = mods[k].bounds(obj)
            D = (lo + hi) / 2 + rng.normal(size=3) * 0.3 - O
            out_t, out_f, stack = scratch()
            n = events[k](par, k, aux, *O, *D, out_t, out_f, 32, stack)
            ref = mods[k].hits(obj, O, D, True)
            assert np.allclose(out_t[:n], [t for t, _ in ref], rtol=1e-12, atol=1e-12)
            assert out_f[:n].tolist() == [f for _, f in ref]


class _Builder:
    """The ray tracer's builder interface the kinds' ``flatten`` writes through (no bounds:
    the prepared scene takes them from each kind's ``bound_points``)."""

    def __init__(self):
        self.rows, self.aux, self.n_aux = [], [], 0

    def add_aux(self, data):
        self.aux.append(data)
        self.n_aux += len(data)
        return self.n_aux - len(data)

    def add(self, ptype, index, obj, W, par, *, top=True, solid=True, shadow=True):
        row = np.zeros(NPAR)
        row[:len(par)] = par
        self.rows.append((ptype, row, solid))
        return len(self.rows) - 1


def test_flatten_through_the_builder_gives_the_same_table():
    b = _Builder()
    mods = [blob, isosurface, lathe, prism]
    for k, (mod, obj) in enumerate(zip(mods, OBJECTS)):
        assert mod.flatten(b, obj, k, np.eye(4), True) == k
    ptype, par, aux = _table()
    assert [r[0] for r in b.rows] == ptype.tolist()
    assert np.array_equal(np.array([r[1] for r in b.rows]), par)
    assert np.array_equal(np.concatenate(b.aux), aux)
    assert [r[2] for r in b.rows] == [True, True, True, True]
