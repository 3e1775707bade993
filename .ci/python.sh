#!/usr/bin/env bash
# CI for the Python package (crates/grains-py, python/): lints the
# bindings, builds the package with `pip install .` in a fresh virtual
# environment, and runs the pytest suite against the CLI built here.
# Idempotent; runs from the repository root of a clean clone on a Debian
# machine with the Rust toolchain and python3.
set -euxo pipefail

cd "$(dirname "$0")/.."

# python3 -m venv needs Debian's python3-venv (ensurepip).
if ! python3 -c 'import ensurepip, venv' >/dev/null 2>&1; then
    apt-get update
    apt-get install -y --no-install-recommends python3-venv python3-pip
fi

# The bindings are not a default workspace member: lint them by name.
cargo fmt --all -- --check
cargo clippy -p grains-py --all-targets -- -D warnings

# The CLI the bit-for-bit tests compare with.
cargo build --release -p grains-cli
export GRAINS_BIN="${CARGO_TARGET_DIR:-$PWD/target}/release/grains"

# A fresh directory of its own, so that two CI runs on one machine never
# share (or remove) each other's environment.
venv=$(mktemp -d /tmp/grains-ci-venv.XXXXXX)
trap 'rm -rf "$venv"' EXIT
python3 -m venv "$venv"
"$venv/bin/python" -m pip install --quiet --upgrade pip
"$venv/bin/python" -m pip install --quiet . pytest pandas
"$venv/bin/python" -c 'import grains; help(grains.Simulation)' >/dev/null

# Run from outside the tree so that `import grains` is the installed one.
status=0
(cd /tmp && "$venv/bin/python" -m pytest -q "$OLDPWD/python/tests") || status=$?
# pytest exits 5 when it collected no tests: that is a failure here too,
# but say so plainly.
if [ "$status" -eq 5 ]; then
    echo "python/tests: pytest collected no tests" >&2
    exit 1
fi
exit "$status"
