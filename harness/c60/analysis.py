"""Figures of the C-60 runs: functional conditions at equilibrium, trip events, the bench
experiments' force-displacement curves, and checks of the contacts against their CAD faces.

Every function takes the scene (as the engine was given it) and the trajectory; lengths in mm,
times in ms, forces in N (the scene's mm-g-ms units).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from clearbench.adapters.trajectory import Trajectory
from clearbench.harness.measure import series as metrics
from clearbench.scenarios.c60 import model
from clearbench.scenarios.c60 import primitives as prim
from clearbench.scenarios.geometry import contacts_between, shape_world_placement
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.shapes import Cylinder

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
    release: after the strike, the hook's latch contacts on the tripping bar (C4, C5) first
    carry no force (the latch let go);
    opening: after the release, C7's gap (moving on fixed contact) first exceeds ``open_gap``
    (0.1 mm: clear of the chatter within the joints' clearances that follows the release);
    chatter: C7's closures (force > 0 after a sample with none) between release and opening;
    gap_after: C7's smallest gap over the ``after`` ms following the opening [mm] (> 0: the
    contacts did not close again).
    """

    strike: float
    release: float
    opening: float
    chatter: int
    gap_after: float


def _first(mask: np.ndarray, times: np.ndarray, after: float) -> float:
    hits = np.nonzero(mask & (times > after))[0]
    return float(times[hits[0]]) if hits.size else math.nan


def trip_events(scene: Scene, trajectory: Trajectory, open_gap: float = 0.1,
                after: float = 1.0) -> TripEvents:
    names = trajectory.contact_names
    force = trajectory.contact_normal_force
    times = trajectory.times
    trip = [i for i, n in enumerate(names) if n.startswith("TRIP_")]
    strike = _first(force[:, trip].sum(axis=1) > FORCE_THRESHOLD, times, -math.inf)
    latch = [i for i, n in enumerate(names) if n.startswith(("Hook_Tbar_C4", "Tbar_Hook_C5"))]
    release = _first(force[:, latch].sum(axis=1) <= FORCE_THRESHOLD, times, strike)
    c7 = names.index(model.C7)
    column = [c.name for c in scene.contacts].index(model.C7)
    gaps = metrics.contact_gaps(scene, trajectory)[:, column]
    opening = _first((force[:, c7] <= FORCE_THRESHOLD) & (gaps > open_gap), times, release)
    between = (times > release) & (times < opening)
    loaded = force[:, c7] > FORCE_THRESHOLD
    chatter = int(np.sum(loaded[1:] & ~loaded[:-1] & between[1:]))
    window = (times >= opening) & (times <= opening + after)
    gap_after = float(np.min(gaps[window])) if window.any() else math.nan
    return TripEvents(strike, release, opening, chatter, gap_after)


@dataclass(frozen=True)
class TripForceCurve:
    """Probe force against its displacement since first contact (Section 5.3)."""

    displacement: np.ndarray
    force: np.ndarray
    peak_force: float
    peak_displacement: float
    trip_distance: float


def running_median(values: np.ndarray, width: int) -> np.ndarray:
    """Median of each window of ``width`` (odd) samples centred on each sample. The edges are
    mirrored about the end samples (numpy's ``reflect``), so a single-sample spike at an end
    (the probe's first touch, an impact) is filtered out like one inside; padding with the end
    value would repeat it ``width // 2`` times and keep it."""
    half = min(width // 2, values.size - 1)
    padded = np.pad(values, half, mode="reflect")
    width = 2 * half + 1
    windows = np.lib.stride_tricks.sliding_window_view(padded, width)
    return np.median(windows, axis=1)


def trip_force_curve(scene: Scene, trajectory: Trajectory, median_width: int = 5,
                     released_for: float = 0.02, release_transient: float = 0.005
                     ) -> TripForceCurve:
    """Probe force against displacement since first contact.

    The release is where the force drops to zero for at least ``released_for`` mm of probe
    travel (the latch let go; NaN if it never does); the trip distance is the displacement
    there. The peak is the largest force over the loading phase, taken on the force smoothed
    by a running median of ``median_width`` recorded samples and up to ``release_transient``
    mm before the release: the first touch and the release are impacts (the bar kicked
    against the probe as the latch lets go: up to 16 N in single 0.02 ms samples) that a
    quasi-static load cell does not register. The curve itself is returned raw.
    """
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
    loaded = force > FORCE_THRESHOLD
    release = None
    for index in np.nonzero(loaded[:-1] & ~loaded[1:])[0] + 1:
        later = np.nonzero(loaded[index:])[0]
        reloaded_at = displacement[index + later[0]] if later.size else math.inf
        if reloaded_at - displacement[index] >= released_for:
            release = index
            break
    trip = float(displacement[release]) if release is not None else math.nan
    limit = trip - release_transient if release is not None else math.inf
    smooth = running_median(force, median_width)
    window = np.nonzero(displacement <= limit)[0]
    peak = int(window[np.argmax(smooth[window])])
    return TripForceCurve(displacement, force, float(smooth[peak]), float(displacement[peak]),
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
    start, reach, leave, end = driver.times[-4:]
    forward = (times >= start) & (times <= reach)
    hold = (times >= 0.5 * (reach + leave)) & (times <= leave)
    backward = (times >= leave) & (times <= end)
    loaded = np.nonzero(forward & (force > FORCE_THRESHOLD))[0]
    origin = float(x[loaded[0]]) if loaded.size else math.nan
    return ContactForceCurve(
        x[forward] - origin, force[forward], x[backward] - origin, force[backward],
        float(np.mean(force[hold])) if hold.any() else math.nan,
        float(np.max(x) - origin))


PIN_FILE = "C60/FC/Tbar_FC_measurement.stp"
LAMAGE_AXIS_FILE = "C60/newFC/tbarassembly_asm_axis_lamage.stp"


def pin_lamage_distance() -> tuple[float, float, float]:
    """The tripping bar's pin axis and lamage axis (the features of FC-2/FC-3 and FC-4/FC-5,
    two points of one rigid body): their distance in the xy plane and along z in the ON pose
    (the bar's z axis is world z there) [mm], and the xy distance between the paper's mean
    points (FC-2, FC-3) and (FC-4, FC-5) [mm]. The FC outputs take the pin at its middle and
    the lamage axis at its middle (:func:`clearbench.scenarios.c60.model.c60_outputs`)."""
    primitives = model.primitives()
    rod = primitives[PIN_FILE].primitives[0]
    pin = np.asarray(rod.axis_point) + 0.5 * rod.length * np.asarray(rod.axis)
    segment = primitives[LAMAGE_AXIS_FILE].primitives[0]
    lamage = 0.5 * (np.asarray(segment.start) + np.asarray(segment.end))
    fcs = {k: v["mean"] for k, v in model.load_model()["paper"]["functional_conditions"].items()}
    return (float(np.hypot(*(pin - lamage)[:2])), float(abs((pin - lamage)[2])),
            float(np.hypot(fcs["FC2"] - fcs["FC4"], fcs["FC3"] - fcs["FC5"])))


def tilt(orientation: np.ndarray) -> float:
    """Angle between a body's z axis and world z [rad] (orientation: unit quaternion w, x,
    y, z)."""
    w, x, y, _ = orientation / np.linalg.norm(orientation)
    return float(np.arccos(np.clip(1.0 - 2.0 * (x * x + y * y), -1.0, 1.0)))


def pin_lamage_cause(largest_tilt: float | None = None) -> str:
    """Why FC-2..FC-5 cannot all match the paper's means for any variant of the model
    (``largest_tilt``: the largest tilt of the tripping bar measured in the runs [rad])."""
    ours, height, paper = pin_lamage_distance()
    needed = math.asin(min(1.0, (paper - ours) / height))
    measured = ("" if largest_tilt is None else
                f"; the runs of the identification study tilt it by at most "
                f"{math.degrees(largest_tilt):.2f} deg")
    return (f"FC-2..FC-5 are the x and y of two points of the rigid tripping bar, its pin "
            f"and its lamage axis, {ours:.3f} mm apart in the xy plane and {height:.2f} mm "
            f"apart along z in the CAD; the paper's means put them {paper:.3f} mm apart in "
            f"xy (the mean of a difference is the difference of the means, so this holds for "
            f"the Monte Carlo means as for one run). Only a tilt of the bar out of the plane "
            f"changes that distance, by at most {height:.2f} mm x sin(tilt): "
            f"{paper:.3f} mm needs a tilt of {math.degrees(needed):.1f} deg{measured}. So "
            f"for any variant of this model at least one of the paper's FC-2..FC-5 is not "
            f"the measurement the source's pairs make.")


#: The plunger's face (the trip coil's magnetic plunger) and the case plane of the FC-6 pair.
PLUNGER_FACE_FILE = "C60/C8/probe_surface.stp"
MAGNETIC_CASE_PLANE_FILE = "C60/newFC/Case_Magnetic_Mcontact_FC_X.stp"


@dataclass(frozen=True)
class MagneticGapGeometry:
    """What the FC-6 pair measures, from the CAD's ON pose [mm]: the world x of the plunger's
    face and of the case plane the pair measures from, and FC-6 itself in that pose."""

    plunger_face_x: float
    case_plane_x: float
    cad_value: float

    @property
    def plunger_in_case_plane(self) -> bool:
        """The plunger's face lies in the case plane (within the CAD's 1e-6 mm round-off): the
        pair is then the tripping bar - plunger distance of the paper's Table 1."""
        return abs(self.plunger_face_x - self.case_plane_x) <= 1e-6


@lru_cache(maxsize=1)
def magnetic_gap_geometry() -> MagneticGapGeometry:
    """FC-6's geometry in the CAD's ON pose (:class:`MagneticGapGeometry`; a property of the
    CAD, computed once per process)."""
    poses = model.on_poses()   # the frame's pose included (identity)
    face = model.primitives()[PLUNGER_FACE_FILE].primitives[0]
    plane = model.primitives()[MAGNETIC_CASE_PLANE_FILE].primitives[0]
    name = model.FUNCTIONAL_CONDITIONS["FC-6"][0]
    output = next(o for o in model.c60_outputs(poses) if o.name == name)
    axis = "xyz".index(output.component)
    value = (poses[output.body_b].point(np.asarray(output.point_b, dtype=float))
             - poses[output.body_a].point(np.asarray(output.point_a, dtype=float)))[axis]
    return MagneticGapGeometry(float(poses[model.PLUNGER].point(face.point)[0]),
                               float(plane.point[0]), float(value))


def _patch_ranges() -> dict[tuple[str, str], tuple[float, float]]:
    """(body, shape) -> angular range of the convex cylinder patches the scene models as full
    cylinders (their own frame: angle from x about z, as :class:`~.shapes.Arc`)."""
    ranges = {}
    for contact in model.load_model()["contacts"]:
        for side in ("1", "2"):
            cad = contact[f"cad{side}"]
            surfaces = [p for p in model.primitives()[cad].primitives
                        if not isinstance(p, prim.Point)]
            labels = model.face_labels(cad, len(surfaces))
            for label, primitive in zip(labels, surfaces, strict=True):
                if (not isinstance(primitive, prim.Cylinder) or isinstance(primitive, prim.Ring)
                        or primitive.is_full or primitive.material == "outside"):
                    continue
                name = cad.rsplit("/", 1)[-1].removesuffix(".stp") + (
                    f"_{label}" if label else "")
                ranges[(contact[f"body{side}"], name)] = (primitive.start_angle,
                                                          primitive.end_angle)
    return ranges


def patch_excursions(scene: Scene, trajectory: Trajectory, end: float = math.inf
                     ) -> dict[str, float]:
    """For every contact pair on a convex cylinder PATCH (modelled as a full cylinder), the
    largest angle [rad] by which a contact point that carries force lies outside the CAD
    patch's angular range (0 when it always stays on the patch), over the recorded samples
    up to time ``end`` [ms]."""
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
            if not isinstance(shape, Cylinder):
                raise TypeError(f"{body}.{shape_name} is a {shape.kind}, not the cylinder "
                                "a convex patch is modelled by")
            worst = 0.0
            column = trajectory.contact_index(contact.name)
            a, b = bodies[contact.body_a], bodies[contact.body_b]
            ia, ib = scene.body_index(contact.body_a), scene.body_index(contact.body_b)
            ib_side = ia if side == "a" else ib
            carrying = (trajectory.contact_normal_force[:, column] > FORCE_THRESHOLD) & (
                trajectory.times <= end)
            for t in np.nonzero(carrying)[0]:
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
