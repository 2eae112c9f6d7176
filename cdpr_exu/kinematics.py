"""Ideal kinematics of a planar cable robot: anchors, pulley tangents, lengths, wrenches.

Pure NumPy/SciPy; no Exudyn. Everything lives in the paper's vertical x-z plane with
gravity along -z. A platform pose is ``(x, z, phi)`` [m, m, rad], ``phi`` positive
counter-clockwise, and a platform anchor is ``p_i = r + R(phi) b_i`` (paper eq. 16) with
``R = [[cos, -sin], [sin, cos]]``.

Pulley convention
-----------------
Each cable comes from its winch straight up the vertical line ``x = c_x + s r_p``
(``s = -1``: the cable hangs on the left side of the pulley, ``s = +1``: on the right),
leaves that line at the *hang point* ``h = (c_x + s r_p, c_z)``, wraps over the top of
the pulley (centre ``c``, radius ``r_p``) by the *wrap angle*, leaves the rim at the
tangent point ``t`` and runs straight to the platform anchor ``p``. In the paper,
pulley 1 at (-1.75, 0) has ``s = -1`` and pulley 2 at (1.75, 0) has ``s = +1``: the
cables hang on the outer sides. ``r_p = 0`` is a point exit at ``c`` (no wrap).

The *ideal cable length* is the length of that path from the hang point to the anchor,
``|p - t| + r_p * wrap``; the vertical part down to the winch is a constant offset.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from cdpr_exu.errors import SceneError, UnreachableError
from cdpr_exu.validation import real_array

__all__ = [
    "PulleyExit",
    "rotation_matrix",
    "planar_cross",
    "anchor_points",
    "anchor_velocities",
    "hang_point",
    "pulley_exit",
    "ideal_cable_length",
    "ideal_cable_length_rate",
    "inverse_kinematics",
    "inverse_kinematics_rates",
    "point_exit_inverse_kinematics",
    "cable_unit_vectors",
    "structure_matrix",
    "initial_cable_nodes",
    "straight_cable_nodes",
]

# A wrap angle this far below zero is rounding, not geometry [rad].
_WRAP_ROUNDING = 1e-9


# ----------------------------------------------------------------------------------
# argument checks
# ----------------------------------------------------------------------------------
def _finite_array(name, value, last_dims=None):
    """Return ``value`` as a finite float array, or raise SceneError naming it."""
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise SceneError(f"{name} must be numeric, got {value!r}") from exc
    if last_dims is not None:
        if array.ndim < len(last_dims) or array.shape[array.ndim - len(last_dims):] != tuple(last_dims):
            raise SceneError(
                f"{name} must have trailing shape {tuple(last_dims)}, got shape {array.shape}: {value!r}"
            )
    if not np.all(np.isfinite(array)):
        raise SceneError(f"{name} must be finite, got {value!r}")
    return array


def _check_radius(name, radius):
    radius = _finite_array(name, radius)
    if radius.ndim != 0:
        raise SceneError(f"{name} must be a scalar, got {radius!r}")
    if radius < 0.0:
        raise SceneError(f"{name} must be >= 0 [m], got {float(radius)!r}")
    return float(radius)


def _check_side(name, side):
    try:
        side_float = float(side)
    except (TypeError, ValueError) as exc:
        raise SceneError(f"{name} must be -1 or +1, got {side!r}") from exc
    if side_float not in (-1.0, 1.0):
        raise SceneError(f"{name} must be -1 (cable on the left) or +1 (on the right), got {side!r}")
    return int(side_float)


# ----------------------------------------------------------------------------------
# small helpers
# ----------------------------------------------------------------------------------
def rotation_matrix(phi):
    """Planar rotation matrix ``R(phi) = [[cos, -sin], [sin, cos]]``.

    Parameters
    ----------
    phi : float or ndarray, shape (...) [rad]
        Rotation angle, positive counter-clockwise in the x-z plane.

    Returns
    -------
    ndarray, shape (..., 2, 2)
    """
    phi = real_array("phi", phi)
    c, s = np.cos(phi), np.sin(phi)
    return np.stack([np.stack([c, -s], axis=-1), np.stack([s, c], axis=-1)], axis=-2)


def planar_cross(a, b):
    """Scalar planar cross product ``a_x b_z - a_z b_x`` (moment about the out-of-plane axis).

    Positive for a counter-clockwise moment, consistent with the platform angle ``phi``.

    Parameters
    ----------
    a, b : ndarray, shape (..., 2)
        Planar vectors, broadcast against each other.

    Returns
    -------
    ndarray, shape (...)
    """
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def _perp(v):
    """Rotate planar vectors by +90 degrees: (x, z) -> (-z, x)."""
    return np.stack([-v[..., 1], v[..., 0]], axis=-1)


def _rotated_anchors(pose, anchors):
    """``R(phi) b_i`` for pose (..., 3) and body anchors (m, 2) -> (..., m, 2)."""
    phi = pose[..., 2][..., None]
    c, s = np.cos(phi), np.sin(phi)
    bx, bz = anchors[:, 0], anchors[:, 1]
    return np.stack([c * bx - s * bz, s * bx + c * bz], axis=-1)


def _check_pose_and_anchors(pose, anchors, pose_name="pose"):
    pose = _finite_array(pose_name, pose, (3,))
    if pose.ndim > 2:
        raise SceneError(f"{pose_name} must have shape (3,) or (N, 3), got shape {pose.shape}")
    anchors = _finite_array("anchors", anchors, (2,))
    if anchors.ndim != 2:
        raise SceneError(f"anchors must have shape (m, 2), got shape {anchors.shape}")
    return pose, anchors


def anchor_points(pose, anchors):
    """World positions of the platform anchors, ``p_i = r + R(phi) b_i`` (paper eq. 16).

    Parameters
    ----------
    pose : array_like, shape (3,) or (N, 3) [m, m, rad]
        Platform pose(s) ``(x, z, phi)``.
    anchors : array_like, shape (m, 2) [m]
        Anchor points ``b_i`` in the platform frame.

    Returns
    -------
    ndarray, shape (m, 2) or (N, m, 2) [m]

    Raises
    ------
    SceneError
        If a shape is wrong or a value is not finite.
    """
    pose, anchors = _check_pose_and_anchors(pose, anchors)
    return pose[..., None, :2] + _rotated_anchors(pose, anchors)


def anchor_velocities(pose, pose_rate, anchors):
    """World velocities of the platform anchors, ``v_i = rdot + phidot * perp(R(phi) b_i)``.

    Parameters
    ----------
    pose : array_like, shape (3,) or (N, 3) [m, m, rad]
        Platform pose(s) ``(x, z, phi)``.
    pose_rate : array_like, same shape as ``pose`` [m/s, m/s, rad/s]
        Pose rate(s) ``(xdot, zdot, phidot)``.
    anchors : array_like, shape (m, 2) [m]
        Anchor points ``b_i`` in the platform frame.

    Returns
    -------
    ndarray, shape (m, 2) or (N, m, 2) [m/s]
    """
    pose, anchors = _check_pose_and_anchors(pose, anchors)
    pose_rate = _finite_array("pose_rate", pose_rate, (3,))
    if pose_rate.shape != pose.shape:
        raise SceneError(f"pose_rate must have the shape of pose {pose.shape}, got shape {pose_rate.shape}")
    arm = _rotated_anchors(pose, anchors)
    return pose_rate[..., None, :2] + pose_rate[..., 2][..., None, None] * _perp(arm)


# ----------------------------------------------------------------------------------
# one cable over one pulley
# ----------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)  # array fields: compare them field by field
class PulleyExit:
    """Where and how an ideal (straight, massless) cable leaves a pulley towards its anchor.

    Attributes
    ----------
    tangent_point : ndarray, shape (2,) or (N, 2) [m]
        Point ``t`` where the cable leaves the rim (the centre for a point exit).
    wrap_angle : float or ndarray, shape (N,) [rad]
        Arc over the top of the pulley from the hang point to ``t``; in ``[0, 3 pi / 2)``.
        Above ``pi`` when the anchor is below the pulley on its inner side; 0 for a
        point exit.
    free_length : float or ndarray, shape (N,) [m]
        Straight length ``|p - t|``.
    unit_vector : ndarray, shape (2,) or (N, 2)
        Unit vector from ``t`` towards the anchor ``p`` (opposite to the pull on the platform).
    arc_length : float or ndarray, shape (N,) [m]
        Wrapped length ``r_p * wrap_angle``.
    """

    tangent_point: np.ndarray
    wrap_angle: float | np.ndarray
    free_length: float | np.ndarray
    unit_vector: np.ndarray
    arc_length: float | np.ndarray

    @property
    def cable_length(self):
        """Ideal length from the hang point to the anchor, ``free_length + arc_length`` [m]."""
        return self.free_length + self.arc_length


def hang_point(center, radius, side):
    """Point ``h = (c_x + s r_p, c_z)`` where the cable leaves its vertical winch line.

    Parameters
    ----------
    center : array_like, shape (2,) [m]
        Pulley centre ``c``.
    radius : float [m]
        Pulley radius ``r_p >= 0``.
    side : {-1, +1}
        Side of the pulley on which the cable hangs (-1 left, +1 right).

    Returns
    -------
    ndarray, shape (2,) [m]
    """
    center = _finite_array("center", center, (2,))
    if center.ndim != 1:
        raise SceneError(f"center must have shape (2,), got shape {center.shape}")
    radius = _check_radius("radius", radius)
    side = _check_side("side", side)
    return center + np.array([side * radius, 0.0])


def _exit_arrays(center, radius, side, anchor):
    """Vectorised core of :func:`pulley_exit` on checked arguments; anchor (..., 2)."""
    delta = anchor - center
    distance = np.hypot(delta[..., 0], delta[..., 1])
    if radius > 0.0:
        inside = distance <= radius
        if np.any(inside):
            bad = anchor[inside] if anchor.ndim > 1 else anchor
            raise UnreachableError(
                f"anchor {np.asarray(bad).tolist()} lies inside the pulley disc "
                f"(centre {center.tolist()}, radius {radius} m)"
            )
    elif np.any(distance == 0.0):
        raise UnreachableError(f"anchor coincides with the point exit {center.tolist()}")
    # the anchor direction from the centre, and the half-angle between it and the tangent
    beta = np.arctan2(delta[..., 1], delta[..., 0])
    alpha = np.arccos(np.clip(radius / distance, -1.0, 1.0))
    angle_t = beta - side * alpha  # rim angle of the tangent point
    angle_h = np.pi if side < 0 else 0.0  # rim angle of the hang point
    # the cable travels from h over the top: counter-clockwise for s = +1, clockwise for s = -1
    wrap = np.mod(side * (angle_t - angle_h) + np.pi / 2.0, 2.0 * np.pi) - np.pi / 2.0
    if radius > 0.0:
        backwards = wrap < -_WRAP_ROUNDING
        if np.any(backwards):
            bad = anchor[backwards] if anchor.ndim > 1 else anchor
            raise UnreachableError(
                f"anchor {np.asarray(bad).tolist()} is above the pulley on the outer side of its "
                f"vertical cable line (centre {center.tolist()}, radius {radius} m, side {side}): "
                "the cable would reach it without touching the pulley"
            )
        wrap = np.maximum(wrap, 0.0)
    else:
        wrap = np.zeros_like(distance)  # a point exit does not wrap
    normal = np.stack([np.cos(angle_t), np.sin(angle_t)], axis=-1)
    tangent_point = center + radius * normal
    unit_vector = side * _perp(normal)  # direction of travel at t, = (p - t) / |p - t|
    free_length = np.sqrt(np.maximum(distance**2 - radius**2, 0.0))
    return tangent_point, wrap, free_length, unit_vector


def _check_pulley(center, radius, side, anchor):
    center = _finite_array("center", center, (2,))
    if center.ndim != 1:
        raise SceneError(f"center must have shape (2,), got shape {center.shape}")
    radius = _check_radius("radius", radius)
    side = _check_side("side", side)
    anchor = _finite_array("anchor", anchor, (2,))
    return center, radius, side, anchor


def pulley_exit(center, radius, side, anchor):
    """Tangent point, wrap angle and free length of a cable running over a pulley to an anchor.

    Parameters
    ----------
    center : array_like, shape (2,) [m]
        Pulley centre ``c``.
    radius : float [m]
        Pulley radius ``r_p >= 0``; 0 is a point exit at ``c``.
    side : {-1, +1}
        Side on which the cable hangs towards its winch (-1 left, +1 right).
    anchor : array_like, shape (2,) or (N, 2) [m]
        Platform anchor(s) ``p`` in the world frame.

    Returns
    -------
    PulleyExit
        Fields of shape (2,) and scalars, or (N, 2) and (N,) for N anchors.

    Raises
    ------
    SceneError
        If an argument is malformed or not finite, or ``side`` is not -1 or +1.
    UnreachableError
        If an anchor is inside the pulley disc (or on the point exit), or above the
        pulley on the outer side of the vertical cable line (negative wrap).

    Notes
    -----
    With ``beta`` the direction of ``p - c`` and ``alpha = arccos(r_p / |p - c|)``, the
    tangent point is at rim angle ``beta - s alpha``; the wrap angle is measured from the
    hang point over the top of the pulley. For the paper's cable 1 (``c = (-1.75, 0)``,
    ``r_p = 0.25``, ``s = -1``, ``p = (-0.15, -1.9)``) the wrap is about 145.7 degrees and
    the free length about 2.471 m.
    """
    center, radius, side, anchor = _check_pulley(center, radius, side, anchor)
    tangent_point, wrap, free_length, unit_vector = _exit_arrays(center, radius, side, anchor)
    if anchor.ndim == 1:
        wrap, free_length = float(wrap), float(free_length)
    return PulleyExit(
        tangent_point=tangent_point,
        wrap_angle=wrap,
        free_length=free_length,
        unit_vector=unit_vector,
        arc_length=radius * wrap,
    )


def ideal_cable_length(center, radius, side, anchor):
    """Ideal cable length from the hang point over the pulley to the anchor.

    ``L = |p - t| + r_p * wrap``: straight, massless, inextensible cable.

    Parameters
    ----------
    center : array_like, shape (2,) [m]
        Pulley centre.
    radius : float [m]
        Pulley radius (0: point exit, ``L = |p - c|``).
    side : {-1, +1}
        Side on which the cable hangs.
    anchor : array_like, shape (2,) or (N, 2) [m]
        Platform anchor(s) in the world frame.

    Returns
    -------
    float or ndarray, shape (N,) [m]

    Raises
    ------
    SceneError, UnreachableError
        As :func:`pulley_exit`.
    """
    return pulley_exit(center, radius, side, anchor).cable_length


def ideal_cable_length_rate(center, radius, side, anchor, anchor_velocity):
    """Rate of the ideal cable length for an anchor moving at ``anchor_velocity``.

    ``dL/dt = u . v`` with ``u`` the unit vector from the tangent point to the anchor:
    the change of wrap exactly cancels the tangential motion of the tangent point.

    Parameters
    ----------
    center : array_like, shape (2,) [m]
    radius : float [m]
    side : {-1, +1}
    anchor : array_like, shape (2,) or (N, 2) [m]
    anchor_velocity : array_like, same shape as ``anchor`` [m/s]

    Returns
    -------
    float or ndarray, shape (N,) [m/s]
    """
    exit_ = pulley_exit(center, radius, side, anchor)
    velocity = _finite_array("anchor_velocity", anchor_velocity, (2,))
    if velocity.shape != exit_.unit_vector.shape:
        raise SceneError(
            f"anchor_velocity must have the shape of anchor {exit_.unit_vector.shape}, got {velocity.shape}"
        )
    rate = np.sum(exit_.unit_vector * velocity, axis=-1)
    return float(rate) if rate.ndim == 0 else rate


# ----------------------------------------------------------------------------------
# the whole robot
# ----------------------------------------------------------------------------------
def _check_pulleys(n_cables, pulley_centers, pulley_radii, sides):
    centers = _finite_array("pulley_centers", pulley_centers, (2,))
    if centers.shape != (n_cables, 2):
        raise SceneError(f"pulley_centers must have shape ({n_cables}, 2), got shape {centers.shape}")
    radii = _finite_array("pulley_radii", pulley_radii)
    if radii.ndim == 0:
        radii = np.full(n_cables, float(radii))
    if radii.shape != (n_cables,):
        raise SceneError(f"pulley_radii must be a scalar or have shape ({n_cables},), got {pulley_radii!r}")
    if np.any(radii < 0.0):
        raise SceneError(f"pulley_radii must be >= 0 [m], got {pulley_radii!r}")
    sides_array = np.broadcast_to(np.asarray(sides), (n_cables,)) if np.ndim(sides) == 0 else np.asarray(sides)
    if sides_array.shape != (n_cables,):
        raise SceneError(f"sides must have shape ({n_cables},), got {sides!r}")
    side_list = [_check_side(f"sides[{i}]", value) for i, value in enumerate(sides_array)]
    return centers, radii, side_list


def _robot_exits(pose, anchors, pulley_centers, pulley_radii, sides):
    """Per-cable exits for pose (..., 3): lists of (tangent, wrap, free, unit) arrays."""
    pose, anchors = _check_pose_and_anchors(pose, anchors)
    centers, radii, side_list = _check_pulleys(len(anchors), pulley_centers, pulley_radii, sides)
    points = pose[..., None, :2] + _rotated_anchors(pose, anchors)
    exits = [
        _exit_arrays(centers[i], float(radii[i]), side_list[i], points[..., i, :]) for i in range(len(anchors))
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
    centers = _finite_array("pulley_centers", pulley_centers, (2,))
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
    pose, anchors = _check_pose_and_anchors(pose, anchors)
    units = _finite_array("unit_vectors", unit_vectors, (2,))
    arm = _rotated_anchors(pose, anchors)
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
    start = _finite_array("start", start, (2,))
    end = _finite_array("end", end, (2,))
    if start.ndim != 1 or end.ndim != 1:
        raise SceneError(f"start and end must have shape (2,), got {start.shape} and {end.shape}")
    n_elements = _check_n_elements(n_elements)
    fraction = np.linspace(0.0, 1.0, n_elements + 1)[:, None]
    return start + fraction * (end - start)


def _check_n_elements(n_elements):
    if isinstance(n_elements, bool) or not isinstance(n_elements, (int, np.integer)) or n_elements < 1:
        raise SceneError(f"n_elements must be an integer >= 1, got {n_elements!r}")
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
    center, radius, side, anchor = _check_pulley(center, radius, side, anchor)
    if anchor.ndim != 1:
        raise SceneError(f"anchor must have shape (2,), got shape {anchor.shape}")
    element_length = _finite_array("element_length", element_length)
    if element_length.ndim != 0 or element_length <= 0.0:
        raise SceneError(f"element_length must be a scalar > 0 [m], got {element_length!r}")
    element_length = float(element_length)
    n_elements = _check_n_elements(n_elements)

    tangent_point, wrap, free_length, unit_vector = _exit_arrays(center, radius, side, anchor)
    wrap, free_length = float(wrap), float(free_length)
    arc_end = free_length + radius * wrap
    hang = center + np.array([side * radius, 0.0])
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
