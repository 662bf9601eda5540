"""``workbench colour``: the colour chapter from the command line.

* ``workbench colour wheel --hue 30 --harmony triad -o wheel.png``: the HSV chromatic circle
  with a harmony marked.
* ``workbench colour display IMAGE_OR_SCENE --mode indexed16-kmeans-fs -o out.png``: an image
  file (PNG/JPEG, sRGB; or .npy, linear) or a scene rendered with ``--method``, shown through a
  display mode; prints the mode's error against the 24-bit image.
* ``workbench colour convert 0.6 0.2 0.4 --from rgb --to hsi``: one colour from one space to
  another (rgb, xyz, cmy, cmyk, hsv, hsl, hsi), or to all of them; a colour outside the RGB
  cube is reported, its values shown unclipped.
"""
from __future__ import annotations

from .args import finite

_IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".npy")
_SPACE_NAMES = "rgb | xyz | cmy | cmyk | hsv | hsl | hsi"
"""The names of ``workbench.core.color.SPACES`` for the help (written out: the parser does not
import numpy)."""


def add_parser(sub):
    p = sub.add_parser("colour", aliases=["color"], help="colour wheel and harmonies; display modes")
    csub = p.add_subparsers(dest="colour_command", metavar="SUBCOMMAND")
    csub.required = True

    w = csub.add_parser("wheel", help="HSV colour wheel with a harmony marked, to a PNG")
    w.add_argument("--hue", type=float, default=0.0, help="base hue in degrees (default 0 = red)")
    w.add_argument("--harmony", default="triad",
                   help="complementary | triad | square | hexagon (default triad)")
    w.add_argument("--size", type=int, default=256, help="image size in pixels (default 256)")
    w.add_argument("-o", "--output", required=True, help="output PNG")
    w.set_defaults(run=run_wheel)

    d = csub.add_parser("display", help="show an image or a rendered scene through a display mode")
    d.add_argument("source", help="image file (.png/.jpg sRGB, .npy linear) or scene file/bundled name")
    d.add_argument("--mode", default="direct16-565",
                   help="direct24 | direct16[-555|-565] | indexedN[-mediancut|-kmeans], optionally "
                        "-bayer or -fs (e.g. indexed16-kmeans-fs; default direct16-565)")
    d.add_argument("--method", "-m", default="phong", help="method rendering a scene (default phong)")
    d.add_argument("-o", "--output", required=True, help="output PNG")
    d.set_defaults(run=run_display)

    c = csub.add_parser("convert", help="one colour from one space to another (RGB, XYZ, CMY(K), HSV, HSL, HSI)")
    c.add_argument("components", nargs="+", type=finite, metavar="X",
                   help="the colour's components in the --from space (4 for cmyk; hues in degrees; "
                        "put -- before them when one is written like -1e-3)")
    c.add_argument("--from", dest="source", default="rgb", metavar="SPACE",
                   help=f"space of the components: {_SPACE_NAMES} (default rgb)")
    c.add_argument("--to", dest="target", default="all", metavar="SPACE",
                   help=f"space to convert to: {_SPACE_NAMES}, or all (default all)")
    c.set_defaults(run=run_convert)


def _png_output(path: str) -> None:
    from ..core.output_paths import check_output_file
    check_output_file(path, "-o", ".png")


def run_wheel(args) -> int:
    from ..core.harmony import harmony_hues, wheel_image
    from ..core.imageio import save_png
    _png_output(args.output)
    hues = harmony_hues(args.hue, args.harmony)
    save_png(args.output, wheel_image(args.hue, args.harmony, args.size))
    print(f"{args.harmony} from hue {args.hue:g}: hues {', '.join(f'{h:g}' for h in hues)} deg "
          f"-> {args.output}")
    return 0


def _image_size(p) -> tuple[int, int]:
    """``(height, width)`` of an image file from its header, without reading its pixels."""
    import numpy as np

    from ..core.errors import WorkbenchError
    from PIL import Image
    try:
        if p.suffix.lower() == ".npy":
            return np.load(p, mmap_mode="r", allow_pickle=False).shape[:2]
        with Image.open(p) as im:
            return im.size[1], im.size[0]
    except (OSError, ValueError, Image.DecompressionBombError) as e:
        raise WorkbenchError(f"{p}: cannot read the image ({e})") from None


def _load_source(source: str, method: str, mode: str):
    """Linear (H, W, 3) image from an image file, or from a scene rendered with ``method``;
    the memory of showing it through ``mode`` is checked before either."""
    from pathlib import Path

    import numpy as np

    from ..core.display import check_display_memory
    from ..core.errors import WorkbenchError
    p = Path(source)
    if p.suffix.lower() in _IMAGE_SUFFIXES:
        if not p.is_file():
            raise WorkbenchError(f"{source}: no such image file")
        check_display_memory(*_image_size(p), mode)
        if p.suffix.lower() == ".npy":
            img = np.load(p, allow_pickle=False)
        else:
            from ..core.imageio import load_image_linear
            try:
                img = load_image_linear(p)[..., :3]
            except OSError as e:
                raise WorkbenchError(f"{source}: cannot read the image ({e})") from None
        if img.ndim != 3 or img.shape[-1] != 3:
            raise WorkbenchError(f"{source}: expected an (H, W, 3) image, got shape {img.shape}")
        if not np.issubdtype(img.dtype, np.number) or not np.isfinite(img).all():
            bad = int(img.size - np.isfinite(img).sum()) if np.issubdtype(img.dtype, np.number) else img.size
            raise WorkbenchError(f"{source}: {bad} value(s) are NaN or infinite (or not numbers): "
                                 "an image must be finite")
        return img, f"image {p.name}"
    from ..renderers.base import render
    from ..scene.io import load_scene
    scene = load_scene(source)
    check_display_memory(scene.camera.height, scene.camera.width, mode)
    result = render(scene, method)
    return result.image, f"{scene.name} / {result.method}"


def run_display(args) -> int:
    import numpy as np

    from ..compare.metrics import metrics
    from ..core.display import apply_display_mode, display_mode
    from ..core.imageio import save_png
    _png_output(args.output)
    mode = display_mode(args.mode)                       # a bad mode fails before any rendering
    image, what = _load_source(args.source, args.method, mode)
    image = np.nan_to_num(np.asarray(image, dtype=np.float32), nan=0.0, posinf=1.0, neginf=0.0)
    ref = apply_display_mode(image, "direct24")
    shown = apply_display_mode(image, mode)
    save_png(args.output, shown)
    m = metrics(shown, ref)
    print(f"{what}: {image.shape[1]}x{image.shape[0]} shown as {mode} -> {args.output}")
    print(f"  error against direct24: RMSE {m['rmse']:.5f}, PSNR {m['psnr']:.2f} dB, FLIP {m['flip']:.4f}")
    return 0


def _number(x: float) -> str:
    """``x`` to 6 decimals, trailing zeros dropped (``330``, ``0.5``, ``0.333333``; no ``-0``)."""
    text = f"{x:.6f}".rstrip("0").rstrip(".")
    return "0" if text == "-0" else text


def _colour_line(name: str, values) -> str:
    """``hsi   H 330 deg  S 0.5  I 0.4``: a space's name and labelled components."""
    from ..core.color import space_labels
    parts = [f"{label} {_number(v)}{' deg' if label == 'H' else ''}"
             for label, v in zip(space_labels(name), values)]
    return f"{name:<5} " + "  ".join(parts)


def run_convert(args) -> int:
    import numpy as np

    from ..core.color import SPACES, convert, space_labels
    from ..core.errors import WorkbenchError
    from ..core.tol import tol
    for option, name in (("--from", args.source), ("--to", args.target)):
        if name not in SPACES and (option, name) != ("--to", "all"):
            raise WorkbenchError(f"colour convert: {option} {name!r} is not a colour space: "
                                 f"expected {_SPACE_NAMES}{' or all' if option == '--to' else ''}")
    targets = list(SPACES) if args.target == "all" else [args.target]
    n = len(space_labels(args.source))
    if len(args.components) != n:
        raise WorkbenchError(f"colour convert: --from {args.source} takes {n} components "
                             f"({' '.join(space_labels(args.source))}), got {len(args.components)}")
    rgb = convert(np.array(args.components), args.source, "rgb")
    for name in targets:
        print(_colour_line(name, convert(rgb, "rgb", name)))
    if np.any((rgb < -tol.zero) | (rgb > 1.0 + tol.zero)):
        print(f"note: RGB ({', '.join(_number(v) for v in rgb)}) is outside the RGB cube [0, 1]: "
              f"values shown unclipped (clipped to the cube: "
              f"{', '.join(_number(v) for v in np.clip(rgb, 0.0, 1.0))})")
    return 0
