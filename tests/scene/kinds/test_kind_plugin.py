"""A kind defined outside the package (``tests/toy_disk.py`` and ``tests/toy_disk_kernels.py``,
the worked example of ``docs/kernels.md``) is registered with
:func:`workbench.scene.kinds.register` and drawn by every method, touching no package file;
a kind module that breaks the contract is refused in one line naming what is wrong."""
from __future__ import annotations

import json
import os
import subprocess
import sys
import types
from pathlib import Path

import numpy as np
import pytest

import toy_disk
from workbench.core.errors import WorkbenchError
from workbench.scene.kinds import KINDS, register

TESTS = Path(__file__).resolve().parents[2]
SCENE = """
[scene]
name = "toy_disk"
background = [0.0, 0.0, 0.0]
ambient = [0.05, 0.05, 0.05]

[camera]
position = [0.0, 2.0, -4.0]
look_at = [0.0, 0.0, 0.0]
fov_y = 45.0

[[lights]]
type = "area"
vertices = [[-0.5, 3.0, -0.5], [0.5, 3.0, -0.5], [0.5, 3.0, 0.5], [-0.5, 3.0, 0.5]]
color = [8.0, 8.0, 8.0]
intensity = 1.0

[[lights]]
type = "point"
position = [1.0, 4.0, -2.0]

[materials.red]
color = [0.8, 0.2, 0.2]
kd = 0.9
ka = 0.1

[[objects]]
type = "disk"
name = "toy"
radius = 1.5
material = "red"
"""
SCRIPT = """
import json, sys
import numpy as np
import workbench, toy_disk
from workbench.core.errors import NotApplicable
from workbench.scene.kinds import register
register(toy_disk)
scene = workbench.load_scene(sys.argv[1])
out = {}
for method in workbench.available_methods():
    try:
        r = workbench.render(scene, method, width=48, height=36)
    except NotApplicable as e:
        out[method] = {"not_applicable": str(e)}
        continue
    img = np.asarray(r.image, dtype=np.float64)
    np.save(f"{sys.argv[2]}/{method}.npy", img)
    out[method] = {"left_out": [str(x) for x in r.left_out]}
print(json.dumps(out))
"""


@pytest.fixture(scope="module")
def renders(tmp_path_factory):
    """Every method's image of the toy scene, rendered by a user's script in a new process."""
    d = tmp_path_factory.mktemp("toy_disk")
    (d / "disk.toml").write_text(SCENE)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(TESTS), os.environ.get("PYTHONPATH", "")]))
    p = subprocess.run([sys.executable, "-c", SCRIPT, str(d / "disk.toml"), str(d)], capture_output=True,
                       text=True, env=env, timeout=1200)
    assert p.returncode == 0, p.stderr[-3000:]
    return d, json.loads(p.stdout.strip().splitlines()[-1])


def test_every_method_draws_the_plugin_kind(renders):
    d, out = renders
    drawn = {m: np.load(d / f"{m}.npy") for m, v in out.items() if "not_applicable" not in v}
    # the analytic reference: the ray caster's mask, checked against the disk's own geometry
    ref = drawn["raycast"].max(-1) > 0.02
    assert 0.1 < ref.mean() < 0.5 and ref[18, 24] and not ref[0, 0]
    assert {"raycast", "raytrace", "pathtrace", "phong", "radiosity"} <= set(drawn)
    for method, img in drawn.items():
        assert np.isfinite(img).all(), method
        assert not any("disk" in note for note in out[method]["left_out"]), (method, out[method])
        if method in ("povray", "mitsuba") and img.max() == 0.0:
            continue  # the outside program is not installed here (its image is black, noted)
        mask = img.max(-1) > 0.02
        # the raster and radiosity draw the inscribed 48-gon, the path tracer antialiases the
        # rim and sees the area light. Noise cannot flip this verdict: the path tracer is
        # seeded (seed 0: the same image on any machine but for rounding), and with seeds 0-3
        # no pixel lies within [0.01, 0.04] of the 0.02 cut (the disk's pixels are >= 0.24),
        # the agreement 0.977-0.982 throughout, so its false-failure probability is 0.
        assert (mask == ref).mean() > 0.95, (method, (mask == ref).mean())


def _broken(**changes) -> types.ModuleType:
    mod = types.ModuleType("broken_kind")
    mod.__dict__.update({k: v for k, v in vars(toy_disk).items() if not k.startswith("__")})
    if "TYPE" in changes:  # its model names the new type, unless the case says otherwise
        mod.MODEL = type("Model", (toy_disk.Disk,), {"kind": changes["TYPE"]})
    for k, v in changes.items():
        if v is None:
            del mod.__dict__[k]
        else:
            setattr(mod, k, v)
    return mod


@pytest.mark.parametrize("changes, says", [
    (dict(hits=None), "missing hits"),
    (dict(PTYPE=KINDS["blob"].PTYPE, TYPE="disk2", FEATURE="disks2"), "PTYPE 7 is taken by kind 'blob'"),
    (dict(TYPE="sphere"), "TYPE 'sphere' is taken"),
    (dict(TYPE="disk6", FEATURE="disks6", PTYPE=43, MODEL=toy_disk.Disk), "its MODEL's kind is 'disk', not its TYPE 'disk6'"),
    (dict(PTYPE=3, TYPE="disk3", FEATURE="disks3"), "PTYPE must be an int >= 7"),
    (dict(KERNELS="no_such_module_here", TYPE="disk4", FEATURE="disks4", PTYPE=41), "cannot import its kernel module"),
    (dict(KERNELS="toy_disk", TYPE="disk5", FEATURE="disks5", PTYPE=42), "lacks first, events"),
])
def test_a_kind_breaking_the_contract_is_refused_in_one_line(changes, says):
    before = dict(KINDS)
    with pytest.raises(WorkbenchError) as e:
        register(_broken(**changes))
    assert says in str(e.value) and "\n" not in str(e.value)
    assert dict(KINDS) == before
