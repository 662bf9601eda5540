"""The kernels' tables have named columns (issue 27, item 1): ``renderers.kernels.columns``.
Each table's members tile its columns exactly (no gap, no overlap), the builders write every
column by name, and a row written by name reads back by name."""
from __future__ import annotations

import numpy as np
import pytest

from workbench.renderers.kernels import columns as C
from workbench.renderers.kernels.columns import Light, Mat, PathOpt, Tex, WhittedOpt, pack, span, width
from workbench.renderers.raytrace.flatten import flatten, light_rows
from workbench.scene import model as m
from workbench.scene.io import scene_from_dict

TABLES = (Mat, Light, Tex, WhittedOpt, PathOpt)


@pytest.mark.parametrize("table", TABLES, ids=lambda t: t.__name__)
def test_members_tile_the_columns(table):
    cols = sorted(c for member in table for c in range(member, member + span(member)))
    assert cols == list(range(width(table)))


def test_pack_refuses_a_missing_unknown_or_misshapen_column():
    full = {c.name.lower(): np.zeros(span(c)) for c in Light}
    assert pack(Light, **full).shape == (C.LIGHT_COLS,)
    with pytest.raises(KeyError, match="COSINE"):
        pack(Light, **{k: v for k, v in full.items() if k != "cosine"})
    with pytest.raises(KeyError, match="SPARE"):
        pack(Light, **full, spare=0.0)
    with pytest.raises(ValueError, match="POWER"):
        pack(Light, **{**full, "power": [1.0, 2.0]})


def test_material_and_light_rows_read_back_by_name():
    d = {"camera": {"position": [0, 0, -5], "look_at": [0, 0, 0]},
         "materials": {"g": {"color": [0.1, 0.2, 0.3], "ka": 0.05, "kd": 0.6, "ks": 0.7, "shininess": 33.0,
                             "kr": 0.11, "kt": 0.44, "ior": 1.33, "absorption": [0.5, 0.6, 0.7],
                             "emission": [2.0, 3.0, 4.0]}},
         "lights": [{"type": "point", "position": [1, 2, 3], "intensity": 2.0, "color": [1.0, 0.5, 0.25]}],
         "objects": [{"type": "sphere", "material": "g", "radius": 1.0}]}
    sd = flatten(scene_from_dict(d, source="columns"))
    row = sd.mat_tab[sd.mat[0]]
    assert sd.mat_tab.shape[1] == C.MAT_COLS
    assert list(row[Mat.COLOR:Mat.COLOR + 3]) == [0.1, 0.2, 0.3]
    assert (row[Mat.KA], row[Mat.KD], row[Mat.KS], row[Mat.SHININESS]) == (0.05, 0.6, 0.7, 33.0)
    assert (row[Mat.KR], row[Mat.KT], row[Mat.IOR]) == (0.11, 0.44, 1.33)
    assert list(row[Mat.ABSORPTION:Mat.ABSORPTION + 3]) == [0.5, 0.6, 0.7]
    assert list(row[Mat.EMISSION:Mat.EMISSION + 3]) == [2.0, 3.0, 4.0]
    assert row[Mat.TEXTURED] == row[Mat.BUMPED] == row[Mat.OPACITY] == 0.0
    (lt,) = sd.lights
    assert lt[Light.KIND] == 0.0 and list(lt[Light.POSITION:Light.POSITION + 3]) == [1, 2, 3]
    assert list(lt[Light.POWER:Light.POWER + 3]) == [2.0, 1.0, 0.5]
    sun = light_rows([m.DirectionalLight(direction=(0.0, -1.0, 0.0), intensity=1.0)])[0]
    assert sun[Light.KIND] == 1.0 and list(sun[Light.POSITION:Light.POSITION + 3]) == [0.0, -1.0, 0.0]
