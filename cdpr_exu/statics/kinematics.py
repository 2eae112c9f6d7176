"""Ideal kinematics of a planar cable robot: cable lengths, rates, unit vectors, wrenches.

Pure NumPy/SciPy; no Exudyn. Poses, anchors and the pulley convention (hang point,
wrap, tangent point, ideal cable length) are defined once in :mod:`cdpr_exu.core.geometry`;
this module applies them to the whole robot. The geometry names are re-exported here
for code that imports them from ``cdpr_exu.statics.kinematics``.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import brentq

from cdpr_exu.core.errors import SceneError
from cdpr_exu.core.validation import per_item, shown
from cdpr_exu.core.geometry import (
    PulleyExit,
    Pulley,
    anchor_points,
    anchor_velocities,
    check_pose_and_anchors,
    check_side,
    exit_arrays,
    finite_array,
    hang_point,
    ideal_cable_length,
    ideal_cable_length_rate,
    planar_cross,
    pulley_exit,
    rotated_anchors,
    rotation_matrix,
)

#: The geometry names above are re-exported for code that imports them from here.
__all__ = [
    "inverse_kinematics",
    "inverse_kinematics_rates",
    "point_exit_inverse_kinematics",
    "pulley_arrays",
    "cable_unit_vectors",
    "structure_matrix",
    "initial_cable_nodes",
    "straight_cable_nodes",
]


# ----------------------------------------------------------------------------------
# the whole robot
# ----------------------------------------------------------------------------------
def _check_pulleys(n_cables, pulley_centers, pulley_radii, sides):
    centers = finite_array("pulley_centers", pulley_centers, (2,))
    if centers.shape != (n_cables, 2):
        raise SceneError(f"pulley_centers must have shape ({n_cables}, 2), got shape {centers.shape}")
    radii = per_item("pulley_radii", pulley_radii, n_cables)
    sides_array = np.broadcast_to(np.asarray(sides), (n_cables,)) if np.ndim(sides) == 0 else np.asarray(sides)
    if sides_array.shape != (n_cables,):
        raise SceneError(f"sides must have shape ({n_cables},), got {shown(sides)}")
    side_list = [check_side(f"sides[{i}]", value) for i, value in enumerate(sides_array)]
    return centers, radii, side_list


def pulley_arrays(pulleys):
    """Centres (m, 2) [m], radii (m,) [m] and sides (m,) of a sequence of :class:`~cdpr_exu.core.geometry.Pulley`,
    the arguments of the robot-level functions below."""
    centers = np.array([p.center for p in pulleys], dtype=float).reshape(-1, 2)
    return centers, np.array([p.radius for p in pulleys], dtype=float), np.array([p.side for p in pulleys], dtype=int)


def _robot_exits(pose, anchors, pulley_centers, pulley_radii, sides):
    """Per-cable exits for pose (..., 3): lists of (tangent, wrap, free, unit) arrays."""
    pose, anchors = check_pose_and_anchors(pose, anchors)
    centers, radii, side_list = _check_pulleys(len(anchors), pulley_centers, pulley_radii, sides)
    points = pose[..., None, :2] + rotated_anchors(pose, anchors)
    exits = [
        exit_arrays(centers[i], float(radii[i]), side_list[i], points[..., i, :]) for i in range(len(anchors))
    ]
    return pose, anchors, radii, exits


def inverse_kinematics(pose, anchors, pulley_centers, pulley_radii, sides):
    """Ideal cable lengths (hang point to anchor) for platform pose(s).

    Parameters
    ----------
    pose : array_like, shape (3,) or (N, 3) [m, m, rad]
        Platform pose(s) ``(x, z, phi)``.
    anchors : array_like, shape (m, 2) [m]
        Anchor points ``b_i`` in the platform frame.
    pulley_centers : array_like, shape (m, 2) [m]
        Centre of the pulley of each cable.
    pulley_radii : float or array_like, shape (m,) [m]
        Pulley radii; 0 is a point exit.
    sides : array_like, shape (m,), values in {-1, +1}
        Side on which each cable hangs towards its winch.

    Returns
    -------
    ndarray, shape (m,) or (N, m) [m]

    Raises
    ------
    SceneError
        If an argument is malformed.
    UnreachableError
        If an anchor is inside a pulley or beyond the outer vertical cable line.
    """
    _, _, radii, exits = _robot_exits(pose, anchors, pulley_centers, pulley_radii, sides)
    return np.stack([free + radii[i] * wrap for i, (_, wrap, free, _) in enumerate(exits)], axis=-1)


def inverse_kinematics_rates(pose, pose_rate, anchors, pulley_centers, pulley_radii, sides):
    """Rates of the ideal cable lengths, ``dL_i/dt = u_i . v_i`` (the winch reeling rates).

    Parameters
    ----------
    pose : array_like, shape (3,) or (N, 3) [m, m, rad]
        Platform pose(s).
    pose_rate : array_like, same shape as ``pose`` [m/s, m/s, rad/s]
        Pose rate(s) ``(xdot, zdot, phidot)``.
    anchors, pulley_centers, pulley_radii, sides
        As :func:`inverse_kinematics`.

    Returns
    -------
    ndarray, shape (m,) or (N, m) [m/s]
        Positive when the cable between pulley and platform lengthens (winch pays out).
    """
    pose, anchors, _, exits = _robot_exits(pose, anchors, pulley_centers, pulley_radii, sides)
    velocities = anchor_velocities(pose, pose_rate, anchors)
    return np.stack([np.sum(unit * velocities[..., i, :], axis=-1) for i, (_, _, _, unit) in enumerate(exits)], axis=-1)


def point_exit_inverse_kinematics(pose, anchors, pulley_centers):
    """Ideal cable lengths with point exits: the distances ``|p_i - c_i|``.

    Parameters
    ----------
    pose : array_like, shape (3,) or (N, 3) [m, m, rad]
    anchors : array_like, shape (m, 2) [m]
    pulley_centers : array_like, shape (m, 2) [m]
        Cable exit points.

    Returns
    -------
    ndarray, shape (m,) or (N, m) [m]
    """
    points = anchor_points(pose, anchors)
    centers = finite_array("pulley_centers", pulley_centers, (2,))
    if centers.shape != (points.shape[-2], 2):
        raise SceneError(f"pulley_centers must have shape ({points.shape[-2]}, 2), got shape {centers.shape}")
    return np.linalg.norm(points - centers, axis=-1)


def cable_unit_vectors(pose, anchors, pulley_centers, pulley_radii, sides):
    """Unit vectors along each cable from its platform anchor towards its pulley.

    These are the directions in which the cables pull on the platform, ready for
    :func:`structure_matrix` (``-PulleyExit.unit_vector``).

    Parameters
    ----------
    pose, anchors, pulley_centers, pulley_radii, sides
        As :func:`inverse_kinematics`.

    Returns
    -------
    ndarray, shape (m, 2) or (N, m, 2)
    """
    _, _, _, exits = _robot_exits(pose, anchors, pulley_centers, pulley_radii, sides)
    return np.stack([-unit for (_, _, _, unit) in exits], axis=-2)


def structure_matrix(pose, anchors, unit_vectors):
    """Wrench (structure) matrix ``A`` of the platform: cable tensions ``f`` give wrench ``A f``.

    Column i is ``[w_i; (R(phi) b_i) x w_i]``, the force and the moment about the
    platform reference point of a unit tension in cable i.

    Parameters
    ----------
    pose : array_like, shape (3,) or (N, 3) [m, m, rad]
        Platform pose(s).
    anchors : array_like, shape (m, 2) [m]
        Anchor points ``b_i`` in the platform frame.
    unit_vectors : array_like, shape (m, 2) or (N, m, 2)
        Unit vectors ``w_i`` from each anchor towards its cable's exit point (the
        direction of pull, see :func:`cable_unit_vectors`). Not re-normalised.

    Returns
    -------
    ndarray, shape (3, m) or (N, 3, m) [1, 1, m]
        Rows: force x, force z, moment (counter-clockwise positive).

    Notes
    -----
    The length rates of the ideal cables are ``dL/dt = -A^T (xdot, zdot, phidot)``.
    """
    pose, anchors = check_pose_and_anchors(pose, anchors)
    units = finite_array("unit_vectors", unit_vectors, (2,))
    arm = rotated_anchors(pose, anchors)
    try:
        units = np.broadcast_to(units, arm.shape)
    except ValueError as exc:
        raise SceneError(f"unit_vectors must have shape {arm.shape}, got shape {units.shape}") from exc
    moment = planar_cross(arm, units)
    return np.concatenate([np.swapaxes(units, -1, -2), moment[..., None, :]], axis=-2)


# ----------------------------------------------------------------------------------
# initial cable configurations
# ----------------------------------------------------------------------------------
def straight_cable_nodes(start, end, n_elements):
    """Evenly spaced nodes on the segment from ``start`` to ``end``.

    Parameters
    ----------
    start, end : array_like, shape (2,) [m]
        First and last node.
    n_elements : int
        Number of elements (>= 1).

    Returns
    -------
    ndarray, shape (n_elements + 1, 2) [m]
        Node 0 at ``start``, node ``n_elements`` at ``end``.
    """
    start = finite_array("start", start, (2,))
    end = finite_array("end", end, (2,))
    if start.ndim != 1 or end.ndim != 1:
        raise SceneError(f"start and end must have shape (2,), got {start.shape} and {end.shape}")
    n_elements = _check_n_elements(n_elements)
    fraction = np.linspace(0.0, 1.0, n_elements + 1)[:, None]
    return start + fraction * (end - start)


def _check_n_elements(n_elements):
    if isinstance(n_elements, bool) or not isinstance(n_elements, (int, np.integer)) or n_elements < 1:
        raise SceneError(f"n_elements must be an integer >= 1, got {shown(n_elements)}")
    return int(n_elements)


def initial_cable_nodes(center, radius, side, anchor, element_length, n_elements):
    """Nodes of a straight, massless, inextensible cable from its winch over a pulley to an anchor.

    The paper's initial state: the cable runs straight from the anchor to the tangent
    point, over the top of the pulley to the hang point, then down the vertical winch
    line. Walking backwards from the anchor, each node is placed on that path at exactly
    ``element_length`` (chord) from the previous one, so that every element starts at
    its unstrained length; nodes on the arc lie on the rim.

    Parameters
    ----------
    center : array_like, shape (2,) [m]
        Pulley centre.
    radius : float [m]
        Pulley radius; 0 is a point exit (straight to the centre, then down).
    side : {-1, +1}
        Side on which the cable hangs towards its winch.
    anchor : array_like, shape (2,) [m]
        Platform anchor in the world frame (the last node).
    element_length : float [m]
        Unstrained element length ``l0 / n`` (> 0).
    n_elements : int
        Number of elements (>= 1).

    Returns
    -------
    ndarray, shape (n_elements + 1, 2) [m]
        Node 0 at the winch end, node ``n_elements`` at the anchor.

    Raises
    ------
    SceneError
        If an argument is malformed.
    UnreachableError
        If the anchor is inside the pulley disc (or beyond the outer vertical line).

    Notes
    -----
    Each node solves ``|P(sigma) - x_prev| = element_length`` for the first path
    parameter ``sigma`` beyond the previous node, ``P`` the path parametrised by arc
    length from the anchor. The distance is 1-Lipschitz in ``sigma``, so stepping by the
    current shortfall (never less than ``element_length / 1000``) cannot jump over a
    crossing wider than that step; the bracket is then refined with Brent's method.
    """
    pulley = Pulley(center, radius, side)
    center, radius, side = np.asarray(pulley.center), pulley.radius, pulley.side
    anchor = finite_array("anchor", anchor, (2,))
    if anchor.ndim != 1:
        raise SceneError(f"anchor must have shape (2,), got shape {anchor.shape}")
    element_length = finite_array("element_length", element_length)
    if element_length.ndim != 0 or element_length <= 0.0:
        raise SceneError(f"element_length must be a scalar > 0 [m], got {shown(element_length)}")
    element_length = float(element_length)
    n_elements = _check_n_elements(n_elements)

    tangent_point, wrap, free_length, unit_vector = exit_arrays(center, radius, side, anchor)
    wrap, free_length = float(wrap), float(free_length)
    arc_end = free_length + radius * wrap
    hang = pulley.hang_point
    angle_t = np.arctan2(tangent_point[1] - center[1], tangent_point[0] - center[0])

    def path(sigma):
        if sigma <= free_length:
            return anchor - sigma * unit_vector
        if sigma <= arc_end:
            # back from the tangent point towards the hang point
            angle = angle_t - side * (sigma - free_length) / radius
            return center + radius * np.array([np.cos(angle), np.sin(angle)])
        return hang - np.array([0.0, sigma - arc_end])

    min_step = 1e-3 * element_length
    nodes = np.empty((n_elements + 1, 2))
    nodes[-1] = anchor
    sigma_prev = 0.0
    for k in range(n_elements - 1, -1, -1):
        previous = nodes[k + 1]

        def shortfall(sigma, previous=previous):
            return np.linalg.norm(path(sigma) - previous) - element_length

        # a chord is never longer than its arc, so the root is at or beyond sigma_prev + l
        sigma = sigma_prev + element_length
        value = shortfall(sigma)
        if value < 0.0:
            while True:
                sigma_next = sigma + max(-value, min_step)
                value_next = shortfall(sigma_next)
                if value_next >= 0.0:
                    sigma = brentq(shortfall, sigma, sigma_next, xtol=1e-14, rtol=4 * np.finfo(float).eps)
                    break
                sigma, value = sigma_next, value_next
        nodes[k] = path(sigma)
        sigma_prev = sigma
    return nodes
