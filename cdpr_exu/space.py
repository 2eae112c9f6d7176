"""The space a robot lives in: the plane of the paper or three dimensions, decided once.

A scene says its dimension once (``dimension = 3`` in TOML, 2 when absent) and gets a
:class:`Space` (:func:`space_of`): the one object that knows what a pose, a position and a
rotation are in that dimension. A concept that is the same in both dimensions (scene,
exits, kinematics, statics, builder, run, result, controllers) is written once and asks its
scene's space for what differs, instead of testing the dimension itself. This module is the
only place that branches on the dimension (:func:`space_of`).

* **Planar** (:data:`PLANE`): the paper's vertical x-z plane, gravity along -z. A pose is
  ``(x, z, phi)`` [m, m, rad], ``phi`` counter-clockwise (paper eq. 17); an anchor ``b`` sits
  at ``r + R(phi) b``. The builder maps (x, z) onto Exudyn's x-y plane (its 2-D items).
* **Spatial** (:data:`SPACE`): z up, gravity along -z. A pose is ``(x, y, z, theta)``
  [m, rad], ``theta`` the platform's rotation vector, ``R = exp([theta]x)``.

Each space computes with its own kernels of :mod:`cdpr_exu.core.geometry`: planar numbers never
go through 3-D arithmetic.

The planar robot embeds in space as ``(x, z, phi) -> (x, 0, z, 0, -phi, 0)``: its plane is
the x-z plane, and a counter-clockwise turn seen with x to the right and z up is a turn
about -y (:meth:`Space.embed`). Units SI.
"""

from __future__ import annotations

import numpy as np

from cdpr_exu.core import geometry
from cdpr_exu.core.errors import SceneError
from cdpr_exu.core.validation import entries, finite, positive, shown, vector

__all__ = ["Space", "PLANE", "SPACE", "space_of", "DIMENSIONS"]


class Space:
    """What a pose, a position and a rotation are in one dimension (see the module notes).

    ``dimension`` 2 or 3, ``name`` "planar" or "spatial" (for messages); ``position_labels``,
    ``rotation_labels``, ``pose_labels`` name the entries in order (tables, CSV headers, figures),
    whose counts are ``position_size`` (2 | 3), ``rotation_size`` (1 | 3), ``pose_size`` and
    ``wrench_size`` (3 | 6), units ``pose_units``; ``vertical`` is the index of the up axis in a position;
    ``pose_columns`` name the entries with their units in CSV files (a run's ``pose.csv``, a trajectory file).
    """

    dimension: int
    name: str
    position_labels: tuple[str, ...]
    rotation_labels: tuple[str, ...]
    pose_columns: tuple[str, ...]

    @property
    def position_size(self) -> int:
        return len(self.position_labels)

    @property
    def rotation_size(self) -> int:
        return len(self.rotation_labels)

    @property
    def pose_size(self) -> int:
        return self.position_size + self.rotation_size

    @property
    def wrench_size(self) -> int:
        return self.pose_size

    @property
    def pose_labels(self) -> tuple[str, ...]:
        return self.position_labels + self.rotation_labels

    @property
    def pose_units(self) -> tuple[str, ...]:
        return ("m",) * self.position_size + ("rad",) * self.rotation_size

    @property
    def vertical(self) -> int:
        return self.position_size - 1

    def __repr__(self) -> str:
        return f"<{self.name} space>"

    def __reduce__(self):  # one object per dimension, also across process pools and pickles
        return space_of, (self.dimension,)

    def rotation_matrix(self, rotation) -> np.ndarray:
        """The rotation matrix of one rotation (an angle [rad], or a rotation vector (3,) [rad]), shape (d, d)."""
        raise NotImplementedError

    def rotation(self, name: str, value=None):
        """A rotation as this space has it, validated (the message names ``name``): the angle [rad] in the
        plane (a float), a rotation vector [rad] in space (a tuple of 3); ``None`` is no rotation."""
        raise NotImplementedError

    def angular_velocity(self, rotation, rotation_rate) -> np.ndarray:
        """The angular velocity [rad/s] in the fixed frame of a rotation (..., rotation_size) [rad] changing
        at ``rotation_rate`` (its time derivative, same shape): the rate itself in the plane,
        ``J_l(theta) theta'`` in space (the rotation vector's rate is not the angular velocity)."""
        raise NotImplementedError

    def rotation_rate(self, rotation, angular_velocity) -> np.ndarray:
        """The rotation's time derivative (..., rotation_size) [rad/s] for an angular velocity in the fixed
        frame (same shape) [rad/s]: the inverse of :meth:`angular_velocity` (in space
        ``J_l(theta)^-1 omega``), so that a measured velocity is the pose's rate in both spaces."""
        raise NotImplementedError

    def anchor_points(self, pose, anchors) -> np.ndarray:
        """World positions of the platform anchors ``r + R b_i``: pose (pose_size,) or (N, pose_size),
        anchors (m, d) in the platform frame -> (m, d) or (N, m, d) [m]."""
        raise NotImplementedError

    def anchor_velocities(self, pose, pose_rate, anchors) -> np.ndarray:
        """World velocities of the anchors for a pose and its rate (the pose's time derivative: in space
        the rotation vector's rate, not the angular velocity), shape as :meth:`anchor_points` [m/s]."""
        raise NotImplementedError

    def rotation_error_deg(self, pose, reference) -> np.ndarray:
        """Angle [deg] of the rotation from the reference orientation to the actual one, poses
        (N, pose_size) -> (N,)."""
        raise NotImplementedError

    def moments(self, pose, anchors, forces) -> np.ndarray:
        """Moments about the platform's reference point of forces at its anchors, ``(R b_i) x f_i``: pose
        (pose_size,) or (N, pose_size), anchors (m, d), forces (m, d) or (N, m, d) -> (..., m, rotation_size)."""
        raise NotImplementedError

    def rotation_moment(self, rotation, rotation_rate, rotation_acceleration, inertia) -> np.ndarray:
        """The moment about the centre of mass that turns a platform of ``inertia`` (:meth:`inertia`) along a
        rotation, its rate and acceleration (N, rotation_size) [rad, rad/s, rad/s^2] -> (N, rotation_size) [N m]:
        ``J phi''`` in the plane, Euler's ``I w' + w x I w`` in space (``I = R diag(inertia) R^T``, ``w =
        J_l(theta) theta'``)."""
        raise NotImplementedError

    def embed(self, pose) -> np.ndarray:
        """Pose(s) (..., pose_size) as spatial poses (..., 6): ``(x, z, phi) -> (x, 0, z, 0, -phi, 0)``
        in the plane (see the module notes), the identity in space."""
        raise NotImplementedError

    def is_rigid(self, point_mass: bool) -> bool:
        """Whether a platform is simulated as a rigid body, which needs a positive mass and inertia: in
        the plane always (Exudyn's 2-D rigid body; a point mass's rotation is locked), in space unless
        every anchor sits at its centre of mass (then it is a mass point, which may weigh nothing)."""
        raise NotImplementedError

    def inertia(self, name: str, value, rigid: bool):
        """A platform's inertia as this space has it, validated: the moment about the axis normal to
        the plane [kg m^2] (a float), or the three principal moments about the platform axes [kg m^2]
        (a tuple). ``rigid``: the platform turns, so every moment must be positive (else zero is
        allowed). The message names ``name``."""
        raise NotImplementedError


class PlanarSpace(Space):
    """The paper's vertical x-z plane (see the module notes)."""

    dimension = 2
    name = "planar"
    position_labels = ("x", "z")
    rotation_labels = ("rotation",)
    pose_columns = ("x_m", "z_m", "rotation_rad")

    def rotation_matrix(self, rotation) -> np.ndarray:
        return geometry.rotation_matrix(float(np.asarray(rotation).reshape(-1)[0]))

    def rotation(self, name: str, value=None) -> float:
        return 0.0 if value is None else finite(name, value)

    def angular_velocity(self, rotation, rotation_rate) -> np.ndarray:
        return np.asarray(rotation_rate, dtype=float)

    def rotation_rate(self, rotation, angular_velocity) -> np.ndarray:
        return np.asarray(angular_velocity, dtype=float)

    def anchor_points(self, pose, anchors) -> np.ndarray:
        return geometry.anchor_points(pose, anchors)

    def anchor_velocities(self, pose, pose_rate, anchors) -> np.ndarray:
        return geometry.anchor_velocities(pose, pose_rate, anchors)

    def rotation_error_deg(self, pose, reference) -> np.ndarray:
        return np.degrees(np.abs(np.asarray(pose)[:, 2] - np.asarray(reference)[:, 2]))

    def moments(self, pose, anchors, forces) -> np.ndarray:
        arms = geometry.rotated_anchors(np.asarray(pose, dtype=float), np.asarray(anchors, dtype=float))
        return geometry.planar_cross(arms, forces)[..., None]

    def rotation_moment(self, rotation, rotation_rate, rotation_acceleration, inertia) -> np.ndarray:
        return inertia * np.asarray(rotation_acceleration, dtype=float)

    def embed(self, pose) -> np.ndarray:
        pose = np.asarray(pose, dtype=float)
        zero = np.zeros(pose.shape[:-1])
        return np.stack([pose[..., 0], zero, pose[..., 1], zero, -pose[..., 2], zero], axis=-1)

    def is_rigid(self, point_mass: bool) -> bool:
        return True

    def inertia(self, name: str, value, rigid: bool) -> float:
        return positive(name, value, "kg m^2")


class SpatialSpace(Space):
    """Three dimensions, z up (see the module notes)."""

    dimension = 3
    name = "spatial"
    position_labels = ("x", "y", "z")
    rotation_labels = ("rx", "ry", "rz")
    pose_columns = ("x_m", "y_m", "z_m", "rotation_x_rad", "rotation_y_rad", "rotation_z_rad")

    def rotation_matrix(self, rotation) -> np.ndarray:
        return geometry.rotation_from_vector(rotation)

    def rotation(self, name: str, value=None) -> tuple[float, float, float]:
        return (0.0, 0.0, 0.0) if value is None else entries(name, value, 3, "rad")

    def angular_velocity(self, rotation, rotation_rate) -> np.ndarray:
        rotation, rate = np.asarray(rotation, dtype=float), np.asarray(rotation_rate, dtype=float)
        jacobians = geometry.left_jacobians(rotation).reshape(-1, 3, 3)
        return np.einsum("nij,nj->ni", jacobians, rate.reshape(-1, 3)).reshape(rate.shape)

    def rotation_rate(self, rotation, angular_velocity) -> np.ndarray:
        rotation, omega = np.asarray(rotation, dtype=float), np.asarray(angular_velocity, dtype=float)
        jacobians = geometry.left_jacobians(rotation).reshape(-1, 3, 3)
        return np.linalg.solve(jacobians, omega.reshape(-1, 3, 1)).reshape(omega.shape)

    def anchor_points(self, pose, anchors) -> np.ndarray:
        return geometry.spatial_anchor_points(pose, anchors)

    def anchor_velocities(self, pose, pose_rate, anchors) -> np.ndarray:
        return geometry.spatial_anchor_velocities(pose, pose_rate, anchors)

    def rotation_error_deg(self, pose, reference) -> np.ndarray:
        angles = []
        for theta, theta_ref in zip(np.asarray(pose)[:, 3:], np.asarray(reference)[:, 3:]):
            relative = geometry.rotation_from_vector(theta_ref).T @ geometry.rotation_from_vector(theta)
            angles.append(np.linalg.norm(geometry.rotation_vector(relative)))
        return np.degrees(np.asarray(angles))

    def moments(self, pose, anchors, forces) -> np.ndarray:
        return np.cross(geometry.spatial_arms(np.asarray(pose, dtype=float), np.asarray(anchors, dtype=float)), forces)

    def rotation_moment(self, rotation, rotation_rate, rotation_acceleration, inertia) -> np.ndarray:
        theta, rate = np.asarray(rotation, dtype=float), np.asarray(rotation_rate, dtype=float)
        step = 1e-6  # d/dt J_l(theta(t)) by a central difference along theta': relative error ~ 1e-12
        turning = (geometry.left_jacobians(theta + step * rate) - geometry.left_jacobians(theta - step * rate)) / (2 * step)
        omega = np.einsum("nij,nj->ni", geometry.left_jacobians(theta), rate)
        omega_rate = (np.einsum("nij,nj->ni", geometry.left_jacobians(theta), rotation_acceleration)
                      + np.einsum("nij,nj->ni", turning, rate))
        rotations = geometry.rotation_matrices(theta)
        world = np.einsum("nij,j,nkj->nik", rotations, np.asarray(inertia, dtype=float), rotations)
        return np.einsum("nij,nj->ni", world, omega_rate) + np.cross(omega, np.einsum("nij,nj->ni", world, omega))

    def embed(self, pose) -> np.ndarray:
        return np.asarray(pose, dtype=float)

    def is_rigid(self, point_mass: bool) -> bool:
        return not point_mass

    def inertia(self, name: str, value, rigid: bool) -> tuple[float, float, float]:
        moments = vector(name, value, 3, " (principal moments) [kg m^2]")
        if np.any(moments < 0.0) or (rigid and np.any(moments <= 0.0)):
            raise SceneError(f"{name} must be {'positive' if rigid else 'zero or positive'} (principal moments "
                             f"[kg m^2]), got {shown(value)}")
        return tuple(float(v) for v in moments)


#: The two spaces, one object each.
PLANE: Space = PlanarSpace()
SPACE: Space = SpatialSpace()
#: The dimensions a scene may have.
DIMENSIONS = (2, 3)


def space_of(dimension) -> Space:
    """The :class:`Space` of ``dimension`` (2 or 3): the one decision on the dimension.

    Raises
    ------
    SceneError
        For any other value, naming ``dimension``.
    """
    if isinstance(dimension, bool) or dimension not in DIMENSIONS:
        raise SceneError(f"dimension must be 2 (planar) or 3 (spatial), got {shown(dimension)}")
    return PLANE if dimension == 2 else SPACE
