"""The run-wide geometry check: the kernel's penetration beside the independent instrument's.

The harness's penetration figures (:func:`.series.penetration`, the clearance excess of
:func:`.series.clearance_motion`) use the gap kernel the reference solver steps with; a blind
spot of the kernel (a ring crossing a bounded face's edge) is then a blind spot of the figure
too. This check reads every recorded state a second way with the instrument
(:mod:`.instrument`, which shares no code with the kernel) and compares, per state and contact
pair, the two penetrations, each max(0, offset - gap) as the kernel's figure takes the offset.

The rule ("unseen penetration")
-------------------------------
At a state where the instrument witnesses a penetration deeper than the kernel's figure by
more than the allowance = (the instrument's certified resolution at that state and pair) +
(a round-off allowance of :data:`ROUND_OFF_FRACTION` of the scene's size), the kernel missed a
penetration that a real point of one shape makes in the other's solid: the run's verdict is
"unseen penetration", naming the pair, the time and both figures, whatever the engine (ours
included). The instrument's witness is a real point, so the flag cannot be a sampling
artefact; a kernel figure deeper than the instrument's is not flagged (the kernel may model a
face as the half-space under it, or a journal as infinitely long: it overstates, it does not
hide). States where a journal has left its bearing ring (:mod:`.instrument.run_figures`) are
not compared.

The agreement figure (both directions, for the docs and ``clearbench check-geometry``): the
largest |instrument - kernel| over the compared states, and whether it is within the
allowance everywhere.

Which states (the cost)
-----------------------
Each pair is read at every ``stride``-th recorded state (and the last, and the state where
the kernel's figure of that pair is largest, so that the two maxima compare), then every pair at
every state within a stride of a state where an unseen penetration was found, so that a
flagged interval's first and last states are exact and a pair flagged only between two
strided states beside it is found too. The run-wide check of every run (:mod:`.figures`) takes the
stride that reads about :data:`STATES_PER_PAIR` states per pair: an unseen penetration lasting
at least a stride of recorded states is found wherever it is; ``clearbench check-geometry``
reads every state (stride 1) unless told otherwise.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from clearbench.harness.measure import series
from clearbench.harness.measure.instrument.run_figures import RunPenetration, run_penetration
from clearbench.scenarios.scales import scene_size

#: Round-off allowance of the comparison, as a fraction of the scene's size
#: (:func:`~clearbench.scenarios.scales.scene_size`): both figures are float64 functions of
#: positions of that magnitude through a few hundred operations (1e-13 of it at most); this
#: is a thousand times that and a million times below the penetrations the check is for
#: (a C-60 scene of about 60 mm: 6e-8 mm against a 19 um blind spot).
ROUND_OFF_FRACTION = 1e-9
#: The verdict of a run with an unseen penetration (a key of
#: :data:`~clearbench.harness.measure.verdicts.VERDICTS`).
UNSEEN_PENETRATION = "unseen penetration"
#: Name of the run figure that carries the rule: the largest excess of the instrument's
#: penetration over the kernel's beyond the allowance [L] (0: none).
UNSEEN_FIGURE = "unseen_penetration"
#: States per pair the run-wide check of every run reads at its stride: the C-60 demo runs'
#: 400-1,060 samples are read at strides 2-5 (the old kernel's blind spot in c60-trip lasts
#: 74 samples), the library scenes' shorter runs whole.
STATES_PER_PAIR = 250


def default_stride(states: int) -> int:
    """The stride that reads about :data:`STATES_PER_PAIR` of ``states`` recorded states."""
    return max(1, -(-states // STATES_PER_PAIR))


@dataclass(frozen=True)
class GeometryCheck:
    """Both penetrations of a run, per recorded state and contact pair (T, npair) [L].

    ``kernel``: the harness's figure (:func:`.series.penetration`); ``instrument``: the
    instrument's reading (NaN at the states it did not read); ``allowance``: its resolution
    plus the round-off allowance; ``compared``: the states read and compared (not those
    where a journal left its ring); ``times`` (T,) [T]; ``stride``: of the first reading.
    """

    names: tuple
    times: np.ndarray
    kernel: np.ndarray
    instrument: RunPenetration
    allowance: np.ndarray
    compared: np.ndarray
    round_off: float
    stride: int = 1

    @property
    def difference(self) -> np.ndarray:
        """Instrument minus kernel penetration, 0 where not compared (T, npair) [L]."""
        return np.where(self.compared, np.nan_to_num(self.instrument.penetration) - self.kernel,
                        0.0)

    @property
    def unseen(self) -> np.ndarray:
        """How far the instrument's penetration exceeds the kernel's beyond the allowance,
        (T, npair) [L] (0 where it does not)."""
        return np.maximum(0.0, self.difference - np.nan_to_num(self.allowance))

    @property
    def unseen_max(self) -> float:
        return float(self.unseen.max()) if self.unseen.size else 0.0

    @property
    def agreement_max(self) -> float:
        """Largest |instrument - kernel| over the compared states [L]."""
        return float(np.abs(self.difference).max()) if self.difference.size else 0.0

    @property
    def agrees(self) -> bool:
        """Both figures within the allowance of each other at every compared state."""
        return bool(np.all(np.abs(self.difference) <= np.nan_to_num(self.allowance, nan=0.0)))

    def worst(self) -> tuple[int, int]:
        """(state, pair) of the largest unseen excess, or of the largest |difference| when
        none is unseen."""
        values = self.unseen if self.unseen_max > 0.0 else np.abs(self.difference)
        state, pair = np.unravel_index(int(np.argmax(values)), values.shape)
        return int(state), int(pair)

    def unseen_intervals(self) -> dict[str, tuple[float, float, int]]:
        """Per pair with an unseen penetration: (first time, last time, states) [T]."""
        out = {}
        flagged = self.unseen > 0.0
        for k, name in enumerate(self.names):
            states = np.nonzero(flagged[:, k])[0]
            if len(states):
                out[name] = (float(self.times[states[0]]), float(self.times[states[-1]]),
                             int(len(states)))
        return out

    def message(self, length: str = "", time: str = "") -> str:
        """The verdict's reason: the worst pair, its time, both figures and the allowance."""
        if self.unseen_max <= 0.0:
            return ""
        state, pair = self.worst()
        first, last, count = self.unseen_intervals()[self.names[pair]]
        others = len(self.unseen_intervals()) - 1
        unit, clock = f" {length}" if length else "", f" {time}" if time else ""
        return (f"{UNSEEN_PENETRATION}: {self.names[pair]} at t = {self.times[state]:.6g}{clock}"
                f": the instrument witnesses {self.instrument.penetration[state, pair]:.3g}"
                f"{unit}, the kernel's figure is {self.kernel[state, pair] + 0.0:.3g}{unit} "
                f"(allowance {self.allowance[state, pair]:.2g}{unit}); unseen at {count} "
                f"recorded states from t = {first:.6g} to {last:.6g}{clock}"
                + (f", and in {others} other pair(s)" if others > 0 else ""))


def check(scene, trajectory, kernel_penetration: np.ndarray | None = None,
          stride: int | None = None) -> GeometryCheck:
    """Compare the kernel's penetration of a run with the instrument's.

    Parameters
    ----------
    scene : Scene
        The scene the engine was given.
    trajectory : Trajectory
        The recorded run.
    kernel_penetration : ndarray (T, npair), optional
        The kernel's figure to compare [L] (default :func:`.series.penetration` of this
        revision's kernel; a stored run of another revision brings its own).
    stride : int, optional
        Read every ``stride``-th state first (default :func:`default_stride`; 1: all).
    """
    kernel = (series.penetration(scene, trajectory) if kernel_penetration is None
              else np.asarray(kernel_penetration, dtype=float))
    count, pairs = len(trajectory.times), len(scene.expanded.contacts)
    if kernel.shape != (count, pairs):
        raise ValueError(f"kernel penetration has shape {kernel.shape}; the scene's pairs and "
                         f"the run's states make {(count, pairs)}")
    stride = default_stride(count) if stride is None else int(stride)
    if stride < 1:
        raise ValueError(f"stride = {stride}: must be at least 1")
    first = np.zeros((count, pairs), dtype=bool)
    first[::stride] = True
    first[-1:] = True
    # And each pair's deepest state by the kernel's figure, so that the two maxima compare.
    if count:
        first[np.argmax(kernel, axis=0), np.arange(pairs)] = True
    round_off = ROUND_OFF_FRACTION * scene_size(scene)
    reading = run_penetration(scene, trajectory, first)
    result = _result(scene, trajectory, kernel, reading, round_off, stride)
    flagged = (result.unseen > 0.0).any(axis=1)
    if stride > 1 and flagged.any():
        # Every pair at every state within a stride of a flagged one (in any pair), to find
        # the intervals' ends and what happens beside them.
        near = np.zeros(count, dtype=bool)
        for shift in range(-stride + 1, stride):
            near |= np.roll(flagged, shift) & _shift_valid(count, shift)
        more = near[:, None] & ~first
        if more.any():
            extra = run_penetration(scene, trajectory, more)
            reading = _merged(reading, extra)
            result = _result(scene, trajectory, kernel, reading, round_off, stride)
    return result


def _shift_valid(count: int, shift: int) -> np.ndarray:
    """(count,) True where np.roll by ``shift`` did not wrap around."""
    valid = np.ones(count, dtype=bool)
    if shift > 0:
        valid[:shift] = False
    elif shift < 0:
        valid[shift:] = False
    return valid


def _merged(first: RunPenetration, extra: RunPenetration) -> RunPenetration:
    """Two readings of disjoint states as one."""
    taken = extra.read
    return RunPenetration(
        first.names, first.read | taken,
        np.where(taken, extra.penetration, first.penetration),
        np.where(taken, extra.resolution, first.resolution),
        np.where(taken, extra.searched, first.searched),
        first.left_ring, first.encloses, first.seconds + extra.seconds)


def _result(scene, trajectory, kernel, reading: RunPenetration, round_off: float,
            stride: int) -> GeometryCheck:
    return GeometryCheck(reading.names, np.asarray(trajectory.times, dtype=float), kernel,
                         reading, reading.resolution + round_off,
                         reading.read & ~reading.left_ring, round_off, stride)


def clearance_excess(scene, result: GeometryCheck) -> tuple[np.ndarray, np.ndarray]:
    """Per clearance joint, the instrument's and the kernel's excess of the journal's
    eccentricity over the radial clearance, (T, nj) each [L]: the largest penetration of the
    joint's two bearing rings (the ring pairs are offset by nothing: a ring's penetration into
    its journal is the eccentricity beyond the clearance, :func:`.series.clearance_motion`)."""
    columns = [[result.names.index(f"{joint.name}.ring_{side}") for side in ("bottom", "top")]
               for joint in scene.clearance_joints]
    count = len(result.times)
    instrument = np.zeros((count, len(columns)))
    kernel = np.zeros((count, len(columns)))
    for j, pair in enumerate(columns):
        instrument[:, j] = np.max(np.where(result.compared[:, pair],
                                           result.instrument.penetration[:, pair], 0.0), axis=1)
        kernel[:, j] = np.max(result.kernel[:, pair], axis=1)
    return instrument, kernel
