"""What importing the package loads: the library, not scipy nor the development code.

Each import runs in a fresh interpreter (this one has imported everything the
suite uses), which reports the modules it holds afterwards.
"""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

#: Modules the package's import must not load: scipy, and the code of the
#: development commands (the paper's reproduction, the bench, the dataset fetchers).
HEAVY = ("scipy", "cloudprox.reproduce", "cloudprox.bench", "cloudprox.datasets")


def _modules_after(code: str) -> set[str]:
    report = "import json, sys; print(json.dumps(sorted(sys.modules)))"
    done = subprocess.run(
        [sys.executable, "-c", f"{code}\n{report}"],
        capture_output=True,
        text=True,
        check=True,
        timeout=120,
    )
    return set(json.loads(done.stdout.strip().splitlines()[-1]))


def _heavy(modules: set[str]) -> list[str]:
    return sorted(m for m in modules if m.split(".")[0] == "scipy" or m.startswith(HEAVY[1:]))


@pytest.mark.parametrize(
    "code",
    [
        "import cloudprox",
        "import cloudprox.cli",
        "import cloudprox.view",
        # the command's help: every subcommand's parser is built
        "import contextlib, io\nfrom cloudprox.cli import main\n"
        "with contextlib.redirect_stdout(io.StringIO()):\n    main(['--help'])",
    ],
)
def test_import_loads_neither_scipy_nor_the_development_code(code: str) -> None:
    modules = _modules_after(code)
    assert "cloudprox._native" in modules
    assert _heavy(modules) == []


def test_the_development_code_is_what_the_check_looks_for() -> None:
    # The check above would pass vacuously if the names were wrong: the
    # reproduction's import does load scipy and itself.
    pytest.importorskip("scipy")
    heavy = _heavy(_modules_after("import cloudprox.reproduce.run"))
    assert "cloudprox.reproduce" in heavy and "scipy" in heavy
