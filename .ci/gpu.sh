#!/usr/bin/env bash
# The GPU engine without a GPU (docs/gpu.md): clippy and a build with the
# cuda feature (cudarc loads libcuda at run time, so no CUDA is needed to
# build), the NVRTC check that every kernel compiles and the checked-in PTX
# is current, and the CPU mirror against the CPU engine, bit for bit.
set -euxo pipefail
cd "$(dirname "$0")/.."

if ! python3 -c 'import nvidia, glob, sys; sys.exit(0 if any(glob.glob(p + "/*/lib/libnvrtc.so*") for p in nvidia.__path__) else 1)' 2>/dev/null; then
    python3 -m pip install --quiet nvidia-cuda-nvrtc \
        || python3 -m pip install --quiet --break-system-packages nvidia-cuda-nvrtc
fi
cargo clippy -p grains -p grains-cli --all-targets --features cuda -- -D warnings
cargo build --release -p grains-cli --features cuda
python3 tools/make_ptx.py --check
cargo test --profile opt-test -p grains --test gpu
cargo test --profile opt-test -p grains --features cuda --test gpu device::  # skips without a device
# Without the feature, --device gpu is refused with the feature's name.
cargo build --release -p grains-cli
if "${CARGO_TARGET_DIR:-target}"/release/grains bench chute --device gpu --steps 1 2>err.txt; then
    echo "--device gpu ran without the cuda feature" >&2
    exit 1
fi
grep -q "features cuda" err.txt
rm -f err.txt
