"""Ideal kinematics and statics of a spatial cable robot over swivel pulleys: lengths, rates, wrenches, tensions.

Pure NumPy/SciPy; no Exudyn. The cables are ideal: straight, massless and
inextensible. z is up, gravity along -z, SI units. A platform pose is
``(r, theta)``, shape (6,): the position ``r`` of its reference point [m] and a
rotation vector ``theta`` [rad]; anchor i is at ``r + R(theta) b_i`` with
``R = exp([theta]x)``, the conventions of :mod:`cdpr_exu.statics.statics`;
the SO(3) helpers are :mod:`cdpr_exu.core.geometry`'s (``rotation_from_vector``,
``left_jacobian``). A
point-mass platform (every cable on one point) has the pose ``r``, shape (3,).

The geometry of one cable over a swivel pulley (its azimuth, tangent point and wrap) and of the
platform (anchor points and velocities, rotation matrices) is :mod:`cdpr_exu.core.geometry`'s.

Sign conventions
----------------
``SwivelExit.unit_vector`` points from the tangent point to the anchor, as in the
planar :class:`cdpr_exu.core.geometry.PulleyExit`. :func:`cable_unit_vectors` returns
``u_i``, the opposite: the direction in which cable i pulls the platform. The
length rate is ``dL_i/dt = -u_i . v_i`` (``v_i`` the anchor's velocity: a change of
wrap exactly cancels the motion of the tangent point along the rim, and a change of
azimuth moves the tangent point sideways, perpendicular to the cable). The
structure matrix ``A`` has columns ``[u_i; (R b_i) x u_i]``: tensions ``f`` exert
the wrench ``A f`` on the platform (moment about ``r``). With the pose rate
``(dr/dt, dtheta/dt)`` and the angular velocity ``omega = J_l(theta) dtheta/dt``::

    dL/d(r, theta) = -A^T blockdiag(I, J_l(theta))
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import nnls

from cdpr_exu.physics.catenary import STANDARD_GRAVITY
from cdpr_exu.core.errors import SceneError, UnreachableError
from cdpr_exu.core.geometry import (check_spatial_pose, finite_array, point3, rotation_from_vector,
                                    spatial_anchor_velocities, spatial_arms, swivel_exit_arrays)
from cdpr_exu.core.validation import non_negative, per_item, shown, vector

__all__ = [
    "robot_exits",
    "inverse_kinematics",
    "inverse_kinematics_rates",
    "cable_unit_vectors",
    "structure_matrix",
    "gravity_wrench",
    "tension_distribution",
    "IdealSpatialRobot",
]

_INFEASIBLE_RESIDUAL = 1e-6
"""NNLS residual below which the least-distance problem is infeasible (a feasible one has ||r|| >= 1/sqrt(1 + m/4))."""

_BOUND_ROUNDING = 1e-9
"""A tension this fraction of the tension range outside its bounds is rounding (and is clipped)."""


def _check_pulleys(n_cables, inlets, pulley_radii):
    inlets = finite_array("inlets", inlets, (3,))
    if inlets.shape != (n_cables, 3):
        raise SceneError(f"inlets must have shape ({n_cables}, 3), got shape {inlets.shape}")
    return inlets, per_item("pulley_radii", pulley_radii, n_cables)


def _check_hints(n_cables, azimuth_hints):
    if azimuth_hints is None:
        return [None] * n_cables
    hints = finite_array("azimuth_hints", azimuth_hints)
    if hints.shape != (n_cables,):
        raise SceneError(f"azimuth_hints must have shape ({n_cables},), got {shown(azimuth_hints)}")
    return [float(h) for h in hints]


def robot_exits(pose, anchors, inlets, pulley_radii, azimuth_hints=None):
    """The :class:`~cdpr_exu.core.geometry.SwivelExit` of every cable for pose(s) (6,)/(N, 6), or positions (3,)/(N, 3) with ``anchors=None``.

    Returns the checked pose, the checked anchors (None for a point mass) and the list of exits.
    """
    pose, anchors = check_spatial_pose(pose, anchors)
    n_cables = len(finite_array("inlets", inlets, (3,)).reshape(-1, 3)) if anchors is None else len(anchors)
    inlets, radii = _check_pulleys(n_cables, inlets, pulley_radii)
    hints = _check_hints(n_cables, azimuth_hints)
    if anchors is None:
        points = np.broadcast_to(pose[..., None, :], pose.shape[:-1] + (n_cables, 3))
    else:
        points = pose[..., None, :3] + spatial_arms(pose, anchors)
    exits = [swivel_exit_arrays(inlets[i], float(radii[i]), np.ascontiguousarray(points[..., i, :]), hints[i])
             for i in range(n_cables)]
    return pose, anchors, exits


def inverse_kinematics(pose, anchors, inlets, pulley_radii, azimuth_hints=None):
    """Ideal cable lengths (inlet over the swivel pulley to the anchor) for platform pose(s).

    Parameters
    ----------
    pose : array_like, shape (6,) or (N, 6) [m, rad]
        Platform pose(s) ``(r, theta)``; a position (3,) or (N, 3) [m] for a point mass.
    anchors : array_like, shape (m, 3) [m], or None
        Anchor points ``b_i`` in the platform frame; None for a point mass (every cable at ``r``).
    inlets : array_like, shape (m, 3) [m]
        Inlet of each cable's swivel pulley (its exit point for a point exit).
    pulley_radii : float or array_like, shape (m,) [m]
        Disc radii; 0 is a point exit.
    azimuth_hints : array_like, shape (m,) [rad], optional
        Azimuth of each pulley for an anchor on its axis (see the module notes).

    Returns
    -------
    ndarray, shape (m,) or (N, m) [m]

    Raises
    ------
    SceneError
        If an argument is malformed; the message names it.
    UnreachableError
        If an anchor is inside a disc, on a point exit, or on a swivel axis with no azimuth to keep.
    """
    _, _, exits = robot_exits(pose, anchors, inlets, pulley_radii, azimuth_hints)
    return np.stack([e.cable_length for e in exits], axis=-1)


def cable_unit_vectors(pose, anchors, inlets, pulley_radii, azimuth_hints=None):
    """Unit vectors ``u_i`` along each cable at its anchor, towards its pulley: the direction it pulls the platform.

    Parameters
    ----------
    pose, anchors, inlets, pulley_radii, azimuth_hints
        As :func:`inverse_kinematics`.

    Returns
    -------
    ndarray, shape (m, 3) or (N, m, 3)
    """
    _, _, exits = robot_exits(pose, anchors, inlets, pulley_radii, azimuth_hints)
    return np.stack([-e.unit_vector for e in exits], axis=-2)


def inverse_kinematics_rates(pose, pose_rate, anchors, inlets, pulley_radii, azimuth_hints=None):
    """Rates of the ideal cable lengths, ``dL_i/dt = -u_i . v_i`` (positive: the winch pays out).

    Parameters
    ----------
    pose : array_like, shape (6,) or (N, 6) [m, rad]
        Platform pose(s); a position (3,) or (N, 3) [m] for a point mass.
    pose_rate : array_like, same shape as ``pose`` [m/s, rad/s]
        ``(dr/dt, dtheta/dt)``, the rate of the rotation vector (see :func:`cdpr_exu.core.geometry.spatial_anchor_velocities`).
    anchors, inlets, pulley_radii, azimuth_hints
        As :func:`inverse_kinematics`.

    Returns
    -------
    ndarray, shape (m,) or (N, m) [m/s]
    """
    pose, anchors, exits = robot_exits(pose, anchors, inlets, pulley_radii, azimuth_hints)
    if anchors is None:
        pose_rate = finite_array("pose_rate", pose_rate, (3,))
        if pose_rate.shape != pose.shape:
            raise SceneError(f"pose_rate must have the shape of pose {pose.shape}, got shape {pose_rate.shape}")
        velocities = np.broadcast_to(pose_rate[..., None, :], pose.shape[:-1] + (len(exits), 3))
    else:
        velocities = spatial_anchor_velocities(pose, pose_rate, anchors)
    return np.stack([np.sum(e.unit_vector * velocities[..., i, :], axis=-1) for i, e in enumerate(exits)], axis=-1)


def structure_matrix(pose, anchors, unit_vectors):
    """Structure (wrench) matrix ``A`` of the platform: cable tensions ``f`` exert the wrench ``A f``.

    Column i is ``[u_i; (R(theta) b_i) x u_i]``: the force and the moment about the
    platform's reference point ``r`` of a unit tension in cable i. For a point mass
    (``anchors=None``) it is the force part only, ``[u_1 ... u_m]``, shape (3, m).

    Parameters
    ----------
    pose : array_like, shape (6,) or (N, 6) [m, rad]
        Platform pose(s); a position (3,) or (N, 3) [m] for a point mass.
    anchors : array_like, shape (m, 3) [m], or None
        Anchor points ``b_i`` in the platform frame; None for a point mass.
    unit_vectors : array_like, shape (m, 3) or (N, m, 3)
        Pull directions ``u_i`` (:func:`cable_unit_vectors`); not re-normalised.

    Returns
    -------
    ndarray, shape (6, m) or (N, 6, m) [1, m]; (3, m) or (N, 3, m) for a point mass
        Rows: force x, y, z; moment x, y, z.

    Notes
    -----
    ``dL/d(r, theta) = -A^T blockdiag(I, J_l(theta))`` (module notes).
    """
    pose, anchors = check_spatial_pose(pose, anchors)
    units = finite_array("unit_vectors", unit_vectors, (3,))
    n_cables = units.shape[-2] if units.ndim >= 2 else 0
    if anchors is not None and (units.ndim < 2 or n_cables != len(anchors)):
        raise SceneError(f"unit_vectors must have shape ({len(anchors)}, 3) or (N, {len(anchors)}, 3), "
                         f"got shape {units.shape}")
    shape = pose.shape[:-1] + (n_cables, 3)
    try:
        units = np.broadcast_to(units, shape)
    except ValueError as exc:
        raise SceneError(f"unit_vectors must have shape {shape}, got shape {units.shape}") from exc
    forces = np.swapaxes(units, -1, -2)
    if anchors is None:
        return np.array(forces)
    moments = np.swapaxes(np.cross(spatial_arms(pose, anchors), units), -1, -2)
    return np.concatenate([forces, moments], axis=-2)


def gravity_wrench(pose, mass, center_of_mass=(0.0, 0.0, 0.0), gravity=STANDARD_GRAVITY):
    """Wrench of the platform's weight about its reference point: ``[(0, 0, -M g); (R c) x (0, 0, -M g)]``.

    Parameters
    ----------
    pose : array_like, shape (6,) [m, rad]
        Platform pose ``(r, theta)``; a position (3,) [m] for a point mass (then the force only).
    mass : float [kg]
    center_of_mass : (float, float, float) [m], optional
        Centre of mass ``c`` in the platform frame (the reference point is at 0).
    gravity : float [m/s^2], optional

    Returns
    -------
    ndarray, shape (6,) [N, N m], or (3,) [N] for a point mass
    """
    pose = finite_array("pose", pose)
    if pose.shape not in ((3,), (6,)):
        raise SceneError(f"pose must have shape (6,) (or (3,) for a point mass), got shape {pose.shape}")
    weight = np.array([0.0, 0.0, -non_negative("mass", mass) * non_negative("gravity", gravity)])
    if pose.shape == (3,):
        return weight
    arm = rotation_from_vector(pose[3:]) @ point3("center_of_mass", center_of_mass)
    return np.concatenate([weight, np.cross(arm, weight)])


# ----------------------------------------------------------------------------------
# tension distribution
# ----------------------------------------------------------------------------------
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
        ``A`` (:func:`structure_matrix`): n = 6 for a rigid platform, 3 for a point mass.
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


# ----------------------------------------------------------------------------------
# a whole robot
# ----------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)  # array fields
class IdealSpatialRobot:
    """A spatial cable robot with ideal cables over swivel pulleys: geometry, mass and tension limits, checked once.

    Parameters
    ----------
    inlets : array_like, shape (m, 3) [m]
        Inlet of each cable's swivel pulley (the exit point when its radius is 0).
    anchors : array_like, shape (m, 3) [m], or None
        Anchors ``b_i`` in the platform frame; None for a point mass (pose = position (3,)).
    pulley_radii : float or array_like, shape (m,) [m]
        Disc radii, 0 for point exits.
    mass : float [kg]
    min_tension, max_tension : float or array_like, shape (m,) [N]
        Tension bounds, ``0 <= min_tension <= max_tension``.
    center_of_mass : (float, float, float) [m], optional
        In the platform frame; ignored for a point mass.
    gravity : float [m/s^2], optional

    Raises
    ------
    SceneError
        Naming the field, if a value is malformed, not finite or out of range.
    """

    inlets: np.ndarray
    anchors: np.ndarray | None
    pulley_radii: float | np.ndarray = 0.0
    mass: float = 0.0
    min_tension: float | np.ndarray = 0.0
    max_tension: float | np.ndarray = np.inf
    center_of_mass: tuple = (0.0, 0.0, 0.0)
    gravity: float = STANDARD_GRAVITY

    def __post_init__(self):
        inlets = finite_array("inlets", self.inlets, (3,))
        if inlets.ndim != 2:
            raise SceneError(f"inlets must have shape (m, 3), got shape {inlets.shape}")
        n_cables = len(inlets)
        if self.anchors is not None:
            anchors = finite_array("anchors", self.anchors, (3,))
            if anchors.shape != (n_cables, 3):
                raise SceneError(f"anchors must have shape ({n_cables}, 3), one per inlet, got shape {anchors.shape}")
            object.__setattr__(self, "anchors", anchors)
        inlets, radii = _check_pulleys(n_cables, inlets, self.pulley_radii)
        lower, upper = _tension_limits(self.min_tension, self.max_tension, n_cables)
        object.__setattr__(self, "inlets", inlets)
        object.__setattr__(self, "pulley_radii", radii)
        object.__setattr__(self, "min_tension", lower)
        object.__setattr__(self, "max_tension", upper)
        object.__setattr__(self, "mass", non_negative("mass", self.mass))
        object.__setattr__(self, "gravity", non_negative("gravity", self.gravity))
        object.__setattr__(self, "center_of_mass", tuple(vector("center_of_mass", self.center_of_mass, 3, " [m]")))

    @property
    def is_point_mass(self):
        """True when the platform is a point mass (no anchors)."""
        return self.anchors is None

    @property
    def n_cables(self):
        """Number of cables m."""
        return len(self.inlets)

    def lengths(self, pose, azimuth_hints=None):
        """Ideal cable lengths (m,) or (N, m) [m]; see :func:`inverse_kinematics`."""
        return inverse_kinematics(pose, self.anchors, self.inlets, self.pulley_radii, azimuth_hints)

    def length_rates(self, pose, pose_rate, azimuth_hints=None):
        """Ideal cable length rates (m,) or (N, m) [m/s]; see :func:`inverse_kinematics_rates`."""
        return inverse_kinematics_rates(pose, pose_rate, self.anchors, self.inlets, self.pulley_radii, azimuth_hints)

    def unit_vectors(self, pose, azimuth_hints=None):
        """Pull directions at the anchors (m, 3) or (N, m, 3); see :func:`cable_unit_vectors`."""
        return cable_unit_vectors(pose, self.anchors, self.inlets, self.pulley_radii, azimuth_hints)

    def structure_matrix(self, pose, azimuth_hints=None):
        """``A``, shape (6, m) or (N, 6, m); (3, m) or (N, 3, m) for a point mass."""
        return structure_matrix(pose, self.anchors, self.unit_vectors(pose, azimuth_hints))

    def gravity_wrench(self, pose):
        """The weight's wrench about the reference point, (6,) [N, N m] or (3,) [N] for a point mass."""
        return gravity_wrench(pose, self.mass, self.center_of_mass, self.gravity)

    def _external(self, external_wrench):
        n_rows = 3 if self.is_point_mass else 6
        if external_wrench is None:
            return np.zeros(n_rows)
        return vector("external_wrench", external_wrench, n_rows, " [N, N m]")

    def tensions(self, pose, external_wrench=None, azimuth_hints=None):
        """Cable tensions (m,) [N] holding the platform at ``pose`` against its weight and ``external_wrench``.

        Parameters
        ----------
        pose : array_like, shape (6,) [m, rad], or (3,) [m] for a point mass
        external_wrench : array_like, shape (6,) [N, N m] (or (3,) [N]), optional
            Extra force and moment about the reference point, world frame.
        azimuth_hints : array_like, shape (m,) [rad], optional

        Raises
        ------
        UnreachableError
            "outside the wrench-feasible workspace" naming the pose (see :func:`tension_distribution`).
        """
        pose_array = finite_array("pose", pose)
        if pose_array.shape != ((3,) if self.is_point_mass else (6,)):
            raise SceneError(f"pose must have shape {(3,) if self.is_point_mass else (6,)}, "
                             f"got shape {pose_array.shape}")
        wrench = self.gravity_wrench(pose_array) + self._external(external_wrench)
        return tension_distribution(self.structure_matrix(pose_array, azimuth_hints), wrench,
                                    self.min_tension, self.max_tension, pose=pose_array)

    def _trajectory(self, poses, external_wrench):
        """Tensions (N, m) along the poses, and the index and error of the first infeasible one (or None)."""
        poses = finite_array("poses", poses, ((3,) if self.is_point_mass else (6,)))
        if poses.ndim != 2:
            raise SceneError(f"poses must have shape (N, {poses.shape[-1]}), got shape {poses.shape}")
        matrices = self.structure_matrix(poses)  # one call: on-axis anchors keep the previous azimuth
        external = self._external(external_wrench)
        result = np.empty((len(poses), self.n_cables))
        for k, (pose, matrix) in enumerate(zip(poses, matrices)):
            try:
                result[k] = tension_distribution(matrix, self.gravity_wrench(pose) + external,
                                                 self.min_tension, self.max_tension, pose=pose)
            except UnreachableError as error:
                return poses, result[:k], (k, error)
        return poses, result, None

    def trajectory_tensions(self, poses, external_wrench=None):
        """Tensions along sampled poses (N, 6) or (N, 3), shape (N, m) [N].

        An anchor on a swivel axis keeps the pulley's azimuth of the previous sample.

        Raises
        ------
        UnreachableError
            At the first pose outside the wrench-feasible workspace, naming its index
            and the pose; or if an anchor is inside a pulley disc.
        """
        _, result, failure = self._trajectory(poses, external_wrench)
        if failure is not None:
            index, error = failure
            raise UnreachableError(f"poses[{index}]: {error}") from None
        return result

    def first_infeasible_pose(self, poses, external_wrench=None):
        """Index and pose of the first sample outside the wrench-feasible workspace, or None if all are inside.

        Parameters
        ----------
        poses : array_like, shape (N, 6) [m, rad], or (N, 3) [m] for a point mass
        external_wrench : array_like, optional

        Returns
        -------
        None, or (int, ndarray)
            The index of the first infeasible sample and its pose.

        Raises
        ------
        SceneError
            If an argument is malformed.
        UnreachableError
            If an anchor is inside a pulley disc (a geometric, not a static, failure).
        """
        poses, _, failure = self._trajectory(poses, external_wrench)
        if failure is None:
            return None
        return failure[0], poses[failure[0]].copy()
