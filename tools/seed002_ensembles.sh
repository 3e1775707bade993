#!/usr/bin/env bash
# Seed 002 Figs. 2-3 under each parameter reading: one `grains sweep` over
# SEEDS per setting (one thread, one job, niced), each writing
# $OUT/<setting>/sweep.csv; tools/seed002_table.py turns them into the
# frequencies and mean strengths of docs/seed-figures.md.
#
#   tools/seed002_ensembles.sh                  # every setting, seeds 1-20
#   tools/seed002_ensembles.sh w-unit-gs0 m-unit   # some settings
#   SEEDS=1,2,3 BIN=target/release/grains OUT=/tmp/e tools/seed002_ensembles.sh
#   SEEDS=1,2 STEPS=2000 tools/seed002_ensembles.sh m-today   # a smoke test (CI)
#   PRINT=1 tools/seed002_ensembles.sh m-today   # print the `grains sweep` command only
#
# The readings (docs/scenario-reference.md section 13):
#   today: gamma = "20 g" -> 200 s^-1 (80 g -> 800), gamma_s = 400 s^-1, dt = t_c/50;
#   unit:  gamma in units of sqrt(g/d0) = 99.05 s^-1: 20 -> 1981, 80 -> 7924 s^-1,
#          gamma_s = 400/f (f in Hz) -> 5.71 sqrt(g/d0) = 566 s^-1 at 70 Hz;
#   seeddt: the seed's 2e4 steps per cycle (dt = 0.714 us at 70 Hz, 2.5 us at
#          20 Hz); the overdamped ten-times-gamma contacts always run at it;
#          seeddt6 its upper bound, 6e4 steps per cycle;
#   flat:  the plate as the 1992 reading (walls.0.motion.surface = "flat");
#   elastic: side walls without normal damping (contact.elastic_walls);
#   soft:  Y = 1e7 s^-2 (the seed's lower bound 1e3 g/d0);
#   lattice: placed regularly on the bottom instead of at random.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bin=${BIN:-$root/target/release/grains}
out=${OUT:-$root/runs/seed002-ensembles}
seeds=${SEEDS:-$(seq -s, 1 20)}
quiet=(--set output.frames=false --set output.movie=false --set output.picture=false)
[ -n "${STEPS:-}" ] && quiet+=(--steps "$STEPS")
fig2=$root/scenarios/seed-convection-modulated.toml
fig3=$root/scenarios/seed-convection-walls.toml

# Settings: name -> scenario and overrides.
seeddt2=(--set run.dt=7.142857142857143e-7)
unit2=(--set contact.gamma_n=1981 --set contact.gamma_t=566)
seeddt3=(--set run.dt=2.5e-6)
unit3=(--set contact.gamma_n=7924 "${seeddt3[@]}")
lattice=(--set particles.placement=lattice)
flat=(--set walls.0.motion.surface=flat)
curved=(--set walls.0.motion.surface=curved)
elastic=(--set 'contact.elastic_walls=["left","right"]')
# The shipped Fig. 3 scenario has elastic side walls since the second
# pass; the damped settings say so explicitly.
damped=(--set 'contact.elastic_walls=[]')
setting() {
  case "$1" in
    # Fig. 2, today's reading (gamma 200, gamma_s 400, t_c/50), curved plate.
    m-today) echo "$fig2" "${curved[@]}" ;;
    m-today-g10) echo "$fig2" "${curved[@]}" --set contact.gamma_n=2000 ;;
    m-today-gs0) echo "$fig2" "${curved[@]}" --set contact.gamma_t=0 ;;
    m-today-flat) echo "$fig2" "${flat[@]}" ;;
    m-today-flat-g10) echo "$fig2" "${flat[@]}" --set contact.gamma_n=2000 ;;
    m-today-flat-gs0) echo "$fig2" "${flat[@]}" --set contact.gamma_t=0 ;;
    m-today-lattice) echo "$fig2" "${curved[@]}" "${lattice[@]}" ;;
    m-today-seeddt) echo "$fig2" "${curved[@]}" "${seeddt2[@]}" ;;
    m-today-seeddt6) echo "$fig2" "${curved[@]}" --set run.dt=2.380952380952381e-7 ;;
    # Fig. 2, the sqrt(g/d0) reading.
    m-unit) echo "$fig2" "${curved[@]}" "${unit2[@]}" ;;
    m-unit-seeddt) echo "$fig2" "${curved[@]}" "${unit2[@]}" "${seeddt2[@]}" ;;
    m-unit-g10) echo "$fig2" "${curved[@]}" "${unit2[@]}" "${seeddt2[@]}" --set contact.gamma_n=19810 ;;
    m-unit-gs0) echo "$fig2" "${curved[@]}" "${unit2[@]}" --set contact.gamma_t=0 ;;
    m-unit-flat) echo "$fig2" "${flat[@]}" "${unit2[@]}" ;;
    m-unit-flat-seeddt) echo "$fig2" "${flat[@]}" "${unit2[@]}" "${seeddt2[@]}" ;;
    m-unit-flat-g10) echo "$fig2" "${flat[@]}" "${unit2[@]}" "${seeddt2[@]}" --set contact.gamma_n=19810 ;;
    m-unit-flat-gs0) echo "$fig2" "${flat[@]}" "${unit2[@]}" --set contact.gamma_t=0 ;;
    m-unit-flat-lattice) echo "$fig2" "${flat[@]}" "${unit2[@]}" "${lattice[@]}" ;;
    m-unit-flat-soft) echo "$fig2" "${flat[@]}" "${unit2[@]}" --set contact.kn=1e7 ;;
    # Fig. 3 (B = 0: the plate is flat in every reading); the unit reading
    # at the seed's time step.
    w-today-gs0) echo "$fig3" "${damped[@]}" ;;
    w-today-gs400) echo "$fig3" "${damped[@]}" --set contact.gamma_t=400 ;;
    w-today-elastic-gs0) echo "$fig3" "${elastic[@]}" ;;
    w-today-elastic-gs400) echo "$fig3" "${elastic[@]}" --set contact.gamma_t=400 ;;
    w-today-elastic-lattice-gs0) echo "$fig3" "${elastic[@]}" "${lattice[@]}" ;;
    w-today-elastic-seeddt-gs0) echo "$fig3" "${elastic[@]}" "${seeddt3[@]}" ;;
    w-today-elastic-seeddt-gs400) echo "$fig3" "${elastic[@]}" "${seeddt3[@]}" --set contact.gamma_t=400 ;;
    w-today-elastic-soft-gs0) echo "$fig3" "${elastic[@]}" --set contact.kn=1e7 ;;
    w-today-elastic-soft-gs400) echo "$fig3" "${elastic[@]}" --set contact.kn=1e7 --set contact.gamma_t=400 ;;
    w-unit-gs0) echo "$fig3" "${damped[@]}" "${unit3[@]}" ;;
    w-unit-gs400) echo "$fig3" "${damped[@]}" "${unit3[@]}" --set contact.gamma_t=400 ;;
    w-unit-lattice-gs0) echo "$fig3" "${damped[@]}" "${unit3[@]}" "${lattice[@]}" ;;
    w-unit-elastic-gs0) echo "$fig3" "${unit3[@]}" "${elastic[@]}" ;;
    w-unit-soft-gs0) echo "$fig3" "${damped[@]}" "${unit3[@]}" --set contact.kn=1e7 ;;
    *) echo "unknown setting $1" >&2; return 2 ;;
  esac
}
all=(m-today m-today-g10 m-today-gs0 m-today-flat m-today-flat-g10 m-today-flat-gs0
  m-today-lattice m-today-seeddt m-today-seeddt6 m-unit m-unit-seeddt m-unit-g10 m-unit-gs0 m-unit-flat m-unit-flat-seeddt m-unit-flat-g10
  m-unit-flat-gs0 m-unit-flat-lattice m-unit-flat-soft
  w-today-gs0 w-today-gs400 w-today-elastic-gs0 w-today-elastic-gs400
  w-today-elastic-lattice-gs0 w-today-elastic-seeddt-gs0 w-today-elastic-seeddt-gs400
  w-today-elastic-soft-gs0
  w-today-elastic-soft-gs400 w-unit-gs0 w-unit-gs400
  w-unit-lattice-gs0 w-unit-elastic-gs0 w-unit-soft-gs0)
[ $# -gt 0 ] && all=("$@")
mkdir -p "$out"
for name in "${all[@]}"; do
  # shellcheck disable=SC2207 # the overrides hold no spaces
  args=($(setting "$name"))
  if [ -n "${PRINT:-}" ]; then
    line="grains sweep"
    for a in "${args[@]#"$root/"}" --vary "seed=$seeds" "${quiet[@]}"; do
      case "$a" in *[\[\"]*) a="'$a'" ;; esac
      line+=" $a"
    done
    echo "$line --threads 1 --jobs 1 --out runs/seed002-ensembles/$name"
    continue
  fi
  [ -f "$out/$name/sweep.csv" ] && { echo "have $name" >&2; continue; }
  echo "running $name: ${args[*]}" >&2
  nice -n 19 "$bin" sweep "${args[@]}" --vary "seed=$seeds" "${quiet[@]}" \
    --threads 1 --jobs 1 --out "$out/$name" >"$out.$name.log" 2>&1 || echo "$name failed" >&2
done
