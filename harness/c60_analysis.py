"""Figures of the C-60 runs: functional conditions at equilibrium, trip events, the bench
experiments' force-displacement curves, and checks of the contacts against their CAD faces.

Every function takes the scene (as the engine was given it) and the trajectory; lengths in mm,
times in ms, forces in N (the scene's mm-g-ms units).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from clearbench.adapters.trajectory import Trajectory
from clearbench.scenarios import c60_model as model
from clearbench.scenarios import c60_primitives as prim
from clearbench.scenarios.geometry import contacts_between, shape_world_placement
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.shapes import Cylinder

from . import metrics

#: A contact carries force when its normal force exceeds this [N] (1e-6 of the 1-30 N forces
#: of the mechanism; the solver's residual tolerance puts round-off far below it).
FORCE_THRESHOLD = 1e-6


def window_mean(values: np.ndarray, times: np.ndarray, start: float, end: float) -> float:
    """Mean of ``values`` over the samples with start <= t <= end."""
    inside = (times >= start) & (times <= end)
    return float(np.mean(values[inside])) if inside.any() else math.nan


def settled_outputs(scene: Scene, trajectory: Trajectory, window: float = 1.0) -> dict:
    """Every named output averaged over the last ``window`` ms of the run."""
    end = float(trajectory.times[-1])
    values = metrics.output_values(scene, trajectory)
    return {name: window_mean(v, trajectory.times, end - window, end)
            for name, v in values.items()}


def output_drift(scene: Scene, trajectory: Trajectory, window: float = 1.0) -> dict:
    """Largest change of each output over the last ``window`` ms (is it settled?)."""
    times = trajectory.times
    inside = times >= times[-1] - window
    return {name: float(np.ptp(v[inside]))
            for name, v in metrics.output_values(scene, trajectory).items()}


@dataclass(frozen=True)
class TripEvents:
    """Times [ms] of the magnetic trip (NaN when it did not happen in the run).

    strike: the plunger first pushes the tripping bar (TRIP contacts carry force);
    release: the hook's last latch contact on the tripping bar (C4, C5) unloads for good;
    opening: C7 (moving on fixed contact) unloads for good and its gap exceeds 0.01 mm;
    final_gap: C7's gap at the end of the run [mm].
    """

    strike: float
    release: float
    opening: float
    final_gap: float

    @property
    def opening_after_strike(self) -> float:
        return self.opening - self.strike


def _last_loaded(force: np.ndarray, times: np.ndarray) -> float:
    """Time after which ``force`` (T,) stays at zero for good (NaN if loaded at the end)."""
    loaded = np.nonzero(force > FORCE_THRESHOLD)[0]
    if loaded.size == 0:
        return math.nan
    last = loaded[-1]
    return math.nan if last == len(times) - 1 else float(times[last + 1])


def trip_events(scene: Scene, trajectory: Trajectory, open_gap: float = 0.01) -> TripEvents:
    names = trajectory.contact_names
    force = trajectory.contact_normal_force
    trip = [i for i, n in enumerate(names) if n.startswith("TRIP_")]
    pushed = np.nonzero(force[:, trip].sum(axis=1) > FORCE_THRESHOLD)[0]
    strike = float(trajectory.times[pushed[0]]) if pushed.size else math.nan
    latch = [i for i, n in enumerate(names) if n.startswith(("Hook_Tbar_C4", "Tbar_Hook_C5"))]
    release = _last_loaded(force[:, latch].sum(axis=1), trajectory.times)
    c7 = names.index(model.C7)
    gaps = metrics.contact_gaps(scene, trajectory)[:, scene.contacts.index(
        next(c for c in scene.contacts if c.name == model.C7))]
    opening = _last_loaded(force[:, c7], trajectory.times)
    if not math.isnan(opening):
        beyond = np.nonzero((trajectory.times >= opening) & (gaps > open_gap))[0]
        opening = float(trajectory.times[beyond[0]]) if beyond.size else math.nan
    return TripEvents(strike, release, opening, float(gaps[-1]))


@dataclass(frozen=True)
class TripForceCurve:
    """Probe force against its displacement since first contact (Section 5.3)."""

    displacement: np.ndarray
    force: np.ndarray
    peak_force: float
    peak_displacement: float
    trip_distance: float


def trip_force_curve(scene: Scene, trajectory: Trajectory, release_fraction: float = 0.05
                     ) -> TripForceCurve:
    """The trip distance is the displacement at which the force, after its peak, falls below
    ``release_fraction`` of the peak (the latch let go; NaN if it never does)."""
    values = metrics.output_values(scene, trajectory)
    force = values["probe_force"]
    position = values["probe_y"]
    touching = np.nonzero(force > FORCE_THRESHOLD)[0]
    if touching.size == 0:
        empty = np.zeros(0)
        return TripForceCurve(empty, empty, math.nan, math.nan, math.nan)
    first = touching[0]
    displacement = position[first:] - position[first]
    force = force[first:]
    peak = int(np.argmax(force))
    after = np.nonzero(force[peak:] < release_fraction * force[peak])[0]
    trip = float(displacement[peak + after[0]]) if after.size else math.nan
    return TripForceCurve(displacement, force, float(force[peak]), float(displacement[peak]),
                          trip)


@dataclass(frozen=True)
class ContactForceCurve:
    """Section 5.2: force on the probe against its position, forward then backward.

    ``displacement`` is measured from the position where the probe first carries load on the
    forward stroke; ``equilibrium_force`` is the mean force over the second half of the hold at
    the reference position; ``loaded_travel`` the displacement from first load to the
    reference."""

    forward_displacement: np.ndarray
    forward_force: np.ndarray
    backward_displacement: np.ndarray
    backward_force: np.ndarray
    equilibrium_force: float
    loaded_travel: float


def contact_force_curve(scene: Scene, trajectory: Trajectory) -> ContactForceCurve:
    values = metrics.output_values(scene, trajectory)
    force = values["probe_force"]
    x = values["probe_x"] - values["probe_x"][0]
    times = trajectory.times
    driver = next(d for d in scene.drivers if d.name == "probe_x")
    start, reach, leave, end = driver.times[1:5]
    forward = (times >= start) & (times <= reach)
    hold = (times >= 0.5 * (reach + leave)) & (times <= leave)
    backward = (times >= leave) & (times <= end)
    loaded = np.nonzero(forward & (force > FORCE_THRESHOLD))[0]
    origin = float(x[loaded[0]]) if loaded.size else math.nan
    return ContactForceCurve(
        x[forward] - origin, force[forward], x[backward] - origin, force[backward],
        float(np.mean(force[hold])) if hold.any() else math.nan,
        float(np.max(x) - origin))


def _patch_ranges() -> dict[tuple[str, str], tuple[float, float]]:
    """(body, shape) -> angular range of the convex cylinder patches the scene models as full
    cylinders (their own frame: angle from x about z, as :class:`~.shapes.Arc`)."""
    ranges = {}
    for contact in model.load_model()["contacts"]:
        for side in ("1", "2"):
            items = [p for p in model.primitives()[contact[f"cad{side}"]].primitives
                     if isinstance(p, prim.Cylinder) and not isinstance(p, prim.Ring)
                     and not p.is_full and p.material != "outside"]
            for primitive in items:
                stem = contact[f"cad{side}"].rsplit("/", 1)[-1].removesuffix(".stp")
                labels = model._face_labels(contact[f"cad{side}"], len(
                    [q for q in model.primitives()[contact[f"cad{side}"]].primitives
                     if not isinstance(q, prim.Point)]))
                index = model.primitives()[contact[f"cad{side}"]].primitives.index(primitive)
                label = labels[index] if len(labels) > 1 else ""
                name = stem + (f"_{label}" if label else "")
                ranges[(contact[f"body{side}"], name)] = (primitive.start_angle,
                                                          primitive.end_angle)
    return ranges


def patch_excursions(scene: Scene, trajectory: Trajectory) -> dict[str, float]:
    """For every contact pair on a convex cylinder PATCH (modelled as a full cylinder), the
    largest angle [rad] by which a contact point that carries force lies outside the CAD
    patch's angular range (0 when it always stays on the patch), over the recorded samples."""
    ranges = _patch_ranges()
    bodies = {b.name: b for b in scene.bodies}
    out = {}
    for contact in scene.contacts:
        for side in ("a", "b"):
            body = getattr(contact, f"body_{side}")
            shape_name = getattr(contact, f"shape_{side}")
            if (body, shape_name) not in ranges:
                continue
            start, end = ranges[(body, shape_name)]
            shape = bodies[body].shape(shape_name)
            assert isinstance(shape, Cylinder)
            worst = 0.0
            column = trajectory.contact_index(contact.name)
            a, b = bodies[contact.body_a], bodies[contact.body_b]
            ia, ib = scene.body_index(contact.body_a), scene.body_index(contact.body_b)
            ib_side = ia if side == "a" else ib
            for t in np.nonzero(trajectory.contact_normal_force[:, column] > FORCE_THRESHOLD)[0]:
                pose_a = (trajectory.positions[t, ia], trajectory.orientations[t, ia])
                pose_b = (trajectory.positions[t, ib], trajectory.orientations[t, ib])
                result = contacts_between(a.shape(contact.shape_a), pose_a,
                                          b.shape(contact.shape_b), pose_b)
                points = result.point_a if side == "a" else result.point_b
                gaps = result.gap - contact.offset
                position, rotation = shape_world_placement(
                    shape, trajectory.positions[t, ib_side], trajectory.orientations[t, ib_side])
                for point, gap in zip(points, gaps, strict=True):
                    if gap > 1e-3:  # an open candidate of the pair (the far rim points)
                        continue
                    local = rotation.T @ (point - position)
                    angle = math.atan2(local[1], local[0])
                    offset = (angle - start) % (2 * math.pi)
                    span = end - start
                    if offset > span:
                        outside = min(offset - span, 2 * math.pi - offset)
                        worst = max(worst, outside)
            out[contact.name] = worst
    return out
