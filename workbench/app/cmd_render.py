"""``workbench render SCENE --method M -o out.png``: one method, one image, its numbers."""
from __future__ import annotations

from .args import key_value, size


def add_parser(sub):
    p = sub.add_parser("render", help="render a scene with one method to a PNG")
    p.add_argument("scene", help="scene file or bundled scene name")
    p.add_argument("--method", "-m", default="phong", help="registered method (see 'workbench methods')")
    p.add_argument("-o", "--output", required=True, help="output PNG (sRGB-encoded)")
    p.add_argument("--size", type=size, help="WIDTHxHEIGHT (default: the scene camera's)")
    p.add_argument("--set", type=key_value, action="append", default=[], metavar="KEY=VALUE",
                   help="method option, repeatable (see 'workbench methods')")
    p.add_argument("--npy", help="also save the linear float32 image as .npy")
    p.add_argument("--json", help="also save timings, stats and left-out features as JSON")
    p.add_argument("--display", metavar="MODE", default="direct24",
                   help="display mode post-process: direct24, direct16-555, direct16-565, "
                        "indexedN[-mediancut|-kmeans][-bayer|-fs] (N = 2..256); its error against "
                        "direct24 is printed")
    p.set_defaults(run=run, prepare=prepare)


def prepare(args) -> None:
    """Import a built-in method's renderer during the program's start-up (see :mod:`.cli`);
    any other name is left to :func:`run`, which checks it in its turn."""
    from ..renderers.base import BUILTIN, get_renderer
    if args.method in BUILTIN:
        get_renderer(args.method)


def run(args) -> int:
    import json

    from ..compare.outputs import jsonable
    from ..core.imageio import npy_writer, png_writer, text_writer
    from ..core.output_paths import check_distinct, check_output_file, write_together
    from ..renderers.base import render, stats_for_display
    from ..scene.io import load_scene
    check_output_file(args.output, "-o", ".png")         # every output checked before any work
    for opt, target in (("--npy", args.npy), ("--json", args.json)):
        if target:
            check_output_file(target, opt)
    check_distinct({"-o": args.output, "--npy": args.npy, "--json": args.json})
    from ..core.display import apply_display_mode, check_display_memory, display_mode
    display_mode(args.display)  # refuse a bad mode before rendering
    scene = load_scene(args.scene)
    w, h = args.size if args.size else (None, None)
    if args.display != "direct24":  # the post-process's memory, before the render's
        check_display_memory(h or scene.camera.height, w or scene.camera.width, args.display)
    options = dict(args.set)
    if "progress" in _accepted(args.method):
        options.setdefault("progress", "true")
    result = render(scene, args.method, width=w, height=h, **options)
    image = result.image
    if args.display != "direct24":
        from ..compare.metrics import metrics
        reference = apply_display_mode(image, "direct24")
        image = apply_display_mode(image, args.display)
        m = metrics(image, reference)
        print(f"  display {args.display} vs direct24: rmse {m['rmse']:.4g}, psnr {m['psnr']:.2f} dB, flip {m['flip']:.4f}")
    stats = stats_for_display(result.stats)
    files = [(args.output, png_writer(image))]
    if args.npy:
        files.append((args.npy, npy_writer(result.image)))
    if args.json:
        files.append((args.json, text_writer(json.dumps(jsonable({
            "scene": scene.name, "method": result.method, "timings": result.timings,
            "stats": stats, "features_used": result.features_used,
            "left_out": result.left_out, "options": {k: str(v) for k, v in result.options.items()}}),
            indent=2, allow_nan=False))))
    write_together(files)                                 # all of them or none
    t = ", ".join(f"{k} {v:.3f} s" for k, v in result.timings.items())
    print(f"{scene.name} / {result.method}: {result.image.shape[1]}x{result.image.shape[0]} -> {args.output}")
    print(f"  timings: {t}")
    for k, v in stats.items():
        print(f"  {k}: {v}")
    if result.left_out:
        print(f"  left out: {'; '.join(map(str, result.left_out))}")
    return 0


def _accepted(method: str) -> dict:
    from ..renderers.base import get_renderer
    return get_renderer(method).options
