"""Kineto-static equilibrium of a planar platform hung on elastic catenary cables.

The platform moves in the vertical x-z plane, gravity along -z. Its pose is the
position ``r = (x, z)`` [m] of its centre of mass and its rotation ``phi`` [rad],
positive counter-clockwise (the paper's eq. 17): an anchor ``b_i`` given in the
platform frame sits at ``p_i = r + R(phi) b_i`` with ``R = [[cos, -sin], [sin, cos]]``.
Moments are about the centre of mass, positive in the sense of ``phi``:
``m = a_x f_z - a_z f_x`` for a force ``f`` applied at offset ``a``.

Each cable is an elastic catenary (`cdpr_exu.physics.catenary`) from its anchor on the
platform (end A) to its upper end (end B), which is either

* a fixed exit point, or
* a pulley: the cable comes up from its winch along the vertical line
  ``x = c_x + side * r_p``, wraps over the top of the pulley and leaves it
  tangentially at the point where the catenary's end direction is tangent to the
  circle. The unstrained length counts from the anchor to the point
  ``(c_x + side * r_p, c_z)`` and includes the wrapped arc.

Pulley approximations (documented choices):

* frictionless: the tension is the same all along the wrap, equal to the tension at
  the tangent point; the wrapped arc's unstrained length is
  ``r_p * wrap_angle / (1 + T / EA)``;
* the weight of the wrapped part is carried by the pulley and neglected in the wrap's
  tension. Exactly, a frictionless wrap gains ``w * height`` of tension going up
  (``dT/ds = w dz/ds``): at most ``w r_p`` (0.86 N for the paper's cable, 12 % of the
  7 N a 1 kg platform puts on each cable). It only changes the stretch of the wrapped
  part, by ``r_p * wrap_angle * w r_p / EA`` (7e-6 m for the paper), and the tension
  that reaches the winch, which is not modelled here. A side effect: length that
  moves between the wrap and the span gains or loses weight, so the model is
  slightly non-conservative and its stiffness slightly asymmetric (2.5e-6 relative
  for the paper's cable; exactly symmetric for w = 0);
* the pulley is a rigid circle; the cable has no bending stiffness; no pulley inertia
  or friction;
* a platform directly under the inner rim of a pulley (left of ``c_x + r_p`` for a
  left pulley wrapped from its outer side) cannot be held: the cable there can only
  pull it inwards, and `solve_inverse_statics` raises `UnreachableError`.

Solvers:

* `solve_forward_statics`: given the unstrained lengths, the pose and the forces;
  unknowns ``(x, z)`` for a point mass, ``(x, z, phi)`` for a rigid platform.
* `solve_inverse_statics`: given the position (and the rotation when it is free to
  choose), the unstrained lengths, forces and, for a rigid platform on two cables,
  the rotation that equilibrium imposes. Unknowns: the horizontal tension of each
  cable (each cable's unstrained length follows from `catenary.solve_inverse`) and,
  when it is not given, the rotation.

Both are Newton iterations with analytic Jacobians built from the catenary end
stiffnesses, and both accept an external wrench on the platform (eg the inertial
load ``-M a`` for dynamic feed-forward, see `inertial_wrench`). The forward problem
is an energy minimum: its line search follows the energy (see `minimise_energy`)
and starts from `straight_cable_pose`. The inverse problem is a root search on the
residual norm; for a rigid platform on two cables it is started at the rotations
where straight massless cables balance the platform (up to a radian near the
workspace edges). Horizontal tension cannot parametrise an exactly vertical cable,
so inverse statics needs every cable off the vertical at the solution.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import minimize

from cdpr_exu.physics.catenary import (
    DEFAULT_MAX_STRAIN,
    STANDARD_GRAVITY,
    CatenaryCable,
    CatenaryState,
    end_stiffness,
    solve_forward,
    solve_inverse,
    span_and_jacobian,
    state_from_end_forces,
)
from cdpr_exu.core.errors import SceneError, UnreachableError
from cdpr_exu.core.geometry import perpendicular, planar_cross, rotation_matrix
from cdpr_exu.core.validation import finite, non_negative, positive, real_array, shown, vector
from cdpr_exu.exits import Exit, Pulley

_RELATIVE_TOLERANCE = 1e-12


# ---------------------------------------------------------------------------
# validation helpers
# ---------------------------------------------------------------------------
def _point(name, value):
    x, z = vector(name, value, 2, " (x, z) [m]")
    return (float(x), float(z))


def _wrench(value):
    if value is None:
        return np.zeros(3)
    return vector("external_wrench", value, 3, " (fx [N], fz [N], moment [N m])")


# ---------------------------------------------------------------------------
# parameters
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class SuspendedCable:
    """One cable of the platform: its material, its anchor and its upper end.

    Parameters
    ----------
    weight_per_length : float [N/m]
        ``w >= 0``, weight per unstrained length.
    axial_stiffness : float [N]
        ``EA > 0``.
    anchor : (float, float) [m]
        Anchor point on the platform, in the platform frame (centre of mass at 0).
    exit_point : (float, float) [m], optional
        Fixed upper end, world frame. Give exactly one of ``exit_point`` and ``pulley``.
    pulley : Exit, optional
        The planar exit the cable leaves from (:mod:`cdpr_exu.exits`): a
        :class:`~cdpr_exu.exits.pulley.Pulley`, or an exit the cable does not wrap (a point
        exit), taken as the fixed ``exit_point`` at its point.
    """

    weight_per_length: float
    axial_stiffness: float
    anchor: tuple = (0.0, 0.0)
    exit_point: tuple | None = None
    pulley: Exit | None = None

    def __post_init__(self):
        object.__setattr__(
            self, "weight_per_length", non_negative("weight_per_length", self.weight_per_length)
        )
        object.__setattr__(
            self, "axial_stiffness", positive("axial_stiffness", self.axial_stiffness)
        )
        object.__setattr__(self, "anchor", _point("anchor", self.anchor))
        if (self.exit_point is None) == (self.pulley is None):
            raise SceneError(
                f"give exactly one of exit_point and pulley, got exit_point={shown(self.exit_point)}, "
                f"pulley={shown(self.pulley)}"
            )
        if self.exit_point is not None:
            object.__setattr__(self, "exit_point", _point("exit_point", self.exit_point))
        elif not isinstance(self.pulley, Exit):
            raise SceneError(f"pulley must be a Pulley or another exit (cdpr_exu.exits), got {shown(self.pulley)}")
        elif not self.pulley.wraps:  # the cable leaves from the exit's point
            object.__setattr__(self, "exit_point", _point("exit_point", self.pulley.point))
            object.__setattr__(self, "pulley", None)

    def catenary(self, unstrained_length):
        """The `CatenaryCable` of this cable with the given unstrained length [m]."""
        return CatenaryCable(unstrained_length, self.weight_per_length, self.axial_stiffness)

    @property
    def upper_reference(self):
        """Exit point, or pulley centre, shape (2,) [m]."""
        if self.pulley is None:
            return np.array(self.exit_point)
        return np.array(self.pulley.center)


def swivel_plane_cable(weight_per_length, axial_stiffness, radius) -> SuspendedCable:
    """The planar cable of a swivel pulley of radius ``radius`` [m], in the vertical plane through its axis
    and the anchor: over a pulley of centre (r_p, 0), hung on its left (side -1), so that its hang point
    is the inlet at the plane's origin and its winch line the swivel axis (:mod:`cdpr_exu.core.geometry`,
    "Swivel pulley"); the anchor at the platform's reference point."""
    radius = float(radius)
    return SuspendedCable(weight_per_length, axial_stiffness, anchor=(0.0, 0.0), pulley=Pulley((radius, 0.0), radius, -1))


@dataclass(frozen=True)
class SuspendedPlatform:
    """A planar platform hung on catenary cables.

    Parameters
    ----------
    cables : sequence of SuspendedCable
    mass : float [kg]
        ``M >= 0``; its weight ``M g`` acts at the centre of mass, along -z.
    gravity : float [m/s^2], optional
        Default 9.81.
    moment_of_inertia : float [kg m^2], optional
        About the centre of mass; only used by `inertial_wrench`.

    A platform whose anchors are all at the centre of mass is a point mass: its
    rotation is irrelevant (fixed at 0) and only the force balance is solved.
    """

    cables: tuple
    mass: float
    gravity: float = STANDARD_GRAVITY
    moment_of_inertia: float = 0.0

    def __post_init__(self):
        try:
            cables = tuple(self.cables)
        except TypeError:
            raise SceneError(f"cables must be a non-empty sequence of SuspendedCable, got {shown(self.cables)}") from None
        if not cables or not all(isinstance(c, SuspendedCable) for c in cables):
            raise SceneError(f"cables must be a non-empty sequence of SuspendedCable, got {shown(self.cables)}")
        object.__setattr__(self, "cables", cables)
        object.__setattr__(self, "mass", non_negative("mass", self.mass))
        object.__setattr__(self, "gravity", non_negative("gravity", self.gravity))
        object.__setattr__(
            self, "moment_of_inertia", non_negative("moment_of_inertia", self.moment_of_inertia)
        )

    @property
    def is_point_mass(self):
        """True when every anchor is at the centre of mass."""
        return all(c.anchor == (0.0, 0.0) for c in self.cables)

    @property
    def degrees_of_freedom(self):
        """2 for a point mass ``(x, z)``, 3 for a rigid platform ``(x, z, phi)``."""
        return 2 if self.is_point_mass else 3

    def anchor_points(self, position, rotation=0.0):
        """World positions of the anchors, shape (n_cables, 2) [m]."""
        turn = rotation_matrix(rotation)
        return np.array([np.asarray(position) + turn @ c.anchor for c in self.cables])


def inertial_wrench(platform, acceleration, angular_acceleration=0.0):
    """D'Alembert load ``(-M a_x, -M a_z, -J alpha)`` for dynamic feed-forward.

    Parameters
    ----------
    platform : SuspendedPlatform
    acceleration : (float, float) [m/s^2]
        Acceleration of the centre of mass.
    angular_acceleration : float [rad/s^2], optional

    Returns
    -------
    ndarray, shape (3,) [N, N, N m]
        To pass as ``external_wrench`` to the statics solvers. Cable inertia is
        neglected (the cables stay in quasi-static equilibrium).
    """
    a = _point("acceleration", acceleration)
    alpha = finite("angular_acceleration", angular_acceleration)
    return np.array(
        [-platform.mass * a[0], -platform.mass * a[1], -platform.moment_of_inertia * alpha]
    )


# ---------------------------------------------------------------------------
# results
# ---------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class CableEquilibrium:
    """One cable in a platform equilibrium.

    Attributes
    ----------
    catenary : CatenaryState
        The suspended part, from the anchor (A) to the exit or tangent point (B).
    unstrained_length : float [m]
        Total: suspended part plus, with a pulley, the wrapped arc up to the winch
        point.
    suspended_length : float [m]
        Unstrained length of the suspended part.
    anchor_point : ndarray, shape (2,) [m]
        World position of the anchor.
    upper_point : ndarray, shape (2,) [m]
        Exit point, or the point where the cable leaves the pulley.
    wrap_angle : float [rad]
        Angle wrapped on the pulley (0 for a fixed exit point).
    """

    catenary: CatenaryState
    unstrained_length: float
    suspended_length: float
    anchor_point: np.ndarray
    upper_point: np.ndarray
    wrap_angle: float = 0.0

    @property
    def force_on_platform(self):
        """Force the cable exerts on the platform at its anchor, shape (2,) [N]."""
        return self.catenary.force_on_a

    @property
    def tension_at_anchor(self):
        """Tension at the anchor [N]."""
        return self.catenary.tension_a

    @property
    def tension_at_exit(self):
        """Tension at the exit or tangent point [N] (uniform along the wrap)."""
        return self.catenary.tension_b


class PlatformEquilibriumViews:
    """Per-cable views of a platform equilibrium that holds ``cables`` and ``stiffness``.

    Shared by the planar :class:`PlatformEquilibrium` and the spatial
    :class:`~cdpr_exu.physics.spatial_statics.SpatialEquilibrium`.
    """

    @property
    def tensions_at_anchor(self):
        """Tension of each cable at its anchor, shape (n_cables,) [N]."""
        return np.array([c.tension_at_anchor for c in self.cables])

    @property
    def forces_on_platform(self):
        """Force of each cable on the platform, shape (n_cables, 2) or (n_cables, 3) [N]."""
        return np.array([c.force_on_platform for c in self.cables])

    @property
    def is_stable(self):
        """True when the symmetric part of `stiffness` is positive definite."""
        return bool(np.all(np.linalg.eigvalsh(0.5 * (self.stiffness + self.stiffness.T)) > 0.0))


@dataclass(frozen=True, eq=False)
class PlatformEquilibrium(PlatformEquilibriumViews):
    """A static (or quasi-static) equilibrium of the platform on its cables.

    Attributes
    ----------
    position : ndarray, shape (2,) [m]
        Centre of mass.
    rotation : float [rad]
        Counter-clockwise; 0 for a point mass.
    cables : tuple of CableEquilibrium
    stiffness : ndarray, shape (k, k)
        ``-d(wrench on the platform)/d(pose)`` at fixed unstrained lengths, with
        ``k = 2`` ``(x, z)`` for a point mass, ``k = 3`` ``(x, z, phi)`` otherwise;
        units N/m, N/rad, N m/m, N m/rad. Positive definite where the equilibrium is
        stable.
    external_wrench : ndarray, shape (3,) [N, N, N m]
    """

    position: np.ndarray
    rotation: float
    cables: tuple
    stiffness: np.ndarray = field(repr=False)
    external_wrench: np.ndarray = field(repr=False)

    @property
    def unstrained_lengths(self):
        """Unstrained length of each cable, shape (n_cables,) [m]."""
        return np.array([c.unstrained_length for c in self.cables])


# ---------------------------------------------------------------------------
# a small damped Newton solver
# ---------------------------------------------------------------------------
def _damped_newton(
    function, x0, tolerance, positive=(), max_iterations=100, what="equilibrium", noise=None,
    line_search_steps=50,
):
    """Newton's method with backtracking on the residual norm.

    ``function(x) -> (residual, jacobian)``; it may raise UnreachableError at a trial
    point, which then counts as a rejected step. Components listed in ``positive``
    are kept above 10 % of their current value. Converged when the residual norm is
    below ``tolerance``, or when no step decreases it any more and it is below
    ``noise`` (default ``1e3 tolerance``), the precision the residual can have.
    Returns ``(x, residual, jacobian)``.
    """
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
    """Newton's method for a conservative equilibrium, with a line search on the energy.

    ``function(x) -> (residual, jacobian)`` where the residual is the net generalised
    force, ``-grad(energy)``, and the jacobian ``-hessian``. The energy itself is not
    needed: along a descent direction ``d`` its slope is ``-residual . d``, and the
    step length is chosen where that slope stops being (strongly) negative, ie near
    the energy minimum along the line. Unlike a search on the residual norm, this
    cannot stall away from an equilibrium, which matters on the curved, stiff valleys
    of near-vertical cables (a pendulum: stiff along the cable, soft across it).
    Where the stiffness is not positive definite along the Newton direction, the
    direction falls back to the (scaled) steepest descent.
    """
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


# ---------------------------------------------------------------------------
# one cable: straight geometry
# ---------------------------------------------------------------------------
def _straight_tangent_angle(pulley, point):
    """Rim angle where a straight cable from ``point`` leaves ``pulley``."""
    centre = np.array(pulley.center)
    offset = centre - point
    distance = float(np.hypot(*offset))
    if distance <= pulley.radius:
        raise UnreachableError(
            f"anchor point ({point[0]:g}, {point[1]:g}) m lies inside the pulley of centre "
            f"{pulley.center} m and radius {pulley.radius:g} m"
        )
    gamma = math.atan2(offset[1], offset[0])
    spread = math.acos(-pulley.radius / distance)
    for angle in (gamma + spread, gamma - spread):
        tangent = pulley.side * np.array([math.sin(angle), -math.cos(angle)])
        if np.dot(pulley.rim_point(angle) - point, tangent) > 0.0:
            return angle
    raise AssertionError("no tangent with the pulley's orientation")  # pragma: no cover


# ---------------------------------------------------------------------------
# one cable: forward (given unstrained length) and inverse (given H)
# ---------------------------------------------------------------------------
def _pulley_residual(cable, pulley, sign_x, point, H, V_B, angle, suspended_length, tension_scale):
    """Residual of the pulley cable (span mismatch, tangency) and its partial derivatives.

    Returns ``(residual (3,), d/d(H, V_B, L_c, angle) (3, 4), catenary)``.
    """
    catenary = cable.catenary(suspended_length)
    span, jac = span_and_jacobian(catenary, H, V_B, sign_x)
    tangent = pulley.rim_point(angle)
    c, s = math.cos(angle), math.sin(angle)
    scale = suspended_length / tension_scale  # tangency residual in metres
    residual = np.empty(3)
    residual[:2] = span - (tangent - point)
    residual[2] = scale * (sign_x * H * c + V_B * s)
    partial = np.zeros((3, 4))
    partial[:2, 0] = jac[:, 0]
    partial[:2, 1] = jac[:, 1]
    partial[:2, 2] = jac[:, 2]
    partial[:2, 3] = -pulley.radius * np.array([-s, c])
    partial[2, 0] = scale * sign_x * c
    partial[2, 1] = scale * s
    partial[2, 3] = scale * (-sign_x * H * s + V_B * c)
    return residual, partial, catenary


def forward_cable(cable, unstrained_length, point, guess, max_strain, max_tension):
    """Cable of given length from an anchor point: equilibrium and ``dF_A/dp_A``.

    Returns ``(CableEquilibrium, d(force on A)/d(anchor point) (2, 2), guess)``.
    """
    if cable.pulley is None:
        catenary_guess = None if guess is None else guess[:2]
        state = solve_forward(
            cable.catenary(unstrained_length),
            np.array(cable.exit_point) - point,
            initial_guess=catenary_guess,
            max_strain=max_strain,
            max_tension=max_tension,
        )
        equilibrium = CableEquilibrium(
            state, unstrained_length, unstrained_length, point.copy(), np.array(cable.exit_point)
        )
        stiffness = end_stiffness(cable.catenary(unstrained_length), state)
        return equilibrium, stiffness, (state.horizontal_tension, state.vertical_tension_b)

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
                raise UnreachableError(
                    f"unstrained_length {unstrained_length:g} m is shorter than the wrap on the pulley"
                )
            state = solve_forward(
                cable.catenary(suspended), pulley.rim_point(angle) - point,
                max_strain=max_strain, max_tension=max_tension,
            )
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
            residual, partial, _ = _pulley_residual(
                cable, pulley, sign_x, point, x[0], x[1], x[2], length, tension_scale
            )
            jacobian = partial[:, [0, 1, 3]] + np.outer(partial[:, 2], derivative)
            return residual, jacobian

        tolerance = _RELATIVE_TOLERANCE * unstrained_length
        x, _, jacobian = _damped_newton(
            function, (H, V_B, angle), tolerance, positive=(0,), what="pulley cable",
            **_INNER_NEWTON,
        )
        return x, jacobian, sign_x, tension_scale

    x, jacobian, sign_x, _ = _warm_then_cold(solve_from, guess)
    H, V_B, angle = x
    length, derivative, wrap = suspended_length(x)
    state = state_from_end_forces(cable.catenary(length), H, V_B, sign_x)
    if state.max_tension > _tension_limit(cable, max_strain, max_tension):
        raise UnreachableError(
            f"cable of unstrained_length {unstrained_length:g} m would need tension "
            f"{state.max_tension:g} N, above its limit"
        )
    # d(H, V_B, angle)/d(point) = -jacobian^-1 d(residual)/d(point), d(residual)/d(point) = [I; 0]
    sensitivity = -np.linalg.solve(jacobian, np.vstack([np.eye(2), np.zeros((1, 2))]))
    force_derivative = np.array(
        [[sign_x, 0.0, 0.0], [-w * derivative[0], 1.0 - w * derivative[1], -w * derivative[2]]]
    )
    stiffness = force_derivative @ sensitivity
    equilibrium = CableEquilibrium(
        state, unstrained_length, length, point.copy(), pulley.rim_point(angle), wrap
    )
    return equilibrium, stiffness, (H, V_B, angle)


def _tension_limit(cable, max_strain, max_tension):
    limit = max_strain * cable.axial_stiffness
    return limit if max_tension is None else min(limit, max_tension)


def inverse_cable(cable, horizontal_tension, point, guess, max_strain, max_tension):
    """Cable with given horizontal tension from an anchor point.

    Returns ``(CableEquilibrium, dF_A/dH (2,), dF_A/dp_A at fixed H (2, 2), guess)``.
    """
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
        equilibrium = CableEquilibrium(state, length, length, point.copy(), np.array(cable.exit_point))
        new_guess = None
    else:
        pulley, r = cable.pulley, cable.pulley.radius

        def solve_from(start_guess):
            if start_guess is None:
                angle = _straight_tangent_angle(pulley, point)
                length, state = solve_inverse(
                    pulley.rim_point(angle) - point, w, EA, H,
                    max_strain=max_strain, max_tension=max_tension,
                )
                V_B = state.vertical_tension_b
            else:
                length, V_B, angle = start_guess
            sign_x = -1.0 if pulley.rim_point(angle)[0] < point[0] else 1.0
            tension_scale = max(math.hypot(H, V_B), w * length, 1e-300)

            def function(x):
                if x[0] <= 0.0:
                    raise UnreachableError("suspended length must stay positive")
                residual, partial, _ = _pulley_residual(
                    cable, pulley, sign_x, point, H, x[1], x[2], x[0], tension_scale
                )
                return residual, partial[:, [2, 1, 3]]

            x, _, jacobian = _damped_newton(
                function, (length, V_B, angle), _RELATIVE_TOLERANCE * length, positive=(0,),
                what="pulley cable", **_INNER_NEWTON,
            )
            return x, jacobian, sign_x, tension_scale

        x, jacobian, sign_x, tension_scale = _warm_then_cold(solve_from, guess)
        length, V_B, angle = x
        _, partial, catenary = _pulley_residual(
            cable, pulley, sign_x, point, H, V_B, angle, length, tension_scale
        )
        d_residual_dH = partial[:, 0]
        d_residual_dp = np.vstack([np.eye(2), np.zeros((1, 2))])
        state = state_from_end_forces(catenary, H, V_B, sign_x)
        wrap = pulley.wrap_to(angle)
        total = length + r * wrap / (1.0 + state.tension_b / EA)
        equilibrium = CableEquilibrium(state, total, length, point.copy(), pulley.rim_point(angle), wrap)
        new_guess = (length, V_B, angle)
    if state.max_tension > _tension_limit(cable, max_strain, max_tension):
        raise UnreachableError(
            f"horizontal_tension {H:g} N needs tension {state.max_tension:g} N, above the limit"
        )
    # unknowns u = (L_c, V_B[, angle]); force on A = (sign_x H, V_B - w L_c)
    d_u_dH = -np.linalg.solve(jacobian, d_residual_dH)
    d_u_dp = -np.linalg.solve(jacobian, d_residual_dp)
    force_dH = np.array([sign_x, d_u_dH[1] - w * d_u_dH[0]])
    force_dp = np.vstack([np.zeros(2), d_u_dp[1] - w * d_u_dp[0]])
    return equilibrium, force_dH, force_dp, new_guess


# ---------------------------------------------------------------------------
# the platform
# ---------------------------------------------------------------------------
def _scales(platform, lengths, wrench):
    """Force [N] and length [m] scales of the equilibrium residual."""
    weight = platform.mass * platform.gravity
    cable_weight = sum(c.weight_per_length * L for c, L in zip(platform.cables, lengths))
    force = weight + cable_weight + float(np.hypot(wrench[0], wrench[1]))
    arm = max((float(np.hypot(*c.anchor)) for c in platform.cables), default=0.0)
    length = arm if arm > 0.0 else 1.0
    force = max(force, abs(wrench[2]) / length, 1e-12)
    return force, length


def _platform_noise(platform, force_scale):
    """Precision of the relative wrench balance.

    Each cable is solved to ``1e-12`` of its length, which leaves a force error of
    about ``1e-12 EA``: a stiff cable cannot balance a light platform any better.
    """
    stiffest = max(c.axial_stiffness for c in platform.cables)
    return 1e3 * _RELATIVE_TOLERANCE * (1.0 + stiffest / force_scale)


def _wrench_residual(platform, rotation, equilibria, wrench, dof):
    """Net wrench on the platform ``(fx, fz[, m])`` [N, N, N m]."""
    turn = rotation_matrix(rotation)
    total = np.array([wrench[0], wrench[1] - platform.mass * platform.gravity, wrench[2]])
    for cable, equilibrium in zip(platform.cables, equilibria):
        force = equilibrium.force_on_platform
        total[:2] += force
        total[2] += planar_cross(turn @ cable.anchor, force)
    return total[:dof]


def _pose_jacobian(platform, rotation, equilibria, stiffnesses, dof):
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


def _lengths(platform, unstrained_lengths):
    try:
        lengths = np.asarray(unstrained_lengths, dtype=float)
    except (TypeError, ValueError):
        raise SceneError(f"unstrained_lengths must be numbers [m], got {shown(unstrained_lengths)}") from None
    if lengths.shape != (len(platform.cables),):
        raise SceneError(
            f"unstrained_lengths must have one entry per cable ({len(platform.cables)}), "
            f"got {shown(unstrained_lengths)}"
        )
    if not np.all(np.isfinite(lengths)) or np.any(lengths <= 0.0):
        raise SceneError(f"unstrained_lengths must be positive and finite, got {shown(unstrained_lengths)}")
    return lengths


def straight_cable_pose(platform, unstrained_lengths, external_wrench=None):
    """Equilibrium pose on straight, massless, elastic cables that may go slack.

    Minimises the potential energy ``M g z - wrench . pose + sum k_i max(l_i - L_i, 0)^2 / 2``
    with ``l_i`` the straight (pulley: tangent plus wrap) length from anchor to winch
    point and ``k_i = EA_i / L_i``. Unlike intersecting the circles of inextensible
    cables, this always has a solution, also when some cables are too long to be
    taut; it is the starting guess of `solve_forward_statics`.

    Parameters
    ----------
    platform : SuspendedPlatform
    unstrained_lengths : array_like, shape (n_cables,) [m]
    external_wrench : (fx, fz, moment), optional
        [N, N, N m].

    Returns
    -------
    position : ndarray, shape (2,) [m]
    rotation : float [rad]
        0 for a point mass.
    """
    lengths = _lengths(platform, unstrained_lengths)
    wrench = _wrench(external_wrench)
    dof = platform.degrees_of_freedom
    stiffness = np.array([c.axial_stiffness / L for c, L in zip(platform.cables, lengths)])
    uppers = np.array([c.upper_reference for c in platform.cables])
    force_scale, length_scale = _scales(platform, lengths, wrench)
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
    solution = minimize(
        energy, start, jac=True, method="BFGS",
        options={"gtol": 1e-9 * force_scale, "maxiter": 2000},
    )
    phi = _wrap_angle(solution.x[2]) if dof == 3 else 0.0
    return solution.x[:2].copy(), phi


def _straight_length_and_gradient(cable, point):
    """Straight length from ``point`` to the winch point [m] and its gradient in ``point``.

    With a pulley, the length is tangent plus wrapped arc; its gradient is the unit
    vector from the tangent point to ``point`` (the wrap change cancels the tangent
    point's motion to first order). Inside a pulley disc (no tangent) the distance
    to the centre plus half a turn stands in, to keep the energy continuous-ish.
    """
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


def solve_forward_statics(
    platform,
    unstrained_lengths,
    initial_pose=None,
    external_wrench=None,
    max_strain=DEFAULT_MAX_STRAIN,
    max_tension=None,
):
    """Equilibrium pose and cable forces of the platform for given cable lengths.

    Solves the force balance (and the moment balance about the centre of mass for a
    rigid platform) by Newton's method with the analytic Jacobian, assembled from the
    cables' end stiffnesses; each residual evaluation solves every cable's catenary,
    warm-started from the previous iterate.

    Parameters
    ----------
    platform : SuspendedPlatform
    unstrained_lengths : array_like, shape (n_cables,) [m]
        Total unstrained length of each cable (with a pulley: up to its winch point).
    initial_pose : (x, z) or (x, z, phi), optional
        Starting pose [m, m, rad]; default: `straight_cable_pose` (massless elastic
        cables).
    external_wrench : (fx, fz, moment), optional
        Extra load on the platform [N, N, N m] at its centre of mass, eg
        `inertial_wrench`.
    max_strain, max_tension : float, optional
        Cable tension limits, as in `catenary.solve_forward`.

    Returns
    -------
    PlatformEquilibrium

    Raises
    ------
    UnreachableError
        If no equilibrium is found within the tension limits.
    SceneError
        If an argument is invalid.
    """
    if not isinstance(platform, SuspendedPlatform):
        raise SceneError(f"platform must be a SuspendedPlatform, got {shown(platform)}")
    lengths = _lengths(platform, unstrained_lengths)
    wrench = _wrench(external_wrench)
    dof = platform.degrees_of_freedom
    if initial_pose is None:
        position, rotation = straight_cable_pose(platform, lengths, wrench)
    else:
        pose = real_array("initial_pose", initial_pose)
        if pose.shape not in ((2,), (3,)) or not np.all(np.isfinite(pose)):
            raise SceneError(f"initial_pose must be (x, z) or (x, z, phi), got {shown(initial_pose)}")
        position, rotation = pose[:2], (float(pose[2]) if pose.size == 3 else 0.0)
    if dof == 2:
        rotation = 0.0
    force_scale, length_scale = _scales(platform, lengths, wrench)
    residual_scale = np.array([force_scale, force_scale, force_scale * length_scale])[:dof]
    pose_scale = np.array([1.0, 1.0, length_scale])[:dof]  # unknowns in metres
    guesses = [None] * len(platform.cables)
    cache = {}

    def evaluate(pose):
        phi = pose[2] if dof == 3 else 0.0
        points = platform.anchor_points(pose[:2], phi)
        equilibria, stiffnesses, new_guesses = [], [], []
        for i, (cable, point, length) in enumerate(zip(platform.cables, points, lengths)):
            equilibrium, stiffness, guess = forward_cable(
                cable, length, point, guesses[i], max_strain, max_tension
            )
            equilibria.append(equilibrium)
            stiffnesses.append(stiffness)
            new_guesses.append(guess)
        guesses[:] = new_guesses
        residual = _wrench_residual(platform, phi, equilibria, wrench, dof)
        jacobian = _pose_jacobian(platform, phi, equilibria, stiffnesses, dof)
        cache["last"] = (equilibria, jacobian)
        return residual, jacobian

    def function(scaled_pose):
        residual, jacobian = evaluate(scaled_pose / pose_scale)
        return residual / residual_scale, jacobian / residual_scale[:, None] / pose_scale[None, :]

    start = np.append(position, rotation)[:dof] * pose_scale
    scaled, _, _ = minimise_energy(
        function, start, _RELATIVE_TOLERANCE, _platform_noise(platform, force_scale),
        what="forward statics",
    )
    pose = scaled / pose_scale
    _, jacobian = evaluate(pose)  # the accepted point, with its own cable states
    equilibria, _ = cache["last"]
    return _result(platform, pose, equilibria, jacobian, wrench, dof)


def _result(platform, pose, equilibria, jacobian, wrench, dof):
    return PlatformEquilibrium(
        position=np.array(pose[:2], dtype=float),
        rotation=_wrap_angle(pose[2]) if dof == 3 else 0.0,
        cables=tuple(equilibria),
        stiffness=-np.array(jacobian),
        external_wrench=wrench,
    )


def _ideal_tensions(platform, position, rotation, wrench, free_rotation):
    """Horizontal tensions of straight massless cables balancing the load (start guess)."""
    points = platform.anchor_points(position, rotation)
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
    """Rotations at which straight massless cables hold the platform with positive tensions.

    Roots of the moment balance (after the force balance fixes the tensions) found by
    scanning ``[-pi, pi)`` and refining with Brent's method; sorted by size. These
    start the inverse statics of a rigid platform on two cables, whose equilibrium
    rotation can be large (near the workspace edge the platform tilts by a radian).
    """
    from scipy.optimize import brentq

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


def solve_inverse_statics(
    platform,
    position,
    rotation=None,
    external_wrench=None,
    max_strain=DEFAULT_MAX_STRAIN,
    max_tension=None,
    initial_guess=None,
    _continuation=True,
):
    """Cable lengths and forces that hold the platform at a given position.

    Unknowns: each cable's horizontal tension, plus the rotation when it is not
    given; each cable's unstrained length and end forces follow from
    `catenary.solve_inverse` (or its pulley version). Equations: force balance, and
    moment balance for a rigid platform. The problem must be square:

    * point mass: 2 cables (more would need a tension distribution);
    * rigid platform on 2 cables: ``rotation=None`` (3 DOF, 2 cables: equilibrium
      fixes the rotation);
    * rigid platform on 3 cables: ``rotation`` given.

    Parameters
    ----------
    platform : SuspendedPlatform
    position : (x, z) [m]
        Desired position of the centre of mass.
    rotation : float [rad], optional
        Desired rotation, when the cables can choose it (see above).
    external_wrench : (fx, fz, moment), optional
        Extra load [N, N, N m], eg `inertial_wrench` for dynamic feed-forward.
    max_strain, max_tension : float, optional
        Cable tension limits, as in `catenary.solve_forward`.
    initial_guess : PlatformEquilibrium, optional
        A nearby solution (eg the previous pose along a trajectory): its horizontal
        tensions and rotation start the iteration.

    Returns
    -------
    PlatformEquilibrium
        With the unstrained lengths, forces, the rotation and the stiffness at fixed
        lengths.

    Raises
    ------
    UnreachableError
        If a cable would have to push (no equilibrium with positive tensions), a cable
        would be vertical (its horizontal tension cannot parametrise it), a tension
        exceeds the limit, or Newton fails.
    SceneError
        If an argument is invalid or the problem is not square.
    """
    position = np.array(_point("position", position))
    wrench = _wrench(external_wrench)
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
        raise SceneError(
            f"inverse statics needs as many unknowns as equations: {n} cables"
            f"{' + rotation' if free_rotation else ''} for {dof} equations; "
            f"pass rotation=None for a rigid platform on 2 cables, a rotation on 3"
        )
    horizontal, tensions, _ = _ideal_tensions(platform, position, rotation, wrench, free_rotation)
    if np.any(tensions <= 0.0):
        # straight massless cables would push; start from a moderate pull and let
        # Newton decide (it fails, with UnreachableError, if they really must push)
        weight = max(platform.mass * platform.gravity, 1e-9)
        horizontal = np.maximum(horizontal, 0.1 * weight)
    lengths_guess = [
        _straight_length_and_gradient(c, p)[0]
        for c, p in zip(platform.cables, platform.anchor_points(position, rotation))
    ]
    force_scale, length_scale = _scales(platform, lengths_guess, wrench)
    residual_scale = np.array([force_scale, force_scale, force_scale * length_scale])[:dof]
    unknown_scale = np.append(np.full(n, 1.0 / force_scale), [1.0 / math.pi] if free_rotation else [])
    guesses = [None] * n
    cache = {}

    def evaluate(u):
        H = u[:n]
        phi = u[n] if free_rotation else rotation
        if np.any(H <= 0.0):
            raise UnreachableError("a cable would have to push (horizontal tension <= 0)")
        points = platform.anchor_points(position, phi)
        turn = rotation_matrix(phi)
        equilibria, new_guesses = [], []
        jacobian = np.zeros((3, n + 1))
        for i, (cable, point) in enumerate(zip(platform.cables, points)):
            equilibrium, force_dH, force_dp, guess = inverse_cable(
                cable, H[i], point, guesses[i], max_strain, max_tension
            )
            equilibria.append(equilibrium)
            new_guesses.append(guess)
            arm = turn @ cable.anchor
            jacobian[:2, i] = force_dH
            jacobian[2, i] = planar_cross(arm, force_dH)
            d_force_dphi = force_dp @ perpendicular(arm)
            jacobian[:2, n] += d_force_dphi
            jacobian[2, n] += planar_cross(arm, d_force_dphi) + planar_cross(
                perpendicular(arm), equilibrium.force_on_platform
            )
        guesses[:] = new_guesses
        residual = _wrench_residual(platform, phi, equilibria, wrench, dof)
        columns = list(range(n)) + ([n] if free_rotation else [])
        cache["last"] = (equilibria, phi)
        return residual, jacobian[:dof][:, columns]

    def function(scaled):
        residual, jacobian = evaluate(scaled / unknown_scale)
        return residual / residual_scale, jacobian / residual_scale[:, None] / unknown_scale[None, :]

    # With a free rotation, a start where a cable hangs exactly vertical (H = 0
    # cannot parametrise it) or far from the answer is retried at other rotations.
    if initial_guess is not None:
        if not isinstance(initial_guess, PlatformEquilibrium) or len(initial_guess.cables) != n:
            raise SceneError(f"initial_guess must be a PlatformEquilibrium of this platform, got {shown(initial_guess)}")
        guessed = np.array([c.catenary.horizontal_tension for c in initial_guess.cables])
        if np.all(guessed > 0.0):
            horizontal = guessed

    def rotation_starts():
        if free_rotation and initial_guess is not None:
            yield initial_guess.rotation
        yield rotation
        if free_rotation:  # only computed when the plain start fails
            yield from _straight_cable_rotations(platform, position, wrench)
            yield from (0.05, -0.05, 0.3, -0.3)

    error = None
    for rotation_start in rotation_starts():
        guesses[:] = [None] * n
        start_tensions = horizontal
        if free_rotation and not (initial_guess is not None and rotation_start == initial_guess.rotation):
            start_tensions, tensions, _ = _ideal_tensions(platform, position, rotation_start, wrench, True)
            if np.any(tensions <= 0.0):
                start_tensions = np.maximum(start_tensions, 0.1 * max(platform.mass * platform.gravity, 1e-9))
        start = np.append(start_tensions, [rotation_start] if free_rotation else []) * unknown_scale
        try:
            scaled, _, _ = _damped_newton(
                function, start, _RELATIVE_TOLERANCE, positive=tuple(range(n)),
                what="inverse statics", noise=_platform_noise(platform, force_scale),
            )
            break
        except UnreachableError as caught:
            error = caught
    else:
        if _continuation and any(c.weight_per_length > 0.0 for c in platform.cables):
            try:
                return _inverse_by_weight_continuation(
                    platform, position, None if free_rotation else rotation, wrench,
                    max_strain, max_tension,
                )
            except UnreachableError:
                pass
        raise UnreachableError(
            f"no equilibrium with pulling cables at position ({position[0]:g}, {position[1]:g}) m"
            f" ({error})"
        ) from None
    evaluate(scaled / unknown_scale)
    equilibria, phi = cache["last"]
    # stiffness at fixed lengths: the forward cable derivatives at the solution
    stiffnesses = []
    for cable, equilibrium in zip(platform.cables, equilibria):
        guess = None
        if cable.pulley is not None:
            guess = (
                equilibrium.catenary.horizontal_tension,
                equilibrium.catenary.vertical_tension_b,
                _rim_angle(cable.pulley, equilibrium.upper_point),
            )
        _, stiffness, _ = forward_cable(
            cable, equilibrium.unstrained_length, equilibrium.anchor_point, guess, max_strain, max_tension
        )
        stiffnesses.append(stiffness)
    jacobian = _pose_jacobian(platform, phi, equilibria, stiffnesses, dof)
    pose = np.append(position, phi)
    return _result(platform, pose, equilibria, jacobian, wrench, dof)


_CONTINUATION_STEPS = (0.0, 0.1, 0.25, 0.45, 0.7, 1.0)


def _inverse_by_weight_continuation(platform, position, rotation, wrench, max_strain, max_tension):
    """Inverse statics by growing the cables' weight from zero, warm-starting each step.

    The last resort when every direct start fails: massless cables are solved
    reliably from the straight-cable guess, and each step's solution starts the next.
    Slow (a handful of solves), so only used on failure.
    """
    previous = None
    for fraction in _CONTINUATION_STEPS:
        cables = tuple(
            SuspendedCable(
                c.weight_per_length * fraction, c.axial_stiffness, c.anchor, c.exit_point, c.pulley
            )
            for c in platform.cables
        )
        scaled = SuspendedPlatform(cables, platform.mass, platform.gravity, platform.moment_of_inertia)
        previous = solve_inverse_statics(
            scaled if fraction < 1.0 else platform, position, rotation, wrench, max_strain,
            max_tension, initial_guess=previous, _continuation=False,
        )
    return previous


def _rim_angle(pulley, point):
    return math.atan2(point[1] - pulley.center[1], point[0] - pulley.center[0])
