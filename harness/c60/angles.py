"""Each body's absolute angle about z and the largest body speed along a C-60 trajectory
(``clearbench c60 angles``): a diagnostic of a run, for example one that
``clearbench c60 validate`` kept in the results store (``reports/store/trajectories/KEY.npz``).

The angle is the one the source's angle laws use, in (-pi, pi]: a body turning through the cut
(pi) shows as a jump here, while the laws keep it continuous.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from clearbench.adapters.trajectory import Trajectory
from clearbench.kernels.quaternion import quat_to_matrix
from clearbench.ref_solver.forces import twist_angle

#: The axis the C-60's bodies turn about.
Z_AXIS = np.array([0.0, 0.0, 1.0])


@dataclass(frozen=True)
class AngleSample:
    """One sample: its time [ms], each body's angle about z [rad] in the trajectory's body
    order, and the largest velocity component of any body [mm/ms]."""

    time: float
    angles: tuple
    max_speed: float


def body_angles(trajectory: Trajectory, every: float = 1.0) -> list[AngleSample]:
    """The sample at or just after every ``every`` [ms] from the first sample to the last."""
    samples = []
    for t in np.arange(trajectory.times[0], trajectory.times[-1] + 1e-12, every):
        k = min(int(np.searchsorted(trajectory.times, t)), len(trajectory.times) - 1)
        angles = tuple(twist_angle(quat_to_matrix(q / np.linalg.norm(q)), Z_AXIS)
                       for q in trajectory.orientations[k])
        samples.append(AngleSample(float(trajectory.times[k]), angles,
                                   float(np.abs(trajectory.velocities[k]).max())))
    return samples
