"""Tension-only (slack) axial spring-dampers of lumped-mass cables: numba kernels.

A real cable cannot push, and a slack cable carries nothing at all. With
``Effects.slack`` the axial force of element e between nodes a and b is

    f = g(s) max(0, k s + c ds/dt),   s = l - l0,   l = |p_b - p_a|,

pulling the nodes together along u = (p_b - p_a) / l (:func:`tension_law`). The switch
g rises from 0 at the rest length to 1 at a strain of :data:`TAUT_BAND` as a C1
smoothstep: below the rest length there is no force at all (not even damping: a slack
element that is pulled straight again does not resist with its Kelvin-Voigt damper),
and Newton sees a force that is continuous with a continuous slope in the length when
a cable snaps taut. Exudyn's built-in spring-damper
has no tension-only option, so these elements join the bending springs in the one
``ObjectGenericODE2`` of the cables (:mod:`cdpr_exu.builder.cable`), with an analytic Jacobian.

No Exudyn here: coordinates are flat arrays (x0, y0, x1, y1, ...) [m, m/s].
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def _element_state(positions, velocities, a, b):
    dx = positions[2 * b] - positions[2 * a]
    dy = positions[2 * b + 1] - positions[2 * a + 1]
    dvx = velocities[2 * b] - velocities[2 * a]
    dvy = velocities[2 * b + 1] - velocities[2 * a + 1]
    length = np.sqrt(dx * dx + dy * dy)
    ux, uy = dx / length, dy / length
    rate = ux * dvx + uy * dvy
    return length, ux, uy, rate, dvx, dvy


#: Strain over which a tension-only element goes from slack (no force) to taut (the full
#: Kelvin-Voigt law); 1e-5 is a hundredth of the strain the paper's cable carries under
#: the platform's weight (about 1e-3), so it moves no taut force noticeably.
TAUT_BAND = 1e-5

#: Strain below which an element counts as lying *on* its rest length (round-off of node
#: coordinates of a few metres over elements of a few millimetres: about 1e-14 measured at
#: 240 elements per cable). There the law's one-sided slopes are 0 (slack) and the taut
#: (k, c); the Jacobian takes the taut ones (see :func:`_element_block`), the force stays 0.
ROUNDOFF_STRAIN = 1.0e-12


@njit(cache=True)
def tension_law(extension, rate, stiffness, damping, band):
    """Tension [N] of a tension-only element at extension s = l - l0 [m] and rate ds/dt [m/s], and its
    slopes in both [N/m, N s/m]; ``band`` [m] the extension over which it goes from slack to taut (C1
    smoothstep). Never negative; zero below the rest length.
    """
    if extension <= 0.0:
        return 0.0, 0.0, 0.0
    viscoelastic = stiffness * extension + damping * rate
    if viscoelastic <= 0.0:
        return 0.0, 0.0, 0.0
    if extension >= band:
        return viscoelastic, stiffness, damping
    x = extension / band
    switch = x * x * (3.0 - 2.0 * x)
    switch_slope = 6.0 * x * (1.0 - x) / band
    return switch * viscoelastic, switch_slope * viscoelastic + switch * stiffness, switch * damping


@njit(cache=True)
def newton_slopes(extension, rate, stiffness, damping, band, cut_slopes, kink=-1.0):
    """:func:`tension_law` as Newton's Jacobian sees it: (tension, slope in s, slope in ds/dt).

    Two places where the law's own slopes mislead Newton get the taut slopes (k, c) with a
    force of zero: an element within ``kink`` [m] of its rest length, on the law's kink
    (:func:`_element_block`; 0: exactly on it; negative, the default: no such rule), and,
    with ``cut_slopes``, an element stretched past the band whose damper cuts its force
    (k s + c ds/dt <= 0: it shortens faster than it relaxes; see :class:`CutSlopes` for why
    and when). Elsewhere the law's own slopes.
    """
    if abs(extension) <= kink:
        return 0.0, stiffness, damping
    force, k, c = tension_law(extension, rate, stiffness, damping, band)
    if cut_slopes and force == 0.0 and extension >= band:
        return 0.0, stiffness, damping
    return force, k, c


#: Force evaluations at one time (Newton's residuals of one attempt at a step) during which the
#: Jacobian gives damper-cut elements their taut slopes (:class:`CutSlopes`); after them, the
#: law's own. At 10 the 64-element spatial move under modified Newton still cut 13 of its 401
#: steps (a Jacobian built after the switch, and then reused, had the cut elements' zero
#: slopes); at 15 and 20 none.
CUT_SLOPE_ITERATIONS = 15


class CutSlopes:
    """When Newton's Jacobian gives a damper-cut tension-only element its taut slopes.

    In an implicit step a Newton update dq changes the velocities by gamma / (beta h) dq, so
    the damper of a Kelvin-Voigt cable sees a change some hundred times larger than the spring:
    an iterate that shortens a taut element by nanometres cuts its force to zero (k s + c ds/dt
    <= 0), and with the law's zero slopes the next Jacobian has no axial term for it (measured:
    18 to 70 iterations per step on the spatial four-cable move). A cut element that keeps its
    taut slopes (:func:`newton_slopes`) is pulled back by the next iterate. An element the
    converged state truly cuts then converges only linearly (the paper circle took 28 times the
    steps), so the rule holds for the first :data:`CUT_SLOPE_ITERATIONS` force evaluations of
    each attempt at a step (at one time ``t``); after them the Jacobian is the law's own. The
    force is never changed.
    """

    def __init__(self, iterations: int = CUT_SLOPE_ITERATIONS):
        self.iterations = int(iterations)
        self.time = None
        self.count = 0

    def force_evaluated(self, t: float) -> None:
        """Count one force evaluation at time ``t`` [s] (a new ``t``: a new attempt at a step)."""
        if t != self.time:
            self.time, self.count = t, 0
        self.count += 1

    @property
    def active(self) -> bool:
        """True while the current attempt at a step is within its first iterations."""
        return self.count <= self.iterations


@njit(cache=True)
def slack_axial_force(positions, velocities, elements, rest_length, stiffness, damping, out):
    """Add the tension-only axial forces to ``out`` (2N,) [N] and return it.

    ``positions``, ``velocities`` (2N,) [m, m/s]; ``elements`` (E, 2) node pairs; ``rest_length``,
    ``stiffness``, ``damping`` (E,) [m, N/m, N s/m]. ``out`` is accumulated into, not zeroed.
    """
    for e in range(elements.shape[0]):
        a, b = elements[e, 0], elements[e, 1]
        length, ux, uy, rate, _, _ = _element_state(positions, velocities, a, b)
        force, _, _ = tension_law(length - rest_length[e], rate, stiffness[e], damping[e],
                                  TAUT_BAND * rest_length[e])
        if force <= 0.0:
            continue
        out[2 * a] += force * ux
        out[2 * a + 1] += force * uy
        out[2 * b] -= force * ux
        out[2 * b + 1] -= force * uy
    return out


@njit(cache=True)
def _element_block(positions, velocities, a, b, rest_length, stiffness, damping, factor_position,
                   factor_velocity, block, kink_strain=0.0, cut_slopes=False):
    """The (b, b) block, shape (2, 2), of ``factor_position * K + factor_velocity * D`` of one
    element into ``block``; the (a, a) block is the same, (a, b) and (b, a) its negative.
    Returns False (block untouched) when the element carries no force (slack).

    With ``kink_strain`` > 0 (the run's first step only, :data:`ROUNDOFF_STRAIN`), an element
    within that strain of its rest length (every element of a cable placed straight at zero
    strain, at t = 0) sits on the law's kink: its block takes the taut slopes (k, c) and no
    geometric term, though it carries no force; with the slack side's zero slopes the first
    Newton iterate would move every node as a free mass. Later (``kink_strain`` = 0) only an
    element exactly on its rest length keeps the taut slopes: one passing *near* it with a
    taut Jacobian stalled Newton (measured on the held catenary scene).

    With ``cut_slopes`` a damper-cut element keeps its taut slopes (:func:`newton_slopes`).
    """
    length, ux, uy, rate, dvx, dvy = _element_state(positions, velocities, a, b)
    extension = length - rest_length
    force, k, c = newton_slopes(extension, rate, stiffness, damping, TAUT_BAND * rest_length, cut_slopes,
                                kink_strain * rest_length)
    if k == 0.0 and c == 0.0:
        return False
    u = (ux, uy)
    # d(rate)/d(p_b) = (dv - u rate) / l
    w = ((dvx - ux * rate) / length, (dvy - uy * rate) / length)
    for i in range(2):
        for j in range(2):
            projector = (1.0 if i == j else 0.0) - u[i] * u[j]
            g = u[i] * (k * u[j] + c * w[j]) + force * projector / length
            block[i, j] = factor_position * g + factor_velocity * c * u[i] * u[j]
    return True


@njit(cache=True)
def slack_axial_jacobian(positions, velocities, elements, rest_length, stiffness, damping,
                         factor_position, factor_velocity, out, kink_strain=0.0, cut_slopes=False):
    """Add ``factor_position * K + factor_velocity * D`` of the slack elements to ``out``.

    K = -df/dq and D = -df/dv (the left-hand-side Jacobians Exudyn expects), shape
    (2N, 2N); zero for an element whose force is not positive (slack). The element's
    stiffness and damping are the slopes of :func:`tension_law` in the extension and its rate
    (:func:`newton_slopes` with ``cut_slopes``).
    """
    block = np.empty((2, 2))
    for e in range(elements.shape[0]):
        a, b = elements[e, 0], elements[e, 1]
        if not _element_block(positions, velocities, a, b, rest_length[e], stiffness[e], damping[e],
                              factor_position, factor_velocity, block, kink_strain, cut_slopes):
            continue
        for i in range(2):
            for j in range(2):
                out[2 * b + i, 2 * b + j] += block[i, j]
                out[2 * a + i, 2 * a + j] += block[i, j]
                out[2 * a + i, 2 * b + j] -= block[i, j]
                out[2 * b + i, 2 * a + j] -= block[i, j]
    return out


@njit(cache=True)
def slack_triplet_pattern(elements):
    """Rows and columns of the slack elements' sparse Jacobian triplets: 16 per element, shape (16 E,) each.

    Per element the blocks (b, b), (a, a), (a, b) and (b, a), each 2 x 2, in that order.
    """
    n = elements.shape[0]
    rows = np.empty(16 * n, dtype=np.int64)
    columns = np.empty(16 * n, dtype=np.int64)
    for e in range(n):
        a, b = elements[e, 0], elements[e, 1]
        pairs = ((b, b), (a, a), (a, b), (b, a))
        for block in range(4):
            r, c = pairs[block]
            for i in range(2):
                for j in range(2):
                    rows[16 * e + 4 * block + 2 * i + j] = 2 * r + i
                    columns[16 * e + 4 * block + 2 * i + j] = 2 * c + j
    return rows, columns


@njit(cache=True)
def slack_triplet_values(positions, velocities, elements, rest_length, stiffness, damping,
                         factor_position, factor_velocity, out_values, kink_strain=0.0, cut_slopes=False):
    """Values of ``factor_position * K + factor_velocity * D`` of the slack elements at
    :func:`slack_triplet_pattern`'s places (overwrites ``out_values``, shape (16 E,))."""
    out_values[:] = 0.0
    block = np.empty((2, 2))
    for e in range(elements.shape[0]):
        if not _element_block(positions, velocities, elements[e, 0], elements[e, 1], rest_length[e], stiffness[e],
                              damping[e], factor_position, factor_velocity, block, kink_strain, cut_slopes):
            continue
        for i in range(2):
            for j in range(2):
                base = 16 * e + 2 * i + j
                out_values[base] = out_values[base + 4] = block[i, j]
                out_values[base + 8] = out_values[base + 12] = -block[i, j]
    return out_values


def cable_elements(nodes_per_cable) -> np.ndarray:
    """Element node pairs (a, b), shape (E, 2), for cables whose nodes are numbered one after another."""
    pairs, start = [], 0
    for count in nodes_per_cable:
        pairs.extend((start + j, start + j + 1) for j in range(count - 1))
        start += count
    return np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
