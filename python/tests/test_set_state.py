"""Setters mid-run carry the stretched springs: the contact forces of a
settled bed (Hertz-Mindlin with epsd rolling springs; JKR adhesion with
constant rolling torque) are the same right after the positions and
velocities are set to themselves, the Cundall-Strack spring included; and
a run whose state is set to itself mid-run, with grains resting on a
tilted wall and on a grain (wall, grain and rolling springs) or leaving
them through stretched JKR contacts, goes on as the straight run does."""

import numpy as np
import pytest

import grains


def settled(scenarios, extra):
    s = grains.Scenario.load(scenarios / "pour-3d-sand.toml")
    sets = [
        ("particles.count", 200),
        ("particles.region.lo", [0.0, 0.0, 0.0006]),
        ("particles.region.hi", [0.012, 0.012, 0.005]),
    ] + extra
    for k, v in sets:
        s = s.set(k, v)
    sim = grains.Simulation(s, threads=1)
    sim.run(steps=30000)  # about 62 ms: the grains rest on the floor
    return sim


def forces(sim):
    """Contact forces by id pair (smaller id first, force on it)."""
    c = sim.contacts()
    out = {}
    for (i, j), f, n in zip(c["ids"], c["force"], c["normal"]):
        key, sign = ((i, j), 1.0) if i < j else ((j, i), -1.0)
        out[key] = (sign * f, sign * n)
    return out


JKR = [
    ("contact.rolling", "constant"),
    ("contact.cohesion", "jkr"),
    ("materials.0.surface_energy", 0.05),
    ("materials.1.surface_energy", 0.05),
]


@pytest.mark.parametrize("extra", [[], JKR], ids=["epsd", "jkr"])
def test_setters_keep_the_stretched_springs(scenarios, extra):
    sim = settled(scenarios, extra)
    before = forces(sim)
    assert len(before) >= 4, "the bed has grain-grain contacts"
    # The tangential part (the Cundall-Strack spring and dashpot) is there:
    # dropping the springs would change these forces.
    tangential = [np.linalg.norm(f - np.dot(f, n) * n) for f, n in before.values()]
    assert max(tangential) > 1e-3 * max(np.linalg.norm(f) for f, _ in before.values())
    sim.positions = sim.positions
    sim.velocities = sim.velocities
    after = forces(sim)
    assert after.keys() == before.keys()
    for k in before:
        np.testing.assert_allclose(after[k][0], before[k][0], rtol=1e-9, atol=1e-15, err_msg=str(k))
    sim.run(steps=1000)
    assert np.all(np.isfinite(sim.positions))


# Mid-run: the setters given the state they read must change nothing. Two
# small scenarios on a plane tilted by 8 degrees about y, whose springs are
# all stretched when the state is set; a straight run of the same steps is
# the reference. Under velocity Verlet nothing but the springs and marks
# carries history, so any spring dropped or mis-assigned shows. Not to the
# bit: a setter restarts the engine from the state, and the forces it
# evaluates there take the contacts' damping at the full-step velocity,
# where the step had taken it at the predicted (half-step) one, as velocity
# Verlet does. On grains at rest (speeds of 1e-15 m/s) that moves the runs
# apart by 1e-21 m/s (measured): they must agree to 1e-12 of the
# scenario's scales (length d, speed v, spin 2 v / d). On a contact that
# is opening at 5 mm/s it moves them by 2e-8 of v (measured): held to
# 1e-6. A dropped spring moves a resting grain by 1e-5 of d; a dropped JKR
# mark ends its contact there, 1e-3 of v.

TILT = np.radians(8.0)
NORMAL = np.array([-np.sin(TILT), 0.0, np.cos(TILT)])  # of the tilted plane through 0


def tilted_scenario(body):
    return grains.Scenario.from_toml(
        f"""
name = "set-state-midrun"
dimension = "3d"
{body}

[domain]
lo = [-0.1, -0.1, -0.1]
hi = [0.1, 0.1, 0.1]

[[walls]]
name = "tilted"
shape = {{ type = "plane", point = [0.0, 0.0, 0.0], normal = {vector(NORMAL)} }}
"""
    )


def vector(v):
    return "[" + ", ".join(repr(float(x)) for x in v) + "]"


def grain(pos, vel=(0.0, 0.0, 0.0), frozen=False):
    flag = "true" if frozen else "false"
    return f"{{ position = {vector(pos)}, velocity = {vector(vel)}, frozen = {flag} }}"


def state(sim):
    return [sim.positions, sim.velocities, sim.angular_velocities]


def same_state(a, b, d, v, tol):
    scales = [d, v, 2 * v / d]
    for x, y, s, what in zip(state(a), state(b), scales, ["positions", "velocities", "spins"]):
        diff = np.max(np.abs(x - y))
        print(f"{what}: largest difference {diff:e} ({diff / s:e} of {s:e})")
        assert diff <= tol * s, f"{what}: largest difference {diff:e}, scale {s:e}"


def set_to_itself(sim):
    sim.positions = sim.positions
    sim.velocities = sim.velocities


def test_setters_mid_run_keep_wall_and_rolling_springs():
    """Hertz-Mindlin with epsd rolling springs, gravity: grain 1 rests on
    the tilted plane (held there by its wall spring, tan 8 deg < mu = 0.5,
    and its wall rolling spring, < mu_r = 0.5); grain 3 rests on the frozen
    grain 2, its line of centres 8 deg from the vertical (a grain spring
    and a rolling spring, tan 8 deg < mu_r / 2). Dropping the wall spring
    lets grain 1 slip by about F_t / k_t = 3e-8 m before it holds again."""
    r = 0.5e-3
    lean = np.array([np.sin(TILT), 0.0, np.cos(TILT)])
    a = np.array([0.0, 0.01, 0.004])
    grains_ = [grain(r * NORMAL), grain(a, frozen=True), grain(a + 2 * r * lean)]
    body = f"""
gravity = [0.0, 0.0, -9.81]

[particles]
placement = "none"
d0 = 1.0e-3
material = "sand"
add = [{", ".join(grains_)}]

[contact]
model = "hertz-mindlin"
rotation = true
rolling = "epsd"

[[materials]]
name = "sand"
density = 2650.0
youngs_modulus = 2.0e7
poisson_ratio = 0.3
restitution = 0.5
friction = 0.5
rolling_friction = 0.5

[run]
integrator = "verlet"
dt = 2.0e-6
duration = 1.0
"""
    scenario = tilted_scenario(body)
    straight = grains.Simulation(scenario, threads=1)
    straight.run(steps=30000)
    mid = grains.Simulation(scenario, threads=1)
    mid.run(steps=20000)  # 40 ms: both grains at rest, their springs stretched
    held = mid.positions[[0, 2]]
    assert np.max(np.abs(mid.velocities[[0, 2]])) < 1e-5, mid.velocities
    set_to_itself(mid)
    mid.run(steps=10000)
    same_state(mid, straight, 2 * r, np.sqrt(9.81 * 2 * r), 1e-12)
    # The grains still rest where they were: the springs hold them.
    assert np.max(np.abs(mid.positions[[0, 2]] - held)) < 1e-9


def test_setters_mid_run_keep_jkr_contacts_beyond_touching():
    """JKR adhesion (R = 1 cm, E = 10 MPa, Gamma = 0.05 J/m^2, restitution
    0.3, constant rolling torque), no gravity: grain 1 leaves the tilted
    plane, grain 3 the frozen grain 2, each at 5 mm/s with 1 mm/s
    sideways (a stretched tangential spring). The state is set while
    each contact is stretched beyond touching, gap between 0.3 and 1 of
    the breaking separation delta_c = (3/4)(pi^2 Gamma^2 R*/E*^2)^(1/3)
    (Johnson, Kendall & Roberts 1971): without the contact's mark the
    contact would be lost there."""
    r, gamma = 0.01, 0.05
    e_star = 1e7 / (2 * (1 - 0.25**2))  # like materials: E / (2 (1 - nu^2))
    breaking = {
        "wall": 0.75 * (np.pi**2 * gamma**2 * r / e_star**2) ** (1 / 3),
        "pair": 0.75 * (np.pi**2 * gamma**2 * (r / 2) / e_star**2) ** (1 / 3),
    }
    side = np.array([0.0, 1.0, 0.0])
    f = np.array([0.0, 0.1, 0.05])
    x = np.array([1.0, 0.0, 0.0])
    grains_ = [
        grain((r - 1e-9) * NORMAL, 5e-3 * NORMAL + 1e-3 * side),
        grain(f, frozen=True),
        grain(f + (2 * r - 1e-9) * x, 5e-3 * x + 1e-3 * side),
    ]
    body = f"""
[particles]
placement = "none"
d0 = 0.02
material = "ball"
add = [{", ".join(grains_)}]

[contact]
model = "hertz-mindlin"
rotation = true
rolling = "constant"
cohesion = "jkr"

[[materials]]
name = "ball"
density = 2500.0
youngs_modulus = 1.0e7
poisson_ratio = 0.25
restitution = 0.3
friction = 0.5
rolling_friction = 0.1
surface_energy = 0.05

[run]
integrator = "verlet"
dt = 1.0e-6
duration = 1.0
"""
    scenario = tilted_scenario(body)

    def gaps(sim):
        p = sim.positions
        return {"wall": p[0] @ NORMAL - r, "pair": np.linalg.norm(p[2] - p[1]) - 2 * r}

    total = 6000
    mid = grains.Simulation(scenario, threads=1)
    todo = {"wall", "pair"}
    while todo:
        mid.run(steps=1)
        assert mid.step < total, f"never stretched: {gaps(mid)}"
        for k, g in gaps(mid).items():
            if k in todo and 0.3 * breaking[k] < g < breaking[k]:
                if k == "pair":
                    c = mid.contacts()
                    assert len(c["overlap"]) == 1 and c["overlap"][0] < 0, c
                set_to_itself(mid)
                todo.remove(k)
    mid.run(steps=total - mid.step)
    straight = grains.Simulation(scenario, threads=1)
    straight.run(steps=total)
    same_state(mid, straight, 2 * r, 5e-3, 1e-6)
