"""POV-Ray 3.7 as an outside reference (method ``povray``): the scene exported by
:mod:`.povray_sdl`, rendered by the ``povray`` program (Debian package ``povray``) in a
temporary folder, read back as a linear float32 image.

Output: POV-Ray writes 16 bits per channel (``+FP16``, binary PPM: POV-Ray's 16-bit PNG carries
the same values, but Pillow reads 16-bit RGB PNGs as 8-bit) with ``File_Gamma=1.0`` and the
scene's ``assumed_gamma 1``: the file holds linear values ``round(65535 min(1, max(0, x)))``,
so the image is exact to 8e-6 within ``[0, 1]`` and clipped outside it (POV-Ray clips on
output; the workbench's own methods do not).  No depth image.

Options: ``max_trace_level`` (the knob: POV-Ray's, primary rays = level 1, like the ray
tracer's ``max_depth``), ``adc_bailout`` (POV-Ray's adaptive depth control, like the ray
tracer's ``threshold``; default the same 1e-3), ``antialias`` (POV-Ray's ``+A`` threshold, 0 =
one ray through each pixel centre, as the ray tracer with ``spp = 1``), ``blinn``,
``threads`` and ``on_progress(phase, done, total, unit)``: with it POV-Ray runs verbose
(``+V``) and its own report is passed on while it runs (:func:`progress_report`: parsing,
which says no amount done, then "Rendered N of M pixels" as each block is done).  Timings: ``export`` (writing the SDL), ``parse`` and ``trace`` (POV-Ray's own
statistics), ``read``; stats: POV-Ray's ray counts.
"""
from __future__ import annotations

import os
import re
import shutil
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np

from ..core.errors import WorkbenchError
from ..scene import features as ft
from ..scene.model import Mesh, Scene
from . import povray_sdl
from . import support as sp
from .base import Knob, Option, RenderResult, callback
from .watch import Tail, relay, run_watched

PROGRAM = "povray"
TIMEOUT_S = 3600
_SDL_BYTES_PER_VERTEX = 120
"""Text of one mesh vertex (position, normal, uv) and face in the exported SDL, generously."""


def read_ppm16(data: bytes) -> np.ndarray:
    """A binary PPM (``P6``, maxval up to 65535) as (H, W, 3) float64 in [0, 1], top row first.
    POV-Ray writes comment lines in the header."""
    head = re.match(rb"P6\s+(?:#[^\n]*\n\s*)*(\d+)\s+(?:#[^\n]*\n\s*)*(\d+)\s+(?:#[^\n]*\n\s*)*(\d+)\s",
                    data)
    if head is None:
        raise WorkbenchError("POV-Ray's output is not a binary PPM image")
    w, h, maxval = (int(x) for x in head.groups())
    dtype = ">u2" if maxval > 255 else "u1"
    n = w * h * 3
    pix = np.frombuffer(data, dtype=dtype, count=n, offset=head.end())
    return pix.reshape(h, w, 3).astype(np.float64) / maxval


RENDERED = re.compile(r"Rendered (\d+) of (\d+) pixels")


def progress_report(lines: list[str], last: tuple | None) -> tuple | None:
    """The latest (phase, done, total, unit) that POV-Ray's verbose output ``lines`` (``+V``,
    standard error) tells, after ``last``: ``("POV-Ray parsing", 0, None, "")`` from its
    "[Parsing...]" banner (parsing reports no amount done), ``("POV-Ray rendering", 0, None,
    "")`` from its "[Rendering...]" banner, ``("POV-Ray rendering", N, M, "pixels")`` from its
    "Rendered N of M pixels" lines; ``last`` when they tell nothing new."""
    for line in lines:
        hit = RENDERED.search(line)
        if hit:
            last = ("POV-Ray rendering", int(hit.group(1)), int(hit.group(2)), "pixels")
        elif "[Parsing" in line:
            last = ("POV-Ray parsing", 0, None, "")
        elif "[Rendering" in line:
            last = ("POV-Ray rendering", 0, None, "")
    return last


def _stat(log: str, pattern: str) -> float:
    hit = re.search(pattern, log)
    return float(hit.group(1)) if hit else 0.0


def _mesh_elements(o) -> int:
    if isinstance(o, Mesh):
        return len(o.vertices) + len(o.faces)
    kids = [o.left, o.right] if getattr(o, "kind", "") == "csg" else []
    return sum(_mesh_elements(k) for k in kids)


POVRAY_PROCESS_BYTES = 32 * 2**20
"""Base memory of a POV-Ray 3.7 process (its resident set, rounded up)."""

class PovrayRenderer:
    """The registered ``povray`` method (see the module docstring)."""

    name = "povray"
    ui_kind = "cpu"
    support = sp.declare(
        approximated={ft.TEXTURES: "patterns POV-Ray cannot express are exported as their plain colour",
                      ft.AREA_LIGHTS: "stand-in point lights without their cosine lobe",
                      ft.SHADOWS: "transmissive occluders attenuate shadows by kt (filtered shadows)"},
        left_out={ft.BUMP: "bump maps not exported to POV-Ray",
                  ft.OPACITY: "opacity maps not exported to POV-Ray",
                  ft.ENVIRONMENT: "environment mapping and the scene's environment not exported "
                                  "(escaping rays see the background colour)",
                  ft.ABSORPTION: "Beer-Lambert absorption not exported to POV-Ray",
                  ft.TEXELS: "POV-Ray has no texel model: the fur's base is exported without its fur",
                  ft.HYPERTEXTURES: "not exported: POV-Ray's noise differs from ours, and its df3 density "
                                    "file interpolates samples at j/S with periodic wrap (our grid: cell "
                                    "centres, clamped edges)"})
    knob = Knob("max_trace_level", (1, 2, 3, 4, 5, 6, 8, 12), 5,
                "POV-Ray's max_trace_level (primary = 1, as the ray tracer's max_depth)")
    options = {
        "max_trace_level": Option(int, 5, "POV-Ray's max_trace_level, 1..256 (primary rays = 1)"),
        "adc_bailout": Option(float, 1e-3, "POV-Ray's adc_bailout: rays of smaller weight are not traced (>= 0)"),
        "antialias": Option(float, 0.0, "POV-Ray's +A threshold (0 = off: one ray through each pixel centre)"),
        "blinn": Option(bool, False, "specular as POV-Ray's specular/roughness 1/n (Blinn) instead of phong/phong_size n"),
        "threads": Option(int, 0, "POV-Ray's Work_Threads (0 = POV-Ray's default: one per core)"),
        "on_progress": Option(callback, None, "callback on_progress(phase, done, total, unit) with "
                              "POV-Ray's own report while it runs (total None: no amount reported)"),
    }

    memory_options = ("max_trace_level",)

    def estimate_bytes(self, scene: Scene, width: int, height: int, **options) -> int:
        """Bytes a render needs: the 16-bit output file and its float64 and float32 copies (3
        channels), the SDL text of the meshes, and the POV-Ray process (a base of
        :data:`POVRAY_PROCESS_BYTES`, 19 MB measured for a one-sphere scene at 320x240, plus its
        own copy of the meshes and a float image buffer)."""
        pixels = int(width) * int(height) * 3
        sdl = sum(_mesh_elements(o) for o in scene.objects) * _SDL_BYTES_PER_VERTEX
        return pixels * (2 + 8 + 4 + 16) + 2 * sdl + POVRAY_PROCESS_BYTES

    def render(self, scene: Scene, width: int, height: int, *, max_trace_level: int = 5,
               adc_bailout: float = 1e-3, antialias: float = 0.0, blinn: bool = False,
               threads: int = 0, on_progress=None) -> RenderResult:
        if not 1 <= max_trace_level <= 256:
            raise WorkbenchError(f"method 'povray': option 'max_trace_level' must be within 1..256, got {max_trace_level}")
        if adc_bailout < 0 or antialias < 0 or threads < 0:
            raise WorkbenchError("method 'povray': options 'adc_bailout', 'antialias' and 'threads' must be >= 0")
        exe = shutil.which(PROGRAM)
        if exe is None:
            raise WorkbenchError("method 'povray' needs the POV-Ray 3.7 program 'povray' on PATH "
                                 "(Debian package povray)")
        t0 = time.perf_counter()
        ex = povray_sdl.export(scene, width, height, max_trace_level=max_trace_level,
                               adc_bailout=adc_bailout, blinn=blinn)
        timings = {"export": time.perf_counter() - t0, "compile": 0.0}
        with tempfile.TemporaryDirectory(prefix="workbench-povray-") as tmp:
            d = Path(tmp)
            (d / "scene.pov").write_text(ex.sdl, encoding="utf-8")
            for name, src in ex.files.items():  # POV-Ray reads files in its working folder
                shutil.copyfile(src, d / name)
            cmd = [exe, "+Iscene.pov", "+Oimage.ppm", f"+W{width}", f"+H{height}", "+FP16",
                   "File_Gamma=1.0", "-D", "-P", "+V" if on_progress else "-V", "+GS", "+MV3.7"]
            cmd.append(f"+A{antialias:.6g}" if antialias > 0 else "-A")
            if threads > 0:
                cmd.append(f"Work_Threads={threads}")
            env = dict(os.environ, HOME=tmp)  # no user configuration file, and no warning about it
            said = Tail(d / "stderr.log")
            poll = relay(lambda last: progress_report(said.lines(), last), on_progress,
                         ("POV-Ray starting", 0, None, ""))
            t1 = time.perf_counter()
            try:
                code, out_text, err_text = run_watched(cmd, d, env, TIMEOUT_S, poll)
            except subprocess.TimeoutExpired:
                raise WorkbenchError(f"method 'povray': POV-Ray did not finish within {TIMEOUT_S} s") from None
            timings["povray_process"] = time.perf_counter() - t1
            log = out_text + err_text
            out = d / "image.ppm"
            if code != 0 or not out.is_file():
                tail = " | ".join(line.strip() for line in re.split(r"[\r\n]+", log.strip())[-6:])
                raise WorkbenchError(f"method 'povray': POV-Ray failed (exit {code}): {tail}")
            t2 = time.perf_counter()
            image = read_ppm16(out.read_bytes()).astype(np.float32)
            timings["read"] = time.perf_counter() - t2
        timings["parse"] = _stat(log, r"Parse Time:.*\(\s*([\d.]+) seconds\)")
        timings["trace"] = _stat(log, r"Trace Time:.*\(\s*([\d.]+) seconds\)")
        stats = {"povray_version": (re.search(r"POV-Ray (\d[\w.\-]*)", log) or [None, "?"])[1],
                 "rays": int(_stat(log, r"Rays:\s+(\d+)")),
                 "shadow_ray_tests": int(_stat(log, r"Shadow Ray Tests:\s+(\d+)")),
                 "reflected_rays": int(_stat(log, r"Reflected Rays:\s+(\d+)")),
                 "refracted_rays": int(_stat(log, r"Refracted Rays:\s+(\d+)")),
                 "sdl_bytes": len(ex.sdl)}
        needs = ft.scene_needs(scene)
        left = sp.complete(self.support, needs, ex.left_out)
        if ft.SHADOWS in needs and any(mt.kt > 0 for mt in scene.materials.values()):
            left.append(sp.Note(ft.SHADOWS, "transmissive occluders attenuate shadows by kt (POV-Ray's "
                                "filtered shadows: the ray tracer's transmissive_shadows = true)",
                                sp.Status.APPROXIMATED))
        used = sp.used(needs, left)
        return RenderResult(self.name, image, timings, stats, used, left)
