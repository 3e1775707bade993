#!/usr/bin/env bash
# Times the mesh-wall benchmark against its analytic twin in turns: 100 000
# grains resting on a floor of 100 352 triangles (bench/mesh-floor.toml)
# and on the plane z = 0 (bench/plane-floor.toml), and prints per round the
# ratio of the run's wall time and of its CPU time (mesh / plane), then
# the medians. The target: at most 1.5.
#
#   bench/mesh_vs_plane.sh                 # 4 rounds of 400 steps, 1 thread
#   ROUNDS=6 STEPS=1000 THREADS=2 bench/mesh_vs_plane.sh
#
# What is timed is a settled bed, the state the target speaks of (grains
# resting on the wall, not a lattice dropping onto it): each side first
# runs SETTLE steps (default 3000, 0.086 s: the bed's slowest breathing
# mode has then done a full swing and its kinetic energy is down to 1e-3
# of its first peak) and writes a checkpoint there, untimed; each round
# then resumes a fresh copy of that checkpoint for STEPS steps. Both sides
# settle the same way from the same lattice, and a flat mesh pushes as the
# plane does, so the timed steps start from the same bed on either floor
# (its kinetic energy agrees to the last digit). A timed run includes
# reading the
# checkpoint and building the floor (for the mesh: reading the STL and
# its grid, about 0.1 s), as a real run does once.
#
# GRAINS names the binary (default the opt-test build, whose arithmetic is
# the release one). Writes the floor's STL under $TMPDIR first
# (tools/make_mesh_stl.py --bench-floor). Needs python3.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
grains=${GRAINS:-"${CARGO_TARGET_DIR:-$root/target}/opt-test/grains"}
rounds=${ROUNDS:-4}
steps=${STEPS:-400}
settle=${SETTLE:-3000}
threads=${THREADS:-1}
[ -x "$grains" ] || { echo "$grains not found: cargo build --profile opt-test -p grains-cli" >&2; exit 2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
python3 "$root/tools/make_mesh_stl.py" --bench-floor "$work/floor.stl" >/dev/null

for kind in mesh plane; do
  set=()
  [ "$kind" = mesh ] && set=(--set "walls.0.shape.file=$work/floor.stl")
  echo "settling the bed on the $kind floor ($settle steps)" >&2
  "$grains" run "$root/bench/$kind-floor.toml" "${set[@]}" --steps "$settle" \
    --checkpoint-every "${settle}steps" --threads "$threads" --out "$work/settled-$kind" --quiet
done

one() { # kind -> "wall cpu fields"
  local kind=$1 out="$work/$1"
  rm -rf "$out"
  cp -r "$work/settled-$kind" "$out"
  /usr/bin/time -f "%U %S" -o "$work/time" "$grains" resume "$out" --steps "$steps" \
    --checkpoint-every 1000000000steps --threads "$threads" --quiet
  python3 - "$out/summary.json" "$work/time" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
u, k = map(float, open(sys.argv[2]).read().split()[-2:])
print(s["wall_seconds"], u + k, s["phase_seconds"]["fields"])
PY
}

printf "%-6s %10s %10s %10s %10s %10s %10s\n" round "mesh wall" "plane wall" "wall ratio" "cpu ratio" "mesh fields" "plane fields"
ratios=()
cpus=()
for r in $(seq "$rounds"); do
  read -r mw mc mf < <(one mesh)
  read -r pw pc pf < <(one plane)
  rw=$(python3 -c "print(f'{$mw / $pw:.3f}')")
  rc=$(python3 -c "print(f'{$mc / $pc:.3f}')")
  ratios+=("$rw")
  cpus+=("$rc")
  printf "%-6s %10.2f %10.2f %10s %10s %10.2f %10.2f\n" "$r" "$mw" "$pw" "$rw" "$rc" "$mf" "$pf"
done
python3 -c "import statistics as s, sys; a = sys.argv[1].split(); b = sys.argv[2].split(); print(f'median ratio: wall {s.median(map(float, a)):.3f}, cpu {s.median(map(float, b)):.3f}')" "${ratios[*]}" "${cpus[*]}"
