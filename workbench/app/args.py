"""Argument types shared by the ``cmd_*`` modules (argparse ``type=`` converters)."""
from __future__ import annotations

import argparse
import math


def size(text: str) -> tuple[int, int]:
    """``"320x240"`` -> ``(320, 240)``, each within 1..16384."""
    try:
        w, h = (int(x) for x in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected WIDTHxHEIGHT such as 320x240, got {text!r}") from None
    if not (1 <= w <= 16384 and 1 <= h <= 16384):
        raise argparse.ArgumentTypeError(f"size must be within 1..16384, got {text!r}")
    return w, h


def key_value(text: str) -> tuple[str, str]:
    """``"max_depth=8"`` -> ``("max_depth", "8")`` (method options, converted by the method)."""
    if "=" not in text:
        raise argparse.ArgumentTypeError(f"expected KEY=VALUE, got {text!r}")
    k, v = text.split("=", 1)
    return k.strip(), v.strip()


def methods_list(text: str) -> list[str]:
    """``"phong,raytrace"`` -> ``["phong", "raytrace"]`` (names checked when running)."""
    return [m.strip() for m in text.split(",") if m.strip()]


def at_least_one(text: str) -> int:
    """A count that must be >= 1 (``--repeat``)."""
    try:
        n = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
    if n < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1, got {n}")
    return n


def finite(text: str) -> float:
    """A number that must be finite (argparse's ``float`` takes ``nan`` and ``inf``)."""
    try:
        x = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not math.isfinite(x):
        raise argparse.ArgumentTypeError(f"expected a finite number, got {text!r}")
    return x


def value_after_option(argv: list[str]) -> list[str]:
    """``["--size", "-5x5"]`` -> ``["--size=-5x5"]``: a value that starts with a minus and a
    digit is the option's value (argparse takes it for an option and says "expected one
    argument"), so that the converter can say what is wrong with it.  After ``--`` (the end of
    the options) it stays a positional argument."""
    out: list[str] = []
    for tok in argv:
        if out and out[-1].startswith("--") and out[-1] != "--" and "=" not in out[-1] and len(tok) > 1 \
                and tok[0] == "-" and (tok[1].isdigit() or tok[1] == "."):
            out[-1] = f"{out[-1]}={tok}"
        else:
            out.append(tok)
    return out
