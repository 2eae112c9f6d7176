"""Cable tensions within their bounds that hold a platform: one tension distribution, planar or spatial.

Pure NumPy/SciPy; no Exudyn. :func:`tension_distribution` solves ``A f + w = 0`` with
``t_min <= f <= t_max`` for any structure matrix ``A`` (planar 3 x m, spatial 6 x m, the
force rows of a point mass) and wrench ``w``; :func:`tensions` does it for a scene along
poses, against the platform's weight (:func:`weight_wrench`) and an external wrench, within
the cables' ``min_tension`` / ``max_tension``. Units SI; the moment about the centre of mass.
"""

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
    limits = []
    for name, value in (("min_tension", min_tension), ("max_tension", max_tension)):
        limits.append(per_item(name, value, n_cables))  # >= 0: cables cannot push
    lower, upper = limits
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

    Solves the quadratic programme::

        minimise ||f - f_mid||^2   subject to   A f = -w,   t_min <= f <= t_max,

    ``f_mid = (t_min + t_max) / 2``, for any number of cables: redundant (m > n),
    square, or too few (then only wrenches in the range of ``A`` are balanced).

    Parameters
    ----------
    structure_matrix : array_like, shape (n, m)
        ``A`` (:func:`cdpr_exu.statics.kinematics.structure_matrix`): n = 3 or 6 (planar or spatial), the
        position size for a point mass.
    wrench : array_like, shape (n,) [N, N m]
        Everything but the cables acting on the platform (weight, external load,
        inertia), about the platform's reference point.
    min_tension, max_tension : float or array_like, shape (m,) [N]
        Tension bounds, ``0 <= t_min <= t_max``.
    pose : array_like, optional
        Only named in the error message.

    Returns
    -------
    ndarray, shape (m,) [N]

    Raises
    ------
    SceneError
        Naming the argument: wrong shapes, non-finite values, negative bounds,
        ``min_tension > max_tension``.
    UnreachableError
        "outside the wrench-feasible workspace", naming the pose, if no tensions
        within the bounds balance the wrench.

    Notes
    -----
    **Why this QP and not the improved closed-form method** (Pott, Springer 2018).
    The closed-form method takes ``f = f_mid - A^+ (w + A f_mid)``; that is exactly
    this QP's minimiser whenever no bound is active, so the two agree inside the
    workspace. When a bound is active, the improved closed-form method fixes the
    violating cable at its limit and repeats with the others: a greedy reduction,
    not guaranteed to find a distribution whenever one exists. The QP is: it has a
    unique solution (strictly convex objective) and reports infeasibility only for an
    empty feasible set, so "outside the wrench-feasible workspace" means what it
    says; its solution is the same for symmetric poses of a symmetric robot. The cost
    (a few NNLS iterations on a (m - n + 1) x 2m matrix) is no concern here.

    **How it is solved, exactly and without tolerances to tune.** With the SVD of
    ``A``, ``f = f_p + N lambda``: ``f_p = f_mid + A^+ (-w - A f_mid)`` the point of
    the equality set closest to ``f_mid`` and ``N`` an orthonormal basis of the null
    space of ``A``. Since ``f_p - f_mid`` is orthogonal to ``N``, the QP becomes the
    least-distance programme ``min ||lambda|| s.t. G lambda >= h`` (the bounds), and
    ``A f = -w`` holds to round-off whatever ``lambda``. Lawson and Hanson's LDP
    algorithm (Solving Least Squares Problems, 1974, ch. 23) solves it with one
    non-negative least-squares problem (``scipy.optimize.nnls``, an active-set method
    with finite termination): ``min ||E u - e_last||, u >= 0``, ``E = [G^T; h^T]``.
    A zero residual ``r`` certifies infeasibility; otherwise
    ``lambda = -r[:-1] / r[-1]`` and ``-r[-1] = ||r||^2 = 1 / (1 + ||lambda||^2)``.
    With tensions scaled by the largest tension range, a feasible ``lambda`` has
    ``||lambda|| <= sqrt(m) / 2`` (``||f - f_mid||^2 = ||f_p - f_mid||^2 + ||lambda||^2``
    and every feasible ``f`` is within ``sqrt(m) / 2`` ranges of ``f_mid``), so a
    feasible problem has ``-r[-1] >= 1 / (1 + m / 4)`` (1/3 for 8 cables). The pose is
    refused when ``-r[-1]`` is below half of that (or NNLS reports a residual below
    1e-6); an accepted solution is then checked against the bounds (to 1e-9 of the
    tension range, then clipped onto them), so a rounding error can only refuse, never
    return tensions outside the bounds.
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
    """The wrench of the platform's weight about its centre of mass: the force ``-M g`` along the vertical,
    no moment, shape (n,) [N, N m] as the scene's :func:`~cdpr_exu.statics.kinematics.structure_matrix`
    (gravity 0 where the scene switches it off)."""
    space = scene.space
    wrench = np.zeros(space.position_size if scene.platform.is_point_mass else space.wrench_size)
    wrench[space.vertical] = -scene.platform.mass * (scene.gravity if scene.effects.gravity else 0.0)
    return wrench


def tensions(scene, poses, external_wrench=None) -> np.ndarray:
    """Cable tensions within the cables' limits that hold the platform at pose(s) against its weight.

    Parameters
    ----------
    scene : cdpr_exu.scenes.scene.Scene
        Its cables' ``min_tension`` / ``max_tension`` bound the tensions (0 and inf where not given).
    poses : array_like, shape (pose_size,) or (N, pose_size) [m, rad]
    external_wrench : array_like, shape (n,) [N, N m], optional
        Extra force and moment about the centre of mass, world frame (n as :func:`weight_wrench`).

    Returns
    -------
    ndarray, shape (m,) or (N, m) [N]

    Raises
    ------
    UnreachableError
        "outside the wrench-feasible workspace", naming the pose (and ``poses[k]``, the first such one
        of several), or an anchor the cables cannot reach.
    """
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
