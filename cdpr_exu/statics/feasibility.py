"""Whether the cables hold the platform at a pose with every tension within [t_min, t_max]: massless or catenary.

Two models of one question, either dimension (the scene's :class:`~cdpr_exu.space.Space`); pure NumPy/SciPy.
**Massless** (:func:`massless_holding`): straight cables, the structure matrix and the tension distribution
(:func:`~cdpr_exu.statics.tension_distribution.tension_distribution`). **Catenary** (:func:`catenary_holding`):
elastic catenaries from the exits to the anchors (:func:`~cdpr_exu.statics.statics.inverse_cable`), whose
weight and sag turn each cable's pull and make its tension vary along it: every tension along every cable must
lie within the limits (the lowest is H where the cable dips below both its ends). The tension distribution is
iterated with the catenaries' end forces (Newton's method on the anchor tensions f: the anchor forces to first
order ``F_i + s_i (f_i - |F_i|)``, ``s_i = dF_i/df_i`` by a difference in H, and each tension's bounds shifted
by its cable's spread of tension), converged when the anchor tensions change by less than :data:`TOLERANCE`
of t_max. The iteration is local: it starts from the massless tensions, then from the mid tensions, and where
neither converges a bounded least-squares search over the horizontal tensions looks for tensions near the
massless ones that balance the platform within the limits. The moment is asked as
:mod:`cdpr_exu.statics.workspace` asks it: when the cables can turn the platform about every axis. Units SI.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from cdpr_exu.core.errors import SceneError, UnreachableError
from cdpr_exu.statics.kinematics import cable_exits, structure_matrix
from cdpr_exu.statics.statics import catenary_platform, inverse_cable
from cdpr_exu.statics.tension_distribution import tension_distribution, weight_wrench
from cdpr_exu.statics.workspace import cables_turn_platform

#: What each status means.
STATUSES = {
    "held": "every tension along every cable within [t_min, t_max], the platform balanced",
    "outside_limits": "no tensions within [t_min, t_max] found that balance the platform",
    "unreachable": "a cable cannot reach its anchor over its exit",
    "not_converged": "the catenary iteration did not converge, or a catenary had no solution",
}
#: Change of the anchor tensions (and imbalance of the search), relative to t_max (the weight), at convergence.
TOLERANCE = 1e-9
#: Catenary iterations before an attempt counts as not converged.
MAX_ITERATIONS = 60
#: Most residual evaluations of the least-squares search (each with a Jacobian of m more by differences).
SEARCH_EVALUATIONS = 60
#: Points along each catenary at which its distance from its chord is measured (the sag: 0.1 % of it, parabola).
SAG_SAMPLES = 33
_FAILED = (UnreachableError, SceneError, ArithmeticError)


@dataclass(frozen=True)
class Holding:
    """How one model holds the platform at one pose: a status (:data:`STATUSES`) and, where held, per cable
    (shape (m,)): the tension at the anchor and at the exit [N] (equal for a massless cable), the length [m]
    (massless: the straight path from where the cable's length counts; catenary: the unstrained length) and
    the sag [m] (largest distance of the cable from its chord; 0 massless); the catenary's iterations."""

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
    return scene.space.wrench_size if cables_turn_platform(scene, matrix) else scene.space.position_size


def massless_holding(scene, pose, limits) -> Holding:
    """The massless model at ``pose`` (pose_size,) [m, rad] within ``limits`` (m, 2) [N] (:func:`tension_bounds`)."""
    try:
        exits, matrix = cable_exits(scene, pose), structure_matrix(scene, pose)
    except UnreachableError:
        return Holding("unreachable")
    rows = _rows(scene, matrix)
    try:
        tensions = tension_distribution(matrix[:rows], weight_wrench(scene)[:rows], limits[:, 0], limits[:, 1])
    except UnreachableError:
        return Holding("outside_limits")
    return Holding("held", tensions, tensions, np.array([float(e.cable_length) for e in exits]),
                   np.zeros(scene.n_cables))


class _Catenaries:
    """The catenary model of one scene at one pose (:func:`catenary_holding`)."""

    def __init__(self, scene, platform, pose, matrix, limits):
        self.space, self.platform, self.pose, self.limits = scene.space, platform, pose, limits
        self.anchors = np.asarray(scene.platform.anchors, dtype=float)
        self.points = self.space.anchor_points(pose, self.anchors)
        self.rows, self.wrench = _rows(scene, matrix), weight_wrench(scene)
        self.across = np.linalg.norm(matrix[:self.space.vertical], axis=0)  # the straight pulls' horizontal parts

    def cables(self, horizontal):
        """The catenaries of horizontal tensions (m,) [N], their anchor forces (m, d) [N] and each cable's
        lowest and highest tension along it [N]."""
        cables = [inverse_cable(c, h, p)[0] for c, h, p in zip(self.platform.cables, horizontal, self.points)]
        states = [c.catenary for c in cables]
        lowest = [s.horizontal_tension if s.vertical_tension_a * s.vertical_tension_b < 0.0
                  else min(s.tension_a, s.tension_b) for s in states]
        return (cables, np.array([c.force_on_platform for c in cables]), np.array(lowest),
                np.array([s.max_tension for s in states]))

    def wrench_of(self, forces):
        """The wrench of forces (m, d) [N] at the anchors, the rows asked [N, N m]."""
        return np.concatenate([forces.T, self.space.moments(self.pose, self.anchors, forces).T])[:self.rows]

    def iterate(self, target) -> Holding:
        """Newton's method on the anchor tensions from ``target`` (m,) [N] (module notes)."""
        lower, upper = self.limits[:, 0], self.limits[:, 1]
        horizontal, rounding = target * self.across, TOLERANCE * np.max(upper)
        for iteration in range(1, MAX_ITERATIONS + 1):
            steps = 1e-6 * horizontal
            try:
                cables, forces, lowest, highest = self.cables(horizontal)
                shifted = self.cables(horizontal + steps)[1]
            except _FAILED:
                return Holding("not_converged", iterations=iteration)
            at_anchor = np.linalg.norm(forces, axis=1)
            if iteration > 1 and np.max(np.abs(at_anchor - target)) <= rounding:
                held = np.all(lowest >= lower - rounding) and np.all(highest <= upper + rounding)
                return _held(cables, iteration) if held else Holding("outside_limits", iterations=iteration)
            rates = (shifted - forces) / steps[:, None]  # dF_i/dH_i
            growth = np.sum(forces * rates, axis=1) / at_anchor  # d|F_i|/dH_i
            slopes = rates / growth[:, None]
            low, high = lower + (at_anchor - lowest), upper - (highest - at_anchor)
            try:
                if np.any(low > high):
                    raise UnreachableError("a cable's spread of tension exceeds its limits")
                offsets = self.wrench_of(forces - slopes * at_anchor[:, None]).sum(axis=1)
                target = tension_distribution(self.wrench_of(slopes), self.wrench[:self.rows] + offsets, low, high)
            except UnreachableError:
                return Holding("outside_limits", iterations=iteration)
            horizontal = np.maximum(horizontal + (target - at_anchor) / growth, 0.5 * horizontal)
        return Holding("not_converged", iterations=MAX_ITERATIONS)

    def search(self, target) -> Holding:
        """Bounded least squares over the horizontal tensions, from the anchor tensions ``target`` (m,) [N]: the
        imbalance over the weight and each tension's excess beyond its limits over t_max; held where both vanish."""
        scale, top = max(float(np.linalg.norm(self.wrench)), 1e-300), float(np.max(self.limits[:, 1]))

        def residual(horizontal):
            try:
                _, forces, lowest, highest = self.cables(horizontal)
            except _FAILED:
                return np.full(self.rows + 2 * len(horizontal), 1e3)
            excess = np.concatenate([np.maximum(self.limits[:, 0] - lowest, 0.0),
                                     np.maximum(highest - self.limits[:, 1], 0.0)])
            imbalance = self.wrench_of(forces).sum(axis=1) + self.wrench[:self.rows]
            return np.concatenate([imbalance / scale, excess / top])

        fit = least_squares(residual, np.clip(target * self.across, 1e-3 * top, top), bounds=(1e-6 * top, top),
                            xtol=1e-15, ftol=1e-15, gtol=1e-15, max_nfev=SEARCH_EVALUATIONS)
        if np.max(np.abs(fit.fun)) > TOLERANCE:
            return Holding("outside_limits" if fit.status > 0 else "not_converged", iterations=int(fit.nfev))
        return _held(self.cables(fit.x)[0], int(fit.nfev))


def _sag(cable) -> float:
    points = cable.points(np.linspace(0.0, cable.suspended_length, SAG_SAMPLES))
    offsets, chord = points - points[0], points[-1] - points[0]
    return float(np.max(np.linalg.norm(offsets - np.outer(offsets @ chord / (chord @ chord), chord), axis=1)))


def _held(cables, iterations) -> Holding:
    return Holding("held", np.array([c.tension_at_anchor for c in cables]), np.array([c.tension_at_exit for c in cables]),
                   np.array([c.unstrained_length for c in cables]), np.array([_sag(c) for c in cables]), iterations)


def catenary_holding(scene, pose, limits, start=None, platform=None) -> Holding:
    """The catenary model at ``pose`` (pose_size,) [m, rad] within ``limits`` (m, 2) [N] (module notes).

    ``start`` (m,) [N]: the massless model's anchor tensions, where it holds (the search runs only from
    them); ``platform``: the scene's :func:`~cdpr_exu.statics.statics.catenary_platform`, when already made.
    """
    pose = np.asarray(pose, dtype=float)
    try:
        matrix = structure_matrix(scene, pose)
    except UnreachableError:
        return Holding("unreachable")
    model = _Catenaries(scene, catenary_platform(scene) if platform is None else platform, pose, matrix, limits)
    starts = ([] if start is None else [np.asarray(start, dtype=float)]) + [limits.mean(axis=1)]
    attempts = [model.iterate(guess) for guess in starts]
    if start is not None and not any(a.held for a in attempts):
        attempts.insert(0, model.search(starts[0]))
        if attempts[0].held:  # the iteration from there gives the tensions nearest the mid ones, where it converges
            polished = model.iterate(attempts[0].anchor_tensions)
            return polished if polished.held else attempts[0]
    return next((a for a in attempts if a.held), None) or next(
        (a for a in attempts if a.status == "outside_limits"), attempts[-1])
