#!/usr/bin/env python3
"""Compiles the GPU engine's kernels (crates/grains/src/gpu/kernels/*.cu) to
PTX with NVRTC, or checks that the checked-in PTX is current.

NVRTC comes from the PyPI wheel `nvidia-cuda-nvrtc` (pip install
nvidia-cuda-nvrtc); its shared library is loaded with ctypes, so no CUDA
toolkit is needed. The PTX is checked in (kernels/ptx/) because the GPU
machine reaches no package registry; the driver JITs it for the device.

    tools/make_ptx.py            # write kernels/ptx/*.ptx and *.fma.ptx
    tools/make_ptx.py --check    # exit 1 if a kernel fails or a PTX file is stale

Each kernel file gives two PTX files: `NAME.ptx` without fused multiply-add
(`--fmad=false`: the CPU engine's bits, the default the host loads) and
`NAME.fma.ptx` with it (what `run.gpu_fma = true` loads).

Exit status 3 when NVRTC cannot be loaded (the test skips on it).
"""

import argparse
import ctypes
import glob
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
KERNELS = os.path.join(ROOT, "crates", "grains", "src", "gpu", "kernels")
PTX_DIR = os.path.join(KERNELS, "ptx")
# H100/H200 (sm_90); the driver JITs this PTX for any newer device too.
ARCH = "compute_90"


def load_nvrtc():
    """libnvrtc from the nvidia-cuda-nvrtc wheel (or the loader's path)."""
    candidates = []
    try:
        import nvidia  # namespace package of the NVIDIA wheels

        for base in nvidia.__path__:
            candidates += sorted(glob.glob(os.path.join(base, "*", "lib", "libnvrtc.so*")))
    except ImportError:
        pass
    candidates = [c for c in candidates if "builtins" not in c]
    candidates += ["libnvrtc.so"]
    for c in candidates:
        try:
            return ctypes.CDLL(c), c
        except OSError:
            continue
    return None, None


def version(nvrtc):
    major, minor = ctypes.c_int(), ctypes.c_int()
    nvrtc.nvrtcVersion(ctypes.byref(major), ctypes.byref(minor))
    return f"{major.value}.{minor.value}"


def compile_ptx(nvrtc, path, fmad):
    """PTX text of one .cu file, or raises with NVRTC's log."""
    src = open(path, "rb").read()
    prog = ctypes.c_void_p()
    name = os.path.basename(path).encode()
    check(nvrtc, nvrtc.nvrtcCreateProgram(ctypes.byref(prog), src, name, 0, None, None), path)
    opts = [
        f"--gpu-architecture={ARCH}",
        f"--fmad={'true' if fmad else 'false'}",
        # IEEE division and square root (NVRTC's defaults, stated).
        "--prec-div=true",
        "--prec-sqrt=true",
        "--ftz=false",
        "--std=c++17",
        f"--include-path={KERNELS}",
    ]
    arr = (ctypes.c_char_p * len(opts))(*[o.encode() for o in opts])
    status = nvrtc.nvrtcCompileProgram(prog, len(opts), arr)
    size = ctypes.c_size_t()
    nvrtc.nvrtcGetProgramLogSize(prog, ctypes.byref(size))
    log = ctypes.create_string_buffer(size.value)
    nvrtc.nvrtcGetProgramLog(prog, log)
    if status != 0:
        raise RuntimeError(f"{path}: NVRTC failed:\n{log.value.decode(errors='replace')}")
    nvrtc.nvrtcGetPTXSize(prog, ctypes.byref(size))
    ptx = ctypes.create_string_buffer(size.value)
    check(nvrtc, nvrtc.nvrtcGetPTX(prog, ptx), path)
    nvrtc.nvrtcDestroyProgram(ctypes.byref(prog))
    return ptx.value.decode()


def check(nvrtc, status, path):
    if status != 0:
        nvrtc.nvrtcGetErrorString.restype = ctypes.c_char_p
        raise RuntimeError(f"{path}: {nvrtc.nvrtcGetErrorString(status).decode()}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--check", action="store_true", help="compare with the checked-in PTX")
    args = ap.parse_args()
    nvrtc, lib = load_nvrtc()
    if nvrtc is None:
        print("make_ptx: NVRTC not found (pip install nvidia-cuda-nvrtc)", file=sys.stderr)
        return 3
    sources = sorted(glob.glob(os.path.join(KERNELS, "*.cu")))
    print(f"make_ptx: NVRTC {version(nvrtc)} ({lib}), {len(sources)} kernels, {ARCH}")
    os.makedirs(PTX_DIR, exist_ok=True)
    stale = []
    for src in sources:
        stem = os.path.splitext(os.path.basename(src))[0]
        variants = [(False, f"{stem}.ptx"), (True, f"{stem}.fma.ptx")]
        for fmad, out in variants:
            try:
                ptx = compile_ptx(nvrtc, src, fmad)
            except RuntimeError as e:
                print(e, file=sys.stderr)
                return 1
            dest = os.path.join(PTX_DIR, out)
            if args.check:
                have = open(dest).read() if os.path.exists(dest) else None
                if have != ptx:
                    stale.append(out)
                print(f"  {out}: {'current' if have == ptx else 'STALE'}")
            else:
                with open(dest, "w") as f:
                    f.write(ptx)
                print(f"  {out}: {len(ptx)} bytes")
    if stale:
        print(f"make_ptx: stale PTX {stale}: run tools/make_ptx.py", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
