#!/usr/bin/env python3
"""Makes the clump chute workload from the sphere chute (data.chute_flow).

The frozen base (type 2) stays as it is. The flowing spheres (type 1) are
visited in id order; each is a candidate centre for a rod of three spheres
of d = 1 at spacing 0.5 along the rod's axis (length 2), with an
orientation drawn uniformly on rotations (Shoemake's method) from one
stream seeded with SEED. A rod is kept when none of its spheres overlaps a
base sphere or a kept rod's sphere (centres at least 1 apart, periodic in
x and y); up to TRIES orientations are drawn per candidate. A kept rod
takes the velocity of the sphere it replaces and no spin.

Writes, beside this script:
  chute-clumps.bodies  one body a line: x y z qw qx qy qz vx vy vz (what
                       `grains bench chute-clumps` reads)
  chute-clumps.rods    LAMMPS commands that make the same bodies from the
                       molecule template rod.mol (read by in.chute-clumps)
  rod.mol              the molecule template: three spheres of d = 1, mass 1

Run from anywhere: python3 bench/make_chute_clumps.py
"""
import math
import os
import random

SEED = 12345
TRIES = 8
SPACING = 0.5
# The box of data.chute_flow, periodic in x and y.
L = 39.89999997739
HERE = os.path.dirname(os.path.abspath(__file__))


def read_chute(path):
    """The atoms (id, type, x, y, z) and their velocities by id."""
    atoms, vel, section = [], {}, None
    with open(path) as f:
        for line in f:
            words = line.split()
            if not words:
                continue
            if words[0] in ("Atoms", "Velocities"):
                section = words[0]
                continue
            if section == "Atoms":
                atoms.append((int(words[0]), int(words[1]), *map(float, words[4:7])))
            elif section == "Velocities":
                vel[int(words[0])] = tuple(map(float, words[1:4]))
    atoms.sort()
    return atoms, vel


def uniform_quat(rng):
    """A unit quaternion (w, x, y, z) uniform on rotations (Shoemake 1992)."""
    u1, u2, u3 = rng.random(), rng.random(), rng.random()
    a, b = math.sqrt(1.0 - u1), math.sqrt(u1)
    t2, t3 = 2.0 * math.pi * u2, 2.0 * math.pi * u3
    return (b * math.cos(t3), a * math.sin(t2), a * math.cos(t2), b * math.sin(t3))


def axis(q):
    """The body x axis in the space frame: the first column of R(q)."""
    w, x, y, z = q
    return (1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y + w * z), 2.0 * (x * z - w * y))


class Grid:
    """Sphere centres in cells of side 1 (periodic in x and y)."""

    def __init__(self):
        self.n = int(L)  # cells of side L / n >= 1
        self.cells = {}

    def key(self, p):
        c = lambda v: int(math.floor(v % L / L * self.n)) % self.n
        return (c(p[0]), c(p[1]), int(math.floor(p[2])))

    def add(self, p):
        self.cells.setdefault(self.key(p), []).append(p)

    def clear(self, p):
        """True when no stored centre is closer than 1 to p."""
        kx, ky, kz = self.key(p)
        for dx in (-1, 0, 1):
            for dy in (-1, 0, 1):
                for dz in (-1, 0, 1):
                    k = ((kx + dx) % self.n, (ky + dy) % self.n, kz + dz)
                    for q in self.cells.get(k, ()):
                        d = [p[0] - q[0], p[1] - q[1], p[2] - q[2]]
                        for a in (0, 1):
                            d[a] -= L * round(d[a] / L)
                        if d[0] * d[0] + d[1] * d[1] + d[2] * d[2] < 1.0:
                            return False
        return True


def main():
    atoms, vel = read_chute(os.path.join(HERE, "data.chute_flow"))
    grid = Grid()
    for _, t, x, y, z in atoms:
        if t == 2:
            grid.add((x, y, z))
    rng = random.Random(SEED)
    bodies = []
    for i, t, x, y, z in atoms:
        if t != 1:
            continue
        for _ in range(TRIES):
            q = uniform_quat(rng)
            e = axis(q)
            spheres = [tuple(c + k * SPACING * ea for c, ea in zip((x, y, z), e)) for k in (-1, 0, 1)]
            if all(grid.clear(s) for s in spheres):
                for s in spheres:
                    grid.add(s)
                bodies.append(((x, y, z), q, vel.get(i, (0.0, 0.0, 0.0))))
                break
    with open(os.path.join(HERE, "chute-clumps.bodies"), "w") as f:
        f.write(f"# made by bench/make_chute_clumps.py (seed {SEED}, {TRIES} tries): {len(bodies)} rods\n")
        f.write("# x y z qw qx qy qz vx vy vz\n")
        for p, q, v in bodies:
            f.write(" ".join(repr(c) for c in (*p, *q, *v)) + "\n")
    with open(os.path.join(HERE, "chute-clumps.rods"), "w") as f:
        f.write(f"# made by bench/make_chute_clumps.py (seed {SEED}): {len(bodies)} rods of rod.mol\n")
        for p, q, _ in bodies:
            # create_atoms turns the template by an angle (degrees) about an axis.
            w = max(-1.0, min(1.0, q[0]))
            half = math.acos(w)
            s = math.sin(half)
            if s < 1e-12:
                theta, ax = 0.0, (1.0, 0.0, 0.0)
            else:
                theta, ax = math.degrees(2.0 * half), (q[1] / s, q[2] / s, q[3] / s)
            f.write("create_atoms 0 single {} {} {} mol rod {} rotate {} {} {} {} units box\n".format(
                *map(repr, p), SEED, *map(repr, (theta, *ax))))
        for b, (_, _, v) in enumerate(bodies):
            f.write("set mol {} vx {} vy {} vz {}\n".format(b + 1, *map(repr, v)))
    with open(os.path.join(HERE, "rod.mol"), "w") as f:
        f.write("# a rod of three spheres of d = 1 at spacing 0.5 (bench/make_chute_clumps.py)\n\n")
        f.write("3 atoms\n\nCoords\n\n")
        for k in (1, 2, 3):
            f.write(f"{k} {(k - 2) * SPACING} 0 0\n")
        f.write("\nTypes\n\n1 1\n2 1\n3 1\n\nDiameters\n\n1 1\n2 1\n3 1\n\nMasses\n\n1 1\n2 1\n3 1\n")
    print(f"{len(bodies)} rods ({3 * len(bodies)} sub-spheres) from {sum(1 for a in atoms if a[1] == 1)} spheres")


if __name__ == "__main__":
    main()
