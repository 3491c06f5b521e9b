"""Kinds about mechanisms and free rotation: ``pendulum``, ``torque_free``, ``slider_crank``
and ``approaches_ideal`` (a clearance joint near its ideal joint)."""

from __future__ import annotations

import numpy as np

from clearbench.harness.measure import series as metrics
from clearbench.harness.measure.criteria import (
    Case,
    Criterion,
    Judged,
    all_of,
    bounded,
    percent,
)
from clearbench.harness.measure.kinds.common import centre_of_mass
from clearbench.harness.measure.kinds.registry import MeasuredKind, TableColumn, register
from clearbench.harness.measure.quantities import COUNT, PURE, L, T, of
from clearbench.kernels.quaternion import quat_normalize_batch, quat_rotate_batch
from clearbench.scenarios import analytic
from clearbench.scenarios.expectation_kinds import (
    APPROACHES_IDEAL,
    PENDULUM,
    SLIDER_CRANK,
    TORQUE_FREE,
)


def pendulum_figures(scene, trajectory, exp):
    p = exp.parameters
    energy = metrics.energy(scene, trajectory).total
    scale = p["mass"] * p["gravity"] * p["pivot_distance"]
    frequency = analytic.physical_pendulum_frequency(p["mass"], p["pivot_distance"],
                                                     p["pivot_inertia"], p["gravity"])
    period = analytic.pendulum_period(p["initial_angle"], frequency)
    angle = None
    for output in scene.outputs:
        if output.kind == "body_angle" and output.body == exp.body:
            angle = metrics.output_values(scene, trajectory)[output.name]
    figures = {"energy_drift": float(np.max(np.abs(energy - energy[0])) / scale),
               "expected_period": period}
    if angle is not None:
        theta = p["initial_angle"] + angle
        crossings = np.nonzero((theta[:-1] > 0) & (theta[1:] <= 0))[0]
        if len(crossings) >= 2:
            t = trajectory.times
            # Linear interpolation of the downward zero crossings.
            times = t[crossings] + theta[crossings] / (theta[crossings] - theta[crossings + 1]) \
                * (t[crossings + 1] - t[crossings])
            measured = float(np.mean(np.diff(times)))
            figures["period"] = measured
            figures["period_relative_error"] = (measured - period) / period
    return figures, "energy_drift", "energy drift relative to m g d"


def _pendulum_judge(case: Case) -> Judged:
    return (*all_of([percent("period error", case.get("period_relative_error"), 0.01),
                     percent("energy drift", case.get("energy_drift"), 0.01)]),
            "period within 1 %, energy drift <= 1 %")


PENDULUM_KIND = register(MeasuredKind(
    "pendulum", pendulum_figures,
    units={"energy_drift": of("m g d"), "expected_period": T, "period": T,
           "period_relative_error": of("the expected period")},
    criterion=Criterion("period within 1 % and energy drift <= 1 % of m g d", _pendulum_judge),
    declaration=PENDULUM,
    analytic_error=(("period_relative_error", None), ("energy_drift", None)),
    table=(TableColumn("energy_drift", "energy drift / (m g d)", 100, "%"),
           TableColumn("period_relative_error", "period, relative error", 100, "%")),
))


def torque_free_figures(scene, trajectory, exp):
    b = scene.body_index(exp.body)
    body = scene.body(exp.body)
    inertia = np.asarray(body.inertia, dtype=float)
    omega = trajectory.angular_velocities[:, b]
    q = trajectory.orientations[:, b]
    momentum = quat_rotate_batch(quat_normalize_batch(q), omega @ inertia.T)
    kinetic = 0.5 * np.einsum("ti,ij,tj->t", omega, inertia, omega)
    l0 = np.linalg.norm(momentum[0])
    return ({"angular_momentum_drift": float(np.max(np.linalg.norm(momentum - momentum[0],
                                                                   axis=1)) / l0),
             "energy_drift": float(np.max(np.abs(kinetic - kinetic[0])) / kinetic[0]),
             "quaternion_norm_error": float(
                 np.max(metrics.quaternion_norm_error(trajectory)[:, b])),
             "flips": float(np.count_nonzero(np.diff(np.sign(omega[:, 1])) != 0))},
            "angular_momentum_drift", "world angular momentum vector, relative to |L0|")


def _torque_free_judge(case: Case) -> Judged:
    return (*percent("momentum drift", case.get("angular_momentum_drift"), 0.01),
            "momentum drift <= 1 %")


TORQUE_FREE_KIND = register(MeasuredKind(
    "torque_free", torque_free_figures,
    units={"angular_momentum_drift": of("|L0|"),
           "energy_drift": of("the initial kinetic energy"), "quaternion_norm_error": PURE,
           "flips": COUNT},
    criterion=Criterion("angular momentum drift <= 1 % of |L0|", _torque_free_judge),
    declaration=TORQUE_FREE,
    analytic_error=(("angular_momentum_drift", None),),
    table=(TableColumn("angular_momentum_drift", "angular momentum drift / L0", 100, "%"),),
))


def slider_crank_figures(scene, trajectory, exp):
    p = exp.parameters
    motion = analytic.slider_crank_motion(trajectory.times, p["crank_length"], p["rod_length"],
                                          p["crank_speed"], offset=p["offset"])
    x = centre_of_mass(scene, trajectory, exp.body)[:, 0]
    error = np.max(np.abs(x - motion.slider_position))
    return ({"slider_position_max_error": float(error),
             "slider_position_relative_error": float(error / p["crank_length"])},
            "slider_position_relative_error", "relative to the crank length")


def _slider_crank_judge(case: Case) -> Judged:
    return (*percent("slider error", case.get("slider_position_relative_error"), 0.01),
            "slider position within 1 % of the crank")


SLIDER_CRANK_KIND = register(MeasuredKind(
    "slider_crank", slider_crank_figures,
    units={"slider_position_max_error": L,
           "slider_position_relative_error": of("the crank length")},
    criterion=Criterion("slider position within 1 % of the crank length", _slider_crank_judge),
    declaration=SLIDER_CRANK,
    analytic_error=(("slider_position_relative_error", None),),
    table=(TableColumn("slider_position_max_error", "slider position error", 1e6, "um"),),
))


def approaches_ideal_figures(scene, trajectory, exp):
    motion = metrics.clearance_motion(scene, trajectory)
    radial = exp.parameters["radial_clearance"]
    excess = float(np.max(motion.excess)) if motion.excess.size else 0.0
    return ({"clearance_excess": excess, "clearance_excess_relative": excess / radial,
             "eccentricity_max": float(np.max(motion.eccentricity)) if motion.excess.size
             else 0.0},
            "clearance_excess_relative",
            "the distance to the ideal-joint motion needs a second run: see the harness")


def _approaches_ideal_judge(case: Case) -> Judged:
    return (*bounded("clearance excess", case.get("clearance_excess_relative"), 1.0,
                     "clearances"), "excess <= one clearance")


APPROACHES_IDEAL_KIND = register(MeasuredKind(
    "approaches_ideal", approaches_ideal_figures,
    units={"clearance_excess": L, "clearance_excess_relative": of("the radial clearance"),
           "eccentricity_max": L},
    criterion=Criterion("clearance excess <= one radial clearance", _approaches_ideal_judge),
    declaration=APPROACHES_IDEAL,
    table=(TableColumn("clearance_excess", "clearance excess", 1e6, "um"),),
))
