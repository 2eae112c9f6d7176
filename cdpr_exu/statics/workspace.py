"""The workspace check: can the cables reach, and hold, every pose of the reference?

One check for every controller, run when the model is built, before any simulation
(:func:`check_reference`). A reference pose is refused, with its time and the scene
fields that conflict, when

* a platform anchor lies inside its pulley's disc (no straight cable leaves the rim
  towards it);
* the ideal cable from the pulley to the anchor is longer than the cable (minus one
  element on the winch side for lumped cables; a massless rope has no elements);
* the winches follow the reference, and the cables cannot hold the platform's weight
  with non-negative tensions there: every
  cable pulls along the line from the anchor to where it leaves its pulley, so a
  platform above the pulleys, or beyond them to the side, could only be held by
  cables that push.

* the cables have tension limits (``cables[i].min_tension``, ``max_tension``), and no
  tensions within them hold the platform on the reference: the ideal (straight,
  massless) cables must give the platform its weight and the reference's acceleration,
  ``M (a_ref + g e_z)``.

The last two tests are the wrench-feasible workspace of the planar robot for forces
(the platform's rotation is free to balance the moment, as a suspended platform does).
Pure NumPy/SciPy (no Exudyn). Units SI; poses (x, z, rotation) in the paper's x-z plane.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import lsq_linear, nnls

from cdpr_exu.core.errors import UnreachableError
from cdpr_exu.statics.kinematics import anchor_points

#: Samples of the reference over the run (plus its turning times).
REFERENCE_SAMPLES = 401
#: Relative residual of the force balance above which the weight counts as not held.
WEIGHT_BALANCE_TOLERANCE = 1e-6


def reference_samples(scene) -> tuple[np.ndarray, np.ndarray]:
    """Times [s], shape (N,), and reference poses, shape (N, 3), at which the workspace is checked.

    A uniform grid over the run, plus the trajectory's turning times (where a coordinate
    of the pose is extreme), so that the extreme poses are checked exactly.
    """
    end = scene.solver.end_time
    times = np.linspace(0.0, end, REFERENCE_SAMPLES)
    turning = np.asarray(scene.trajectory.turning_times(end), dtype=float).reshape(-1)
    times = np.unique(np.concatenate([times, turning[(turning >= 0.0) & (turning <= end)]]))
    return times, np.atleast_2d(scene.trajectory.pose(times))


def _pose_text(times: np.ndarray, poses: np.ndarray, k: int) -> str:
    return f"the reference pose {np.round(poses[k], 4).tolist()} (x [m], z [m], rotation [rad]) at t = {times[k]:.3f} s"


def _check_anchors_outside_discs(scene, times, poses, anchors) -> None:
    table = scene.exits_table
    for i, exit_ in enumerate(scene.exits):
        if not exit_.wraps:
            continue
        distance = np.linalg.norm(anchors[:, i] - np.asarray(exit_.point), axis=1)
        inside = np.flatnonzero(distance <= exit_.radius * (1.0 + 1e-9))
        if inside.size:
            k = inside[0]
            raise UnreachableError(
                f"platform.anchors[{i}] enters {table}[{i}] ({_pose_text(times, poses, k)}): the anchor at "
                f"{np.round(anchors[k, i], 4).tolist()} m lies {distance[k]:.4f} m from {table}[{i}].center "
                f"{list(exit_.point)} m, inside {table}[{i}].radius = {exit_.radius} m")


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
                    f"platform.anchors[{i}] cannot be reached over {path} ({_pose_text(times, poses, k)}; "
                    f"{exit_.describe(path)}): {err}") from None
        raise


def _exits(scene, times, poses, anchors):
    """Per cable: ideal lengths, shape (N,) [m], and unit pull directions on the platform, shape (N, 2)."""
    lengths, pulls = [], []
    for i in range(scene.n_cables):
        exit_ = _exit_named(scene, i, times, poses, anchors[:, i])
        lengths.append(np.asarray(exit_.cable_length))
        pulls.append(-np.asarray(exit_.unit_vector))
    return lengths, pulls


def _check_lengths(scene, times, poses, lengths) -> None:
    lumped = scene.effects.cable_mass
    for i, (cable, exit_, length) in enumerate(zip(scene.cables, scene.exits, lengths)):
        if not exit_.wraps:
            continue  # a cable fixed at the exit point: its length is checked with the scene (initial pose)
        # A lumped cable keeps at least one element on the winch side of the pulley; a
        # massless rope has no elements, so its whole length may be paid out.
        spare = cable.element_length if lumped else 0.0
        too_long = np.flatnonzero(length > cable.unstrained_length - spare + 1e-12)
        if too_long.size:
            k = too_long[0]
            kept = (f"one element, {cable.element_length:.4f} m, must stay on the winch side"
                    if lumped else "a massless rope can pay out at most its whole length")
            raise UnreachableError(
                f"{_pose_text(times, poses, k)} needs {length[k]:.4f} m of cable {i + 1} between "
                f"{scene.exits_table}[{i}] and platform.anchors[{i}], but cables[{i}].unstrained_length is "
                f"{cable.unstrained_length} m ({kept})")


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


def _check_weight_held(scene, times, poses, pulls) -> None:
    weight = scene.platform.mass * scene.gravity
    if weight <= 0.0 or scene.winch.kind == "fixed":
        return  # fixed winches follow no reference: it only measures the error (a pendulum swings)
    directions = np.stack(pulls, axis=2)  # (N, 2, m)
    unheld = first_unheld(directions, np.array([0.0, weight]))  # the cables must pull the platform up by its weight
    if unheld is not None:
        k, residual, _ = unheld
        upward = directions[k][1]
        reason = ("every cable pulls it downwards (it is above the pulleys)" if np.all(upward <= 0.0)
                  else "the cables' pulls cannot combine into an upward force without one pushing")
        raise UnreachableError(
            f"{_pose_text(times, poses, k)} is outside the workspace: the cables cannot hold the "
            f"platform's weight ({weight:.4g} N, platform.mass = {scene.platform.mass} kg) with "
            f"non-negative tensions, because {reason}; an unbalanced force of {residual:.4g} N remains")


def limits_text(free: np.ndarray, limits: np.ndarray) -> str:
    """The cables whose needed tension lies outside their limits, naming the scene fields."""
    outside = [f"cable {i + 1} needs {free[i]:.4g} N (cables[{i}].min_tension = {limits[i, 0]:g} N, "
               f"cables[{i}].max_tension = {limits[i, 1]:g} N)"
               for i in range(len(free)) if not limits[i, 0] <= free[i] <= limits[i, 1]]
    return "; ".join(outside) or "no tensions within the limits balance the platform"


def _check_tension_limits(scene, times, poses, pulls) -> None:
    limits = scene.tension_limits
    if limits is None or scene.winch.kind == "fixed":
        return
    mass, gravity = scene.platform.mass, scene.gravity
    acceleration = np.atleast_2d(scene.trajectory.acceleration(times))[:, :2]
    needed = mass * (acceleration + np.array([0.0, gravity]))  # (N, 2): what the cables must give the platform
    unheld = first_unheld(np.stack(pulls, axis=2), needed, limits)
    if unheld is not None:
        k, residual, free = unheld
        raise UnreachableError(
            f"{_pose_text(times, poses, k)} cannot be held within the cables' tension limits: "
            f"{limits_text(free, limits)} to give the platform its weight and the reference's acceleration "
            f"({np.round(needed[k], 4).tolist()} N); {residual:.4g} N would remain unbalanced")


def check_reference(scene) -> None:
    """Refuse a reference trajectory the cables cannot follow, before any simulation.

    Raises
    ------
    UnreachableError
        Naming the time, the pose and the scene fields that conflict (``platform.anchors[i]``,
        ``pulleys[i].center``, ``pulleys[i].radius``, ``cables[i].unstrained_length``,
        ``platform.mass``, ``cables[i].min_tension``, ``cables[i].max_tension``).
    """
    times, poses = reference_samples(scene)
    anchors = anchor_points(poses, np.asarray(scene.platform.anchors))
    _check_anchors_outside_discs(scene, times, poses, anchors)
    lengths, pulls = _exits(scene, times, poses, anchors)
    _check_lengths(scene, times, poses, lengths)
    _check_weight_held(scene, times, poses, pulls)
    _check_tension_limits(scene, times, poses, pulls)
