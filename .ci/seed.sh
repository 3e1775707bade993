#!/usr/bin/env bash
# Seed 002 second pass (issue 31): the ensemble tools run end to end on a
# short smoke ensemble (two seeds, 2000 steps, one Fig. 2 and one Fig. 3
# setting) and their table has a row per setting. Needs python3 (standard
# library only) and the opt-test build of the binary
# (cargo build --profile opt-test -p grains-cli); idempotent.
set -euxo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
bin="${CARGO_TARGET_DIR:-$root/target}/opt-test/grains"
[ -x "$bin" ] || (cd "$root" && cargo build --profile opt-test -p grains-cli)
BIN="$bin" OUT="$work/e" SEEDS=1,2 STEPS=2000 \
  "$root/tools/seed002_ensembles.sh" m-today-flat w-today-elastic-gs0
python3 "$root/tools/seed002_table.py" "$work/e" >"$work/table.md"
cat "$work/table.md"
grep -q '^| m-today-flat | 2/2 |' "$work/table.md"
grep -q '^| w-today-elastic-gs0 | 2/2 |' "$work/table.md"
echo "seed: ensemble tools ran"
