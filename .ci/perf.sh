#!/usr/bin/env bash
# The up-front memory estimates (scenario/memory.rs) against the measured
# peak RSS of the benchmark workloads: MD with both integrators at 10^6
# grains, the DSMC gases at 10^7 particles (about 1.5 GB in all, 2 minutes
# on two cores). Needs the release build of .ci/run and GNU time.
set -euxo pipefail
cd "$(dirname "$0")/.."
if [ ! -x /usr/bin/time ]; then
    apt-get update
    apt-get install -y --no-install-recommends time
fi
cargo build --release -p grains-cli
CHECK=1 GRAINS="${CARGO_TARGET_DIR:-target}/release/grains" \
    N_MD=1000000 N_GAS=10000000 STEPS=3 bench/memory_footprint.sh
