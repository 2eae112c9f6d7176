"""Cable tensions within their bounds that hold a platform: one tension distribution, planar or spatial.

Pure NumPy/SciPy. :func:`tension_distribution` solves ``A f + w = 0``, ``t_min <= f <= t_max`` for any
structure matrix (planar 3 x m, spatial 6 x m, a point mass's force rows) and wrench; :func:`tensions`
does it for a scene along poses, against the platform's weight (:func:`weight_wrench`) and an external
wrench, within the cables' ``min_tension`` / ``max_tension``. Units SI; moments about the centre of mass."""

from __future__ import annotations

import numpy as np
from scipy.optimize import nnls

from cdpr_exu.core.errors import SceneError, UnreachableError
from cdpr_exu.core.geometry import finite_array
from cdpr_exu.core.validation import per_item, shown, vector
from cdpr_exu.statics import kinematics

__all__ = ["tension_distribution", "weight_wrench", "tensions"]

_INFEASIBLE_RESIDUAL = 1e-6
"""NNLS residual below which the least-distance problem is infeasible (a feasible one has ||r|| >= 1/sqrt(1 + m/4))."""

_BOUND_ROUNDING = 1e-9
"""A tension this fraction of the tension range outside its bounds is rounding (and is clipped)."""


def _tension_limits(min_tension, max_tension, n_cables):
    lower = per_item("min_tension", min_tension, n_cables)
    upper = per_item("max_tension", max_tension, n_cables)
    if np.any(lower > upper):
        raise SceneError(f"min_tension must not exceed max_tension, got min_tension {shown(min_tension)} "
                         f"and max_tension {shown(max_tension)} [N]")
    return lower, upper


def _outside(pose, wrench, lower, upper, reason):
    where = "the pose" if pose is None else f"pose {np.asarray(pose).tolist()}"
    span = (f"[{lower[0]:g}, {upper[0]:g}] N" if np.all(lower == lower[0]) and np.all(upper == upper[0])
            else "their bounds")
    return UnreachableError(f"{where} is outside the wrench-feasible workspace: no cable tensions within {span} "
                            f"balance the wrench {np.asarray(wrench).tolist()} [N, N m] ({reason})")


def tension_distribution(structure_matrix, wrench, min_tension, max_tension, pose=None):
    """Cable tensions within their bounds that balance a wrench: ``A f + w = 0``, closest to the mid tensions.

    Solves ``min ||f - f_mid||^2`` subject to ``A f = -w``, ``t_min <= f <= t_max``,
    ``f_mid = (t_min + t_max) / 2``, for any number of cables (too few: only wrenches in the range of
    ``A`` are balanced).

    Parameters
    ----------
    structure_matrix : array_like, shape (n, m)
        ``A`` (:func:`cdpr_exu.statics.kinematics.structure_matrix`).
    wrench : array_like, shape (n,) [N, N m]
        Everything but the cables acting on the platform (weight, external load, inertia).
    min_tension, max_tension : float or array_like, shape (m,) [N]
        ``0 <= t_min <= t_max``.
    pose : array_like, optional
        Only named in the error message.

    Returns the tensions (m,) [N]. Raises SceneError naming the argument (wrong shapes, non-finite values,
    negative bounds, ``min_tension > max_tension``), UnreachableError "outside the wrench-feasible
    workspace", naming the pose, if no tensions within the bounds balance the wrench.

    Notes
    -----
    **Why this QP, not the improved closed-form method** (Pott, Springer 2018). Both give
    ``f = f_mid - A^+ (w + A f_mid)`` while no bound is active; when one is, the closed-form method fixes
    the violating cable at its limit and repeats, a greedy reduction not guaranteed to find a distribution
    that exists. The strictly convex QP has a unique solution and is infeasible only for an empty feasible
    set, so "outside the wrench-feasible workspace" means what it says.

    **How, exactly and without tolerances to tune.** With the SVD of ``A``, ``f = f_p + N lambda``: ``f_p =
    f_mid + A^+ (-w - A f_mid)`` is the point of the equality set closest to ``f_mid``, ``N`` an orthonormal
    null-space basis, so the QP becomes the least-distance programme ``min ||lambda|| s.t. G lambda >= h``
    (the bounds), ``A f = -w`` holding to round-off. Lawson and Hanson's LDP algorithm (Solving Least Squares
    Problems, 1974, ch. 23) solves it with one NNLS (``min ||E u - e_last||, u >= 0``, ``E = [G^T; h^T]``): a
    zero residual ``r`` certifies infeasibility, else ``lambda = -r[:-1] / r[-1]`` and ``-r[-1] = 1 / (1 +
    ||lambda||^2)``. With tensions in units of the largest range a feasible ``lambda`` has ``||lambda|| <=
    sqrt(m) / 2``, so ``-r[-1] >= 1 / (1 + m / 4)``; the pose is refused below half of that (or an NNLS
    residual below 1e-6), and a solution is checked against the bounds (to 1e-9 of the range, then clipped):
    rounding can only refuse, never return tensions outside the bounds.
    """
    matrix = finite_array("structure_matrix", structure_matrix)
    if matrix.ndim != 2 or matrix.shape[1] < 1:
        raise SceneError(f"structure_matrix must have shape (n, m), got shape {matrix.shape}")
    n_rows, n_cables = matrix.shape
    wrench = finite_array("wrench", wrench)
    if wrench.shape != (n_rows,):
        raise SceneError(f"wrench must have shape ({n_rows},) to match structure_matrix, got shape {wrench.shape}")
    lower, upper = _tension_limits(min_tension, max_tension, n_cables)
    target = -wrench
    middle = 0.5 * (lower + upper)

    u_matrix, singular, v_transposed = np.linalg.svd(matrix)
    largest = singular[0] if singular.size else 0.0
    rank = int(np.sum(singular > max(matrix.shape) * np.finfo(float).eps * largest))
    shortfall = u_matrix[:, :rank].T @ (target - matrix @ middle)
    particular = middle + v_transposed[:rank].T @ (shortfall / singular[:rank])
    scale = float(np.linalg.norm(target)) + largest * float(np.linalg.norm(particular)) + 1e-300
    if np.linalg.norm(matrix @ particular - target) > 1e-9 * scale:
        raise _outside(pose, wrench, lower, upper,
                       f"the cables cannot exert it at all: the structure matrix has rank {rank} < {n_rows}")
    null_space = v_transposed[rank:].T  # (m, m - rank), orthonormal columns
    tension_scale = float(np.max(upper - lower))
    if tension_scale <= 0.0:
        tension_scale = max(float(np.max(upper)), 1.0)
    if null_space.shape[1] == 0:
        tensions = particular
    else:
        # G lambda >= h: f_p + N lambda >= t_min and -(f_p + N lambda) >= -t_max, tensions in units of the range
        g_matrix = np.vstack([null_space, -null_space])
        h_vector = np.concatenate([lower - particular, particular - upper]) / tension_scale
        e_matrix = np.vstack([g_matrix.T, h_vector[None, :]])
        rhs = np.zeros(e_matrix.shape[0])
        rhs[-1] = 1.0
        solution, residual_norm = nnls(e_matrix, rhs, maxiter=50 * e_matrix.shape[1])
        residual = e_matrix @ solution - rhs
        # feasible: -r_last = ||r||^2 >= 1 / (1 + m / 4); infeasible: r = 0 (up to the rounding of E u, which
        # grows with u near the workspace's boundary: 1e-4 there, measured); half the floor separates them
        if residual_norm <= _INFEASIBLE_RESIDUAL or -residual[-1] < 0.5 / (1.0 + n_cables / 4.0):
            raise _outside(pose, wrench, lower, upper, "the bounds and the balance have no common point")
        tensions = particular + tension_scale * (null_space @ (-residual[:-1] / residual[-1]))
    rounding = _BOUND_ROUNDING * tension_scale
    if not np.all((tensions >= lower - rounding) & (tensions <= upper + rounding)):  # NaN fails too
        raise _outside(pose, wrench, lower, upper, f"the balancing tensions {tensions.tolist()} N leave the bounds")
    return np.clip(tensions, lower, upper)


def weight_wrench(scene) -> np.ndarray:
    """The platform's weight as a wrench about its centre of mass, shape (n,) [N, N m] as the scene's
    structure matrix (gravity 0 where the scene switches it off)."""
    space = scene.space
    wrench = np.zeros(space.position_size if scene.platform.is_point_mass else space.wrench_size)
    wrench[space.vertical] = -scene.platform.mass * (scene.gravity if scene.effects.gravity else 0.0)
    return wrench


def tensions(scene, poses, external_wrench=None) -> np.ndarray:
    """Cable tensions (m,) or (N, m) [N] within the cables' limits (0 and inf where not given) that hold the
    platform at ``poses`` (pose_size,) or (N, pose_size) [m, rad] against its weight and ``external_wrench``
    (n,) [N, N m] (world frame, about the centre of mass).

    Raises UnreachableError "outside the wrench-feasible workspace", naming the pose (and ``poses[k]``, the
    first such one), or for an anchor the cables cannot reach."""
    poses = finite_array("poses", poses, (scene.space.pose_size,))
    wrench = weight_wrench(scene)
    if external_wrench is not None:
        wrench = wrench + vector("external_wrench", external_wrench, len(wrench), " [N, N m]")
    limits = scene.tension_limits
    lower, upper = (0.0, np.inf) if limits is None else (limits[:, 0], limits[:, 1])
    matrices = kinematics.structure_matrix(scene, poses)  # one call: on-axis anchors keep the previous azimuth
    if poses.ndim == 1:
        return tension_distribution(matrices, wrench, lower, upper, pose=poses)
    result = np.empty((len(poses), scene.n_cables))
    for k, (pose, matrix) in enumerate(zip(poses, matrices)):
        try:
            result[k] = tension_distribution(matrix, wrench, lower, upper, pose=pose)
        except UnreachableError as error:
            raise UnreachableError(f"poses[{k}]: {error}") from None
    return result
