"""Exact-angle bending of spatial cables: isotropic, no torsion, numba kernels.

At the joint of node b between the segments a -> b and b -> c the cable bends by the
angle theta between e1 = p_b - p_a and e2 = p_c - p_b, whatever the plane it bends in.
The spring stores U = k theta^2 / 2 (the planar model's law, :mod:`cdpr_exu.physics.bending`,
for a cable that stays in a plane). Written through c = cos(theta),

    f = -dU/dq = k phi(c) dc/dq,      phi(c) = theta / sin(theta) = arccos(c) / sqrt(1 - c^2),

which stays smooth at a straight cable (phi -> 1 + (1 - c)/3 + ...), where arccos itself
is not differentiable. The stiffness matrix is K = -df/dq = -k (phi'(c) g g^T + phi(c) H)
with g, H the gradient and Hessian of c; it is handed to Exudyn as sparse triplets,
81 per joint, in a fixed pattern.

Damping is not here yet. The candidate damper on the relative angular velocity of the
two segments, w2 - w1 with w_i = e_i x de_i/dt / |e_i|^2 (:func:`relative_angular_velocity`),
damps a rigid rotation of a bent joint about an axis in its plane: there
|w2 - w1| = Omega sin(theta), a dissipation d Omega^2 sin^2(theta). A damper on dc/dt
ignores every rigid motion but its torque vanishes as theta^2 at a straight cable (see
docs/spatial.md).

Coordinates: flat arrays (x0, y0, z0, x1, ...) [m]; spatial scenes have z up.
"""

from __future__ import annotations

import numpy as np
from numba import njit

#: Below this 1 - cos(theta), phi and its slope are taken from their series (the closed
#: forms lose digits there): 1e-6 keeps the series' truncation below 1e-13.
SERIES_BELOW = 1e-6


@njit(cache=True)
def angle_factor(c):
    """phi(c) = arccos(c) / sqrt(1 - c^2) and its derivative d phi / d c, for c in [-1, 1]."""
    c = min(1.0, max(-1.0, c))
    x = 1.0 - c
    if x < SERIES_BELOW:
        # arccos(1 - x) / sqrt(x (2 - x)) = 1 + x / 3 + 2 x^2 / 15 + ...
        return 1.0 + x / 3.0 + 2.0 * x * x / 15.0, -(1.0 / 3.0 + 4.0 * x / 15.0)
    s2 = 1.0 - c * c
    s = np.sqrt(s2)
    theta = np.arccos(c)
    phi = theta / s
    # d/dc [theta / s] = (-1/s) / s + theta * c / s^3
    return phi, (-1.0 + theta * c / s) / s2


@njit(cache=True)
def _joint(positions, a, b, c, grad, hess):
    """cos(theta) of one joint, its gradient (9,) and Hessian (9, 9) in (p_a, p_b, p_c)."""
    e1 = np.empty(3)
    e2 = np.empty(3)
    for k in range(3):
        e1[k] = positions[3 * b + k] - positions[3 * a + k]
        e2[k] = positions[3 * c + k] - positions[3 * b + k]
    n1 = np.sqrt(e1[0] ** 2 + e1[1] ** 2 + e1[2] ** 2)
    n2 = np.sqrt(e2[0] ** 2 + e2[1] ** 2 + e2[2] ** 2)
    u = e1 / n1
    v = e2 / n2
    cos = u[0] * v[0] + u[1] * v[1] + u[2] * v[2]
    g1 = (v - cos * u) / n1  # dc/de1
    g2 = (u - cos * v) / n2  # dc/de2
    for k in range(3):
        grad[k] = -g1[k]
        grad[3 + k] = g1[k] - g2[k]
        grad[6 + k] = g2[k]
    if hess.shape[0] == 9:
        h11 = np.empty((3, 3))
        h22 = np.empty((3, 3))
        h12 = np.empty((3, 3))
        for i in range(3):
            for j in range(3):
                delta = 1.0 if i == j else 0.0
                h11[i, j] = -(u[i] * g1[j] + g1[i] * u[j]) / n1 - cos * (delta - u[i] * u[j]) / (n1 * n1)
                h22[i, j] = -(v[i] * g2[j] + g2[i] * v[j]) / n2 - cos * (delta - v[i] * v[j]) / (n2 * n2)
                h12[i, j] = ((delta - v[i] * v[j]) / n2 - u[i] * g2[j]) / n1  # d^2 c / de1_i de2_j
        # e1 = p_b - p_a, e2 = p_c - p_b: blocks of (p_a, p_b, p_c)
        for i in range(3):
            for j in range(3):
                hess[i, j] = h11[i, j]
                hess[i, 3 + j] = -h11[i, j] + h12[i, j]
                hess[i, 6 + j] = -h12[i, j]
                hess[3 + i, j] = -h11[i, j] + h12[j, i]
                hess[3 + i, 3 + j] = h11[i, j] - h12[i, j] - h12[j, i] + h22[i, j]
                hess[3 + i, 6 + j] = h12[i, j] - h22[i, j]
                hess[6 + i, j] = -h12[j, i]
                hess[6 + i, 3 + j] = h12[j, i] - h22[i, j]
                hess[6 + i, 6 + j] = h22[i, j]
    return cos


@njit(cache=True)
def spatial_bending_force(positions, joints, stiffness, out):
    """Overwrite ``out`` (3N,) with the bending force [N] of the joints (J, 3) with stiffness (J,) [N m/rad]."""
    out[:] = 0.0
    grad = np.empty(9)
    no_hess = np.empty((0, 0))
    for j in range(joints.shape[0]):
        cos = _joint(positions, joints[j, 0], joints[j, 1], joints[j, 2], grad, no_hess)
        phi, _ = angle_factor(cos)
        for node in range(3):
            for k in range(3):
                out[3 * joints[j, node] + k] += stiffness[j] * phi * grad[3 * node + k]
    return out


@njit(cache=True)
def spatial_bending_energy(positions, joints, stiffness):
    """Elastic bending energy sum k theta^2 / 2 [J]."""
    grad = np.empty(9)
    no_hess = np.empty((0, 0))
    energy = 0.0
    for j in range(joints.shape[0]):
        cos = _joint(positions, joints[j, 0], joints[j, 1], joints[j, 2], grad, no_hess)
        theta = np.arccos(min(1.0, max(-1.0, cos)))
        energy += 0.5 * stiffness[j] * theta * theta
    return energy


@njit(cache=True)
def spatial_bending_pattern(joints):
    """Rows and columns of the stiffness triplets: 81 per joint, shape (81 J,) each."""
    n = joints.shape[0]
    rows = np.empty(81 * n, dtype=np.int64)
    columns = np.empty(81 * n, dtype=np.int64)
    for j in range(n):
        for i in range(9):
            for m in range(9):
                rows[81 * j + 9 * i + m] = 3 * joints[j, i // 3] + i % 3
                columns[81 * j + 9 * i + m] = 3 * joints[j, m // 3] + m % 3
    return rows, columns


@njit(cache=True)
def spatial_bending_stiffness(positions, joints, stiffness, factor, out_values):
    """``factor * K`` (K = -df/dq [N/m]) at :func:`spatial_bending_pattern`'s places (overwrites ``out_values``)."""
    grad = np.empty(9)
    hess = np.empty((9, 9))
    for j in range(joints.shape[0]):
        cos = _joint(positions, joints[j, 0], joints[j, 1], joints[j, 2], grad, hess)
        phi, slope = angle_factor(cos)
        k = stiffness[j]
        for i in range(9):
            for m in range(9):
                out_values[81 * j + 9 * i + m] = -factor * k * (slope * grad[i] * grad[m] + phi * hess[i, m])
    return out_values


def relative_angular_velocity(positions, velocities, a, b, c) -> np.ndarray:
    """w2 - w1 [rad/s], shape (3,): the angular velocities w_i = e_i x de_i/dt / |e_i|^2 of the
    segments e1 = p_b - p_a and e2 = p_c - p_b of the joint (a, b, c), a damper candidate."""
    p = np.asarray(positions, dtype=float).reshape(-1, 3)
    v = np.asarray(velocities, dtype=float).reshape(-1, 3)
    e1, e2 = p[b] - p[a], p[c] - p[b]
    w1 = np.cross(e1, v[b] - v[a]) / (e1 @ e1)
    w2 = np.cross(e2, v[c] - v[b]) / (e2 @ e2)
    return w2 - w1


def chain_joints(nodes_per_cable) -> np.ndarray:
    """Joints (a, b, c) of cables whose nodes are numbered one after another, shape (J, 3)."""
    joints, start = [], 0
    for count in nodes_per_cable:
        joints.extend((start + j, start + j + 1, start + j + 2) for j in range(count - 2))
        start += count
    return np.asarray(joints, dtype=np.int64).reshape(-1, 3)
