"""The README's "from sensor files" commands, run verbatim in a fresh folder."""

from __future__ import annotations

import contextlib
import io
import os
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

README = Path(__file__).resolve().parents[1] / "README.md"


def _block(tag: str) -> str:
    """The fenced code block that follows ``<!-- readme-test: TAG -->``."""
    text = README.read_text()
    m = re.search(rf"<!-- readme-test: {tag} -->\n```\w+\n(.*?)```", text, re.S)
    assert m, f"README has no block tagged readme-test: {tag}"
    return m.group(1)


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("readme")


def test_readme_cli_line(folder: Path) -> None:
    line = _block("cli").strip()
    assert "\n" not in line, "the README promises one command line"
    # Run each `&&`-joined command: the installed `cloudprox` script when it is on
    # PATH (as the README runs it), else the package's module.
    script = shutil.which("cloudprox")
    launcher = [script] if script else [sys.executable, "-m", "cloudprox"]
    outputs = []
    for command in line.split("&&"):
        argv = shlex.split(command)
        assert argv[0] == "cloudprox"
        done = subprocess.run(
            [*launcher, *argv[1:]],
            cwd=folder,
            capture_output=True,
            text=True,
            check=False,
            env={**os.environ, "COLUMNS": "200"},
        )
        assert done.returncode == 0, done.stderr
        outputs.append(done.stdout)
    assert "state: free" in outputs[-1], outputs[-1]
    assert "shadow ->" in outputs[-1]


def test_readme_python_lines(folder: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    code = _block("python")
    lines = [ln for ln in code.splitlines() if ln.strip()]
    assert len(lines) == 5, "the README promises five lines of Python"
    if not (folder / "example" / "scan.pcd").exists():
        from cloudprox.examples import write_example_files

        write_example_files(folder / "example")
    monkeypatch.chdir(folder)
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(code, str(README), "exec"), {})
    probability, state = out.getvalue().split()[:2]
    assert state == "collision"
    assert float(probability) >= 0.9


def test_readme_api_python_block() -> None:
    """The Python section's block: a request, a query, typed statistics."""
    code = _block("api-python")
    assert "request=" in code and "CollisionRequest(" in code
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(code, str(README), "exec"), {})
    fields = out.getvalue().split()
    assert 0.0 <= float(fields[0]) <= 1.0
    assert fields[1] in ("free", "contact", "collision")
    assert float(fields[-1]) > 0.0
