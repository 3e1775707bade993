#!/usr/bin/env bash
# CI for `grains view` (hooked into .ci/run after the release build): plays a
# small 2D and a small 3D run in Debian's headless chromium through
# playwright-core (which never downloads a browser of its own here), and
# checks the first frame, the grain count, Play and the console.
set -euxo pipefail

cd "$(dirname "$0")/.."
grains="${CARGO_TARGET_DIR:-target}/release/grains"
test -x "$grains"

if ! command -v chromium >/dev/null 2>&1; then
    apt-get update
    DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends chromium
fi
if ! command -v npm >/dev/null 2>&1; then
    apt-get update
    DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends nodejs npm
fi
(cd tools/view-test && PLAYWRIGHT_SKIP_BROWSER_DOWNLOAD=1 npm ci --no-audit --no-fund)

runs="$(mktemp -d)"
trap 'rm -rf "$runs"' EXIT
"$grains" run --out "$runs/v2" --steps 400 --set output.every=0.0005 --quiet
"$grains" run scenarios/pour-3d.toml --out "$runs/v3" --steps 400 \
    --set output.every=0.0002 --quiet
node tools/view-test/view_test.mjs "$grains" "$runs/v2" "$runs/v3"
