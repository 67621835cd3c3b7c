#!/usr/bin/env bash
# Runs every check and test of cloudprox: Rust (format, lints, unit, integration
# and doc tests) and Python (the package built and installed, ruff, pytest).
# Usage: bash scripts/test.sh
set -euo pipefail
cd "$(dirname "$0")/.."

step() { printf '\n==> %s\n' "$*"; }

step "cargo fmt --check"
cargo fmt --all -- --check

step "cargo clippy (all targets, -D warnings)"
cargo clippy --workspace --all-targets -- -D warnings

step "cargo test (core crate: unit, integration, doc tests)"
cargo test -p cloudprox

step "system packages (Open3D's libraries, apt lists for the Kinect frame)"
bash scripts/system-deps.sh

step "build and install the Python package"
python3 -m pip install --quiet --disable-pip-version-check -e '.[test]'

step "ruff"
python3 -m ruff check python tests benches
python3 -m ruff format --check python tests benches

step "stubs match the compiled module (mypy.stubtest)"
python3 -m mypy.stubtest cloudprox._native

step "pytest"
python3 -m pytest -q
