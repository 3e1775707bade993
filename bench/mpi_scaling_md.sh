#!/usr/bin/env bash
# Speed-up of the decomposed MD engine versus MPI ranks on `grains bench`
# WORKLOAD (first argument or $WORKLOAD; default bed3d, the dense 3D bed, at
# N grains; chute: the LAMMPS chute flow, 32k grains), STEPS timed steps,
# THREADS threads per rank (default 1). One rank is the plain process (the
# serial engine); more ranks run under mpirun. Needs the binary built with
# `cargo build --release -p grains-cli --features mpi` and Open MPI's mpirun.
# Writes ranks,wall_seconds,ns_per_particle_step,ghosts to $OUT/scaling.csv
# (wall_seconds: the timed step loop, the slowest rank's).
set -euo pipefail
cd "$(dirname "$0")/.."
G=${GRAINS:-${CARGO_TARGET_DIR:-target}/release/grains}
WORKLOAD=${1:-${WORKLOAD:-bed3d}}
N=${N:-1000000}
STEPS=${STEPS:-100}
RANKS=${RANKS:-"1 2"}
THREADS=${THREADS:-1}
if [ "$WORKLOAD" = bed3d ]; then
    OUT=${OUT:-/tmp/grains-scaling-md}
else
    OUT=${OUT:-/tmp/grains-scaling-md-$WORKLOAD}
fi
mkdir -p "$OUT"
echo "ranks,wall_seconds,ns_per_particle_step,ghosts" > "$OUT/scaling.csv"
for np in $RANKS; do
    args=(bench "$WORKLOAD" --steps "$STEPS" --threads "$THREADS" --json)
    if [ "$WORKLOAD" = bed3d ]; then
        args+=(--particles "$N")
    fi
    if [ "$np" = 1 ]; then
        line=$("$G" "${args[@]}")
    else
        line=$(mpirun --oversubscribe --allow-run-as-root --bind-to none -np "$np" "$G" "${args[@]}")
    fi
    echo "load: $(cut -d' ' -f1-3 /proc/loadavg)  $line" >&2
    python3 - "$np" "$line" >> "$OUT/scaling.csv" <<'PY'
import json, sys
s = json.loads(sys.argv[2])
print(f"{sys.argv[1]},{s['wall_seconds']:.4f},{s['ns_per_particle_step']:.2f},{s.get('ghosts', 0)}")
PY
done
cat "$OUT/scaling.csv"
