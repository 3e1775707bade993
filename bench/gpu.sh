#!/usr/bin/env bash
# The GPU engine on the GPU machine (an NVIDIA H200), in a few minutes:
# first the GPU against the CPU mirror bit for bit (PTX without fused
# multiply-add; the rebuild decided on the device, and by the host after
# each step), the FMA kernels against a second FMA run; then
# particle-steps per second and device memory on the chute (34 656
# grains: device-decided rebuilds, a read per step, FMA) and bed3d at
# 10^6 (with and without FMA) and 10^7 grains. docs/gpu.md.
#
# Without a GPU it says so and exits 0 (skipped); with a binary built
# without the cuda feature it says how to build one and exits 2.
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

if [ ! -x "$GRAINS" ]; then
    echo "bench/gpu.sh: no binary at $GRAINS: cargo build --release -p grains-cli --features cuda" >&2
    exit 2
fi
if ! nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader 2>/dev/null; then
    echo "bench/gpu.sh: skipped: no NVIDIA GPU here (nvidia-smi finds none)"
    exit 0
fi
probe=$("$GRAINS" bench chute --device gpu --steps 1 2>&1 >/dev/null)
case "$probe" in
*"features cuda"*)
    echo "bench/gpu.sh: $GRAINS was built without the cuda feature: cargo build --release -p grains-cli --features cuda" >&2
    exit 2
    ;;
*"no CUDA"*)
    echo "bench/gpu.sh: skipped: $probe"
    exit 0
    ;;
esac
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
#    tests/gpu/mirror.rs): the chute over 1000 steps and a bed with a
#    floor, re-sorted every second build (into Morton order), the chute in
#    the CPU's cell order, the chute with the rebuild decided by the host
#    each step; FMA runs repeat their bits.
step 120 chute --device gpu --steps 1000 --verify --sort-every 2
step 60 bed3d --device gpu --particles 20000 --steps 300 --verify --sort-every 2
step 60 chute --device gpu --steps 300 --verify --sort-every 2 --cpu-order
step 60 chute --device gpu --steps 300 --verify --sync-each-step
step 60 chute --device gpu --steps 300 --verify --graph --sort-every 2
step 60 chute --device gpu --steps 300 --verify --fma --sort-every 2

# 2. Throughput. Set-up (scenario, CPU engine, upload) is not timed.
for mode in "" --sync-each-step --graph --fma --cpu-order; do
    step 60 chute --device gpu --steps 3000 $mode
done
step 150 bed3d --device gpu --particles 1000000 --steps 300
step 150 bed3d --device gpu --particles 1000000 --steps 300 --fma
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
    rerun = r.get("same_bits_on_rerun")
    mode = "fma" if r.get("fma") else "sync" if r.get("sync_each_step") else "-"
    mode += "+graph" if r.get("graph") else ""
    mode += "/" + str(r.get("cell_order"))
    print(f'{r["workload"]:6} {r["particles"]:>9} grains {r["steps"]:>5} steps {mode:10}: '
          f'{r["particle_steps_per_second"]:.3e} particle-steps/s, '
          f'{r["ns_per_particle_step"]:.3f} ns, {mem:.2f} GiB'
          + ("" if same is None else f", same bits as the mirror: {same}")
          + ("" if rerun is None else f", same bits on a rerun: {rerun}"))
PY
exit $status
