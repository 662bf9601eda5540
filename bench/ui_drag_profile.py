"""Where a frame of a camera drag goes: wall and CPU milliseconds per stage of the UI's frame
(three 512 px GL panels, flat / Gouraud / Phong, the ``fps`` script's drag, Xvfb + llvmpipe).

The window runs in this process (``workbench.app.ui.main.run``) with hello_imgui's callbacks
and every dockable window's gui function wrapped by a timer:

* ``poll+idle``: after the previous swap up to ``pre_new_frame`` (events, idling sleep);
* ``new_frame``: imgui's and the docking layout's new frame, up to ``show_gui``;
* ``update_images`` (the GL panels' draws), ``track`` (the error plot's bookkeeping), the
  rest of ``show_gui`` (``show_gui other``: the script, the title);
* one stage per dockable window (``gui Panels``: the display passes; ``gui Difference``: the
  difference pass, its read-back and colour map), ``status``;
* ``blits``: the panel images copied into the window (``before_imgui_render``);
* ``imgui_render``: imgui's drawing of the window, up to ``before_swap``; ``swap``.

CPU time is the process's (``time.process_time``: every thread, llvmpipe's rasterizer threads
included).  With ``--sync`` every stage ends with ``glFinish`` so the GPU work a stage queues is
counted in it (the frame then loses the overlap of the rasterizer threads with Python; the sum
is the work of a frame); without it a stage's time is what it waits for.

Usage: python bench/ui_drag_profile.py [--sync] [--step 0] [--display indexed16-kmeans-fs]
       [--seconds 6] [--window 1600x900] [--size 512] [--methods flat,gouraud,phong]
       [--drag-resolution full|adaptive]
Writes ``bench/results/ui_drag_profile[_sync][_MODE][_adaptive].json`` and ``docs/benchmarks/ui_drag_profile.md``
(every variant found beside the result) and prints a table.  Needs ``Xvfb``.  ``--smoke``: 0.5 s of
counted frames, 64 px panels in an 800 x 500 window.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "bench"))
from _common import Page, first_paragraph, fmt, table  # noqa: E402
from ui_fps import free_display  # noqa: E402


class StageClock:
    """Wall and process-CPU seconds summed per stage over the counted frames."""

    def __init__(self, sync: bool):
        self.sync, self.ctx, self.counting = sync, None, False
        self.wall, self.cpu = defaultdict(float), defaultdict(float)
        self.mark = None

    def _now(self):
        if self.sync and self.ctx is not None:
            self.ctx.finish()
        return time.perf_counter(), time.process_time()

    def lap(self, stage: str) -> None:
        """Close ``stage``: the time since the last lap goes to it."""
        now = self._now()
        if self.mark is not None and self.counting:
            self.wall[stage] += now[0] - self.mark[0]
            self.cpu[stage] += now[1] - self.mark[1]
        self.mark = self._now() if self.sync else now

    def wrap(self, fn, stage: str, before: str | None = None):
        """``fn`` timed as ``stage`` (the time before it, since the last lap, to ``before``)."""
        def timed(*a, **k):
            if before is not None:
                self.lap(before)
            else:
                self.mark = self._now()
            out = fn(*a, **k)
            self.lap(stage)
            return out
        return timed


def run(args) -> dict:
    from imgui_bundle import immapp

    from workbench.app.ui import main, panel_refresh, plot
    from workbench.app.ui.session_file import load_session
    from workbench.app.ui.state import new_state

    clock = StageClock(args.sync)
    fps = load_session(f"{ROOT / 'tests' / 'app' / 'ui' / 'sessions.py'}:Fps")
    script = fps(Path(args.script_out), seconds=args.seconds, display=args.display or None,
                         step=args.step)
    counted = {"n": 0}

    def counting_script(state):
        script(state)
        clock.counting = script.t0 is not None and "fps" not in script.log
        counted["n"] += clock.counting

    counting_script.keeps_awake = True
    panel_refresh.update_images = clock.wrap(panel_refresh.update_images, "update_images")
    plot.track = clock.wrap(plot.track, "track")
    real_run = immapp.run

    def patched(params, *rest):
        cb = params.callbacks
        show_gui, before, status = cb.show_gui, cb.before_imgui_render, cb.show_status
        post_init = cb.post_init

        def init():
            post_init()
            clock.ctx = state.ctx

        cb.post_init = init
        cb.pre_new_frame = lambda: clock.lap("poll+idle")
        cb.show_gui = clock.wrap(show_gui, "show_gui other", before="new_frame")
        cb.show_status = clock.wrap(status, "status", before="between windows")
        cb.before_imgui_render = clock.wrap(before, "blits", before="between windows")
        cb.before_swap = lambda: clock.lap("imgui_render")
        cb.after_swap = lambda: clock.lap("swap")
        for w in params.docking_params.dockable_windows:
            w.gui_function = clock.wrap(w.gui_function, f"gui {w.label}",
                                        before="between windows")
        return real_run(params, *rest)

    immapp.run = patched
    state = new_state(args.scene, args.methods.split(","), args.size)
    state.drag.enabled = args.drag_resolution == "adaptive"
    w, h = (int(x) for x in args.window.split("x"))
    t0, c0 = time.perf_counter(), time.process_time()
    main.run(state, None, counting_script, (w, h))
    n = max(1, counted["n"])
    stages = {k: {"wall_ms": clock.wall[k] / n * 1e3, "cpu_ms": clock.cpu[k] / n * 1e3}
              for k in sorted(clock.wall, key=lambda s: -clock.cpu[s])}
    return {"frames": counted["n"], "sync": args.sync, "display": args.display or "direct24",
            "fps_script": script.log, "stages_ms_per_frame": stages,
            "sum_wall_ms": sum(v["wall_ms"] for v in stages.values()),
            "sum_cpu_ms": sum(v["cpu_ms"] for v in stages.values()),
            "gl_renderer": state.gl_renderer, "load_average_1_5_15": os.getloadavg(),
            "run_seconds": time.perf_counter() - t0, "run_cpu_seconds": time.process_time() - c0}


def tables(res: dict) -> str:
    log = res["fps_script"]
    st = res["stages_ms_per_frame"]
    return (f"{res['frames']} frames counted, display `{res['display']}`, {'glFinish after every stage' if res['sync'] else 'no sync'}"
            f"; {fmt(log.get('fps'))} fps, {fmt(log.get('cpu_ms_per_frame'))} CPU ms per frame; {res['gl_renderer']}; "
            f"load {[round(x, 2) for x in res.get('load_average_1_5_15_before', [])]}.  No outside anchor: the stages' sum against the frame.\n\n"
            + table(["stage", "wall ms / frame", "CPU ms / frame"],
                    [[k, v["wall_ms"], v["cpu_ms"]] for k, v in st.items()]
                    + [["**sum**", res["sum_wall_ms"], res["sum_cpu_ms"]]]))


PAGE = Page("ui_drag_profile", "Where a frame of a camera drag goes (the UI window)", first_paragraph(__doc__),
            "python bench/ui_drag_profile.py  (variants: --sync, --step 0, --display indexed16-kmeans-fs)", tables,
            variants=True, smoke_note="0.5 s of frames, 64 px panels, 800 x 500 window")


def main(argv=None) -> None:
    p = argparse.ArgumentParser()
    p.add_argument("--scene", default="whitted")
    p.add_argument("--methods", default="flat,gouraud,phong")
    p.add_argument("--size", type=int, default=512)
    p.add_argument("--window", default="1600x900")
    p.add_argument("--seconds", type=float, default=6.0)
    p.add_argument("--display", default="", help="every GL panel's display mode")
    p.add_argument("--sync", action="store_true", help="glFinish at the end of every stage")
    p.add_argument("--step", type=float, default=0.002, help="radians of orbit per frame (0: "
                   "a static camera, the frame without panel draws)")
    p.add_argument("--drag-resolution", choices=("full", "adaptive"), default="full",
                   help="the GL panels' resolution during the drag (workbench ui's option; "
                        "default full: the drag this page has profiled since before the adaptation)")
    p.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    p.add_argument("--script-out", default="", help=argparse.SUPPRESS)
    argv = sys.argv[1:] if argv is None else list(argv)
    a = PAGE.parse(p, argv)
    if a.smoke:
        a.seconds, a.size, a.window = 0.5, 64, "800x500"
    if a.child:
        print(json.dumps(run(a)))
        return
    n = free_display()
    w, h = (int(x) for x in a.window.split("x"))
    xvfb = subprocess.Popen(["Xvfb", f":{n}", "-screen", "0", f"{w + 64}x{h + 64}x24",
                             "-nolisten", "tcp"], stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    try:
        while not Path(f"/tmp/.X11-unix/X{n}").exists():
            time.sleep(0.05)
        with tempfile.TemporaryDirectory() as out:
            load = os.getloadavg()
            child = subprocess.run([sys.executable, __file__, "--child", "--script-out", out,
                                    *argv, "--out", str(a.out)], cwd=ROOT, timeout=600,
                                   # its own config folder: the user's remembered window size stays
                                   env={**os.environ, "DISPLAY": f":{n}", "WORKBENCH_CONFIG_DIR": out},
                                   capture_output=True,
                                   text=True)
            if child.returncode != 0:  # the window's own error, not the wrapper's traceback
                sys.exit(f"ui_drag_profile: the window failed (exit {child.returncode}):\n"
                         + "\n".join(child.stderr.strip().splitlines()[-15:]))
            res = child.stdout
    finally:
        xvfb.terminate()
        xvfb.wait(10)
    result = {"load_average_1_5_15_before": load, **json.loads(res.strip().splitlines()[-1])}
    name = ("ui_drag_profile" + ("_sync" if a.sync else "") + ("_static" if not a.step else "")
            + (f"_{a.display}" if a.display else "")
            + ("_adaptive" if a.drag_resolution == "adaptive" else ""))
    PAGE.write(a, result, stem=name)
    log = result["fps_script"]
    print(f"{result['frames']} frames, {log.get('fps', 0):.1f} fps, "
          f"{log.get('cpu_ms_per_frame', 0):.1f} CPU ms/frame, load {load[0]:.2f}")
    print(f"{'stage':<22}{'wall ms':>9}{'CPU ms':>9}")
    for k, v in result["stages_ms_per_frame"].items():
        print(f"{k:<22}{v['wall_ms']:9.2f}{v['cpu_ms']:9.2f}")
    print(f"{'sum':<22}{result['sum_wall_ms']:9.2f}{result['sum_cpu_ms']:9.2f}")


if __name__ == "__main__":
    main()
