"""The one mechanical energy (scenarios/energy.py) the harness and every engine's energy guard
use: hand values for kinetic, gravity and spring energy, one state and a trajectory of states
alike, and torsional springs counted only when their angle is given."""

from __future__ import annotations

import numpy as np
import pytest

from clearbench.adapters.energy_guard import EnergyGuard
from clearbench.scenarios.bodies import Body, Motion
from clearbench.scenarios.energy import mechanical_energy, rigid_spring_points
from clearbench.scenarios.expectations import Expectation
from clearbench.scenarios.inertia import diagonal
from clearbench.scenarios.loads import LinearSpringDamper, TorsionalSpringDamper
from clearbench.scenarios.scene import Scene

MASS = 2.0  # kg
INERTIA = (0.1, 0.2, 0.3)  # kg m^2, principal
STIFFNESS, REST, PRELOAD = 50.0, 0.5, 3.0  # N/m, m, N
TORSION_STIFFNESS, TORSION_REST, TORSION_PRELOAD = 4.0, 0.2, 0.5  # N m/rad, rad, N m


def _scene(expectations=()) -> Scene:
    return Scene(
        name="energy-probe", description="a free body on a spring to a fixed base",
        horizon=1.0, time_step=1e-3,
        bodies=(Body("base", motion=Motion.FIXED),
                Body("bob", mass=MASS, inertia=diagonal(*INERTIA), position=(0.0, 0.0, 1.0))),
        loads=(LinearSpringDamper("spring", body_a="base", body_b="bob", stiffness=STIFFNESS,
                                  rest_length=REST, preload=PRELOAD),
               TorsionalSpringDamper("torsion", body_a="base", body_b="bob",
                                     stiffness=TORSION_STIFFNESS, rest_angle=TORSION_REST,
                                     preload=TORSION_PRELOAD)),
        expectations=expectations,
    )


def _state(height: float, speed: float):
    """One state of the probe: the bob at ``height`` [m] moving up at ``speed`` [m/s] and
    spinning at (1, 2, 3) rad/s in body axes."""
    com = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, height]])
    velocity = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, speed]])
    omega = np.array([[0.0, 0.0, 0.0], [1.0, 2.0, 3.0]])
    rotations = np.repeat(np.eye(3)[None], 2, axis=0)
    return com, velocity, omega, rotations


def test_hand_values_of_one_state():
    scene = _scene()
    com, velocity, omega, rotations = _state(1.5, 2.0)
    angle = 0.7
    energy = mechanical_energy(scene, com, velocity, omega,
                               rigid_spring_points(scene, com, rotations), {"torsion": angle})
    kinetic = 0.5 * MASS * 2.0**2 + 0.5 * (0.1 * 1 + 0.2 * 4 + 0.3 * 9)
    gravity = MASS * 9.81 * 1.5  # scene gravity (0, 0, -9.81); the fixed base counts nothing
    stretch = 1.5 - REST
    springs = PRELOAD * stretch + 0.5 * STIFFNESS * stretch**2 \
        + TORSION_PRELOAD * angle + 0.5 * TORSION_STIFFNESS * (angle - TORSION_REST) ** 2
    # Sums of a few products of numbers of order 1 to 100: equal to a few ulps.
    assert float(energy.kinetic) == pytest.approx(kinetic, rel=1e-14)
    assert float(energy.gravity) == pytest.approx(gravity, rel=1e-14)
    assert float(energy.springs) == pytest.approx(springs, rel=1e-14)
    assert float(energy.total) == pytest.approx(kinetic + gravity + springs, rel=1e-14)


def test_a_trajectory_is_its_states_one_by_one():
    scene = _scene()
    states = [_state(h, v) for h, v in ((1.0, 0.0), (1.2, -0.5), (0.8, 3.0))]
    stacked = [np.stack(parts) for parts in zip(*states, strict=True)]
    com, velocity, omega, rotations = stacked
    angles = np.array([0.0, 0.1, -0.3])

    def points(load):
        return com[:, 0], com[:, 1]

    batch = mechanical_energy(scene, com, velocity, omega, points, {"torsion": angles})
    assert batch.total.shape == (3,)
    for k, (c, v, w, r) in enumerate(states):
        one = mechanical_energy(scene, c, v, w, rigid_spring_points(scene, c, r),
                                {"torsion": angles[k]})
        # The same operations on the same numbers: equal to the last bit.
        assert float(one.total) == batch.total[k]


def test_a_torsional_spring_without_its_angle_is_not_counted_and_keeps_the_guard_off():
    scene = _scene()
    com, velocity, omega, rotations = _state(1.5, 0.0)
    points = rigid_spring_points(scene, com, rotations)
    without = mechanical_energy(scene, com, velocity, omega, points)
    with_angle = mechanical_energy(scene, com, velocity, omega, points, {"torsion": 0.0})
    assert float(with_angle.springs - without.springs) == pytest.approx(
        0.5 * TORSION_STIFFNESS * TORSION_REST**2, rel=1e-14)  # a few ulps, as above
    guarded = _scene(expectations=(Expectation("energy", "energy_non_increasing"),))
    assert EnergyGuard(guarded, 0.1, 10).applies
    blind = EnergyGuard(guarded, 0.1, 10, counts_torsional_springs=False)
    assert not blind.applies
    assert "torsional_springs do uncounted work" in blind.notes[0]
