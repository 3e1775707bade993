#!/usr/bin/env python3
"""Draws a mesh scenario's run: the STL wall as a wireframe and the grains
of the last VTK frame, in a 3D view, and the load on the mesh from
walls.csv underneath.

    python3 tools/plot_mesh_run.py RUN_DIR MESH.stl OUT.png \
        [--scale 1e-3] [--translate X Y Z] [--wall NAME] [--turn OMEGA_Z]

--turn: the mesh turns about z at this rate (rad/s) from t = 0 (the
mixer's blade), so it is drawn where it stands at the frame's time.
Needs numpy and matplotlib (python3 -m pip install numpy matplotlib).
"""

import argparse
import csv
import glob
import math
import os
import re
import struct

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def read_stl(path):
    """Binary STL triangles, an (n, 3, 3) array."""
    with open(path, "rb") as f:
        data = f.read()
    n = struct.unpack_from("<I", data, 80)[0]
    tris = np.zeros((n, 3, 3))
    for k in range(n):
        v = struct.unpack_from("<12f", data, 84 + 50 * k)
        tris[k] = np.array(v[3:]).reshape(3, 3)
    return tris


def last_frame(run):
    frames = sorted(glob.glob(os.path.join(run, "frames", "*.vtp")))
    text = open(frames[-1]).read()
    time = float(re.search(r'Name="TimeValue"[^>]*>([^<]+)<', text).group(1))

    def array(name):
        body = re.search(r'Name="%s"[^>]*>([^<]+)<' % name, text).group(1)
        return np.array([float(x) for x in body.split()])

    pts = re.search(r"<Points>.*?>([^<]+)<", text, re.S).group(1)
    pos = np.array([float(x) for x in pts.split()]).reshape(-1, 3)
    return time, pos, array("radius")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("run")
    ap.add_argument("stl")
    ap.add_argument("out")
    ap.add_argument("--scale", type=float, default=1e-3)
    ap.add_argument("--translate", type=float, nargs=3, default=[0, 0, 0])
    ap.add_argument("--wall", default=None)
    ap.add_argument("--turn", type=float, default=0.0)
    ap.add_argument("--title", default="")
    a = ap.parse_args()

    time, pos, radius = last_frame(a.run)
    tris = read_stl(a.stl) * a.scale + np.array(a.translate)
    if a.turn:
        c, s = math.cos(a.turn * time), math.sin(a.turn * time)
        rot = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
        tris = tris @ rot.T
    mm = 1e3
    fig = plt.figure(figsize=(9, 5))
    ax = fig.add_subplot(1, 2, 1, projection="3d")
    # The grains cut by the plane y = centre (the front half), so the inside shows.
    yc = np.median(pos[:, 1])
    front = pos[:, 1] <= yc
    ax.scatter(pos[front, 0] * mm, pos[front, 1] * mm, pos[front, 2] * mm,
               s=6, c=radius[front] * mm, cmap="viridis", depthshade=False)
    step = max(1, len(tris) // 1500)
    for t in tris[::step]:
        loop = np.vstack([t, t[:1]]) * mm
        ax.plot(loop[:, 0], loop[:, 1], loop[:, 2], color="0.45", lw=0.3)
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_zlabel("z (mm)")
    ax.set_title(f"{a.title} t = {time:.2f} s")
    ax.view_init(elev=18, azim=-60)

    ax2 = fig.add_subplot(1, 2, 2)
    rows = list(csv.DictReader(open(os.path.join(a.run, "walls.csv"))))
    wall = a.wall or rows[0].keys().__iter__().__next__()
    t = [float(r["time"]) for r in rows]
    for key, label in [("fz", "force z (mN)"), ("tz", "torque z (µN m)")]:
        col = f"{wall}_{key}"
        f = 1e3 if key == "fz" else 1e6
        ax2.plot(t, [float(r[col]) * f for r in rows], label=label)
    ax2.set_xlabel("time (s)")
    ax2.set_title(f"load on '{wall}' (walls.csv)")
    ax2.legend()
    fig.tight_layout()
    fig.savefig(a.out, dpi=110)
    print(a.out)


if __name__ == "__main__":
    main()
