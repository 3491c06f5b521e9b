"""The figures of one run: drift, stiction, energy, error, solver statistics, and the verdict.

:func:`measure` computes them from the trajectory and the scene with the per-sample kernels
(:mod:`.series`), the expectation figures (:mod:`.expectation_figures`) and their criteria
(:mod:`.verdicts`), never from an engine's own report; the worker stores them with every run.
Every figure is a float in the scene's units (named below); a figure that does not apply to the
scene is absent.

=======================================  =====================================================
``penetration_max``                      max over pairs and samples of max(0, -gap) [L]
``penetration_beyond_rebuild_max``       the same less each pair's rebuild overlap (how deep
                                         the exact surfaces can overlap while the engine's
                                         rebuilt shapes only touch, a ring of spheres' sag;
                                         ``Trajectory.rebuild_overlap``) [L]
``penetration_relative``                 the same over the smallest feature of its pair [-]
``penetration_swept_max``                largest penetration on the straight path between two
                                         recorded samples (swept test, series.py) [L]
``clearance_eccentricity_max``           largest eccentricity in a clearance joint [L]
``clearance_excess_max``                 eccentricity beyond the radial clearance [L]
``clearance_excess_relative``            the same over the radial clearance [-]
``instrument_penetration_max``           the independent instrument's penetration
                                         (:mod:`.geometry_check`), max over pairs and
                                         samples [L]
``instrument_resolution_max``            its largest certified resolution [L]
``instrument_difference_max``            max |instrument - kernel| penetration [L]
``instrument_clearance_excess_max``      the instrument's clearance-joint excess [L]
``unseen_penetration``                   largest excess of the instrument's penetration over
                                         the kernel's beyond the allowance [L] (> 0: the
                                         verdict "unseen penetration")
``unseen_penetration_time``              the time of that state [T]
``joint_distance_max``                   ideal-joint anchor separation [L]
``joint_angle_max``                      ideal-joint axis / orientation violation [rad]
``driver_offset_max``                    driven translation off its prescription [L]
``driver_angle_offset_max``              driven rotation off its prescription [rad]
``quaternion_norm_error_max``            max | |p| - 1 | as returned by the engine [-]
``stiction_displacement``                largest displacement of a body that must stick [L]
``stiction_creep_rate``                  its mean creep rate (least-squares slope) [L/T]
``energy_scale``                         energy the run is judged against [M L^2/T^2]
``energy_drift``                         max |E - E0| / energy_scale [-]
``energy_growth``                        max rise of E (contact energy included) above its
                                         running minimum / scale [-]
``energy_growth_contact_free``           cross-check: the same without contact energy, on the
                                         samples where every contact is open [-]
``output_error.NAME``                    max |y - y_ref| on named output NAME [its unit]
``error``                                headline error (relative): analytic where the scene
                                         has an analytic reference (see verdicts.py), else the
                                         largest relative output error against the reference
                                         trajectory [-]
``EXPECTATION.FIGURE``                   every figure of every expectation (expectation_figures)
``solver_unconverged_steps``             recorded steps whose one-step problem did not converge
``solver_residual_max``                  largest recorded residual (engine's measure) [-]
``solver_iterations_per_step``           contact-solver iterations per step of the run
                                         (``Trajectory.iterations_per_step``)
=======================================  =====================================================

Verdict (for a run the engine finished): ``diverged`` when a value is not finite, when energy
that may not grow grows by more than :data:`ENERGY_GROWTH_LIMIT` of its scale, when a body
escapes (:data:`ESCAPE_FACTOR`), when a journal leaves its bore (excess beyond
:data:`BORE_ESCAPE_FACTOR` clearances), when an ideal joint comes apart (anchors farther apart
than :data:`JOINT_BREAK_FRACTION` of the scene's size, or axes more than
:data:`JOINT_BREAK_ANGLE` apart; a driven component off its prescription by as much), or
when a penetration, on a sample or on the straight path between two (swept), exceeds the
smallest feature of its pair (tunnelling); ``ok`` otherwise. An ok run whose
``unseen_penetration`` is > 0 has the verdict "unseen penetration"
(:func:`~clearbench.harness.measure.verdicts.run_verdict`), its ``verdict_reason`` naming the
pair, the time and both figures (:mod:`.geometry_check`).
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass

import numpy as np

from clearbench.adapters.trajectory import RunStatus, Trajectory
from clearbench.harness.measure import geometry_check
from clearbench.harness.measure import series as metrics
from clearbench.harness.measure.expectation_figures import evaluate, evaluate_implied
from clearbench.harness.measure.verdicts import analytic_error, has_analytic_error, judgement
from clearbench.scenarios.bodies import Motion
from clearbench.scenarios.expectation_kinds import body_stays, energy_may_not_grow
from clearbench.scenarios.scales import contact_feature_sizes, scene_size
from clearbench.scenarios.scene import Scene

LOG = logging.getLogger(__name__)

#: Energy growth beyond this fraction of the energy scale is a diverged run.
ENERGY_GROWTH_LIMIT = 0.1
#: A body farther than this many scene sizes (plus free-flight reach) from its start escaped.
ESCAPE_FACTOR = 100.0
#: A clearance-joint excess beyond this many radial clearances means the journal left its bore:
#: past one clearance the joint already fails its physics (``approaches_ideal``); three more
#: clearances of penetration into the bearing wall is a joint the engine no longer holds.
BORE_ESCAPE_FACTOR = 3.0
#: Ideal-joint anchors farther apart than this fraction of the scene's size
#: (:func:`~clearbench.scenarios.scales.scene_size`) mean the joint came apart: the mechanism
#: no longer has its geometry. A compliant engine's joint error at a workable step is orders
#: of magnitude below it (docs/harness.md gives the measured figures).
JOINT_BREAK_FRACTION = 0.05
#: Ideal-joint axes (revolute) or relative orientations (prismatic, fixed) farther apart than
#: this [rad] (5.7 degrees) mean the joint came apart.
JOINT_BREAK_ANGLE = 0.1


@dataclass(frozen=True)
class Measurement:
    """Figures of one run (see the module docstring for names and units)."""

    figures: dict
    expectations: tuple
    verdict: RunStatus
    verdict_reason: str = ""
    error_source: str = ""
    metrics_error: str = ""


def has_analytic_reference(scene: Scene) -> bool:
    """True when an expectation of the scene has an analytic solution to measure error by."""
    return any(has_analytic_error(e.kind) for e in scene.expectations)


def first_non_finite(trajectory: Trajectory) -> str | None:
    """Where the trajectory first holds a non-finite value, as a message; None if nowhere."""
    for name in ("positions", "orientations", "velocities", "angular_velocities",
                 "contact_normal_force", "contact_force"):
        values = np.asarray(getattr(trajectory, name), dtype=float)
        if values.size == 0:
            continue
        bad = ~np.isfinite(values.reshape(len(values), -1)).all(axis=1)
        if bad.any():
            k = int(np.argmax(bad))
            t = trajectory.times[k] if k < len(trajectory.times) else float("nan")
            return f"non-finite {name} at t = {t:.6g} (sample {k})"
    if len(trajectory.times) and not np.isfinite(trajectory.times).all():
        return "non-finite sample times"
    return None


def _expectation_results(scene: Scene, trajectory: Trajectory, out: _Collector):
    """Every expectation's figures (also flattened into ``NAME.FIGURE`` figures), pass/fail,
    criterion and detail (:mod:`.verdicts`), the implied checks that apply
    (:func:`~.expectation_figures.evaluate_implied`), and the analytic error with its
    source."""
    expectations = {e.name: e for e in scene.expectations}
    results = []
    errors = []
    evaluated = evaluate(scene, trajectory)
    implied = evaluate_implied(scene, trajectory, out.figures)
    for result in evaluated + implied:
        figures = {k: float(v) for k, v in result.figures.items()}
        expectation = expectations.get(result.name)
        verdict = judgement(scene, result.kind, expectation.body if expectation else None,
                            figures, result.where, expectation)
        results.append({"name": result.name, "kind": result.kind, "figures": figures,
                        "headline": result.headline, "note": result.note,
                        "passed": verdict.passed, "criterion": verdict.criterion,
                        "detail": verdict.detail})
        for key, value in figures.items():
            out.put(f"{result.name}.{key}", value)
        error = analytic_error(result.kind, figures)
        if math.isfinite(error):
            errors.append((error, result.name))
    if not errors:
        return results, math.nan, ""
    value, name = max(errors)
    return results, value, f"analytic ({name})"


class _Collector:
    def __init__(self):
        self.figures: dict[str, float] = {}
        self.errors: list[str] = []

    def put(self, name: str, value) -> None:
        self.figures[name] = float(value)

    def guard(self, group: str):
        collector = self

        class _Guard:
            def __enter__(self):
                return self

            def __exit__(self, kind, error, tb):
                if error is not None and isinstance(error, Exception):
                    LOG.debug("metric group %s failed", group, exc_info=True)
                    collector.errors.append(f"{group}: {type(error).__name__}: {error}")
                    return True
                return False

        return _Guard()


def _solver_figures(trajectory: Trajectory, out: _Collector) -> None:
    if len(trajectory.times) == 0:
        return
    converged = np.asarray(trajectory.solver_converged, dtype=bool)
    out.put("solver_unconverged_steps", int(np.count_nonzero(~converged[1:])))
    residual = np.asarray(trajectory.solver_residual, dtype=float)
    if np.isfinite(residual).any():
        out.put("solver_residual_max", float(np.nanmax(residual)))
    out.put("solver_iterations_per_step", trajectory.iterations_per_step)


def measure(scene: Scene, trajectory: Trajectory, reference: Trajectory | None = None,
            reference_label: str = "reference trajectory") -> Measurement:
    """Every figure of one run, its expectations and its verdict.

    Parameters
    ----------
    scene : Scene
        The scene the engine was given.
    trajectory : Trajectory
        What the engine returned.
    reference : Trajectory, optional
        The same scene by the reference solver at a fine step; the run's named outputs are
        compared with it where the scene has no analytic reference.
    """
    out = _Collector()
    _solver_figures(trajectory, out)
    status = trajectory.status
    if status is not RunStatus.OK or len(trajectory.times) == 0:
        return Measurement(out.figures, (), status, trajectory.message)
    reasons: list[str] = []

    with out.guard("drift"):
        _drift(scene, trajectory, out, reasons)
    with out.guard("stiction"):
        _stiction(scene, trajectory, out)
    with out.guard("energy"):
        _energy(scene, trajectory, out, reasons)
    with out.guard("escape"):
        _escape(scene, trajectory, reasons)
    unseen = ""
    with out.guard("geometry check"):
        unseen = _geometry(scene, trajectory, out)

    results: list[dict] = []
    error, source = math.nan, ""
    with out.guard("expectations"):
        results, error, source = _expectation_results(scene, trajectory, out)
    if math.isnan(error) and reference is not None and scene.outputs:
        with out.guard("reference error"):
            error = _output_error(scene, trajectory, reference, out)
            source = reference_label if math.isfinite(error) else ""
    if math.isfinite(error):
        out.put("error", error)
    verdict = RunStatus.DIVERGED if reasons else RunStatus.OK
    return Measurement(out.figures, tuple(results), verdict,
                       _broken(trajectory, reasons) or unseen, source, "; ".join(out.errors))


def _geometry(scene, trajectory, out: _Collector) -> str:
    """The independent instrument's figures beside the kernel's (:mod:`.geometry_check`);
    returns the "unseen penetration" reason ("" when there is none)."""
    if not scene.expanded.contacts:
        return ""
    result = geometry_check.check(scene, trajectory)
    out.put("instrument_penetration_max", np.nanmax(result.instrument.penetration))
    out.put("instrument_resolution_max", np.nanmax(result.instrument.resolution))
    out.put("instrument_difference_max", result.agreement_max)
    out.put(geometry_check.UNSEEN_FIGURE, result.unseen_max)
    if scene.clearance_joints:
        out.put("instrument_clearance_excess_max",
                np.max(geometry_check.clearance_excess(scene, result)[0]))
    if result.unseen_max <= 0.0:
        return ""
    out.put(f"{geometry_check.UNSEEN_FIGURE}_time", result.times[result.worst()[0]])
    return result.message(scene.units.length, scene.units.time)


def _broken(trajectory: Trajectory, reasons: list[str]) -> str:
    """The verdict's reason: what the engine said and what the harness found, when the engine
    called a run ok that the harness judges broken (empty when it judges it sound)."""
    if not reasons:
        return ""
    return (f"engine status {trajectory.status.value}, harness: diverged "
            f"({'; '.join(reasons)})")


def _drift(scene, trajectory, out: _Collector, reasons: list[str]) -> None:
    out.put("quaternion_norm_error_max", np.max(metrics.quaternion_norm_error(trajectory)))
    contacts = scene.expanded.contacts
    if contacts:
        depth = metrics.penetration(scene, trajectory)
        out.put("penetration_max", np.max(depth))
        out.put("penetration_beyond_rebuild_max",
                np.max(metrics.penetration_beyond_rebuild(scene, trajectory, depth)))
        feature = contact_feature_sizes(scene)
        relative = np.max(depth, axis=0) / feature
        out.put("penetration_relative", np.max(relative))
        worst = int(np.argmax(relative))
        if relative[worst] > 1.0:
            k = int(np.argmax(depth[:, worst] > feature[worst]))
            reasons.append(f"penetration {np.max(depth[:, worst]):.3g} in {contacts[worst].name}"
                           f" exceeds its smallest feature {feature[worst]:.3g} (tunnelled, "
                           f"from t = {trajectory.times[k]:.4g})")
        else:
            swept = metrics.swept_penetration(scene, trajectory)
            out.put("penetration_swept_max", np.max(swept))
            worst = int(np.argmax(swept / feature))
            if swept[worst] > feature[worst]:
                reasons.append(f"{contacts[worst].name} crossed between two samples: "
                               f"penetration {swept[worst]:.3g} on the path between them exceeds"
                               f" its smallest feature {feature[worst]:.3g} (tunnelled)")
    if scene.clearance_joints:
        motion = metrics.clearance_motion(scene, trajectory)
        out.put("clearance_eccentricity_max", np.max(motion.eccentricity))
        out.put("clearance_excess_max", np.max(motion.excess))
        radial = np.array([j.radial_clearance for j in scene.clearance_joints])
        relative = np.max(motion.excess, axis=0) / radial
        out.put("clearance_excess_relative", np.max(relative))
        worst = int(np.argmax(relative))
        if relative[worst] > BORE_ESCAPE_FACTOR:
            k = int(np.argmax(motion.excess[:, worst] > BORE_ESCAPE_FACTOR * radial[worst]))
            reasons.append(f"journal of {motion.names[worst]} left its bore at t = "
                           f"{trajectory.times[k]:.4g} (excess {relative[worst]:.3g} radial "
                           "clearances)")
    if scene.joints:
        violation = metrics.joint_violation(scene, trajectory)
        out.put("joint_distance_max", np.max(violation.distance))
        out.put("joint_angle_max", np.max(violation.angle))
        bound = JOINT_BREAK_FRACTION * scene_size(scene)
        distance = np.max(violation.distance, axis=0)
        angle = np.max(violation.angle, axis=0)
        for j, name in enumerate(violation.names):
            if distance[j] > bound or angle[j] > JOINT_BREAK_ANGLE:
                reasons.append(f"ideal joint {name} came apart (anchors {distance[j]:.3g} apart,"
                               f" limit {bound:.3g}; axes {angle[j]:.3g} rad, limit "
                               f"{JOINT_BREAK_ANGLE:g})")
                break
    if scene.drivers:
        _drivers(scene, trajectory, out, reasons)


def _drivers(scene, trajectory, out: _Collector, reasons: list[str]) -> None:
    """A driver not followed is a constraint broken like a joint come apart (an engine that
    cannot satisfy a driver and the joints together may give up either)."""
    deviation = np.max(metrics.driver_deviation(scene, trajectory), axis=0)
    rotation = np.array([d.is_rotation for d in scene.drivers])
    bounds = np.where(rotation, JOINT_BREAK_ANGLE, JOINT_BREAK_FRACTION * scene_size(scene))
    if (~rotation).any():
        out.put("driver_offset_max", np.max(deviation[~rotation]))
    if rotation.any():
        out.put("driver_angle_offset_max", np.max(deviation[rotation]))
    for d, driver in enumerate(scene.drivers):
        if deviation[d] > bounds[d]:
            reasons.append(f"driver {driver.name} not followed ({driver.component} off its "
                           f"prescription by {deviation[d]:.3g}, limit {bounds[d]:.3g})")
            return


def _stiction(scene, trajectory, out: _Collector) -> None:
    worst = None
    for expectation in scene.expectations:
        if not body_stays(expectation.kind):
            continue
        start = float(expectation.parameters.get("start_time", 0.0))
        end = expectation.parameters.get("end_time")
        result = metrics.stiction(scene, trajectory, expectation.body, start,
                                  None if end is None else float(end))
        if worst is None or result.displacement > worst.displacement:
            worst = result
    if worst is not None:
        out.put("stiction_displacement", worst.displacement)
        out.put("stiction_creep_rate", worst.creep_rate)


def _energy(scene, trajectory, out: _Collector, reasons: list[str]) -> None:
    if not metrics.energy_balance_applies(scene):
        return
    energy = metrics.energy(scene, trajectory)
    total = energy.total
    scale = metrics.energy_scale(scene, energy)
    out.put("energy_scale", scale)
    out.put("energy_drift", np.max(np.abs(total - total[0])) / scale)
    rise, rise_scale = metrics.energy_growth(scene, trajectory, energy)
    growth = rise / rise_scale
    out.put("energy_growth", growth)
    free_rise, free_scale = metrics.energy_growth_contact_free(scene, trajectory, energy)
    out.put("energy_growth_contact_free", free_rise / free_scale)
    must_not_grow = any(energy_may_not_grow(e.kind) for e in scene.expectations)
    if must_not_grow and growth > ENERGY_GROWTH_LIMIT:
        reasons.append(f"energy grew by {100 * growth:.3g} % of its scale {rise_scale:.3g} "
                       "(energy that may not grow)")


def _escape(scene, trajectory, reasons: list[str]) -> None:
    positions = metrics.centre_of_mass_positions(scene, trajectory)
    moved = np.linalg.norm(positions - positions[:1], axis=2)
    horizon = float(trajectory.times[-1] - trajectory.times[0])
    speed = max((float(np.linalg.norm(b.velocity)) for b in scene.bodies), default=0.0)
    reach = speed * horizon + 0.5 * float(np.linalg.norm(scene.gravity)) * horizon**2
    limit = ESCAPE_FACTOR * scene_size(scene) + reach
    for b, body in enumerate(scene.bodies):
        if body.motion is Motion.FIXED:
            continue
        if np.max(moved[:, b]) > limit:
            k = int(np.argmax(moved[:, b] > limit))
            reasons.append(f"body {body.name} escaped ({moved[k, b]:.3g} from its start at "
                           f"t = {trajectory.times[k]:.4g}, limit {limit:.3g})")
            return


def _output_error(scene, trajectory, reference, out: _Collector) -> float:
    """Max |y - y_ref| per named output (reference interpolated to the run's samples, within
    its time span); returns the largest relative to the reference's range."""
    values = metrics.output_values(scene, trajectory)
    expected = metrics.output_values(scene, reference)
    t, t_ref = trajectory.times, reference.times
    inside = (t >= t_ref[0] - 1e-12 * max(1.0, abs(t_ref[-1]))) & \
        (t <= t_ref[-1] * (1 + 1e-12) + 1e-300)
    worst = math.nan
    for name, y in values.items():
        y_ref = np.interp(t[inside], t_ref, expected[name])
        difference = float(np.max(np.abs(y[inside] - y_ref))) if inside.any() else math.nan
        out.put(f"output_error.{name}", difference)
        span = float(np.ptp(expected[name])) or float(np.max(np.abs(expected[name]))) or 1.0
        relative = difference / span
        if math.isfinite(relative) and not relative <= worst:
            worst = relative
    return worst
