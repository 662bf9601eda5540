"""Export of the comparison on screen, in a form the CLI replays.

Into one folder (written whole or not at all: a temporary sibling renamed at the end):

* ``M.png`` per panel **as displayed** (its display mode applied) and ``M.npy``, the linear
  float32 image (the data the error plot and the probe use);
* ``difference.png`` (its colour scale) and ``difference.npy`` when the difference view has
  a map;
* ``scene.toml``: the scene as shown: the scene file with the material and light overrides
  written in and the camera as moved (its resolution the panels'), file paths made absolute;
* ``settings.json``: scene, camera, methods with their options and display modes, the
  overrides, the panels skipped and why (a panel whose method does not apply to the scene, or
  whose render failed, has no image to write), ``panels``: the state each exported image was
  in (:func:`panel_record`: done, or a path tracer still refining at how many spp and passes of
  its target, whether it converged; a ray trace with how many rows rendered; a stale image),
  and ``replay``: one ``workbench render`` command per panel that renders ``scene.toml`` with
  the panel's options and display mode into the same PNG and NPY (``tests/app/ui/test_ui_export.py``
  runs them).  A refining panel's options and replay carry the spp its image has, not its
  target (issue #29, item 5: such an export recorded spp=256).
"""
from __future__ import annotations

import json
import math
import os
import shutil
import tomllib
from dataclasses import asdict
from pathlib import Path

import numpy as np

from .panel_refresh import mismatch
from .state import AppState, method_kind, shown_image


def toml_value(v) -> str:
    """One TOML value: numbers, booleans, strings, arrays and inline tables."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    if isinstance(v, (float, np.floating)):
        x = float(v)
        if not math.isfinite(x):
            raise ValueError(f"not a finite number: {x}")
        return repr(x)
    if isinstance(v, str):
        return json.dumps(v)  # a TOML basic string: JSON's escapes are TOML's
    if isinstance(v, (list, tuple, np.ndarray)):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{json.dumps(str(k))} = {toml_value(x)}" for k, x in v.items()) + "}"
    raise ValueError(f"no TOML value for {type(v).__name__}")


def toml_text(data: dict) -> str:
    """A TOML document of ``data``: top-level scalars first, then a ``[table]`` per dict and
    a ``[[table]]`` per list of dicts (their entries as ``key = value``, nested values inline)."""
    lines, tables = [], []
    for k, v in data.items():
        if isinstance(v, dict) or (isinstance(v, list) and v and all(isinstance(x, dict) for x in v)):
            tables.append((k, v))
        else:
            lines.append(f"{json.dumps(str(k))} = {toml_value(v)}")
    for k, v in tables:
        if isinstance(v, dict):
            scalars = {a: b for a, b in v.items() if not isinstance(b, dict)}
            subs = {a: b for a, b in v.items() if isinstance(b, dict)}
            lines += ["", f"[{json.dumps(str(k))}]"] + [f"{json.dumps(str(a))} = {toml_value(b)}"
                                                        for a, b in scalars.items()]
            for a, b in subs.items():  # [materials.NAME]
                lines += ["", f"[{json.dumps(str(k))}.{json.dumps(str(a))}]"]
                lines += [f"{json.dumps(str(c))} = {toml_value(d)}" for c, d in b.items()]
        else:
            for entry in v:
                lines += ["", f"[[{json.dumps(str(k))}]]"]
                lines += [f"{json.dumps(str(a))} = {toml_value(b)}" for a, b in entry.items()]
    return "\n".join(lines) + "\n"


def _absolute_paths(node, base: Path):
    """``node`` with every string naming an existing file relative to ``base`` made absolute
    (textures, meshes, environment maps of a scene written elsewhere)."""
    if isinstance(node, dict):
        return {k: _absolute_paths(v, base) for k, v in node.items()}
    if isinstance(node, list):
        return [_absolute_paths(v, base) for v in node]
    if isinstance(node, str) and not Path(node).is_absolute() and (base / node).is_file():
        return str((base / node).resolve())
    return node


def scene_document(state: AppState) -> dict:
    """The scene file of ``state`` as a dict with the overrides and the camera written in."""
    data = tomllib.loads(state.scene_path.read_text(encoding="utf-8"))
    data = _absolute_paths(data, state.scene_path.parent)
    cam = state.camera
    data["camera"] = {**data["camera"], "position": list(cam.position),
                      "look_at": list(cam.look_at), "up": list(cam.up), "fov_y": float(cam.fov_y),
                      "resolution": [cam.width, cam.height]}
    for name, fields in state.overrides.items():
        data.setdefault("materials", {}).setdefault(name, {}).update(
            {k: float(v) for k, v in fields.items()})
    lights = data.get("lights", [])
    for k, fields in state.light_overrides.items():
        light = state.scene.lights[k]  # the overrides applied (an area light's moved vertices)
        for name in fields:
            if name == "centre":
                lights[k]["vertices"] = np.asarray(light.vertices, float).tolist()
            else:
                value = getattr(light, name)
                lights[k][name] = float(value) if name == "intensity" else [float(x) for x in value]
    return data


def skipped_panels(state: AppState) -> dict[str, str]:
    """Panels with no image to write, and why (the method does not apply to the scene, its
    render failed, or nothing has come yet)."""
    out = {}
    for m in state.methods:
        job = state.jobs.current.get(m) if state.jobs is not None else None
        error = getattr(job, "error", None)
        proc = state.pyrender if m == "pyrender" else None
        error = error or getattr(proc, "error", None)
        if error:
            out[m] = error
        elif m not in state.images:
            out[m] = "no image yet"
    return out


def panel_record(state: AppState, method: str) -> dict:
    """The state ``method``'s exported image was in: ``{"state": "done"}`` for a GL panel (drawn
    in the frame; ``"reduced"`` with its ``size`` and ``full_size`` when drawn at a drag's
    lower resolution, :mod:`.drag_resolution`) and a child's image of the current request; a CPU or progressive panel's
    :func:`.panel_refresh.shown_progress` (``refining`` with ``spp``, ``target_spp``,
    ``passes``, ``noise``, ``converged``; ``rendering`` with ``rows_done``; ``stale``); a
    child's image of an earlier request ``stale``."""
    kind = method_kind(state, method)
    if kind in ("cpu", "progressive"):
        return dict(state.progress.get(method, {"state": "stale"}))
    if kind == "child":
        proc = state.pyrender
        current = (state.scene_version, state.camera, tuple(sorted(state.options[method].items())))
        return {"state": "done" if proc is not None and proc.image_key == current else "stale"}
    h, w = np.shape(state.images[method])[:2] if method in state.images else (0, 0)
    if (h, w) != (state.camera.height, state.camera.width):  # drawn during a drag, at its scale
        return {"state": "reduced", "size": [w, h], "full_size": [state.camera.width, state.camera.height]}
    return {"state": "done"}


def shown_options(state: AppState, method: str, record: dict) -> dict:
    """The panel's options as its image has them: a refining panel's ``spp`` is the spp done
    (its target is ``record["target_spp"]``)."""
    from ...renderers.base import get_renderer
    opts = dict(state.options.get(method, {}))
    if "spp" in record and not record.get("converged"):
        opts[get_renderer(method).knob.name] = record["spp"]
    return opts


def progress_note(method: str, record: dict) -> str:
    """One phrase on a panel exported before its render was done (empty when done)."""
    if record["state"] == "refining":
        return f"{method} at {record['spp']}/{record['target_spp']} spp (not converged)"
    if record["state"] == "shooting":
        return f"{method} after {record['shots']} shots ({100 * record['unshot']:.2g} % of the power unshot)"
    if record["state"] == "rendering":
        return f"{method} partial ({record['rows_done']}/{record['rows']} rows)"
    if record["state"] == "reduced":
        (w, h), (fw, fh) = record["size"], record["full_size"]
        return f"{method} at {w}x{h} of {fw}x{fh} (drawn during a camera drag)"
    if record["state"] != "done":
        return f"{method} {record['state']} (an earlier request's image)"
    return ""


def replay_command(state: AppState, method: str, folder: Path, options: dict) -> list[str]:
    """The ``workbench render`` command that renders ``method``'s panel from ``scene.toml``
    with ``options`` (:func:`shown_options`)."""
    cmd = ["workbench", "render", str(folder / "scene.toml"), "--method", method,
           "--size", f"{state.camera.width}x{state.camera.height}"]
    for k, v in options.items():
        cmd += ["--set", f"{k}={v}"]
    cmd += ["--display", state.display.get(method, "direct24"),
            "-o", str(folder / f"{method}.png"), "--npy", str(folder / f"{method}.npy")]
    return cmd


def settings(state: AppState, folder: Path, skipped: dict[str, str], records: dict) -> dict:
    """The export's ``settings.json`` (``records``: :func:`panel_record` of each panel
    exported)."""
    shown = [m for m in state.methods if m not in skipped]
    options = {m: shown_options(state, m, records.get(m, {})) for m in state.methods}
    return {"scene": str(state.scene_path), "scene_file": str(folder / "scene.toml"),
            "camera": asdict(state.camera), "methods": list(state.methods),
            "options": options, "panels": records,
            "display": {m: state.display.get(m, "direct24") for m in state.methods},
            "material_overrides": state.overrides,
            "light_overrides": {str(k): v for k, v in state.light_overrides.items()},
            "difference": {"a": state.diff_pair[0], "b": state.diff_pair[1],
                           "kind": state.diff_kind,
                           "paused": mismatch(state, *state.diff_pair)},
            "skipped": skipped,
            "replay": [replay_command(state, m, folder, options[m]) for m in shown]}


def export(state: AppState, folder: Path) -> list[Path]:
    """Write the comparison into ``folder`` (see the module docstring; an existing folder is
    replaced); returns the files written.  ``state.status["export"]`` says where, and which
    panels were skipped."""
    from ...core.imageio import save_png, save_png8
    from .colours import colour_scale
    folder = Path(folder).resolve()
    tmp = folder.with_name(folder.name + ".partial")
    shutil.rmtree(tmp, ignore_errors=True)
    tmp.mkdir(parents=True)
    skipped = skipped_panels(state)
    records = {m: panel_record(state, m) for m in state.methods if m not in skipped}
    names = []
    for m in state.methods:
        if m in skipped:
            continue
        save_png(tmp / f"{m}.png", shown_image(state, m))
        np.save(tmp / f"{m}.npy", np.asarray(state.images[m], np.float32))
        names += [f"{m}.png", f"{m}.npy"]
    err = state.images.get("difference")
    if err is not None and not set(state.diff_pair) & set(skipped):
        save_png8(tmp / "difference.png", colour_scale(err, float(err.max())))
        np.save(tmp / "difference.npy", np.asarray(err, np.float32))
        names += ["difference.png", "difference.npy"]
    (tmp / "scene.toml").write_text(toml_text(scene_document(state)), encoding="utf-8")
    (tmp / "settings.json").write_text(json.dumps(settings(state, folder, skipped, records),
                                                  indent=1, default=str))
    names += ["scene.toml", "settings.json"]
    if folder.exists():
        shutil.rmtree(folder)
    os.replace(tmp, folder)
    note = "" if not skipped else "; skipped: " + "; ".join(f"{m} ({why})" for m, why in skipped.items())
    unfinished = [x for x in (progress_note(m, r) for m, r in records.items()) if x]
    if unfinished:
        note += "; as shown: " + "; ".join(unfinished)
    state.status["export"] = f"saved {len(names)} files to {folder}{note}"
    return [folder / n for n in names]
