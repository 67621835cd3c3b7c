r"""MkDocs hooks of the documentation site (``mkdocs.yml``: ``hooks``).

Three things happen to a page:

- ``<!-- include: FILE -->`` is replaced by the repository file ``FILE`` (a path
  from the repository's root), and ``<!-- include: FILE#HEADING -->`` by the
  section of ``FILE`` under that heading (up to the next heading of the same or
  a higher level, the heading itself left out). Relative links and images of
  the included text are rewritten to point from the page to the same files, so
  ``README.md`` and ``BENCHMARKS.md`` stay the single source of what they say.
- The command-line reference (``docs/reference/cli.md``) is generated at build
  time from the installed ``cloudprox`` command's argparse parser
  (``cloudprox.cli.build_parser``): the page holds a marker that is replaced by
  the help of the command and of every subcommand, so the reference cannot
  drift from the code.
- Formulas (TeX between ``\(`` and ``\)`` or ``\[`` and ``\]``, marked by
  ``pymdownx.arithmatex``) are converted to MathML when the page is built
  (``latex2mathml``), which browsers render natively: no script, no network.
"""

from __future__ import annotations

import argparse
import html
import logging
import os
import posixpath
import re
from pathlib import Path
from typing import Any

#: The repository's root (this file is ``scripts/docs/hooks.py``).
ROOT = Path(__file__).resolve().parents[2]
#: ``<!-- include: FILE -->`` or ``<!-- include: FILE#HEADING -->``.
INCLUDE = re.compile(r"^<!-- include: ([^#>]+?)(?:#(.+?))? -->$", re.M)
#: A formula as ``pymdownx.arithmatex`` (generic mode) leaves it in the HTML.
MATH = re.compile(
    r'<span class="arithmatex">\\\((.*?)\\\)</span>'
    r'|<div class="arithmatex">\\\[(.*?)\\\]</div>',
    re.S,
)
#: TeX left in a page's text: a formula that arithmatex did not mark (in a
#: list item without blank lines around it, say) and that shows as source.
STRAY_TEX = re.compile(r"\\(?:[a-zA-Z]{2,}|[()\[\]])")
#: Code, and the MathML already made, where TeX-like text is expected.
CODE = re.compile(r"<(pre|code|math)\b.*?</\1>", re.S)

log = logging.getLogger("mkdocs.hooks.docs")

#: A Markdown link or image target: ``](target)``.
LINK = re.compile(r"\]\(([^)\s]+)\)")

#: The line of ``docs/reference/cli.md`` replaced by the generated reference.
CLI_MARKER = "<!-- cli-reference -->"
#: Width of the generated help text (argparse reads it from ``COLUMNS``).
HELP_WIDTH = 78


def _subcommands(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    """Return the subcommands of ``parser`` by name, in the order they were added."""
    out: dict[str, argparse.ArgumentParser] = {}
    for action in parser._actions:  # argparse has no public accessor for them
        if isinstance(action, argparse._SubParsersAction):
            out.update(action.choices)
    return out


def _help(parser: argparse.ArgumentParser) -> str:
    """``parser``'s help at a fixed width, whatever the terminal."""
    before = os.environ.get("COLUMNS")
    os.environ["COLUMNS"] = str(HELP_WIDTH)
    try:
        return parser.format_help().rstrip()
    finally:
        if before is None:
            del os.environ["COLUMNS"]
        else:
            os.environ["COLUMNS"] = before


def cli_reference() -> str:
    """Markdown of the command's help and every subcommand's help."""
    from cloudprox.cli import build_parser

    parser = build_parser()
    subcommands = _subcommands(parser)
    parts = [
        "## `cloudprox`",
        "",
        "Subcommands: " + ", ".join(f"[`{name}`](#cloudprox-{name})" for name in subcommands) + ".",
        "",
        "```text",
        _help(parser),
        "```",
    ]
    for name, sub in subcommands.items():
        parts += ["", f"## `cloudprox {name}` {{ #cloudprox-{name} }}", ""]
        parts += ["```text", _help(sub), "```"]
    return "\n".join(parts) + "\n"


def section(text: str, heading: str) -> str:
    """Return the body of the section of Markdown ``text`` under ``heading`` (its title)."""
    lines = text.splitlines()
    for i, line in enumerate(lines):
        m = re.match(r"^(#+)\s+(.*?)\s*$", line)
        if m and m.group(2) == heading:
            level = len(m.group(1))
            end = len(lines)
            fenced = False
            for j in range(i + 1, len(lines)):
                if lines[j].startswith("```"):
                    fenced = not fenced
                n = None if fenced else re.match(r"^(#+)\s", lines[j])
                if n and len(n.group(1)) <= level:
                    end = j
                    break
            return "\n".join(lines[i + 1 : end]).strip("\n")
    raise ValueError(f"no heading {heading!r}")


def _relink(text: str, source: str, page: str, docs_dir: str) -> str:
    """Rewrite the relative link targets of ``text`` (from ``source``) for ``page``.

    ``source`` is the included file's path from the repository's root, ``page`` the
    page's path from ``docs_dir`` (itself a path from the root).
    """
    source_dir = posixpath.dirname(source)
    page_dir = posixpath.dirname(posixpath.join(docs_dir, page))

    def fix(m: re.Match[str]) -> str:
        target = m.group(1)
        if re.match(r"^[a-z][a-z0-9+.-]*:", target) or target.startswith(("#", "/")):
            return m.group(0)
        path = posixpath.normpath(posixpath.join(source_dir, target))
        return f"]({posixpath.relpath(path, page_dir)})"

    return LINK.sub(fix, text)


def include(markdown: str, page: str, docs_dir: str) -> str:
    """Replace every include marker of ``markdown`` (see the module docs)."""

    def fill(m: re.Match[str]) -> str:
        source, heading = m.group(1).strip(), m.group(2)
        text = (ROOT / source).read_text(encoding="utf-8")
        if heading is not None:
            text = section(text, heading.strip())
        return _relink(text, source, page, docs_dir)

    return INCLUDE.sub(fill, markdown)


def on_page_markdown(markdown: str, *, page: Any, config: Any, files: Any) -> str:
    """Fill the include markers and the command-line reference of a page."""
    docs_dir = posixpath.relpath(Path(config["docs_dir"]).resolve().as_posix(), ROOT.as_posix())
    markdown = include(markdown, page.file.src_uri, docs_dir)
    if CLI_MARKER in markdown:
        markdown = markdown.replace(CLI_MARKER, cli_reference())
    return markdown


def mathml(page_html: str) -> str:
    """Replace the formulas of ``page_html`` by MathML."""
    from latex2mathml.converter import convert

    def fill(m: re.Match[str]) -> str:
        inline, block = m.group(1), m.group(2)
        tex = html.unescape(inline if inline is not None else block).strip()
        if inline is not None:
            return convert(tex, display="inline")
        return f'<div class="math-block">{convert(tex, display="block")}</div>'

    return MATH.sub(fill, page_html)


def on_page_content(html_text: str, *, page: Any, config: Any, files: Any) -> str:
    """Typeset the page's formulas as MathML; warn of TeX left as text."""
    out = mathml(html_text)
    stray = STRAY_TEX.search(CODE.sub("", out))
    if stray is not None:
        log.warning("%s: TeX outside a formula: %r", page.file.src_uri, stray.group(0))
    return out
