"""The ray tracer's BVH build and primary rays against Embree 4 (the package ``embreex``) on
the bundled ``mesh`` scene's 81,920 triangles and camera, in one run (issue #28, item 3).

1. Build.  Ours: :func:`workbench.renderers.raytrace.bvh.build_bvh4`, the build the renderer
   runs (binned SAH over the triangles' boxes, the root's two subtrees on two threads, then
   collapsed to 4-wide nodes and the leaves' triangles packed by four), from the world-space
   triangles ``(T, 9)`` float64.  Embree: a new ``EmbreeScene`` on one device created
   beforehand, a ``TriangleMesh`` of the same triangles (indexed: float32 vertices, int32
   faces, made beforehand) and the scene's commit, which is where Embree builds its BVH
   (embreex commits on the first ``run``: one ray is traced for it); Embree's default build
   for a static scene, on its TBB threads.
2. Primary rays.  The camera rays of the ``mesh`` scene's camera at ``--size`` (pixel
   centres, :meth:`workbench.scene.model.Camera.rays`) against the mesh alone (the scene's
   floor is left out: Embree gets only triangles).  Ours: the ray caster's closest-hit kernel
   ``trace_batch`` (:mod:`workbench.renderers.raytrace.kernels`: the BVH walk of
   :mod:`workbench.renderers.kernels.walks` and the hit's geometric normal), as the
   public ``workbench.raytrace.intersect`` calls it (its arrays allocated), on numba's
   thread count of Python threads (:func:`workbench.renderers.kernels.tasks.run_tasks`), warm.  Embree:
   ``EmbreeScene.run(origins, directions, output=1)`` (distance, barycentrics, geometric
   normal and triangle of each ray, one ``rtcIntersect1`` per ray on one thread), the same
   rays in float32.  Also ours without the surface data: ``kernels.intersect.closest`` alone
   over the rays (:func:`closest_kernel`), the traversal nearer to what ``run`` does, and
   ``trace_batch`` with the whole surface data (shading normal, uv,
   object-space point, vertex emission).  The hits are compared (hit or miss per ray; distance within a relative
   ``T_RTOL``; geometric normals parallel), so that both answer the same question.

Each quantity is measured ``--runs`` times, Embree's and ours alternating (A B A B: the
machine is shared and its load comes and goes; our three ray measurements take turns at running
first after Embree's, whose run leaves the caches holding its own tree: the one run right
after another of ours over the same rays and tree measured 3-8 % more rays per CPU-second,
on a loaded machine), wall and CPU seconds (``time.process_time``:
every thread of this process, so Embree's TBB threads and numba's alike); the tables give the
medians and their ratios.  Rays per CPU-second is the fair figure on a loaded machine with
threads on one side and one thread on the other; on an idle one the CPU seconds also count the
time thread pools spend waiting actively for work (Embree's TBB workers after a build; numba's
OpenMP workers, GNU libgomp, after a ``prange`` kernel unless ``OMP_WAIT_POLICY=passive`` is
set in the environment before the run, recorded in the results: our kernels here run on Python
threads, which sleep when they wait), so that CPU can exceed wall times the threads at work.  Timing is never a pass/fail test.

Writes ``bench/results/embree.json`` and ``docs/benchmarks/embree.md``.  Run:
``.venv/bin/python bench/embree.py [--size 640x480] [--runs 7]``.  Without ``embreex`` our side
is measured alone (its columns skipped).  ``--smoke``: 64 x 48 rays, 2 runs each.
"""
from __future__ import annotations

import argparse
import os
import time
from dataclasses import replace

import numpy as np
from _common import Page, first_paragraph, fmt, ratio, skip_note, table

T_RTOL = 1e-4
"""Relative distance tolerance of two hits of the same ray (Embree's rays and triangles are in
float32: about 1e-7 relative each)."""
COS_MIN = 0.999
"""Two hits' geometric normals count as parallel above this |cos| (the same triangle, or one
of a smooth mesh's neighbours across an edge the ray grazes)."""


def mesh_triangles(scene):
    """World-space triangles ``(T, 9)`` float64 of ``scene``'s meshes, as the renderer flattens
    them (the objects' transforms applied)."""
    from workbench.renderers.raytrace.flatten import _Builder, _triangles
    b = _Builder(scene)
    for i, o in enumerate(scene.objects):
        b.leaf(o, i, np.eye(4), top=True)
    return np.ascontiguousarray(_triangles(b.meshes)[0])


def indexed(tri):
    """The triangle soup ``(T, 9)`` as float32 vertices ``(V, 3)`` (shared corners merged) and
    int32 faces ``(T, 3)``, Embree's usual input."""
    corners = tri.reshape(-1, 3).astype(np.float32)
    V, inv = np.unique(corners, axis=0, return_inverse=True)
    return np.ascontiguousarray(V), np.ascontiguousarray(inv.reshape(-1, 3).astype(np.int32))


def timed(fn):
    """``(result, wall seconds, CPU seconds)`` of ``fn()``."""
    t0, c0 = time.perf_counter(), time.process_time()
    out = fn()
    return out, time.perf_counter() - t0, time.process_time() - c0


def median_of(runs: list[dict]) -> dict:
    return {k: float(np.median([r[k] for r in runs])) for k in runs[0]}


class EmbreeSide:
    """Embree through embreex: the device is made once; each build is a new scene."""

    def __init__(self):
        from embreex import rtcore, rtcore_scene
        from embreex.mesh_construction import TriangleMesh
        self.scene_cls, self.mesh_cls = rtcore_scene.EmbreeScene, TriangleMesh
        self.device = rtcore.EmbreeDevice()
        text = repr(self.device)  # "Embree version:  4.4.0"
        self.embree_version = text.split(":")[-1].strip() if "version" in text.lower() else None
        self._o = np.zeros((1, 3), np.float32)
        self._d = np.array([[0.0, 0.0, 1.0]], np.float32)

    def build(self, V, F):
        """A committed scene of the mesh (embreex commits on the first ``run``), and the wall
        and CPU seconds of its two steps: ``mesh`` (the scene and embreex's ``TriangleMesh``,
        which copies the arrays into Embree's buffers) and ``commit`` (Embree's BVH build)."""
        t0, c0 = time.perf_counter(), time.process_time()
        sc = self.scene_cls(self.device)
        self.mesh_cls(sc, V, F)
        t1, c1 = time.perf_counter(), time.process_time()
        sc.run(self._o, self._d)
        t2, c2 = time.perf_counter(), time.process_time()
        return sc, dict(commit_wall_s=t2 - t1, commit_cpu_s=c2 - c1, mesh_wall_s=t1 - t0, mesh_cpu_s=c1 - c0,
                        wall_s=t2 - t0, cpu_s=c2 - c0)

    @staticmethod
    def trace(sc, O32, D32):
        return sc.run(O32, D32, output=1)


class OurSide:
    """The ray caster's arrays of the mesh alone, and its closest-hit kernel."""

    def __init__(self, scene):
        from workbench.core.tol import tol
        from workbench.renderers.raytrace.flatten import flatten
        from workbench.renderers.raytrace.whitted import _alloc, _kernels
        self.tol, self.alloc, self.kernels = tol, _alloc, _kernels()
        self.sd = flatten(scene)
        self.geo = self.sd.kernel_args()

    def closest(self, O, D):
        """:func:`closest_kernel` over the rays: ``(t, triangle)``."""
        if not hasattr(self, "_closest"):
            self._closest = closest_kernel()
        n = len(O)
        t, tri = np.empty(n), np.empty(n, np.int64)
        self._closest(self.geo, O, D, self.tol.zero, self.tol.ray_offset, self.sd.extent, t, tri)
        return t, tri

    def trace(self, O, D, surface=False):
        """``trace_batch`` over the rays as ``intersect`` calls it (the geometric normal alone),
        or with ``surface``, the whole surface data (shading normal, uv, object
        point, vertex emission)."""
        n = len(O)
        h = self.alloc(n, surface)
        self.kernels.trace_batch(self.geo, O, D, np.zeros(n), np.full(n, np.inf), self.tol.zero,
                                 self.tol.ray_offset, self.sd.extent, self.tol.normal_cancel, False, h["t"],
                                 h["prim"], h["ng"], h["ns"], h["uv"], h["po"], h["ev"])
        return h


def closest_kernel():
    """A kernel of the closest hits alone: ``kernels.intersect.closest`` (the function
    ``trace_batch`` calls for each ray) over the rays, writing ``t`` and the triangle, without
    the surface data; run as ``trace_batch`` is (runs of consecutive chunks of 64 rays handed
    out to numba's thread count of Python threads, :func:`workbench.renderers.kernels.tasks.run_tasks`).
    Built here (not cached: a few seconds to compile)."""
    import numba as nb

    from workbench.renderers.kernels.intersect import closest, scratch
    from workbench.renderers.kernels.tasks import run_tasks
    from workbench.renderers.raytrace.kernels import MAX_TASKS

    @nb.njit(nogil=True, error_model="numpy")
    def closest_task(geo, O, D, zero, rel_eps, extent, t_out, tri_out, c, nit):
        n = O.shape[0]
        nch = (n + 63) // 64
        stack, st, sp_, sf, sn = scratch()
        for i in range(c * nch // nit * 64, min(n, (c + 1) * nch // nit * 64)):
            ox, oy, oz = O[i, 0], O[i, 1], O[i, 2]
            eps = rel_eps * max(max(abs(ox), abs(oy), abs(oz)), extent)
            t, k, f, tri, b1, b2, _, _, _ = closest(geo, ox, oy, oz, D[i, 0], D[i, 1], D[i, 2], 0.0, np.inf,
                                           np.bool_(False), np.bool_(False), np.bool_(False), zero, eps, stack, st,
                                           sp_, sf, sn)
            t_out[i], tri_out[i] = t, tri

    def closest_only(geo, O, D, zero, rel_eps, extent, t_out, tri_out):
        run_tasks(closest_task, max(1, min((len(O) + 63) // 64, MAX_TASKS)), geo, O, D, zero, rel_eps, extent,
                  t_out, tri_out)
    return closest_only


def compare_hits(ours: dict, emb: dict) -> dict:
    """Hit or miss, distance and geometric normal of each ray, ours against Embree's."""
    hit_o = ours["prim"] >= 0
    hit_e = emb["primID"] >= 0
    both = hit_o & hit_e
    t_o = ours["t"][both]
    t_e = emb["tfar"][both].astype(np.float64)
    rel = np.abs(t_o - t_e) / np.maximum(t_o, 1e-300)
    ng_e = emb["Ng"][both].astype(np.float64)
    ng_e /= np.maximum(np.linalg.norm(ng_e, axis=1, keepdims=True), 1e-300)
    cos = np.abs(np.einsum("ij,ij->i", ours["ng"][both], ng_e))
    n = len(hit_o)
    mism = int((hit_o != hit_e).sum())
    out = dict(rays=int(n), hits_ours=int(hit_o.sum()), hits_embree=int(hit_e.sum()),
               hit_mask_mismatches=mism, hit_mask_agreement=float(1.0 - mism / max(n, 1)),
               t_rel_diff_max=float(rel.max()) if len(rel) else 0.0,
               t_rel_diff_p999=float(np.quantile(rel, 0.999)) if len(rel) else 0.0,
               t_within_tol=float((rel <= T_RTOL).mean()) if len(rel) else 1.0,
               normals_parallel=float((cos >= COS_MIN).mean()) if len(cos) else 1.0,
               t_rtol=T_RTOL, cos_min=COS_MIN)
    # the same answers: at most 1 ray in 10^4 differs in hit or miss (a silhouette ray, where the
    # float32 vertices move an edge), and 99.9 % of the common hits agree in distance
    out["same_hits"] = bool(mism <= max(1, 1e-4 * n) and out["t_within_tol"] >= 0.999)
    return out


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="640x480", help="camera rays, WIDTHxHEIGHT")
    ap.add_argument("--runs", type=int, default=7, help="alternating runs of each side (at least 5 for a result)")
    args = PAGE.parse(ap, argv)
    if args.smoke:
        args.size, args.runs = "64x48", 2
    w, h = (int(x) for x in args.size.lower().split("x"))
    import numba

    import workbench
    from workbench.renderers.raytrace.bvh import PARALLEL_MIN, build_bvh4
    scene = workbench.load_scene("mesh")
    tri = mesh_triangles(scene)
    meshes = tuple(o for o in scene.objects if type(o).__name__ == "Mesh")
    mesh_scene = replace(scene, objects=meshes, camera=scene.camera.with_resolution(w, h))
    V32, F32 = indexed(tri)
    O, D = (np.ascontiguousarray(a.reshape(-1, 3)) for a in mesh_scene.camera.rays())
    O32, D32 = O.astype(np.float32), D.astype(np.float32)
    emb = None
    if PAGE.anchor(args, "embreex") is not None:
        try:
            emb = EmbreeSide()
        except ImportError as e:  # a broken install counts as absent
            print(f"embree: {skip_note('embreex')} ({e})", flush=True)
    res = dict(scene="mesh", triangles=int(len(tri)), vertices_embree=int(len(V32)), size=f"{w}x{h}",
               rays=int(len(O)), runs=args.runs, numba_threads=int(numba.get_num_threads()),
               omp_wait_policy=os.environ.get("OMP_WAIT_POLICY", "(unset)"),
               embree_version=emb.embree_version if emb else None)

    # ---- 1. build, alternating
    build_bvh4(tri[:2 * PARALLEL_MIN])  # JIT or cache load (of the two-thread path too), outside the measurement
    if emb:
        emb.build(V32, F32)
    b_ours, b_emb = [], []
    for _ in range(args.runs):
        if emb:
            b_emb.append(emb.build(V32, F32)[1])
        _, wall, cpu = timed(lambda: build_bvh4(tri))
        b_ours.append(dict(wall_s=wall, cpu_s=cpu))
    res["build"] = dict(ours=median_of(b_ours), ours_runs=b_ours,
                        embree=median_of(b_emb) if emb else None, embree_runs=b_emb)

    # ---- 2. primary rays, alternating (both warm: one untimed pass first)
    ours = OurSide(mesh_scene)
    h_ours = ours.trace(O, D)
    try:  # the one loaded by a prange kernel; none if none ran
        res["numba_threading_layer"] = numba.threading_layer()
    except ValueError:
        res["numba_threading_layer"] = "none"
    t_c, _ = ours.closest(O, D)
    res["closest_only_same_t"] = bool(np.array_equal(t_c, np.where(h_ours["prim"] >= 0, h_ours["t"], np.inf)))
    if emb:
        sc = emb.build(V32, F32)[0]
        h_emb = emb.trace(sc, O32, D32)
        res["hits"] = compare_hits(h_ours, h_emb)
    r_ours, r_emb, r_cl, r_full = [], [], [], []
    n = len(O)
    ours_fns = ((r_ours, lambda: ours.trace(O, D)), (r_cl, lambda: ours.closest(O, D)),
                (r_full, lambda: ours.trace(O, D, surface=True)))
    for run in range(args.runs):
        if emb:
            _, wall, cpu = timed(lambda: emb.trace(sc, O32, D32))
            r_emb.append(dict(wall_s=wall, cpu_s=cpu, mrays_per_s=n / wall / 1e6,
                              mrays_per_cpu_s=n / max(cpu, 1e-9) / 1e6))
        for k in range(len(ours_fns)):  # our three in turn first after Embree's (its caches' state)
            runs, fn = ours_fns[(run + k) % len(ours_fns)]
            _, wall, cpu = timed(fn)
            runs.append(dict(wall_s=wall, cpu_s=cpu, mrays_per_s=n / wall / 1e6,
                             mrays_per_cpu_s=n / max(cpu, 1e-9) / 1e6))
    res["primary"] = dict(ours=median_of(r_ours), ours_runs=r_ours,
                       embree=median_of(r_emb) if emb else None, embree_runs=r_emb,
                       ours_closest=median_of(r_cl), ours_closest_runs=r_cl,
                       ours_surface=median_of(r_full), ours_surface_runs=r_full)
    print(tables(res), flush=True)
    return PAGE.write(args, res)


def tables(res: dict) -> str:
    bo, be = res["build"]["ours"], res["build"]["embree"] or {}
    ro, re_ = res["primary"]["ours"], res["primary"]["embree"] or {}
    runs = res["runs"]
    anchor = (f"Embree {res['embree_version']}" if res.get("embree_version") else "Embree") + " (embreex)"
    lines = [f"Mesh scene: {res['triangles']} triangles; {res['rays']} camera rays ({res['size']}); "
             f"medians of {runs} runs each, Embree's and ours alternating; numba threads: "
             f"{res.get('numba_threads')} (threading layer {res.get('numba_threading_layer', '?')}, "
             f"OMP_WAIT_POLICY {res.get('omp_wait_policy', '?')}).  The ratio columns are ours over Embree's (time: below 1 is "
             "faster; rate: above 1 is faster).", "",
             "## BVH build", "",
             table(["", "ours: build_bvh4 (ms)", f"{anchor}: commit (ms)", "ours / Embree",
                    "Embree: embreex's TriangleMesh (ms)", "ours / Embree's commit + TriangleMesh"],
                   [[k, 1e3 * bo[f"{x}_s"], _ms(be.get(f"commit_{x}_s")), ratio(bo[f"{x}_s"], be.get(f"commit_{x}_s")),
                     _ms(be.get(f"mesh_{x}_s")), ratio(bo[f"{x}_s"], be.get(f"{x}_s"))]
                    for k, x in (("wall", "wall"), ("CPU", "cpu"))]),
             "The commit is Embree's BVH build; embreex's `TriangleMesh` copies the vertex and face "
             "arrays into Embree's buffers in the wrapper's own loops (no Embree work): a cost of the "
             "binding, shown apart.", "",
             "## Primary rays (closest hit)", "",
             table(["", "ours: trace_batch (t, primitive, geometric normal)", f"{anchor}: run(output=1)",
                    "ours / Embree"],
                   [["M rays per CPU-second", ro["mrays_per_cpu_s"], re_.get("mrays_per_cpu_s"),
                     ratio(ro["mrays_per_cpu_s"], re_.get("mrays_per_cpu_s"))],
                    ["M rays per second (wall)", ro["mrays_per_s"], re_.get("mrays_per_s"),
                     ratio(ro["mrays_per_s"], re_.get("mrays_per_s"))],
                    ["wall (ms)", 1e3 * ro["wall_s"], 1e3 * re_["wall_s"] if re_ else None, ratio(ro["wall_s"], re_.get("wall_s"))],
                    ["CPU (ms)", 1e3 * ro["cpu_s"], 1e3 * re_["cpu_s"] if re_ else None, ratio(ro["cpu_s"], re_.get("cpu_s"))]])]
    rc, rs = res["primary"].get("ours_closest"), res["primary"].get("ours_surface")
    if rc:
        rows = [("closest only", rc)] + ([("trace_batch with the whole surface data", rs)] if rs else [])
        lines += ["`trace_batch` as `workbench.raytrace.intersect` calls it (above: the distance, the "
                  "primitive and the geometric normal of each hit, as Embree's `run(output=1)` gives "
                  "them, with barycentrics); below, the closest hits alone (`kernels.intersect.closest`, "
                  "the function `trace_batch` calls for each ray; the same distances: "
                  f"{fmt(res.get('closest_only_same_t'))}) and `trace_batch` with the whole surface data "
                  "of a hit (shading normal, uv, object-space point, vertex emission: "
                  "the arrays of every ray allocated, the hit triangle's normals, uv and emission read):", "",
                  table(["ours", "M rays per CPU-second", "ours / Embree", "M rays per second (wall)",
                         "ours / Embree"],
                        [[name, r["mrays_per_cpu_s"], ratio(r["mrays_per_cpu_s"], re_.get("mrays_per_cpu_s")),
                          r["mrays_per_s"], ratio(r["mrays_per_s"], re_.get("mrays_per_s"))]
                         for name, r in rows])]
    hits = res.get("hits")
    if hits:
        lines += ["## Same hits?", "",
                  table(["rays", "hits: ours / Embree", "hit or miss differs", "distance within "
                         f"{fmt(hits['t_rtol'])} (relative)", "largest relative distance difference",
                         f"normals parallel (abs cos >= {hits['cos_min']})", "same hits"],
                        [[hits["rays"], f"{hits['hits_ours']} / {hits['hits_embree']}", hits["hit_mask_mismatches"],
                          f"{100 * hits['t_within_tol']:.3f} %", hits["t_rel_diff_max"],
                          f"{100 * hits['normals_parallel']:.3f} %", hits["same_hits"]]])]
    else:
        lines += ["Embree absent: only our side was measured.", ""]
    cols = ((res["build"]["embree_runs"], "commit_"), (res["build"]["ours_runs"], ""),
            (res["primary"]["embree_runs"], ""), (res["primary"]["ours_runs"], ""))
    lines += ["Every run, in the order run (ms, wall / CPU):", "",
              table(["run", "build: Embree's commit", "build: ours", "rays: Embree", "rays: ours"],
                    [[i + 1] + [f"{1e3 * xs[i][p + 'wall_s']:.1f} / {1e3 * xs[i][p + 'cpu_s']:.1f}"
                                if i < len(xs) else "–" for xs, p in cols]
                     for i in range(runs)])]
    return "\n".join(lines)


def _ms(s):
    return None if s is None else 1e3 * s


PAGE = Page("embree", "BVH build and primary rays against Embree 4", first_paragraph(__doc__),
            "python bench/embree.py", tables, anchors=("embreex",), smoke_note="64 x 48 rays, 2 runs each")


if __name__ == "__main__":
    main()
