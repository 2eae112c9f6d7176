"""Ideal kinematics of a cable robot, planar or spatial: cable lengths, rates, pull directions, structure matrix.

Pure NumPy/SciPy; no Exudyn. The ideal cables (straight, massless, inextensible) of a
scene are its exits' (:mod:`cdpr_exu.exits`: each computes its cable towards an anchor
with the kernels of :mod:`cdpr_exu.core.geometry`, a planar pulley's, a swivel pulley's, a
point's) at the anchors its :class:`~cdpr_exu.space.Space` places. On those two, written
once for both dimensions: the ideal paid-out lengths and their rates
(:func:`ideal_paid_out`), the directions in which the cables pull the platform
(:func:`pull_directions`), the structure matrix (:func:`structure_matrix`) and the
length Jacobian (:func:`length_jacobian`). The initial node layouts of planar cables are
here too. The tensions that hold the platform: :mod:`cdpr_exu.statics.tension_distribution`.

Sign conventions
----------------
An exit's ``unit_vector`` ``u_i`` points from where the cable leaves the exit towards its
anchor; the cable pulls the platform along ``w_i = -u_i``. The length rate is
``dL_i/dt = u_i . v_i`` (``v_i`` the anchor's velocity: a change of wrap cancels the
motion of the tangent point along the rim, a swivel's turn moves it sideways). The
structure matrix ``A`` has columns ``[w_i; (R b_i) x w_i]``: tensions ``f`` exert the
wrench ``A f`` on the platform, the moment about its reference point (the centre of mass),
the Space's cross product (planar: ``a_x b_z - a_z b_x``, counter-clockwise positive). A
point-mass platform (every anchor at the centre of mass) has the force rows only. With
the pose rate and, in space, the angular velocity ``omega = J_l(theta) dtheta/dt``::

    dL/dt = -A^T (dr/dt, dphi/dt)            (plane)
    dL/d(r, theta) = -A^T blockdiag(I, J_l(theta))   (space)
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import brentq

from cdpr_exu.core.errors import SceneError
from cdpr_exu.core.validation import shown
from cdpr_exu.core.geometry import anchor_points, check_radius, check_side, exit_arrays, finite_array

__all__ = [
    "cable_exits",
    "ideal_paid_out",
    "pull_directions",
    "structure_matrix",
    "length_jacobian",
    "initial_cable_nodes",
    "straight_cable_nodes",
    "anchor_points",  # re-exported for the planar builder and controllers
]


def _anchors(scene) -> np.ndarray:
    return np.asarray(scene.platform.anchors, dtype=float)


def cable_exits(scene, poses: np.ndarray) -> list:
    """Each cable's ideal exit towards its anchor at the platform pose(s) (N, pose_size) or (pose_size,):
    :class:`~cdpr_exu.core.geometry.PulleyExit` (tangent point, wrap, free length, unit vector ``u_i``
    from the exit towards the anchor), one per cable, from its exit (:meth:`cdpr_exu.exits.base.Exit.exit`)."""
    points = scene.space.anchor_points(poses, _anchors(scene))
    return [exit_.exit(points[..., i, :]) for i, exit_ in enumerate(scene.exits)]


def ideal_paid_out(scene, poses: np.ndarray, pose_rates: np.ndarray | None = None):
    """Ideal paid-out lengths (and rates) of every cable for reference poses, planar or spatial.

    Each exit gives its ideal cable to the anchor (:func:`cable_exits`: straight from a point, over a
    pulley's rim or a swivel pulley's disc), its length ``L_i`` and unit vector ``u_i``; the rate is
    ``dL_i/dt = u_i . v_i``, ``v_i`` the anchor's velocity (the scene's :class:`~cdpr_exu.space.Space`).

    Parameters
    ----------
    scene : cdpr_exu.scenes.scene.Scene
    poses : ndarray, shape (N, pose_size) or (pose_size,) [m, rad]
    pose_rates : ndarray, same shape, or None [m/s, rad/s]
        The poses' time derivatives (in space, the rotation vector's rate).

    Returns
    -------
    lengths : ndarray, shape (N, m) or (m,) [m]
    rates : ndarray, shape (N, m) or (m,) [m/s], or None
    """
    exits = cable_exits(scene, poses)
    lengths = np.stack([e.cable_length for e in exits], axis=-1)
    if pose_rates is None:
        return lengths, None
    velocities = scene.space.anchor_velocities(poses, pose_rates, _anchors(scene))
    return lengths, np.stack([np.sum(e.unit_vector * velocities[..., i, :], axis=-1) for i, e in enumerate(exits)],
                             axis=-1)


def pull_directions(scene, poses: np.ndarray) -> np.ndarray:
    """Unit vectors ``w_i = -u_i`` along each cable at its anchor, towards its exit: the direction it pulls the
    platform, shape (m, d) or (N, m, d) for pose(s) (pose_size,) or (N, pose_size)."""
    return np.stack([-e.unit_vector for e in cable_exits(scene, poses)], axis=-2)


def structure_matrix(scene, poses: np.ndarray) -> np.ndarray:
    """Structure (wrench) matrix ``A`` of the platform: cable tensions ``f`` exert the wrench ``A f``.

    Column i is ``[w_i; (R b_i) x w_i]`` (module notes): the force and the moment about the
    centre of mass of a unit tension in cable i; the force rows only for a point mass.

    Parameters
    ----------
    scene : cdpr_exu.scenes.scene.Scene
    poses : ndarray, shape (pose_size,) or (N, pose_size) [m, rad]

    Returns
    -------
    ndarray, shape (n, m) or (N, n, m) [1, m]
        n = the Space's wrench size (3 planar: force x, z, moment; 6 spatial: force x, y, z,
        moment x, y, z), or its position size for a point mass.
    """
    pulls = pull_directions(scene, poses)
    forces = np.swapaxes(pulls, -1, -2)
    if scene.platform.is_point_mass:
        return np.array(forces)
    moments = scene.space.moments(poses, _anchors(scene), pulls)
    return np.concatenate([forces, np.swapaxes(moments, -1, -2)], axis=-2)


def length_jacobian(scene, poses: np.ndarray) -> np.ndarray:
    """``-A^T``: the change of each ideal cable length per platform displacement and small rotation (about
    the world axes, in space; the angle in the plane), shape (m, n) or (N, m, n) (:func:`structure_matrix`).

    Moving the platform by ``d`` and turning it by ``phi`` moves anchor i by ``d + phi x R b_i`` and
    lengthens its cable by ``u_i . (d + phi x R b_i)``; its first position columns are the ``u_i``.
    """
    return -np.swapaxes(structure_matrix(scene, poses), -1, -2)


# --- initial cable configurations
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
