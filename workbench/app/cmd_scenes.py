"""``workbench scenes``: the bundled scenes with what each demonstrates and needs."""
from __future__ import annotations
from ..scene.features import scene_needs


def add_parser(sub):
    p = sub.add_parser("scenes", help="list the bundled scenes with their needs")
    p.set_defaults(run=run)


def run(args) -> int:
    from ..scene.io import SceneError, load_scene
    from ..scene.library import bundled, header
    for path in bundled():
        try:
            needs = ", ".join(sorted(scene_needs(load_scene(path))))
        except SceneError as e:
            needs = f"(does not load: {e})"
        print(f"{path.stem}\n    {header(path)}\n    needs: {needs}")
    return 0
