"""Load-time geometry checks are relative to the object's own size (``tol.degenerate``): a scene
scaled by 1e-6 or 1e6 loads like the unscaled one, and a truly degenerate object (zero-area
polygon, singular transform, camera looking at itself, quadric with no x, y, z terms) is
refused at every scale.

Before: absolute thresholds refused a 1e-6 polygon as "zero area", a 1e-6 scale transform as
"singular", a generated torus of radius 1e-6 as "no triangles", and the Q matrix of an
ellipsoid of radius 1e6 (terms 1e-12) as "degenerate"; an asymmetric Q of that ellipsoid
passed.
"""
from __future__ import annotations

import copy

import numpy as np
import pytest

from workbench.scene.io import SceneError, scene_from_dict

SCALES = [1e-6, 1.0, 1e6]


def _scene(s: float, obj: dict, camera: dict | None = None) -> dict:
    """One object in a scene whose camera and light are scaled by ``s``."""
    return {
        "camera": camera or {"position": [0.3 * s, 0.2 * s, 5 * s], "look_at": [0, 0, 0]},
        "lights": [{"type": "point", "position": [2 * s, 3 * s, 5 * s]}],
        "materials": {"m": {"color": [0.8, 0.8, 0.8]}},
        "objects": [dict(obj, material="m")],
    }


def _refused(data: dict, key: str, expect: str) -> None:
    with pytest.raises(SceneError) as e:
        scene_from_dict(data)
    msg = str(e.value)
    assert key in msg and expect in msg, msg
    assert "\n" not in msg


def _pentagon(s: float, offset=(0.0, 0.0, 0.0)) -> list:
    a = np.linspace(0, 2 * np.pi, 5, endpoint=False)
    return [[float(offset[0] + s * np.cos(t)), float(offset[1] + s * np.sin(t)), float(offset[2])] for t in a]


@pytest.mark.parametrize("s", SCALES)
def test_polygon_and_area_light_load_at_every_scale(s):
    sc = scene_from_dict(_scene(s, {"type": "polygon", "vertices": _pentagon(s)}))
    assert np.allclose(sc.objects[0].vertices, _pentagon(s), rtol=0, atol=1e-15 * s)
    d = _scene(s, {"type": "sphere", "radius": s})
    d["lights"].append({"type": "area", "vertices": _pentagon(0.1 * s, (0.0, 0.0, 2 * s))})
    assert len(scene_from_dict(d).lights) == 2


@pytest.mark.parametrize("s", SCALES)
@pytest.mark.parametrize("verts", [
    [[0, 0, 0], [1, 1, 0], [2, 2, 0]],                 # collinear
    [[0, 0, 0], [1, 0, 0], [1, 0, 0], [0, 0, 0]],      # repeated points
    [[0, 0, 0], [1, 0, 0], [2, 1e-12, 0]],             # a sliver: area 1e-12 of its diameter squared
], ids=["collinear", "repeated", "sliver"])
def test_zero_area_polygon_refused_at_every_scale(s, verts):
    v = [[s * x for x in p] for p in verts]
    _refused(_scene(s, {"type": "polygon", "vertices": v}), ".vertices", "zero area")
    d = _scene(s, {"type": "sphere", "radius": s})
    d["lights"].append({"type": "area", "vertices": v})
    _refused(d, "[[lights]] #2.vertices", "zero area")


@pytest.mark.parametrize("s", SCALES)
def test_thin_polygon_far_from_the_origin_is_judged_by_its_own_size(s):
    """A 1000:1 triangle 100 diameters from the origin is a polygon; the same points made
    collinear (rounded to the nearest double) are not."""
    far = (100 * s, -50 * s, 30 * s)
    thin = [[far[0], far[1], far[2]], [far[0] + s, far[1], far[2]], [far[0] + 0.5 * s, far[1] + 1e-3 * s, far[2]]]
    assert scene_from_dict(_scene(s, {"type": "polygon", "vertices": thin})).objects
    line = copy.deepcopy(thin)
    line[2][1] = far[1]
    _refused(_scene(s, {"type": "polygon", "vertices": line}), ".vertices", "zero area")


@pytest.mark.parametrize("s", SCALES)
def test_scaled_transforms_load_at_every_scale(s):
    for tf, det in (({"scale": s}, 1.0), ({"scale": [s, 2 * s, 0.5 * s], "rotate": [10, 20, 30]}, 1.0),
                    ({"matrix": [[0, s, 0, 1], [-s, 0, 0, 2], [0, 0, 3 * s, 0], [0, 0, 0, 1]]}, 3.0)):
        sc = scene_from_dict(_scene(s, {"type": "sphere", "radius": 1.0, "transform": tf}))
        M = np.asarray(sc.objects[0].world_from_object)
        assert abs(np.linalg.det(M[:3, :3] / s) - det) <= 1e-12


@pytest.mark.parametrize("s", SCALES)
def test_singular_transform_refused_at_every_scale(s):
    flat = [[s, 0, 0, 0], [0, s, 0, 0], [0, 0, 0, 0], [0, 0, 0, 1]]
    rank2 = [[s, 2 * s, 0, 0], [2 * s, 4 * s, 0, 0], [0, 0, s, 0], [0, 0, 0, 1]]
    nearly = [[s, 0, 0, 0], [0, s, 0, 0], [0, 0, 1e-12 * s, 0], [0, 0, 0, 1]]
    for M in (flat, rank2, nearly):
        _refused(_scene(s, {"type": "sphere", "radius": 1.0, "transform": {"matrix": M}}), ".transform", "singular")
    for sv in (0.0, [s, s, 0.0], [s, s, 1e-12 * s]):
        _refused(_scene(s, {"type": "sphere", "radius": 1.0, "transform": {"scale": sv}}), ".transform.scale", "non-zero")


@pytest.mark.parametrize("s", SCALES)
def test_camera_checks_at_every_scale(s):
    assert scene_from_dict(_scene(s, {"type": "sphere", "radius": s})).camera
    p = [0.3 * s, 0.2 * s, 5 * s]
    _refused(_scene(s, {"type": "sphere", "radius": s}, {"position": p, "look_at": p}), "[camera].look_at", "must differ")
    # look_at within rounding of the position (relative 1e-12): no view direction either
    at = [p[0], p[1], p[2] * (1 + 1e-12)]
    _refused(_scene(s, {"type": "sphere", "radius": s}, {"position": p, "look_at": at}), "[camera].look_at", "must differ")
    _refused(_scene(s, {"type": "sphere", "radius": s}, {"position": p, "look_at": [0, 0, 0], "up": p}),
             "[camera].up", "parallel")


@pytest.mark.parametrize("s", SCALES)
def test_generated_torus_has_its_triangles_at_every_scale(s):
    sc = scene_from_dict(_scene(s, {"type": "mesh", "generate": {"kind": "torus", "radius": s, "subdivisions": 0}}))
    mesh = sc.objects[0]
    assert len(mesh.faces) == 2 * 8 ** 2
    r = np.linalg.norm(np.asarray(mesh.vertices)[:, :2], axis=1)   # trimesh's torus turns about z
    assert abs(r.max() - 4 / 3 * s) <= 1e-12 * s and abs(r.min() - 2 / 3 * s) <= 1e-12 * s


@pytest.mark.parametrize("s", SCALES)
def test_quadric_matrix_checks_at_every_scale(s):
    a = 1.0 / s ** 2
    Q = [[a, 0, 0, 0], [0, a, 0, 0], [0, 0, a, 0], [0, 0, 0, -1.0]]
    bounds = {"min": [-s, -s, -s], "max": [s, s, s]}
    sc = scene_from_dict(_scene(s, {"type": "quadric", "Q": Q, "bounds": bounds}))
    assert sc.objects[0].shape == "general"
    skew = copy.deepcopy(Q)
    skew[0][1], skew[1][0] = 0.5 * a, 0.6 * a
    _refused(_scene(s, {"type": "quadric", "Q": skew, "bounds": bounds}), ".Q", "not symmetric")
    none = [[0.0] * 4 for _ in range(3)] + [[0, 0, 0, -1.0]]
    _refused(_scene(s, {"type": "quadric", "Q": none, "bounds": bounds}), ".Q", "degenerate quadric")


@pytest.mark.parametrize("s", [1e-6, 1e6])
def test_general_quadric_tessellates_to_the_scaled_mesh(s):
    """A quadric given by Q (hyperboloid of one sheet) scaled by ``s`` tessellates to the mesh
    of scale 1, scaled.  Before: the level set's gradient floor was ``diagonal * 1e-6`` (a
    length where a gradient is inverse length), which at 1e6 replaced every gradient and
    moved the vertices (the phong image covered 864 pixels instead of 859)."""
    from workbench.scene.tessellate import tessellate_object

    def part(s):
        a = 1.0 / s ** 2
        Q = [[a, 0, 0, 0], [0, -a, 0, 0], [0, 0, a, 0], [0, 0, 0, -0.25]]
        sc = scene_from_dict(_scene(s, {"type": "quadric", "Q": Q, "bounds": {"min": [-s] * 3, "max": [s] * 3}}))
        (p,) = tessellate_object(sc.objects[0], 3)
        return p

    ref, got = part(1.0), part(s)
    assert len(ref.faces) > 100 and np.array_equal(got.faces, ref.faces)
    # manifold3d hands its points back in float32 (relative rounding 6e-8), at every scale
    assert np.abs(got.positions / s - ref.positions).max() <= 1e-6
    assert np.abs(got.normals - ref.normals).max() <= 1e-5
