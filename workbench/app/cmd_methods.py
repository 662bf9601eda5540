"""``workbench methods``: registered methods with their quality knob and options."""
from __future__ import annotations


def add_parser(sub):
    p = sub.add_parser("methods", help="list the registered methods, their knob and options")
    p.set_defaults(run=run)


def run(args) -> int:
    from ..renderers.base import available, get_renderer
    for name in available():
        r = get_renderer(name)
        print(f"{name}: knob {r.knob.name} = {list(r.knob.values)} (default {r.knob.default})")
        for k, o in r.options.items():
            ch = f" one of {list(o.choices)}" if o.choices else ""
            print(f"    --set {k}=... ({getattr(o.kind, '__name__', 'value')}, default {o.default!r}{ch}) {o.help}")
    return 0
