#!/usr/bin/env bash
# The μ(I) sweep of the 3D shear cell (docs/shear-cell.md): scenarios/shear-3d
# (1000 spheres, P = 50 Pa) at nine shear rates, I ≈ 0.001 … 1, one run per
# rate on one thread. Each rate relaxes 0.4 s (the loose box closes) plus a
# strain of 0.5 (the flow sets in at that rate), then is measured over the
# strain given beside it: a fixed strain, not a fixed time, since the low
# rates are the slow ones. `grains sweep` varies one value per key, so the
# per-rate lengths are set here.
#
# usage: tools/mu_of_i_3d.sh OUT_DIR [GRAINS_BINARY]
#        python3 tools/mu_of_i.py OUT_DIR --png mu-of-i-3d.png \
#            --reference "Jop et al. 2006, glass beads:0.382,0.643,0.279"
set -euo pipefail
out=${1:?usage: tools/mu_of_i_3d.sh OUT_DIR [GRAINS_BINARY]}
bin=${2:-grains}
cd "$(dirname "$0")/.."
# rate (1/s) : measured strain. I = rate · d0 / √(P/ρ) = rate × 7.07e-3.
for spec in 0.1414:1.5 0.354:1.5 0.849:2 2.12:3 5.66:4 14.14:5.6 42.4:8 84.9:10 141.4:12; do
    rate=${spec%%:*}
    strain=${spec##*:}
    relax=$(python3 -c "print(0.4 + 0.5 / $rate)")
    duration=$(python3 -c "print($strain / $rate)")
    echo "rate $rate 1/s: relax $relax s, measured $duration s"
    "$bin" run scenarios/shear-3d.toml --threads 1 --quiet --overwrite \
        --set domain.shear.rate="$rate" --set run.relax="$relax" \
        --set run.duration="$duration" --set output.picture=false \
        --out "$out/rate-$rate"
done
