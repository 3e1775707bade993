#!/usr/bin/env bash
# Physics equivalence with LAMMPS (issues 27, 28): the first 200 steps of
# the chute workloads in both codes (chute: gran/hooke/history; chute-hertz:
# pair granular with hertz/material, tsuji, mindlin, rolling sds) agree in
# translational and rotational kinetic energy to 1e-6 at every thermo output. Installs Debian's LAMMPS
# when `lmp` is missing, builds the release binary, runs the check.
set -euxo pipefail
cd "$(dirname "$0")/.."

if ! command -v lmp >/dev/null 2>&1; then
    apt-get update
    apt-get install -y --no-install-recommends lammps
fi
command -v python3 >/dev/null
cargo build --release -p grains-cli
bench/check_lammps_equivalence.sh chute chute-hertz
