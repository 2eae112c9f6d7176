"""The cables' Python-side forces (exact-angle bending and tension-only axial elements) in
one numba call each for the force and its Jacobian.

Exudyn calls the cables' ``ObjectGenericODE2`` force function once per Newton iteration
and its Jacobian function once per Jacobian update. Calling the bending and the
tension-only kernels separately from Python, with their argument checks, cost about
11 us per force call on the paper circle (2 x 16 nodes); one call of one compiled
function does the same arithmetic in the same order (so the same bits) for a few
microseconds (``benchmarks/bench_accuracy_speed.py``).

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

    Parameters
    ----------
    reference, q : ndarray, shape (2N,) [m]
        Exudyn's reference positions and displacements; ``positions`` (2N,) receives their sum.
    q_t : ndarray, shape (2N,) [m/s]
    joints, stiffness, damping : the bending joints (J, 3) and their k_theta, d_theta (J,)
        [N m/rad, N m s/rad] (:func:`cdpr_exu.physics.bending.bending_force_kernel`).
    elements, rest_length, axial_stiffness, axial_damping : the tension-only elements (E, 2)
        and their l0, k, c (E,) [m, N/m, N s/m] (:func:`cdpr_exu.physics.axial.slack_axial_force`);
        E = 0 for push-capable cables (Exudyn's own spring-dampers).
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
