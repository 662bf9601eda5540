"""Vertex layout and back-face culling of the raster methods: closedness of tessellated
objects, one provoking vertex per triangle for flat shading, culling that never changes the
image (camera outside a closed object) and is off when it would (camera inside)."""
from __future__ import annotations

import numpy as np
import pytest

import workbench
from workbench.renderers.raster import RasterSession
from workbench.scene.io import scene_from_dict
from workbench.scene.tessellate import tessellate_object
from workbench.scene.tessellate_topology import closed_outward, provoking_layout


def _scene(objects, eye=(0.0, 0.0, 4.0)):
    return scene_from_dict({
        "scene": {"ambient": [0.1, 0.1, 0.1]},
        "camera": {"position": list(eye), "look_at": [0.0, 0.0, -1.0], "fov_y": 60.0, "resolution": [64, 48]},
        "lights": [{"type": "point", "position": [0.3, 0.2, 0.5], "intensity": 1.0}],
        "materials": {"m": {"color": [0.8, 0.3, 0.2], "ka": 0.2, "kd": 0.6, "ks": 0.4, "shininess": 30.0}},
        "objects": objects})


SPHERE = {"type": "sphere", "material": "m", "center": [0.0, 0.0, 0.0], "radius": 1.0}
BOX = {"type": "box", "material": "m", "min": [-0.5, -0.5, -0.5], "max": [0.5, 0.5, 0.5]}
PLANE = {"type": "plane", "material": "m", "point": [0, -1, 0], "normal": [0, 1, 0], "size": [4, 4]}


@pytest.mark.parametrize("obj, closed", [(SPHERE, True), (BOX, True), (PLANE, False)])
def test_closed_outward_per_kind(obj, closed):
    (part,) = tessellate_object(_scene([obj]).objects[0], 3)
    assert closed_outward(part.positions, part.faces) is closed
    # inward winding is not "outward"; a missing triangle opens the surface
    assert not closed_outward(part.positions, part.faces[:, ::-1])
    assert not closed_outward(part.positions, part.faces[1:])


def test_every_shell_must_be_outward_not_only_the_total_volume():
    (big,) = tessellate_object(_scene([{**BOX, "min": [-1.5] * 3, "max": [1.5] * 3}]).objects[0], 3)
    (small,) = tessellate_object(_scene([BOX]).objects[0], 3)
    small_far = small.positions + 5.0  # a separate shell beside the big one

    def joined(faces_small):
        return (np.concatenate([big.positions, small_far]),
                np.concatenate([big.faces, faces_small + len(big.positions)]))
    assert closed_outward(*joined(small.faces))
    # the big shell's volume outweighs an inside-out small one: still not outward
    assert not closed_outward(*joined(small.faces[:, ::-1]))


def test_provoking_layout_gives_each_triangle_its_own_last_vertex():
    (part,) = tessellate_object(_scene([SPHERE]).objects[0], 4)
    V, F = len(part.positions), part.faces
    source, owner, out = provoking_layout(V, F)
    last = out[:, 2]
    assert len(np.unique(last)) == len(F)               # distinct provoking vertices
    assert (owner[last] == np.arange(len(F))).all()     # each carries its own triangle
    assert len(source) < 2 * len(F) < 3 * len(F)        # far fewer than an unwelded list
    # same triangles, same winding: the corners are a rotation of the input's
    P = part.positions
    got, want = P[source][out], P[F]
    rotated = np.zeros(len(F), dtype=bool)
    for r in range(3):
        rotated |= (got == np.roll(want, r, axis=1)).all(axis=(1, 2))
    assert rotated.all()


@pytest.mark.parametrize("method", ["flat", "gouraud", "phong"])
def test_culling_leaves_the_image_unchanged_outside(gl_ctx, method):
    scene = _scene([SPHERE, BOX | {"min": [1.2, -0.5, -1.0], "max": [2.0, 0.3, 0.0]}, PLANE])
    a = RasterSession(scene, method, backface_culling=False)
    b = RasterSession(scene, method)
    assert sum(d.cull >= 0 for d in b.draws) == 2  # the sphere and the box, not the plane
    np.testing.assert_array_equal(a.draw(), b.draw())
    a.release(), b.release()


@pytest.mark.parametrize("method", ["flat", "gouraud", "phong"])
def test_camera_inside_a_closed_object_sees_its_inside(gl_ctx, method):
    scene = _scene([SPHERE | {"radius": 3.0}], eye=(0.0, 0.0, 1.0))
    r = workbench.render(scene, method, width=32, height=24)
    assert np.isfinite(r.depth).all()  # every pixel sees the sphere's inside
    assert r.image.max() > 0.1
