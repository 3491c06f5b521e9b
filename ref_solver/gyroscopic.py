"""Momentum-conserving treatment of the gyroscopic term.

With body-axes angular velocity and the Lie-group update p_{k+1} = p_k exp(h Omega_theta),
Omega_theta = theta Omega_{k+1} + (1 - theta) Omega_k, the world angular momentum
L = R J Omega of a torque-free body is conserved exactly when

    J Omega_{k+1} = exp(-h Omega_theta)^ (J Omega_k),

i.e. the body-axes momentum is rotated back by the same increment that rotates the body. This
implicit relation is solved by fixed-point iteration (a contraction for h |Omega| < 1); the
result replaces the explicit gyroscopic torque J Omega x Omega of the theta-scheme.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from clearbench.kernels.quaternion import quat_exp, quat_integrate, quat_rotate
from clearbench.ref_solver.linalg3 import mat_vec


@njit(cache=True)
def gyroscopic_update(omega, inertia, inverse_inertia, fixed, h, theta, tolerance=1e-15,
                      max_iterations=50):
    """Torque-free angular velocities at the end of the step, (nb, 3) body axes.

    Returns the new angular velocities and the largest number of iterations used.
    """
    nb = omega.shape[0]
    out = omega.copy()
    worst = 0
    for b in range(nb):
        if fixed[b]:
            continue
        momentum = mat_vec(inertia[b], omega[b])
        current = omega[b].copy()
        scale = max(np.sqrt(np.sum(omega[b] ** 2)), 1e-300)
        for iteration in range(max_iterations):
            mid = theta * current + (1.0 - theta) * omega[b]
            rotated = quat_rotate(quat_exp(-h * mid), momentum)
            updated = mat_vec(inverse_inertia[b], rotated)
            change = np.sqrt(np.sum((updated - current) ** 2))
            current = updated
            if change <= tolerance * scale:
                worst = max(worst, iteration + 1)
                break
        else:
            worst = max_iterations
        out[b] = current
    return out, worst


@njit(cache=True)
def integrate_orientations(p, rotation_vectors, fixed):
    """p_b * exp(rotation_vectors_b) for every body that is not fixed, (nb, 4)."""
    out = p.copy()
    for b in range(p.shape[0]):
        if not fixed[b]:
            out[b] = quat_integrate(p[b], rotation_vectors[b])
    return out
