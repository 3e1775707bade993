#!/usr/bin/env bash
# Times two `grains bench` runs in turns and prints the ratio of each pair
# of figures (wall times unless FIGURE says; second / first), then their
# median: the figures of docs/performance.md that compare grains with
# itself (Gear-5 against Verlet, two threads against one) and A/B checks
# of two builds.
#
#   bench/side_by_side.sh "chute --steps 300 --threads 1" \
#                         "chute --steps 300 --threads 1 --integrator gear5"
#   bench/side_by_side.sh "chute --steps 300 --threads 2" "chute --steps 300 --threads 1"
#   GRAINS_B=/tmp/grains-old bench/side_by_side.sh "chute --steps 300 --threads 1"
#
# ROUNDS (default 8) sets the number of pairs: on a shared machine one pair
# can be off by half either way, so quote the median of many. The second
# command defaults to the first; GRAINS_A and GRAINS_B name the binaries
# (both default to the release build). FIGURE names the field of the
# bench's JSON to compare (default wall_seconds, the whole run with its
# set-up; ns_per_particle_step compares the timed steps alone):
#
#   FIGURE=ns_per_particle_step bench/side_by_side.sh \
#     "chute-hertz --steps 500 --threads 1" "chute --steps 500 --threads 1"
# Needs a release build (`cargo build --release`; found under
# $CARGO_TARGET_DIR when set) and python3. Run from anywhere.
set -euo pipefail
[ $# -ge 1 ] || { sed -n '2,22p' "$0" >&2; exit 2; }
first=$1
second=${2:-$1}
rounds=${ROUNDS:-8}
figure=${FIGURE:-wall_seconds}
case "$figure" in
  wall_seconds|cpu_seconds|ns_per_particle_step) ;;
  *) echo "FIGURE must be wall_seconds, cpu_seconds or ns_per_particle_step, not '$figure'" >&2; exit 2 ;;
esac
[[ "$rounds" =~ ^[1-9][0-9]*$ ]] || { echo "ROUNDS must be a positive whole number, not '$rounds'" >&2; exit 2; }
root=$(cd "$(dirname "$0")/.." && pwd)
grains_a=${GRAINS_A:-"${CARGO_TARGET_DIR:-$root/target}/release/grains"}
grains_b=${GRAINS_B:-$grains_a}
for bin in "$grains_a" "$grains_b"; do
  [ -x "$bin" ] || { echo "$bin not found: cargo build --release" >&2; exit 2; }
done

measure() {
  local out
  # shellcheck disable=SC2086 # the bench arguments are meant to split
  out=$("$1" bench $2 --json) || exit 1
  echo "$out" | FIGURE=$figure python3 -c 'import json,os,sys; print(json.load(sys.stdin)[os.environ["FIGURE"]])'
}
results=()
for _ in $(seq "$rounds"); do
  a=$(measure "$grains_a" "$first")
  b=$(measure "$grains_b" "$second")
  results+=("$a $b")
done
python3 - "$figure" "$first" "$second" "${results[@]}" <<'PY'
import statistics, sys
figure, first, second = sys.argv[1], sys.argv[2], sys.argv[3]
unit = {"wall_seconds": "s", "cpu_seconds": "s", "ns_per_particle_step": "ns"}[figure]
pairs = [tuple(map(float, p.split())) for p in sys.argv[4:]]
print(f"A: grains bench {first}\nB: grains bench {second}\n({figure})")
for a, b in pairs:
    print(f"  A {a:8.3f} {unit:2}  B {b:8.3f} {unit:2}  B / A {b / a:.3f}")
ratios = sorted(b / a for a, b in pairs)
print(f"  median B / A of {len(pairs)} pairs: {statistics.median(ratios):.3f} "
      f"(from {ratios[0]:.3f} to {ratios[-1]:.3f})")
PY
