#!/usr/bin/env bash
# Physics equivalence with LAMMPS: runs the first 200 steps of the chute
# workload in both codes from the same data file, with thermo output every 10
# steps, and compares the total translational and rotational kinetic energy
# at every output. Passes when every relative difference is below 1e-6.
#
#   bench/check_lammps_equivalence.sh            # from the repository root
#
# Needs LAMMPS (`apt-get install lammps`) and `cargo build --release`.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
grains="${CARGO_TARGET_DIR:-$root/target}/release/grains"
command -v lmp >/dev/null || { echo "lmp not found: apt-get install lammps" >&2; exit 2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
sed -e 's/^thermo\t\t1000/thermo\t\t10/' \
    -e 's/^thermo_style\tcustom step atoms ke c_1 vol/thermo_style\tcustom step ke c_1\nthermo_modify\tformat float %.17g/' \
    "$root/bench/in.chute" > "$work/in.chute"
(cd "$root/bench" && lmp -in "$work/in.chute" -var steps 200 -log none -nocite) \
  | awk '/^ *Step/ {on=1; next} /^Loop time/ {on=0} on && NF==3 {print $1","$2","$3}' > "$work/lammps.csv"
"$grains" run "$root/scenarios/bench-chute.toml" --out "$work/grains" --quiet --set output.every=0.001
python3 - "$work/lammps.csv" "$work/grains/thermo.csv" <<'PY'
import csv, sys
lmp = {int(r[0]): (float(r[1]), float(r[2])) for r in csv.reader(open(sys.argv[1]))}
worst = 0.0
rows = 0
for r in csv.DictReader(open(sys.argv[2])):
    step = int(float(r["step"]))
    if step not in lmp:
        continue
    ke, rot = float(r["kinetic_energy"]), float(r["rotational_energy"])
    d = max(abs(ke - lmp[step][0]) / lmp[step][0], abs(rot - lmp[step][1]) / lmp[step][1])
    worst = max(worst, d)
    rows += 1
print(f"compared {rows} thermo outputs; largest relative difference {worst:.3e}")
sys.exit(0 if rows >= 20 and worst < 1e-6 else 1)
PY
