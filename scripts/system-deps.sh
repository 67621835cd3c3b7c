#!/usr/bin/env bash
# System packages the test suite and `cloudprox reproduce` need beyond Python and
# Rust: the shared libraries Open3D (the reconstruct-then-collide baseline) links
# to, and apt's package lists, from which the real Kinect frame of Debian's
# `mrpt-common` is fetched (`apt-get download`, into cloudprox's cache), and
# headless Chromium, which renders the interactive view in tests/test_view.py.
# Usage (as root on Debian/Ubuntu): bash scripts/system-deps.sh
set -euo pipefail
if ! command -v apt-get >/dev/null 2>&1; then
    echo "system-deps: no apt-get here; install libusb-1.0, libGL, libX11 and chromium yourself" >&2
    exit 0
fi
if [ "$(id -u)" != 0 ]; then
    echo "system-deps: not root; run as root: apt-get update && apt-get install libusb-1.0-0 libgl1 libx11-6 chromium" >&2
    exit 0
fi
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
apt-get install -y -qq --no-install-recommends libusb-1.0-0 libgl1 libx11-6 >/dev/null
# Headless Chromium renders the interactive view's HTML in tests/test_view.py.
apt-get install -y -qq --no-install-recommends chromium >/dev/null \
    || apt-get install -y -qq --no-install-recommends chromium-browser >/dev/null \
    || echo "system-deps: could not install chromium; tests/test_view.py will fail on CI" >&2
