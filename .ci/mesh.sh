#!/usr/bin/env bash
# Mesh walls (issue 33): the committed STL files of scenarios/meshes/ are
# what tools/make_mesh_stl.py writes, byte for byte, and the mesh
# scenarios build (`grains check`). Needs python3 and the release build
# of the binary (cargo build --release -p grains-cli).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
python3 "$root/tools/make_mesh_stl.py" "$work" >/dev/null
for f in "$root"/scenarios/meshes/*.stl; do
  cmp "$f" "$work/$(basename "$f")"
done
grains="${CARGO_TARGET_DIR:-$root/target}/release/grains"
for s in mesh-hopper-3d mesh-silo-3d mesh-mixer-3d mesh-funnel-2d; do
  "$grains" check "$root/scenarios/$s.toml" >/dev/null
done
echo "mesh: STL files reproduced, mesh scenarios check"
