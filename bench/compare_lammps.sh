#!/usr/bin/env bash
# Runs LAMMPS and grains on the same workload back to back, one core each,
# and prints both loop times per particle-step and their ratio.
#
#   bench/compare_lammps.sh chute 2000     # workload, steps
#   bench/compare_lammps.sh vib2d 20000
#   ROUNDS=3 bench/compare_lammps.sh chute-hertz 1000   # pair granular vs the preset
#   ROUNDS=5 bench/compare_lammps.sh chute 500   # alternate five times
#
# With ROUNDS=N the two codes take turns N times and the ratio of each
# round is printed, then the median: on a shared machine one pair of runs
# can be off by a quarter either way.
#
# Needs LAMMPS (`apt-get install lammps`, command `lmp`) and a release build
# of grains (`cargo build --release`; found under $CARGO_TARGET_DIR when set).
# Run from the repository root.
set -euo pipefail
workload=${1:-chute}
steps=${2:-1000}
threads=${THREADS:-1}
root=$(cd "$(dirname "$0")/.." && pwd)
grains="${CARGO_TARGET_DIR:-$root/target}/release/grains"
command -v lmp >/dev/null || { echo "lmp not found: apt-get install lammps" >&2; exit 2; }
[ -x "$grains" ] || { echo "$grains not found: cargo build --release" >&2; exit 2; }
case "$workload" in
  chute) input=in.chute; atoms=34656 ;;
  chute-hertz) input=in.chute-hertz; atoms=34656 ;;
  vib2d) input=in.vib2d; atoms=3700 ;;
  *) echo "unknown workload $workload (chute, chute-hertz or vib2d)" >&2; exit 2 ;;
esac

rounds=${ROUNDS:-1}
results=()
for _ in $(seq "$rounds"); do
  lmp_out=$(cd "$root/bench" && OMP_NUM_THREADS=1 lmp -in "$input" -var steps "$steps" -log none -nocite)
  lmp_loop=$(echo "$lmp_out" | awk '/^Loop time of/ {print $4}')
  lmp_pct=$(echo "$lmp_out" | awk '/% CPU use/ {sub("%", "", $1); print $1}')
  grains_json=$("$grains" bench "$workload" --steps "$steps" --threads "$threads" --json)
  grains_loop=$(echo "$grains_json" | python3 -c 'import json,sys; d=json.load(sys.stdin); print(d["wall_seconds"], d["cpu_seconds"])')
  results+=("$lmp_loop ${lmp_pct:-100} $grains_loop")
done
python3 - "$workload" "$steps" "$atoms" "$threads" "${results[@]}" <<'PY'
import statistics, sys
w, steps, atoms, threads = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
# Each round: LAMMPS loop (wall) and its CPU use (%), grains wall and CPU
# seconds. CPU time (LAMMPS: loop x CPU use) is the fairer figure on a
# loaded machine.
rounds = [tuple(map(float, row.split())) for row in sys.argv[5:]]
per = lambda t: 1e9 * t / (steps * atoms)
print(f"{w}: {steps} steps, {atoms} atoms (all atoms counted for both codes)")
for lmp, pct, gr, gr_cpu in rounds:
    lmp_cpu = lmp * pct / 100
    print(f"  LAMMPS (1 core)       loop {lmp:8.3f} s  {per(lmp):7.1f} ns per particle-step; CPU {lmp_cpu:.3f} s")
    print(f"  grains ({threads} thread(s))   loop {gr:8.3f} s  {per(gr):7.1f} ns per particle-step; CPU {gr_cpu:.3f} s")
    print(f"  grains / LAMMPS time: {gr / lmp:.3f} (wall), {gr_cpu / lmp_cpu:.3f} (CPU)")
if len(rounds) > 1:
    for name, ratio in [("wall", lambda r: r[2] / r[0]), ("CPU", lambda r: r[3] / (r[0] * r[1] / 100))]:
        ratios = sorted(ratio(r) for r in rounds)
        print(f"  median of {len(rounds)} rounds ({name}): {statistics.median(ratios):.3f} "
              f"(from {ratios[0]:.3f} to {ratios[-1]:.3f})")
PY
