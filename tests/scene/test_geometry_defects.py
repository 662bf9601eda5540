"""Defects of issue 17 where an object vanished or was drawn wrong, each pinned by a test that
failed before its fix."""
from __future__ import annotations

import numpy as np
import pytest

from seen_pixels import coverage, iou, scene_dict
from workbench.scene.io import scene_from_dict
from workbench.scene.polygon_pieces import convex_pieces, ear_triangles

L_SHAPE = [[-1, -1, 0], [1, -1, 0], [1, 0, 0], [0, 0, 0], [0, 1, 0], [-1, 1, 0]]
U_SHAPE = [[-1.5, -1, 0], [1.5, -1, 0], [1.5, 1, 0], [0.7, 1, 0], [0.7, -0.2, 0], [-0.7, -0.2, 0],
           [-0.7, 1, 0], [-1.5, 1, 0]]
STAR = [[1.5 * (1.0 if k % 2 == 0 else 0.4) * np.cos(np.pi / 2 + k * np.pi / 5),
         1.5 * (1.0 if k % 2 == 0 else 0.4) * np.sin(np.pi / 2 + k * np.pi / 5), 0.0] for k in range(10)]


def _area(v):
    v = np.asarray(v, dtype=np.float64)
    return 0.5 * np.linalg.norm(np.cross(v[1:-1] - v[0], v[2:] - v[0]).sum(0))


@pytest.mark.parametrize("verts", [L_SHAPE, U_SHAPE, STAR], ids=["L", "U", "star"])
def test_ear_clipping_covers_the_polygon_exactly(verts):
    tris = ear_triangles(np.asarray(verts, dtype=np.float64))
    assert len(tris) == len(verts) - 2
    total = sum(_area(np.asarray(verts, dtype=np.float64)[t]) for t in tris)
    assert abs(total - _area(verts)) <= 1e-12 * _area(verts)
    for t in tris:  # every triangle wound like the polygon (its normal +z)
        a, b, c = np.asarray(verts, dtype=np.float64)[t]
        assert np.cross(b - a, c - a)[2] > 0.0
    assert len(convex_pieces(verts)) == len(verts) - 2
    assert len(convex_pieces(L_SHAPE[:3] + [[-1, 1, 0]])) == 1  # a convex quad stays whole


@pytest.mark.gl
@pytest.mark.parametrize("verts", [L_SHAPE, U_SHAPE, STAR], ids=["L", "U", "star"])
def test_concave_polygon_same_coverage_in_ray_caster_and_raster(verts, gl_ctx):
    sc = scene_from_dict(scene_dict([{"type": "polygon", "vertices": verts, "material": "m"}]))
    ray, ras = coverage(sc, "raycast", 64, 48), coverage(sc, "phong", 64, 48)
    assert ray.sum() > 0.3 * ras.sum()
    assert iou(ray, ras) >= 0.97, iou(ray, ras)
    # the polygon's own area, seen head on: the pixel count matches it (edges within a pixel)
    th = np.tan(np.radians(20.0))
    px_area = (2 * 6 * th / 48) ** 2
    perimeter_px = sum(np.linalg.norm(np.subtract(a, b)) for a, b in zip(verts, np.roll(verts, -1, 0))) / np.sqrt(px_area)
    assert abs(ray.sum() - _area(verts) / px_area) <= perimeter_px, (ray.sum(), _area(verts) / px_area)


def test_concave_polygon_radiosity_patches_cover_its_area():
    from workbench.renderers.radiosity.patches import patches_from_scene
    sc = scene_from_dict(scene_dict([{"type": "polygon", "vertices": STAR, "material": "m"}]))
    ps, _ = patches_from_scene(sc, 0.2)
    assert abs(ps.areas.sum() - _area(STAR)) <= 1e-9 * _area(STAR)


def _ellipsoid_scene(R, *, scaled):
    obj = ({"type": "quadric", "shape": "ellipsoid", "radii": [1, 1, 1], "transform": {"scale": R}, "material": "m"}
           if scaled else {"type": "quadric", "shape": "ellipsoid", "radii": [R, R, R], "material": "m"})
    cam = {"position": [0, 0, 3 * R], "look_at": [0, 0, 0], "fov_y": 40.0, "resolution": [33, 33]}
    return scene_from_dict(scene_dict([obj], camera=cam, lights=[{"type": "point", "position": [2 * R, 3 * R, 6 * R]}]))


@pytest.mark.parametrize("R,scaled", [(R, s) for R in (1.0, 100.0, 1e4, 1e6, 1e-6) for s in (False, True)])
def test_ray_through_the_pole_of_an_ellipsoid_hits_it_at_every_scale(R, scaled):
    """Before: a miss at the pole from R = 100 (the hit point rounded out of the bounds) and
    everywhere at R = 1e6 (|A| <= zero (|A| + |B| + |C|) took the quadric for a plane)."""
    import workbench
    from workbench.renderers.raytrace import reference
    sc = _ellipsoid_scene(R, scaled=scaled)
    O, D = np.array([0.0, 0.0, 3 * R]), np.array([0.0, 0.0, -1.0])
    t_kernel = workbench.raytrace.intersect(sc, O[None], D[None])[0][0]
    hit = reference.closest(reference.Context(sc), O, D, 0.0)
    assert abs(t_kernel - 2 * R) <= 1e-9 * R
    assert hit is not None and abs(hit.t - 2 * R) <= 1e-9 * R


@pytest.mark.parametrize("R", [1e-6, 1.0, 1e6])
def test_quadric_seen_whole_by_the_ray_caster_at_every_scale(R):
    import workbench
    seen = [np.isfinite(workbench.render(_ellipsoid_scene(R, scaled=s), "raycast", width=33, height=33).depth)
            for s in (False, True)]
    ref = np.isfinite(workbench.render(_ellipsoid_scene(1.0, scaled=False), "raycast", width=33, height=33).depth)
    assert ref.sum() > 700
    for s in seen:
        assert (s == ref).all()


NEAR_SPHERE = {"type": "sphere", "center": [0, 0, 0], "radius": 1.0, "material": "m"}


@pytest.mark.gl
@pytest.mark.parametrize("extra", [
    {"type": "sphere", "center": [3e4, 0, -1e5], "radius": 1.0, "material": "m"},         # tiny, far
    {"type": "plane", "point": [0, -1.5, 0], "normal": [0, 1, 0], "size": [2e6, 2e6], "material": "m"},  # huge floor
    {"type": "sphere", "center": [0, 0, 0], "radius": 1e5, "material": "m"},               # sky sphere around the camera
], ids=["tiny_far_sphere", "huge_floor", "sky_sphere"])
def test_automatic_clip_planes_keep_the_near_object(extra, gl_ctx):
    """Before: near = far * 1e-3 from one box around the scene put the near plane past the
    sphere in front of the camera (the sphere vanished from every raster method)."""
    alone = scene_from_dict(scene_dict([NEAR_SPHERE]))
    both = scene_from_dict(scene_dict([NEAR_SPHERE, extra]))
    import workbench
    d_alone = workbench.render(alone, "phong", width=64, height=48).depth
    r = workbench.render(both, "phong", width=64, height=48)
    seen = np.isfinite(d_alone)
    assert seen.sum() > 200
    # the sphere's pixels still show the sphere, at its depth (5..6; the 24-bit depth buffer
    # resolves it to far better than 1e-2 with either set of clip planes)
    same = np.abs(r.depth[seen] - d_alone[seen]) <= 1e-2
    assert same.mean() >= 0.97, same.mean()
    # and the ray caster agrees on every pixel covered by something
    assert iou(coverage(both, "raycast", 64, 48), np.isfinite(r.depth)) >= 0.97


@pytest.mark.parametrize("position", [[1800.0, 273.0, 280.0], [-1300.0, 273.0, 280.0], [278.0, 273.0, 1800.0]],
                         ids=["outside_left", "outside_right", "outside_back"])
def test_hybrid_does_not_light_the_outside_of_the_cornell_walls(position):
    """Before: the radiosity patches' vertex emission was seen from both sides, so the outer
    faces of the walls glowed red/green (0.15, 0.006, 0.0005) where Phong, the ray tracer and
    radiosity give 0.  The inside, seen from the scene's own camera, stays lit."""
    from dataclasses import replace

    import workbench
    sc = workbench.load_scene("scenes/cornell_spheres.toml")
    cam = replace(sc.camera, position=tuple(position), look_at=(278.0, 273.0, 280.0), fov_y=5.0,
                  width=16, height=16)
    out = workbench.render(replace(sc, camera=cam), "hybrid", patch_size=0.2)
    assert np.isfinite(out.depth).all()  # the whole image is a wall's outer face
    assert out.image.max() == 0.0
    inside = workbench.render(sc, "hybrid", width=16, height=16, patch_size=0.2).image
    assert inside.mean() > 0.05


def _cube_ply(tmp_path) -> str:
    import trimesh
    path = tmp_path / "cube.ply"
    trimesh.creation.box(extents=(2.0, 2.0, 2.0)).export(path)  # 8 shared vertices
    return str(path)


def test_crease_normals_split_a_cube_and_keep_a_sphere_smooth(tmp_path):
    import trimesh

    from workbench.scene.mesh_normals import crease_normals
    sc = scene_from_dict(scene_dict([{"type": "mesh", "path": _cube_ply(tmp_path), "material": "m"}]))
    cube = sc.objects[0]
    assert len(cube.vertices) == 24  # 8 corners x 3 faces
    fn = np.cross(cube.vertices[cube.faces[:, 1]] - cube.vertices[cube.faces[:, 0]],
                  cube.vertices[cube.faces[:, 2]] - cube.vertices[cube.faces[:, 0]])
    fn /= np.linalg.norm(fn, axis=1, keepdims=True)
    for k in range(3):  # every corner's normal is its face's normal
        assert np.allclose(cube.normals[cube.faces[:, k]], fn, atol=1e-12)
    ico = trimesh.creation.icosphere(subdivisions=3)
    V, F, N, _ = crease_normals(ico.vertices, ico.faces)
    assert len(V) == len(ico.vertices) and F is not None
    assert np.allclose(N, ico.vertices / np.linalg.norm(ico.vertices, axis=1, keepdims=True), atol=0.02)
    V, F, N, _ = crease_normals(ico.vertices, ico.faces, crease_angle=0.0)  # faceted
    fn = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    fn /= np.linalg.norm(fn, axis=1, keepdims=True)
    assert len(V) > 2 * len(ico.vertices)
    for k in range(3):
        assert np.allclose(N[F[:, k]], fn, atol=1e-9)


@pytest.mark.gl
@pytest.mark.parametrize("method", ["raycast", "phong", "gouraud"])
def test_cube_mesh_faces_shade_flat(tmp_path, method):
    """Before: the cube's 8 shared vertices had averaged normals (the diagonal), so each face
    was shaded as a rounded patch.  Directional light, no specular: a flat face is one colour."""
    import workbench
    lights = [{"type": "directional", "direction": [-0.3, -0.5, -1.0]}]
    cam = {"position": [3.0, 2.5, 4.0], "look_at": [0, 0, 0], "fov_y": 40.0, "resolution": [64, 48]}
    sc = scene_from_dict(scene_dict([{"type": "mesh", "path": _cube_ply(tmp_path), "material": "m"}],
                                    camera=cam, lights=lights))
    r = workbench.render(sc, method)
    seen = np.isfinite(r.depth)
    lum = r.image.sum(-1)[seen]
    # three visible faces: at most three distinct shades (edge pixels aside)
    hist = np.unique(np.round(lum, 3), return_counts=True)[1]
    assert np.sort(hist)[-3:].sum() >= 0.95 * seen.sum(), np.sort(hist)[-6:]
