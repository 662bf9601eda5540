"""The bundled scenes (``scenes/*.toml``, found by :func:`workbench.core.resources.data_dir`) and name
resolution."""
from __future__ import annotations

from pathlib import Path

from ..core.resources import data_dir
from .readers import SceneError

SCENES_DIR = data_dir("scenes")
DEFAULT_SCENE = "whitted"


def bundled() -> list[Path]:
    """Paths of the bundled scene files, sorted by name."""
    return sorted(SCENES_DIR.glob("*.toml"))


def header(path: Path) -> str:
    """The leading comment block of a scene file (what it demonstrates)."""
    lines = []
    for line in Path(path).read_text(encoding="utf-8").splitlines():
        if not line.startswith("#"):
            break
        lines.append(line.lstrip("# ").rstrip())
    return " ".join(x for x in lines if x)


def resolve(name: str | Path) -> Path:
    """A scene file path from a path or a bundled scene's name (``"cornell"``)."""
    if not isinstance(name, (str, Path)):
        raise SceneError(f"a scene is given by a file path or a bundled scene's name (str), got "
                         f"{type(name).__name__} {name!r}")
    p = Path(name)
    if p.is_file():
        return p.resolve()
    cand = SCENES_DIR / f"{name}.toml"
    if cand.is_file():
        return cand
    names = ", ".join(q.stem for q in bundled())
    raise SceneError(f"{name}: no such scene file, and not a bundled scene (bundled: {names})")
