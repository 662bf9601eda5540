"""Which image is the reference of a scene, by one documented rule.

Rule (first candidate that is registered and applies wins; each at the most accurate value of
its quality knob, ``knob.values[-1]``):

1. scenes with emitters (area lights or emissive materials): ``hybrid`` when the scene also has
   mirror / glass materials, then ``radiosity`` (global diffuse illumination: only these
   compute the interreflection the emitter causes);
2. ``raytrace`` (Whitted: analytic primitives under the same local model plus shadows,
   reflection and refraction: the limit of the raster methods under finer tessellation, and
   the only one computing every ray-optics feature);
3. ``raycast`` (analytic primitives, local model, no secondary rays);
4. ``phong`` at its finest tessellation (per-pixel local model);
5. otherwise the first registered method that applies, at its finest setting.

The reference is point-sampled at pixel centres (the workbench's definition of an image; only
the knob is raised, other options keep their defaults, e.g. ``spp = 1``).  Supersampling
(``spp > 1``) converges to the box-filtered image instead, so its error against this
reference does not fall with ``spp``: :data:`SAMPLING_NOTE` says so in the reports.

``--reference METHOD`` overrides the rule.  Methods that leave out features the reference
builds (e.g. Phong has no reflection, refraction or shadows) differ *physically* from it, not
only by discretisation: :func:`physical_differences` says which, and the report shows it.
"""
from __future__ import annotations

from dataclasses import dataclass

from ..core.errors import WorkbenchError
from ..renderers.base import available, get_renderer
from ..scene import features as F
from ..scene.model import Scene
from .runs import MethodRun, timed_run


SAMPLING_NOTE = ("The reference samples each pixel at its centre (1 sample); supersampled images "
                 "(spp > 1) converge to the pixel-averaged image instead, so their error against this "
                 "reference measures antialiasing, not convergence.")


@dataclass
class Reference:
    method: str
    options: dict
    reason: str
    run: MethodRun


def candidates(scene: Scene) -> list[tuple[str, str]]:
    """Reference candidates in rule order, each with the reason it would be chosen."""
    needs = scene.needs()
    out = []
    if F.EMITTERS in needs:
        if needs & {F.REFLECTION, F.REFRACTION}:
            out.append(("hybrid", "scene has emitters and mirror/glass: radiosity + ray-traced specular pass"))
        out.append(("radiosity", "scene has emitters: only radiosity computes diffuse interreflection"))
    out.append(("raytrace", "analytic primitives under the same local model with shadows, reflection "
                            "and refraction (limit of the raster methods under refinement)"))
    out.append(("raycast", "analytic primitives under the same local model (no secondary rays)"))
    out.append(("phong", "per-pixel local model at the finest tessellation (no ray tracer registered)"))
    rest = [m for m in available() if m not in {c for c, _ in out}]
    out.extend((m, "first registered method that applies, at its finest setting") for m in rest)
    return [(m, why) for m, why in out if m in available()]


def finest_options(method: str) -> dict:
    """Options putting ``method``'s quality knob at its most accurate value."""
    knob = get_renderer(method).knob
    return {knob.name: knob.values[-1]} if knob.values else {}


def choose_reference(scene: Scene, width: int, height: int, method: str | None = None,
                     repeat: int = 0) -> Reference:
    """Render the reference image by the rule above (or with ``method``, if given)."""
    if method is not None:
        cands = [(method, "chosen by the user (--reference)")]
        get_renderer(method)  # unknown name -> WorkbenchError
    else:
        cands = candidates(scene)
    tried = []
    for m, why in cands:
        try:
            opts = finest_options(m)
        except ImportError as e:  # registered but its module has not landed / is broken
            tried.append(f"{m}: cannot be loaded ({e})")
            continue
        run = timed_run(scene, m, width, height, repeat=repeat, options=opts)
        if run.status == "ok":
            knob = get_renderer(m).knob
            return Reference(m, opts, f"{why}; {knob.name} = {knob.values[-1]!r} (finest)" if opts else why, run)
        tried.append(f"{m}: {run.reason}")
    raise WorkbenchError("no reference image: no registered method renders this scene ("
                         + "; ".join(tried or ["no method registered"]) + ")")


def physical_differences(result_left_out: list[str], reference_features: list[str]) -> list[str]:
    """Features the reference builds that a method leaves out (``"feature: reason"`` entries).

    A method with any such feature differs from the reference physically, not only by
    discretisation; its error measures the missing effect too.
    """
    left = {entry.split(":", 1)[0].strip() for entry in result_left_out}
    return sorted(left & set(reference_features))


__all__ = ["Reference", "candidates", "choose_reference", "finest_options", "physical_differences"]
