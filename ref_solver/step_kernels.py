"""Compiled pieces of one Moreau–Jean step: the free velocity, the velocity-stage rows and the
crossing fraction of an impact localised within a step.

Both do what ``MoreauJeanStepper._single_step`` (step 1) and ``_velocity_stage`` (the
assembly of the one-step problem) did in numpy, in one numba call each, so that a step of a
small mechanism does not pay tens of numpy calls from Python.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from clearbench.ref_solver.constraints import bilateral_rows, contact_rows, delassus, row_values
from clearbench.ref_solver.forces import applied_forces, rotation_matrices, spring_jacobians
from clearbench.ref_solver.gyroscopic import gyroscopic_update, integrate_orientations


@njit(cache=True)
def cluster_inverse(matrix, cluster_dofs, cluster_start, fixed):
    """Inverse of the block-diagonal (by clusters) iteration matrix (6 nb, 6 nb); a block that
    is all zero stays zero, and the rows and columns of fixed bodies are zero."""
    out = np.zeros_like(matrix)
    for c in range(cluster_start.shape[0] - 1):
        dofs = cluster_dofs[cluster_start[c]:cluster_start[c + 1]]
        n = dofs.shape[0]
        block = np.empty((n, n))
        nonzero = False
        for i in range(n):
            for j in range(n):
                block[i, j] = matrix[dofs[i], dofs[j]]
                nonzero = nonzero or block[i, j] != 0.0
        if not nonzero:
            continue
        inverse = np.linalg.inv(block)
        for i in range(n):
            for j in range(n):
                out[dofs[i], dofs[j]] = inverse[i, j]
    for b in range(fixed.shape[0]):
        if fixed[b]:
            out[6 * b:6 * b + 6, :] = 0.0
            out[:, 6 * b:6 * b + 6] = 0.0
    return out


@njit(cache=True)
def free_velocity(t_theta, h, theta, x, p, rotation, v, omega, mass, inertia, inverse_inertia,
                  gravity, fixed, force_kind, force_body_a, force_body_b, force_parameters,
                  angle_memory, has_springs, length_step, mass_matrix, inverse_mass,
                  cluster_dofs, cluster_start):
    """Step 1 of the scheme: (free twist (nb, 6), the inverse iteration matrix (6 nb, 6 nb),
    gyroscopic iterations).

    Forces at t_theta; with springs, W = M - h theta C - h^2 theta^2 K and the right-hand side
    h F + h^2 theta K nu; the gyroscopic update replaces the torque-free change of omega.
    """
    nb = x.shape[0]
    nu = np.empty(6 * nb)
    for b in range(nb):
        for i in range(3):
            nu[6 * b + i] = v[b, i]
            nu[6 * b + 3 + i] = omega[b, i]
    forces = applied_forces(t_theta, x, rotation, v, omega, mass, gravity, fixed, force_kind,
                            force_body_a, force_body_b, force_parameters, angle_memory)
    rhs = h * forces.ravel()
    inverse = inverse_mass
    if has_springs:
        stiffness, damping = spring_jacobians(t_theta, x, p, v, omega, fixed, force_kind,
                                              force_body_a, force_body_b, force_parameters,
                                              angle_memory, length_step)
        iteration = mass_matrix - h * theta * damping - h * h * theta * theta * stiffness
        rhs = rhs + h * h * theta * (stiffness @ nu)
        inverse = cluster_inverse(iteration, cluster_dofs, cluster_start, fixed)
    free = (nu + inverse @ rhs).reshape(nb, 6)
    omega_gyro, gyro_iterations = gyroscopic_update(omega, inertia, inverse_inertia, fixed, h,
                                                    theta)
    for b in range(nb):
        for i in range(3):
            free[b, 3 + i] += omega_gyro[b, i] - omega[b, i]
    return free, inverse, gyro_iterations


@njit(cache=True)
def velocity_problem(arrays, n_bilateral, n_joint_rows, t1, h, theta, x, p, v, omega,
                     rotation, point_a, point_b, frame, pairs, slots, nu, free, inverse,
                     cluster, cluster_dofs, cluster_start, restitution, threshold,
                     midpoint_joints):
    """The one-step problem of the velocity stage: (W (m, m), Y (6 nb, m), q (m,), row_body,
    row_coef, u_k (nc,) normal velocities at the start, impacting (nc,) bool).

    Joint rows at the predicted configuration q_k + theta h v_k, contact rows at q_k for the
    selected (pairs, slots); q = H free - target, with the mid-step joint law
    (``midpoint_joints``, off in a step with an impact) and Newton's law e u_k on the normal
    rows of the contacts approaching faster than ``threshold``.
    """
    nc = pairs.shape[0]
    m = n_bilateral + 3 * nc
    row_body = np.full((m, 2), -1, dtype=np.int64)
    row_coef = np.zeros((m, 2, 6))
    violation = np.zeros(m)
    target = np.zeros(m)
    fixed = arrays[0]
    if n_bilateral:
        x_mid = x + theta * h * v
        p_mid = integrate_orientations(p, theta * h * omega, fixed)
        bilateral_rows(t1, x_mid, p_mid, rotation_matrices(p_mid), fixed, arrays[9],
                       arrays[10], arrays[11], arrays[12], arrays[13], arrays[14], arrays[15],
                       arrays[16], arrays[17], arrays[18], arrays[19], arrays[20], arrays[21],
                       arrays[22], arrays[23], arrays[24], row_body, row_coef, violation,
                       target)
    if nc:
        contact_rows(x, rotation, fixed, arrays[3], arrays[6], arrays[7], pairs, slots,
                     point_a, point_b, frame, row_body, row_coef, n_bilateral)
    w, y = delassus(row_body, row_coef, m, inverse, cluster, cluster_dofs, cluster_start)
    q = row_values(row_body, row_coef, free, 0, m) - target
    u_k = np.zeros(nc)
    impacting = np.zeros(nc, dtype=np.bool_)
    any_impact = False
    if nc:
        u_k = row_values(row_body, row_coef, nu, n_bilateral, m)[0::3].copy()
        for c in range(nc):
            impacting[c] = u_k[c] < -threshold
            any_impact = any_impact or impacting[c]
    if n_joint_rows and midpoint_joints and not any_impact:
        joint = row_values(row_body, row_coef, nu, 0, n_joint_rows)
        for i in range(n_joint_rows):
            q[i] += (1.0 - theta) / theta * joint[i]
    for c in range(nc):
        if impacting[c]:
            q[n_bilateral + 3 * c] += restitution[pairs[c]] * u_k[c]
    return w, y, q, row_body, row_coef, u_k, impacting


@njit(cache=True)
def crossing_fraction(gap_start, gap_rate, gap_end):
    """Fraction s in (0, 1] of a step at which a contact's gap reaches zero.

    The gap over the step is taken as the quadratic g(s) = g0 + b s + c s^2 through the gap at
    the start g0 = ``gap_start`` > 0 [L], its rate b = ``gap_rate`` = h u_N,k [L] (normal
    velocity times the step) and the gap at the end of the step's free motion g1 =
    ``gap_end`` <= 0 [L] (the caller checks both signs): exact for ballistic flight (constant
    acceleration), where the theta = 1/2 position update is exact. Returns the smallest root in
    (0, 1] (there is exactly one, since g(0) > 0 >= g(1)); where round-off put it just outside,
    the quadratic is bisected.
    """
    g0, b, g1 = gap_start, gap_rate, gap_end
    c = g1 - g0 - b
    best = math.inf
    if c == 0.0:
        if b != 0.0:
            root = -g0 / b
            if 0.0 < root <= 1.0:
                best = root
    else:
        q = -0.5 * (b + math.copysign(math.sqrt(max(b * b - 4.0 * c * g0, 0.0)), b))
        root = q / c
        if 0.0 < root <= 1.0:
            best = root
        if q != 0.0:
            root = g0 / q
            if 0.0 < root <= 1.0:
                best = min(best, root)
    if best < math.inf:
        return best
    low, high = 0.0, 1.0
    for _ in range(80):
        middle = 0.5 * (low + high)
        if g0 + middle * (b + c * middle) > 0.0:
            low = middle
        else:
            high = middle
    return high
