"""MuJoCo adapter, pure parts: restitution mapping, presets, time-step guard, ring errors,
driver profile integration. No model is compiled here."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from clearbench.adapters.mujoco.engine import create
from clearbench.adapters.mujoco.settings import (
    PRESETS,
    contact_parameters,
    damping_ratio_for_restitution,
    effective_stiffness_damping,
    resolve_settings,
    restitution_for_damping_ratio,
    ring_chord_error,
    ring_clearance_error,
    time_step_warnings,
)


def _restitution_by_ode(zeta: float) -> float:
    """Exit speed of a unit-speed impact on x'' = -x - 2 zeta x', ended when x + 2 zeta x'
    (the contact force) falls to zero."""

    def force(t, y):
        return y[0] + 2.0 * zeta * y[1]

    force.terminal = True
    force.direction = -1
    solution = solve_ivp(lambda t, y: [y[1], -y[0] - 2.0 * zeta * y[1]], (0.0, 1e3),
                         [0.0, 1.0], events=force, rtol=1e-12, atol=1e-14, max_step=0.01)
    return -float(solution.y_events[0][0][1])


@pytest.mark.parametrize("zeta", [0.01, 0.0744, 0.3, 0.7, 0.999, 1.0, 1.001, 2.0, 3.0, 8.0])
def test_closed_form_restitution_matches_the_ode(zeta):
    # Both are exact; 1e-8 covers the ODE solver's tolerance (rtol 1e-12 on an O(1) state,
    # event located to ~1e-10).
    assert restitution_for_damping_ratio(zeta) == pytest.approx(_restitution_by_ode(zeta),
                                                                rel=1e-8)


def test_unilateral_mapping_gives_the_measured_damping_ratio_for_e_08():
    # docs/engines/mujoco.md: zeta(0.8) = 0.0744 for a damper that only pushes (the textbook formula
    # e = exp(-zeta pi / sqrt(1 - zeta^2)), which waits for the spring to relax, gives 0.0709).
    zeta = damping_ratio_for_restitution(0.8)
    assert zeta == pytest.approx(0.0744, abs=5e-5)  # 4 digits as docs/engines/mujoco.md states it
    textbook = -math.log(0.8) / math.sqrt(math.pi**2 + math.log(0.8) ** 2)
    assert textbook == pytest.approx(0.0709, abs=5e-5)
    assert restitution_for_damping_ratio(1.0) == pytest.approx(math.exp(-2.0), rel=1e-15)


def test_restitution_mapping_round_trips_and_is_monotone():
    zetas = np.linspace(0.0, 3.0, 301)
    restitutions = [restitution_for_damping_ratio(z) for z in zetas]
    assert np.all(np.diff(restitutions) < 0)
    for e in (0.05, 0.2, 0.5, 0.8, 0.9, 0.99):
        zeta = damping_ratio_for_restitution(e)
        # Bisection to 1e-12 relative in zeta; de/dzeta is O(1): 1e-10 in e.
        assert restitution_for_damping_ratio(zeta) == pytest.approx(e, abs=1e-10)
    # e = 0 is out of reach of a spring-damper: it maps to the plastic ratio (e = 0.024 at 3).
    assert damping_ratio_for_restitution(0.0) == 3.0
    assert restitution_for_damping_ratio(3.0) == pytest.approx(0.0238, abs=1e-4)
    assert damping_ratio_for_restitution(1.0) == 0.0
    with pytest.raises(ValueError, match="restitution"):
        damping_ratio_for_restitution(1.5)


def test_contact_parameters_lengthen_the_timeconst_for_enough_steps_per_contact():
    settings = resolve_settings("tuned")
    dt = 1e-3
    chosen = contact_parameters(0.9, settings, dt)
    timeconst, zeta = chosen.solref
    assert chosen.mapped and zeta == pytest.approx(damping_ratio_for_restitution(0.9))
    # Half period of the contact spring pi / omega, omega = 1 / (timeconst zeta): at least
    # the requested 20 steps (equality up to round-off).
    half_period = math.pi * timeconst * zeta
    assert half_period >= settings.restitution_contact_steps * dt * (1 - 1e-12)
    # Linear spring: constant impedance d0 = dmax.
    assert chosen.solimp[0] == chosen.solimp[1] == settings.solimp[1]
    # tuned maps e = 0 to the plastic ratio 3; without map_plastic e = 0 pairs keep the
    # preset's solref (2 dt, 1); MuJoCo's default keeps (0.02, 1).
    assert contact_parameters(0.0, settings, dt).solref[1] == 3.0
    plastic = contact_parameters(0.0, resolve_settings("tuned", {"map_plastic": False}), dt)
    assert not plastic.mapped and plastic.solref == (2 * dt, 1.0)
    assert contact_parameters(0.0, resolve_settings("default"), dt).solref == (0.02, 1.0)


def test_time_step_guard_flags_stiff_and_overdamped_constraints():
    dt = 1e-3
    # docs/engines/mujoco.md: solref "0.005 0.07" at dt 1e-3 launched a ball to 32x its drop height.
    stiffness, damping = effective_stiffness_damping((0.005, 0.07), dt)
    assert stiffness * dt**2 == pytest.approx(1e-6 / (0.005 * 0.07) ** 2)
    assert any("stiffness*dt^2" in w for w in time_step_warnings("pair", (0.005, 0.07), dt))
    # A negative solref with damping*dt > 2 also gained energy.
    assert any("damping*dt" in w for w in time_step_warnings("pair", (-100.0, -2500.0), dt))
    # MuJoCo's default and the tuned (2 dt, 1) stay within the bounds.
    assert time_step_warnings("pair", (0.02, 1.0), dt) == []
    assert time_step_warnings("pair", (2 * dt, 1.0), dt) == []
    # refsafe clamps the timeconst to 2 dt: (1e-4, 1) acts as (2e-3, 1) at dt 1e-3.
    assert effective_stiffness_damping((1e-4, 1.0), dt) == effective_stiffness_damping(
        (2e-3, 1.0), dt)
    assert time_step_warnings("pair", (1e-4, 1.0), dt, refsafe=False)


def test_presets_and_options():
    assert set(PRESETS) >= {"default", "tuned"}
    default = resolve_settings("default")
    assert (default.cone, default.noslip_iterations, default.solref) == ("pyramidal", 0,
                                                                          (0.02, 1.0))
    tuned = resolve_settings("tuned")
    assert tuned.cone == "elliptic" and tuned.noslip_iterations == 10
    assert tuned.contact_timeconst(1e-4) == pytest.approx(2e-4)
    # An explicit solref replaces the step-relative timeconst of the preset.
    assert resolve_settings("tuned", {"solref": (0.005, 0.07)}).contact_timeconst(1e-3) == 0.005
    with pytest.raises(ValueError, match="unknown mujoco option"):
        create("tuned").settings({"solref_typo": 1})
    with pytest.raises(ValueError, match="unknown mujoco preset"):
        create("fast")
    with pytest.raises(ValueError, match="cone"):
        resolve_settings("default", {"cone": "round"})


def test_ring_errors():
    # docs/engines/mujoco.md figures for a 2.1 mm bore (C-60 scale) with a polygon of capsules:
    # 41 um at N = 16 and 2.5 um at N = 64 (R (1/cos(pi/N) - 1), rounded there).
    assert ring_chord_error(2.1e-3, 16, "capsule") == pytest.approx(41e-6, rel=0.02)
    assert ring_chord_error(2.1e-3, 64, "capsule") == pytest.approx(2.5e-6, rel=0.02)
    # Spheres on the circle: the chord sags R (1 - cos(pi/N)) inside, slightly less.
    assert ring_chord_error(2.1e-3, 64, "sphere") < ring_chord_error(2.1e-3, 64, "capsule")
    # The clearance a nearly filling journal sees grows by about c (pi/N)^2 / 2, far below
    # the chord error (c = 21 um in a 2.1 mm bore).
    for piece in ("sphere", "capsule"):
        extra = ring_clearance_error(2.1e-3, 21e-6, 64, piece)
        assert 0 < extra == pytest.approx(21e-6 * (math.pi / 64) ** 2 / 2, rel=0.05)
