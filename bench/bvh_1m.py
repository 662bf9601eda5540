"""BVH build time and peak memory for a mesh of about 1M triangles (target: a few seconds,
under 1 GB).

The mesh is the procedural blob at 8 subdivisions (20 * 4^8 = 1,310,720 triangles).  The
build the ray tracer runs (binned SAH, collapsed to 4-wide nodes, leaves packed by four:
:func:`workbench.renderers.raytrace.bvh.build_bvh4`) runs in a child process that
first loads the triangles and compiles (or loads from the numba cache) the builder on a tiny
input, so that its peak resident memory before the build is the baseline; the peak after the
build minus that baseline is the build's own peak memory.  Also traces 640 x 480 primary rays
against it (closest hit through the BVH) for a rays/s figure.

Writes ``bench/results/bvh_1m.json`` and ``docs/benchmarks/bvh_1m.md`` and prints it.  Run:
``.venv/bin/python bench/bvh_1m.py``; ``--smoke``: the blob at 3 subdivisions (1,280 triangles), 64 x 48 rays.
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from _common import Page, first_paragraph, kv_table

ROOT = Path(__file__).resolve().parents[1]

CHILD = r"""
import json, resource, sys, time
import numpy as np
from workbench.renderers.raytrace.bvh import build_bvh4
tri = np.load(sys.argv[1])
build_bvh4(tri[:64])  # JIT or cache load, outside the measurement
base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
t0 = time.perf_counter()
order, bvh = build_bvh4(tri)
dt = time.perf_counter() - t0
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
print(json.dumps(dict(build_s=dt, baseline_rss_mb=base / 1024, peak_rss_mb=peak / 1024,
                      build_peak_extra_mb=(peak - base) / 1024, nodes_4wide=int(len(bvh.node)),
                      leaves=int(len(bvh.leaf)), groups_of_4=int(len(bvh.first)),
                      bvh_bytes_mb=(sum(a.nbytes for a in bvh) + order.nbytes) / 2**20,
                      triangles_mb=tri.nbytes / 2**20)))
"""


def tables(res: dict) -> str:
    r = res.get("render_640x480_primary", {})
    size = res.get("render_size", "640x480")
    return kv_table([
        ("triangles", res["triangles"]), ("mesh generation (s)", res.get("mesh_generation_s")),
        ("BVH build (s; target: a few seconds)", res["build_s"]),
        ("build's own peak memory (MB; target: under 1 GB)", res["build_peak_extra_mb"]),
        ("peak resident memory of the build process (MB)", res["peak_rss_mb"]),
        ("4-wide nodes / leaves", f"{res['nodes_4wide']} / {res['leaves']}"),
        ("BVH arrays + order (MB) / triangles (MB)", f"{res['bvh_bytes_mb']:.1f} / {res['triangles_mb']:.1f}"),
        (f"render {size} primary rays: trace (s)", r.get("trace_s")),
        (f"render {size}: BVH build inside the render (s)", r.get("bvh_build_in_render_s")),
        (f"render {size}: Mrays/s", r.get("mrays_per_s")),
    ]) + "\nNo outside anchor: the targets of the issue are the yardstick.\n"


PAGE = Page("bvh_1m", "BVH build time and peak memory, about 1M triangles", first_paragraph(__doc__),
            "python bench/bvh_1m.py", tables, smoke_note="1,280 triangles, 64 x 48 rays")


def main(argv=None) -> dict:
    import time

    import os

    import workbench
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--subdivisions", type=int, default=8, help="of the blob (8: 1,310,720 triangles)")
    args = PAGE.parse(ap, argv)
    W, H = (64, 48) if args.smoke else (640, 480)
    if args.smoke:
        args.subdivisions = 3
    from workbench.scene.generate import generate_mesh
    from workbench.scene.io import scene_from_dict
    load_start = os.getloadavg()
    t0 = time.perf_counter()
    mesh = generate_mesh("blob", subdivisions=args.subdivisions)
    gen_s = time.perf_counter() - t0
    V, F = np.asarray(mesh.vertices), np.asarray(mesh.faces)
    tri = np.ascontiguousarray(V[F].reshape(-1, 9))
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "tri.npy"
        np.save(path, tri)
        p = subprocess.run([sys.executable, "-c", CHILD, str(path)], capture_output=True, text=True, cwd=ROOT)
        if p.returncode != 0:
            raise RuntimeError(p.stderr[-3000:])
        res = json.loads(p.stdout.strip().splitlines()[-1])
    res.update(machine=f"{os.cpu_count()} CPUs (shared)", load_average_start=load_start,
               triangles=int(len(F)), mesh_generation_s=gen_s)
    # primary rays against the 1.3M-triangle mesh (BVH built inside the render: timings)
    from workbench.scene import model as m
    sc = scene_from_dict({"camera": {"position": [0, 0.5, -3.5], "look_at": [0, 0, 0], "resolution": [W, H]},
                          "materials": {"clay": {"color": [0.75, 0.55, 0.4]}},
                          "objects": [{"type": "sphere", "radius": 0.01, "material": "clay"}]})
    from dataclasses import replace
    blob = m.Mesh("clay", vertices=V, faces=F, normals=np.asarray(mesh.vertex_normals))
    sc = replace(sc, objects=(blob,))
    r = workbench.render(sc, "raycast")
    res["render_size"] = f"{W}x{H}"
    res["render_640x480_primary"] = dict(trace_s=r.timings["trace"], bvh_build_in_render_s=r.timings["bvh_build"],
                                         mrays_per_s=r.stats["mrays_per_s"], rays=r.stats["total_rays"])
    res["load_average_end"] = os.getloadavg()
    print(json.dumps(res, indent=2))
    return PAGE.write(args, res)


if __name__ == "__main__":
    main()
