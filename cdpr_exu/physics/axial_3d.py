"""Tension-only (slack) axial spring-dampers of spatial lumped-mass cables: numba kernels.

The spatial counterpart of :mod:`cdpr_exu.physics.axial`, with its law
(:func:`cdpr_exu.physics.axial.tension_law`) on s = l - l0 and ds/dt = u . (v_b - v_a) - dl0/dt,
u = (p_b - p_a) / l. Above the band a taut element is exactly Exudyn's
``ObjectConnectorSpringDamper``, its ``velocityOffset`` the rest length's rate ``rest_rate``
(nonzero while a winch pays the cable out: the damper acts on the strain rate).

The Jacobian ``f_q K + f_q_t D`` (K = -df/dq, D = -df/dv) goes to Exudyn as sparse triplets,
one 6 x 6 block per element on (p_a, p_b). With G the (b, b) block,

    G_ij = f_q [u_i (k' u_j + c' w_j) + T (delta_ij - u_i u_j) / l] + f_q_t c' u_i u_j,
    w = (dv - u ds/dt) / l = d(ds/dt)/dp_b,

(k', c' the slopes of the law in s and ds/dt) the block is [[G, -G], [-G, G]]; it is
zero for a slack element.

No Exudyn here: coordinates are flat arrays (x0, y0, z0, x1, ...) [m, m/s].
"""

from __future__ import annotations

import numpy as np
from numba import njit

from cdpr_exu.physics.axial import TAUT_BAND, newton_slopes, tension_law

@njit(cache=True)
def _element_state(positions, velocities, a, b, u, dv):
    """Length [m] and length rate [m/s] of element (a, b); its unit vector into ``u`` (3,)
    and the relative velocity v_b - v_a into ``dv`` (3,)."""
    length2 = 0.0
    for k in range(3):
        d = positions[3 * b + k] - positions[3 * a + k]
        u[k] = d
        dv[k] = velocities[3 * b + k] - velocities[3 * a + k]
        length2 += d * d
    length = np.sqrt(length2)
    rate = 0.0
    for k in range(3):
        u[k] /= length
        rate += u[k] * dv[k]
    return length, rate


@njit(cache=True)
def tension_only_tensions(positions, velocities, elements, rest_length, stiffness, damping, rest_rate, out):
    """Tension [N] of each element (E,) into ``out`` (never negative; 0 when slack)."""
    u = np.empty(3)
    dv = np.empty(3)
    for e in range(elements.shape[0]):
        length, rate = _element_state(positions, velocities, elements[e, 0], elements[e, 1], u, dv)
        out[e], _, _ = tension_law(length - rest_length[e], rate - rest_rate[e], stiffness[e], damping[e],
                                   TAUT_BAND * rest_length[e])
    return out


@njit(cache=True)
def tension_only_force(positions, velocities, elements, rest_length, stiffness, damping, rest_rate, out):
    """Add the tension-only axial forces [N] to ``out`` (3N,) (accumulated, not zeroed) and return it.

    ``positions``, ``velocities`` (3N,) [m, m/s]; ``elements`` (E, 2) node pairs; ``rest_length``,
    ``stiffness``, ``damping``, ``rest_rate`` (E,) [m, N/m, N s/m, m/s] (dl0/dt: 0 but while a winch
    changes the cable's length).
    """
    u = np.empty(3)
    dv = np.empty(3)
    for e in range(elements.shape[0]):
        a, b = elements[e, 0], elements[e, 1]
        length, rate = _element_state(positions, velocities, a, b, u, dv)
        force, _, _ = tension_law(length - rest_length[e], rate - rest_rate[e], stiffness[e], damping[e],
                                  TAUT_BAND * rest_length[e])
        if force <= 0.0:
            continue
        for k in range(3):
            out[3 * a + k] += force * u[k]
            out[3 * b + k] -= force * u[k]
    return out


@njit(cache=True)
def tension_only_energy(positions, elements, rest_length, stiffness):
    """Elastic energy [J] of the elements: the potential of the undamped law, k int_0^s g(x) x dx.

    Zero at and below the rest length; inside the band (x = s / b, b = TAUT_BAND l0)
    k b^2 (3 x^4 / 4 - 2 x^5 / 5); above it k (s^2 - b^2) / 2 + 0.35 k b^2, 0.15 k b^2 more
    than Exudyn's spring energy k s^2 / 2. It does not see the damped law's cut-off.
    """
    energy = 0.0
    for e in range(elements.shape[0]):
        a, b = elements[e, 0], elements[e, 1]
        length2 = 0.0
        for k in range(3):
            d = positions[3 * b + k] - positions[3 * a + k]
            length2 += d * d
        extension = np.sqrt(length2) - rest_length[e]
        if extension <= 0.0:
            continue
        band = TAUT_BAND * rest_length[e]
        if extension >= band:
            energy += stiffness[e] * (0.5 * (extension * extension - band * band) + 0.35 * band * band)
        else:
            x = extension / band
            energy += stiffness[e] * band * band * x ** 4 * (0.75 - 0.4 * x)
    return energy


@njit(cache=True)
def tension_only_triplet_values(positions, velocities, elements, rest_length, stiffness, damping, rest_rate,
                                factor_position, factor_velocity, out_values, cut_slopes=False):
    """``factor_position * K + factor_velocity * D`` (K = -df/dq, D = -df/dv) at
    :func:`~cdpr_exu.physics.sparse_blocks.block_pattern`'s places; overwrites ``out_values`` (36 E,).
    With ``cut_slopes`` a damper-cut element keeps its taut slopes (:func:`cdpr_exu.physics.axial.newton_slopes`)."""
    out_values[:] = 0.0
    u = np.empty(3)
    dv = np.empty(3)
    for e in range(elements.shape[0]):
        length, rate = _element_state(positions, velocities, elements[e, 0], elements[e, 1], u, dv)
        force, k, c = newton_slopes(length - rest_length[e], rate - rest_rate[e], stiffness[e], damping[e],
                                    TAUT_BAND * rest_length[e], cut_slopes)
        if k == 0.0 and c == 0.0:
            continue
        for i in range(3):
            for j in range(3):
                w_j = (dv[j] - u[j] * rate) / length
                projector = (1.0 if i == j else 0.0) - u[i] * u[j]
                g = u[i] * (k * u[j] + c * w_j) + force * projector / length
                value = factor_position * g + factor_velocity * c * u[i] * u[j]
                base = 36 * e + 6 * i + j
                out_values[base] = value  # (a, a)
                out_values[base + 21] = value  # (b, b): 3 rows and 3 columns on
                out_values[base + 3] = -value  # (a, b)
                out_values[base + 18] = -value  # (b, a)
    return out_values

