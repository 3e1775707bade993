#!/usr/bin/env bash
# The clump chute (7302 rigid three-sphere rods on the chute's frozen base)
# in LAMMPS (in.chute-clumps: fix rigid/small, pair gran/hooke/history) and
# in grains (`grains bench chute-clumps`), one core each, in turns: the
# loop times per sub-sphere-step, their ratio, and the bodies' state after
# the steps side by side (translational and rotational kinetic energy,
# mean x velocity).
#
#   bench/compare_lammps_clumps.sh 1000            # steps
#   ROUNDS=6 bench/compare_lammps_clumps.sh 1000   # six alternated pairs, medians
#   CHECK=1 bench/compare_lammps_clumps.sh 100     # fail unless the states agree
#
# With CHECK=1 the script exits 1 unless, after the steps, the two codes'
# translational energy and mean velocity agree within TOL (default 1e-9,
# relative) and the rotational energy within ROT_TOL (default 1e-5): the
# codes integrate rotations differently (LAMMPS's rigid/small: Richardson
# iteration of the quaternion; grains: NO_SQUISH), so the rotation parts
# agree only to the integrators' own error, which grows with the steps
# (measured: 4e-8 after 100 steps, 1.5e-7 after 1000; the translational
# parts 2e-12 and 5e-11). The defaults hold for up to 1000 steps.
#
# Needs LAMMPS with the RIGID and MOLECULE packages (Debian's `lmp`:
# apt-get install lammps; LMP names another binary), a release build of
# grains (found under $CARGO_TARGET_DIR when set) and python3. The bodies
# come from bench/make_chute_clumps.py (its files are in the repository).
set -euo pipefail
steps=${1:-1000}
rounds=${ROUNDS:-1}
lmp=${LMP:-lmp}
root=$(cd "$(dirname "$0")/.." && pwd)
grains="${CARGO_TARGET_DIR:-$root/target}/release/grains"
command -v "$lmp" >/dev/null || { echo "$lmp not found: apt-get install lammps" >&2; exit 2; }
[ -x "$grains" ] || { echo "$grains not found: cargo build --release" >&2; exit 2; }
[[ "$steps" =~ ^[1-9][0-9]*$ ]] || { echo "steps must be a positive whole number, not '$steps'" >&2; exit 2; }
[[ "$rounds" =~ ^[1-9][0-9]*$ ]] || { echo "ROUNDS must be a positive whole number, not '$rounds'" >&2; exit 2; }

results=()
for _ in $(seq "$rounds"); do
  lmp_out=$(cd "$root/bench" && OMP_NUM_THREADS=1 "$lmp" -in in.chute-clumps -var steps "$steps" \
    -var every "$steps" -log none -nocite | grep -v -e 'settings made' -e 'Setting atom' -e 'Created' -e 'create_atoms CPU')
  # The last thermo row (step, atoms, ke, erotate, mean vx) and the loop time.
  lmp_row=$(echo "$lmp_out" | awk -v s="$steps" '$1 == s && NF == 5 {print $3, $4, $5}')
  lmp_loop=$(echo "$lmp_out" | awk '/^Loop time of/ {print $4}')
  lmp_pct=$(echo "$lmp_out" | awk '/% CPU use/ {sub("%", "", $1); print $1}')
  [ -n "$lmp_row" ] && [ -n "$lmp_loop" ] || { echo "$lmp_out" | tail -20 >&2; echo "LAMMPS failed" >&2; exit 1; }
  g=$(cd "$root" && "$grains" bench chute-clumps --steps "$steps" --threads 1 --json)
  g_row=$(echo "$g" | python3 -c 'import json,sys; d=json.load(sys.stdin); print(d["wall_seconds"], d["cpu_seconds"], d["particles"], d["body_kinetic_energy"], d["body_rotational_energy"], d["body_mean_vx"])')
  results+=("$lmp_loop ${lmp_pct:-100} $lmp_row $g_row")
done
python3 - "$steps" "${CHECK:-0}" "${TOL:-1e-9}" "${ROT_TOL:-1e-5}" "${results[@]}" <<'PY'
import statistics, sys
steps, check, tol, rot_tol = int(sys.argv[1]), sys.argv[2] == "1", float(sys.argv[3]), float(sys.argv[4])
rows = [list(map(float, r.split())) for r in sys.argv[5:]]
ok = True
# Each row: LAMMPS loop (wall), its CPU use (%), its state; grains wall and
# CPU seconds, sub-spheres, its state. CPU time (LAMMPS: loop x CPU use)
# is the fairer figure on a loaded machine.
for lmp, pct, lke, lrot, lvx, gr, gr_cpu, n, gke, grot, gvx in rows:
    per = lambda t: 1e9 * t / (steps * n)
    lmp_cpu = lmp * pct / 100
    print(f"clump chute, {steps} steps, {int(n)} sub-spheres of {int(n) // 3} rods, one core")
    print(f"  LAMMPS loop {lmp:8.3f} s {per(lmp):7.1f} ns per sub-sphere-step; CPU {lmp_cpu:.3f} s {per(lmp_cpu):7.1f} ns")
    print(f"  grains loop {gr:8.3f} s {per(gr):7.1f} ns per sub-sphere-step; CPU {gr_cpu:.3f} s {per(gr_cpu):7.1f} ns")
    print(f"  grains / LAMMPS: {gr / lmp:.3f} (wall), {gr_cpu / lmp_cpu:.3f} (CPU)")
    rel = lambda a, b: abs(a - b) / max(abs(b), 1e-300)
    for name, a, b, t in [("1/2 M V^2", gke, lke, tol), ("1/2 L.w", grot, lrot, rot_tol), ("mean vx", gvx, lvx, tol)]:
        r = rel(a, b)
        ok &= r <= t
        print(f"  {name:10} grains {a:.12e}  LAMMPS {b:.12e}  relative difference {r:.2e} (held to {t:g})")
if len(rows) > 1:
    for name, ratio in [("wall", lambda r: r[5] / r[0]), ("CPU", lambda r: r[6] / (r[0] * r[1] / 100))]:
        ratios = sorted(ratio(r) for r in rows)
        print(f"  median grains / LAMMPS of {len(rows)} pairs ({name}): {statistics.median(ratios):.3f} "
              f"(from {ratios[0]:.3f} to {ratios[-1]:.3f})")
if check and not ok:
    print("the two codes' states differ beyond the tolerances", file=sys.stderr)
    sys.exit(1)
PY
