"""Kineto-static equilibrium of a platform hung on elastic catenary cables, in the plane or in space.

One statics for both dimensions: a :class:`SuspendedPlatform` (its :class:`~cdpr_exu.space.Space`,
cables, mass, gravity, inertia), made from a scene by :func:`catenary_platform`; one forward
driver :func:`solve_statics` (the pose from the cables' unstrained lengths) and one inverse
driver :func:`solve_inverse_statics` (the lengths that hold a pose), both returning a
:class:`PlatformEquilibrium` of :class:`CableEquilibrium`. Units SI, gravity along -z.

**Poses.** Planar (the paper's vertical x-z plane): ``(x, z, phi)``, ``phi`` counter-clockwise
(paper eq. 17), an anchor ``b_i`` at ``r + R(phi) b_i``, moments ``m = a_x f_z - a_z f_x``.
Spatial (z up): ``(r, theta)``, ``theta`` the rotation vector, ``R = exp([theta]x)``; a change
``d theta`` turns the body by ``J_l(theta) d theta`` (left Jacobian of SO(3)), so the generalised
force on ``theta`` is ``J_l^T M``. A point mass (every anchor at the centre of mass) has only its
position solved. Each dimension keeps its floating-point pose kernel (:class:`_PlanarStatics`,
:class:`_SpatialStatics`): residual, pose Jacobian, straight-cable start and inverse.

**Cables.** Each cable is an elastic catenary (:mod:`cdpr_exu.physics.catenary`) from its anchor
(end A) to its exit (end B), solved as the exit asks (:func:`forward_cable`, :func:`inverse_cable`):

* planar, a fixed exit point, or a pulley: up the winch line ``x = c_x + side r_p``, over the top and
  off the rim tangentially, the length counted from the hang point ``(c_x + side r_p, c_z)``.
  Frictionless (the wrap's unstrained length ``r_p wrap / (1 + T / EA)``), its weight carried by the
  pulley (at most ``w r_p`` of tension: 7e-6 m of stretch, 2.5e-6 relative stiffness asymmetry for the
  paper's cable); rigid rim, no pulley inertia;
* spatial, a point exit: the planar catenary in the vertical plane through the ends (MoorPy's trick),
  its end stiffness ``Q K2 Q^T - (H / h) (P_h - u u^T)``, ``Q = [u, e_z]``, ``u`` the horizontal
  direction from the anchor to the exit and ``h`` the horizontal span (a sideways step turns the pull;
  vertical: ``H / h`` tends to ``-K2[0, 0]``);
* spatial, a swivel pulley: the planar pulley cable in the vertical plane through the axis and the
  anchor, its stiffness ``Q K2 Q^T + (f_rho / rho) (P_h - e_rho e_rho^T)``.

**Solvers.** The forward problem is an energy minimum (:func:`solve_statics`); statically
indeterminate robots need no tension distribution (the cables' elasticity picks the equilibrium).
The inverse (:func:`solve_inverse_statics`) is parametrised by the horizontal tensions, so it
needs every cable off the vertical. Both accept an external wrench (eg :func:`inertial_wrench`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import brentq, minimize

from cdpr_exu.core.errors import SceneError, UnreachableError
from cdpr_exu.core.geometry import all_at_centre
from cdpr_exu.core.geometry import (left_jacobian, perpendicular, planar_cross, rotation_from_vector, rotation_matrix,
                                    rotation_vector, skew, swivel_pulley_exit)
from cdpr_exu.core.validation import finite, non_negative, positive, real_array, shown, vector
from cdpr_exu.exits import Exit, Pulley
from cdpr_exu.physics.catenary import (DEFAULT_MAX_STRAIN, STANDARD_GRAVITY, CatenaryCable, CatenaryState,
                                       end_stiffness, profile, solve_forward, solve_inverse, span_and_jacobian,
                                       state_from_end_forces, tension_limit)
from cdpr_exu.space import PLANE, SPACE, Space, space_of

_RELATIVE_TOLERANCE = 1e-12
"""Target of the scaled wrench residual (the cables are solved to 1e-12 of their length)."""

_E_Z = np.array([0.0, 0.0, 1.0])
_HORIZONTAL = np.diag([1.0, 1.0, 0.0])
_PLANE_X = np.array([1.0, 0.0])


def _point(name, value, size=None):
    """A point as a tuple of floats: (x, z) or (x, y, z) [m], its size given or read from ``value``."""
    if size is None:
        size = 2 if isinstance(value, (tuple, list, np.ndarray)) and len(value) == 2 else 3
    labels = space_of(size).position_labels
    return tuple(float(v) for v in vector(name, value, size, f" ({', '.join(labels)}) [m]"))


@dataclass(frozen=True)
class SuspendedCable:
    """One cable of the platform: its weight per unstrained length ``w >= 0`` [N/m], ``EA > 0`` [N], its
    anchor (platform frame, centre of mass at 0; default the centre) and exactly one of ``exit_point``
    (world frame, (x, z) or (x, y, z) [m]: its size is the cable's dimension) and ``pulley``, the
    :class:`~cdpr_exu.exits.Exit` it leaves from (an exit it does not wrap is taken as its point)."""

    weight_per_length: float
    axial_stiffness: float
    anchor: tuple | None = None
    exit_point: tuple | None = None
    pulley: Exit | None = None

    def __post_init__(self):
        set_ = object.__setattr__
        set_(self, "weight_per_length", non_negative("weight_per_length", self.weight_per_length))
        set_(self, "axial_stiffness", positive("axial_stiffness", self.axial_stiffness))
        if (self.exit_point is None) == (self.pulley is None):
            raise SceneError(f"give exactly one of exit_point and pulley, got exit_point={shown(self.exit_point)}, "
                             f"pulley={shown(self.pulley)}")
        if self.exit_point is not None:
            set_(self, "exit_point", _point("exit_point", self.exit_point))
        elif not isinstance(self.pulley, Exit):
            raise SceneError(f"pulley must be a Pulley or another exit (cdpr_exu.exits), got {shown(self.pulley)}")
        elif not self.pulley.wraps:  # the cable leaves from the exit's point
            set_(self, "exit_point", _point("exit_point", self.pulley.point))
            set_(self, "pulley", None)
        size = len(self.point)
        set_(self, "anchor", _point("anchor", (0.0,) * size if self.anchor is None else self.anchor, size))

    @property
    def space(self) -> Space:
        """The space the cable hangs in, from the size of its exit's point."""
        return space_of(len(self.point))

    @property
    def point(self) -> tuple:
        """The exit's fixed point [m]: the exit point, a planar pulley's centre or a swivel's inlet."""
        return self.exit_point if self.pulley is None else tuple(self.pulley.point)

    @property
    def hang_point(self) -> np.ndarray:
        """Where the unstrained length counts from, shape (d,) [m] (:attr:`cdpr_exu.exits.Exit.hang_point`)."""
        return np.array(self.exit_point) if self.pulley is None else self.pulley.hang_point

    @property
    def pulley_radius(self) -> float:
        """Radius [m] of the disc the cable wraps over; 0 for a fixed exit point."""
        return 0.0 if self.pulley is None else float(self.pulley.radius)

    def catenary(self, unstrained_length):
        """The `CatenaryCable` of this cable with the given unstrained length [m]."""
        return CatenaryCable(unstrained_length, self.weight_per_length, self.axial_stiffness)


@dataclass(frozen=True)
class SuspendedPlatform:
    """A platform hung on catenary cables (all planar or all spatial), of mass ``M >= 0`` [kg] whose weight
    ``M g`` (``gravity`` [m/s^2], default 9.81) acts at its centre of mass along -z; ``inertia`` [kg m^2]
    about it: planar about the plane's normal, spatial the principal moments (default 0).

    Raises SceneError naming the field: no cables, cables of two dimensions, a negative mass, two cables
    sharing an exit point, two cables of a rigid platform sharing an anchor, too few cables to hang it (a
    point mass needs one, a rigid body two), or, in space, anchors all on one line through the centre of
    mass (it would turn freely about it).
    """

    cables: tuple
    mass: float
    gravity: float = STANDARD_GRAVITY
    inertia: float | tuple | None = None

    def __post_init__(self):
        try:
            cables = tuple(self.cables)
        except TypeError:
            raise SceneError(f"cables must be a sequence of SuspendedCable, got {shown(self.cables)}") from None
        if not all(isinstance(c, SuspendedCable) for c in cables):
            raise SceneError(f"cables must be a sequence of SuspendedCable, got {shown(self.cables)}")
        if len({c.space for c in cables}) > 1:
            raise SceneError("cables must all be planar or all spatial, got exits "
                             f"{[list(c.point) for c in cables]}")
        object.__setattr__(self, "cables", cables)
        object.__setattr__(self, "mass", non_negative("mass", self.mass))
        object.__setattr__(self, "gravity", non_negative("gravity", self.gravity))
        needed = 1 if self.is_point_mass else 2
        if len(cables) < needed:
            kind = "a point mass" if needed == 1 else "a rigid platform"
            raise SceneError(f"cables: {kind} needs at least {needed} cable(s) to hang, got {len(cables)}")
        object.__setattr__(self, "inertia", _KERNELS[self.space].inertia(self.inertia))
        exits = np.array([c.point for c in cables])
        anchors = self.anchors
        size = max(1.0, float(np.abs(exits).max(initial=0.0)))
        for i in range(len(cables)):
            for j in range(i):
                if np.linalg.norm(exits[i] - exits[j]) <= 1e-9 * size:
                    raise SceneError(f"cables[{j}] and cables[{i}] share the exit_point {shown(exits[i])} m")
        if not self.is_point_mass:
            arm = max(float(np.linalg.norm(anchors, axis=1).max()), 1e-300)
            for i in range(len(cables)):
                for j in range(i):
                    if np.linalg.norm(anchors[i] - anchors[j]) <= 1e-9 * arm:
                        raise SceneError(f"cables[{j}] and cables[{i}] share the anchor {shown(anchors[i])} m "
                                         f"on a rigid platform")
            # the anchors must pin every axis the platform can turn about: in space, not all on one line
            if np.linalg.matrix_rank(anchors, tol=1e-9 * arm) < min(2, self.space.rotation_size):
                raise SceneError(f"cables: the anchors {anchors.tolist()} m lie on one line through the centre "
                                 f"of mass; the platform would turn freely about it")

    @property
    def space(self) -> Space:
        """The platform's space (:data:`~cdpr_exu.space.PLANE` or :data:`~cdpr_exu.space.SPACE`)."""
        return self.cables[0].space

    @property
    def is_point_mass(self):
        """True when every anchor is at the centre of mass."""
        return all_at_centre([c.anchor for c in self.cables])

    @property
    def degrees_of_freedom(self):
        """The position's size for a point mass, the pose's for a rigid platform: 2 | 3 planar, 3 | 6 spatial."""
        return self.space.position_size if self.is_point_mass else self.space.pose_size

    @property
    def anchors(self):
        """Anchors in the platform frame, shape (n_cables, d) [m]."""
        return np.array([c.anchor for c in self.cables])


def catenary_platform(scene) -> SuspendedPlatform:
    """The catenary-statics model of a scene's robot: each cable's ``w = rho0 g`` [N/m] (0 without cable
    mass or gravity), ``EA``, anchor and exit, the platform's mass, gravity (0 when off) and inertia;
    SceneError if a weight per length overflows or the platform cannot hang."""
    gravity = scene.gravity if scene.effects.gravity else 0.0
    weighs = scene.effects.cable_mass and scene.effects.gravity
    weights = [c.linear_density * gravity if weighs else 0.0 for c in scene.cables]
    for i, (cable, weight) in enumerate(zip(scene.cables, weights)):
        if not math.isfinite(weight):
            raise SceneError(f"cables[{i}].linear_density = {shown(cable.linear_density)} kg/m and gravity = "
                             f"{shown(gravity)} m/s^2 give a weight per length of {shown(weight)} N/m, out of "
                             "floating-point range")
    cables = [SuspendedCable(w, c.axial_rigidity, anchor=a, pulley=exit_)
              for c, w, exit_, a in zip(scene.cables, weights, scene.exits, scene.platform.anchors)]
    return SuspendedPlatform(tuple(cables), scene.platform.mass, gravity, scene.platform.inertia)


def inertial_wrench(platform, acceleration, angular_acceleration=None):
    """D'Alembert load ``(-M a, -I alpha)`` (wrench_size,) [N, N m] for dynamic feed-forward, as
    ``external_wrench`` of the statics (the cables' inertia neglected: they stay quasi-static).

    ``acceleration`` (d,) [m/s^2] of the centre of mass; ``angular_acceleration`` [rad/s^2], planar a float,
    spatial (3,) about the platform's principal axes (no gyroscopic term; at the reference orientation)."""
    space = platform.space
    a = vector("acceleration", acceleration, space.position_size, f" ({', '.join(space.position_labels)}) [m/s^2]")
    if angular_acceleration is None:
        moment = np.zeros(space.rotation_size)
    else:
        alpha = real_array("angular_acceleration", angular_acceleration).reshape(-1)
        if alpha.shape != (space.rotation_size,):
            raise SceneError(f"angular_acceleration must have {space.rotation_size} entries [rad/s^2], "
                             f"got {shown(angular_acceleration)}")
        moment = -np.asarray(platform.inertia) * alpha
    return np.concatenate([-platform.mass * a, moment])


def chain_element_mass(cable, length, n_elements, gravity):
    """Mass of one of the ``n_elements`` equal elements of ``cable`` (a :class:`SuspendedCable`) of unstrained
    ``length`` [m] [kg]: its weight per length over ``gravity`` [m/s^2] (> 0)."""
    return cable.weight_per_length / gravity * length / n_elements


def node_masses_along(n_elements, element_mass, mass_lumping="consistent"):
    """Lumped masses of the n + 1 nodes of a cable of equal elements, exit first, shape (n + 1,) [kg]:
    "consistent" puts half of each element on each of its nodes; "paper" puts it on its far node,
    the held exit node getting half an element."""
    masses = np.full(n_elements + 1, float(element_mass))
    masses[0] = 0.5 * element_mass
    if mass_lumping == "consistent":
        masses[-1] = 0.5 * element_mass
    return masses


@dataclass(frozen=True, eq=False)
class CableEquilibrium:
    """One cable in a platform equilibrium; d is the space's dimension.

    Attributes
    ----------
    catenary : CatenaryState
        The suspended part in its vertical plane, A at the anchor, B at the exit or tangent point.
    unstrained_length : float [m]
        Total: suspended part plus, over a pulley, the wrap up to the hang point.
    anchor_point, exit_point : ndarray, shape (d,) [m]
        The anchor and the exit (over a pulley: tangent) point.
    force_on_platform, force_on_exit : ndarray, shape (d,) [N]
        The cable's forces on the platform and on its exit (tangent) point.
    cable, guess : CatenaryCable, tuple
        The suspended part's; the warm start of the cable's next solve.
    horizontal_direction : ndarray, shape (d,)
        The catenary plane's x axis: planar (1, 0); spatial the horizontal unit vector from the anchor
        towards the exit, over a swivel ``e_rho`` from the axis towards the anchor.
    pulley_radius, wrap_angle, inlet : float [m], float [rad], ndarray (3,) [m] or None
        The disc the cable wraps (0 for a fixed exit point); a swivel pulley's inlet.
    """

    catenary: CatenaryState
    unstrained_length: float
    anchor_point: np.ndarray
    exit_point: np.ndarray
    force_on_platform: np.ndarray
    force_on_exit: np.ndarray
    cable: CatenaryCable = field(repr=False)
    guess: tuple = field(default=None, repr=False)
    horizontal_direction: np.ndarray | None = field(default=None, repr=False)
    pulley_radius: float = 0.0
    wrap_angle: float = 0.0
    inlet: np.ndarray | None = None

    @property
    def suspended_length(self):
        """Unstrained length of the suspended part, anchor to exit or tangent point [m]."""
        return self.cable.unstrained_length

    @property
    def tension_at_anchor(self):
        """Tension at the anchor [N]."""
        return self.catenary.tension_a

    @property
    def tension_at_exit(self):
        """Tension at the exit or tangent point [N] (uniform along the wrap)."""
        return self.catenary.tension_b

    def points(self, s):
        """Points (n, d) [m] of the loaded cable at unstrained arc lengths ``s`` (n,) [m] from the anchor;
        over a swivel pulley, beyond the suspended part on the wrap (stretched by the tension at the tangent
        point), up to ``unstrained_length`` at the inlet."""
        s = np.atleast_1d(np.asarray(s, dtype=float))
        suspended = self.suspended_length
        hanging = s <= suspended if self.inlet is not None else np.ones(s.shape, bool)
        up = np.eye(len(self.anchor_point))[-1]
        points = np.empty((s.size, len(self.anchor_point)))
        if hanging.any():
            planar = profile(self.cable, self.catenary, s[hanging])
            points[hanging] = (self.anchor_point + np.outer(planar[:, 0], self.horizontal_direction)
                               + np.outer(planar[:, 1], up))
        if not hanging.all():
            radius = self.pulley_radius
            stretch = 1.0 + self.tension_at_exit / self.cable.axial_stiffness
            # rim angle in the plane (rho, z) about the centre (r_p, 0): the inlet is at pi
            angle = np.minimum(math.pi - self.wrap_angle + (s[~hanging] - suspended) * stretch / radius, math.pi)
            points[~hanging] = (self.inlet + np.outer(radius * (1.0 + np.cos(angle)), self.horizontal_direction)
                                + np.outer(radius * np.sin(angle), up))
        return points


@dataclass(frozen=True, eq=False)
class PlatformEquilibrium:
    """A static (or quasi-static) equilibrium of the platform on its cables.

    Attributes
    ----------
    position : ndarray, shape (d,) [m]
        Centre of mass.
    rotation, rotation_matrix : float or ndarray (3,) [rad], ndarray (d, d)
        Planar the angle ``phi``, spatial the rotation vector (0 for a point mass); platform to world.
    stiffness : ndarray, shape (k, k), or None
        ``-d(generalised force)/d(pose)`` at fixed unstrained lengths over the k degrees of freedom
        (positive definite where stable); None from the spatial inverse.
    external_wrench, net_wrench : ndarray, shape (wrench_size,) [N, N m]
        The external load, and the force and moment left about the centre of mass (zero to tolerance).
    """

    space: Space
    position: np.ndarray
    rotation: float | np.ndarray
    rotation_matrix: np.ndarray = field(repr=False)
    cables: tuple = ()
    stiffness: np.ndarray | None = field(default=None, repr=False)
    external_wrench: np.ndarray | None = field(default=None, repr=False)
    net_wrench: np.ndarray | None = field(default=None, repr=False)

    @property
    def unstrained_lengths(self):
        """Unstrained length of each cable, shape (n_cables,) [m]."""
        return np.array([c.unstrained_length for c in self.cables])

    @property
    def horizontal_tensions(self):
        """Horizontal tension of each cable, shape (n_cables,) [N]."""
        return np.array([c.catenary.horizontal_tension for c in self.cables])

    @property
    def tensions_at_anchor(self):
        """Tension of each cable at its anchor, shape (n_cables,) [N]."""
        return np.array([c.tension_at_anchor for c in self.cables])


def _damped_newton(function, x0, tolerance, positive=(), max_iterations=100, what="equilibrium", noise=None,
                   line_search_steps=50):
    """Newton's method on ``function(x) -> (residual, jacobian)``, backtracking on the residual norm; returns
    ``(x, residual, jacobian)``. A trial that raises UnreachableError is rejected; components in ``positive``
    stay above 10 % of their value. Converged below ``tolerance``, or where no step decreases the norm and
    it is below ``noise`` (default ``1e3 tolerance``), the precision the residual can have."""
    noise = 1e3 * tolerance if noise is None else max(noise, tolerance)
    x = np.array(x0, dtype=float)
    residual, jacobian = function(x)
    norm = float(np.linalg.norm(residual))
    history = []
    for iteration in range(max_iterations):
        if norm <= tolerance:
            return x, residual, jacobian
        history.append(norm)
        if iteration >= _STAGNATION_WINDOW and norm > 0.1 * history[-1 - _STAGNATION_WINDOW]:
            break  # no tenfold progress in many damped steps: give up early
        try:
            step = -np.linalg.solve(jacobian, residual)
        except np.linalg.LinAlgError:
            break
        if not np.all(np.isfinite(step)):
            break
        alpha = 1.0
        for index in positive:
            if step[index] < -0.9 * x[index]:
                alpha = min(alpha, 0.9 * x[index] / -step[index])
        accepted = False
        for _ in range(line_search_steps):
            trial = x + alpha * step
            try:
                trial_residual, trial_jacobian = function(trial)
                trial_norm = float(np.linalg.norm(trial_residual))
            except UnreachableError:
                trial_norm = math.inf
            if trial_norm < (1.0 - 1e-4 * alpha) * norm or trial_norm <= tolerance:
                accepted = True
                break
            alpha *= 0.5
        if not accepted:
            break
        x, residual, jacobian, norm = trial, trial_residual, trial_jacobian, trial_norm
    if norm <= noise:  # stalled at round-off level
        return x, residual, jacobian
    raise UnreachableError(f"{what} did not converge (scaled residual {norm:.3g})")


def minimise_energy(function, x0, tolerance, noise, max_iterations=200, what="equilibrium"):
    """Newton's method for a conservative equilibrium, ``function(x) -> (residual, jacobian)`` the net
    generalised force ``-grad(energy)`` and ``-hessian``, with a line search on the energy: along a descent
    direction ``d`` its slope is ``-residual . d``, and the step ends near the minimum on the line (where
    that slope stops being strongly negative). Unlike a search on the residual norm this cannot stall away
    from an equilibrium in the curved, stiff valleys of near-vertical cables. Where the stiffness is not
    positive definite along the Newton direction, the (scaled) steepest descent is taken."""
    x = np.array(x0, dtype=float)
    residual, jacobian = function(x)
    norm = float(np.linalg.norm(residual))
    for _ in range(max_iterations):
        if norm <= tolerance:
            return x, residual, jacobian
        stiffness = -jacobian
        try:
            direction = np.linalg.solve(stiffness, residual)
        except np.linalg.LinAlgError:
            direction = None
        if direction is None or not np.all(np.isfinite(direction)) or residual @ direction <= 0.0:
            scale = max(float(np.abs(np.diag(stiffness)).max()), 1e-300)
            direction = residual / scale
        slope0 = -float(residual @ direction)  # < 0: descent

        def slope_at(alpha):
            try:
                r, j = function(x + alpha * direction)
            except UnreachableError:
                return math.inf, None, None
            return -float(r @ direction), r, j

        slope1, residual1, jacobian1 = slope_at(1.0)
        alpha = 1.0
        if not slope1 <= 0.5 * abs(slope0):
            # the energy turns up before alpha = 1: find where its slope crosses zero
            low, high, slope_low, slope_high = 0.0, 1.0, slope0, slope1
            for _ in range(60):
                if math.isfinite(slope_high) and slope_high > slope_low:
                    alpha = low - slope_low * (high - low) / (slope_high - slope_low)
                    alpha = min(max(alpha, low + 0.1 * (high - low)), high - 0.1 * (high - low))
                else:
                    alpha = 0.5 * (low + high)
                slope1, residual1, jacobian1 = slope_at(alpha)
                if abs(slope1) <= 0.5 * abs(slope0) and residual1 is not None:
                    break
                if slope1 < 0.0:
                    low, slope_low = alpha, slope1
                else:
                    high, slope_high = alpha, slope1
            else:
                break
        if residual1 is None:
            break
        step_norm = float(np.linalg.norm(alpha * direction))
        x, residual, jacobian = x + alpha * direction, residual1, jacobian1
        new_norm = float(np.linalg.norm(residual))
        if step_norm <= 1e-15 * max(1.0, float(np.linalg.norm(x))) and new_norm >= norm:
            norm = new_norm
            break  # no more progress at round-off level
        norm = new_norm
    if norm <= noise:
        return x, residual, jacobian
    raise UnreachableError(f"{what} did not converge (scaled residual {norm:.3g})")


_STAGNATION_WINDOW = 25
_INNER_NEWTON = {"max_iterations": 40, "line_search_steps": 30}
"""Budget of a single pulley-cable solve: it starts close, so failing fast is cheaper."""


def _warm_then_cold(solve_from, guess):
    """Run ``solve_from(guess)``, and from the straight-cable start if that fails."""
    if guess is not None:
        try:
            return solve_from(guess)
        except UnreachableError:
            pass
    return solve_from(None)


def _straight_tangent_angle(pulley, point):
    """Rim angle where a straight cable from ``point`` leaves ``pulley``."""
    centre = np.array(pulley.center)
    offset = centre - point
    distance = float(np.hypot(*offset))
    if distance <= pulley.radius:
        raise UnreachableError(f"anchor point ({point[0]:g}, {point[1]:g}) m lies inside the pulley of "
                               f"centre {pulley.center} m and radius {pulley.radius:g} m")
    gamma = math.atan2(offset[1], offset[0])
    spread = math.acos(-pulley.radius / distance)
    for angle in (gamma + spread, gamma - spread):
        tangent = pulley.side * np.array([math.sin(angle), -math.cos(angle)])
        if np.dot(pulley.rim_point(angle) - point, tangent) > 0.0:
            return angle
    raise AssertionError("no tangent with the pulley's orientation")  # pragma: no cover


# --- one cable: forward (given unstrained length) and inverse (given H)
def _pulley_residual(cable, pulley, sign_x, point, H, V_B, angle, suspended_length, tension_scale):
    """Residual of the pulley cable (span mismatch, tangency) (3,), its derivatives in (H, V_B, L_c, angle)
    (3, 4), and the suspended part's catenary."""
    catenary = cable.catenary(suspended_length)
    span, jac = span_and_jacobian(catenary, H, V_B, sign_x)
    tangent = pulley.rim_point(angle)
    c, s = math.cos(angle), math.sin(angle)
    scale = suspended_length / tension_scale  # tangency residual in metres
    residual = np.empty(3)
    residual[:2] = span - (tangent - point)
    residual[2] = scale * (sign_x * H * c + V_B * s)
    partial = np.zeros((3, 4))
    partial[:2, :3] = jac
    partial[:2, 3] = -pulley.radius * np.array([-s, c])
    partial[2, 0] = scale * sign_x * c
    partial[2, 1] = scale * s
    partial[2, 3] = scale * (-sign_x * H * s + V_B * c)
    return residual, partial, catenary


def _planar_equilibrium(state, catenary_cable, unstrained_length, point, upper, guess, wrap=0.0, radius=0.0):
    return CableEquilibrium(state, unstrained_length, point.copy(), upper, state.force_on_a, state.force_on_b,
                            catenary_cable, guess, _PLANE_X, radius, wrap)


def _planar_forward_cable(cable, unstrained_length, point, guess, max_strain, max_tension):
    """A planar cable of given length from an anchor point: its equilibrium (the next guess in it) and
    ``d(force on A)/d(anchor point)`` (2, 2)."""
    if cable.pulley is None:
        catenary_cable = cable.catenary(unstrained_length)
        state = solve_forward(catenary_cable, np.array(cable.exit_point) - point,
                              initial_guess=None if guess is None else guess[:2], max_strain=max_strain,
                              max_tension=max_tension)
        guess = (state.horizontal_tension, state.vertical_tension_b)
        equilibrium = _planar_equilibrium(state, catenary_cable, unstrained_length, point,
                                          np.array(cable.exit_point), guess)
        return equilibrium, end_stiffness(catenary_cable, state)

    pulley, EA, w, r = cable.pulley, cable.axial_stiffness, cable.weight_per_length, cable.pulley.radius

    def suspended_length(x):
        H_, V_, angle_ = x
        tension = math.hypot(H_, V_)
        stretch = 1.0 + tension / EA
        wrap = pulley.wrap_to(angle_)
        length = unstrained_length - r * wrap / stretch
        # d(length)/d(H, V_B, angle)
        factor = r * wrap / (EA * stretch**2 * tension) if tension > 0.0 else 0.0
        derivative = np.array([factor * H_, factor * V_, -r * pulley.side / stretch])
        return length, derivative, wrap

    def solve_from(start_guess):
        if start_guess is None:
            angle = _straight_tangent_angle(pulley, point)
            suspended = unstrained_length - r * pulley.wrap_to(angle)
            if suspended <= 0.0:
                raise UnreachableError(f"unstrained_length {unstrained_length:g} m is shorter than the wrap "
                                       "on the pulley")
            state = solve_forward(cable.catenary(suspended), pulley.rim_point(angle) - point,
                                  max_strain=max_strain, max_tension=max_tension)
            H, V_B = state.horizontal_tension, state.vertical_tension_b
            if H <= 0.0:  # a just-taut massless (or vertical) start: pull a little
                H = 1e-9 * EA
        else:
            H, V_B, angle = start_guess
        sign_x = -1.0 if pulley.rim_point(angle)[0] < point[0] else 1.0
        tension_scale = max(math.hypot(H, V_B), w * unstrained_length, 1e-300)

        def function(x):
            if x[0] <= 0.0:
                raise UnreachableError("horizontal tension must stay positive")
            length, derivative, _ = suspended_length(x)
            if length <= 0.0:
                raise UnreachableError("the whole cable would lie on the pulley")
            residual, partial, _ = _pulley_residual(cable, pulley, sign_x, point, x[0], x[1], x[2], length,
                                                    tension_scale)
            return residual, partial[:, [0, 1, 3]] + np.outer(partial[:, 2], derivative)

        x, _, jacobian = _damped_newton(function, (H, V_B, angle), _RELATIVE_TOLERANCE * unstrained_length,
                                        positive=(0,), what="pulley cable", **_INNER_NEWTON)
        return x, jacobian, sign_x, tension_scale

    x, jacobian, sign_x, _ = _warm_then_cold(solve_from, guess)
    H, V_B, angle = x
    length, derivative, wrap = suspended_length(x)
    catenary_cable = cable.catenary(length)
    state = state_from_end_forces(catenary_cable, H, V_B, sign_x)
    if state.max_tension > tension_limit(cable.axial_stiffness, max_strain, max_tension):
        raise UnreachableError(f"cable of unstrained_length {unstrained_length:g} m would need tension "
                               f"{state.max_tension:g} N, above its limit")
    # d(H, V_B, angle)/d(point) = -jacobian^-1 d(residual)/d(point), d(residual)/d(point) = [I; 0]
    sensitivity = -np.linalg.solve(jacobian, np.vstack([np.eye(2), np.zeros((1, 2))]))
    force_derivative = np.array([[sign_x, 0.0, 0.0], [-w * derivative[0], 1.0 - w * derivative[1], -w * derivative[2]]])
    stiffness = force_derivative @ sensitivity
    equilibrium = _planar_equilibrium(state, catenary_cable, unstrained_length, point, pulley.rim_point(angle),
                                      (H, V_B, angle), wrap, r)
    return equilibrium, stiffness


def _planar_inverse_cable(cable, horizontal_tension, point, guess, max_strain, max_tension):
    """A planar cable with given horizontal tension from an anchor point: ``(CableEquilibrium, dF_A/dH (2,),
    dF_A/dp_A at fixed H (2, 2))``, the next guess in the first."""
    H, w, EA = horizontal_tension, cable.weight_per_length, cable.axial_stiffness
    if cable.pulley is None:
        span = np.array(cable.exit_point) - point
        length, state = solve_inverse(span, w, EA, H, max_strain=max_strain, max_tension=max_tension)
        _, jac = span_and_jacobian(cable.catenary(length), H, state.vertical_tension_b, state.horizontal_sign)
        # residual span(H, V_B, L) - (e - p); unknowns (L, V_B)
        jacobian = jac[:, [2, 1]]
        d_residual_dH = jac[:, 0]
        d_residual_dp = np.eye(2)
        sign_x = state.horizontal_sign
        equilibrium = _planar_equilibrium(state, cable.catenary(length), length, point, np.array(cable.exit_point),
                                          None)
    else:
        pulley, r = cable.pulley, cable.pulley.radius

        def solve_from(start_guess):
            if start_guess is None:
                angle = _straight_tangent_angle(pulley, point)
                length, state = solve_inverse(pulley.rim_point(angle) - point, w, EA, H,
                                              max_strain=max_strain, max_tension=max_tension)
                V_B = state.vertical_tension_b
            else:
                length, V_B, angle = start_guess
            sign_x = -1.0 if pulley.rim_point(angle)[0] < point[0] else 1.0
            tension_scale = max(math.hypot(H, V_B), w * length, 1e-300)

            def function(x):
                if x[0] <= 0.0:
                    raise UnreachableError("suspended length must stay positive")
                residual, partial, _ = _pulley_residual(cable, pulley, sign_x, point, H, x[1], x[2], x[0],
                                                        tension_scale)
                return residual, partial[:, [2, 1, 3]]

            x, _, jacobian = _damped_newton(function, (length, V_B, angle), _RELATIVE_TOLERANCE * length,
                                            positive=(0,), what="pulley cable", **_INNER_NEWTON)
            return x, jacobian, sign_x, tension_scale

        x, jacobian, sign_x, tension_scale = _warm_then_cold(solve_from, guess)
        length, V_B, angle = x
        _, partial, catenary = _pulley_residual(cable, pulley, sign_x, point, H, V_B, angle, length, tension_scale)
        d_residual_dH = partial[:, 0]
        d_residual_dp = np.vstack([np.eye(2), np.zeros((1, 2))])
        state = state_from_end_forces(catenary, H, V_B, sign_x)
        wrap = pulley.wrap_to(angle)
        total = length + r * wrap / (1.0 + state.tension_b / EA)
        equilibrium = _planar_equilibrium(state, catenary, total, point, pulley.rim_point(angle), (length, V_B, angle),
                                          wrap, r)
    if state.max_tension > tension_limit(cable.axial_stiffness, max_strain, max_tension):
        raise UnreachableError(f"horizontal_tension {H:g} N needs tension {state.max_tension:g} N, above the limit")
    # unknowns u = (L_c, V_B[, angle]); force on A = (sign_x H, V_B - w L_c)
    d_u_dH = -np.linalg.solve(jacobian, d_residual_dH)
    d_u_dp = -np.linalg.solve(jacobian, d_residual_dp)
    force_dH = np.array([sign_x, d_u_dH[1] - w * d_u_dH[0]])
    force_dp = np.vstack([np.zeros(2), d_u_dp[1] - w * d_u_dp[0]])
    return equilibrium, force_dH, force_dp


# --- one spatial cable: the planar cable in its vertical plane
def _vertical_plane_forward_cable(cable, unstrained_length, anchor_point, guess, max_strain, max_tension):
    """A spatial cable from a point exit: the planar catenary in the vertical plane through its ends."""
    catenary_cable = cable.catenary(unstrained_length)
    exit_point = np.array(cable.exit_point)
    span = exit_point - anchor_point
    horizontal = float(math.hypot(span[0], span[1]))
    direction = np.array([span[0], span[1], 0.0]) / horizontal if horizontal > 0.0 else np.array([1.0, 0.0, 0.0])
    state = solve_forward(catenary_cable, (horizontal, span[2]), initial_guess=guess, max_strain=max_strain,
                          max_tension=max_tension)
    planar = end_stiffness(catenary_cable, state)
    basis = np.column_stack([direction, _E_Z])
    stiffness = basis @ planar @ basis.T
    vertical = horizontal <= 1e-9 * max(unstrained_length, float(np.linalg.norm(span)))
    sideways = -planar[0, 0] if vertical else state.horizontal_tension / horizontal
    stiffness -= sideways * (_HORIZONTAL - np.outer(direction, direction))
    return _in_vertical_plane(state, float(unstrained_length), anchor_point, exit_point, catenary_cable,
                              (state.horizontal_tension, state.vertical_tension_b), direction), stiffness


def _in_vertical_plane(state, length, anchor_point, exit_point, catenary_cable, guess, direction):
    """A point exit's cable, the catenary ``state`` in the vertical plane along ``direction`` (3,), in 3-D."""
    return CableEquilibrium(state, length, np.array(anchor_point, dtype=float), exit_point,
                            state.force_on_a[0] * direction + state.force_on_a[1] * _E_Z,
                            state.force_on_b[0] * direction + state.force_on_b[1] * _E_Z, catenary_cable,
                            guess, direction)


def _swivel_plane(cable, anchor_point):
    """The vertical plane through a swivel pulley's axis and ``anchor_point`` (3,) [m]: the inlet (3,) [m],
    its horizontal unit vector e_rho (3,), the anchor's span (rho, dz) [m] from the inlet, and its planar
    pulley cable. Refuses (UnreachableError) an anchor on the axis."""
    inlet = np.array(cable.point)
    offset = np.asarray(anchor_point, dtype=float) - inlet
    rho = float(math.hypot(offset[0], offset[1]))
    if rho <= 1e-12 * (float(np.linalg.norm(offset)) + cable.pulley_radius):
        raise UnreachableError(f"anchor {np.asarray(anchor_point).tolist()} lies on the axis of the swivel pulley at "
                               f"{inlet.tolist()}: its azimuth is undefined")
    e_rho = np.array([offset[0], offset[1], 0.0]) / rho
    # a disc of centre (r_p, 0) hung on its left: hang point the inlet, winch line the axis (core.geometry)
    radius = cable.pulley_radius
    planar_cable = SuspendedCable(cable.weight_per_length, cable.axial_stiffness, anchor=(0.0, 0.0),
                                  pulley=Pulley((radius, 0.0), radius, -1))
    return inlet, e_rho, np.array([rho, offset[2]]), planar_cable


def _lifted(planar, cable, anchor_point, inlet, e_rho, force):
    """The planar pulley cable's equilibrium in the swivel's plane, lifted to 3-D."""
    state = planar.catenary
    return CableEquilibrium(
        state, planar.unstrained_length, np.array(anchor_point, dtype=float),
        inlet + planar.exit_point[0] * e_rho + planar.exit_point[1] * _E_Z,
        force[0] * e_rho + force[1] * _E_Z, state.force_on_b[0] * e_rho + state.force_on_b[1] * _E_Z,
        cable.catenary(planar.suspended_length), None if planar.guess is None else tuple(planar.guess), e_rho,
        cable.pulley_radius, float(planar.wrap_angle), inlet)


def _swivel_forward_cable(cable, unstrained_length, anchor_point, guess, max_strain, max_tension):
    """A spatial cable over a swivel pulley: the planar pulley cable in the plane through the axis and the anchor."""
    anchor_point = np.asarray(anchor_point, dtype=float)
    inlet, e_rho, span, planar_cable = _swivel_plane(cable, anchor_point)
    planar, planar_stiffness = _planar_forward_cable(planar_cable, float(unstrained_length), span, guess,
                                                     max_strain, max_tension)
    basis = np.column_stack([e_rho, _E_Z])
    force = planar.force_on_platform
    stiffness = basis @ planar_stiffness @ basis.T + force[0] / span[0] * (_HORIZONTAL - np.outer(e_rho, e_rho))
    return _lifted(planar, cable, anchor_point, inlet, e_rho, force), stiffness


def _vertical_plane_inverse_cable(cable, horizontal_tension, anchor_point, guess, max_strain, max_tension):
    """A spatial cable from a point exit at horizontal tension H (the plane's inverse catenary)."""
    exit_point = np.array(cable.exit_point)
    span = exit_point - anchor_point
    horizontal = float(math.hypot(span[0], span[1]))
    if horizontal <= 0.0:
        raise UnreachableError(f"cable from {shown(exit_point)} hangs vertically above its anchor: its horizontal "
                               "tension is zero and the inverse catenary has no answer")
    direction = np.array([span[0], span[1], 0.0]) / horizontal
    length, state = solve_inverse((horizontal, span[2]), cable.weight_per_length, cable.axial_stiffness,
                                  horizontal_tension)
    equilibrium = _in_vertical_plane(state, length, anchor_point, exit_point, cable.catenary(length), None,
                                     direction)
    return equilibrium, None, None


def _swivel_inverse_cable(cable, horizontal_tension, anchor_point, guess, max_strain, max_tension):
    """A spatial cable over a swivel pulley at horizontal tension H: the planar pulley cable's inverse in the
    vertical plane through the axis and the anchor (the length counts from the inlet, the wrap included)."""
    inlet, e_rho, span, planar_cable = _swivel_plane(cable, anchor_point)
    planar, _, _ = _planar_inverse_cable(planar_cable, float(horizontal_tension), span, None, DEFAULT_MAX_STRAIN,
                                         None)
    return _lifted(planar, cable, anchor_point, inlet, e_rho, planar.force_on_platform), None, None


def forward_cable(cable, unstrained_length, anchor_point, guess=None, max_strain=DEFAULT_MAX_STRAIN,
                  max_tension=None):
    """Solve one cable of given unstrained length [m] from an anchor point (d,) [m] to its exit.

    The solver is the exit's (module notes); ``guess``: a previous :attr:`CableEquilibrium.guess`.
    Returns the :class:`CableEquilibrium` and ``d(force on platform)/d(anchor point)`` (d, d) [N/m];
    UnreachableError if the span is beyond reach at the tension limit."""
    solve = _CABLE_KERNELS[cable.space][cable.pulley is not None][0]
    return solve(cable, unstrained_length, np.asarray(anchor_point, dtype=float), guess, max_strain,
                 max_tension)


def inverse_cable(cable, horizontal_tension, anchor_point, guess=None, max_strain=DEFAULT_MAX_STRAIN,
                  max_tension=None):
    """Solve one cable of given horizontal tension [N] from a given anchor point (d,) [m] to its exit.

    Returns ``(CableEquilibrium, dF_A/dH, dF_A/dp_A at fixed H)``: the derivatives (d,) and (d, d) of
    a planar cable; None for a spatial one (its inverse statics differentiates numerically).
    """
    solve = _CABLE_KERNELS[cable.space][cable.pulley is not None][1]
    return solve(cable, horizontal_tension, np.asarray(anchor_point, dtype=float), guess, max_strain,
                 max_tension)


#: Each cable's solvers (forward, inverse), by its space and whether it wraps over its exit.
_CABLE_KERNELS = {PLANE: {False: (_planar_forward_cable, _planar_inverse_cable),
                          True: (_planar_forward_cable, _planar_inverse_cable)},
                  SPACE: {False: (_vertical_plane_forward_cable, _vertical_plane_inverse_cable),
                          True: (_swivel_forward_cable, _swivel_inverse_cable)}}


# --- the platform: the one driver and its checks
def checked_unstrained_lengths(platform, unstrained_lengths):
    """The cables' unstrained lengths [m] as a float array, one positive length per cable of ``platform``;
    else SceneError naming ``unstrained_lengths``."""
    lengths = real_array("unstrained_lengths", unstrained_lengths)
    if lengths.shape != (len(platform.cables),):
        raise SceneError(f"unstrained_lengths must have one entry per cable ({len(platform.cables)}), "
                         f"got {shown(unstrained_lengths)}")
    if np.any(lengths <= 0.0):
        raise SceneError(f"unstrained_lengths must be positive, got {shown(unstrained_lengths)}")
    return lengths


def _checked_platform(platform):
    if not isinstance(platform, SuspendedPlatform):
        raise SceneError(f"platform must be a SuspendedPlatform, got {shown(platform)}")
    return _KERNELS[platform.space]


def _wrench(platform, value):
    space = platform.space
    if value is None:
        return np.zeros(space.wrench_size)
    labels = ", ".join([f"f{c}" for c in space.position_labels] + (["moment"] if space.rotation_size == 1 else
                                                                   [f"m{c}" for c in space.position_labels]))
    return vector("external_wrench", value, space.wrench_size, f" ({labels}) [N, N m]")


def _check_reach(platform, lengths, max_strain, max_tension):
    """Refuse cables that cannot all meet the platform: hang points farther apart than two cables and the
    anchors reach."""
    reaches = [length * (1.0 + tension_limit(c.axial_stiffness, max_strain, max_tension) / c.axial_stiffness)
               for c, length in zip(platform.cables, lengths)]
    exits, anchors = np.array([c.hang_point for c in platform.cables]), platform.anchors
    for i in range(len(lengths)):
        for j in range(i):
            gap = float(np.linalg.norm(exits[i] - exits[j]))
            reach = reaches[i] + reaches[j] + float(np.linalg.norm(anchors[i] - anchors[j]))
            if gap > reach:
                raise UnreachableError(
                    f"unstrained_lengths: cables[{j}] and cables[{i}] cannot both reach the platform: their exit "
                    f"points are {gap:g} m apart, beyond the {reach:g} m their lengths ({lengths[j]:g}, "
                    f"{lengths[i]:g} m, at the tension limit) and anchors span")


def solve_statics(platform, unstrained_lengths, initial_pose=None, external_wrench=None,
                  max_strain=DEFAULT_MAX_STRAIN, max_tension=None):
    """Equilibrium pose of the platform and every cable's forces, for given unstrained lengths.

    Newton's method on the net generalised force (rigid: with the moment, planar about the centre of mass,
    spatial ``J_l^T M``), the analytic stiffness from the cables' end stiffnesses and a line search on the
    energy (:func:`minimise_energy`), from the pose on straight, massless, elastic cables that may go slack
    (the minimum of ``M g z - wrench . pose + sum k_i max(l_i - L_i, 0)^2 / 2``, ``l_i`` the straight length
    to the hang point and ``k_i = EA_i / L_i``, which always exists), or ``initial_pose`` (a position or a
    pose [m, rad]); every evaluation solves each cable warm-started from the previous iterate.

    Parameters
    ----------
    platform : SuspendedPlatform
    unstrained_lengths : array_like, shape (n_cables,) [m]
        Over a pulley from its hang point.
    external_wrench : array_like, shape (wrench_size,) [N, N m], optional
        Extra force and moment about the centre of mass, eg :func:`inertial_wrench`.
    max_strain, max_tension : float, optional
        Cable tension limits (:func:`cdpr_exu.physics.catenary.tension_limit`).

    Returns a :class:`PlatformEquilibrium`. Raises SceneError naming an invalid argument, UnreachableError if
    two cables cannot both reach the platform (both before any solve) or no equilibrium is found within the
    tension limits.
    """
    kernel = _checked_platform(platform)
    space = platform.space
    lengths = checked_unstrained_lengths(platform, unstrained_lengths)
    wrench = _wrench(platform, external_wrench)
    max_strain = positive("max_strain", max_strain)
    if max_tension is not None:
        max_tension = positive("max_tension", max_tension)
    dof = platform.degrees_of_freedom
    if initial_pose is not None:
        start = real_array("initial_pose", initial_pose)
        if start.shape not in ((space.position_size,), (space.pose_size,), (dof,)):
            raise SceneError(f"initial_pose must be a position ({', '.join(space.position_labels)}) or a pose "
                             f"({', '.join(space.pose_labels)}), got {shown(initial_pose)}")
        start = np.append(start, np.zeros(space.pose_size - start.size))
    _check_reach(platform, lengths, max_strain, max_tension)
    if initial_pose is None:
        start = kernel.straight_cable_pose(platform, lengths, wrench)
    force_scale, length_scale = kernel.scales(platform, lengths, wrench)
    residual_scale = np.array([force_scale] * space.position_size
                              + [force_scale * length_scale] * space.rotation_size)[:dof]
    pose_scale = np.array([1.0] * space.position_size + [length_scale] * space.rotation_size)[:dof]  # in metres
    stiffest = max(c.axial_stiffness for c in platform.cables)
    noise = 1e3 * _RELATIVE_TOLERANCE * (1.0 + stiffest / force_scale)
    guesses = [None] * len(platform.cables)
    cache = {}

    def function(scaled):
        residual, jacobian, cache["last"] = kernel.evaluate(platform, scaled / pose_scale, lengths, wrench, guesses,
                                                            max_strain, max_tension)
        return residual / residual_scale, jacobian / residual_scale[:, None] / pose_scale[None, :]

    try:
        scaled, _, _ = minimise_energy(function, start[:dof] * pose_scale, _RELATIVE_TOLERANCE, noise,
                                       what="statics")
    except UnreachableError as error:
        raise UnreachableError(f"no equilibrium found for unstrained_lengths {lengths.tolist()} m: {error}") from None
    function(scaled)  # the accepted point, with its own cable states
    return kernel.result(platform, cache["last"], wrench)


def solve_inverse_statics(platform, pose, external_wrench=None, initial_guess=None, max_strain=DEFAULT_MAX_STRAIN,
                          max_tension=None):
    """Unstrained lengths and cable forces that hold the platform at ``pose`` [m, rad], on elastic catenaries.

    The unknowns are the cables' horizontal tensions (each cable's length and forces follow from its
    inverse catenary, :func:`inverse_cable`); the equations the platform's balance under its weight and
    ``external_wrench`` (wrench_size,) [N, N m] (eg :func:`inertial_wrench`).

    * Planar: a square Newton iteration from straight massless cables (weight continuation as the last
      resort): a point mass on 2 cables; a rigid platform on 2 cables at a position ``(x, z)`` (the
      rotation is equilibrium's) or on 3 at a pose ``(x, z, phi)``. Returns the stiffness too.
    * Spatial ((3,) for a point mass, else (6,)): the tensions nearest ``initial_guess`` (required; least
      squares) that balance the force, and the moment on at least six cables (with fewer the rotation is
      left free), by Gauss-Newton with forward differences; continued along a trajectory, a redundant
      robot keeps its internal tension.

    ``initial_guess``: a nearby :class:`PlatformEquilibrium` or positive horizontal tensions (n_cables,)
    [N], the start (planar, with its rotation). ``max_strain``, ``max_tension``: as in :func:`solve_statics`.

    Raises UnreachableError if a cable would have to push or hang vertically, a tension exceeds its limit,
    or the iteration fails; SceneError for an invalid argument or (planar) a problem that is not square.
    """
    kernel = _checked_platform(platform)
    wrench = _wrench(platform, external_wrench)
    if initial_guess is not None and not isinstance(initial_guess, PlatformEquilibrium):
        initial_guess = real_array("initial_guess", initial_guess)
        if initial_guess.shape != (len(platform.cables),) or np.any(initial_guess <= 0.0):
            raise SceneError(f"initial_guess must be a PlatformEquilibrium or one positive horizontal tension per "
                             f"cable, got {shown(initial_guess.tolist())}")
    elif initial_guess is not None and len(initial_guess.cables) != len(platform.cables):
        raise SceneError(f"initial_guess must be a PlatformEquilibrium of this platform, got {shown(initial_guess)}")
    return kernel.inverse(platform, pose, wrench, initial_guess, max_strain, max_tension)


# --- the pose kernels: what differs per dimension
class _PlanarStatics:
    """The plane's pose kernel: ``(x, z, phi)``, planar cross products (the paper's statics, bit for bit)."""

    @staticmethod
    def inertia(value):
        return non_negative("inertia", 0.0 if value is None else value)

    @staticmethod
    def anchor_points(platform, position, rotation=0.0):
        turn = rotation_matrix(rotation)
        return np.array([np.asarray(position) + turn @ c.anchor for c in platform.cables])

    @staticmethod
    def scales(platform, lengths, wrench):
        """Force [N] and length [m] scales of the equilibrium residual."""
        weight = platform.mass * platform.gravity
        cable_weight = sum(c.weight_per_length * L for c, L in zip(platform.cables, lengths))
        force = weight + cable_weight + float(np.hypot(wrench[0], wrench[1]))
        arm = max((float(np.hypot(*c.anchor)) for c in platform.cables), default=0.0)
        length = arm if arm > 0.0 else 1.0
        force = max(force, abs(wrench[2]) / length, 1e-12)
        return force, length

    @staticmethod
    def wrench_residual(platform, rotation, equilibria, wrench):
        """Net wrench on the platform ``(fx, fz, m)`` [N, N, N m]."""
        turn = rotation_matrix(rotation)
        total = np.array([wrench[0], wrench[1] - platform.mass * platform.gravity, wrench[2]])
        for cable, equilibrium in zip(platform.cables, equilibria):
            force = equilibrium.force_on_platform
            total[:2] += force
            total[2] += planar_cross(turn @ cable.anchor, force)
        return total

    @staticmethod
    def pose_jacobian(platform, rotation, equilibria, stiffnesses, dof):
        """``d(net wrench)/d(pose)`` from the cables' ``dF_A/dp_A``, shape (dof, dof)."""
        turn = rotation_matrix(rotation)
        jacobian = np.zeros((3, 3))
        for cable, equilibrium, stiffness in zip(platform.cables, equilibria, stiffnesses):
            arm = turn @ cable.anchor
            d_point = np.column_stack([np.eye(2), perpendicular(arm)])  # dp/d(x, z, phi)
            d_force = stiffness @ d_point
            force = equilibrium.force_on_platform
            jacobian[:2] += d_force
            jacobian[2] += arm[0] * d_force[1] - arm[1] * d_force[0]
            jacobian[2, 2] += planar_cross(perpendicular(arm), force)
        return jacobian[:dof, :dof]

    def evaluate(self, platform, pose, lengths, wrench, guesses, max_strain, max_tension):
        dof = platform.degrees_of_freedom
        phi = pose[2] if dof == 3 else 0.0
        points = self.anchor_points(platform, pose[:2], phi)
        equilibria, stiffnesses = [], []
        for i, (cable, point, length) in enumerate(zip(platform.cables, points, lengths)):
            equilibrium, stiffness = forward_cable(cable, length, point, guesses[i], max_strain, max_tension)
            equilibria.append(equilibrium)
            stiffnesses.append(stiffness)
        guesses[:] = [e.guess for e in equilibria]
        total = self.wrench_residual(platform, phi, equilibria, wrench)
        jacobian = self.pose_jacobian(platform, phi, equilibria, stiffnesses, dof)
        return total[:dof], jacobian, (pose, equilibria, jacobian, total)

    def result(self, platform, state, wrench):
        pose, equilibria, jacobian, total = state
        phi = _wrap_angle(pose[2]) if platform.degrees_of_freedom == 3 else 0.0
        return PlatformEquilibrium(PLANE, np.array(pose[:2], dtype=float), phi, rotation_matrix(phi),
                                   tuple(equilibria), -np.array(jacobian), wrench, total)

    def straight_cable_pose(self, platform, lengths, wrench):
        dof = platform.degrees_of_freedom
        stiffness = np.array([c.axial_stiffness / L for c, L in zip(platform.cables, lengths)])
        uppers = np.array([c.point for c in platform.cables])
        force_scale, length_scale = self.scales(platform, lengths, wrench)
        weight = platform.mass * platform.gravity

        def energy(q):
            phi = q[2] if dof == 3 else 0.0
            turn = rotation_matrix(phi)
            value = weight * q[1] - wrench[0] * q[0] - wrench[1] * q[1] - wrench[2] * phi
            gradient = np.array([-wrench[0], weight - wrench[1], -wrench[2]])
            for cable, L, k in zip(platform.cables, lengths, stiffness):
                arm = turn @ cable.anchor
                length, direction = _straight_length_and_gradient(cable, q[:2] + arm)
                extension = length - L
                if extension > 0.0:
                    value += 0.5 * k * extension**2
                    pull = k * extension * direction
                    gradient[:2] += pull
                    gradient[2] += planar_cross(arm, pull)
            return value, gradient[:dof]

        start = np.array([uppers[:, 0].mean(), uppers[:, 1].mean() - lengths.mean(), 0.0])[:dof]
        solution = minimize(energy, start, jac=True, method="BFGS",
                            options={"gtol": 1e-9 * force_scale, "maxiter": 2000})
        phi = _wrap_angle(solution.x[2]) if dof == 3 else 0.0
        return np.append(solution.x[:2], phi)

    def inverse(self, platform, pose, wrench, initial_guess, max_strain, max_tension):
        pose = real_array("pose", pose)
        if pose.shape not in ((2,), (3,)):
            raise SceneError(f"pose must be a position (x, z) or a pose (x, z, rotation), got {shown(pose.tolist())}")
        return _planar_inverse(platform, pose[:2], None if pose.size == 2 else float(pose[2]), wrench, max_strain,
                               max_tension, initial_guess)


class _SpatialStatics:
    """Space's pose kernel: ``(r, theta)``, left Jacobians of SO(3)."""

    @staticmethod
    def inertia(value):
        inertia = vector("inertia", (0.0, 0.0, 0.0) if value is None else value, 3,
                         " (principal moments) [kg m^2]")
        if np.any(inertia < 0.0):
            raise SceneError(f"inertia must be zero or positive, got {shown(value)}")
        return tuple(inertia)

    @staticmethod
    def scales(platform, lengths, wrench):
        weight = platform.mass * platform.gravity
        force_scale = max(weight + sum(c.weight_per_length * L for c, L in zip(platform.cables, lengths))
                          + float(np.linalg.norm(wrench[:3])), 1e-12)
        arm = float(np.linalg.norm(platform.anchors, axis=1).max())
        return force_scale, (arm if arm > 0.0 else 1.0)

    @staticmethod
    def pose(platform, coordinates):
        """Position, rotation matrix and rotation vector from the unknowns."""
        theta = coordinates[3:6] if platform.degrees_of_freedom == 6 else np.zeros(3)
        return coordinates[:3], rotation_from_vector(theta), theta

    def evaluate(self, platform, coordinates, lengths, wrench, guesses, max_strain, max_tension):
        dof = platform.degrees_of_freedom
        position, rotation, theta = self.pose(platform, coordinates)
        arms = platform.anchors @ rotation.T
        wrench_total = wrench.copy()
        wrench_total[2] -= platform.mass * platform.gravity
        jacobian = np.zeros((6, 6))  # d(force, moment)/d(r, world rotation)
        equilibria = []
        for i, (cable, length, arm_) in enumerate(zip(platform.cables, lengths, arms)):
            equilibrium, stiffness = forward_cable(cable, length, position + arm_, guesses[i], max_strain, max_tension)
            guesses[i] = equilibrium.guess
            equilibria.append(equilibrium)
            force = equilibrium.force_on_platform
            wrench_total[:3] += force
            wrench_total[3:] += np.cross(arm_, force)
            arm_skew = skew(arm_)
            jacobian[:3, :3] += stiffness
            jacobian[:3, 3:] -= stiffness @ arm_skew
            jacobian[3:, :3] += arm_skew @ stiffness
            jacobian[3:, 3:] += -arm_skew @ stiffness @ arm_skew + skew(force) @ arm_skew
        if dof == 3:
            residual, generalised = wrench_total[:3], jacobian[:3, :3]
        else:
            tangent = left_jacobian(theta)
            residual = np.concatenate([wrench_total[:3], tangent.T @ wrench_total[3:]])
            # d(J_l^T M)/d(theta) also has a term in dJ_l/d(theta) M, which vanishes at equilibrium: left out
            generalised = jacobian @ np.block([[np.eye(3), np.zeros((3, 3))], [np.zeros((3, 3)), tangent]])
            generalised[3:] = tangent.T @ generalised[3:]
        return residual, generalised, (position, rotation, equilibria, generalised, wrench_total)

    def result(self, platform, state, wrench):
        position, rotation, equilibria, jacobian, wrench_total = state
        return PlatformEquilibrium(SPACE, np.array(position, dtype=float),
                                   rotation_vector(rotation) if platform.degrees_of_freedom == 6 else np.zeros(3),
                                   rotation, tuple(equilibria), -jacobian, wrench, wrench_total)

    def straight_cable_pose(self, platform, lengths, wrench):
        dof = platform.degrees_of_freedom
        stiffness = np.array([c.axial_stiffness for c in platform.cables]) / lengths
        exits = np.array([c.point for c in platform.cables])
        weight = platform.mass * platform.gravity
        scale = weight + sum(c.weight_per_length * L for c, L in zip(platform.cables, lengths)) + 1e-12

        def energy(q):
            position, rotation, theta = self.pose(platform, q)
            arms = platform.anchors @ rotation.T
            value = weight * position[2] - wrench[:3] @ position - (wrench[3:] @ theta if dof == 6 else 0.0)
            force = np.array([0.0, 0.0, weight]) - wrench[:3]
            moment = -wrench[3:].copy()
            for cable, arm, exit_point, length, k in zip(platform.cables, arms, exits, lengths, stiffness):
                distance, direction = _straight_path(cable, exit_point, position + arm)
                if distance > length:
                    value += 0.5 * k * (distance - length) ** 2
                    pull = k * (distance - length) * direction
                    force += pull
                    moment += np.cross(arm, pull)
            gradient = force if dof == 3 else np.concatenate([force, left_jacobian(theta).T @ moment])
            return value / scale, gradient / scale

        # Unknowns in metres (rotation vector times the largest arm): a step turns the anchors as far as it
        # moves them (unscaled, CoGiRo's stiff cables, EA / L of 3e5 N/m, spun the platform several turns).
        arm = float(np.linalg.norm(platform.anchors, axis=1).max()) if dof == 6 else 1.0
        unit = np.array([1.0] * 3 + [max(arm, 1e-3)] * 3)[:dof]

        def scaled_energy(x):
            value, gradient = energy(x / unit)
            return value, gradient / unit

        # Start at the exits' centroid, unrotated: the weight and the taut cables pull the platform onto its
        # equilibrium (a cable length below the exits stretched CoGiRo's stiff cables by metres).
        start = np.zeros(dof)
        start[:3] = exits.mean(axis=0)
        solution = minimize(scaled_energy, start * unit, jac=True, method="BFGS",
                            options={"gtol": 1e-10, "maxiter": 5000})
        return np.append(solution.x / unit, np.zeros(6 - dof))

    def inverse(self, platform, pose, wrench, initial_guess, max_strain, max_tension, tolerance=1e-9,
                max_iterations=30):
        pose = real_array("pose", pose)
        dof = platform.degrees_of_freedom
        if pose.shape != (6,) and not (dof == 3 and pose.shape == (3,)):
            raise SceneError(f"pose must have 6 entries (3 for a point mass), got {shown(pose.tolist())}")
        if initial_guess is None:
            raise SceneError("initial_guess: the spatial inverse statics needs horizontal tensions to stay near "
                             "(eg the rest's), got None")
        guess = (initial_guess.horizontal_tensions if isinstance(initial_guess, PlatformEquilibrium)
                 else initial_guess)
        position = pose[:3]
        theta = pose[3:6] if pose.shape == (6,) and dof == 6 else np.zeros(3)
        rotation = rotation_from_vector(pose[3:6]) if pose.shape == (6,) and dof == 6 else np.eye(3)
        arms = platform.anchors @ rotation.T
        anchor_points = position + arms
        rows = 6 if (dof == 6 and len(platform.cables) >= 6) else 3
        weight = platform.mass * platform.gravity
        arm_scale = max(float(np.linalg.norm(platform.anchors, axis=1).max()), 1e-3)
        scale = np.array([1.0, 1.0, 1.0, 1.0 / arm_scale, 1.0 / arm_scale, 1.0 / arm_scale])[:rows]

        def balance(tensions):
            cables = [inverse_cable(c, h, p)[0] for c, p, h in zip(platform.cables, anchor_points, tensions)]
            forces = np.array([c.force_on_platform for c in cables])
            total = np.concatenate([forces.sum(axis=0) + wrench[:3] - [0.0, 0.0, weight],
                                    np.cross(arms, forces).sum(axis=0) + wrench[3:]])
            return cables, forces, total

        tensions = guess.copy()
        for _ in range(max_iterations):
            cables, forces, total = balance(tensions)
            residual = float(np.abs(total[:rows] * scale).max())
            if residual <= tolerance * max(weight, float(np.abs(forces).max()), 1e-12):
                return PlatformEquilibrium(SPACE, position.copy(), theta.copy(), rotation, tuple(cables), None,
                                           wrench, total)
            jacobian = np.zeros((rows, len(tensions)))
            for i, (cable, point, h) in enumerate(zip(platform.cables, anchor_points, tensions)):
                step = 1e-6 * h
                shifted = inverse_cable(cable, h + step, point)[0].force_on_platform
                derivative = (shifted - forces[i]) / step
                jacobian[:, i] = np.concatenate([derivative, np.cross(arms[i], derivative)])[:rows] * scale
            # the change nearest the guess that cancels the imbalance to first order
            offset = tensions - guess
            correction = -offset + np.linalg.pinv(jacobian) @ (jacobian @ offset - total[:rows] * scale)
            tensions = tensions + correction
            if np.any(tensions <= 0.0):
                raise UnreachableError(f"pose {np.round(pose, 6).tolist()}: the catenaries balance the platform only "
                                       f"if a cable pushes (horizontal tensions {np.round(tensions, 3).tolist()} N): "
                                       "it is outside the wrench-feasible workspace")
        raise UnreachableError(f"pose {np.round(pose, 6).tolist()}: the catenaries' balance did not converge "
                               f"(imbalance {residual:.3g} N after {max_iterations} iterations)")


_KERNELS = {PLANE: _PlanarStatics(), SPACE: _SpatialStatics()}


def _straight_path(cable, exit_point, point):
    """Length [m] of a straight, massless spatial cable from its exit to ``point`` (3,), and the unit vector
    (3,) of its last straight part towards ``point`` (the length's gradient). Over a swivel pulley it wraps
    the disc (:func:`cdpr_exu.core.geometry.swivel_pulley_exit`); where that is undefined (only ever an
    iterate of the start) the straight distance from the inlet stands in."""
    span = point - exit_point
    distance = float(np.linalg.norm(span))
    if cable.pulley_radius > 0.0:
        try:
            path = swivel_pulley_exit(exit_point, cable.pulley_radius, point)
        except UnreachableError:
            pass
        else:
            return float(path.arc_length + path.free_length), np.asarray(path.unit_vector, dtype=float)
    return distance, span / distance if distance > 0.0 else np.zeros(3)


def _straight_length_and_gradient(cable, point):
    """Straight length [m] of a planar cable from ``point`` to the hang point and its gradient in ``point``:
    over a pulley tangent plus wrap, the gradient the unit vector from the tangent point (the wrap's change
    cancels the tangent point's motion); inside the disc the distance to the centre plus half a turn."""
    if cable.pulley is None:
        offset = point - np.array(cable.exit_point)
        length = float(np.hypot(*offset))
        return length, (offset / length if length > 0.0 else np.zeros(2))
    pulley = cable.pulley
    offset = point - np.array(pulley.center)
    distance = float(np.hypot(*offset))
    if distance <= pulley.radius:
        return distance + math.pi * pulley.radius, offset / max(distance, 1e-300)
    angle = _straight_tangent_angle(pulley, point)
    offset = point - pulley.rim_point(angle)
    straight = float(np.hypot(*offset))
    return straight + pulley.radius * pulley.wrap_to(angle), offset / straight


def _wrap_angle(angle):
    """Angle in ``[-pi, pi)`` [rad] (unchanged, bit for bit, if already there)."""
    angle = float(angle)
    if -math.pi <= angle < math.pi:
        return angle
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


# --- the planar inverse: a square Newton iteration in the horizontal tensions
def _ideal_tensions(platform, position, rotation, wrench, free_rotation):
    """Horizontal tensions of straight massless cables balancing the load (start guess)."""
    points = _PlanarStatics.anchor_points(platform, position, rotation)
    turn = rotation_matrix(rotation)
    load = -np.array([wrench[0], wrench[1] - platform.mass * platform.gravity, wrench[2]])
    columns, horizontal = [], []
    for cable, point in zip(platform.cables, points):
        if cable.pulley is None:
            upper = np.array(cable.exit_point)
        else:
            upper = cable.pulley.rim_point(_straight_tangent_angle(cable.pulley, point))
        direction = upper - point
        length = float(np.hypot(*direction))
        unit = direction / length
        load[1] += 0.5 * cable.weight_per_length * length  # the anchor carries about half
        arm = turn @ cable.anchor
        columns.append([unit[0], unit[1], planar_cross(arm, unit)])
        horizontal.append(abs(unit[0]))
    structure = np.array(columns).T  # structure matrix, shape (3, n)
    rows = 2 if (platform.degrees_of_freedom == 2 or free_rotation) else 3
    tensions, *_ = np.linalg.lstsq(structure[:rows], load[:rows], rcond=None)
    moment_residual = float(structure[2] @ tensions - load[2])
    return tensions * np.array(horizontal), tensions, moment_residual


def _straight_cable_rotations(platform, position, wrench):
    """Rotations in ``[-pi, pi)`` at which straight massless cables hold the platform with positive tensions,
    smallest first: roots of the moment balance, scanned and refined by Brent's method. They start the
    inverse of a rigid platform on two cables, which tilts by up to a radian near the workspace edge."""
    def moment(phi):
        try:
            _, tensions, residual = _ideal_tensions(platform, position, phi, wrench, True)
        except (UnreachableError, np.linalg.LinAlgError, ZeroDivisionError):
            return math.nan, None
        return residual, tensions

    samples = np.linspace(-math.pi, math.pi, 73)
    values = [moment(phi)[0] for phi in samples]
    roots = []
    for a, b, fa, fb in zip(samples[:-1], samples[1:], values[:-1], values[1:]):
        if math.isfinite(fa) and math.isfinite(fb) and fa * fb <= 0.0 and fa != fb:
            try:
                root = brentq(lambda phi: moment(phi)[0], a, b, xtol=1e-12)
            except ValueError:
                continue
            tensions = moment(root)[1]
            if tensions is not None and np.all(tensions > 0.0):
                roots.append(_wrap_angle(root))
    return sorted(set(roots), key=abs)


def _planar_inverse(platform, position, rotation, wrench, max_strain, max_tension, initial_guess=None,
                    continuation=True):
    """:func:`solve_inverse_statics` of a planar platform (``rotation`` None: free, or a point mass)."""
    kernel = _KERNELS[PLANE]
    position = np.array(_point("pose", position, 2))
    dof = platform.degrees_of_freedom
    n = len(platform.cables)
    if dof == 2:
        if rotation not in (None, 0, 0.0):
            raise SceneError(f"a point-mass platform has no rotation, got rotation={shown(rotation)}")
        free_rotation = False
        rotation = 0.0
    else:
        free_rotation = rotation is None
        rotation = 0.0 if rotation is None else finite("rotation", rotation)
    if n + int(free_rotation) != dof:
        raise SceneError(f"inverse statics needs as many unknowns as equations: {n} cables"
                         f"{' + rotation' if free_rotation else ''} for {dof} equations; give a position "
                         f"(x, z) for a rigid platform on 2 cables, a pose (x, z, rotation) on 3")
    horizontal, tensions, _ = _ideal_tensions(platform, position, rotation, wrench, free_rotation)
    if np.any(tensions <= 0.0):
        # straight massless cables would push: start from a moderate pull and let Newton decide
        weight = max(platform.mass * platform.gravity, 1e-9)
        horizontal = np.maximum(horizontal, 0.1 * weight)
    lengths_guess = [_straight_length_and_gradient(c, p)[0]
                     for c, p in zip(platform.cables, kernel.anchor_points(platform, position, rotation))]
    force_scale, length_scale = kernel.scales(platform, lengths_guess, wrench)
    residual_scale = np.array([force_scale, force_scale, force_scale * length_scale])[:dof]
    unknown_scale = np.append(np.full(n, 1.0 / force_scale), [1.0 / math.pi] if free_rotation else [])
    noise = 1e3 * _RELATIVE_TOLERANCE * (1.0 + max(c.axial_stiffness for c in platform.cables) / force_scale)
    guesses = [None] * n
    cache = {}

    def evaluate(u):
        H = u[:n]
        phi = u[n] if free_rotation else rotation
        if np.any(H <= 0.0):
            raise UnreachableError("a cable would have to push (horizontal tension <= 0)")
        points = kernel.anchor_points(platform, position, phi)
        turn = rotation_matrix(phi)
        equilibria = []
        jacobian = np.zeros((3, n + 1))
        for i, (cable, point) in enumerate(zip(platform.cables, points)):
            equilibrium, force_dH, force_dp = inverse_cable(cable, H[i], point, guesses[i], max_strain, max_tension)
            equilibria.append(equilibrium)
            arm = turn @ cable.anchor
            jacobian[:2, i] = force_dH
            jacobian[2, i] = planar_cross(arm, force_dH)
            d_force_dphi = force_dp @ perpendicular(arm)
            jacobian[:2, n] += d_force_dphi
            jacobian[2, n] += (planar_cross(arm, d_force_dphi)
                               + planar_cross(perpendicular(arm), equilibrium.force_on_platform))
        guesses[:] = [e.guess for e in equilibria]
        residual = kernel.wrench_residual(platform, phi, equilibria, wrench)[:dof]
        columns = list(range(n)) + ([n] if free_rotation else [])
        cache["last"] = (equilibria, phi)
        return residual, jacobian[:dof][:, columns]

    def function(scaled):
        residual, jacobian = evaluate(scaled / unknown_scale)
        return residual / residual_scale, jacobian / residual_scale[:, None] / unknown_scale[None, :]

    # With a free rotation, a start where a cable hangs vertically (H = 0) or far off is retried turned.
    guessed_rotation = None
    if initial_guess is not None:
        guessed = initial_guess
        if isinstance(initial_guess, PlatformEquilibrium):
            guessed, guessed_rotation = initial_guess.horizontal_tensions, initial_guess.rotation
        if np.all(guessed > 0.0):
            horizontal = guessed

    def rotation_starts():
        if free_rotation and guessed_rotation is not None:
            yield guessed_rotation
        yield rotation
        if free_rotation:  # only computed when the plain start fails
            yield from _straight_cable_rotations(platform, position, wrench)
            yield from (0.05, -0.05, 0.3, -0.3)

    error = None
    for rotation_start in rotation_starts():
        guesses[:] = [None] * n
        start_tensions = horizontal
        if free_rotation and not (guessed_rotation is not None and rotation_start == guessed_rotation):
            start_tensions, tensions, _ = _ideal_tensions(platform, position, rotation_start, wrench, True)
            if np.any(tensions <= 0.0):
                start_tensions = np.maximum(start_tensions, 0.1 * max(platform.mass * platform.gravity, 1e-9))
        start = np.append(start_tensions, [rotation_start] if free_rotation else []) * unknown_scale
        try:
            scaled, _, _ = _damped_newton(function, start, _RELATIVE_TOLERANCE, positive=tuple(range(n)),
                                          what="inverse statics", noise=noise)
            break
        except UnreachableError as caught:
            error = caught
    else:
        if continuation and any(c.weight_per_length > 0.0 for c in platform.cables):
            try:
                return _inverse_by_weight_continuation(platform, position, None if free_rotation else rotation,
                                                       wrench, max_strain, max_tension)
            except UnreachableError:
                pass
        raise UnreachableError(f"no equilibrium with pulling cables at position ({position[0]:g}, "
                               f"{position[1]:g}) m ({error})") from None
    evaluate(scaled / unknown_scale)
    equilibria, phi = cache["last"]
    # stiffness at fixed lengths: the forward cable derivatives at the solution
    stiffnesses = []
    for cable, equilibrium in zip(platform.cables, equilibria):
        guess = None
        if cable.pulley is not None:
            guess = (equilibrium.catenary.horizontal_tension, equilibrium.catenary.vertical_tension_b,
                     _rim_angle(cable.pulley, equilibrium.exit_point))
        _, stiffness = forward_cable(cable, equilibrium.unstrained_length, equilibrium.anchor_point, guess,
                                     max_strain, max_tension)
        stiffnesses.append(stiffness)
    jacobian = kernel.pose_jacobian(platform, phi, equilibria, stiffnesses, dof)
    pose = np.append(position, phi)
    total = kernel.wrench_residual(platform, phi, equilibria, wrench)
    return kernel.result(platform, (pose, equilibria, jacobian, total), wrench)


_CONTINUATION_STEPS = (0.0, 0.1, 0.25, 0.45, 0.7, 1.0)


def _inverse_by_weight_continuation(platform, position, rotation, wrench, max_strain, max_tension):
    """Inverse statics by growing the cables' weight from zero, each step warm-started from the last: the
    last resort when every direct start fails (massless cables solve reliably from straight cables)."""
    previous = None
    for fraction in _CONTINUATION_STEPS:
        cables = tuple(SuspendedCable(c.weight_per_length * fraction, c.axial_stiffness, c.anchor, c.exit_point,
                                      c.pulley) for c in platform.cables)
        scaled = SuspendedPlatform(cables, platform.mass, platform.gravity, platform.inertia)
        previous = _planar_inverse(scaled if fraction < 1.0 else platform, position, rotation, wrench, max_strain,
                                   max_tension, initial_guess=previous, continuation=False)
    return previous


def _rim_angle(pulley, point):
    return math.atan2(point[1] - pulley.center[1], point[0] - pulley.center[0])
