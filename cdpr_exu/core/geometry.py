"""Geometry of a cable robot: poses, rotations, anchor points, pulley exits (one home each).

Pure NumPy; no Exudyn. Units SI. A planar robot lives in the paper's vertical x-z plane
(the builder maps it onto Exudyn's x-y plane: Exudyn's y is the paper's z); its pose is
``(x, z, phi)`` [m, m, rad], ``phi`` counter-clockwise, and an anchor is
``p_i = r + R(phi) b_i`` (paper eq. 16). A spatial robot (z up) turns its platform by a
rotation vector ``theta`` [rad], ``R = exp([theta]x)``.

Pulley convention
-----------------
Each cable comes from its winch up the vertical line ``x = c_x + s r_p`` (``s = -1``: on
the pulley's left, ``+1``: right), leaves it at the *hang point* ``h = (c_x + s r_p, c_z)``,
wraps over the top of the pulley (centre ``c``, radius ``r_p``) by the *wrap angle*, leaves
the rim at the tangent point ``t`` and runs straight to the anchor ``p``. The paper's
pulleys at (-1.75, 0) and (1.75, 0) have ``s = -1`` and ``+1`` (cables on the outer sides).
``r_p = 0`` is a point exit. The *ideal cable length* is ``|p - t| + r_p * wrap``; the
*paid-out length* lambda is the cable beyond the hang point: a cable of unstrained length
``L0`` has its winch end at ``h - (0, L0 - lambda)``.

Swivel pulley
-------------
A swivel pulley turns about the vertical axis through its **inlet** ``e`` (3,), where the
cable leaves the axis (it hangs down the axis to its winch) onto the disc, which lies in
the vertical plane through the axis and the anchor. Its **azimuth** is
``psi = atan2(p_y - e_y, p_x - e_x)``. In that plane, with ``(rho, z) = ((p - e) . e_rho,
p_z - e_z)``, the cable is the planar one of a pulley at ``(r_p, 0)``, radius ``r_p``,
``side = -1`` (its hang point is the inlet), mapped back by ``(rho, z) -> e + rho e_rho + z e_z``.
As ``rho >= 0`` every anchor outside the disc is reachable (wrap up to 3 pi / 2); a winch
above the pulley (the mirror image) is not covered. An anchor on the axis (``rho`` below
1e-12 of ``|p - e| + r_p``) has no azimuth: the previous pose's of the same call, else
``azimuth_hint``, is kept; with neither the pose is refused for ``r_p > 0`` (a point exit's
vertical cable takes 0).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from cdpr_exu.core.errors import SceneError, UnreachableError
from cdpr_exu.core.validation import non_negative, real_array, shown

# A wrap angle this far below zero is rounding, not geometry [rad].
_WRAP_ROUNDING = 1e-9


def all_at_centre(anchors) -> bool:
    """True when every anchor [m] sits exactly at the centre of mass: a point-mass platform."""
    return not np.any(np.asarray(anchors, dtype=float))


def finite_array(name, value, last_dims=None):
    """Return ``value`` as a finite float array, or raise SceneError naming it."""
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise SceneError(f"{name} must be numeric, got {shown(value)}") from exc
    if last_dims is not None:
        if array.ndim < len(last_dims) or array.shape[array.ndim - len(last_dims):] != tuple(last_dims):
            raise SceneError(
                f"{name} must have trailing shape {tuple(last_dims)}, got shape {array.shape}: {shown(value)}"
            )
    if not np.all(np.isfinite(array)):
        raise SceneError(f"{name} must be finite, got {shown(value)}")
    return array


def check_radius(name, radius):
    radius = finite_array(name, radius)
    if radius.ndim != 0:
        raise SceneError(f"{name} must be a scalar, got {shown(radius)}")
    if radius < 0.0:
        raise SceneError(f"{name} must be >= 0 [m], got {shown(float(radius))}")
    return float(radius)


def check_side(name, side):
    try:
        side_float = float(side)
    except (TypeError, ValueError) as exc:
        raise SceneError(f"{name} must be -1 or +1, got {shown(side)}") from exc
    if side_float not in (-1.0, 1.0):
        raise SceneError(f"{name} must be -1 (cable on the left) or +1 (on the right), got {shown(side)}")
    return int(side_float)


def rotation_matrix(phi):
    """Planar rotation matrix ``R(phi) = [[cos, -sin], [sin, cos]]`` (..., 2, 2) of ``phi`` (...) [rad]."""
    if isinstance(phi, (float, int)) and not isinstance(phi, bool) and math.isfinite(phi):
        c, s = math.cos(phi), math.sin(phi)  # one angle: the statics' Newton loops call this often
        return np.array([[c, -s], [s, c]])
    phi = real_array("phi", phi)
    c, s = np.cos(phi), np.sin(phi)
    return np.stack([np.stack([c, -s], axis=-1), np.stack([s, c], axis=-1)], axis=-2)


def planar_cross(a, b):
    """Planar cross product ``a_x b_z - a_z b_x`` of (..., 2) vectors, (...): counter-clockwise positive."""
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def perpendicular(v):
    """Rotate planar vectors by +90 degrees: (x, z) -> (-z, x)."""
    return np.stack([-v[..., 1], v[..., 0]], axis=-1)


def rotated_anchors(pose, anchors):
    """``R(phi) b_i`` for pose (..., 3) and body anchors (m, 2) -> (..., m, 2)."""
    phi = pose[..., 2][..., None]
    c, s = np.cos(phi), np.sin(phi)
    bx, bz = anchors[:, 0], anchors[:, 1]
    return np.stack([c * bx - s * bz, s * bx + c * bz], axis=-1)


def check_pose_and_anchors(pose, anchors, pose_rate=None, sizes=(3, 2), pose_name="pose"):
    """Pose(s) (w,) or (N, w), anchors (m, d) and optionally ``pose_rate`` (the pose's shape) as finite float
    arrays, ``sizes`` = (w, d): (3, 2) planar, (6, 3) spatial; SceneError naming a wrong one."""
    width, d = sizes
    pose = finite_array(pose_name, pose, (width,))
    if pose.ndim > 2:
        raise SceneError(f"{pose_name} must have shape ({width},) or (N, {width}), got shape {pose.shape}")
    anchors = finite_array("anchors", anchors, (d,))
    if anchors.ndim != 2:
        raise SceneError(f"anchors must have shape (m, {d}), got shape {anchors.shape}")
    if pose_rate is None:
        return pose, anchors
    pose_rate = finite_array("pose_rate", pose_rate, (width,))
    if pose_rate.shape != pose.shape:
        raise SceneError(f"pose_rate must have the shape of pose {pose.shape}, got shape {pose_rate.shape}")
    return pose, anchors, pose_rate


def anchor_points(pose, anchors):
    """World positions ``p_i = r + R(phi) b_i`` (paper eq. 16), shape (m, 2) or (N, m, 2) [m], of the
    anchors (m, 2) [m] at pose(s) ``(x, z, phi)`` (3,) or (N, 3) [m, m, rad]."""
    pose, anchors = check_pose_and_anchors(pose, anchors)
    return pose[..., None, :2] + rotated_anchors(pose, anchors)


def anchor_velocities(pose, pose_rate, anchors):
    """World velocities ``v_i = rdot + phidot * perp(R(phi) b_i)``, shape (m, 2) or (N, m, 2) [m/s], for
    ``pose`` (3,) or (N, 3) [m, m, rad], its rate (same shape) [m/s, m/s, rad/s] and anchors (m, 2) [m]."""
    pose, anchors, pose_rate = check_pose_and_anchors(pose, anchors, pose_rate)
    arm = rotated_anchors(pose, anchors)
    return pose_rate[..., None, :2] + pose_rate[..., 2][..., None, None] * perpendicular(arm)


@dataclass(frozen=True, eq=False)  # array fields: compare them field by field
class PulleyExit:
    """Where and how an ideal (straight, massless) cable leaves a pulley towards its anchor.

    Scalars and (d,) vectors for one anchor, (N,) and (N, d) arrays for N.

    Attributes
    ----------
    tangent_point : [m]
        Where the cable leaves the rim (the centre, or a swivel's inlet, for a point exit).
    wrap_angle : [rad]
        Arc over the top of the pulley from the hang point to ``t``, in ``[0, 3 pi / 2)``
        (above pi for an anchor below the pulley on its inner side).
    free_length : [m]
        Straight length ``|p - t|``.
    unit_vector : [-]
        From ``t`` towards the anchor (opposite to the pull on the platform).
    arc_length : [m]
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


def exit_arrays(center, radius, side, anchor):
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
    unit_vector = side * perpendicular(normal)  # direction of travel at t, = (p - t) / |p - t|
    free_length = np.sqrt(np.maximum(distance**2 - radius**2, 0.0))
    return tangent_point, wrap, free_length, unit_vector


def planar_exit(center, radius, side, anchor) -> PulleyExit:
    """The :class:`PulleyExit` of a checked pulley (``center`` (2,) [m], ``radius`` [m], ``side`` -1 or +1) to
    anchor(s) (2,) or (N, 2) [m], checked here: the kernel of every planar exit (a point exit: radius 0)."""
    anchor = finite_array("anchor", anchor, (2,))
    tangent_point, wrap, free_length, unit_vector = exit_arrays(np.asarray(center), radius, side, anchor)
    if anchor.ndim == 1:
        wrap, free_length = float(wrap), float(free_length)
    return PulleyExit(tangent_point=tangent_point, wrap_angle=wrap, free_length=free_length,
                      unit_vector=unit_vector, arc_length=radius * wrap)


def pulley_exit(center, radius, side, anchor):
    """The :class:`PulleyExit` of a cable over the pulley (``center`` (2,) [m], ``radius`` >= 0 [m], ``side``
    -1 or +1) to anchor(s) ``p`` (2,) or (N, 2) [m], every argument checked.

    With ``beta`` the direction of ``p - c`` and ``alpha = arccos(r_p / |p - c|)``, the tangent
    point is at rim angle ``beta - s alpha``. The paper's cable 1 (``c = (-1.75, 0)``, ``r_p =
    0.25``, ``s = -1``, ``p = (-0.15, -1.9)``) wraps about 145.7 degrees, free length 2.471 m.

    Raises
    ------
    SceneError
        For a malformed or non-finite argument, or ``side`` not -1 or +1.
    UnreachableError
        For an anchor inside the disc (or on the point exit), or above the pulley on the
        outer side of its vertical cable line (negative wrap).
    """
    center = finite_array("center", center, (2,))
    if center.ndim != 1:
        raise SceneError(f"center must have shape (2,), got shape {center.shape}")
    return planar_exit((float(center[0]), float(center[1])), check_radius("radius", radius), check_side("side", side),
                       anchor)


def skew(vector_):
    """``[v]x``, the matrix of ``v x ...``, shape (3, 3)."""
    x, y, z = vector_
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


def rotation_from_vector(rotation_vector):
    """Spatial rotation matrix ``R = exp([theta]x)`` of a rotation vector ``theta`` [rad] (Rodrigues), shape (3, 3)."""
    theta = np.asarray(rotation_vector, dtype=float)
    angle = float(np.linalg.norm(theta))
    if not angle < 1e150:  # [theta]x squared (and the norm) overflow: the same formula on the unit axis
        angle = math.hypot(*theta)
        k = skew(theta / angle)
        return np.eye(3) + np.sin(angle) * k + (1.0 - np.cos(angle)) * (k @ k)
    k = skew(theta)
    if angle < 1e-8:  # series: 1 - a^2/6 and 1/2 - a^2/24, exact to round-off here
        return np.eye(3) + (1.0 - angle**2 / 6.0) * k + (0.5 - angle**2 / 24.0) * (k @ k)
    return np.eye(3) + math.sin(angle) / angle * k + (1.0 - math.cos(angle)) / angle**2 * (k @ k)


def rotation_vector(matrix):
    """The rotation vector [rad] (angle in [0, pi]) of a rotation matrix, shape (3,)."""
    matrix = np.asarray(matrix, dtype=float)
    cosine = min(max(0.5 * (np.trace(matrix) - 1.0), -1.0), 1.0)
    angle = math.acos(cosine)
    axial = 0.5 * np.array([matrix[2, 1] - matrix[1, 2], matrix[0, 2] - matrix[2, 0], matrix[1, 0] - matrix[0, 1]])
    if angle < 1e-8:
        return axial  # sin(a) ~ a
    if angle > math.pi - 1e-6:  # near a half turn: axis from the symmetric part
        symmetric = 0.5 * (matrix + matrix.T) - cosine * np.eye(3)
        column = int(np.argmax(np.diag(symmetric)))
        axis = symmetric[:, column] / math.sqrt(max(symmetric[column, column], 1e-300))
        if axis @ axial < 0.0:
            axis = -axis
        return angle * axis / np.linalg.norm(axis)
    return angle / math.sin(angle) * axial


def left_jacobian(rotation_vector_):
    """``J_l(theta)``: ``exp([theta + d]x) = exp([J_l d]x) exp([theta]x)`` to first order in ``d``."""
    theta = np.asarray(rotation_vector_, dtype=float)
    angle = float(np.linalg.norm(theta))
    k = skew(theta)
    if angle < 1e-6:
        return np.eye(3) + 0.5 * k + (k @ k) / 6.0
    return (np.eye(3) + (1.0 - math.cos(angle)) / angle**2 * k
            + (angle - math.sin(angle)) / angle**3 * (k @ k))


def rotation_angles_deg(rotation: np.ndarray) -> np.ndarray:
    """Roll, pitch, yaw [deg] of a rotation matrix, R = Rz(yaw) Ry(pitch) Rx(roll) (for reading only)."""
    pitch = np.arcsin(np.clip(-rotation[2, 0], -1.0, 1.0))
    roll = np.arctan2(rotation[2, 1], rotation[2, 2])
    yaw = np.arctan2(rotation[1, 0], rotation[0, 0])
    return np.degrees([roll, pitch, yaw])


ON_AXIS = 1e-12
"""An anchor closer to the swivel axis than this fraction of its distance (plus r_p) is on the axis."""


@dataclass(frozen=True, eq=False)  # array fields
class SwivelExit(PulleyExit):
    """A :class:`PulleyExit` in 3-D over a swivel pulley, with its ``azimuth`` [rad] (scalar or (N,)):
    the direction of the anchor seen from the swivel axis, ``atan2(dy, dx)``."""

    azimuth: float | np.ndarray


def _fill_azimuths(azimuth, on_axis, azimuth_hint, radius, anchor, inlet):
    """Azimuths of on-axis anchors: the previous one in the batch, else the hint, else refuse (r_p > 0)."""
    flat_azimuth = azimuth.reshape(-1)
    flat_on_axis = on_axis.reshape(-1)
    flat_anchor = anchor.reshape(-1, 3)
    previous = azimuth_hint
    for k in range(flat_azimuth.size):
        if not flat_on_axis[k]:
            previous = flat_azimuth[k]
            continue
        if previous is None:
            if radius > 0.0:
                raise UnreachableError(
                    f"anchor {flat_anchor[k].tolist()} lies on the axis of the swivel pulley (inlet "
                    f"{inlet.tolist()}, radius {radius} m): which way the pulley turns (its azimuth) is undefined "
                    "there; start the reference (the scene's trajectory) with every anchor off the vertical axis "
                    "of its swivel pulley (in Python, swivel_pulley_exit also takes the previous azimuth as "
                    "azimuth_hint)")
            previous = 0.0  # a point exit: the vertical cable does not depend on it
        flat_azimuth[k] = previous
    return flat_azimuth.reshape(azimuth.shape)


def swivel_pulley_exit(inlet, radius, anchor, azimuth_hint=None):
    """The :class:`SwivelExit` of a cable over a swivel pulley (``inlet`` (3,) [m], ``radius`` >= 0 [m], 0 a
    point exit) to anchor(s) (3,) or (N, 3) [m]; ``azimuth_hint`` [rad] for an anchor on the axis.

    The planar cable of :func:`planar_exit` in the plane of the azimuth (module notes; Pott,
    "Cable-Driven Parallel Robots", Springer 2018, pulley kinematics).

    Raises
    ------
    SceneError
        For a malformed or non-finite argument, or a negative ``radius``.
    UnreachableError
        For an anchor inside the disc (or on a point exit), or on the axis of a pulley of
        positive radius with no azimuth to keep.
    """
    inlet = finite_array("inlet", inlet, (3,))
    if inlet.ndim != 1:
        raise SceneError(f"inlet must have shape (3,), got shape {inlet.shape}")
    radius = non_negative("radius", radius)
    anchor = finite_array("anchor", anchor, (3,))
    if anchor.ndim > 2:
        raise SceneError(f"anchor must have shape (3,) or (N, 3), got shape {anchor.shape}")
    if azimuth_hint is not None:
        azimuth_hint = float(finite_array("azimuth_hint", azimuth_hint))
    delta = anchor - inlet
    distance = np.linalg.norm(delta, axis=-1)
    if radius == 0.0 and np.any(distance == 0.0):
        bad = anchor[distance == 0.0] if anchor.ndim > 1 else anchor
        raise UnreachableError(f"anchor {np.asarray(bad).tolist()} coincides with the point exit {inlet.tolist()}")
    rho = np.hypot(delta[..., 0], delta[..., 1])
    azimuth = np.arctan2(delta[..., 1], delta[..., 0])
    on_axis = rho <= ON_AXIS * (distance + radius)
    if np.any(on_axis):
        azimuth = _fill_azimuths(np.array(azimuth, dtype=float), on_axis, azimuth_hint, radius, anchor, inlet)
        rho = np.where(on_axis, 0.0, rho)
    height = delta[..., 2]
    if radius > 0.0:
        inside = np.hypot(rho - radius, height) <= radius
        if np.any(inside):
            bad = anchor[inside] if anchor.ndim > 1 else anchor
            raise UnreachableError(f"anchor {np.asarray(bad).tolist()} lies inside the disc of the swivel pulley "
                                   f"(inlet {inlet.tolist()}, radius {radius} m)")
    # the planar pulley in the plane (rho, z), origin at the inlet: its hang point is the inlet
    radius = float(radius)
    planar = planar_exit((radius, 0.0), radius, -1, np.stack([rho, height], axis=-1))
    e_rho = np.stack([np.cos(azimuth), np.sin(azimuth), np.zeros_like(azimuth)], axis=-1)
    e_z = np.array([0.0, 0.0, 1.0])

    def to_world(planar_vector):
        return planar_vector[..., :1] * e_rho + planar_vector[..., 1:] * e_z

    return SwivelExit(
        azimuth=float(azimuth) if np.ndim(azimuth) == 0 else azimuth,
        tangent_point=inlet + to_world(planar.tangent_point),
        wrap_angle=planar.wrap_angle,
        free_length=planar.free_length,
        unit_vector=to_world(planar.unit_vector),
        arc_length=planar.arc_length,
    )


def rotation_matrices(rotation_vectors):
    """:func:`rotation_from_vector` of rotation vectors (..., 3) [rad], shape (..., 3, 3)."""
    theta = np.asarray(rotation_vectors, dtype=float)
    flat = theta.reshape(-1, 3)
    return np.array([rotation_from_vector(t) for t in flat]).reshape(theta.shape[:-1] + (3, 3))


def left_jacobians(rotation_vectors):
    """``J_l(theta)`` (:func:`left_jacobian`) for rotation vectors (..., 3) [rad] -> (..., 3, 3)."""
    theta = np.asarray(rotation_vectors, dtype=float)
    return np.array([left_jacobian(t) for t in theta.reshape(-1, 3)]).reshape(theta.shape[:-1] + (3, 3))


def spatial_arms(pose, anchors):
    """``R(theta) b_i``, shape (..., m, 3)."""
    return np.einsum("...jk,mk->...mj", rotation_matrices(pose[..., 3:6]), anchors)


def spatial_anchor_points(pose, anchors):
    """World positions ``p_i = r + R(theta) b_i``, shape (m, 3) or (N, m, 3) [m], of the anchors (m, 3) [m]
    at pose(s) ``(r, theta)`` (6,) or (N, 6) [m, rad]."""
    pose, anchors = check_pose_and_anchors(pose, anchors, sizes=(6, 3))
    return pose[..., None, :3] + spatial_arms(pose, anchors)


def spatial_anchor_velocities(pose, pose_rate, anchors):
    """World velocities ``v_i = dr/dt + omega x (R b_i)``, ``omega = J_l(theta) dtheta/dt``, shape (m, 3) or
    (N, m, 3) [m/s], for ``pose`` (6,) or (N, 6), its rate ``(dr/dt, dtheta/dt)`` [m/s, rad/s] (the rotation
    vector's, not the angular velocity) and anchors (m, 3) [m]."""
    pose, anchors, pose_rate = check_pose_and_anchors(pose, anchors, pose_rate, (6, 3))
    omega = np.einsum("...jk,...k->...j", left_jacobians(pose[..., 3:6]), pose_rate[..., 3:6])
    return pose_rate[..., None, :3] + np.cross(omega[..., None, :], spatial_arms(pose, anchors))


def above_exits(anchor_heights, exit_tops, exits: str = "pulleys") -> str | None:
    """Why no cable can hold the platform up (every anchor at or above its exit's top), or None.

    A cable pulls its anchor towards where it leaves its exit, no higher than the exit's top
    (:attr:`cdpr_exu.exits.base.Exit.top`); with every anchor at or above it, no cable pulls
    upwards. ``anchor_heights`` and ``exit_tops`` (m,) [m]; ``exits`` names the scene field in
    the message.
    """
    heights, tops = np.asarray(anchor_heights, dtype=float), np.asarray(exit_tops, dtype=float)
    if heights.shape != tops.shape or np.any(heights < tops):
        return None
    where = "; ".join(f"platform.anchors[{i}] at z = {h:.4g} m, {exits}[{i}] up to z = {t:.4g} m"
                      for i, (h, t) in enumerate(zip(heights, tops)))
    return (f"every anchor is at or above the top of its exit ({where}): no cable can hold a platform above its "
            "exits, as cables cannot push")


def penetration(pulley, positions: np.ndarray) -> np.ndarray:
    """Depth [m] by which each node (..., 2) [m] lies inside the disc of ``pulley`` (0 outside), (...)."""
    distance = np.linalg.norm(np.asarray(positions) - np.asarray(pulley.center), axis=-1)
    return np.maximum(pulley.radius - distance, 0.0)


def segment_penetration(pulley, positions: np.ndarray) -> np.ndarray:
    """Depth [m] by which each element of one cable (nodes (n + 1, 2) [m]) cuts into the disc of ``pulley``:
    r_p minus the segment's distance from the centre, 0 outside, shape (n,)."""
    positions = np.asarray(positions, dtype=float)
    center = np.asarray(pulley.center)
    a, b = positions[:-1], positions[1:]
    d = b - a
    t = np.clip(np.einsum("ij,ij->i", center - a, d) / np.maximum(np.einsum("ij,ij->i", d, d), 1e-300), 0.0, 1.0)
    closest = a + t[:, None] * d
    return np.maximum(pulley.radius - np.linalg.norm(closest - center, axis=1), 0.0)
