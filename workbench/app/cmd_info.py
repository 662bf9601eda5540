"""``workbench info SCENE``: camera, lights, materials, objects and needs of a scene."""
from __future__ import annotations
from ..scene.features import scene_needs


def add_parser(sub):
    p = sub.add_parser("info", help="describe a scene (camera, lights, objects, needs)")
    p.add_argument("scene", help="scene file or bundled scene name")
    p.set_defaults(run=run)


def run(args) -> int:
    from ..scene.io import load_scene
    s = load_scene(args.scene)
    c = s.camera
    print(f"scene {s.name}: {s.description}\n  file: {s.source}")
    print(f"  camera: position {c.position} look_at {c.look_at} up {c.up} fov_y {c.fov_y} "
          f"resolution {c.width}x{c.height}")
    for light in s.lights:
        print(f"  light: {type(light).__name__} color {light.color} intensity {light.intensity}")
    for name, m in s.materials.items():
        extra = [k for k in ("texture", "bump", "opacity") if getattr(m, k) is not None]
        print(f"  material {name}: color {m.color} ka {m.ka} kd {m.kd} ks {m.ks} n {m.shininess} "
              f"kr {m.kr} kt {m.kt} ior {m.ior}" + (f" [{', '.join(extra)}]" if extra else ""))
    for o in s.objects:
        print(f"  object {o.kind}{' ' + o.name if o.name else ''}: material {o.material}")
    print(f"  needs: {', '.join(sorted(scene_needs(s)))}")
    return 0
