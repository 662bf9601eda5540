"""The ``hypertexture`` kind (Perlin and Hoffert 1989): bad keys refused through the console
script, one line naming the key, exit 2; the numba field (:mod:`..hypertexture_kernels`) against
the readable numpy one (:mod:`..hypertexture`) on random points for every base and noise kind,
amplitude and octave extremes included; and ``D = 0`` outside :func:`bound_radius` (what makes
the ray tracer's bounding sphere a valid boundary of the medium)."""
from __future__ import annotations

import subprocess
import sys
import zlib

import numpy as np
import pytest

from workbench.core.noise import value_noise as np_value_noise
from workbench.scene.kinds import hypertexture as ht

SCENE = """\
[camera]
position = [0.0, 0.0, -4.0]
look_at = [0.0, 0.0, 0.0]
[[lights]]
type = "point"
position = [-3.0, 4.0, -4.0]
[materials.m]
color = [0.8, 0.8, 0.8]
[[objects]]
type = "hypertexture"
material = "m"
{keys}
"""
GOOD = {"base": '"sphere"', "size": "0.8", "density": "2.0"}

BAD = [  # (key named in the message, overrides)
    ("base", {"base": '"cone"'}),
    ("size", {"size": "0.0"}),
    ("size", {"base": '"box"', "size": "[1.0, -0.5, 1.0]"}),
    ("size", {"base": '"torus"', "size": "[0.5, 0.5]"}),
    ("ramp[1]", {"ramp": "[[0.6, [1.0, 1.0, 1.0]], [0.2, [1.0, 0.5, 0.0]]]"}),
    ("albedo", {"albedo": "[1.2, 0.5, 0.5]"}),
    ("step", {"step": "1.0e-6"}),
    ("grid", {"grid": "1"}),
    ("octaves", {"octaves": "0"}),
    ("noise", {"noise": '"perlin"'}),
    ("density", {"density": "0.0"}),
    ("bias", {"bias": "1.0"}),
]


def _scene_text(over: dict) -> str:
    keys = {**GOOD, **over}
    return SCENE.format(keys="\n".join(f"{k} = {v}" for k, v in keys.items()))


def test_bad_keys_exit_2_with_one_line_naming_the_key(tmp_path):
    """Each bad scene through ``python -m workbench render``: exit 2, stderr one line
    ``workbench: error: ...`` naming the key, no traceback; the good scene renders."""
    runs = []
    for i, (key, over) in enumerate([("", {})] + BAD):
        path = tmp_path / f"s{i}.toml"
        path.write_text(_scene_text(over))
        cmd = [sys.executable, "-m", "workbench", "render", str(path), "-m", "raycast", "--size", "8x6",
               "-o", str(tmp_path / f"s{i}.png")]
        runs.append((key, over, subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)))
    for key, over, p in runs:
        out, err = p.communicate(timeout=300)
        if not key:
            assert p.returncode == 0, err
            continue
        lines = [x for x in err.splitlines() if x.strip()]
        assert p.returncode == 2, (over, p.returncode, err)
        assert len(lines) == 1 and lines[0].startswith("workbench: error:"), (over, err)
        assert f".{key}" in lines[0] or f"{key}:" in lines[0] or f"'{key}'" in lines[0], (key, lines[0])
        assert "Traceback" not in err + out


# --------------------------------------------------------------------------- numpy against numba
BASES = {"sphere": (0.7,), "box": (0.6, 0.4, 0.5), "torus": (0.7, 0.25)}
WHITE = np.array([[0.0, 1.0, 1.0, 1.0], [1.0, 1.0, 1.0, 1.0]])


def _objects():
    """Every base x noise kind, at ordinary settings and at the extremes of amplitude, octaves,
    bias and gain; with and without a ramp."""
    ramp = np.array([[0.0, 0.2, 0.1, 0.0], [0.4, 0.9, 0.5, 0.1], [1.0, 1.0, 1.0, 0.8]])
    out = []
    for base, size in BASES.items():
        for noise in ht.NOISES:
            for amp, oct_, b, g in ((1.0, 4, 0.5, 0.5), (0.0, 1, 0.3, 0.8), (8.0, 8, 0.999, 0.001),
                                    (3.0, 2, 1e-6, 0.999)):
                out.append(ht.Hypertexture(
                    material="m", base=base, size=size, soft=0.3, noise=noise, frequency=3.0, amplitude=amp,
                    octaves=oct_, phase=(0.3, -1.7, 2.2), bias=b, gain=g, density=5.0, albedo=(0.9, 0.6, 0.3),
                    emission=(2.0, 1.0, 0.5), ramp=ramp if oct_ % 2 == 0 else WHITE))
    return out


def _par(h):
    head, aux = ht.params(h, 0)
    return np.asarray(head, np.float64)[None, :], np.asarray(aux, np.float64)


def test_numba_field_and_optics_match_numpy():
    """density and optics of the numba twin against the numpy field at 400 random points per
    object inside the bounding cube: |difference| <= 1e-9 (both float64, the same formulas;
    pow and the ramp's division round differently)."""
    from kernel_twins import Twins
    from workbench.scene.kinds import hypertexture_kernels
    hk = Twins(hypertexture_kernels)
    rng = np.random.default_rng(31)
    worst = 0.0
    for h in _objects():
        par, aux = _par(h)
        R = ht.bound_radius(h)
        p = rng.uniform(-R, R, (400, 3))
        want = ht.density(h, p)
        got = np.array([hk.density(par, 0, aux, *q) for q in p])
        assert np.isfinite(got).all()
        worst = max(worst, float(np.abs(got - want).max()))
        assert np.abs(got - want).max() <= 1e-9, (h.base, h.noise, h.amplitude, h.bias, h.gain)
        col = ht.ramp(h, want)
        opt = np.array([hk.optics(par, 0, aux, *q) for q in p])
        live = want > 0
        assert np.allclose(opt[:, 0], h.density * want, rtol=0, atol=1e-8)
        assert np.allclose(opt[live, 1:4], (np.asarray(h.albedo) * col)[live], rtol=0, atol=1e-8)
        assert np.allclose(opt[live, 4:7], (np.asarray(h.emission) * col)[live], rtol=0, atol=1e-8)
        assert (opt[~live] == 0.0).all()
    assert worst <= 1e-9


def test_numba_value_noise_matches_numpy():
    """The lattice value noise at random points from 1e-3 to 1e8 in size, negative too: the
    numba twin gives numpy's value exactly or within 1e-12."""
    from kernel_twins import Twins
    from workbench.scene.kinds import hypertexture_kernels
    hk = Twins(hypertexture_kernels)
    rng = np.random.default_rng(7)
    p = rng.uniform(-1.0, 1.0, (3000, 3)) * 10.0 ** rng.uniform(-3, 8, (3000, 1))
    want = np_value_noise(p)
    got = np.array([hk.value_noise(*q) for q in p])
    assert np.isfinite(got).all() and (got >= 0).all() and (got < 1).all()
    assert np.abs(got - want).max() <= 1e-12


@pytest.mark.parametrize("base", list(BASES))
def test_density_is_zero_outside_the_bounding_sphere(base):
    """D = 0 (numpy and numba) at random points from just outside bound_radius (1 + 1e-9) to 3
    times it, on every object of :func:`_objects` with this base."""
    from kernel_twins import Twins
    from workbench.scene.kinds import hypertexture_kernels
    hk = Twins(hypertexture_kernels)
    rng = np.random.default_rng(zlib.crc32(base.encode()))  # (str hash changes with each process)
    for h in [o for o in _objects() if o.base == base]:
        par, aux = _par(h)
        R = ht.bound_radius(h)
        d = rng.normal(size=(300, 3))
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        r = R * np.concatenate([np.full(100, 1 + 1e-9), rng.uniform(1 + 1e-9, 3.0, 200)])
        p = d * r[:, None]
        assert (ht.density(h, p) == 0.0).all(), (h.base, h.noise, h.amplitude)
        assert all(hk.density(par, 0, aux, *q) == 0.0 for q in p), (h.base, h.noise, h.amplitude)
