"""The projection's corrections are bounded by the violation they set out to remove.

A Gauss–Newton correction is the least motion that removes the linearised violations; where
the rows are nearly dependent and their values not compatible it is far larger than them and
follows a direction the linearisation does not describe. In the reference's ``c60-trip`` of
the variant ``paper-table-4`` at 16 us, the projection of step 706 (11.296 ms) moved the hook by
13.9 mm and turned it by 2.07 rad to remove a violation of 2.1 um, met its active rows again at
other candidates, and the run went on with the plate's journals 1.5 m out of their bores while
its status read ok. ``projection_kernel.correction_budget`` bounds the sum of a projection's
corrections (docs/reference-solver.md, "The projection's bound").

Lengths in mm, times in ms (the C-60's units).
"""

from __future__ import annotations

import dataclasses
import itertools

import numpy as np
import pytest

from clearbench.adapters.base import RunSettings
from clearbench.adapters.reference import create
from clearbench.adapters.reference.build import build
from clearbench.harness.measure import series
from clearbench.ref_solver.forces import rotation_matrices
from clearbench.ref_solver.projection_kernel import (
    CORRECTION_FLOOR,
    PROJECTION_REACH,
    correction_budget,
    correction_size,
)
from clearbench.ref_solver.stepper import MoreauJeanStepper
from clearbench.scenarios.bodies import Body, Motion
from clearbench.scenarios.contacts import ContactPair
from clearbench.scenarios.geometry import MAX_CONTACTS_PER_PAIR
from clearbench.scenarios.inertia import solid_sphere
from clearbench.scenarios.library import get_scene
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.shapes import Plane, Sphere

#: The C-60's length scale [mm] (its largest feature), as the reference engine sets it.
C60_LENGTH = 7.8


def test_a_correction_moves_a_body_point_by_its_translation_and_its_turn_at_the_length():
    delta = np.zeros((3, 6))
    delta[0, :3] = (3e-3, 4e-3, 0.0)        # 5e-3 mm
    delta[1, :3] = (1e-3, 0.0, 0.0)         # 1e-3 mm, and
    delta[1, 3:] = (0.0, 0.0, 1e-3)         # 1e-3 rad at 7.8 mm: 7.8e-3 mm
    # Exact to round-off: a sum of two square roots of sums of three squares.
    assert correction_size(delta, C60_LENGTH) == pytest.approx(8.8e-3, rel=1e-14)
    assert correction_size(np.zeros((2, 6)), C60_LENGTH) == 0.0


def test_the_budget_is_the_reach_times_the_violation_above_a_floor_of_the_length():
    assert correction_budget(2e-3, C60_LENGTH) == pytest.approx(
        PROJECTION_REACH * 2e-3 + CORRECTION_FLOOR * C60_LENGTH, rel=1e-15)
    # A violation at round-off (1e-13 mm) keeps the floor, 7.8e-6 mm (the reach's share,
    # 1e-10 mm, is 1.3e-5 of it, inside the 1e-4 asked): the corrections of redundant rows
    # near convergence (1e-7 mm on the C-60) are not bounded.
    assert correction_budget(1e-13, C60_LENGTH) == pytest.approx(7.8e-6, rel=1e-4)


def test_a_coarse_step_does_not_take_the_c60_apart():
    # 16 us, the coarsest step of the C-60's ladder, to 11.5 ms (719 steps, past step 706).
    # Without the budget the plate's journals read 19 mm out of their bores from 11.296 ms on
    # (1.5 m by 20 ms). With it every pair's penetration stays at the projection's round-off
    # (1e-13 mm measured); the bound, 1e-6 mm, is the scene's own no-penetration limit, four
    # orders below the C-60's smallest clearance (0.01 mm) and seven below the jump.
    scene = get_scene("c60-trip", variant="paper-table-4")
    trajectory = create().run(scene, RunSettings(time_step=0.016, horizon=11.5,
                                                 record_every=1))
    penetration = series.penetration(scene, trajectory)
    names = [contact.name for contact in scene.expanded.contacts]
    deepest = int(np.argmax(penetration.max(axis=0)))
    assert penetration.max() <= 1e-6, (
        f"{names[deepest]} {penetration[:, deepest].max():.3g} mm deep at "
        f"{trajectory.times[int(np.argmax(penetration[:, deepest]))]:.4f} ms")
    # And no body moves by more than 1 mm in a step: at 16 us the fastest part (the hook, at
    # most 8.7 mm/ms as the latch lets go) travels at most 0.14 mm a step (0.089 mm measured);
    # the jump was 13.9 mm.
    step_moves = np.linalg.norm(np.diff(trajectory.positions, axis=0), axis=2)
    assert step_moves.max() <= 1.0, f"a body moved {step_moves.max():.3g} mm in one step"


# --- The budget binding, through the compiled kernel and its Python mirror -------------------
#
# A ball (radius WEDGE_RADIUS, unit mass, no friction) is pinched between a fixed floor (normal
# +z) and a fixed ceiling plane tilted by a small angle about x, both contacts penetrated by
# WEDGE_DEPTH. The two normal rows are nearly dependent (their normals are 180 degrees less the
# tilt apart) and their values incompatible: removing both penetrations needs the ball to slide
# toward the wedge's opening, by WEDGE_DEPTH / sin(tilt / 2) (the Gauss–Newton correction, the
# least motion in the projection's metric). The scene's length scale L is the ball's radius (its
# only feature), so the budget is 1000 * 1e-4 + 1e-6 * 0.1 = 0.1000001 (SI units here).

WEDGE_RADIUS = 0.1
WEDGE_DEPTH = 1e-4


def _wedge(tilt: float, arm: float):
    """The ball in the wedge: (stepper, start state, active (npair, K), length scale). With
    ``arm`` > 0 the ball's sphere sits ``arm`` above its centre of mass, so that a correction
    turns it and the gaps are no longer linear in the correction."""
    angle = np.pi - tilt  # the ceiling's normal: (0, -sin(tilt), -cos(tilt))
    ceiling = (np.cos(0.5 * angle), np.sin(0.5 * angle), 0.0, 0.0)
    centre = WEDGE_RADIUS - WEDGE_DEPTH
    height = centre + (WEDGE_RADIUS - WEDGE_DEPTH) / np.cos(tilt)
    scene = Scene(
        description="a ball pinched in a nearly closed wedge", horizon=1.0, time_step=1e-3,
        bodies=(Body("ground", motion=Motion.FIXED, shapes=(
                    Plane("floor"),
                    Plane("ceiling", position=(0.0, 0.0, height), orientation=ceiling))),
                Body("ball", mass=1.0, inertia=solid_sphere(1.0, WEDGE_RADIUS),
                     position=(0.0, 0.0, centre - arm),
                     shapes=(Sphere("sphere", radius=WEDGE_RADIUS, position=(0.0, 0.0, arm)),))),
        contacts=(ContactPair("floor", body_a="ground", shape_a="floor",
                              body_b="ball", shape_b="sphere"),
                  ContactPair("ceiling", body_a="ground", shape_a="ceiling",
                              body_b="ball", shape_b="sphere")))
    model = build(scene, create("default").run_settings(scene, RunSettings()),
                  python_step=False)
    active = np.zeros((2, MAX_CONTACTS_PER_PAIR), dtype=bool)
    active[:, 0] = True  # sphere-plane: one candidate per pair
    return model.stepper, model.state, active, model.stepper.settings.length_scale


def _turn(p0: np.ndarray, p1: np.ndarray) -> float:
    """Angle [rad] of the rotation taking the unit quaternion p0 (w, x, y, z) to p1."""
    w = p0[0] * p1[0] + p0[1:] @ p1[1:]
    v = p0[0] * p1[1:] - p1[0] * p0[1:] - np.cross(p0[1:], p1[1:])
    return 2.0 * np.arctan2(np.linalg.norm(v), abs(w))


def _motion(start, end, length: float) -> float:
    """The largest |dx| + L |dtheta| over the bodies from ``start`` to ``end`` (the measure of
    ``correction_size``, computed here from the positions and orientations)."""
    return max(float(np.linalg.norm(end.x[b] - start.x[b]))
               + length * _turn(start.p[b], end.p[b]) for b in range(start.x.shape[0]))


def _gauss_newton_size(stepper, state, active, closed, length: float) -> float:
    """The size (|dx| + L |dtheta|) of the unbounded Gauss–Newton correction at ``state``:
    dq = Mp^-1 H^T delta with H Mp^-1 H^T delta = -values, solved here with numpy from the
    projection's rows. Every row is pushing (delta > 0), so it is also the mixed LCP's
    solution when the contacts are unilateral."""
    row_body, row_coef, values, _, _ = stepper._violations(state, active, closed)
    nb = state.x.shape[0]
    jacobian = np.zeros((values.size, 6 * nb))
    for i in range(values.size):
        for body, coefficients in zip(row_body[i], row_coef[i], strict=True):
            if body >= 0:
                jacobian[i, 6 * body:6 * body + 6] += coefficients
    metric_inverse = stepper.projection_inverse
    multipliers = np.linalg.solve(jacobian @ metric_inverse @ jacobian.T, -values)
    assert np.all(multipliers > 0.0)
    delta = (metric_inverse @ jacobian.T @ multipliers).reshape(nb, 6)
    return max(float(np.linalg.norm(d[:3]) + length * np.linalg.norm(d[3:])) for d in delta)


def _project(stepper, state, active, closed, compiled: bool):
    """(iterations, worst, converged, end state) of one projection from a copy of ``state``:
    the compiled kernel (``projection_kernel.project``) or ``_project_python``."""
    end = state.copy()
    if compiled:
        stepper.compiled_projection = True
        result = stepper._project(end, active, closed)
    else:
        result = stepper._project_python(end, active, closed)
    return (*result, end)


# Contacts closed with impulse (equalities, ``closed`` = +inf) or not (unilateral, -inf).
CLOSED = pytest.mark.parametrize("closed_value", [np.inf, -np.inf],
                                 ids=["equalities", "unilateral"])


@CLOSED
def test_a_correction_beyond_the_budget_is_scaled_to_it_on_both_paths(closed_value):
    tilt = 1e-4
    stepper, start, active, length = _wedge(tilt, arm=0.0)
    closed = np.full(active.shape, closed_value)
    assert length == WEDGE_RADIUS
    # Both gaps read -WEDGE_DEPTH to the round-off of building the ceiling's height (0.2 m,
    # ulps of 3e-17 m: 3e-13 of the depth; 1e-9 leaves a thousandfold margin).
    gaps = stepper._candidates(start.x, rotation_matrices(start.p))[0][:, 0]
    np.testing.assert_allclose(gaps, -WEDGE_DEPTH, rtol=1e-9)
    worst = stepper._violations(start, active, closed)[4]
    budget = correction_budget(worst, length)
    # The unbounded correction: a slide of depth / sin(tilt / 2) = 2.0 m, 20 times the budget
    # (0.1 m). 1e-6: the rows' Delassus matrix has a condition number of 1 / sin^2(tilt / 2)
    # = 4e8, which turns the solves' round-off (2.2e-16) into up to 9e-8 of the correction's
    # size (the kernel's solve and this test's differ by that much here); ten times that is
    # still below the bound.
    unbounded = _gauss_newton_size(stepper, start, active, closed, length)
    assert unbounded == pytest.approx(WEDGE_DEPTH / np.sin(0.5 * tilt), rel=1e-6)
    assert unbounded > 10.0 * budget
    ends = {}
    for compiled in (True, False):
        iterations, remaining, converged, end = _project(stepper, start, active, closed,
                                                         compiled)
        ends[compiled] = end
        # The first correction is scaled to the whole budget, the gaps (linear in a
        # translation) both improve by the same fraction of it, the step is accepted and the
        # budget is spent: the projection stops there, unconverged.
        assert (iterations, converged) == (1, False)
        # Remaining penetration: depth (1 - budget / unbounded). The kernel scales by its own
        # unbounded size, 9e-8 from this test's (above), which moves the remainder by
        # 0.05 / 0.95 of that, 5e-9; 1e-6 is the bound above again, and still tells a step
        # taken whole (0.95 of the depth left) from a halved one (0.975).
        assert remaining == pytest.approx(WEDGE_DEPTH * (1.0 - budget / unbounded), rel=1e-6)
        # The ball moved by the budget, no more: the scaled correction's size is the budget
        # to a few ulps (a product and a norm), and measuring it from the positions adds the
        # round-off of x0 + dx (1e-17 m on 0.1 m); 1e-12 relative is far above both.
        motion = _motion(start, end, length)
        assert motion <= budget * (1.0 + 1e-12)
        assert motion >= budget * (1.0 - 1e-12)
    # The two paths agree (measured: identically). They may differ by the order of sums in the
    # rows' products and solves; the correction is a sum of terms 1e4 times its size that
    # cancel (multipliers of 2e4 on normals 1e-4 from opposite), so their round-off (1e-16)
    # reaches 1e-12 of it, and 1e-10 of the budget allows a hundredfold more. The ball does
    # not turn (its rows have no lever arm): its quaternion changes by round-off (2e-16), and
    # 1e-10 still catches any turn the budget could have spent.
    assert np.max(np.abs(ends[True].x - ends[False].x)) <= 1e-10 * budget
    assert np.max(np.abs(ends[True].p - ends[False].p)) <= 1e-10


@CLOSED
def test_a_correction_beyond_what_remains_of_the_budget_is_scaled_to_the_remainder(
        closed_value):
    # A wider wedge (2e-3 rad: an unbounded slide of 0.1 m, 1.2 times the budget once the turn
    # is counted) with the sphere 0.01 m above the ball's centre of mass: a correction turns
    # the ball, the gaps are no longer linear in it, and the projection takes three
    # iterations. Measured: the first correction, scaled to the budget, is halved twice before
    # it helps (0.25 of the budget spent); the second, 0.96 of the budget unbounded, is scaled
    # to the remaining 0.75 and halved once (0.375); the third, 0.59 unbounded, is scaled to
    # the remaining 0.375, helps, and spends the budget.
    stepper, start, active, length = _wedge(2e-3, arm=0.01)
    closed = np.full(active.shape, closed_value)
    budget = correction_budget(stepper._violations(start, active, closed)[4], length)
    assert _gauss_newton_size(stepper, start, active, closed, length) > budget
    paths = {}
    for compiled in (True, False):
        iterations, _, converged, end = _project(stepper, start, active, closed, compiled)
        assert (iterations, converged) == (3, False)
        # The iterates: a projection capped at k iterations runs the same first k ones.
        iterates = [start]
        for cap in (1, 2):
            capped = MoreauJeanStepper(stepper.system, dataclasses.replace(
                stepper.settings, max_projection_iterations=cap))
            iterates.append(_project(capped, start, active, closed, compiled)[3])
        iterates.append(end)
        steps = [_motion(a, b, length) for a, b in itertools.pairwise(iterates)]
        # 1e-12 of the budget: as in the test above, each measured step is its correction's
        # size to a few ulps; three of them add three such errors.
        slack = 1e-12 * budget
        assert all(step > 0.0 for step in steps)
        # The second and third corrections would exceed what was left of the budget; the third
        # is scaled to it ...
        assert _gauss_newton_size(stepper, iterates[1], active, closed, length) \
            > budget - steps[0] + slack
        left = budget - steps[0] - steps[1]
        assert _gauss_newton_size(stepper, iterates[2], active, closed, length) > left + slack
        assert abs(steps[2] - left) <= slack
        # ... so that the corrections together move the ball by the budget, no more.
        assert abs(sum(steps) - budget) <= slack
        # Its net motion is within it too (the triangle inequality).
        assert _motion(start, end, length) <= budget + slack
        paths[compiled] = iterates
    # The paths agree at every iterate (measured: 1.1e-15 m and 5e-15 in the quaternions).
    # The cancellation of the test above is 20 times smaller here (a wedge 20 times wider)
    # and the halvings are exact; 1e-10 of the budget again, and 1e-10 in the quaternions (a
    # turn of at most budget / L = 1 rad, to 1e-12 of it, allowed a hundredfold).
    for compiled_state, python_state in zip(paths[True], paths[False], strict=True):
        assert np.max(np.abs(compiled_state.x - python_state.x)) <= 1e-10 * budget
        assert np.max(np.abs(compiled_state.p - python_state.p)) <= 1e-10
