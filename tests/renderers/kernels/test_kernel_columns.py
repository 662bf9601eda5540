"""The kernels' tables have named columns (issue 27, item 1): ``renderers.kernels.columns``
(``core.columns.Columns``), and each kind's ``Par`` names its columns of the primitive table.
Each table's members tile its columns exactly (no gap, no overlap), the builders write every
column by name, and a row written by name reads back by name."""
from __future__ import annotations

import numpy as np
import pytest

from workbench.renderers.kernels import columns as C
from workbench.core.columns import Columns, cell, pack, width
from workbench.renderers.kernels.columns import Light, Mat, PathOpt, Tex, TraversalCount, WalkCount, WhittedOpt
from workbench.renderers.raytrace.flatten import NPAR, flatten, light_rows
from workbench.scene import model as m
from workbench.scene.io import scene_from_dict
from workbench.scene.kinds import KINDS
from workbench.scene.kinds.aux_rows import AUX_OFFSET

TABLES = (Mat, Light, Tex, WhittedOpt, PathOpt, WalkCount, TraversalCount)
KIND_PARS = tuple(k.Par for k in KINDS.values() if hasattr(k, "Par"))


@pytest.mark.parametrize("table", TABLES + KIND_PARS, ids=lambda t: f"{t.__module__}.{t.__name__}")
def test_members_tile_the_columns(table):
    cols = sorted(c for member in table for c in range(member, member + member.span))
    assert cols == list(range(width(table)))


def test_every_kind_with_a_table_row_names_its_parameters_within_the_row():
    """Every kind whose ``flatten`` writes parameters names them (the mesh writes none), in at
    most ``NPAR`` columns; the aux kinds keep the offset of their numbers in ``AUX_OFFSET``."""
    named = {k.TYPE for k in KINDS.values() if hasattr(k, "Par")}
    assert named == {k.TYPE for k in KINDS.values()} - {"mesh"}
    for k in KINDS.values():
        if hasattr(k, "Par"):
            assert isinstance(k.Par, type) and issubclass(k.Par, Columns) and width(k.Par) <= NPAR
        if hasattr(k, "params"):
            assert k.Par.OFFSET == AUX_OFFSET


def test_width_refuses_a_gap_or_an_overlap():
    class Gap(Columns):
        A = 0
        B = 2

    class Overlap(Columns):
        A = 0, 3
        B = 2

    for table in (Gap, Overlap):
        with pytest.raises(ValueError, match=table.__name__):
            width(table)


def test_cell_reads_a_run_or_one_column():
    row = pack(Light, kind=1.0, position=[1, 2, 3], power=[4, 5, 6], inverse_square=0.0, cosine=0.0,
               cosine_normal=[0, 0, 1])
    assert list(cell(row, Light.POSITION)) == [1, 2, 3] and cell(row, Light.KIND) == 1.0


def test_pack_refuses_a_missing_unknown_or_misshapen_column():
    full = {c.name.lower(): np.zeros(c.span) for c in Light}
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
