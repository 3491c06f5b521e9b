"""The instrument's penetration of every contact pair of a recorded run.

For each contact pair of ``scene.expanded`` (explicit pairs, then those of the clearance joints)
and each recorded state, the instrument's signed distance G (:mod:`.pair`) less the pair's
offset, as the kernel's figure takes it: penetration = max(0, offset - G).

Which states are read, and the guarantee
----------------------------------------
The caller chooses the states read per pair (default: every recorded state; the run-wide
check reads a stride of them and refines around what it finds, :mod:`..geometry_check`).
A state read first meets a screen (one evaluation): the partner's
exact signed distance at the centre of the bounded shape's bounding sphere, less its radius, is
a lower bound of G (a signed distance is 1-Lipschitz); where that bound is above both 0 and the
offset, the pair cannot penetrate at that state and its penetration is 0 exactly. Every other
state is searched to the pair's resolution with the offset as floor (:func:`.search.minimise`,
at most :data:`RUN_CELLS_PER_STATE` cells per state): the witnessed penetration is a real
point's, and the true one (as :mod:`.pair` defines it) is at most ``penetration +
resolution``.

A ring around a journal (a circle or arc against a cylinder whose axis crosses the ring's
plane inside the ring in the scene's initial configuration: a bearing ring of a clearance
joint) is a special case: once the journal's axis crosses the ring's plane outside the ring,
the journal has left it and the ring's points are no longer the measure of how deep it went;
those states are marked ``left_ring`` (the kernel's figure counts them as ever deeper, the
instrument's does not compare them).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from clearbench.harness.measure.instrument.pair import pair_gaps, pair_resolution
from clearbench.harness.measure.instrument.placement import shape_placements

#: The search's budget of cells per state and pair when reading a run: a state where the
#: deepest points fill a curve (a part sunk through half a thin one, in a diverged run) then
#: reports the coarser resolution it reached instead of costing seconds; the C-60 demo runs'
#: states stay below it (at most about 1,250 on average over a run's states and pairs).
RUN_CELLS_PER_STATE = 5_000


@dataclass(frozen=True)
class RunPenetration:
    """The instrument's reading of a run, per recorded state and contact pair (T, npair).

    Attributes
    ----------
    names : tuple of str
        Contact pair names (``scene.expanded.contacts``).
    read : ndarray (T, npair) of bool
        The states read (the others have penetration and resolution NaN).
    penetration : ndarray (T, npair)
        Witnessed penetration max(0, offset - G) [L].
    resolution : ndarray (T, npair)
        The true penetration is at most ``penetration + resolution`` [L] (0 where the screen
        cleared the state).
    searched : ndarray (T, npair) of bool
        States the full search read (the others were cleared by the screen).
    left_ring : ndarray (T, npair) of bool
        Ring-around-journal pairs whose journal's axis has left the ring (not compared).
    encloses : ndarray (npair,) of bool
        Which pairs are rings around a journal.
    seconds : float
        Wall time of the reading [s].
    """

    names: tuple
    read: np.ndarray
    penetration: np.ndarray
    resolution: np.ndarray
    searched: np.ndarray
    left_ring: np.ndarray
    encloses: np.ndarray
    seconds: float


def _ring_and_journal(shape_a, shape_b):
    """(ring, journal, ring is A) for a circle/arc against a cylinder, else None."""
    if shape_a.kind in ("circle", "arc") and shape_b.kind == "cylinder":
        return shape_a, shape_b, True
    if shape_b.kind in ("circle", "arc") and shape_a.kind == "cylinder":
        return shape_b, shape_a, False
    return None


def axis_inside_ring(ring, ring_poses, journal, journal_poses) -> np.ndarray:
    """(T,) True where the journal's axis crosses the ring's plane inside the ring's circle
    (False where it is parallel to that plane). Poses: (positions (T, 3), quaternions (T, 4))
    of the two bodies."""
    ring_position, ring_rotation = shape_placements(ring, *ring_poses)
    axis_point, axis_rotation = shape_placements(journal, *journal_poses)
    normal = ring_rotation[:, :, 2]
    axis = axis_rotation[:, :, 2]
    along = np.sum(axis * normal, axis=1)
    parallel = np.abs(along) < 1e-12
    t = np.sum((ring_position - axis_point) * normal, axis=1) / np.where(parallel, 1.0, along)
    crossing = axis_point + t[:, None] * axis
    inside = np.linalg.norm(crossing - ring_position, axis=1) < ring.radius
    return inside & ~parallel


def _body_poses(trajectory, body: int, states=None):
    positions = trajectory.positions[:, body]
    orientations = trajectory.orientations[:, body]
    if states is not None:
        positions, orientations = positions[states], orientations[states]
    return positions, orientations


def run_penetration(scene, trajectory, read=None) -> RunPenetration:
    """The instrument's penetration of every contact pair at the recorded states.

    Parameters
    ----------
    scene : clearbench.scenarios.scene.Scene
        The scene the engine was given.
    trajectory : clearbench.adapters.trajectory.Trajectory
        The recorded run (body-frame positions (T, nb, 3) [L], quaternions (T, nb, 4)).
    read : ndarray (T, npair) of bool, optional
        The states to read per pair (default all).
    """
    start = time.perf_counter()
    expanded = scene.expanded
    index = {body.name: i for i, body in enumerate(expanded.bodies)}
    count, pairs = len(trajectory.times), len(expanded.contacts)
    read = (np.ones((count, pairs), dtype=bool) if read is None
            else np.asarray(read, dtype=bool).copy())
    penetration = np.full((count, pairs), np.nan)
    resolution = np.full((count, pairs), np.nan)
    searched = np.zeros((count, pairs), dtype=bool)
    left_ring = np.zeros((count, pairs), dtype=bool)
    encloses = np.zeros(pairs, dtype=bool)
    for k, contact in enumerate(expanded.contacts):
        a, b = index[contact.body_a], index[contact.body_b]
        body_a, body_b = expanded.bodies[a], expanded.bodies[b]
        shape_a, shape_b = body_a.shape(contact.shape_a), body_b.shape(contact.shape_b)
        poses_a, poses_b = _body_poses(trajectory, a), _body_poses(trajectory, b)
        ring = _ring_and_journal(shape_a, shape_b)
        if ring is not None:
            ring_shape, journal, ring_is_a = ring
            initial = ((np.array([body_a.position]), np.array([body_a.orientation])),
                       (np.array([body_b.position]), np.array([body_b.orientation])))
            ring_initial, journal_initial = initial if ring_is_a else initial[::-1]
            if axis_inside_ring(ring_shape, ring_initial, journal, journal_initial)[0]:
                encloses[k] = True
                ring_poses, journal_poses = (poses_a, poses_b) if ring_is_a else (poses_b,
                                                                                  poses_a)
                left_ring[:, k] = ~axis_inside_ring(ring_shape, ring_poses, journal,
                                                    journal_poses)
        states = np.nonzero(read[:, k])[0]
        if not len(states):
            continue
        reading = pair_gaps(shape_a, poses_a, shape_b, poses_b,
                            resolution=pair_resolution(shape_a, shape_b),
                            floor=np.full(count, contact.offset), states=states, polish=False,
                            cells_per_state=RUN_CELLS_PER_STATE)
        witnessed = np.maximum(0.0, contact.offset - reading.gap[states])
        bound = np.maximum(0.0, contact.offset - reading.lower[states])
        penetration[states, k] = witnessed
        resolution[states, k] = bound - witnessed
        searched[states, k] = np.isfinite(reading.gap[states])
    return RunPenetration(tuple(c.name for c in expanded.contacts), read, penetration,
                          resolution, searched, left_ring, encloses,
                          time.perf_counter() - start)
