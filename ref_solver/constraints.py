"""Constraint rows of the reference solver: ideal joints, drivers and contacts.

A row is a linear form on the twists of at most two bodies:
``u = coef_a . nu_a + coef_b . nu_b`` with nu = (v world (3), omega body (3)); ``body = -1``
marks an unused side (and rows never reference fixed bodies, whose twist is zero). For a world
direction d at a point p = x + R s of a body, the point-velocity row is (d, s x R^T d).

Position-level values of the same rows (joint violations, contact gaps) are returned next to the
rows so that the projection stage uses Jacobians consistent with them.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from clearbench.kernels.quaternion import quat_conjugate, quat_multiply
from clearbench.kernels.time_profiles import profile_integral, profile_slope, profile_value
from clearbench.ref_solver.linalg3 import cross, dot, mat_mat, mat_t_vec, mat_vec
from clearbench.ref_solver.system import JOINT_FIXED, JOINT_PRISMATIC, JOINT_REVOLUTE, JOINT_ROWS
from clearbench.scenarios.geometry import MAX_CONTACTS_PER_PAIR, pair_contacts


@njit(cache=True, inline="always")
def _point_row(coef, rotation, local, direction, sign):
    """Write sign * (d, s x R^T d) into coef (6,)."""
    angular = cross(local, mat_t_vec(rotation, direction))
    for i in range(3):
        coef[i] = sign * direction[i]
        coef[3 + i] = sign * angular[i]


@njit(cache=True, inline="always")
def _angular_row(coef, rotation, direction, sign):
    """Write sign * (0, R^T d): the world angular velocity component along d."""
    angular = mat_t_vec(rotation, direction)
    for i in range(3):
        coef[i] = 0.0
        coef[3 + i] = sign * angular[i]


@njit(cache=True)
def bilateral_rows(t, x, p, rotation, fixed, joint_kind, joint_a, joint_b, anchor_a, anchor_b,
                   frame_a, axis_b, relative0, driver_body, driver_component, driver_quantity,
                   driver_start, driver_times, driver_values, driver_initial,
                   driver_reference, row_body, row_coef, violation, velocity_target):
    """Fill the bilateral rows of joints then drivers.

    Parameters
    ----------
    row_body : (m, 2) int, out
    row_coef : (m, 2, 6), out
    violation : (m,), out
        Position-level residual of each row. For rotation drivers: the rotation about the world
        axis since t = 0 (twist of p p0^-1) minus the prescribed angle, wrapped to (-pi, pi].
    velocity_target : (m,), out
        Required value of the row at the end of the step (non-zero for drivers only).
    """
    row = 0
    for j in range(joint_kind.shape[0]):
        a = joint_a[j]
        b = joint_b[j]
        kind = joint_kind[j]
        ra = rotation[a]
        rb = rotation[b]
        pa = x[a] + mat_vec(ra, anchor_a[j])
        pb = x[b] + mat_vec(rb, anchor_b[j])
        side_a = -1 if fixed[a] else a
        side_b = -1 if fixed[b] else b
        frame_world = mat_mat(ra, frame_a[j])
        n_rows = JOINT_ROWS[kind]
        for r in range(n_rows):
            row_body[row + r, 0] = side_a
            row_body[row + r, 1] = side_b
            velocity_target[row + r] = 0.0
        if kind == JOINT_PRISMATIC or kind == JOINT_FIXED:
            # Relative rotation error in world axes: q_e = p_B q0^-1 p_A^-1 (small angle).
            q_e = quat_multiply(quat_multiply(p[b], quat_conjugate(relative0[j])),
                                quat_conjugate(p[a]))
            sign = 1.0 if q_e[0] >= 0.0 else -1.0
            first = 0 if kind == JOINT_PRISMATIC else 3
            for r in range(3):
                e_r = np.zeros(3)
                e_r[r] = 1.0
                _angular_row(row_coef[row + first + r, 0], ra, e_r, -1.0)
                _angular_row(row_coef[row + first + r, 1], rb, e_r, 1.0)
                violation[row + first + r] = 2.0 * sign * q_e[1 + r]
        if kind != JOINT_PRISMATIC:
            for r in range(3):
                e_r = np.zeros(3)
                e_r[r] = 1.0
                _point_row(row_coef[row + r, 0], ra, anchor_a[j], e_r, -1.0)
                _point_row(row_coef[row + r, 1], rb, anchor_b[j], e_r, 1.0)
                violation[row + r] = pb[r] - pa[r]
        if kind == JOINT_REVOLUTE:
            a_b = mat_vec(rb, axis_b[j])
            for r in range(2):
                t_r = frame_world[:, 1 + r].copy()
                # d/dt (t_r . a_B) = (omega_B - omega_A) . (a_B x t_r)
                direction = cross(a_b, t_r)
                _angular_row(row_coef[row + 3 + r, 0], ra, direction, -1.0)
                _angular_row(row_coef[row + 3 + r, 1], rb, direction, 1.0)
                violation[row + 3 + r] = dot(t_r, a_b)
        if kind == JOINT_PRISMATIC:
            separation = pb - pa
            for r in range(2):
                t_r = frame_world[:, 1 + r].copy()
                _point_row(row_coef[row + 3 + r, 0], ra, anchor_a[j], t_r, -1.0)
                _point_row(row_coef[row + 3 + r, 1], rb, anchor_b[j], t_r, 1.0)
                # + (p_B - p_A) . (omega_A x t_r) = omega_A . (t_r x (p_B - p_A))
                extra = mat_t_vec(ra, cross(t_r, separation))
                for i in range(3):
                    row_coef[row + 3 + r, 0, 3 + i] += extra[i]
                violation[row + 3 + r] = dot(t_r, separation)
        row += n_rows
    for d in range(driver_body.shape[0]):
        b = driver_body[d]
        component = driver_component[d]
        row_body[row, 0] = -1
        row_body[row, 1] = b
        for i in range(6):
            row_coef[row, 0, i] = 0.0
        e_r = np.zeros(3)
        e_r[component % 3] = 1.0
        start = driver_start[d]
        stop = driver_start[d + 1]
        times = driver_times[start:stop]
        values = driver_values[start:stop]
        rate = profile_rate(times, values, driver_quantity[d], t)
        if component < 3:
            _point_row(row_coef[row, 1], rotation[b], np.zeros(3), e_r, 1.0)
            displacement = profile_displacement(times, values, driver_quantity[d], t)
            violation[row] = x[b, component] - driver_initial[d] - displacement
        else:
            _angular_row(row_coef[row, 1], rotation[b], e_r, 1.0)
            change = quat_multiply(p[b], quat_conjugate(driver_reference[d]))
            axis = component - 3
            twist = 2.0 * math.atan2(change[1 + axis], change[0])
            error = twist - profile_displacement(times, values, driver_quantity[d], t)
            violation[row] = (error + math.pi) % (2.0 * math.pi) - math.pi
        velocity_target[row] = rate
        row += 1
    return row


@njit(cache=True)
def profile_rate(times, values, quantity, t):
    """Prescribed rate at t: the profile (velocity) or its slope (position)."""
    if quantity == 0:
        return profile_value(times, values, t)
    return profile_slope(times, values, t)


@njit(cache=True)
def profile_displacement(times, values, quantity, t):
    """Prescribed displacement from t = 0."""
    if quantity == 0:
        return profile_integral(times, values, t)
    return profile_value(times, values, t) - profile_value(times, values, 0.0)


@njit(cache=True)
def contact_candidates(x, rotation, shape_kind, shape_parameters, shape_body, shape_position,
                       shape_rotation, pair_a, pair_b, pair_offset, gap, point_a, point_b,
                       frame, count, selected):
    """Evaluate every contact pair with ``selected`` (npair,) bool set: up to
    MAX_CONTACTS_PER_PAIR candidates each (the outputs of the others are left as they are).

    Outputs (npair, K, ...) arrays: ``gap`` = geometric gap - offset, world points, contact
    frames (rows n, t1, t2; n from A toward B); ``count`` (npair,). The offset is taken on A's
    side: A's point is moved by ``offset`` along n, so that ``p_B - p_A = gap n`` holds for the
    offset gap too and a closed contact acts at one point on both bodies (otherwise its
    friction forces, a distance ``offset`` apart, would exert a spurious moment).
    """
    for k in range(pair_a.shape[0]):
        if not selected[k]:
            continue
        sa = pair_a[k]
        sb = pair_b[k]
        ba = shape_body[sa]
        bb = shape_body[sb]
        pos_a = x[ba] + mat_vec(rotation[ba], shape_position[sa])
        rot_a = mat_mat(rotation[ba], shape_rotation[sa])
        pos_b = x[bb] + mat_vec(rotation[bb], shape_position[sb])
        rot_b = mat_mat(rotation[bb], shape_rotation[sb])
        n = pair_contacts(shape_kind[sa], shape_parameters[sa], pos_a, rot_a,
                          shape_kind[sb], shape_parameters[sb], pos_b, rot_b,
                          gap[k], point_a[k], point_b[k], frame[k])
        count[k] = n
        offset = pair_offset[k]
        for c in range(n):
            gap[k, c] -= offset
            for i in range(3):
                point_a[k, c, i] += offset * frame[k, c, 0, i]


@njit(cache=True)
def contact_rows(x, rotation, fixed, shape_body, pair_a, pair_b, selected_pair,
                 selected_slot, point_a, point_b, frame, row_body, row_coef, first_row):
    """Three rows (N, T1, T2) per selected contact, from row ``first_row`` on."""
    for c in range(selected_pair.shape[0]):
        k = selected_pair[c]
        s = selected_slot[c]
        ba = shape_body[pair_a[k]]
        bb = shape_body[pair_b[k]]
        local_a = mat_t_vec(rotation[ba], point_a[k, s] - x[ba])
        local_b = mat_t_vec(rotation[bb], point_b[k, s] - x[bb])
        for r in range(3):
            row = first_row + 3 * c + r
            direction = frame[k, s, r].copy()
            row_body[row, 0] = -1 if fixed[ba] else ba
            row_body[row, 1] = -1 if fixed[bb] else bb
            _point_row(row_coef[row, 0], rotation[ba], local_a, direction, -1.0)
            _point_row(row_coef[row, 1], rotation[bb], local_b, direction, 1.0)


@njit(cache=True)
def row_values(row_body, row_coef, nu, first, last):
    """Values of rows first..last-1 for the twist nu (nb, 6)."""
    out = np.zeros(last - first)
    for row in range(first, last):
        total = 0.0
        for side in range(2):
            b = row_body[row, side]
            if b >= 0:
                for i in range(6):
                    total += row_coef[row, side, i] * nu[b, i]
        out[row - first] = total
    return out


@njit(cache=True)
def delassus(row_body, row_coef, m, inverse_blocks, cluster, cluster_dofs, cluster_start):
    """W = H Winv H^T (m, m) and Y = Winv H^T (6 nb, m) for the first m rows.

    ``inverse_blocks`` (6 nb, 6 nb) is the inverse iteration matrix, block diagonal by
    clusters of bodies coupled by springs; ``cluster`` (nb,) the cluster of each body;
    ``cluster_dofs`` the dof indices of cluster c at cluster_dofs[cluster_start[c]:...].
    Only pairs of rows that touch a common cluster are visited, so the cost is the sum over
    clusters of (rows touching it)^2, not m^2.
    """
    n = inverse_blocks.shape[0]
    n_clusters = cluster_start.shape[0] - 1
    y = np.zeros((n, m))
    for j in range(m):
        for side in range(2):
            b = row_body[j, side]
            if b < 0:
                continue
            c = cluster[b]
            for idx in range(cluster_start[c], cluster_start[c + 1]):
                d = cluster_dofs[idx]
                total = 0.0
                for i in range(6):
                    total += inverse_blocks[d, 6 * b + i] * row_coef[j, side, i]
                y[d, j] += total
    # Rows touching each cluster (a row whose two bodies share a cluster is listed once).
    counts = np.zeros(n_clusters + 1, dtype=np.int64)
    for j in range(m):
        c0 = cluster[row_body[j, 0]] if row_body[j, 0] >= 0 else -1
        c1 = cluster[row_body[j, 1]] if row_body[j, 1] >= 0 else -1
        if c0 >= 0:
            counts[c0 + 1] += 1
        if c1 >= 0 and c1 != c0:
            counts[c1 + 1] += 1
    for c in range(n_clusters):
        counts[c + 1] += counts[c]
    members = np.empty(counts[n_clusters], dtype=np.int64)
    fill = counts[:n_clusters].copy()
    for j in range(m):
        c0 = cluster[row_body[j, 0]] if row_body[j, 0] >= 0 else -1
        c1 = cluster[row_body[j, 1]] if row_body[j, 1] >= 0 else -1
        if c0 >= 0:
            members[fill[c0]] = j
            fill[c0] += 1
        if c1 >= 0 and c1 != c0:
            members[fill[c1]] = j
            fill[c1] += 1
    w = np.zeros((m, m))
    for c in range(n_clusters):
        for a in range(counts[c], counts[c + 1]):
            i = members[a]
            for bb in range(counts[c], counts[c + 1]):
                j = members[bb]
                total = 0.0
                for side in range(2):
                    b = row_body[i, side]
                    if b < 0 or cluster[b] != c:
                        continue
                    for k in range(6):
                        total += row_coef[i, side, k] * y[6 * b + k, j]
                w[i, j] += total
    return w, y


KMAX = MAX_CONTACTS_PER_PAIR
