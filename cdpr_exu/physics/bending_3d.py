"""Exact-angle bending of spatial cables: isotropic, no torsion, numba kernels.

At the joint of node b between the segments a -> b and b -> c the cable bends by the
angle theta between e1 = p_b - p_a and e2 = p_c - p_b, whatever the plane it bends in.
The spring stores U = k theta^2 / 2 (the planar model's law, :mod:`cdpr_exu.physics.bending`,
for a cable that stays in a plane). Written through c = cos(theta),

    f = -dU/dq = k phi(c) dc/dq,      phi(c) = theta / sin(theta) = arccos(c) / sqrt(1 - c^2),

which stays smooth at a straight cable (phi -> 1 + (1 - c)/3 + ...), where arccos itself
is not differentiable. K = -df/dq = -k (phi'(c) g g^T + phi(c) H), g and H the gradient and
Hessian of c, goes to Exudyn as sparse triplets, 81 per joint.

Bending dampers (:func:`add_spatial_bending_damping_force`, the planar model's c_theta =
d_n J / l0 per joint) act on the relative angular velocity of the two segments,
dw = w2 - w1 with w_i = e_i x de_i/dt / |e_i|^2, through the Rayleigh function

    R = (c/2) dw^T M dw,   M = (eps^2 I + kappa kappa^T) / (|kappa|^2 + eps^2),   kappa = u1 x u2,

u_i = e_i / |e_i| (|kappa| = sin(theta)), and the force -dR/dv. Along the joint plane's
normal dw is the rate of theta; in the plane it is also what a rigid rotation about an
in-plane axis makes (|dw| = Omega sin(theta)), which a point-mass joint cannot tell apart.
M keeps the normal part whole and weights the in-plane part by eps^2 / (sin^2(theta) + eps^2)
(eps = :data:`ISOTROPIC_BEND`; ``inf`` gives M = I): a straight cable has the isotropic damper,
with no plane to choose; a bent joint damps only the rate of its angle. A cable moving in one
plane feels exactly the planar damper c dtheta/dt. The Jacobians are analytic (docs/spatial.md).

Coordinates: flat arrays (x0, y0, z0, x1, ...) [m]; spatial scenes have z up.
"""

from __future__ import annotations

import numpy as np
from numba import njit

#: Below this 1 - cos(theta), phi and its slope are taken from their series (the closed
#: forms lose digits there): 1e-6 keeps the series' truncation below 1e-13.
SERIES_BELOW = 1e-6

#: The bending dampers' ``isotropic_bend`` eps (see the module notes): joints bent by
#: sin(theta) >> eps damp only the rate of their angle, straighter ones every relative turn.
#: 0.05 (about 3 degrees) leaves the free spans of the shipped scenes (joints bent below
#: 2 degrees) nearly isotropic and cuts the spurious damping of a turning swivel pulley's
#: wrap (joints up to 27 degrees) 21-fold; measured in docs/spatial.md.
ISOTROPIC_BEND = 0.05


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


@njit(cache=True, inline="always")
def _joint(positions, a, b, c, grad, hess, work):
    """cos(theta) of one joint, its gradient (9,) and Hessian (9, 9) in (p_a, p_b, p_c); ``work`` (15, 3) is
    scratch space (no array allocated per joint: a third of the kernels' time on the swivel robot)."""
    e1, e2, u, v, g1, g2 = work[0], work[1], work[2], work[3], work[4], work[5]
    for k in range(3):
        e1[k] = positions[3 * b + k] - positions[3 * a + k]
        e2[k] = positions[3 * c + k] - positions[3 * b + k]
    n1 = np.sqrt(e1[0] ** 2 + e1[1] ** 2 + e1[2] ** 2)
    n2 = np.sqrt(e2[0] ** 2 + e2[1] ** 2 + e2[2] ** 2)
    for k in range(3):
        u[k] = e1[k] / n1
        v[k] = e2[k] / n2
    cos = u[0] * v[0] + u[1] * v[1] + u[2] * v[2]
    for k in range(3):
        g1[k] = (v[k] - cos * u[k]) / n1  # dc/de1
        g2[k] = (u[k] - cos * v[k]) / n2  # dc/de2
    for k in range(3):
        grad[k] = -g1[k]
        grad[3 + k] = g1[k] - g2[k]
        grad[6 + k] = g2[k]
    if hess.shape[0] == 9:
        h11, h22, h12 = work[6:9], work[9:12], work[12:15]
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
    work = np.empty((15, 3))
    for j in range(joints.shape[0]):
        cos = _joint(positions, joints[j, 0], joints[j, 1], joints[j, 2], grad, no_hess, work)
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
    work = np.empty((15, 3))
    energy = 0.0
    for j in range(joints.shape[0]):
        cos = _joint(positions, joints[j, 0], joints[j, 1], joints[j, 2], grad, no_hess, work)
        theta = np.arccos(min(1.0, max(-1.0, cos)))
        energy += 0.5 * stiffness[j] * theta * theta
    return energy


@njit(cache=True)
def spatial_bending_stiffness(positions, joints, stiffness, factor, out_values):
    """``factor * K`` (K = -df/dq [N/m]) at :func:`~cdpr_exu.physics.sparse_blocks.block_pattern`'s places
    (overwrites ``out_values``)."""
    grad = np.empty(9)
    hess = np.empty((9, 9))
    work = np.empty((15, 3))
    for j in range(joints.shape[0]):
        cos = _joint(positions, joints[j, 0], joints[j, 1], joints[j, 2], grad, hess, work)
        phi, slope = angle_factor(cos)
        k = stiffness[j]
        for i in range(9):
            for m in range(9):
                out_values[81 * j + 9 * i + m] = -factor * k * (slope * grad[i] * grad[m] + phi * hess[i, m])
    return out_values


@njit(cache=True, inline="always")
def _cross(a, b, scale, out):
    """out = scale (a x b), all (3,)."""
    out[0] = scale * (a[1] * b[2] - a[2] * b[1])
    out[1] = scale * (a[2] * b[0] - a[0] * b[2])
    out[2] = scale * (a[0] * b[1] - a[1] * b[0])


@njit(cache=True, inline="always")
def _skew(v, scale, out):
    """out = scale [v]x (3, 3), [v]x w = v x w."""
    out[0, 0] = out[1, 1] = out[2, 2] = 0.0
    out[0, 1] = -scale * v[2]
    out[0, 2] = scale * v[1]
    out[1, 0] = scale * v[2]
    out[1, 2] = -scale * v[0]
    out[2, 0] = -scale * v[1]
    out[2, 1] = scale * v[0]


@njit(cache=True, inline="always")
def _product(a, b, scale, out):
    """out = scale a b, all (3, 3)."""
    for i in range(3):
        for j in range(3):
            out[i, j] = scale * (a[i, 0] * b[0, j] + a[i, 1] * b[1, j] + a[i, 2] * b[2, j])


@njit(cache=True, inline="always")
def _damper_joint(positions, velocities, a, b, c, damping, isotropic_bend, force, jacobian_q, jacobian_v,
                  vectors, matrices):
    """The damper of one joint on its segments e1 = p_b - p_a, e2 = p_c - p_b.

    Fills ``force`` (6,) with g = -dR/d(de1/dt, de2/dt) [N] and, when ``jacobian_q`` has
    36 entries, ``jacobian_q`` = -dg/d(e1, e2) [N/m] and ``jacobian_v`` = -dg/d(de1/dt, de2/dt)
    [N s/m] (6, 6). ``vectors`` (13, 3) and ``matrices`` (16, 3, 3) are scratch space.
    Returns the dissipated power 2 R [W].
    """
    e1, e2, d1, d2, w1, w2, dw, u1, u2, kappa, m, h1, h2 = (
        vectors[0], vectors[1], vectors[2], vectors[3], vectors[4], vectors[5], vectors[6], vectors[7],
        vectors[8], vectors[9], vectors[10], vectors[11], vectors[12])
    for k in range(3):
        e1[k] = positions[3 * b + k] - positions[3 * a + k]
        e2[k] = positions[3 * c + k] - positions[3 * b + k]
        d1[k] = velocities[3 * b + k] - velocities[3 * a + k]
        d2[k] = velocities[3 * c + k] - velocities[3 * b + k]
    n1 = e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]
    n2 = e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2]
    _cross(e1, d1, 1.0 / n1, w1)
    _cross(e2, d2, 1.0 / n2, w2)
    for k in range(3):
        dw[k] = w2[k] - w1[k]
    isotropic = not np.isfinite(isotropic_bend)
    eps2 = den = normal_rate = 0.0
    l1 = np.sqrt(n1)
    l2 = np.sqrt(n2)
    if isotropic:
        for k in range(3):
            m[k] = dw[k]
    else:
        for k in range(3):
            u1[k] = e1[k] / l1
            u2[k] = e2[k] / l2
        _cross(u1, u2, 1.0, kappa)  # sin(theta) times the joint plane's normal
        eps2 = isotropic_bend * isotropic_bend
        den = kappa[0] * kappa[0] + kappa[1] * kappa[1] + kappa[2] * kappa[2] + eps2
        normal_rate = kappa[0] * dw[0] + kappa[1] * dw[1] + kappa[2] * dw[2]
        for k in range(3):
            m[k] = (eps2 * dw[k] + normal_rate * kappa[k]) / den  # M dw, M = (eps^2 I + kappa kappa^T) / den
    _cross(m, e1, 1.0 / n1, h1)
    _cross(m, e2, 1.0 / n2, h2)
    for k in range(3):
        force[k] = damping * h1[k]
        force[3 + k] = -damping * h2[k]
    power = damping * (m[0] * dw[0] + m[1] * dw[1] + m[2] * dw[2])
    if jacobian_q.shape[0] != 6:
        return power
    (matrix, s1, s2, a1, a2, dm_de1, dm_de2, dm_dd1, dm_dd2, q, dk1, dk2, skew_m, tmp, tmp2, _) = (
        matrices[0], matrices[1], matrices[2], matrices[3], matrices[4], matrices[5], matrices[6], matrices[7],
        matrices[8], matrices[9], matrices[10], matrices[11], matrices[12], matrices[13], matrices[14], matrices[15])
    for i in range(3):
        for j in range(3):
            delta = 1.0 if i == j else 0.0
            matrix[i, j] = delta if isotropic else (eps2 * delta + kappa[i] * kappa[j]) / den
    _skew(e1, -1.0 / n1, s1)  # dh1/dm = dw/d(de1/dt)
    _skew(e2, -1.0 / n2, s2)  # dh2/dm = -dw/d(de2/dt)
    _skew(d1, -1.0 / n1, a1)  # dw1/de1 = (-[d1]x - 2 w1 e1^T) / n1
    _skew(d2, -1.0 / n2, a2)
    for i in range(3):
        for j in range(3):
            a1[i, j] -= 2.0 * w1[i] * e1[j] / n1
            a2[i, j] -= 2.0 * w2[i] * e2[j] / n2
    _product(matrix, a1, -1.0, dm_de1)
    _product(matrix, a2, 1.0, dm_de2)
    if not isotropic:
        _skew(u2, -1.0, tmp)  # dkappa/de1 = -[u2]x (I - u1 u1^T) / l1
        for i in range(3):
            for j in range(3):
                tmp2[i, j] = ((1.0 if i == j else 0.0) - u1[i] * u1[j]) / l1
        _product(tmp, tmp2, 1.0, dk1)
        _skew(u1, 1.0, tmp)  # dkappa/de2 = [u1]x (I - u2 u2^T) / l2
        for i in range(3):
            for j in range(3):
                tmp2[i, j] = ((1.0 if i == j else 0.0) - u2[i] * u2[j]) / l2
        _product(tmp, tmp2, 1.0, dk2)
        for i in range(3):
            for j in range(3):  # dm/dkappa
                q[i, j] = (kappa[i] * dw[j] + (normal_rate if i == j else 0.0) - 2.0 * m[i] * kappa[j]) / den
        _product(q, dk1, 1.0, tmp)
        _product(q, dk2, 1.0, tmp2)
        for i in range(3):
            for j in range(3):
                dm_de1[i, j] += tmp[i, j]
                dm_de2[i, j] += tmp2[i, j]
    _product(matrix, s1, 1.0, dm_dd1)
    _product(matrix, s2, -1.0, dm_dd2)
    _skew(m, 1.0, skew_m)
    # g1 = c h1, g2 = -c h2; the matrices are -dg: rows of g1 carry -c, rows of g2 +c
    _product(s1, dm_de1, 1.0, tmp)
    for i in range(3):
        for j in range(3):
            jacobian_q[i, j] = -damping * ((skew_m[i, j] - 2.0 * h1[i] * e1[j]) / n1 + tmp[i, j])
    _product(s2, dm_de2, 1.0, tmp)
    for i in range(3):
        for j in range(3):
            jacobian_q[3 + i, 3 + j] = damping * ((skew_m[i, j] - 2.0 * h2[i] * e2[j]) / n2 + tmp[i, j])
    _product(s1, dm_de2, -damping, tmp)
    _product(s2, dm_de1, damping, tmp2)
    for i in range(3):
        for j in range(3):
            jacobian_q[i, 3 + j] = tmp[i, j]
            jacobian_q[3 + i, j] = tmp2[i, j]
    _product(s1, dm_dd1, -damping, tmp)
    _product(s1, dm_dd2, -damping, tmp2)
    for i in range(3):
        for j in range(3):
            jacobian_v[i, j] = tmp[i, j]
            jacobian_v[i, 3 + j] = tmp2[i, j]
    _product(s2, dm_dd1, damping, tmp)
    _product(s2, dm_dd2, damping, tmp2)
    for i in range(3):
        for j in range(3):
            jacobian_v[3 + i, j] = tmp[i, j]
            jacobian_v[3 + i, 3 + j] = tmp2[i, j]
    return power


#: The segment-to-node map: e1 = p_b - p_a, e2 = p_c - p_b, as (segment, node) coefficients.
_INCIDENCE = np.array([[-1.0, 1.0, 0.0], [0.0, -1.0, 1.0]])


@njit(cache=True)
def add_spatial_bending_damping_force(positions, velocities, joints, damping, isotropic_bend, out):
    """Add the bending dampers' force -dR/dv [N] to ``out`` (3N,).

    ``positions``, ``velocities`` (3N,) [m, m/s]; ``joints`` (J, 3); ``damping`` (J,) c
    [N m s/rad]; ``isotropic_bend`` eps [-] of the module notes (``inf``: R = (c/2)|w2 - w1|^2).
    """
    segment = np.empty(6)
    none = np.empty((0, 0))
    vectors = np.empty((13, 3))
    no_matrices = np.empty((0, 3, 3))
    for j in range(joints.shape[0]):
        _damper_joint(positions, velocities, joints[j, 0], joints[j, 1], joints[j, 2], damping[j], isotropic_bend,
                      segment, none, none, vectors, no_matrices)
        for k in range(3):
            out[3 * joints[j, 0] + k] -= segment[k]
            out[3 * joints[j, 1] + k] += segment[k] - segment[3 + k]
            out[3 * joints[j, 2] + k] += segment[3 + k]
    return out


@njit(cache=True)
def add_spatial_bending_damping_jacobian(positions, velocities, joints, damping, isotropic_bend, factor_position,
                                         factor_velocity, out_values):
    """Add ``factor_position * K + factor_velocity * D`` of the bending dampers (K = -df/dq [N/m],
    D = -df/dv [N s/m]) to ``out_values`` at :func:`~cdpr_exu.physics.sparse_blocks.block_pattern`'s places."""
    segment = np.empty(6)
    jacobian_q = np.empty((6, 6))
    jacobian_v = np.empty((6, 6))
    combined = np.empty((6, 6))
    vectors = np.empty((13, 3))
    matrices = np.empty((16, 3, 3))
    for j in range(joints.shape[0]):
        _damper_joint(positions, velocities, joints[j, 0], joints[j, 1], joints[j, 2], damping[j], isotropic_bend,
                      segment, jacobian_q, jacobian_v, vectors, matrices)
        for i in range(6):
            for m in range(6):
                combined[i, m] = factor_position * jacobian_q[i, m] + factor_velocity * jacobian_v[i, m]
        for node_i in range(3):
            for node_m in range(3):
                for s in range(2):
                    p = _INCIDENCE[s, node_i]
                    if p == 0.0:
                        continue
                    for t in range(2):
                        r = _INCIDENCE[t, node_m]
                        if r == 0.0:
                            continue
                        for i in range(3):
                            for m in range(3):
                                out_values[81 * j + 9 * (3 * node_i + i) + 3 * node_m + m] += \
                                    p * r * combined[3 * s + i, 3 * t + m]
    return out_values


@njit(cache=True)
def bending_damping_dissipation(positions, velocities, joints, damping, isotropic_bend):
    """Power the bending dampers dissipate, 2 R [W] (R the Rayleigh function, quadratic in v)."""
    segment = np.empty(6)
    none = np.empty((0, 0))
    vectors = np.empty((13, 3))
    no_matrices = np.empty((0, 3, 3))
    power = 0.0
    for j in range(joints.shape[0]):
        power += _damper_joint(positions, velocities, joints[j, 0], joints[j, 1], joints[j, 2], damping[j],
                               isotropic_bend, segment, none, none, vectors, no_matrices)
    return power

