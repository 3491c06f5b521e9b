"""Recorded runs as the viewer's frames: every run sampled on one time grid, poses and contact
forces quantised to 16 bits, delta-encoded over time and gzip-compressed, so that a page with
several engines stays small.

Layout of one run's block (little-endian int16, gzip, then base64)::

    poses     F x nb x 7   position (3) then quaternion w,x,y,z (4) of each body, each frame;
                           positions as round((p - centre) / position_step), quaternions as
                           round(q * 32767); stored as differences from the previous frame
                           (the first frame as is; the browser adds them up, wrapping at 16
                           bits as numpy does)
    counts    F            the number of contacts drawn in each frame
    contacts  n x 7        pair index, point (3) and force (3) of each contact drawn, frame
                           after frame: points as positions, forces as
                           round(f / force_max * 32767)

``position_step`` = the half-size of the box around every drawn point / 32000 (0.8 um for the
C-60's 50 mm), quaternions 3e-5, forces force_max / 32767: far below what a screen shows.
A pose beyond the box (a run that flew off) is clamped to it and the run says so.
"""

from __future__ import annotations

import base64
import gzip
import math
from dataclasses import dataclass, field

import numpy as np

from clearbench.adapters.trajectory import Trajectory
from clearbench.scenarios.geometry import (
    MAX_CONTACTS_PER_PAIR,
    pack_shape_parameters,
    pair_contacts,
    shape_code,
    shape_world_placements,
)
from clearbench.scenarios.scene import Scene

#: Largest int16 used for quantised values (a margin below 32767 keeps clamped values apart).
QUANT = 32000
#: A contact is drawn in a frame when its normal force exceeds this fraction of the largest
#: normal force of the run (1e-4: a 15 N mechanism shows its 1.5 mN contacts, not round-off).
FORCE_FRACTION = 1e-4
#: The box poses are quantised in reaches this many scene sizes around the scene's centre.
BOX_SIZES = 1.5


@dataclass(frozen=True)
class RecordedRun:
    """One run to show: ``label`` (engine[preset] and step), its trajectory, its status,
    and its events (name -> time [T], NaN when it did not happen)."""

    label: str
    trajectory: Trajectory
    status: str = "ok"
    message: str = ""
    events: dict = field(default_factory=dict)


def time_grid(runs: list[RecordedRun], frames: int, events: list[float] = ()) -> np.ndarray:
    """``frames`` evenly spaced times from 0 to the longest run's end, the event times added
    (each event a frame of its own, so the snapshots show the pose at the event) [T]."""
    ends = [float(r.trajectory.times[-1]) for r in runs if len(r.trajectory.times)]
    end = max(ends, default=0.0)
    start = min((float(r.trajectory.times[0]) for r in runs if len(r.trajectory.times)),
                default=0.0)
    grid = np.linspace(start, end, max(2, frames))
    extra = [t for t in events if math.isfinite(t) and start <= t <= end]
    return np.unique(np.concatenate([grid, np.asarray(extra, dtype=float)]))


def sample_indices(times: np.ndarray, grid: np.ndarray) -> np.ndarray:
    """Per grid time, the last recorded sample at or before it (the first sample before
    the run's start), (F,) int."""
    index = np.searchsorted(times, grid + 1e-12 * max(1.0, abs(grid[-1])), side="right") - 1
    return np.clip(index, 0, len(times) - 1)


@dataclass(frozen=True)
class Quantiser:
    """The box every drawn point is quantised in: ``centre`` (3,) and ``step`` [L]."""

    centre: np.ndarray
    step: float

    @classmethod
    def around(cls, centre, size: float) -> Quantiser:
        return cls(np.asarray(centre, dtype=float), BOX_SIZES * size / QUANT)

    def positions(self, points: np.ndarray) -> tuple[np.ndarray, bool]:
        """Points (..., 3) [L] as int16, and whether any was clamped to the box."""
        scaled = np.round((points - self.centre) / self.step)
        finite = np.where(np.isfinite(scaled), scaled, 0.0)
        clamped = bool(np.any(np.abs(finite) > QUANT) or not np.all(np.isfinite(scaled)))
        return np.clip(finite, -QUANT, QUANT).astype(np.int16), clamped


def _quaternions(q: np.ndarray) -> np.ndarray:
    norm = np.linalg.norm(q, axis=-1, keepdims=True)
    unit = np.where(norm > 0, q / np.where(norm > 0, norm, 1.0), [1.0, 0.0, 0.0, 0.0])
    unit = np.where(np.isfinite(unit), unit, [1.0, 0.0, 0.0, 0.0])
    return np.round(unit * 32767).astype(np.int16)


def _pair_shapes(scene: Scene, trajectory: Trajectory) -> list:
    """Per contact column of the trajectory: (body index A, shape A, body index B, shape B)
    or None where the scene has no such pair."""
    expanded = scene.expanded
    index = {b.name: i for i, b in enumerate(expanded.bodies)}
    by_name = {c.name: c for c in expanded.contacts}
    out = []
    for name in trajectory.contact_names:
        contact = by_name.get(name)
        if contact is None:
            out.append(None)
            continue
        a, b = index[contact.body_a], index[contact.body_b]
        out.append((a, expanded.bodies[a].shape(contact.shape_a),
                    b, expanded.bodies[b].shape(contact.shape_b)))
    return out


@dataclass(frozen=True)
class DrawnContacts:
    """The contacts drawn, n of them, ordered by frame then pair: ``frame`` (n,) index into
    the time grid, ``pair`` (n,) contact column, ``point`` (n, 3) [L], ``force`` (n, 3) on
    body B [F]."""

    frame: np.ndarray
    pair: np.ndarray
    point: np.ndarray
    force: np.ndarray


NO_CONTACTS = DrawnContacts(np.zeros(0, int), np.zeros(0, int), np.zeros((0, 3)),
                            np.zeros((0, 3)))


def contact_frames(scene: Scene, trajectory: Trajectory, samples: np.ndarray) -> DrawnContacts:
    """In each frame (recorded sample index in ``samples``), the contacts that carry force.
    The point is the middle of the pair's closest candidate (the scene's own geometry, the
    kernel of :func:`~clearbench.scenarios.geometry.contacts_between`, placements computed for
    every frame of a pair at once); the force the engine's, or its normal force along that
    candidate's normal where the engine gives no vector."""
    none = NO_CONTACTS
    normal = trajectory.contact_normal_force
    if normal.size == 0:
        return none
    finite = np.where(np.isfinite(normal), normal, 0.0)[samples]          # (F, np)
    largest = float(np.max(np.abs(finite))) if finite.size else 0.0
    if largest <= 0.0:
        return none
    loaded = finite > FORCE_FRACTION * largest
    gap = np.empty(MAX_CONTACTS_PER_PAIR)
    point_a = np.empty((MAX_CONTACTS_PER_PAIR, 3))
    point_b = np.empty((MAX_CONTACTS_PER_PAIR, 3))
    frame = np.empty((MAX_CONTACTS_PER_PAIR, 3, 3))
    frames, pairs, points, normals = [], [], [], []
    for column, pair in enumerate(_pair_shapes(scene, trajectory)):
        where = np.nonzero(loaded[:, column])[0]
        if pair is None or not where.size:
            continue
        a, shape_a, b, shape_b = pair
        k = samples[where]
        poses = [(trajectory.positions[k, i], trajectory.orientations[k, i]) for i in (a, b)]
        usable = (np.all(np.isfinite(poses[0][0]), axis=1)
                  & np.all(np.isfinite(poses[1][0]), axis=1)).tolist()
        position_a, rotation_a = shape_world_placements(shape_a, *poses[0])
        position_b, rotation_b = shape_world_placements(shape_b, *poses[1])
        code_a, code_b = shape_code(shape_a), shape_code(shape_b)
        params_a, params_b = pack_shape_parameters(shape_a), pack_shape_parameters(shape_b)
        for j, f in enumerate(where.tolist()):
            if not usable[j]:
                continue
            count = pair_contacts(code_a, params_a, position_a[j], rotation_a[j], code_b,
                                  params_b, position_b[j], rotation_b[j], gap, point_a,
                                  point_b, frame)
            if count:
                best = int(np.argmin(gap[:count]))
                frames.append(f)
                pairs.append(column)
                points.append(0.5 * (point_a[best] + point_b[best]))
                normals.append(frame[best, 0].copy())
    if not frames:
        return none
    frame_index, pair_index = np.array(frames), np.array(pairs)
    force = np.asarray(trajectory.contact_force[samples[frame_index], pair_index], dtype=float)
    given = np.any(force != 0, axis=1) & np.all(np.isfinite(force), axis=1)
    force = np.where(given[:, None], force,
                     finite[frame_index, pair_index][:, None] * np.array(normals))
    order = np.lexsort((pair_index, frame_index))
    return DrawnContacts(frame_index[order], pair_index[order], np.array(points)[order],
                         force[order])


def _encode(arrays: list[np.ndarray]) -> str:
    raw = b"".join(np.ascontiguousarray(a, dtype="<i2").tobytes() for a in arrays)
    return base64.b64encode(gzip.compress(raw, compresslevel=9, mtime=0)).decode("ascii")


def encode_run(scene: Scene, run: RecordedRun, grid: np.ndarray, quantiser: Quantiser,
               force_max: float, contacts: bool = True) -> dict:
    """One run's block (module docstring) and what the page says about it: label, status,
    message, events, the time its recording ends [T] and whether a pose left the box."""
    trajectory = run.trajectory
    samples = sample_indices(trajectory.times, grid)
    positions, clamped = quantiser.positions(trajectory.positions[samples])
    poses = np.concatenate([positions, _quaternions(trajectory.orientations[samples])],
                           axis=-1)                                  # (F, nb, 7) int16
    deltas = poses.copy()
    deltas[1:] = poses[1:] - poses[:-1]                              # wraps like int16 adds
    drawn = contact_frames(scene, trajectory, samples) if contacts else NO_CONTACTS
    counts = np.bincount(drawn.frame, minlength=len(grid)).astype(np.int16)
    table = np.column_stack([drawn.pair, quantiser.positions(drawn.point)[0],
                             _forces(drawn.force, force_max)]).astype(np.int16).reshape(-1, 7)
    end = float(trajectory.times[-1]) if len(trajectory.times) else 0.0
    return {"label": run.label, "status": run.status, "message": run.message,
            "events": {k: (float(v) if math.isfinite(v) else None)
                       for k, v in run.events.items()},
            "ends": end, "clamped": clamped, "contacts": int(len(table)),
            "data": _encode([deltas, counts, table])}


def _forces(forces: np.ndarray, force_max: float) -> np.ndarray:
    """Forces (n, 3) [F] as int16 of ``force_max`` / 32767, each longer than ``force_max``
    shortened to it (same direction)."""
    magnitude = np.linalg.norm(forces, axis=1, keepdims=True)
    scale = np.where(magnitude > force_max, force_max / np.where(magnitude > 0, magnitude, 1.0),
                     1.0)
    return np.round(forces * scale / force_max * 32767).astype(np.int16).reshape(-1, 3)


#: The arrows' scale is this percentile of the finished runs' normal forces: an impact's
#: peak (single samples 10-100 times the static forces) does not shrink every other arrow.
FORCE_PERCENTILE = 99.0
#: Forces are quantised up to this many times the arrows' scale (longer ones shortened).
FORCE_RANGE = 8.0


def force_scale(runs: list[RecordedRun]) -> float:
    """The arrows' force scale [F]: :data:`FORCE_PERCENTILE` of the positive normal forces
    of the finished runs (of every run when none finished); 1 when none carries force."""
    for chosen in ([r for r in runs if r.status == "ok"], runs):
        values = [r.trajectory.contact_normal_force[r.trajectory.contact_normal_force > 0]
                  for r in chosen if r.trajectory.contact_normal_force.size]
        values = [v[np.isfinite(v)] for v in values]
        if values and sum(v.size for v in values):
            scale = float(np.percentile(np.concatenate(values), FORCE_PERCENTILE))
            if scale > 0:
                return scale
    return 1.0
