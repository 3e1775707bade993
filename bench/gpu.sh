#!/usr/bin/env bash
# The GPU engine on the GPU machine (an NVIDIA H200), in a few minutes:
# first the GPU against the CPU mirror bit for bit (PTX without fused
# multiply-add), then particle-steps per second and device memory on the
# chute (34 656 grains) and bed3d at 10^6 and 10^7 grains. docs/gpu.md.
#
# The GPU machine reaches no registry and may have no Rust toolchain:
# build the binary where you can and bring it along, e.g.
#   cargo build --release -p grains-cli --features cuda
#   (device session) run: bench/gpu.sh   carry: target/release/grains
# GRAINS=path overrides the binary; OUT=dir keeps the JSON lines (default
# $OUT when set by the device runner, else bench-gpu-out).
set -uo pipefail
cd "$(dirname "$0")/.."
GRAINS="${GRAINS:-target/release/grains}"
OUT="${OUT:-bench-gpu-out}"
mkdir -p "$OUT"
log="$OUT/gpu.jsonl"
: >"$log"

nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader || true
date -u +"date %Y-%m-%dT%H:%MZ"
status=0

step() {
    local limit="$1"
    shift
    echo "== grains bench $*"
    if ! timeout "$limit" "$GRAINS" bench "$@" --json | tee -a "$log"; then
        echo "   FAILED or timed out (limit ${limit}s): grains bench $*"
        status=1
    fi
}

# 1. Same bits as the mirror (which matches the CPU engine bit for bit:
#    tests/gpu/mirror.rs): the chute over 1000 steps, a bed with a floor.
step 120 chute --device gpu --steps 1000 --verify
step 60 bed3d --device gpu --particles 20000 --steps 300 --verify

# 2. Throughput. Set-up (scenario, CPU engine, upload) is not timed.
step 60 chute --device gpu --steps 3000
step 150 bed3d --device gpu --particles 1000000 --steps 300
step 300 bed3d --device gpu --particles 10000000 --steps 100

echo "== summary (particle-steps per second, device memory used)"
python3 - "$log" <<'PY' || true
import json, sys
for line in open(sys.argv[1]):
    try:
        r = json.loads(line)
    except ValueError:
        continue
    mem = (r.get("device_memory_bytes") or 0) / 2**30
    same = r.get("same_bits_as_mirror")
    print(f'{r["workload"]:6} {r["particles"]:>9} grains {r["steps"]:>5} steps: '
          f'{r["particle_steps_per_second"]:.3e} particle-steps/s, '
          f'{r["ns_per_particle_step"]:.3f} ns, {mem:.2f} GiB'
          + ("" if same is None else f", same bits: {same}"))
PY
exit $status
