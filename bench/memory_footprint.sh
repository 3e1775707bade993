#!/usr/bin/env bash
# Measures the peak resident memory of the benchmark workloads and sets it
# beside the up-front estimate of `scenario::memory` (which refuses a run
# that cannot fit): the estimate should stay within 20% above the
# measurement, so that a machine accepts every run that fits.
#
#   bench/memory_footprint.sh                     # 10^6 grains, 10^7 particles
#   N_MD=10000000 N_GAS=100000000 bench/memory_footprint.sh
#   GRAINS=target/release/grains bench/memory_footprint.sh
#   CHECK=1 bench/memory_footprint.sh             # exit 1 unless every ratio is in 0.8–1.2
#
# Each line: workload, count, peak RSS per grain or particle (from
# /usr/bin/time -v, the whole process), the estimate, and their ratio.
# Runs under `nice -n 19`; the sizes above need about 0.5 GB (MD) and
# 0.6 GB (3D gas). Needs python3 and GNU time (/usr/bin/time).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
grains=${GRAINS:-$root/target/release/grains}
n_md=${N_MD:-1000000}
n_gas=${N_GAS:-10000000}
steps=${STEPS:-3}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$root"

measure() {
  local name=$1
  shift
  nice -n 19 /usr/bin/time -v "$grains" bench "$@" --steps "$steps" --threads 1 --json \
    >"$work/out.json" 2>"$work/time.txt"
  python3 - "$name" "$work/out.json" "$work/time.txt" <<'PY'
import json, re, sys
name, out, timing = sys.argv[1:]
doc = json.loads(open(out).read().strip().splitlines()[-1])
kb = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", open(timing).read()).group(1))
n = doc["particles"]
per = kb * 1024 / n
est = doc["estimate_bytes_per_particle"]
ratio = est / per
print(f"{name:14s} {n:>11d}  peak {per:7.1f} B  estimate {est:5d} B  estimate/peak {ratio:5.2f}")
open(out + ".ratio", "w").write(f"{ratio}\n")
PY
  if [ -n "${CHECK:-}" ] && ! python3 -c "import sys; r = float(open('$work/out.json.ratio').read()); sys.exit(0 if 0.8 <= r <= 1.2 else 1)"; then
    echo "$name: the estimate is not within 20% of the measured peak" >&2
    failed=1
  fi
}
failed=0

measure "bed3d verlet" bed3d --particles "$n_md" --integrator verlet
measure "bed3d gear5" bed3d --particles "$n_md" --integrator gear5
measure "gas2d" gas2d --particles "$n_gas"
measure "gas3d" gas3d --particles "$n_gas"
exit $failed
