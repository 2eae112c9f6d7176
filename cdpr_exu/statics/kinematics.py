"""Ideal kinematics of a cable robot, planar or spatial: cable lengths, rates, pull directions, structure matrix.

Pure NumPy/SciPy, once for both dimensions: the ideal cables (straight, massless, inextensible) are the
exits' (:mod:`cdpr_exu.exits`) at the anchors the scene's :class:`~cdpr_exu.space.Space` places. The
initial node layouts of planar cables are here too.

Sign conventions
----------------
An exit's ``unit_vector`` ``u_i`` points from where the cable leaves the exit towards its anchor; the
cable pulls the platform along ``w_i = -u_i``. The length rate is ``dL_i/dt = u_i . v_i`` (``v_i`` the
anchor's velocity: a change of wrap cancels the tangent point's motion along the rim). The structure
matrix ``A`` has columns ``[w_i; (R b_i) x w_i]``: tensions ``f`` exert the wrench ``A f`` about the
centre of mass, with the Space's cross product (planar ``a_x b_z - a_z b_x``, counter-clockwise
positive); a point mass has the force rows only. With ``omega = J_l(theta) dtheta/dt`` in space::

    dL/dt = -A^T (dr/dt, dphi/dt)            (plane)
    dL/d(r, theta) = -A^T blockdiag(I, J_l(theta))   (space)
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import brentq

from cdpr_exu.core.errors import SceneError
from cdpr_exu.core.validation import positive, shown, vector
from cdpr_exu.core.geometry import anchor_points, check_radius, check_side, exit_arrays

__all__ = ["cable_exits", "ideal_paid_out", "pull_directions", "structure_matrix", "length_jacobian",
           "initial_cable_nodes", "straight_cable_nodes", "anchor_points"]  # anchor_points: for the builder


def _anchors(scene) -> np.ndarray:
    return np.asarray(scene.platform.anchors, dtype=float)


def cable_exits(scene, poses: np.ndarray) -> list:
    """Each cable's ideal exit towards its anchor at the pose(s) (N, pose_size) or (pose_size,): a
    :class:`~cdpr_exu.core.geometry.PulleyExit` (tangent point, wrap, free length, ``u_i``) per cable."""
    points = scene.space.anchor_points(poses, _anchors(scene))
    return [exit_.exit(points[..., i, :]) for i, exit_ in enumerate(scene.exits)]


def ideal_paid_out(scene, poses: np.ndarray, pose_rates: np.ndarray | None = None):
    """Ideal paid-out lengths ``L_i`` (N, m) or (m,) [m] of every cable at ``poses`` (N, pose_size) or
    (pose_size,) [m, rad], and, given the poses' time derivatives ``pose_rates`` (same shape; in space the
    rotation vector's rate), their rates ``u_i . v_i`` [m/s] (else None)."""
    exits = cable_exits(scene, poses)
    lengths = np.stack([e.cable_length for e in exits], axis=-1)
    if pose_rates is None:
        return lengths, None
    velocities = scene.space.anchor_velocities(poses, pose_rates, _anchors(scene))
    return lengths, np.stack([np.sum(e.unit_vector * velocities[..., i, :], axis=-1) for i, e in enumerate(exits)],
                             axis=-1)


def pull_directions(scene, poses: np.ndarray) -> np.ndarray:
    """Unit vectors ``w_i = -u_i`` along each cable at its anchor, towards its exit, shape (m, d) or (N, m,
    d)."""
    return np.stack([-e.unit_vector for e in cable_exits(scene, poses)], axis=-2)


def structure_matrix(scene, poses: np.ndarray) -> np.ndarray:
    """Structure (wrench) matrix ``A`` at pose(s) (pose_size,) or (N, pose_size): tensions ``f`` exert ``A
    f``.

    Column i ``[w_i; (R b_i) x w_i]`` (module notes), shape (n, m) or (N, n, m) [1, m]: n the Space's wrench
    size (3 planar, 6 spatial), or its position size for a point mass."""
    pulls = pull_directions(scene, poses)
    forces = np.swapaxes(pulls, -1, -2)
    if scene.platform.is_point_mass:
        return np.array(forces)
    moments = scene.space.moments(poses, _anchors(scene), pulls)
    return np.concatenate([forces, np.swapaxes(moments, -1, -2)], axis=-2)


def length_jacobian(scene, poses: np.ndarray) -> np.ndarray:
    """``-A^T``: each ideal cable length's change per platform displacement ``d`` and small rotation ``phi``
    (about the world axes in space), shape (m, n) or (N, m, n): anchor i moves by ``d + phi x R b_i``."""
    return -np.swapaxes(structure_matrix(scene, poses), -1, -2)


def straight_cable_nodes(start, end, n_elements):
    """``n_elements + 1`` evenly spaced nodes (n_elements + 1, 2) [m] from ``start`` to ``end`` (2,) [m]."""
    start, end = vector("start", start, 2, " [m]"), vector("end", end, 2, " [m]")
    n_elements = _check_n_elements(n_elements)
    fraction = np.linspace(0.0, 1.0, n_elements + 1)[:, None]
    return start + fraction * (end - start)


def _check_n_elements(n_elements):
    if isinstance(n_elements, bool) or not isinstance(n_elements, (int, np.integer)) or n_elements < 1:
        raise SceneError(f"n_elements must be an integer >= 1, got {shown(n_elements)}")
    return int(n_elements)


def initial_cable_nodes(center, radius, side, anchor, element_length, n_elements):
    """Nodes (n_elements + 1, 2) [m] of a straight, massless, inextensible cable from its winch over a pulley
    to an anchor, winch end first.

    The paper's initial state: straight from the anchor to the tangent point, over the top of the pulley
    (centre (2,) [m], ``radius`` [m], 0: a point exit; hung on ``side`` -1 | +1) to the hang point, then down
    the winch line. Walking back from ``anchor`` (2,) [m], each node is placed on that path at exactly
    ``element_length`` [m] (chord) from the previous one, so every element starts unstrained; nodes on the
    arc lie on the rim. Each solves ``|P(sigma) - x_prev| = element_length`` for the first arc length
    ``sigma`` beyond the previous node: the distance is 1-Lipschitz in ``sigma``, so stepping by the
    shortfall (at least ``element_length / 1000``) cannot jump over a crossing; Brent's method refines it.

    Raises SceneError for a malformed argument, UnreachableError for an anchor inside the pulley disc.
    """
    center, anchor = vector("center", center, 2, " [m]"), vector("anchor", anchor, 2, " [m]")
    radius, side = check_radius("radius", radius), check_side("side", side)
    element_length = positive("element_length", element_length, "m")
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
