#!/usr/bin/env python3
"""Writes the STL meshes of the shipped mesh scenarios (binary STL, mm).

    python3 tools/make_mesh_stl.py [OUT_DIR]     # default scenarios/meshes
    python3 tools/make_mesh_stl.py --bench-floor FILE   # bench/mesh_vs_plane.sh

- cone-hopper.stl: a conical funnel, outlet radius 3 mm at z = 0, opening
  at 30 deg from the vertical up to radius 12 mm (beyond the half diagonal
  of the 16 mm silo of scenarios/mesh-hopper-3d.toml, so grains refilled
  into the silo's corners land inside it); 96 sectors x 24 rings.
- silo-floor.stl: the floor of scenarios/hopper-3d.toml as a mesh: a 16 mm
  square at z = 0 with a centred 5 mm square hole, cut into 0.5 mm squares
  (1848 triangles), for the STL-versus-analytic discharge comparison.
- mixer-blade.stl: a flat two-armed paddle, 22 mm across and 4 mm high,
  in the plane y = 0 about the z axis, 2 x 11 x 4 squares.
- --bench-floor: a 100 mm square at z = 0 cut into 224 x 224 squares
  (100 352 triangles, 0.45 mm wide: a 1 mm grain touches several), the
  floor of bench/mesh-floor.toml (not committed: 5 MB).

Only the standard library: the files are small and the format is simple
(80-byte header, triangle count, then per triangle a normal, three
vertices as little-endian float32 and a 2-byte attribute).
"""

import math
import os
import struct
import sys


def write_stl(path, triangles):
    with open(path, "wb") as f:
        f.write(b"grains mesh".ljust(80, b" "))
        f.write(struct.pack("<I", len(triangles)))
        for a, b, c in triangles:
            u = [b[i] - a[i] for i in range(3)]
            v = [c[i] - a[i] for i in range(3)]
            n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
            length = math.sqrt(sum(x * x for x in n)) or 1.0
            f.write(struct.pack("<3f", *[x / length for x in n]))
            for p in (a, b, c):
                f.write(struct.pack("<3f", *p))
            f.write(b"\0\0")
    print(f"{path}: {len(triangles)} triangles")


def quad(p00, p10, p11, p01):
    return [(p00, p10, p11), (p00, p11, p01)]


def cone(r_out=3.0, r_top=12.0, half_angle_deg=30.0, sectors=96, rings=24):
    height = (r_top - r_out) / math.tan(math.radians(half_angle_deg))
    tris = []
    for k in range(rings):
        z0, z1 = height * k / rings, height * (k + 1) / rings
        ra = r_out + (r_top - r_out) * k / rings
        rb = r_out + (r_top - r_out) * (k + 1) / rings
        for s in range(sectors):
            # The last sector ends on the first one's vertices exactly (not
            # at 2π, whose sine is -2.4e-16), so the cone is closed.
            t0, t1 = 2 * math.pi * s / sectors, 2 * math.pi * ((s + 1) % sectors) / sectors
            p = lambda r, t, z: (r * math.cos(t), r * math.sin(t), z)
            tris += quad(p(ra, t0, z0), p(ra, t1, z0), p(rb, t1, z1), p(rb, t0, z1))
    return tris


def silo_floor(side=16.0, hole=5.0, cell=0.5):
    n = int(round(side / cell))
    lo, hi = (side - hole) / 2, (side + hole) / 2
    tris = []
    for i in range(n):
        for j in range(n):
            x0, y0, x1, y1 = i * cell, j * cell, (i + 1) * cell, (j + 1) * cell
            if hole > 0 and lo <= x0 and x1 <= hi and lo <= y0 and y1 <= hi:
                continue
            tris += quad((x0, y0, 0.0), (x1, y0, 0.0), (x1, y1, 0.0), (x0, y1, 0.0))
    return tris


def blade(radius=11.0, height=4.0, cells=11, rows=4):
    tris = []
    for i in range(2 * cells):
        x0 = -radius + i * radius / cells
        x1 = x0 + radius / cells
        for j in range(rows):
            z0, z1 = j * height / rows, (j + 1) * height / rows
            tris += quad((x0, 0.0, z0), (x1, 0.0, z0), (x1, 0.0, z1), (x0, 0.0, z1))
    return tris


def main():
    if len(sys.argv) == 3 and sys.argv[1] == "--bench-floor":
        write_stl(sys.argv[2], silo_floor(side=100.0, hole=0.0, cell=100.0 / 224))
        return
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        os.path.dirname(__file__), "..", "scenarios", "meshes")
    os.makedirs(out, exist_ok=True)
    write_stl(os.path.join(out, "cone-hopper.stl"), cone())
    write_stl(os.path.join(out, "silo-floor.stl"), silo_floor())
    write_stl(os.path.join(out, "mixer-blade.stl"), blade())


if __name__ == "__main__":
    main()
