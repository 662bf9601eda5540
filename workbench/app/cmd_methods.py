"""``workbench methods``: registered methods with their quality knob and options."""
from __future__ import annotations


def add_parser(sub):
    p = sub.add_parser("methods", help="list the registered methods, their knob and options")
    p.set_defaults(run=run)


def run(args) -> int:
    from ..renderers.base import USER_PREFIX, available, get_renderer
    from ..renderers.user_shading import bundled_examples
    for name in available():
        r = get_renderer(name)
        print(f"{name}: knob {r.knob.name} = {list(r.knob.values)} (default {r.knob.default})")
        for k, o in r.options.items():
            ch = f" one of {list(o.choices)}" if o.choices else ""
            print(f"    --set {k}=... ({getattr(o.kind, '__name__', 'value')}, default {o.default!r}{ch}) {o.help}")
    examples = bundled_examples()
    print(f"{USER_PREFIX}FILE: your own shading model (the function shade() of a GLSL file), options as phong "
          f"plus the file's '#pragma parameter' lines")
    for stem, path in examples.items():
        print(f"    {USER_PREFIX}{stem} = {path}")
    return 0
