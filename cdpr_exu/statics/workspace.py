"""The workspace check: can the cables reach, and hold, every pose of the reference? Planar or spatial.

One check for every controller and both dimensions, run before any simulation
(:func:`check_reference`), on the reference sampled over the run and at its turning times
(:func:`reference_samples`). A reference pose is refused, with its time and the scene
fields that conflict, when

* the trajectory leaves floating-point range;
* a cable cannot reach its anchor over its exit (an anchor inside a pulley's disc, beyond
  a planar pulley's outer vertical, on a swivel's axis at the start: the exit's own refusal,
  :meth:`cdpr_exu.exits.base.Exit.exit`, named with the pose and the exit's fields);
* a cable would be reeled in completely, or its exit's winch cannot pay out what the pose
  needs (:meth:`cdpr_exu.exits.base.Exit.paid_out_refusal`: a planar pulley's cable
  longer than the cable, a swivel's winch line);
* the winches follow the reference, and no allowed cable tensions hold the platform there.
  Without tension limits, non-negative tensions must hold its weight at rest: every cable
  pulls along the line from its anchor to where it leaves its exit, so a platform above its
  exits could only be held by cables that push (a reference that accelerates the platform
  beyond what taut cables give is a run's to show: the cables go slack and snap taut). With
  the cables' ``min_tension`` / ``max_tension``, tensions within them must give it its
  weight and the reference's acceleration, ``M (a_ref + g e_z)``, and the moment about the
  centre of mass that the reference's rotation needs (:func:`reference_wrenches`).

**One rule for the moment, both dimensions.** The cables can turn the platform about every
axis when it is rigid (not a point mass), it has at least as many cables as its wrench has
entries (3 in the plane, 6 in space) and its structure matrix at the first sample has full
rank: then the moment is asked with the force (none at rest, or the rotation's within
tension limits). With fewer cables (the paper's two, the spatial four-cable robots) the
platform turns to balance the moment, as a suspended platform does, and the force alone is
asked. Pure NumPy/SciPy (no Exudyn). Units SI.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import lsq_linear, nnls

from cdpr_exu.core.errors import UnreachableError
from cdpr_exu.core.validation import shown
from cdpr_exu.statics.kinematics import structure_matrix

#: Samples of the reference over the run (plus its turning times).
REFERENCE_SAMPLES = 401
#: Relative residual of the force balance above which the weight counts as not held.
WEIGHT_BALANCE_TOLERANCE = 1e-6


def reference_samples(scene) -> tuple[np.ndarray, np.ndarray]:
    """Times [s], shape (N,), and reference poses, shape (N, pose_size), at which the workspace is checked.

    A uniform grid over the run, plus the trajectory's turning times (where a coordinate
    of the pose is extreme), so that the extreme poses are checked exactly.
    """
    end = scene.solver.end_time
    times = np.linspace(0.0, end, REFERENCE_SAMPLES)
    turning = np.asarray(scene.trajectory.turning_times(end), dtype=float).reshape(-1)
    times = np.unique(np.concatenate([times, turning[(turning >= 0.0) & (turning <= end)]]))
    return times, np.atleast_2d(scene.trajectory.pose(times))


def _pose_text(scene, times: np.ndarray, poses: np.ndarray, k: int) -> str:
    space = scene.space
    labels = ", ".join(f"{label} [{unit}]" for label, unit in zip(space.pose_labels, space.pose_units))
    return f"the reference pose {np.round(poses[k], 4).tolist()} ({labels}) at t = {times[k]:.3f} s"


def _check_finite(times, values) -> None:
    for name, value in values.items():
        if not np.all(np.isfinite(value)):
            k = int(np.argmin(np.all(np.isfinite(value), axis=1)))
            raise UnreachableError(f"trajectory is out of floating-point range: its {name} at t = {times[k]:.3f} s is "
                                   f"{shown(value[k])} (a trajectory field far beyond any robot, e.g. its "
                                   "angular_rate or radius)")


def _exit_named(scene, i, times, poses, anchors):
    """The exit of cable i at every sample; its refusal names the fields and the time."""
    exit_, path = scene.exits[i], f"{scene.exits_table}[{i}]"
    try:
        return exit_.exit(anchors)
    except UnreachableError as err:
        for k in range(len(anchors)):
            try:
                exit_.exit(anchors[k])
            except UnreachableError:
                raise UnreachableError(
                    f"platform.anchors[{i}] cannot be reached over {path} ({_pose_text(scene, times, poses, k)}; "
                    f"{exit_.describe(path)}): {err}") from None
        raise


def _check_lengths(scene, times, poses, lengths) -> None:
    """Refuse a pose that reels a cable in completely, or needs more than its exit's winch pays out."""
    paid_out = scene.unstrained_lengths + lengths - lengths[0]
    short = np.argwhere(paid_out <= 0.0)
    if short.size:
        k, i = short[0]
        raise UnreachableError(f"{_pose_text(scene, times, poses, k)} needs cable {i + 1} paid out to "
                               f"{paid_out[k, i]:.4g} m from its cables[{i}].unstrained_length = "
                               f"{scene.cables[i].unstrained_length:.4g} m at the start: it would be reeled in completely")
    for i, (cable, exit_) in enumerate(zip(scene.cables, scene.exits)):
        refusal = exit_.paid_out_refusal(cable, i, lengths[:, i], scene.effects.cable_mass, f"{scene.exits_table}[{i}]")
        if refusal is not None:
            k, needs = refusal
            raise UnreachableError(f"{_pose_text(scene, times, poses, k)} needs {needs}")


def first_unheld(directions: np.ndarray, needed: np.ndarray, limits: np.ndarray | None = None):
    """The first sample where no allowed cable tensions give the platform the force it needs.

    Parameters
    ----------
    directions : ndarray, shape (N, d, m)
        Unit pull of each of the m cables on the platform (d = 2 planar, 3 spatial).
    needed : ndarray, shape (N, d) or (d,) [N]
        Force the cables must give the platform (its weight, plus its mass times the
        reference's acceleration).
    limits : ndarray, shape (m, 2) [N], optional
        Each cable's (t_min, t_max); default: non-negative tensions.

    Returns
    -------
    None, or (k, residual [N], tensions [N] the limits forbid, shape (m,)) for the first sample k
    whose force balance leaves more than :data:`WEIGHT_BALANCE_TOLERANCE` of the need unbalanced.
    """
    needed = np.broadcast_to(np.asarray(needed, dtype=float), directions.shape[:2])
    scale = max(float(np.abs(needed).max()), 1e-300)
    for k in range(len(directions)):
        if limits is None:
            _, residual = nnls(directions[k], needed[k])
        else:
            fit = lsq_linear(directions[k], needed[k], bounds=(limits[:, 0], limits[:, 1]))
            residual = float(np.linalg.norm(directions[k] @ fit.x - needed[k]))
        if residual > WEIGHT_BALANCE_TOLERANCE * scale:
            free, *_ = np.linalg.lstsq(directions[k], needed[k], rcond=None)
            return k, float(residual), free
    return None


def limits_text(free: np.ndarray, limits: np.ndarray) -> str:
    """The cables whose needed tension lies outside their limits, naming the scene fields."""
    outside = [f"cable {i + 1} needs {free[i]:.4g} N (cables[{i}].min_tension = {limits[i, 0]:g} N, "
               f"cables[{i}].max_tension = {limits[i, 1]:g} N)"
               for i in range(len(free)) if not limits[i, 0] <= free[i] <= limits[i, 1]]
    return "; ".join(outside) or "no tensions within the limits balance the platform"


def reference_wrenches(scene, times: np.ndarray) -> np.ndarray:
    """The wrench the cables must give the platform to follow the reference, shape (N, wrench_size) [N, N m].

    The force ``M (a + g e_z)`` and the moment about the centre of mass that turns the platform
    along the reference (:meth:`cdpr_exu.space.Space.rotation_moment`: ``J phi''`` in the plane,
    Euler's equations in space): zero for a platform at rest, whatever its orientation.
    """
    space, trajectory = scene.space, scene.trajectory
    d = space.position_size
    gravity = scene.gravity if scene.effects.gravity else 0.0
    pose, rate = np.atleast_2d(trajectory.pose(times)), np.atleast_2d(trajectory.velocity(times))
    acceleration = np.atleast_2d(trajectory.acceleration(times))
    up = np.zeros(d)
    up[space.vertical] = gravity
    force = scene.platform.mass * (acceleration[:, :d] + up)
    moment = space.rotation_moment(pose[:, d:], rate[:, d:], acceleration[:, d:], scene.platform.inertia)
    return np.column_stack([force, moment])


def cables_turn_platform(scene, matrix: np.ndarray) -> bool:
    """Whether the cables can turn the platform about every axis (the module notes' rule): then the moment is
    asked with the force. ``matrix`` (wrench_size, m): the structure matrix at a pose."""
    size = scene.space.wrench_size
    return (not scene.platform.is_point_mass and scene.n_cables >= size
            and len(matrix) == size and np.linalg.matrix_rank(matrix) == size)


def _check_held(scene, times, poses) -> None:
    """Refuse a pose where no allowed tensions give the platform what following the reference takes (module notes)."""
    if scene.winch.kind == "fixed":
        return  # fixed winches follow no reference: it only measures the error (a pendulum swings)
    d, limits, inertia = scene.space.position_size, scene.tension_limits, shown(scene.platform.inertia)
    matrices = structure_matrix(scene, poses)  # (N, n, m): force and moment about the centre of mass
    if limits is None:  # held at rest at each pose: its weight, no moment
        wrenches = np.zeros((len(poses), scene.space.wrench_size))
        wrenches[:, scene.space.vertical] = scene.platform.mass * (scene.gravity if scene.effects.gravity else 0.0)
        what, allowed = "hold the platform's weight", "with non-negative tensions"
        moment = (f"no moment about its centre of mass (at rest; the reference's angular acceleration, with "
                  f"platform.inertia = {inertia} kg m^2, is asked within tension limits)")
    else:
        wrenches = reference_wrenches(scene, times)
        what, allowed = "hold the platform's weight and give it the reference's acceleration", "within the cables' tension limits"
        moment = ("the moment about its centre of mass that the reference's rotation needs ({} N m: zero at rest, plus "
                  f"the angular acceleration and velocity with platform.inertia = {inertia} kg m^2)")
    for rows, unit in ((slice(0, d), "N"), (slice(None), "(N, N m)")):
        unheld = first_unheld(matrices[:, rows], wrenches[:, rows], limits)
        if unheld is not None:
            k, residual, free = unheld
            why = allowed if limits is None else f"{allowed} ({limits_text(free, limits)})"
            force = f"{what} ({np.round(wrenches[k, :d], 4).tolist()} N, platform.mass = {scene.platform.mass} kg)"
            if unit == "N":
                above = scene.above_exits(poses[k, :d], scene.space.rotation_matrix(poses[k, d:]))
                raise UnreachableError(
                    f"{_pose_text(scene, times, poses, k)} is outside the workspace: the cables cannot {force} {why}; "
                    f"{residual:.4g} N would remain unbalanced"
                    + ("" if above is None else f"; the pose is above the exits: {above}"))
            raise UnreachableError(
                f"{_pose_text(scene, times, poses, k)} is outside the workspace: the cables can {force}, but not "
                f"together with {moment.format(np.round(wrenches[k, d:], 4).tolist())} {why}; {residual:.4g} {unit} "
                "would remain unbalanced")
        if not cables_turn_platform(scene, matrices[0]):
            return  # the platform turns to balance the moment (a point mass has none)


def check_reference(scene) -> None:
    """Refuse a reference trajectory the cables cannot follow, before any simulation (module notes).

    Nothing to check for a scene without a trajectory (a spatial scene's static mode).

    Raises
    ------
    SceneError
        A trajectory too fast to sample (naming its field).
    UnreachableError
        Naming the time, the pose and the scene fields that conflict (``platform.anchors[i]``,
        ``pulleys[i].center``, ``exits[i].radius``, ``cables[i].unstrained_length``,
        ``exits[i].winch_line``, ``platform.mass``, ``platform.inertia``, ``cables[i].min_tension``,
        ``cables[i].max_tension``).
    """
    if scene.trajectory is None:
        return
    times, poses = reference_samples(scene)
    _check_finite(times, {"pose": poses, "acceleration": np.atleast_2d(scene.trajectory.acceleration(times))})
    points = scene.space.anchor_points(poses, np.asarray(scene.platform.anchors, dtype=float))
    lengths = np.stack([np.asarray(_exit_named(scene, i, times, poses, points[:, i]).cable_length)
                        for i in range(scene.n_cables)], axis=1)
    _check_lengths(scene, times, poses, lengths)
    _check_held(scene, times, poses)
