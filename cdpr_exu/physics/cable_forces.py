"""The cables' Python-side forces (exact-angle bending and tension-only axial elements) in
one numba call each for the force and its Jacobian, which Exudyn calls once per Newton
iteration and per Jacobian update: the same arithmetic as the separate kernels, in the same
order (so the same bits), without their Python-side calls.

No Exudyn here: coordinates are flat arrays (x0, y0, x1, y1, ...) [m, m/s].
"""

from __future__ import annotations

from numba import njit

from cdpr_exu.physics.axial import slack_axial_force, slack_axial_jacobian
from cdpr_exu.physics.bending import bending_force_kernel, bending_jacobian_kernel


@njit(cache=True)
def cable_force(reference, q, q_t, positions, joints, stiffness, damping, elements, rest_length,
                axial_stiffness, axial_damping, out):
    """Bending plus tension-only axial force of the cables, shape (2N,) [N], into ``out``.

    ``reference``, ``q`` (2N,) [m]: Exudyn's reference positions and displacements (``positions``
    receives their sum); ``q_t`` (2N,) [m/s]; the bending ``joints`` (J, 3) with their ``stiffness``
    and ``damping`` (J,) [N m/rad, N m s/rad]; the tension-only ``elements`` (E, 2) with their l0,
    k, c (E,) [m, N/m, N s/m] (E = 0 for push-capable cables, Exudyn's own spring-dampers).
    """
    for i in range(positions.shape[0]):
        positions[i] = reference[i] + q[i]
    bending_force_kernel(positions, q_t, joints, stiffness, damping, out)
    slack_axial_force(positions, q_t, elements, rest_length, axial_stiffness, axial_damping, out)
    return out


@njit(cache=True)
def cable_jacobian(reference, q, q_t, positions, joints, stiffness, damping, elements, rest_length,
                   axial_stiffness, axial_damping, factor_position, factor_velocity, no_force, no_matrix, out,
                   kink_strain=0.0, cut_slopes=False):
    """``factor_position * K + factor_velocity * D`` of the same forces, dense (2N, 2N), into ``out``.

    K = -df/dq, D = -df/dq_t; ``no_force`` (0,) and ``no_matrix`` (0, 0) are empty arrays
    (what the bending kernel takes for "no force" and "weighted sum"); ``kink_strain`` as
    :func:`cdpr_exu.physics.axial.slack_axial_jacobian` (the run's first step only), ``cut_slopes``
    as there (:class:`cdpr_exu.physics.axial.CutSlopes`).
    """
    for i in range(positions.shape[0]):
        positions[i] = reference[i] + q[i]
    bending_jacobian_kernel(positions, q_t, joints, stiffness, damping, factor_position, factor_velocity,
                            no_force, out, no_matrix)
    slack_axial_jacobian(positions, q_t, elements, rest_length, axial_stiffness, axial_damping,
                         factor_position, factor_velocity, out, kink_strain, cut_slopes)
    return out
