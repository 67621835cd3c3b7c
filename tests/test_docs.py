"""The documentation site's build hooks (scripts/docs/hooks.py)."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from types import ModuleType

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _hooks() -> ModuleType:
    spec = importlib.util.spec_from_file_location(
        "cloudprox_docs_hooks", ROOT / "scripts/docs/hooks.py"
    )
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


hooks = _hooks()


def test_cli_reference_has_every_subcommand() -> None:
    from cloudprox.cli import build_parser

    text = hooks.cli_reference()
    names = list(hooks._subcommands(build_parser()))
    assert {"demo", "collide", "view", "robot", "example", "info", "bench", "reproduce"} <= set(
        names
    )
    for name in names:
        assert f"## `cloudprox {name}` {{ #cloudprox-{name} }}" in text
        assert f"usage: cloudprox {name}" in text
    assert "--pose-a" in text and "--q-file" in text


def test_section_stops_at_the_next_heading_of_its_level() -> None:
    text = "# A\nintro\n## B\nb text\n```bash\n# not a heading\n```\n### C\nc text\n## D\nd text\n"
    assert hooks.section(text, "B") == "b text\n```bash\n# not a heading\n```\n### C\nc text"
    with pytest.raises(ValueError, match="no heading"):
        hooks.section(text, "E")


def test_include_relinks_from_the_source_to_the_page() -> None:
    page = "Before\n\n<!-- include: README.md#Robots -->\n\nAfter\n"
    out = hooks.include(page, "tutorials/robot.md", "docs")
    assert "<!-- include" not in out
    assert "](../planning/planning.png)" in out  # README's docs/planning/planning.png


def test_include_of_a_whole_file() -> None:
    out = hooks.include("<!-- include: BENCHMARKS.md -->", "benchmarks.md", "docs")
    assert out.startswith("# Benchmarks")


def test_formulas_become_mathml() -> None:
    pytest.importorskip("latex2mathml")
    page = (
        '<p><span class="arithmatex">\\(p_i = \\Phi(-d / \\sigma)\\)</span></p>'
        '<div class="arithmatex">\\[a &lt; b\\]</div>'
    )
    out = hooks.mathml(page)
    assert "arithmatex" not in out
    assert out.count("<math") == 2 and 'display="block"' in out
    assert "&#x0003C;" in out  # the HTML-escaped "<" reaches MathML as a character
