#!/usr/bin/env bash
# Physics equivalence with LAMMPS: runs the first 200 steps of a chute
# workload in both codes from the same data file, with thermo output every 10
# steps, and compares the total translational and rotational kinetic energy
# at every output. Passes when every relative difference is below 1e-6.
#
#   bench/check_lammps_equivalence.sh                   # chute and chute-hertz
#   bench/check_lammps_equivalence.sh chute-hertz       # one of them
#
# chute: in.chute (gran/hooke/history) against scenarios/bench-chute.toml;
# chute-hertz: in.chute-hertz (pair granular, hertz/material + tsuji +
# mindlin + rolling sds) against scenarios/bench-chute-hertz.toml.
#
# Needs LAMMPS (`apt-get install lammps`) and `cargo build --release`.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
grains="${CARGO_TARGET_DIR:-$root/target}/release/grains"
command -v lmp >/dev/null || { echo "lmp not found: apt-get install lammps" >&2; exit 2; }
workloads=("$@")
[ ${#workloads[@]} -gt 0 ] || workloads=(chute chute-hertz)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
status=0
for w in "${workloads[@]}"; do
  case "$w" in
    chute|chute-hertz) ;;
    *) echo "unknown workload $w (chute or chute-hertz)" >&2; exit 2 ;;
  esac
  sed -e 's/^thermo\t\t1000/thermo\t\t10/' \
      -e 's/^thermo_style\tcustom step atoms ke c_1 vol/thermo_style\tcustom step ke c_1\nthermo_modify\tformat float %.17g/' \
      "$root/bench/in.$w" > "$work/in.$w"
  (cd "$root/bench" && lmp -in "$work/in.$w" -var steps 200 -log none -nocite) \
    | awk '/^ *Step/ {on=1; next} /^Loop time/ {on=0} on && NF==3 {print $1","$2","$3}' > "$work/lammps-$w.csv"
  "$grains" run "$root/scenarios/bench-$w.toml" --out "$work/grains-$w" --quiet --set output.every=0.001
  python3 - "$w" "$work/lammps-$w.csv" "$work/grains-$w/thermo.csv" <<'PY' || status=1
import csv, sys
lmp = {int(r[0]): (float(r[1]), float(r[2])) for r in csv.reader(open(sys.argv[2]))}
worst = 0.0
rows = 0
for r in csv.DictReader(open(sys.argv[3])):
    step = int(float(r["step"]))
    if step not in lmp:
        continue
    ke, rot = float(r["kinetic_energy"]), float(r["rotational_energy"])
    d = max(abs(ke - lmp[step][0]) / lmp[step][0], abs(rot - lmp[step][1]) / lmp[step][1])
    worst = max(worst, d)
    rows += 1
print(f"{sys.argv[1]}: compared {rows} thermo outputs; largest relative difference {worst:.3e}")
sys.exit(0 if rows >= 20 and worst < 1e-6 else 1)
PY
done
exit $status
