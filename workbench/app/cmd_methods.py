"""``workbench methods``: registered methods with their quality knob and options;
``--support``: the feature x method support table (issue #27, item 4:
:mod:`workbench.renderers.support`)."""
from __future__ import annotations


def add_parser(sub):
    p = sub.add_parser("methods", help="list the registered methods, their knob and options")
    p.add_argument("--support", action="store_true",
                   help="print what each method does with each scene feature instead: yes (supported), "
                        "approx (approximated) or no (left out), then the reasons")
    p.set_defaults(run=run)


def run(args) -> int:
    from ..renderers.base import USER_PREFIX, available, get_renderer
    from ..renderers.user_shading import bundled_examples
    if args.support:
        return _support({name: get_renderer(name).support for name in available()})
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


def _support(tables: dict) -> int:
    """The grid of :func:`workbench.renderers.support.table_rows`, then per method the features
    it approximates or leaves out, with the reason."""
    from ..renderers.support import Status, table_rows
    rows = table_rows(tables)
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    for r in rows:
        print("  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip())
    print("\nyes: supported, approx: approximated, no: left out (listed in a render's left_out when "
          "the scene uses it)")
    for name, table in tables.items():
        print(f"\n{name}:")
        shown = [(f, s) for f, s in table.items() if s.status is not Status.SUPPORTED]
        for f, s in shown:
            print(f"    {f}: {s.status.value}: {s.reason}")
        if not shown:
            print("    every feature supported")
    return 0
