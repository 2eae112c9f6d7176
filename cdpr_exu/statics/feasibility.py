"""Whether the cables hold the platform at a pose with every tension within [t_min, t_max]: massless or catenary.

Two models of one question, either dimension (the scene's :class:`~cdpr_exu.space.Space`); pure NumPy/SciPy:

* **massless** (:func:`massless_holding`): straight cables, the structure matrix
  (:func:`~cdpr_exu.statics.kinematics.structure_matrix`) and the tension distribution
  (:func:`~cdpr_exu.statics.tension_distribution.tension_distribution`);
* **catenary** (:func:`catenary_holding`): elastic catenaries from the exits to the anchors
  (:func:`~cdpr_exu.statics.statics.inverse_cable`), whose weight and sag turn the pull at each anchor and
  make the tension vary along the cable. The tension distribution is iterated with the catenaries' end
  forces: the structure matrix's columns are the catenaries' unit pulls at the anchors, each anchor
  tension's bounds are shifted by the cable's spread of tension (so that its lowest and highest tension
  along it stay within [t_min, t_max]), and each cable's horizontal tension is rescaled to the anchor
  tension found; converged when the anchor tensions change by less than :data:`TOLERANCE` of t_max.

The moment is asked as :mod:`cdpr_exu.statics.workspace` asks it: when the cables can turn the platform
about every axis; otherwise (a point mass, too few cables) the force alone. Units SI.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from cdpr_exu.core.errors import SceneError, UnreachableError
from cdpr_exu.statics.kinematics import cable_exits, structure_matrix
from cdpr_exu.statics.statics import catenary_platform, inverse_cable
from cdpr_exu.statics.tension_distribution import tension_distribution, weight_wrench
from cdpr_exu.statics.workspace import _turns

#: What each status means.
STATUSES = {
    "held": "every tension along every cable within [t_min, t_max], the platform balanced",
    "outside_limits": "no tensions within [t_min, t_max] balance the platform (catenary: at the last iterate's sag)",
    "unreachable": "a cable cannot reach its anchor over its exit",
    "not_converged": "the catenary iteration did not converge, or a catenary had no solution",
}
#: Largest change of the anchor tensions, relative to t_max, at which the catenary iteration has converged.
TOLERANCE = 1e-9
#: Catenary iterations before a pose counts as not converged.
MAX_ITERATIONS = 60
#: Most residual evaluations of the least-squares search (each with a Jacobian of m more by differences).
SEARCH_EVALUATIONS = 60
#: Points along each catenary at which its distance from its chord is measured (the sag: 0.1 % of it, parabola).
SAG_SAMPLES = 33


@dataclass(frozen=True)
class Holding:
    """How one model holds the platform at one pose: a status (:data:`STATUSES`) and, where held, per cable
    (shape (m,)): the tension at the anchor and at the exit [N] (equal for a massless cable), the length [m]
    (massless: the straight path from where the cable's length counts; catenary: the unstrained length) and
    the sag [m] (largest distance of the cable from the chord between its ends; 0 for a massless cable)."""

    status: str
    anchor_tensions: np.ndarray | None = None
    exit_tensions: np.ndarray | None = None
    lengths: np.ndarray | None = None
    sags: np.ndarray | None = None
    iterations: int = 0

    @property
    def held(self) -> bool:
        return self.status == "held"


def tension_bounds(scene, min_tension=None, max_tension=None) -> np.ndarray:
    """Each cable's (t_min, t_max) [N], shape (m, 2): the scene's, or the ones given for every cable.

    Raises
    ------
    SceneError
        Naming ``cables[i].min_tension`` / ``max_tension`` when a cable has no finite limit and none is given.
    """
    limits = scene.tension_limits
    limits = np.array([[0.0, np.inf]] * scene.n_cables) if limits is None else limits.copy()
    for column, value in enumerate((min_tension, max_tension)):
        if value is not None:
            limits[:, column] = value
    for i, (low, high) in enumerate(limits):
        if not (np.isfinite(high) and 0.0 <= low < high):
            raise SceneError(f"cables[{i}].min_tension and cables[{i}].max_tension must bound the tension "
                             f"(0 <= t_min < t_max < inf) for a workspace, got {low:g} and {high:g} N "
                             "(set them in the scene, or give min_tension and max_tension)")
    return limits


def _rows(scene, matrix) -> int:
    return scene.space.wrench_size if _turns(scene, matrix) else scene.space.position_size


def massless_holding(scene, pose, limits) -> Holding:
    """The massless model at ``pose`` (pose_size,) [m, rad] within ``limits`` (m, 2) [N] (:func:`tension_bounds`)."""
    try:
        exits = cable_exits(scene, pose)
        matrix = structure_matrix(scene, pose)
    except UnreachableError:
        return Holding("unreachable")
    rows = _rows(scene, matrix)
    try:
        tensions = tension_distribution(matrix[:rows], weight_wrench(scene)[:rows], limits[:, 0], limits[:, 1])
    except UnreachableError:
        return Holding("outside_limits")
    return Holding("held", tensions, tensions, np.array([float(e.cable_length) for e in exits]),
                   np.zeros(scene.n_cables))


def _sag(cable) -> float:
    points = cable.points(np.linspace(0.0, cable.suspended_length, SAG_SAMPLES))
    offsets, chord = points - points[0], points[-1] - points[0]
    return float(np.max(np.linalg.norm(offsets - np.outer(offsets @ chord / (chord @ chord), chord), axis=1)))


def catenary_holding(scene, pose, limits, start=None, platform=None) -> Holding:
    """The catenary model at ``pose`` (pose_size,) [m, rad] within ``limits`` (m, 2) [N] (module notes).

    The iteration is local: it starts from ``start`` (m,) [N] (the massless model's anchor tensions, when
    they hold), then from the mid tensions; where neither converges from the massless tensions, a bounded
    least-squares search (:func:`_search`) looks for tensions that balance the platform within the limits
    near them, and the iteration starts again from what it finds (kept if the iteration fails from there).
    ``platform``: the scene's :func:`~cdpr_exu.statics.statics.catenary_platform`, when already made.
    """
    pose = np.asarray(pose, dtype=float)
    platform = catenary_platform(scene) if platform is None else platform
    try:
        matrix = structure_matrix(scene, pose)
    except UnreachableError:
        return Holding("unreachable")
    lower, upper = limits[:, 0], limits[:, 1]
    guesses = ([] if start is None else [np.asarray(start, dtype=float)]) + [0.5 * (lower + upper)]
    attempts = [_iterate(scene, platform, pose, matrix, limits, guess) for guess in guesses]
    if start is not None and not any(a.held for a in attempts):
        found = _search(scene, platform, pose, matrix, limits, guesses[0])
        if found.held:
            polished = _iterate(scene, platform, pose, matrix, limits, found.anchor_tensions)
            return polished if polished.held else found
        attempts.insert(0, found)
    return next((a for a in attempts if a.held), None) or next(
        (a for a in attempts if a.status == "outside_limits"), attempts[-1])


def _cables(platform, horizontal, points):
    """The catenaries of horizontal tensions (m,) [N] to the anchor points; their anchor tensions and the
    lowest and highest tension along each (the lowest is H where the cable dips below both ends)."""
    cables = [inverse_cable(c, h, p)[0] for c, h, p in zip(platform.cables, horizontal, points)]
    states = [c.catenary for c in cables]
    lowest = np.array([s.horizontal_tension if s.vertical_tension_a * s.vertical_tension_b < 0.0
                       else min(s.tension_a, s.tension_b) for s in states])
    return cables, lowest, np.array([s.max_tension for s in states])


def _held(cables, iterations) -> Holding:
    return Holding("held", np.array([c.tension_at_anchor for c in cables]), np.array([c.tension_at_exit for c in cables]),
                   np.array([c.unstrained_length for c in cables]), np.array([_sag(c) for c in cables]), iterations)


def _search(scene, platform, pose, matrix, limits, target) -> Holding:
    """Bounded nonlinear least squares over the horizontal tensions: the imbalance (over the platform's weight)
    and each tension's excess beyond its limits (over t_max); held where both vanish (to :data:`TOLERANCE`)."""
    space, anchors = scene.space, np.asarray(scene.platform.anchors, dtype=float)
    rows, wrench, points = _rows(scene, matrix), weight_wrench(scene), space.anchor_points(pose, anchors)
    scale, top = max(float(np.linalg.norm(wrench)), 1e-300), float(np.max(limits[:, 1]))

    def residual(horizontal):
        try:
            cables, lowest, highest = _cables(platform, horizontal, points)
        except (UnreachableError, SceneError, ArithmeticError):
            return np.full(rows + 2 * len(horizontal), 1e3)
        forces = np.array([c.force_on_platform for c in cables])
        imbalance = np.concatenate([forces.sum(axis=0), space.moments(pose, anchors, forces).sum(axis=0)])[:rows]
        excess = np.concatenate([np.maximum(limits[:, 0] - lowest, 0.0), np.maximum(highest - limits[:, 1], 0.0)])
        return np.concatenate([(imbalance + wrench[:rows]) / scale, excess / top])

    start = np.clip(target * np.linalg.norm(matrix[:space.vertical], axis=0), 1e-3 * top, top)
    fit = least_squares(residual, start, bounds=(1e-6 * top, top), xtol=1e-15, ftol=1e-15, gtol=1e-15, max_nfev=SEARCH_EVALUATIONS)
    if np.max(np.abs(fit.fun)) > TOLERANCE:
        return Holding("outside_limits" if fit.status > 0 else "not_converged", iterations=int(fit.nfev))
    return _held(_cables(platform, fit.x, points)[0], int(fit.nfev))


def _iterate(scene, platform, pose, matrix, limits, target) -> Holding:
    """The tension distribution iterated with the catenaries' end forces from the anchor tensions ``target``."""
    space, anchors = scene.space, np.asarray(scene.platform.anchors, dtype=float)
    rows, wrench = _rows(scene, matrix), weight_wrench(scene)
    lower, upper = limits[:, 0], limits[:, 1]
    horizontal = target * np.linalg.norm(matrix[:space.vertical], axis=0)  # the straight pull's horizontal part
    points = space.anchor_points(pose, anchors)
    for iteration in range(1, MAX_ITERATIONS + 1):
        try:
            cables, lowest, highest = _cables(platform, horizontal, points)
        except (UnreachableError, SceneError, ArithmeticError):
            return Holding("not_converged", iterations=iteration)
        forces = np.array([c.force_on_platform for c in cables])
        at_anchor = np.linalg.norm(forces, axis=1)
        if iteration > 1 and np.max(np.abs(at_anchor - target)) <= TOLERANCE * np.max(upper):
            rounding = TOLERANCE * np.max(upper)
            if np.all(lowest >= lower - rounding) and np.all(highest <= upper + rounding):
                return _held(cables, iteration)
            return Holding("outside_limits", iterations=iteration)
        # the anchor forces to first order in the anchor tensions f: F_i + s_i (f_i - |F_i|), s_i = dF_i/df_i
        steps = 1e-6 * horizontal
        try:
            shifted = np.array([inverse_cable(c, h + dh, p)[0].force_on_platform
                                for c, h, dh, p in zip(platform.cables, horizontal, steps, points)])
        except (UnreachableError, SceneError, ArithmeticError):
            return Holding("not_converged", iterations=iteration)
        pulls, rates = forces / at_anchor[:, None], (shifted - forces) / steps[:, None]  # rates: dF_i/dH_i
        growth = np.sum(pulls * rates, axis=1)  # d|F_i|/dH_i
        slopes, offsets = rates / growth[:, None], forces - rates / growth[:, None] * at_anchor[:, None]
        columns = np.concatenate([slopes.T, space.moments(pose, anchors, slopes).T])[:rows]
        rest = np.concatenate([offsets.sum(axis=0), space.moments(pose, anchors, offsets).sum(axis=0)])[:rows]
        low, high = lower + (at_anchor - lowest), upper - (highest - at_anchor)
        if np.any(low > high):
            return Holding("outside_limits", iterations=iteration)
        try:
            target = tension_distribution(columns, wrench[:rows] + rest, low, high)
        except UnreachableError:
            return Holding("outside_limits", iterations=iteration)
        horizontal = np.maximum(horizontal + (target - at_anchor) / growth, 0.5 * horizontal)
    return Holding("not_converged", iterations=MAX_ITERATIONS)
