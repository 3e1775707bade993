#!/usr/bin/env bash
# Times two `grains bench` runs in turns and prints the ratio of each pair
# of wall times (second / first), then their median: the figures of
# docs/performance.md that compare grains with itself (Gear-5 against
# Verlet, two threads against one) and A/B checks of two builds.
#
#   bench/side_by_side.sh "chute --steps 300 --threads 1" \
#                         "chute --steps 300 --threads 1 --integrator gear5"
#   bench/side_by_side.sh "chute --steps 300 --threads 2" "chute --steps 300 --threads 1"
#   GRAINS_B=/tmp/grains-old bench/side_by_side.sh "chute --steps 300 --threads 1"
#
# ROUNDS (default 8) sets the number of pairs: on a shared machine one pair
# can be off by half either way, so quote the median of many. The second
# command defaults to the first; GRAINS_A and GRAINS_B name the binaries
# (both default to the release build).
# Needs a release build (`cargo build --release`; found under
# $CARGO_TARGET_DIR when set) and python3. Run from anywhere.
set -euo pipefail
[ $# -ge 1 ] || { sed -n '2,17p' "$0" >&2; exit 2; }
first=$1
second=${2:-$1}
rounds=${ROUNDS:-8}
[[ "$rounds" =~ ^[1-9][0-9]*$ ]] || { echo "ROUNDS must be a positive whole number, not '$rounds'" >&2; exit 2; }
root=$(cd "$(dirname "$0")/.." && pwd)
grains_a=${GRAINS_A:-"${CARGO_TARGET_DIR:-$root/target}/release/grains"}
grains_b=${GRAINS_B:-$grains_a}
for bin in "$grains_a" "$grains_b"; do
  [ -x "$bin" ] || { echo "$bin not found: cargo build --release" >&2; exit 2; }
done

wall() {
  local out
  # shellcheck disable=SC2086 # the bench arguments are meant to split
  out=$("$1" bench $2 --json) || exit 1
  echo "$out" | python3 -c 'import json,sys; print(json.load(sys.stdin)["wall_seconds"])'
}
results=()
for _ in $(seq "$rounds"); do
  a=$(wall "$grains_a" "$first")
  b=$(wall "$grains_b" "$second")
  results+=("$a $b")
done
python3 - "$first" "$second" "${results[@]}" <<'PY'
import statistics, sys
first, second = sys.argv[1], sys.argv[2]
pairs = [tuple(map(float, p.split())) for p in sys.argv[3:]]
print(f"A: grains bench {first}\nB: grains bench {second}")
for a, b in pairs:
    print(f"  A {a:8.3f} s   B {b:8.3f} s   B / A {b / a:.3f}")
ratios = sorted(b / a for a, b in pairs)
print(f"  median B / A of {len(pairs)} pairs: {statistics.median(ratios):.3f} "
      f"(from {ratios[0]:.3f} to {ratios[-1]:.3f})")
PY
