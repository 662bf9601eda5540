"""User expressions (the isosurface's ``function``, the only kind that takes one) are sampled
at load: a function that is NaN or infinite over its bounds, or steeper than its declared
``max_gradient`` (including a jump), is refused in one line naming the key and a sample point,
through the API (``workbench.load_scene``) and the console script (exit 2, no output file);
before, the render went on with the object silently missing."""
from __future__ import annotations

import subprocess
import time

import pytest

import workbench
from ui_command import WORKBENCH
from one_object import scene_text
from workbench.core.errors import WorkbenchError
from workbench.scene.kinds import isosurface as I
from workbench.scene.kinds.expression import compile_expression

ISO = 'type = "isosurface"\nfunction = "{f}"\nthreshold = 0.5\nmax_gradient = {L}\n' \
      'bounds = {{ min = [-1, -1, -1], max = [1, 1, 1] }}'
CSG = 'type = "csg"\nop = "union"\n' \
      'left = {{ type = "sphere", material = "m", center = [2, 0, 0], radius = 0.5 }}\n' \
      'right = {{ type = "isosurface", material = "m", function = "{f}", threshold = 0.5, ' \
      'max_gradient = {L}, bounds = {{ min = [-1, -1, -1], max = [1, 1, 1] }} }}'

BAD = {  # id -> (function, max_gradient, key refused, words the line must hold)
    "division by zero": ("x/0", 1, "function", ["'x/0'", "inf", "[-1.0, -1.0, -1.0]"]),
    "square root of a negative": ("sqrt(-1-x^2)", 1, "function", ["nan", "finite"]),
    "logarithm of zero": ("log(0*x)", 1, "function", ["-inf"]),
    "pole inside the bounds": ("1/(x^2+y^2+z^2)", 100, "function", ["inf", "[0.0, 0.0, 0.0]"]),
    # |grad| = 1/(2 sqrt|x|) is infinite at x = 0 (NaN there, skipped by the gradient check):
    # the slope between x = 0 and x = 1/8 is sqrt(8) = 2.83 > 2.5
    "infinite slope at a sample": ("sqrt(abs(x))", 2.5, "max_gradient", ["2.82843", "[0.0,"]),
    # a jump of 1 every 1/3: 8 between the samples x = -0.75 and -0.625
    "discontinuous field": ("floor(3*x)", 2, "max_gradient", ["jumps", "8 between"]),
    "gradient above the bound": ("x^2+y^2+z^2", 3, "max_gradient", ["|grad f| = 3.4641"]),
}
GOOD = {  # functions at their exact Lipschitz bound: the float margin must let them through
    "linear at its slope": ("x", 1),
    "far from zero": ("1e12 + x", 1),
    "cone, no gradient at the apex": ("sqrt(x^2+y^2+z^2)", 1),
    "gyroid": ("sin(x)*cos(y) + sin(y)*cos(z) + sin(z)*cos(x)", 2.5),
}


def _write(tmp_path, f, L, template=ISO):
    p = tmp_path / "s.toml"
    p.write_text(scene_text(template.format(f=f, L=L)), encoding="utf-8")
    return p


@pytest.mark.parametrize("template", [ISO, CSG], ids=["alone", "in csg"])
@pytest.mark.parametrize("case", sorted(BAD))
def test_load_scene_refuses_in_one_line(case, template, tmp_path):
    f, L, key, words = BAD[case]
    with pytest.raises(WorkbenchError) as e:
        workbench.load_scene(_write(tmp_path, f, L, template))
    msg = str(e.value)
    assert "\n" not in msg and f".{key}: " in msg and "s.toml" in msg, msg
    for w in words:
        assert w in msg, msg


@pytest.mark.parametrize("case", sorted(GOOD))
def test_functions_within_their_bound_load(case, tmp_path):
    f, L = GOOD[case]
    (obj,) = workbench.load_scene(_write(tmp_path, f, L)).objects
    assert obj.max_gradient == L and obj.function == f


def test_check_is_fast():
    """The load-time sampling stays a few milliseconds (budget 50 ms) even for a long function."""
    prog = compile_expression(" + ".join(["sin(x)*cos(y) + sin(y)*cos(z) + sin(z)*cos(x)"] * 8))
    t = time.perf_counter()
    I.check_samples(prog, 20.0, (-3.0,) * 3, (3.0,) * 3, "o")
    assert time.perf_counter() - t < 0.25     # generous for a loaded machine


@pytest.mark.parametrize("case", ["division by zero", "discontinuous field"])
def test_cli_refuses_with_exit_2(case, tmp_path):
    f, L, key, _ = BAD[case]
    scene = _write(tmp_path, f, L)
    out = tmp_path / "x.png"
    p = subprocess.run([WORKBENCH, "render", str(scene), "-m", "raycast", "--size", "16x12", "-o", str(out)],
                       cwd=tmp_path, capture_output=True, text=True, timeout=300)
    lines = [ln for ln in p.stderr.splitlines() if ln.strip()]
    assert p.returncode == 2, p.stderr[-2000:]
    assert len(lines) == 1 and lines[0].startswith("workbench: error: ") and f".{key}: " in lines[0], p.stderr
    assert not out.exists()
