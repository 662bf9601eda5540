"""Acceleration structures of the ray tracer (``accel=bvh|octree|none``) on two triangle
scenes and on scenes of many analytic spheres, and the BVH build time before and after a
revision of the build.

Scenes: the bundled ``mesh`` (one 81,920-triangle blob on an analytic floor: dense, compact),
``many`` (a 20 x 20 grid of 80-triangle icospheres over a floor, 32,000 triangles in 400
objects with empty space between them: where a uniform subdivision and a SAH tree differ) and
``spheres_1000`` / ``spheres_10000`` (that many analytic spheres of random centres and radii,
seeded, in a cube over a floor: the analytic primitives' structure; ``none`` tests every
sphere with every ray, camera and shadow alike).
For each structure: build time (``timings["bvh_build"]`` of the render: the structure and the
reordering of the triangle arrays; best of the runs), trace time of a ``raycast`` render
(``timings["trace"]``, best of ``--repeat`` warm runs), nodes visited and triangle tests per
camera ray (option ``traversal_stats``: its pass's time ``stats_pass_s`` beside the trace time of the same
render, ``stats_render_trace_s``; the rendering kernels themselves carry no counters), triangle rows held (the octree repeats triangles) and
the memory estimate.  The images of the three structures are compared (equal: ``same_image``).

BVH build before / after: ``build_bvh4`` on the mesh scene's triangles in one child process
that loads both versions of ``bvh.py`` (``--before``: a git revision, default ``7c5be9a``, the
last one before the sampled binning, exported with ``git archive`` to a temporary folder;
after: this checkout) and alternates them, best and median of 15 builds each, wall and CPU
seconds; the two trees' arrays are compared (``same_tree``) and their SAH costs given.

Writes ``bench/results/accel.json`` and ``docs/benchmarks/accel.md``.  Run:
``.venv/bin/python bench/accel.py [--size 160x120] [--repeat 3] [--before 7c5be9a]``; ``--smoke``: 32 x 24,
one run, the mesh scene and 200 spheres (not ``many``), 2 builds of 4,000 triangles.
The machine is shared: its load average is recorded at the start and the end.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from _common import Page, first_paragraph

ROOT = Path(__file__).resolve().parents[1]
ACCELS = ("bvh", "octree", "none")

BUILD_CHILD = r"""
import hashlib, importlib.util, json, sys, time
import numpy as np
from workbench.renderers.raytrace import bvh as after
spec = importlib.util.spec_from_file_location("bvh_before", sys.argv[2])
before = importlib.util.module_from_spec(spec)
sys.modules["bvh_before"] = before  # a named module: numba's cache can load its functions back
spec.loader.exec_module(before)
tri = np.load(sys.argv[1])[:int(sys.argv[4]) or None]
codes = {"before": before.build_bvh4, "after": after.build_bvh4}
for f in codes.values():
    f(tri[:64])  # JIT or cache load, outside the measurement
wall = {k: [] for k in codes}
cpu = {k: [] for k in codes}
for _ in range(int(sys.argv[3])):  # alternating, so that both see the same load
    for k, f in codes.items():
        t0, c0 = time.perf_counter(), time.process_time()
        f(tri)
        wall[k].append(time.perf_counter() - t0)
        cpu[k].append(time.process_time() - c0)
out = {}
for k, f in codes.items():
    order, bvh = f(tri)
    h = hashlib.sha256(order.tobytes())
    for a in bvh:
        h.update(np.ascontiguousarray(a).tobytes())
    def area(b):
        d = b[..., 3:] - b[..., :3]
        return d[..., 0] * d[..., 1] + d[..., 1] * d[..., 2] + d[..., 2] * d[..., 0]
    # SAH cost of the 4-wide tree: 1/2 per node box tested, 1 per triangle lane tested, over the root's area
    root = np.concatenate([bvh.node[0, :3].min(1), bvh.node[0, 3:].max(1)])
    with np.errstate(invalid="ignore"):
        kids = area(np.moveaxis(bvh.node, 2, 1))  # (N4, 4); empty slots NaN, never read
    inner = (bvh.child >= 0)
    leafs = bvh.child <= -2
    lanes = np.zeros_like(kids)
    lanes[leafs] = 4 * bvh.leaf[-2 - bvh.child[leafs], 1]
    sah = (0.5 * 4 * kids[inner].sum() + 0.5 * 4 * area(root) + (kids * lanes)[leafs].sum()) / area(root)
    out[k] = dict(wall_best_s=min(wall[k]), wall_median_s=float(np.median(wall[k])), cpu_best_s=min(cpu[k]),
                  cpu_median_s=float(np.median(cpu[k])), nodes_4wide=int(len(bvh.node)), leaves=int(len(bvh.leaf)),
                  sah_cost=float(sah), tree_sha256=h.hexdigest())
print(json.dumps(out))
"""


def many_scene():
    from workbench.scene.io import scene_from_dict
    objs = [{"type": "mesh", "material": "m", "generate": {"kind": "icosphere", "subdivisions": 1},
             "transform": {"translate": [-4.75 + 0.5 * i, 0.2, -4.75 + 0.5 * j], "scale": 0.18}}
            for i in range(20) for j in range(20)]
    objs.append({"type": "plane", "material": "floor", "point": [0, 0, 0], "normal": [0, 1, 0], "size": [12, 12]})
    return scene_from_dict({
        "scene": {"name": "many", "background": [0.08, 0.08, 0.1], "ambient": [0.12, 0.12, 0.12]},
        "camera": {"position": [0.0, 4.0, 7.5], "look_at": [0.0, 0.0, 0.0], "fov_y": 45.0, "resolution": [320, 240]},
        "lights": [{"type": "point", "position": [3.0, 6.0, 3.0], "intensity": 0.9}],
        "materials": {"m": {"color": [0.7, 0.5, 0.3], "ks": 0.3}, "floor": {"color": [0.6, 0.6, 0.6]}},
        "objects": objs})


def spheres_scene(n: int, seed: int = 7):
    """``n`` analytic spheres, random centres in a cube of side 10 and radii so that they fill
    about 5 % of it, over a floor (a rectangle), one point light."""
    from workbench.scene.io import scene_from_dict
    rng = np.random.default_rng(seed)
    r_mean = (0.05 * 1000.0 * 3.0 / (4.0 * np.pi * n)) ** (1.0 / 3.0)
    objs = [{"type": "sphere", "material": "m" + str(i % 3), "center": [float(x) for x in rng.uniform(-5, 5, 3) + [0, 5.2, 0]],
             "radius": float(r_mean * rng.uniform(0.5, 1.5))} for i in range(n)]
    objs.append({"type": "plane", "material": "floor", "point": [0, 0, 0], "normal": [0, 1, 0], "size": [30, 30]})
    return scene_from_dict({
        "scene": {"name": f"spheres_{n}", "background": [0.08, 0.08, 0.1], "ambient": [0.12, 0.12, 0.12]},
        "camera": {"position": [0.0, 7.0, 16.0], "look_at": [0.0, 4.5, 0.0], "fov_y": 50.0, "resolution": [320, 240]},
        "lights": [{"type": "point", "position": [6.0, 14.0, 8.0], "intensity": 0.9}],
        "materials": {"m0": {"color": [0.8, 0.3, 0.2], "ks": 0.3}, "m1": {"color": [0.2, 0.6, 0.3]},
                      "m2": {"color": [0.3, 0.4, 0.8], "ks": 0.5}, "floor": {"color": [0.6, 0.6, 0.6]}},
        "objects": objs})


def structures(scene, w, h, repeat):
    import workbench
    from workbench.renderers.base import check_memory, convert_options, get_renderer
    r = get_renderer("raycast")
    out, images = {}, {}
    for a in ACCELS:
        runs = [workbench.render(scene, "raycast", width=w, height=h, accel=a)
                for _ in range(1 if a == "none" and st_slow(scene) else repeat)]
        counted = workbench.render(scene, "raycast", width=w, height=h, accel=a, traversal_stats=True)
        st = counted.stats
        images[a] = runs[-1].image
        out[a] = dict(build_s=min(x.timings["bvh_build"] for x in runs),
                      trace_s=min(x.timings["trace"] for x in runs),
                      stats_pass_s=counted.timings["traversal_stats"], stats_render_trace_s=counted.timings["trace"],
                      frame_s=min(x.timings["total"] for x in runs),
                      nodes_per_ray=st["accel_nodes_per_ray"],
                      triangle_nodes_per_ray=st["accel_triangle_nodes_per_ray"],
                      analytic_nodes_per_ray=st["accel_analytic_nodes_per_ray"],
                      analytic_tests_per_ray=st["accel_analytic_tests_per_ray"],
                      triangle_tests_per_ray=st["accel_triangle_tests_per_ray"],
                      primitive_tests_per_ray=st["accel_primitive_tests_per_ray"],
                      triangles=st["triangles"], triangle_rows=st["triangle_references"], primitives=st["primitives"],
                      memory_estimate_mb=check_memory(r, scene, w, h, convert_options(r, {"accel": a})) / 2 ** 20)
    for a in ACCELS:
        out[a]["same_image_as_bvh"] = bool(np.array_equal(images[a], images["bvh"]))
    return out


def st_slow(scene) -> bool:
    """Brute force on a scene of many primitives: one run (it takes seconds)."""
    return len(scene.objects) > 100


def build_before_after(before: str, builds: int = 15, triangles: int = 0, keep: bool = False):
    """The build before (``before``, a git revision) and after, in one child process.  ``keep``
    (the smoke run): the exported revision stays in the system's temporary folder and the child
    uses this process's numba cache, so that a second run loads both builders compiled."""
    import workbench
    from workbench.renderers.raytrace.flatten import _Builder, _triangles
    scene = workbench.load_scene("mesh")
    b = _Builder(scene)
    for i, o in enumerate(scene.objects):
        b.leaf(o, i, np.eye(4), top=True)
    tri = np.ascontiguousarray(_triangles(b.meshes)[0])
    if triangles:
        tri = tri[:triangles]
    res = {"triangles": int(len(tri)), "before_revision": before, "builds": builds}
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "tri.npy"
        np.save(path, tri)
        old = Path(tempfile.gettempdir()) / f"workbench-bench-accel-{before}" if keep else Path(tmp) / "before"
        if not old.exists():
            part = Path(tempfile.mkdtemp(dir=old.parent, prefix=old.name + "-part-"))
            arch = subprocess.run(["git", "archive", before, "workbench"], cwd=ROOT, capture_output=True, check=True)
            subprocess.run(["tar", "-x", "-C", str(part)], input=arch.stdout, check=True)
            part.rename(old)
        env = dict(os.environ, PYTHONPATH=str(ROOT))
        if not keep:
            env["NUMBA_CACHE_DIR"] = str(Path(tmp) / "cache")
        p = subprocess.run([sys.executable, "-c", BUILD_CHILD, str(path),
                            str(old / "workbench" / "renderers" / "raytrace" / "bvh.py"), str(builds), str(triangles)],
                           capture_output=True, text=True, cwd=tmp, env=env)
        if p.returncode != 0:
            raise RuntimeError(p.stderr[-3000:])
        res.update(json.loads(p.stdout.strip().splitlines()[-1]))
    res["same_tree"] = res["before"]["tree_sha256"] == res["after"]["tree_sha256"]
    return res


def markdown(res) -> str:
    lines = [f"Ray casting at {res['size']}; load average {res['load_average_start'][0]:.1f} "
             f"at the start, {res['load_average_end'][0]:.1f} at the end, {res['machine']}.  No outside anchor: "
             "the baseline is `none` (every ray against every primitive) and, for the build, the code before "
             "the sampled binning.", ""]
    for name, rows in res["scenes"].items():
        lines += [f"## {name} ({rows['bvh']['triangles']} triangles, {rows['bvh']['primitives']} analytic primitives)", "",
                  "| accel | build (ms) | trace (ms) | trace: none / this | frame (ms) | nodes / ray (triangles + analytic) | "
                  "triangle tests / ray | analytic tests / ray | triangle rows | memory estimate (MiB) | same image | "
                  "statistics pass (ms) |",
                  "|---|---|---|---|---|---|---|---|---|---|---|---|"]
        for a in ACCELS:
            r = rows[a]
            lines.append(f"| {a} | {1e3 * r['build_s']:.1f} | {1e3 * r['trace_s']:.1f} | "
                         f"{rows['none']['trace_s'] / r['trace_s']:.1f} | {1e3 * r['frame_s']:.1f} | "
                         f"{r['triangle_nodes_per_ray']:.2f} + {r['analytic_nodes_per_ray']:.2f} | "
                         f"{r['triangle_tests_per_ray']:.1f} | {r['analytic_tests_per_ray']:.1f} | {r['triangle_rows']} | "
                         f"{r['memory_estimate_mb']:.0f} | {'yes' if r['same_image_as_bvh'] else 'NO'} | {1e3 * r['stats_pass_s']:.1f} |")
        lines.append("")
    b = res["bvh_build"]
    lines += [f"## BVH build, {b['triangles']} triangles (mesh scene), best / median of {b.get('builds', 15)}", "",
              "| code | wall (ms) | CPU (ms) | 4-wide nodes | leaves | SAH cost |", "|---|---|---|---|---|---|"]
    for k in ("before", "after"):
        r = b[k]
        lines.append(f"| {k}{' (' + b['before_revision'] + ')' if k == 'before' else ''} | "
                     f"{1e3 * r['wall_best_s']:.1f} / {1e3 * r['wall_median_s']:.1f} | "
                     f"{1e3 * r['cpu_best_s']:.1f} / {1e3 * r['cpu_median_s']:.1f} | {r['nodes_4wide']} | {r['leaves']} | "
                     f"{r['sah_cost']:.2f} |")
    lines += ["", f"Same tree before and after: {'yes' if b['same_tree'] else 'no'}; after / before wall time "
              f"(best): {b['after']['wall_best_s'] / b['before']['wall_best_s']:.2f}.", ""]
    return "\n".join(lines)


PAGE = Page("accel", "Acceleration structures of the ray tracer", first_paragraph(__doc__),
            "python bench/accel.py", markdown, smoke_note="32 x 24, one run, mesh and 200 spheres, 2 builds of 4,000 triangles")


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="160x120")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--before", default="7c5be9a")
    ap.add_argument("--spheres", default="1000,10000", help="sphere counts of the many-spheres scenes")
    args = PAGE.parse(ap, argv)
    builds, triangles = 15, 0
    if args.smoke:
        args.size, args.repeat, args.spheres, builds, triangles = "32x24", 1, "200", 2, 4000
    w, h = (int(x) for x in args.size.lower().split("x"))
    import workbench
    res = {"machine": f"{os.cpu_count()} CPUs (shared)", "load_average_start": os.getloadavg(), "size": f"{w}x{h}",
           "command": "python bench/accel.py " + " ".join(argv if argv is not None else sys.argv[1:])}
    t0 = time.perf_counter()
    for a in ACCELS:  # JIT or cache load of the kernels and the counting pass, outside the measurements
        workbench.render(many_scene(), "raycast", width=8, height=6, accel=a, traversal_stats=True)
    res["scenes"] = {"mesh": structures(workbench.load_scene("mesh"), w, h, args.repeat)}
    if not args.smoke:  # (the smoke run: one triangle scene, one of analytic spheres)
        res["scenes"]["many"] = structures(many_scene(), w, h, args.repeat)
    for n in (int(x) for x in args.spheres.split(",") if x):
        res["scenes"][f"spheres_{n}"] = structures(spheres_scene(n), w, h, args.repeat)
    res["bvh_build"] = build_before_after(args.before, builds, triangles, keep=args.smoke)
    res["load_average_end"] = os.getloadavg()
    res["bench_s"] = time.perf_counter() - t0
    print(markdown(res))
    return PAGE.write(args, res)


if __name__ == "__main__":
    main()
