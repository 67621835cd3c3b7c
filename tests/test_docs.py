"""The documentation: the site's build hooks (scripts/docs/hooks.py), BENCHMARKS.md as
the rendering of its results file, and the user docs' promises (sizes, no development
history, no commit hashes of this repository)."""

from __future__ import annotations

import importlib.util
import re
import shutil
import subprocess
import sys
from pathlib import Path
from types import ModuleType

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _load(name: str, path: str) -> ModuleType:
    spec = importlib.util.spec_from_file_location(name, ROOT / path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


hooks = _load("cloudprox_docs_hooks", "scripts/docs/hooks.py")
benchmarks_md = _load("cloudprox_benchmarks_md", "scripts/benchmarks_md.py")


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
    assert "](../how-to/check-a-robot.md)" in out  # README's docs/how-to/check-a-robot.md


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


# ------------------------------------------------------------------ BENCHMARKS.md


def test_benchmarks_md_is_the_rendering_of_the_results_file() -> None:
    rendered = benchmarks_md.render(benchmarks_md.load())
    assert (ROOT / "BENCHMARKS.md").read_text(encoding="utf-8") == rendered, (
        "BENCHMARKS.md is generated: edit benchmarks/results.json, then run "
        "python3 scripts/benchmarks_md.py"
    )


def test_every_benchmark_states_machine_date_and_command() -> None:
    entries = benchmarks_md.load()["benchmarks"]
    assert len({e["id"] for e in entries}) == len(entries)
    for entry in entries:
        assert entry["machine"].strip() and entry["command"], entry["id"]
        assert re.search(r"\b20\d\d-\d\d-\d\d\b", entry["date"]), entry["id"]
        assert entry["rows"] and all(len(r) == len(entry["columns"]) for r in entry["rows"])


def test_the_renderer_refuses_a_ragged_table() -> None:
    entry = dict(benchmarks_md.load()["benchmarks"][0])
    entry["rows"] = [["one cell"]]
    with pytest.raises(ValueError, match="cells"):
        benchmarks_md.render_entry(entry)


# ------------------------------------------------------------------ the user docs

#: The user docs: the files a newcomer reads, and every page of the site.
USER_DOCS = [
    "README.md",
    "BENCHMARKS.md",
    "CHANGELOG.md",
    *sorted(p.relative_to(ROOT).as_posix() for p in (ROOT / "docs").rglob("*.md")),
]
KB = 1024


def _text(path: str) -> str:
    return (ROOT / path).read_text(encoding="utf-8")


def test_readme_is_a_landing_page() -> None:
    text = _text("README.md")
    assert len(text.splitlines()) <= 300 and len(text.encode()) <= 25 * KB
    first = "\n".join(text.splitlines()[:40])
    assert "python3 -m pip install . && cloudprox demo" in first
    assert "bash scripts/test.sh" in first


def test_sizes() -> None:
    assert len(_text("BENCHMARKS.md").encode()) <= 40 * KB
    for path in USER_DOCS:
        assert len(_text(path).encode()) <= 60 * KB, path


def _commits() -> list[str]:
    git = shutil.which("git")
    if git is None:
        pytest.skip("git is not installed")
    done = subprocess.run(
        [git, "rev-list", "--all"], cwd=ROOT, capture_output=True, text=True, check=False
    )
    if done.returncode != 0 or not done.stdout.strip():
        pytest.skip("not a git checkout")
    return done.stdout.split()


def test_no_commit_hash_of_this_repository_in_the_user_docs() -> None:
    commits = _commits()
    found = []
    for path in USER_DOCS:
        for token in set(re.findall(r"\b[0-9a-fA-F]{7,40}\b", _text(path))):
            if any(c.startswith(token.lower()) for c in commits):
                found.append(f"{path}: {token}")
    assert not found, found


#: Development history in prose: the working sessions, numbered rounds or stops,
#: issue numbers and before/after lines with commit-like tokens.
ORDINAL = (
    r"(?:first|second|third|fourth|fifth|sixth|seventh|eighth|ninth|tenth|eleventh|"
    r"twelfth|thirteenth|fourteenth|fifteenth|sixteenth|seventeenth|eighteenth|"
    r"nineteenth|twentieth|twenty-\w+|thirtieth|\d+(?:st|nd|rd|th))"
)
HISTORY = [
    r"\bsessions?\b",
    rf"\b{ORDINAL}\s+(?:session|round|section|stop)\b",
    r"\b(?:round|stop)\s+\d+\b",
    r"\bissue\s+#?\d+\b",
    r"\b(?:before|after) = `?[0-9a-f]{7,}",
    r"\b[0-9a-f]{7,12}\b.*\b(?:against|before|after)\b",
]


def test_no_development_history_in_the_user_docs() -> None:
    found = []
    for path in USER_DOCS:
        for n, line in enumerate(_text(path).splitlines(), 1):
            for pattern in HISTORY:
                if re.search(pattern, line, re.I):
                    found.append(f"{path}:{n}: {line.strip()[:80]}")
            # What was tried and set aside is listed in the design records only.
            if "not kept" in line.lower() and not path.startswith("docs/design/"):
                found.append(f"{path}:{n}: {line.strip()[:80]}")
    assert not found, "\n".join(found)


def test_dates_only_on_measurements() -> None:
    """Dates belong to BENCHMARKS.md's measurements, not to the prose."""
    found = [
        f"{path}: {m.group(0)}"
        for path in USER_DOCS
        if path != "BENCHMARKS.md"
        for m in re.finditer(r"\b20\d\d-\d\d-\d\d\b", _text(path))
    ]
    assert not found, found


def test_benchmarks_hold_no_before_and_after() -> None:
    text = _text("BENCHMARKS.md")
    assert not re.search(r"\d\s*->\s*\d|\bbefore and after\b", text, re.I)


def test_the_default_model_is_named_in_two_marked_places() -> None:
    """README and the concepts page name the default model; no other page does.

    (The CHANGELOG may record a change of default.)
    """
    readme = _text("README.md")
    assert readme.count("<!-- default-model -->") == 1
    assert "The default model" in _text("docs/concepts/probability.md")
    found = [
        path
        for path in USER_DOCS
        if path not in ("README.md", "CHANGELOG.md", "docs/concepts/probability.md")
        and re.search(r"default model|(?:stays|remains|is not|not) the default", _text(path), re.I)
    ]
    assert not found, found


def test_relative_links_of_the_root_files_resolve() -> None:
    """README, CHANGELOG and BENCHMARKS link to files that exist (GitHub renders them)."""
    missing = []
    for path in ("README.md", "CHANGELOG.md", "BENCHMARKS.md"):
        for target in re.findall(r"\]\(([^)\s]+)\)", _text(path)):
            if re.match(r"^[a-z][a-z0-9+.-]*:", target) or target.startswith("#"):
                continue
            if not (ROOT / target.split("#")[0]).exists():
                missing.append(f"{path}: {target}")
    assert not missing, missing
