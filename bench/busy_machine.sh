#!/usr/bin/env bash
# Times grains with all its threads against one thread while another
# process keeps one core busy (a laptop with a browser open, a shared node),
# in alternating pairs, and prints each pair's ratio and their median
# (all threads / one thread: at most 1.10 is the target). Then the same on
# the quiet machine, where more threads should pay.
#
#   bench/busy_machine.sh                     # the default run and the chute
#   ROUNDS=5 bench/busy_machine.sh
#   GRAINS=/tmp/grains-old bench/busy_machine.sh   # another build
#
# The pairs: `grains run` (the built-in default, default threads against
# --threads 1) and `grains bench chute --steps 300` (--threads 2 against
# --threads 1). Needs a release build (`cargo build --release`) and python3.
set -euo pipefail
rounds=${ROUNDS:-5}
[[ "$rounds" =~ ^[1-9][0-9]*$ ]] || { echo "ROUNDS must be a positive whole number, not '$rounds'" >&2; exit 2; }
root=$(cd "$(dirname "$0")/.." && pwd)
grains=${GRAINS:-"${CARGO_TARGET_DIR:-$root/target}/release/grains"}
[ -x "$grains" ] || { echo "$grains not found: cargo build --release" >&2; exit 2; }
out=$(mktemp -d)
busy=
stop_busy() { [ -n "$busy" ] && kill "$busy" 2>/dev/null; busy=; }
trap 'stop_busy; rm -rf "$out"' EXIT

# Seconds of one command, from its own JSON (run: summary.json; bench: --json).
run_seconds() {
  "$grains" run --out "$out/run" --overwrite --quiet "$@"
  python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["wall_seconds"])' "$out/run/summary.json"
}
bench_seconds() {
  "$grains" bench chute --steps 300 --json "$@" |
    python3 -c 'import json,sys; print(json.load(sys.stdin)["wall_seconds"])'
}

# Prints the pairs' ratios (A / B) and their median: `pairs NAME CMD_A -- CMD_B`.
pairs() {
  local name=$1; shift
  local a=() b=() seen=
  for x in "$@"; do
    if [ "$x" = -- ]; then seen=1; elif [ -z "$seen" ]; then a+=("$x"); else b+=("$x"); fi
  done
  local results=() ta tb
  # Every other round runs B first: the first of two runs back to back
  # tends to be the slower one, which would otherwise count against A.
  for r in $(seq "$rounds"); do
    if ((r % 2)); then
      ta=$("${a[@]}"); tb=$("${b[@]}")
    else
      tb=$("${b[@]}"); ta=$("${a[@]}")
    fi
    results+=("$ta $tb")
  done
  python3 - "$name" "${results[@]}" <<'PY'
import statistics, sys
name, pairs = sys.argv[1], [tuple(map(float, p.split())) for p in sys.argv[2:]]
ratios = sorted(a / b for a, b in pairs)
print(f"{name}: " + ", ".join(f"{a:.3f}/{b:.3f}" for a, b in pairs))
print(f"  median ratio of {len(pairs)} pairs: {statistics.median(ratios):.3f} "
      f"(from {ratios[0]:.3f} to {ratios[-1]:.3f})")
PY
}

cores=$(nproc)
echo "machine: $cores CPUs available; $grains"
for load in busy quiet; do
  if [ "$load" = busy ]; then
    # One core kept busy by another process.
    sh -c 'while :; do :; done' &
    busy=$!
  fi
  echo "== $load machine"
  pairs "grains run, default threads / --threads 1" run_seconds -- run_seconds --threads 1
  pairs "bench chute, --threads 2 / --threads 1" bench_seconds --threads 2 -- bench_seconds --threads 1
  stop_busy
done
