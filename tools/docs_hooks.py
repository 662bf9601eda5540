"""MkDocs hooks of the documentation site (``hooks:`` in mkdocs.yml).

* ``reference/cli.md`` is generated at every build from the command line's own parser
  (:func:`workbench.app.cli.build_parser`): each command's ``--help`` text, so the page cannot
  fall behind the program.
* The docstrings cross-reference in Sphinx's roles (``:class:`Scene```); mkdocstrings shows the
  role's name before the code, so the API pages drop it (``:class:<code>`` -> ``<code>``), and a
  leading ``~.`` or ``.`` of a relative name.
* ``benchmarks/index.md`` gets, in place of the line ``<!-- benchmark tables -->``, a list of
  the benchmark tables present in ``docs/benchmarks/`` (each bench script writes its own
  ``NAME.md`` there; which ones exist depends on which scripts have been run).
"""
from __future__ import annotations

import argparse
import os
import re
import sys
from pathlib import Path

from mkdocs.structure.files import File

ROOT = Path(__file__).resolve().parents[1]
CLI_PAGE = "reference/cli.md"
TABLES_MARKER = "<!-- benchmark tables -->"
COLUMNS = "78"
"""Width of the help texts on the page (argparse wraps to the terminal's ``COLUMNS``)."""


def _help(parser: argparse.ArgumentParser) -> str:
    old = os.environ.get("COLUMNS")
    os.environ["COLUMNS"] = COLUMNS
    try:
        return parser.format_help().rstrip()
    finally:
        if old is None:
            del os.environ["COLUMNS"]
        else:
            os.environ["COLUMNS"] = old


def _subcommands(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    """Name -> parser of ``parser``'s subcommands, in the order they were added, aliases left out."""
    out: dict[str, argparse.ArgumentParser] = {}
    seen: set[int] = set()
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                if id(sub) not in seen:
                    seen.add(id(sub))
                    out[name] = sub
    return out


def cli_reference() -> str:
    """The markdown of the command-line reference page."""
    if str(ROOT) not in sys.path:
        sys.path.insert(0, str(ROOT))
    from workbench.app.cli import build_parser
    top = build_parser()
    lines = ["# Command-line reference", "",
             "Generated from the program's own `--help` texts when this site is built. "
             "The [command-line guide](../guide/cli.md) explains the commands with examples.", "",
             "```text", _help(top), "```", ""]
    for name, parser in _subcommands(top).items():
        nested = _subcommands(parser)
        lines += [f"## workbench {name}", "", "```text", _help(parser), "```", ""]
        for sub_name, sub in nested.items():
            lines += [f"### workbench {name} {sub_name}", "", "```text", _help(sub), "```", ""]
    return "\n".join(lines)


SPHINX_ROLE = re.compile(r":(?:class|func|meth|mod|data|attr|exc|obj):<code>~?\.?")
"""A Sphinx role in a docstring as rendered: the role's name, then the name in ``<code>``."""


def on_page_content(html, page, config, files):
    if not page.file.src_uri.startswith("reference/api/"):
        return html
    return SPHINX_ROLE.sub("<code>", html)


def on_files(files, config):
    files.append(File.generated(config, CLI_PAGE, content=cli_reference()))
    return files


def on_page_markdown(markdown, page, config, files):
    if page.file.src_uri != "benchmarks/index.md" or TABLES_MARKER not in markdown:
        return markdown
    folder = Path(config["docs_dir"]) / "benchmarks"
    tables = sorted(p.name for p in folder.glob("*.md") if p.name not in ("index.md", "history.md"))
    if tables:
        listing = "\n".join(f"- [`{name[:-3]}`]({name})" for name in tables)
    else:
        listing = "No benchmark table has been written here yet: run a script above to write its table."
    return markdown.replace(TABLES_MARKER, listing)
