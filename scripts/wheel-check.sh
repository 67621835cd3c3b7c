#!/usr/bin/env bash
# Checks the packages a user installs, as CI runs it (.ci/run):
#   1. `maturin sdist`, unpacked in a temporary folder;
#   2. a release wheel built from the unpacked sdist alone (so the sdist holds
#      everything it needs), checked to be an abi3 wheel for the Python floor
#      that the PyO3 crate is built for (`abi3-py311`: cp311-abi3);
#   3. that wheel installed into a fresh virtual environment (`python3 -m venv`),
#      and `cloudprox demo` run from there, which must write its PNG.
# One wheel build in all. CARGO_TARGET_DIR defaults to this repository's target/,
# so the registry dependencies already compiled by `pip install .` (README
# command 1) are reused; only the two workspace crates are compiled again.
# Usage: bash scripts/wheel-check.sh   (needs maturin: python3 -m pip install maturin)
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD

step() { printf '\n==> [%ss] %s\n' "$SECONDS" "$*"; }

work=$(mktemp -d "${TMPDIR:-/tmp}/cloudprox-wheel.XXXXXX")
trap 'rm -rf "$work"' EXIT
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$root/target}"
# The floor the extension is built for: `abi3-pyXY` in the PyO3 crate's features.
abi3=$(sed -n 's/.*"abi3-py\([0-9]*\)".*/\1/p' crates/cloudprox-py/Cargo.toml)
if [ -z "$abi3" ]; then
    echo "wheel-check: no abi3-pyXY feature in crates/cloudprox-py/Cargo.toml" >&2
    exit 1
fi

step "sdist (maturin sdist), unpacked in $work"
python3 -m maturin sdist --out "$work/sdist" 2>&1 | tail -n 1
sdist=$(find "$work/sdist" -name 'cloudprox-*.tar.gz' | head -n 1)
tar -xzf "$sdist" -C "$work"
src=$(find "$work" -mindepth 1 -maxdepth 1 -type d -name 'cloudprox-*' | head -n 1)
echo "$(basename "$sdist"): $(tar -tzf "$sdist" | wc -l) files"
# Newer than anything in the shared target dir: cargo compiles the workspace
# crates from the sdist's own sources (not the artifacts of the repository's).
find "$src" -type f -exec touch {} +

step "release wheel from the unpacked sdist alone"
(cd "$src" && python3 -m maturin build --release --out "$work/wheels" 2>&1 | grep -E "Compiling cloudprox|Built wheel")
wheel=$(find "$work/wheels" -name 'cloudprox-*.whl' | head -n 1)
name=$(basename "$wheel")
echo "$name"
case "$name" in
    *-cp"$abi3"-abi3-*) echo "abi3 tag: cp$abi3-abi3, as crates/cloudprox-py builds it" ;;
    *)
        echo "wheel-check: $name is not a cp$abi3-abi3 wheel" >&2
        exit 1
        ;;
esac

step "the wheel in a fresh virtual environment: cloudprox demo"
python3 -m venv "$work/venv"
"$work/venv/bin/python" -m pip install --quiet --disable-pip-version-check "$wheel"
(cd "$work" && "$work/venv/bin/cloudprox" demo --out "$work/demo" >/dev/null)
test -s "$work/demo/demo.png"
echo "demo.png: $(wc -c <"$work/demo/demo.png") bytes, from $("$work/venv/bin/python" --version)"
