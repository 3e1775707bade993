#!/usr/bin/env bash
# Speed-up of a distributed DSMC run versus MPI ranks: the 3D cooling gas
# of scenarios/gas-cooling-3d.toml scaled to N particles at the same number
# density (n d³ = 0.00604, cells of λ/2), STEPS steps, THREADS threads per rank (default 1).
# Needs the binary built with `cargo build --release -p grains-cli
# --features mpi` and Open MPI's mpirun. Writes ranks,wall_seconds,... to
# $OUT/scaling.csv (wall_seconds: the step loop, from summary.json).
set -euo pipefail
cd "$(dirname "$0")/.."
G=${GRAINS:-${CARGO_TARGET_DIR:-target}/release/grains}
N=${N:-1000000}
STEPS=${STEPS:-40}
RANKS=${RANKS:-"1 2 4"}
THREADS=${THREADS:-1}
OUT=${OUT:-/tmp/grains-scaling}
mkdir -p "$OUT"
L=$(awk -v n="$N" 'BEGIN { printf "%.6f", (n * 1e-9 / 0.00604)^(1/3) }')
echo "ranks,wall_seconds,ns_per_particle_step,imbalance" > "$OUT/scaling.csv"
for np in $RANKS; do
    d="$OUT/np$np"
    rm -rf "$d"
    mpirun --oversubscribe --allow-run-as-root --bind-to none -np "$np" "$G" run scenarios/gas-cooling-3d.toml \
        --set particles.count="$N" --set "domain.hi=[$L,$L,$L]" \
        --set output.every=1e9 --set dsmc.profile_bins=0 --set output.picture=false \
        --steps "$STEPS" --threads "$THREADS" --quiet --out "$d"
    python3 - "$d/summary.json" "$np" >> "$OUT/scaling.csv" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
print(f"{sys.argv[2]},{s['wall_seconds']:.4f},{s['ns_per_particle_step']:.2f},{s.get('imbalance', 0.0):.4f}")
PY
done
cat "$OUT/scaling.csv"
