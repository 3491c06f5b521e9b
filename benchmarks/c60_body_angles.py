"""Each C-60 body's angle about z [rad] and the largest body speed [mm/ms] along a trajectory.

Run: ``.venv/bin/python benchmarks/c60_body_angles.py TRAJECTORY.npz [STEP_MS]``

For a trajectory written by the reference engine (for example the cache of
``clearbench c60 validate``: ``.cache/c60/contact_force_test.npz``), prints every STEP_MS
(default 1 ms) the absolute angle of each moving body about z (the angle the source's angle
laws use, in (-pi, pi]) and the largest body speed. A diagnostic; asserts nothing.
"""

from __future__ import annotations

import sys

import numpy as np

from clearbench.adapters.trajectory import Trajectory
from clearbench.kernels.quaternion import quat_to_matrix
from clearbench.ref_solver.forces import twist_angle

Z = np.array([0.0, 0.0, 1.0])


def main(path: str, every: float) -> None:
    trajectory = Trajectory.load(path)
    names = trajectory.body_names
    print("t [ms]  " + "  ".join(f"{n[:12]:>12s}" for n in names) + "  max speed")
    for t in np.arange(trajectory.times[0], trajectory.times[-1] + 1e-12, every):
        k = min(int(np.searchsorted(trajectory.times, t)), len(trajectory.times) - 1)
        angles = []
        for q in trajectory.orientations[k]:
            angles.append(twist_angle(quat_to_matrix(q / np.linalg.norm(q)), Z))
        speed = np.abs(trajectory.velocities[k]).max()
        print(f"{trajectory.times[k]:6.2f}  " + "  ".join(f"{a:12.3f}" for a in angles)
              + f"  {speed:9.3g}")


if __name__ == "__main__":
    main(sys.argv[1], float(sys.argv[2]) if len(sys.argv) > 2 else 1.0)
