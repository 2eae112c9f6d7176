"""Ideal kinematics of a cable robot: cable lengths, rates and unit vectors, the planar wrench matrix.

Pure NumPy/SciPy; no Exudyn. The ideal cables (straight, massless, inextensible) of a
scene, planar or spatial, are its exits' (:mod:`cdpr_exu.exits`: each computes its cable
with the kernels of :mod:`cdpr_exu.core.geometry`) at the anchors its
:class:`~cdpr_exu.space.Space` places: :func:`cable_exits`, :func:`ideal_paid_out`. The
planar wrench matrix and the initial node layouts of planar cables are here too (the
spatial ones: :mod:`cdpr_exu.physics.spatial_kinematics`). The planar geometry names are
re-exported here for code that imports them from ``cdpr_exu.statics.kinematics``.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import brentq

from cdpr_exu.core.errors import SceneError
from cdpr_exu.core.validation import shown
from cdpr_exu.core.geometry import (anchor_points, anchor_velocities, check_pose_and_anchors, check_radius, check_side,
                                    exit_arrays, finite_array, planar_cross, pulley_exit, rotated_anchors,
                                    rotation_matrix)

#: The geometry names above are re-exported for code that imports them from here.
__all__ = [
    "cable_exits",
    "ideal_paid_out",
    "structure_matrix",
    "initial_cable_nodes",
    "straight_cable_nodes",
]


# ----------------------------------------------------------------------------------
# the whole robot, planar or spatial: through its exits
# ----------------------------------------------------------------------------------
def cable_exits(scene, poses: np.ndarray) -> list:
    """Each cable's ideal exit towards its anchor at the platform pose(s) (N, pose_size) or (pose_size,):
    :class:`~cdpr_exu.core.geometry.PulleyExit` (tangent point, wrap, free length, unit vector ``u_i``
    from the exit towards the anchor), one per cable, from its exit (:meth:`cdpr_exu.exits.base.Exit.exit`)."""
    points = scene.space.anchor_points(poses, np.asarray(scene.platform.anchors, dtype=float))
    return [exit_.exit(points[..., i, :]) for i, exit_ in enumerate(scene.exits)]


def ideal_paid_out(scene, poses: np.ndarray, pose_rates: np.ndarray | None = None):
    """Ideal paid-out lengths (and rates) of every cable for reference poses, planar or spatial.

    Each exit gives its ideal cable to the anchor (:func:`cable_exits`: straight from a point, over a
    pulley's rim or a swivel pulley's disc), its length ``L_i`` and unit vector ``u_i``; the rate is
    ``dL_i/dt = u_i . v_i``, ``v_i`` the anchor's velocity (the scene's :class:`~cdpr_exu.space.Space`).

    Parameters
    ----------
    scene : cdpr_exu.scenes.scene.Scene
    poses : ndarray, shape (N, pose_size) [m, rad]
    pose_rates : ndarray, shape (N, pose_size) or None [m/s, rad/s]
        The poses' time derivatives (in space, the rotation vector's rate).

    Returns
    -------
    lengths : ndarray, shape (N, m) [m]
    rates : ndarray, shape (N, m) [m/s] or None
    """
    exits = cable_exits(scene, poses)
    lengths = np.stack([e.cable_length for e in exits], axis=-1)
    if pose_rates is None:
        return lengths, None
    velocities = scene.space.anchor_velocities(poses, pose_rates, np.asarray(scene.platform.anchors, dtype=float))
    return lengths, np.stack([np.sum(e.unit_vector * velocities[..., i, :], axis=-1) for i, e in enumerate(exits)],
                             axis=-1)


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
        direction of pull: minus the exits' unit vectors, :func:`cable_exits`). Not re-normalised.

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
    center = finite_array("center", center, (2,))
    if center.ndim != 1:
        raise SceneError(f"center must have shape (2,), got shape {center.shape}")
    radius, side = check_radius("radius", radius), check_side("side", side)
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
    hang = np.array([center[0] + side * radius, center[1]])
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
