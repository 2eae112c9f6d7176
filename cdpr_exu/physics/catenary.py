"""The elastic catenary: a suspended cable with weight and axial elasticity, no bending.

Irvine's model (1981), as used for cable robots by Kozak, Zhou and Wang (2006): a cable of
unstrained length ``L`` [m], weight per unstrained length ``w`` [N/m] and axial stiffness ``EA`` [N],
linear elastic (Hooke's law on the unstrained arc length), hanging between its ends A and B in the
vertical x-z plane, gravity along -z; no ground contact.

Conventions
-----------
Arc length ``s`` is unstrained, from A (s = 0) to B (s = L). The tension vector, pointing towards
B, is ``(H, V(s))``, ``V(s) = V_A + w s``: ``H >= 0`` the horizontal tension (constant) and ``V_B``
the upward force of the support at B on the cable. For a span ``(dx, dz) = p_B - p_A``, ``dx > 0``
(Irvine's eqs.; `paper-params.md`)::

    dx = H/w [asinh(V_B/H) - asinh(V_A/H)] + H L / EA
    dz = H/w [sqrt(1 + (V_B/H)^2) - sqrt(1 + (V_A/H)^2)] + (V_B L - w L^2 / 2) / EA

Spans with ``dx < 0`` are solved mirrored (x -> -x); ``dx == 0`` is the vertical limit ``H = 0`` (a
straight hanging cable, or, slack, folded into a zero-width U), solved in closed form.

Numerics
--------
The textbook form divides by ``w`` and by ``H``; the inextensible terms and the analytic Jacobian
``d(dx, dz)/d(H, V_B)`` are rewritten without either division (`_span_and_jacobian`), so the
massless limit ``w -> 0`` (a straight linear spring) is reached without cancellation and ``w = 0``
is solved in closed form.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from cdpr_exu.core.errors import SceneError, UnreachableError
from cdpr_exu.core.validation import finite, non_negative, positive, real_array, shown, vector

STANDARD_GRAVITY = 9.81
"""Default gravitational acceleration [m/s^2]."""

DEFAULT_MAX_STRAIN = 0.1
"""Largest strain ``T / EA`` before a span counts as unreachable (an elastic cable reaches any span by
stretching; steel yields near 0.5 %). ``max_strain`` or ``max_tension`` give a tighter, physical limit."""

_RELATIVE_TOLERANCE = 1e-12
_VERTICAL_TOLERANCE = 1e-12
_MAX_NEWTON_ITERATIONS = 200


def tension_limit(axial_stiffness, max_strain=DEFAULT_MAX_STRAIN, max_tension=None):
    """Largest admissible tension [N] of a cable of ``EA`` [N]: ``max_strain EA``, or ``max_tension`` [N]."""
    max_strain = positive("max_strain", max_strain)
    limit = max_strain * axial_stiffness
    if max_tension is not None:
        limit = min(limit, positive("max_tension", max_tension))
    return limit


@dataclass(frozen=True)
class CatenaryCable:
    """A suspended elastic cable: unstrained length ``L > 0`` [m], weight per unstrained length ``w >= 0``
    [N/m] (0: the massless, straight linear spring) and axial stiffness ``EA > 0`` [N]; SceneError for a
    value that is not finite or out of range."""

    unstrained_length: float
    weight_per_length: float
    axial_stiffness: float

    def __post_init__(self):
        for name, check in (("unstrained_length", positive), ("weight_per_length", non_negative),
                            ("axial_stiffness", positive)):
            object.__setattr__(self, name, check(name, getattr(self, name)))


@dataclass(frozen=True, eq=False)
class CatenaryState:
    """A solved elastic catenary.

    Attributes
    ----------
    horizontal_tension : float [N]
        ``H >= 0``, constant along the cable.
    vertical_tension_a, vertical_tension_b : float [N]
        ``V_A`` and ``V_B = V_A + w L``, the tension vector's (A towards B) vertical component at A and B:
        ``V_B`` is the upward force of the support at B on the cable, ``-V_A`` the one at A.
    force_on_a, force_on_b : ndarray, shape (2,) [N]
        Forces (x, z) of the cable on its supports at A and B; their sum is its weight ``(0, -w L)``.
    tension_a, tension_b : float [N]
        Tensions at the ends, the largest along the cable at one of them.
    unstrained_length, stretched_length : float [m]
        The latter the arc length of the loaded cable.
    span : ndarray, shape (2,) [m]
        ``p_B - p_A``.
    """

    horizontal_tension: float
    vertical_tension_a: float
    vertical_tension_b: float
    force_on_a: np.ndarray = field(repr=False)
    force_on_b: np.ndarray = field(repr=False)
    tension_a: float
    tension_b: float
    unstrained_length: float
    stretched_length: float
    span: np.ndarray

    @property
    def max_tension(self):
        """Largest tension along the cable [N] (at one of its ends)."""
        return max(self.tension_a, self.tension_b)

    @property
    def horizontal_sign(self):
        """+1 when B lies right of A or above it (``dx >= 0``), -1 when left."""
        return -1.0 if self.span[0] < 0.0 else 1.0


def _log1p_ratio(y):
    """``log(1 + y) / y``, 1 at ``y = 0``, 0 at ``y = inf``."""
    if y == 0.0:
        return 1.0
    if math.isinf(y):
        return 0.0
    return math.log1p(y) / y


def _atan_ratio(z):
    """``atan(z) / z``, 1 at ``z = 0``."""
    return 1.0 if z == 0.0 else math.atan(z) / z


def _sin_ratio(u):
    """``sin(u) / u``, 1 at ``u = 0``."""
    return 1.0 if u == 0.0 else math.sin(u) / u


def _span_and_jacobian(H, V_B, L, w, EA, with_jacobian=True):
    """Span (mirrored so that dx >= 0) of a catenary and its Jacobian in (H, V_B).

    Valid for ``H >= 0``, ``w >= 0``, ``L >= 0``, any ``V_B``. Returns
    ``(dx, dz, jacobian)`` with ``jacobian = d(dx, dz)/d(H, V_B)`` (2x2 list of
    lists, or None); ``jacobian[0][0]`` is ``inf`` for the vertical slack U (H = 0).

    Derivation notes. With ``T = hypot(H, V)``, ``asinh`` odd, and flipping
    ``(V_A, V_B) -> (-V_B, -V_A)`` when ``V_A + V_B < 0`` (this leaves dx unchanged),
    call the flipped values ``b <= a`` with ``a + b >= 0``. Then::

        asinh(a/H) - asinh(b/H) = log1p(y),   y = w L q c,
        q = 1 + (a + b)/(T_a + T_b) in [1, 2],  c = (T_b - b)/H^2 = 1/(T_b + b) if b > 0

    so ``dx_inext = (H/w) log1p(y) = H L q c log1p(y)/y``. Also
    ``sqrt(H^2 + V_B^2) - sqrt(H^2 + V_A^2) = w L (V_A + V_B)/(T_A + T_B)``, so
    ``dz_inext = L (V_A + V_B)/(T_A + T_B)``. In the Jacobian,
    ``(V_B/T_B - V_A/T_A)/w = 2 cos(mean angle) sin(dtheta/2)/w`` with
    ``dtheta = atan2(H w L, H^2 + V_A V_B)`` the turning of the cable, evaluated
    through ``atan(z)/z`` and ``sin(u)/u``.
    """
    V_A = V_B - w * L
    T_A = math.hypot(H, V_A)
    T_B = math.hypot(H, V_B)
    sum_V = V_A + V_B
    sum_T = T_A + T_B
    if sum_T == 0.0:  # massless cable at zero tension: straight, direction undefined
        direction_ratio = 0.0
    else:
        direction_ratio = sum_V / sum_T  # mean sine of the cable angle, in [-1, 1]

    # flipped values: b <= a, a + b >= 0
    if sum_V < 0.0:
        a, b, T_b = -V_A, -V_B, T_B
    else:
        a, b, T_b = V_B, V_A, T_A
    q = 1.0 + abs(direction_ratio)
    if b > 0.0:
        c = 1.0 / (T_b + b)
    elif H > 0.0:
        c = (T_b - b) / H / H  # (not H * H: that underflows first)
    else:
        c = math.inf  # vertical U: the cable folds over at H = 0
    if math.isinf(c):
        dx_over_H = math.inf
        dx_inextensible = 0.0
    else:
        y = w * L * q * c
        dx_over_H = L * q * c * _log1p_ratio(y)
        dx_inextensible = H * dx_over_H
    dz_inextensible = L * direction_ratio

    dx = dx_inextensible + H * L / EA
    dz = dz_inextensible + L * sum_V / (2.0 * EA)
    if not with_jacobian:
        return dx, dz, None

    # d(dz_inext)/d(V_B) = (V_B/T_B - V_A/T_A)/w
    D = H * H + V_A * V_B
    if D > 0.0:
        turning_over_w = H * L / D * _atan_ratio(H * w * L / D)
    elif w > 0.0:
        turning_over_w = math.atan2(H * w * L, D) / w
    else:
        turning_over_w = 0.0  # w = 0 and H = V = 0: zero tension everywhere
    turning = turning_over_w * w
    mean_angle = 0.5 * (math.atan2(V_A, H) + math.atan2(V_B, H))
    ddz_inext_dV = math.cos(mean_angle) * turning_over_w * _sin_ratio(0.5 * turning)

    if T_A * T_B * sum_T > 0.0:
        cross = -H * L * sum_V / (T_A * T_B * sum_T)
    else:
        cross = 0.0
    return dx, dz, [[dx_over_H - ddz_inext_dV + L / EA, cross], [cross, ddz_inext_dV + L / EA]]


def _tension_integral(H, V_B, L, w):
    """``integral of T ds`` over the unstrained length [N m], cancellation-free.

    ``int T ds = (V_B T_B - V_A T_A)/(2 w) + H dx_inext / 2``; the first term is
    rewritten as ``L (V_A+V_B)(H^2+V_A^2+V_B^2) / (2 (V_B T_B + V_A T_A))`` when V_A
    and V_B have the same sign (where it would cancel).
    """
    V_A = V_B - w * L
    T_A = math.hypot(H, V_A)
    T_B = math.hypot(H, V_B)
    if V_A + V_B < 0.0:
        a, b, T_a, T_b = -V_A, -V_B, T_A, T_B
    else:
        a, b, T_a, T_b = V_B, V_A, T_B, T_A
    if b >= 0.0:
        denominator = a * T_a + b * T_b
        if denominator > 0.0:
            vt_over_w = L * (a + b) * (H * H + a * a + b * b) / denominator
        else:
            vt_over_w = L * H  # a = b = 0 (w = 0, horizontal cable)
    else:
        vt_over_w = (a * T_a - b * T_b) / w
    dx_inextensible, _, _ = _span_and_jacobian(H, V_B, L, w, math.inf, with_jacobian=False)
    return 0.5 * vt_over_w + 0.5 * H * dx_inextensible


def _make_state(cable, H, V_B, sign_x, slack_span=None):
    """State from ``(H, V_B)``; ``slack_span`` is the span of a slack massless cable."""
    L, w, EA = cable.unstrained_length, cable.weight_per_length, cable.axial_stiffness
    if slack_span is None:
        dx, dz, _ = _span_and_jacobian(H, V_B, L, w, EA, with_jacobian=False)
        stretched = L + _tension_integral(H, V_B, L, w) / EA
    else:  # no tension: the cable lies in some unknown shape between its ends
        dx, dz = abs(float(slack_span[0])), float(slack_span[1])
        stretched = L
    V_A = V_B - w * L
    return CatenaryState(horizontal_tension=H, vertical_tension_a=V_A, vertical_tension_b=V_B,
                         force_on_a=np.array([sign_x * H, V_A]), force_on_b=np.array([-sign_x * H, -V_B]),
                         tension_a=math.hypot(H, V_A), tension_b=math.hypot(H, V_B), unstrained_length=L,
                         stretched_length=stretched, span=np.array([sign_x * dx, dz]))


def state_from_end_forces(cable, horizontal_tension, vertical_tension_b, horizontal_sign=1.0):
    """The :class:`CatenaryState` a given end force produces (the span in closed form): ``H >= 0`` [N],
    ``V_B`` [N], ``horizontal_sign`` +1 for B right of A (``dx >= 0``), -1 for B left of it."""
    H = non_negative("horizontal_tension", horizontal_tension)
    V_B = finite("vertical_tension_b", vertical_tension_b)
    if horizontal_sign not in (1, -1, 1.0, -1.0):
        raise SceneError(f"horizontal_sign must be +1 or -1, got {shown(horizontal_sign)}")
    return _make_state(cable, H, V_B, float(horizontal_sign))


def _vertical_solution(L, w, EA, dz):
    """``V_B`` of a vertical cable (H = 0) with span ``(0, dz)``, in closed form: taut with B above A
    (``V_A >= 0``), taut with B below A (``V_B <= 0``), or slack and folded into a zero-width U
    (``V_A < 0 < V_B``, only for ``w > 0``), each linear in ``V_B``."""
    V_A = (dz - L) * EA / L - 0.5 * w * L
    if V_A >= 0.0:
        return V_A + w * L
    V_B = (dz + L) * EA / L + 0.5 * w * L
    if V_B <= 0.0:
        return V_B
    if w == 0.0:
        return 0.0  # slack massless cable: no tension
    return (dz + L + w * L * L / (2.0 * EA)) / (2.0 / w + L / EA)


def _initial_guess(L, w, EA, dx, dz):
    """Starting ``(H, V_B)`` for Newton (dx > 0, w > 0). Taut spans (chord >= L): the straight elastic spring
    plus half the weight at each end, or MoorPy's taut guess ``lambda = 0.2`` if larger. Slack spans: the
    parabolic estimate of Peyrot and Goulois (FAST, MoorPy): ``lambda = sqrt(3 ((L^2 - dz^2)/dx^2 - 1))``,
    ``H = w dx / (2 lambda)``, ``V_B = w/2 (dz / tanh(lambda) + L)``."""
    chord = math.hypot(dx, dz)
    if chord >= L:
        spring_tension = EA * (chord - L) / L
        H = max(spring_tension * dx / chord, w * dx / (2.0 * 0.2))
        return H, H * dz / dx + 0.5 * w * L
    ratio = (L * L - dz * dz) / (dx * dx) - 1.0
    lam = math.sqrt(3.0 * ratio) if ratio > 0.0 else 0.2
    lam = min(max(lam, 1e-3), 1e6)
    H = max(w * dx / (2.0 * lam), 1e-12 * w * L)
    return H, 0.5 * w * (dz / math.tanh(lam) + L)


def _damped_newton_2d(residual, x, y, tolerance, max_drop=None):
    """Damped Newton on two unknowns, ``residual(x, y) -> (rx, rz, jacobian)``, ``x`` kept positive: the step,
    scaled as a whole so that ``x`` drops by at most the fraction ``max_drop``, halved until the residual norm
    decreases (Armijo). Returns ``(x, y, norm)`` at convergence or where the iteration stalls."""
    rx, rz, jac = residual(x, y)
    norm = math.hypot(rx, rz)
    for _ in range(_MAX_NEWTON_ITERATIONS):
        if norm <= tolerance:
            break
        (a11, a12), (a21, a22) = jac
        det = a11 * a22 - a12 * a21
        if not math.isfinite(det) or det == 0.0:
            break
        step_x = -(a22 * rx - a12 * rz) / det
        step_y = -(-a21 * rx + a11 * rz) / det
        alpha = 1.0
        if max_drop is not None and step_x < -max_drop * x:
            alpha = max_drop * x / -step_x
        accepted = False
        for _ in range(60):
            x_new = x + alpha * step_x
            y_new = y + alpha * step_y
            if x_new > 0.0:
                rx_new, rz_new, jac_new = residual(x_new, y_new)
                norm_new = math.hypot(rx_new, rz_new)
                if norm_new < (1.0 - 1e-4 * alpha) * norm or norm_new <= tolerance:
                    accepted = True
                    break
            alpha *= 0.5
        if not accepted:
            break
        x, y, rx, rz, jac, norm = x_new, y_new, rx_new, rz_new, jac_new, norm_new
    return x, y, norm


def _newton_forward(L, w, EA, dx, dz, H, V_B):
    """:func:`_damped_newton_2d` in ``(H, V_B)``, ``H`` dropping by at most 90 % (the step keeps its
    direction: near-taut cables have a narrow valley along the cable that a change of variables such as ``log
    H`` would leave); returns ``(H, V_B, converged)``."""
    scale = max(L, math.hypot(dx, dz))
    tolerance = _RELATIVE_TOLERANCE * scale

    def residual(H_, V_):
        rx, rz, jac = _span_and_jacobian(H_, V_, L, w, EA)
        return rx - dx, rz - dz, jac

    H, V_B, norm = _damped_newton_2d(residual, H, V_B, tolerance, max_drop=0.9)
    return H, V_B, norm <= 10.0 * tolerance  # stalled at round-off level counts


def _bracket_root(function, low, high, grow):
    """Expand ``[low, high]`` (by ``grow(low, high)``) until ``function`` changes sign."""
    f_low, f_high = function(low), function(high)
    for _ in range(2000):
        if f_low <= 0.0 <= f_high:
            return low, high
        low, high = grow(low, high, f_low > 0.0)
        f_low, f_high = function(low), function(high)
    raise UnreachableError("could not bracket the catenary solution")


def _nested_forward(L, w, EA, dx, dz, H_start):
    """Globally convergent fallback, for the singular corner of a vertical just-taut cable whose lower end is
    at zero tension: nested Brent solves in ``log H`` and ``V_B``. ``dz`` grows strictly with ``V_B`` at fixed
    ``H`` (``J22 > 0``), and along a curve of fixed ``dz``, ``dx`` with ``H`` (``det J / J22 > 0``, the
    flexibility being positive definite), so they always find the solution."""
    from scipy.optimize import brentq

    weight = max(w * L, 1e-300)

    def vertical_force(H):
        def mismatch(V):
            return _span_and_jacobian(H, V, L, w, EA, with_jacobian=False)[1] - dz

        def grow(low, high, too_high):
            width = high - low
            return (low - 2.0 * width, high) if too_high else (low, high + 2.0 * width)

        low, high = _bracket_root(mismatch, -weight, 2.0 * weight, grow)
        return brentq(mismatch, low, high, xtol=1e-300, rtol=1e-15, maxiter=400)

    def horizontal_mismatch(log_H):
        H = math.exp(log_H)
        return _span_and_jacobian(H, vertical_force(H), L, w, EA, with_jacobian=False)[0] - dx

    def grow(low, high, too_high):
        return (low - 5.0, high) if too_high else (low, high + 5.0)

    centre = math.log(H_start)
    low, high = _bracket_root(horizontal_mismatch, centre - 1.0, centre + 1.0, grow)
    log_H = brentq(horizontal_mismatch, low, high, xtol=1e-15, rtol=1e-15, maxiter=400)
    H = math.exp(log_H)
    return H, vertical_force(H)


def _solve_span(L, w, EA, dx, dz, guess):
    """``(H, V_B)`` for a span with ``dx > 0``: Newton, then the bracketing fallback."""
    default = _initial_guess(L, w, EA, dx, dz)
    starts = [default] if guess is None else [guess, default]
    best = None
    for H0, V0 in starts:
        H, V_B, converged = _newton_forward(L, w, EA, dx, dz, H0, V0)
        if converged:
            return H, V_B
        best = (H, V_B)
    H, V_B = _nested_forward(L, w, EA, dx, dz, max(best[0], default[0], 1e-300))
    H_polished, V_polished, converged = _newton_forward(L, w, EA, dx, dz, H, V_B)
    if converged:
        return H_polished, V_polished
    rx, rz, _ = _span_and_jacobian(H, V_B, L, w, EA, with_jacobian=False)
    residual = math.hypot(rx - dx, rz - dz)
    if residual <= 1e3 * _RELATIVE_TOLERANCE * max(L, math.hypot(dx, dz)):
        return H, V_B
    raise UnreachableError(f"elastic catenary did not converge for span ({dx:g}, {dz:g}) m and "
                           f"unstrained_length {L:g} m (residual {residual:.3g} m)")


def solve_forward(cable, span, initial_guess=None, max_strain=DEFAULT_MAX_STRAIN, max_tension=None):
    """The :class:`CatenaryState` of a cable hung across ``span`` (2,) [m] (``p_B - p_A``, any signs).

    Newton's method on Irvine's equations in ``(H, V_B)`` (steps keep ``H`` positive, backtracking), from
    ``initial_guess`` (``(H, V_B)`` [N] where ``dx >= 0``, eg the previous solution along a path) or the
    Peyrot-Goulois / MoorPy guess; should it stall (a just-taut, nearly vertical cable whose lower end is at
    zero tension), a nested bracketing solve, which always converges. Vertical spans (``|dx| <= 1e-12 L``)
    and massless cables in closed form. ``max_strain`` and ``max_tension`` [N]: :func:`tension_limit`.

    Raises UnreachableError if the chord exceeds the cable's reach at the tension limit or the solution
    the limit; SceneError if ``span`` is not a finite 2-vector or a limit is not positive.
    """
    span = vector("span", span, 2, " (dx, dz) [m]")
    if not isinstance(cable, CatenaryCable):
        raise SceneError(f"cable must be a CatenaryCable, got {shown(cable)}")
    L, w, EA = cable.unstrained_length, cable.weight_per_length, cable.axial_stiffness
    limit = tension_limit(EA, max_strain, max_tension)
    sign_x = -1.0 if span[0] < 0.0 else 1.0
    dx, dz = abs(float(span[0])), float(span[1])
    chord = math.hypot(dx, dz)
    reach = L * (1.0 + limit / EA)  # stretched length <= reach, chord <= it
    if chord > reach:
        raise UnreachableError(f"span ({span[0]:g}, {span[1]:g}) m is {chord:g} m long, beyond the reach "
                               f"{reach:g} m of unstrained_length {L:g} m at tension limit {limit:g} N")

    slack_span = None
    if w == 0.0:  # massless: straight linear spring, or slack (no force)
        tension = EA * (chord - L) / L if chord > L else 0.0
        H = tension * dx / chord if chord > 0.0 else 0.0
        V_B = tension * dz / chord if chord > 0.0 else 0.0
        if tension == 0.0:
            slack_span = span
    elif dx <= _VERTICAL_TOLERANCE * max(L, chord):
        # vertical: closed form (for dx below 1e-12 of the length the difference from
        # the true catenary is below the solver tolerance, and Newton is ill-posed)
        H, V_B = 0.0, _vertical_solution(L, w, EA, dz)
    else:
        guess = None
        if initial_guess is not None:
            H0, V0 = real_array("initial_guess", initial_guess).reshape(2)
            if H0 > 0.0 and math.isfinite(H0) and math.isfinite(V0):
                guess = (H0, V0)
        H, V_B = _solve_span(L, w, EA, dx, dz, guess)

    state = _make_state(cable, H, V_B, sign_x, slack_span)
    if state.max_tension > limit:
        raise UnreachableError(f"span ({span[0]:g}, {span[1]:g}) m with unstrained_length {L:g} m needs "
                               f"tension {state.max_tension:g} N, above the limit {limit:g} N")
    return state


def _inextensible_length(w, H, dx, dz):
    """Inextensible catenary through the span with horizontal tension H: (L, V_B).

    ``dx = (H/w)(u_B - u_A)``, ``dz = (H/w)(cosh u_B - cosh u_A)`` with
    ``u = asinh(V/H)`` give ``u_B - u_A = delta = w dx / H`` and the mean
    ``mu = asinh(dz/dx * (delta/2)/sinh(delta/2))``;
    ``L = dx cosh(mu) sinh(delta/2)/(delta/2)``. Safe as ``w -> 0``.
    """
    half = 0.5 * w * dx / H
    shape = 1.0 if half == 0.0 else math.sinh(half) / half
    mu = math.asinh(dz / dx / shape)
    L = dx * math.cosh(mu) * shape
    V_B = H * math.sinh(mu + half)
    return L, V_B


def solve_inverse(span, weight_per_length, axial_stiffness, horizontal_tension, max_strain=DEFAULT_MAX_STRAIN,
                  max_tension=None):
    """Unstrained length [m] and :class:`CatenaryState` of the cable (``w >= 0`` [N/m], ``EA > 0`` [N]) that
    hangs across ``span`` (2,) [m] (``dx != 0``: a vertical cable has ``H = 0``) with horizontal tension
    ``H > 0`` [N]: the closed-form inextensible catenary, corrected for the stretch by Newton's method in
    ``(L, V_B)``. The tension limit as in :func:`solve_forward`.

    Raises UnreachableError for a vertical span, a tension above the limit or a failed Newton;
    SceneError for an invalid argument.
    """
    span = vector("span", span, 2, " (dx, dz) [m]")
    w = non_negative("weight_per_length", weight_per_length)
    EA = positive("axial_stiffness", axial_stiffness)
    H = positive("horizontal_tension", horizontal_tension)
    limit = tension_limit(EA, max_strain, max_tension)
    sign_x = -1.0 if span[0] < 0.0 else 1.0
    dx, dz = abs(float(span[0])), float(span[1])
    if dx == 0.0:
        raise UnreachableError(f"span ({span[0]:g}, {span[1]:g}) m is vertical: no cable hangs across it "
                               f"with horizontal_tension {H:g} N > 0")
    chord = math.hypot(dx, dz)

    if w == 0.0:
        tension = H * chord / dx
        L = chord / (1.0 + tension / EA)
        V_B = tension * dz / chord
    else:
        try:
            L_inext, V_B = _inextensible_length(w, H, dx, dz)
        except OverflowError:
            raise UnreachableError(f"span ({span[0]:g}, {span[1]:g}) m: horizontal_tension {H:g} N is too "
                                   f"small for weight_per_length {w:g} N/m (the cable would be "
                                   "astronomically long)") from None
        mean_tension = 0.5 * (math.hypot(H, V_B) + math.hypot(H, V_B - w * L_inext))
        L = L_inext / (1.0 + mean_tension / EA)
        V_B = V_B - 0.5 * w * (L_inext - L)  # keep the low point roughly in place
        L, V_B = _newton_inverse(w, EA, H, dx, dz, L, V_B)

    cable = CatenaryCable(L, w, EA)
    state = _make_state(cable, H, V_B, sign_x)
    if state.max_tension > limit:
        raise UnreachableError(f"span ({span[0]:g}, {span[1]:g}) m with horizontal_tension {H:g} N needs "
                               f"tension {state.max_tension:g} N, above the limit {limit:g} N")
    return L, state


def _newton_inverse(w, EA, H, dx, dz, L, V_B):
    """Damped Newton in ``(L, V_B)`` at fixed ``H``; returns ``(L, V_B)``."""
    scale = max(L, math.hypot(dx, dz))
    tolerance = _RELATIVE_TOLERANCE * scale

    def evaluate(L_, V_):
        rx, rz, jac = _span_and_jacobian(H, V_, L_, w, EA)
        V_A = V_ - w * L_
        T_A = math.hypot(H, V_A)
        # d span / d L at fixed (H, V_B): the piece added at A, along the cable at A
        dL = (H / T_A + H / EA, V_A / T_A + V_A / EA)
        return rx - dx, rz - dz, ((dL[0], jac[0][1]), (dL[1], jac[1][1]))

    L, V_B, norm = _damped_newton_2d(evaluate, L, V_B, tolerance)
    if norm <= 1e3 * tolerance:
        return L, V_B
    raise UnreachableError(f"inverse elastic catenary did not converge for span ({dx:g}, {dz:g}) m and "
                           f"horizontal_tension {H:g} N (residual {norm:.3g} m)")


def profile(cable, state, s):
    """Points ``(x, z)`` (n, 2) [m] relative to A of the loaded cable (``state`` a solution of ``cable``) at
    unstrained arc lengths ``s`` (n,) [m] from A: the span formula with ``L`` replaced by ``s`` and ``V_B``
    by ``V(s) = V_A + w s``. SceneError for an ``s`` outside ``[0, L]`` (beyond round-off)."""
    L, w, EA = cable.unstrained_length, cable.weight_per_length, cable.axial_stiffness
    s = np.atleast_1d(real_array("s", s))
    if s.ndim != 1 or not np.all(np.isfinite(s)):
        raise SceneError(f"s must be a finite 1-D array of arc lengths [m], got shape {s.shape}")
    slack = 1e-12 * L
    if np.any(s < -slack) or np.any(s > L + slack):
        raise SceneError(f"s must lie in [0, unstrained_length = {L:g}] m, got [{s.min():g}, {s.max():g}]")
    s = np.clip(s, 0.0, L)
    H, V_A = state.horizontal_tension, state.vertical_tension_a
    points = np.empty((s.size, 2))
    for k, s_k in enumerate(s):
        x, z, _ = _span_and_jacobian(H, V_A + w * s_k, s_k, w, EA, with_jacobian=False)
        points[k] = (state.horizontal_sign * x, z)
    return points


def span_and_jacobian(cable, horizontal_tension, vertical_tension_b, horizontal_sign=1.0):
    """Span ``p_B - p_A`` (2,) [m] of the catenary from its end force (as :func:`state_from_end_forces`), and
    ``d(span)/d(H, V_B, L)`` (2, 3) [m/N, m/N, -].

    The last column adds unstrained length at end A with ``(H, V_B)`` fixed: the new piece continues
    the cable along its direction at A. Entry ``[0, 0]`` is ``inf`` for a slack vertical cable (a U
    of zero width: no horizontal stiffness).
    """
    if not isinstance(cable, CatenaryCable):
        raise SceneError(f"cable must be a CatenaryCable, got {shown(cable)}")
    H, V_B = positive("horizontal_tension", horizontal_tension), finite("vertical_tension_b", vertical_tension_b)
    L, w, EA = cable.unstrained_length, cable.weight_per_length, cable.axial_stiffness
    sign = -1.0 if horizontal_sign < 0 else 1.0
    dx, dz, jac = _span_and_jacobian(H, V_B, L, w, EA)
    V_A = V_B - w * L
    T_A = math.hypot(H, V_A)
    if T_A > 0.0:
        length_column = (H / T_A + H / EA, V_A / T_A + V_A / EA)
    else:
        length_column = (0.0, 0.0)
    span = np.array([sign * dx, dz])
    jacobian = np.array([[sign * jac[0][0], sign * jac[0][1], sign * length_column[0]],
                         [jac[1][0], jac[1][1], length_column[1]]])
    return span, jacobian


def end_stiffness(cable, state):
    """``d(force on B)/d(p_B)`` at fixed A, which also equals ``d(force on A)/d(p_A)``.

    The force the cable exerts on a support is ``S (H, V_B)`` up to a constant, with
    ``S = diag(-sign_x, -1)`` at B; the span moves with ``p_B``, so
    ``d(force on B)/d(p_B) = -S' J^-1 S'`` with ``S' = diag(sign_x, 1)`` and
    ``J = d(dx_mirrored, dz)/d(H, V_B)``. The matrix is symmetric and negative
    (semi-)definite: ``K = -end_stiffness`` is the usual positive tangent stiffness. Shape (2, 2) [N/m].
    """
    w = cable.weight_per_length
    H, V_B = state.horizontal_tension, state.vertical_tension_b
    L, EA = cable.unstrained_length, cable.axial_stiffness
    sign = state.horizontal_sign
    if w == 0.0:  # straight spring: axial EA/L plus geometric T/l across
        chord = float(np.hypot(*state.span))
        tension = state.tension_a
        if chord == 0.0 or (tension == 0.0 and chord < L):
            return np.zeros((2, 2))
        unit = state.span / chord
        axial = EA / L if chord >= L else 0.0
        stiffness = axial * np.outer(unit, unit) + tension / chord * (np.eye(2) - np.outer(unit, unit))
        return -stiffness
    _, _, jac = _span_and_jacobian(H, V_B, L, w, EA)
    if math.isinf(jac[0][0]):  # slack vertical U: no horizontal stiffness
        inverse = np.array([[0.0, 0.0], [0.0, 1.0 / jac[1][1]]])
    else:
        inverse = np.linalg.inv(np.array(jac))
    mirror = np.diag([sign, 1.0])
    return -mirror @ inverse @ mirror

