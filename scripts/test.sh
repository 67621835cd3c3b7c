#!/usr/bin/env bash
# Runs every check and test of cloudprox: Rust (format, lints, documentation, unit,
# integration and doc tests) and Python (the package built and installed, ruff,
# the documentation site, pytest).
# Usage: bash scripts/test.sh
set -euo pipefail
cd "$(dirname "$0")/.."

# Each step's header carries the seconds since the script started.
step() { printf '\n==> [%ss] %s\n' "$SECONDS" "$*"; }

step "cargo fmt --check"
cargo fmt --all -- --check

step "cargo clippy (all targets, -D warnings)"
cargo clippy --workspace --all-targets -- -D warnings

step "cargo doc (core crate, warnings as errors: missing docs, broken links)"
RUSTDOCFLAGS="-D warnings" cargo doc -p cloudprox --no-deps --quiet

step "cargo test (core crate: unit, integration, doc tests; the fuzz smoke run, tests/fuzz_smoke.rs)"
if cargo nextest --version >/dev/null 2>&1; then
    # Every test binary's tests side by side (cargo test runs the binaries one
    # after another), then the doc tests, which nextest does not run.
    cargo nextest run -p cloudprox --cargo-profile test --no-fail-fast --status-level fail
    cargo test -p cloudprox --doc
else
    cargo test -p cloudprox
fi

step "system packages (Open3D's libraries, apt lists for the Kinect frame)"
bash scripts/system-deps.sh

step "build and install the Python package"
python3 -m pip install --quiet --disable-pip-version-check -e '.[test]'

step "ruff"
python3 -m ruff check python tests benches scripts
python3 -m ruff format --check python tests benches scripts

step "stubs match the compiled module (mypy.stubtest)"
python3 -m mypy.stubtest cloudprox._native

step "documentation site (mkdocs build --strict, API reference from the installed package)"
NO_MKDOCS_2_WARNING=1 python3 -m mkdocs build --strict --site-dir "${TMPDIR:-/tmp}/cloudprox-site"

step "pytest: the whole suite (two workers, one file each; the quick reproduction first)"
# One run, so the quick reproduction (the longest file, tests/conftest.py
# schedules it first) runs beside the rest of the suite; a developer's fast
# run is -m "not network and not slow".
python3 -m pytest -q -n 2 --dist loadfile
