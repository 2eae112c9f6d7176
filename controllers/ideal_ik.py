"""Joint-space control from the ideal inverse kinematics (the paper's scheme).

The cables are taken as straight, massless and inextensible: the paid-out length of
cable i is the straight length from its pulley's tangent point to the anchor plus the
arc it wraps on the pulley, evaluated on the reference pose. The winch follows it
open-loop; sag and stretch are ignored, which is the error the paper measures.
"""

from __future__ import annotations

import numpy as np

from cdpr_exu.statics.kinematics import inverse_kinematics, inverse_kinematics_rates, pulley_arrays

from .base import Measurement, WinchCommand


def _spatial_ideal_lengths(scene, poses, pose_rates=None):
    """:func:`ideal_paid_out` of a spatial scene: straight distances from the exit points to the
    anchors, over the swivel pulleys where there are (wrap plus tangent length from the inlet,
    :mod:`cdpr_exu.physics.spatial_kinematics`), poses (N, 6) (x, y, z, rotation vector); a
    point-mass platform's rotation is ignored."""
    from cdpr_exu.physics.spatial_kinematics import inverse_kinematics, inverse_kinematics_rates

    poses = np.atleast_2d(poses)
    exits = np.asarray(scene.exits)
    if scene.platform.is_point_mass:
        points, anchors = poses[:, :3], None
        rates = None if pose_rates is None else np.atleast_2d(pose_rates)[:, :3]
    else:
        points, anchors = poses, np.asarray(scene.platform.anchors)
        rates = None if pose_rates is None else np.atleast_2d(pose_rates)
    radii = np.asarray(getattr(scene, "pulley_radii", 0.0))  # swivel pulleys (0: a point exit)
    lengths = inverse_kinematics(points, anchors, exits, radii)
    if rates is None:
        return lengths, None
    return lengths, inverse_kinematics_rates(points, rates, anchors, exits, radii)


def ideal_paid_out(scene, poses: np.ndarray, pose_rates: np.ndarray | None = None):
    """Ideal paid-out lengths (and rates) of every cable for reference poses.

    Parameters
    ----------
    scene : cdpr_exu.scenes.scene.Scene
    poses : ndarray, shape (N, 3) [m, m, rad]
    pose_rates : ndarray, shape (N, 3) or None [m/s, m/s, rad/s]

    Returns
    -------
    lengths : ndarray, shape (N, m) [m]
    rates : ndarray, shape (N, m) [m/s] or None
    """
    if getattr(scene, "dimension", 2) == 3:
        return _spatial_ideal_lengths(scene, poses, pose_rates)
    anchors = np.asarray(scene.platform.anchors)
    centers, radii, sides = pulley_arrays(scene.exits)
    lengths = inverse_kinematics(poses, anchors, centers, radii, sides)
    rates = None
    if pose_rates is not None:
        rates = inverse_kinematics_rates(poses, pose_rates, anchors, centers, radii, sides)
    return lengths, rates


def table_lookup(t: float, times: np.ndarray, table: np.ndarray) -> np.ndarray:
    """Row of ``table`` (shape (K, m)) at time ``t`` [s], linear between ``times`` (shape (K,), increasing).

    ``np.interp`` on every column, in one pass: the same formula, so the same bits
    (``fp[j] + slope (t - xp[j])``, the end values outside the table, the table's
    value where ``t`` hits a sample).
    """
    j = int(np.searchsorted(times, t, side="right")) - 1
    if j < 0:
        return table[0].copy()
    if j >= times.size - 1:
        return table[-1].copy()
    if t == times[j]:
        return table[j].copy()
    slope = (table[j + 1] - table[j]) / (times[j + 1] - times[j])
    return slope * (t - times[j]) + table[j]


class IdealIKController:
    """Open-loop winch lengths from ideal (straight, massless, inextensible) cables.

    As in the paper, the ideal length is imposed as a velocity (flow) source: the
    command is the initial paid-out length plus the change of the ideal length since
    t = 0. The table is computed once per run on the solver's step grid and read by
    linear interpolation, so a step costs no inverse kinematics.
    """

    name = "ideal_ik"
    uses_pose = False
    uses_tension = False

    def __init__(self) -> None:
        self._times = None
        self._lengths = None
        self._rates = None

    def reset(self, scene, initial_paid_out) -> None:
        """Tabulate the commands for ``scene.trajectory`` on the step grid."""
        solver = scene.solver
        self._times = np.linspace(0.0, solver.end_time, solver.n_steps + 1)
        poses = scene.trajectory.pose(self._times)
        rates = scene.trajectory.velocity(self._times)
        lengths, self._rates = ideal_paid_out(scene, poses, rates)
        self._lengths = np.asarray(initial_paid_out, dtype=float) + lengths - lengths[0]

    def command(self, measurement: Measurement) -> WinchCommand:
        if self._times is None:
            raise RuntimeError("IdealIKController.reset(scene) must be called before command()")
        t = measurement.time
        return WinchCommand(table_lookup(t, self._times, self._lengths), table_lookup(t, self._times, self._rates))
