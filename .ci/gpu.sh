#!/usr/bin/env bash
# The GPU engine without a GPU (docs/gpu.md): clippy with the cuda feature
# (cudarc loads libcuda at run time, so no CUDA is needed to build; it
# type-checks the device tests too), and the NVRTC check that every kernel
# compiles and the checked-in PTX is current. The CPU mirror's tests
# (`--test gpu`) run in the main `cargo test`; .ci/run builds the release
# binary this script uses.
set -euxo pipefail
cd "$(dirname "$0")/.."

if ! python3 -c 'import nvidia, glob, sys; sys.exit(0 if any(glob.glob(p + "/*/lib/libnvrtc.so*") for p in nvidia.__path__) else 1)' 2>/dev/null; then
    python3 -m pip install --quiet nvidia-cuda-nvrtc==13.5.37 \
        || python3 -m pip install --quiet --break-system-packages nvidia-cuda-nvrtc==13.5.37
fi
cargo clippy -p grains -p grains-cli --all-targets --features cuda -- -D warnings
python3 tools/make_ptx.py --check
# Without the feature, --device gpu is refused with the feature's name.
err=$(mktemp)
trap 'rm -f "$err"' EXIT
if "${CARGO_TARGET_DIR:-target}"/release/grains bench chute --device gpu --steps 1 2>"$err"; then
    echo "--device gpu ran without the cuda feature" >&2
    exit 1
fi
grep -q "features cuda" "$err"
# Without a GPU, the prepared device script says it skipped and exits 0.
if ! command -v nvidia-smi >/dev/null; then
    OUT=$(mktemp -d) GRAINS="${CARGO_TARGET_DIR:-target}"/release/grains bench/gpu.sh | grep -q "skipped: no NVIDIA GPU"
fi
