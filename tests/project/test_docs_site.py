"""The documentation: the MkDocs site builds with ``--strict`` (no broken link or anchor, every
page in the navigation, the API reference generated from the docstrings), and the README stays
what a newcomer reads in five minutes: short, with no link out of the repository, no commit hash
and no date (those belong in docs/benchmarks/history.md and the git history)."""
from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
README = ROOT / "README.md"
README_MAX_LINES = 250

COMMIT_LIKE = re.compile(r"(?<![0-9A-Za-z_])(?=[0-9a-f]*[a-f])(?=[0-9a-f]*[0-9])[0-9a-f]{7,40}(?![0-9A-Za-z_])")
"""A git hash as people paste them: 7 to 40 lowercase hex digits with at least one digit and one
letter, standing alone (``whitted_grid``, ``0.1719`` or ``1280x720`` are not)."""
DATE = re.compile(r"\b(19|20)\d\d-(0[1-9]|1[0-2])-(0[1-9]|[12]\d|3[01])\b")
"""An ISO date such as 2026-12-01."""
LINK = re.compile(r"\]\(([^)\s]+)[^)]*\)|<img[^>]+src=\"([^\"]+)\"|^\[[^\]]+\]:\s*(\S+)", re.M)
"""Targets of markdown links and images, inline, HTML or reference-style."""


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    """(completed ``mkdocs build --strict`` process, output folder)."""
    out = tmp_path_factory.mktemp("site")
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1"}
    p = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--config-file",
                        str(ROOT / "mkdocs.yml"), "--site-dir", str(out)],
                       cwd=ROOT, capture_output=True, text=True, env=env, timeout=600)
    return p, out


def test_the_site_builds_strictly(site):
    p, out = site
    assert p.returncode == 0, (p.stdout + p.stderr)[-4000:]
    assert "WARNING" not in p.stderr, p.stderr[-4000:]
    assert (out / "index.html").is_file()


def test_the_site_has_the_generated_pages(site):
    p, out = site
    assert p.returncode == 0, p.stderr[-2000:]
    cli = (out / "reference" / "cli.html").read_text()
    from workbench.app.cli import COMMANDS
    for command in (c.removeprefix("cmd_") for c in COMMANDS):
        assert f"workbench {command}" in cli, command
    assert "--max-memory" in cli and "--version" in cli
    api = (out / "reference" / "api" / "workbench.html").read_text()
    for name in ("load_scene", "available_methods", "WorkbenchError"):
        assert name in api, name
    render_api = (out / "reference" / "api" / "render.html").read_text()
    assert "RenderResult" in render_api
    assert ":class:<code>" not in render_api and ":func:<code>" not in render_api  # roles dropped
    for page in ("benchmarks/history.html", "methods/errata.html", "kernels.html", "guide/scenes.html"):
        assert (out / page).is_file(), page


def test_the_benchmark_index_lists_the_tables_present(tmp_path):
    """The bench scripts write docs/benchmarks/NAME.md; the index page links those that exist."""
    import importlib.util
    from types import SimpleNamespace
    spec = importlib.util.spec_from_file_location("docs_hooks", ROOT / "tools" / "docs_hooks.py")
    hooks = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(hooks)
    folder = tmp_path / "benchmarks"
    folder.mkdir()
    for name in ("index.md", "history.md"):
        (folder / name).write_text("# x\n")
    page = SimpleNamespace(file=SimpleNamespace(src_uri="benchmarks/index.md"))
    config = {"docs_dir": str(tmp_path)}
    text = f"## Tables\n\n{hooks.TABLES_MARKER}\n"
    empty = hooks.on_page_markdown(text, page, config, None)
    assert hooks.TABLES_MARKER not in empty and "No benchmark table" in empty
    (folder / "accel.md").write_text("# accel\n")
    (folder / "zbuffer.md").write_text("# zbuffer\n")
    listed = hooks.on_page_markdown(text, page, config, None)
    assert "- [`accel`](accel.md)\n- [`zbuffer`](zbuffer.md)" in listed
    assert "history" not in listed and "index.md" not in listed
    other = SimpleNamespace(file=SimpleNamespace(src_uri="guide/cli.md"))
    assert hooks.on_page_markdown(text, other, config, None) == text


def test_every_scene_kind_is_documented():
    from workbench.scene.kinds import KINDS
    text = (ROOT / "docs" / "guide" / "scenes.md").read_text()
    for kind in KINDS:
        assert f"| `{kind}` |" in text, kind


def test_every_method_is_in_the_methods_table():
    from workbench import available_methods
    text = (ROOT / "docs" / "methods" / "index.md").read_text()
    for method in available_methods():
        assert f"| `{method}` |" in text, method


def readme_problems(text: str) -> list[str]:
    """What keeps ``text`` from being the README: too long, a link leaving the repository
    (``../``, an absolute path), a commit-like hash, a date."""
    problems = []
    lines = text.splitlines()
    if len(lines) > README_MAX_LINES:
        problems.append(f"{len(lines)} lines (at most {README_MAX_LINES})")
    for n, line in enumerate(lines, 1):
        for match in LINK.finditer(line):
            target = next(g for g in match.groups() if g)
            if target.startswith(("../", "/")) or "/../" in target:
                problems.append(f"line {n}: link out of the repository: {target}")
        if "../" in line:
            problems.append(f"line {n}: a path out of the repository: {line.strip()}")
        for h in COMMIT_LIKE.findall(line):
            problems.append(f"line {n}: commit-like token {h}")
        if DATE.search(line):
            problems.append(f"line {n}: date {DATE.search(line).group(0)}")
    return problems


def test_the_readme_checks_catch_what_they_look_for():
    assert readme_problems("short\n") == []
    assert readme_problems("x\n" * (README_MAX_LINES + 1))
    assert readme_problems("see [design](../shared/DESIGN.md)\n")
    assert readme_problems("fixed in a4177d6\n")
    assert readme_problems("measured 2026-12-01 21:07\n")
    # names, sizes and numbers that only look like hex are fine
    assert readme_problems("![grid](docs/images/whitted_grid.png) at 1280x720, RMSE 0.1719, cafe\n") == []


def test_the_readme_is_short_and_timeless():
    problems = readme_problems(README.read_text())
    assert problems == [], "\n".join(problems)


def test_the_readme_links_resolve():
    text = README.read_text()
    targets = [next(g for g in m.groups() if g) for m in LINK.finditer(text)]
    local = [t.split("#")[0] for t in targets if not re.match(r"[a-z]+:", t) and not t.startswith("#")]
    assert local, "the README links into docs/"
    for target in local:
        assert (ROOT / target).exists(), target
