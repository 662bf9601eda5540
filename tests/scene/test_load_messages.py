"""Every numeric value of every object kind's bundled example, set to a bad value in turn: the
scene loads, or :func:`workbench.load_scene` raises one :class:`WorkbenchError` line that names
the key, with no numpy repr (``np.float64(-1.0)`` was in the lathe's message) and no other
exception."""
from __future__ import annotations

import copy
import tomllib
import warnings

import pytest

from workbench.core.errors import SceneWarning, WorkbenchError
from workbench.scene.io import scene_from_dict
from workbench.scene.kinds import KINDS
from workbench.scene.library import bundled

BAD_VALUES = (-1.0, 0.0, 1e300, -1e300)
EXTRA_KINDS = {"box": {"type": "box", "min": [-1.0, 0.0, -1.0], "max": [1.0, 1.0, 1.0]}}
"""Kinds no bundled scene shows, with an example written here."""


def _examples() -> dict[str, tuple[dict, object]]:
    """kind -> (its first bundled scene's data, the object's index), or a minimal scene."""
    found: dict[str, tuple[dict, object]] = {}
    for path in sorted(bundled()):
        data = tomllib.loads(path.read_text())
        for i, obj in enumerate(data.get("objects", [])):
            found.setdefault(obj["type"], (data, i))
    for kind, obj in EXTRA_KINDS.items():
        if kind not in found:
            base = tomllib.loads(next(p for p in bundled() if p.stem == "whitted").read_text())
            base["objects"] = [dict(obj, material=next(iter(base["materials"])))]
            found[kind] = (base, 0)
    return found


def _numeric_paths(value, path=()):
    """Paths (tuples of keys and indices) of the numbers inside ``value``."""
    if isinstance(value, bool):
        return
    if isinstance(value, (int, float)):
        yield path
    elif isinstance(value, dict):
        for k, v in value.items():
            yield from _numeric_paths(v, path + (k,))
    elif isinstance(value, list):
        for i, v in enumerate(value):
            yield from _numeric_paths(v, path + (i,))


def _set(obj, path, value):
    for key in path[:-1]:
        obj = obj[key]
    obj[path[-1]] = value


def test_every_kind_has_an_example():
    assert set(_examples()) == set(KINDS), set(KINDS) ^ set(_examples())


@pytest.mark.parametrize("kind", sorted(KINDS))
def test_bad_numbers_give_one_clean_line(kind):
    data, index = _examples()[kind]
    paths = list(_numeric_paths(data["objects"][index]))
    assert paths
    tried = refused = 0
    for path in paths:
        for bad in BAD_VALUES:
            d = copy.deepcopy(data)
            _set(d["objects"][index], path, bad)
            tried += 1
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", SceneWarning)
                try:
                    scene_from_dict(d)
                except WorkbenchError as e:
                    refused += 1
                    msg = str(e)
                    assert "\n" not in msg and "np." not in msg and "Traceback" not in msg, (path, bad, msg)
    assert refused > 0, f"{kind}: no bad value of {tried} was refused"


def test_a_loaded_scene_holds_python_numbers():
    """The scene model holds plain floats (a texture's pole and equator were numpy scalars, shown
    as np.float64(...) in any repr or message that quoted a material)."""
    from workbench.scene.library import resolve
    from workbench.scene.io import load_scene
    for path in bundled():
        assert "np." not in repr(load_scene(resolve(path.stem))), path.stem
