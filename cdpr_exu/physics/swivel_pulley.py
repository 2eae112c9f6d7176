"""Swivel pulley of a spatial cable: node-on-disc contact with a turning disc, numba kernels.

A swivel pulley turns about the vertical axis (z up, gravity -z) through its cable inlet
point A; the winch side of the cable runs along that axis. One swivel coordinate psi
[rad] carries a disc of radius r_p whose plane contains the axis: its centre is

    C(psi) = A + r_p e_r(psi),   e_r = (cos psi, sin psi, 0),   n = (-sin psi, cos psi, 0),

so the inlet A is the same point of the disc for every psi, and nothing is singular on
the axis. In the disc's coordinates a node at x (r = x - A) has

    a = e_r . r - r_p   (in-plane horizontal offset from the centre),
    w = e_z . r         (in-plane vertical offset),
    s = n . r           (sideways offset from the disc plane),

with da/dpsi = s and ds/dpsi = -(a + r_p). Its distance from the centre within the disc
plane is d = sqrt(a^2 + w^2). The groove bottom is curved sideways (groove radius r_g)
and rises to flanks of height h:

    penetration  delta = r_p - d + g(s),   g(s) = h (1 - exp(-s^2 / (2 r_g h))),

g(s) ~ s^2 / (2 r_g) near the groove's middle, so the sideways force comes from the
contact force itself (a sideways spring switched on and off with contact is not
conservative, docs/spatial.md). The flanks of height h bound g, so that only nodes within h
of the rim can touch (an unbounded s^2 / (2 r_g) reaches nodes far below the rim).

The normal force is the planar node contact's law (:mod:`cdpr_exu.physics.node_contact`,
:func:`cdpr_exu.physics.axial.tension_law`): F = S(delta / b) max(0, k_p delta + c_p d(delta)/dt),
S a C1 smoothstep over the onset band b. With q = (x, y, z, psi) of one node and its
pulley, G = d delta / dq (4,), H = d^2 delta / dq^2 (4, 4):

    f = -F G,     K = -df/dq = F_e G G^T + F_r G (H qdot)^T + F H,     D = -df/dqdot = F_r G G^T,

F_e = dF/d delta, F_r = dF/d(d delta/dt). The psi entries of f, summed over the nodes,
are the contact's torque on the swivel [N m]. The elastic part derives from the
potential U = sum integral_0^delta F d delta (:func:`swivel_contact_energy`).

Flat arrays (x0, y0, z0, x1, ...) [m, m/s]; no Exudyn here (the builder is
:mod:`cdpr_exu.builder.swivel_chain`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from cdpr_exu.physics.axial import tension_law
from cdpr_exu.core.errors import CdprWarning, SceneError
from cdpr_exu.core.validation import non_negative, positive, shown, vector

__all__ = ["SAFE_ELEMENT_FRACTION", "SAFE_NEWTON_TOLERANCE", "SwivelPulley", "SwivelStabilityWarning",
           "stability_concerns", "swivel_contact_force", "swivel_contact_energy", "swivel_contact_pattern",
           "swivel_contact_values", "swivel_penetration", "exit_azimuth"]

#: Below this in-plane distance from the disc centre [m] the normal is undefined: no force.
_MIN_DISTANCE = 1.0e-12


@njit(cache=True)
def swivel_penetration(positions, node, psi, inlet, radius, groove_radius, flange_height, grad, hess):
    """Penetration delta [m] of one node, its gradient (4,) and, if ``hess`` is (4, 4), Hessian
    in (x, y, z, psi) of that node. Returns (delta, d); d = 0 (no derivatives) at the centre."""
    cp, sp = np.cos(psi), np.sin(psi)
    rx = positions[3 * node] - inlet[0]
    ry = positions[3 * node + 1] - inlet[1]
    rz = positions[3 * node + 2] - inlet[2]
    a = cp * rx + sp * ry - radius
    s = -sp * rx + cp * ry
    w = rz
    d = np.sqrt(a * a + w * w)
    u = s * s / (2.0 * groove_radius * flange_height)
    decay = np.exp(-u)
    g = flange_height * (1.0 - decay)
    delta = radius - d + g
    if d <= _MIN_DISTANCE:
        return delta, 0.0
    g1 = s / groove_radius * decay  # g'(s)
    g2 = decay / groove_radius * (1.0 - s * s / (groove_radius * flange_height))  # g''(s)
    ma, mw = a / d, w / d
    # d delta / d(a, s, w)
    da, ds, dw = -ma, g1, -mw
    # rows of d(a, s, w)/dq, q = (x, y, z, psi)
    ja = (cp, sp, 0.0, s)
    js = (-sp, cp, 0.0, -(a + radius))
    jw = (0.0, 0.0, 1.0, 0.0)
    for i in range(4):
        grad[i] = da * ja[i] + ds * js[i] + dw * jw[i]
    if hess.shape[0] == 4:
        # second derivatives of delta in (a, s, w): -(I - m m^T)/d in (a, w), g'' in s
        haa = -(1.0 - ma * ma) / d
        hww = -(1.0 - mw * mw) / d
        haw = ma * mw / d
        for i in range(4):
            for j in range(4):
                hess[i, j] = (haa * ja[i] * ja[j] + hww * jw[i] * jw[j] + haw * (ja[i] * jw[j] + jw[i] * ja[j])
                              + g2 * js[i] * js[j])
        # + d delta/da * d^2 a/dq^2 + d delta/ds * d^2 s/dq^2 (d^2 w/dq^2 = 0):
        # d^2 a / dx dpsi = n, d^2 a / dpsi^2 = -(a + r_p); d^2 s / dx dpsi = -e_r, d^2 s / dpsi^2 = -s
        n = (-sp, cp)
        e = (cp, sp)
        for i in range(2):
            cross = da * n[i] - ds * e[i]
            hess[i, 3] += cross
            hess[3, i] += cross
        hess[3, 3] += -da * (a + radius) - ds * s
    return delta, d


@njit(cache=True)
def swivel_contact_force(positions, velocities, psi, psi_rate, nodes, inlet, radius, groove_radius,
                         flange_height, stiffness, damping, band, out):
    """Add the contact forces on ``nodes`` and the torque on psi to ``out`` and return it.

    ``positions``, ``velocities`` (3N,) [m, m/s]; ``psi``, ``psi_rate`` [rad, rad/s]; ``nodes`` (C,) that
    can touch the pulley; ``inlet`` (3,) [m] and the rest as :class:`SwivelPulley`'s (``band`` its
    ``onset_band``). ``out`` (3N + 1,) [N, N m]: node forces, then the torque on psi; accumulated into.
    """
    grad = np.empty(4)
    no_hess = np.empty((0, 0))
    last = out.shape[0] - 1
    for k in range(nodes.shape[0]):
        node = nodes[k]
        delta, d = swivel_penetration(positions, node, psi, inlet, radius, groove_radius, flange_height,
                                      grad, no_hess)
        if delta <= 0.0 or d <= _MIN_DISTANCE:
            continue
        rate = (grad[0] * velocities[3 * node] + grad[1] * velocities[3 * node + 1]
                + grad[2] * velocities[3 * node + 2] + grad[3] * psi_rate)
        force = tension_law(delta, rate, stiffness, damping, band)[0]
        for i in range(3):
            out[3 * node + i] -= force * grad[i]
        out[last] -= force * grad[3]
    return out


@njit(cache=True)
def swivel_contact_energy(positions, psi, nodes, inlet, radius, groove_radius, flange_height, stiffness, band):
    """Elastic contact potential U = sum integral_0^delta S(x/b) k_p x dx [J] (damping aside)."""
    grad = np.empty(4)
    no_hess = np.empty((0, 0))
    energy = 0.0
    for k in range(nodes.shape[0]):
        delta, d = swivel_penetration(positions, nodes[k], psi, inlet, radius, groove_radius, flange_height,
                                      grad, no_hess)
        if delta <= 0.0:
            continue
        if delta < band:
            energy += stiffness * (0.75 * delta**4 / band**2 - 0.4 * delta**5 / band**3)
        else:
            energy += stiffness * (0.35 * band * band + 0.5 * (delta * delta - band * band))
    return energy


@njit(cache=True)
def swivel_contact_pattern(nodes, n_coordinates):
    """Rows and columns of the contact's sparse Jacobian: 16 per node over (x, y, z, psi),
    psi being coordinate ``n_coordinates - 1``; shape (16 C,) each."""
    rows = np.empty(16 * nodes.shape[0], dtype=np.int64)
    columns = np.empty(16 * nodes.shape[0], dtype=np.int64)
    last = n_coordinates - 1
    for k in range(nodes.shape[0]):
        for i in range(4):
            for j in range(4):
                rows[16 * k + 4 * i + j] = 3 * nodes[k] + i if i < 3 else last
                columns[16 * k + 4 * i + j] = 3 * nodes[k] + j if j < 3 else last
    return rows, columns


@njit(cache=True)
def swivel_contact_values(positions, velocities, psi, psi_rate, nodes, inlet, radius, groove_radius,
                          flange_height, stiffness, damping, band, factor_position, factor_velocity, out_values):
    """``factor_position * K + factor_velocity * D`` (K = -df/dq [N/m], D = -df/dqdot [N s/m], psi
    rows and columns included) at :func:`swivel_contact_pattern`'s places (overwrites ``out_values``)."""
    out_values[:] = 0.0
    grad = np.empty(4)
    hess = np.empty((4, 4))
    for k in range(nodes.shape[0]):
        node = nodes[k]
        delta, d = swivel_penetration(positions, node, psi, inlet, radius, groove_radius, flange_height, grad, hess)
        if delta <= 0.0 or d <= _MIN_DISTANCE:
            continue
        qdot = (velocities[3 * node], velocities[3 * node + 1], velocities[3 * node + 2], psi_rate)
        rate = grad[0] * qdot[0] + grad[1] * qdot[1] + grad[2] * qdot[2] + grad[3] * qdot[3]
        force, slope, viscous = tension_law(delta, rate, stiffness, damping, band)
        if force == 0.0 and slope == 0.0 and viscous == 0.0:
            continue
        hv = np.zeros(4)  # H qdot
        for i in range(4):
            for j in range(4):
                hv[i] += hess[i, j] * qdot[j]
        for i in range(4):
            for j in range(4):
                stiff = slope * grad[i] * grad[j] + viscous * grad[i] * hv[j] + force * hess[i, j]
                out_values[16 * k + 4 * i + j] = (factor_position * stiff
                                                  + factor_velocity * viscous * grad[i] * grad[j])
    return out_values


def exit_azimuth(point, inlet) -> float:
    """Azimuth [rad] of ``point`` (3,) [m] seen from the swivel axis through ``inlet`` (3,) [m]:
    the angle psi of the plane through the axis that contains it (ideal kinematics, Pott 2018)."""
    return math.atan2(point[1] - inlet[1], point[0] - inlet[0])


#: Full Newton held every measured run without the energy guard at this relative tolerance
#: or tighter (benchmarks/results/swivel_pulley.md); at 1e-8 and 1e-6, 4 of 24 runs gained.
SAFE_NEWTON_TOLERANCE = 1e-10

#: Longest element, as a fraction of the pulley radius, that full Newton was measured to
#: hold without the guard (0.5 held; 1.0 lost the wrap and gained 710 J at 5e-3 s steps).
SAFE_ELEMENT_FRACTION = 0.5


class SwivelStabilityWarning(CdprWarning):
    """A run over a swivel pulley is set up outside what was measured to hold without the
    energy guard; the message names the setting."""


def stability_concerns(modified_newton: bool, spectral_radius: float, newton_tolerance: float,
                       element_length: float, radius: float) -> list[str]:
    """Why a run without the energy guard lies outside the measured region, one message per setting
    (empty inside it; ``element_length``, ``radius`` [m]).

    Measured to hold (benchmarks/results/swivel_pulley.md, J_s 1e-6 to 1 kg m^2, d_s 0 to
    0.1 N m s, steps 5e-3 and 2e-3 s): full Newton at spectral radius <= 0.5, relative
    tolerance <= :data:`SAFE_NEWTON_TOLERANCE` and elements up to :data:`SAFE_ELEMENT_FRACTION`
    of the radius; and modified Newton at spectral radius 0 and tolerance 1e-6, with elements
    up to the radius. The messages say what was measured to gain energy.
    """
    concerns = []
    if spectral_radius > 0.5:
        concerns.append(f"spectral_radius = {spectral_radius:g} is above 0.5; at 1 even a planar hang over the "
                        "swivel pulley was measured to gain energy")
    if modified_newton:
        if spectral_radius > 0.0 or newton_tolerance > 1e-6 or element_length > radius:
            concerns.append("modified Newton was measured to hold at spectral_radius = 0, newton_tolerance <= 1e-6 "
                            f"and elements up to the pulley radius only; got {spectral_radius:g}, "
                            f"{newton_tolerance:g} and {element_length:g} m")
        return concerns
    if newton_tolerance > SAFE_NEWTON_TOLERANCE:
        concerns.append(f"newton_tolerance = {newton_tolerance:g} is looser than {SAFE_NEWTON_TOLERANCE:g}; with "
                        "full Newton, 4 of 24 runs over a swivel pulley were measured to gain energy at 1e-8 "
                        "and at 1e-6")
    if element_length > SAFE_ELEMENT_FRACTION * radius:
        concerns.append(f"element_length = {element_length:g} m is longer than {SAFE_ELEMENT_FRACTION:g} of the pulley "
                        f"radius ({radius:g} m); with full Newton such a run lost the wrap and gained energy")
    return concerns


@dataclass(frozen=True)
class SwivelPulley:
    """A swivel pulley: a grooved disc that turns about the vertical axis through its inlet.

    Parameters
    ----------
    inlet : (x, y, z) [m]
        Inlet point A on the swivel axis, at the height of the disc centre (see the module notes).
    radius, groove_radius, flange_height : float [m]
        Groove-bottom radius r_p of the disc, sideways curvature radius r_g of the groove bottom,
        height h of its flanks (nodes further than h from the rim never touch).
    contact_stiffness, contact_damping : float [N/m, N s/m]
        Penalty stiffness k_p and damping c_p on the penetration rate (0: none).
    swivel_inertia, bearing_damping : float [kg m^2, N m s]
        J_s of the turning part about the axis and the bearing's viscous torque d_s psi_dot.
    onset_band : float [m]
        Penetration over which contact switches on (C1 smoothstep).
    """

    inlet: tuple = (0.0, 0.0, 0.0)
    radius: float = 0.1
    groove_radius: float = 0.01
    flange_height: float = 0.01
    contact_stiffness: float = 1.0e6
    contact_damping: float = 0.0
    swivel_inertia: float = 1.0e-2
    bearing_damping: float = 1.0e-3
    onset_band: float = 1.0e-5

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        set_(self, "inlet", tuple(float(v) for v in vector("swivel.inlet", self.inlet, 3, " (x, y, z) [m]")))
        units = {"radius": "m", "groove_radius": "m", "flange_height": "m", "contact_stiffness": "N/m",
                 "swivel_inertia": "kg m^2", "contact_damping": "N s/m", "bearing_damping": "N m s", "onset_band": "m"}
        for name in ("radius", "groove_radius", "flange_height", "contact_stiffness", "swivel_inertia"):
            set_(self, name, positive(f"swivel.{name}", getattr(self, name), units[name]))
        for name in ("contact_damping", "bearing_damping", "onset_band"):
            set_(self, name, non_negative(f"swivel.{name}", getattr(self, name), units[name]))
        if self.groove_radius >= self.radius:
            raise SceneError(f"swivel.groove_radius must be smaller than swivel.radius = {shown(self.radius)}, "
                             f"got {shown(self.groove_radius)}")
        if self.flange_height >= self.radius:
            raise SceneError(f"swivel.flange_height must be smaller than swivel.radius = {shown(self.radius)}, "
                             f"got {shown(self.flange_height)}")

    @property
    def inlet_array(self) -> np.ndarray:
        """Inlet point A, shape (3,) [m]."""
        return np.asarray(self.inlet, dtype=float)


def cable_path_over_swivel(pulley: SwivelPulley, psi: float, winch_length: float, free_length: float,
                           free_angle: float, element_length: float) -> np.ndarray:
    """Nodes of a cable over a swivel pulley, equally spaced along the path, shape (N, 3) [m].

    The path comes up the axis from ``winch_length`` [m] below the inlet, wraps over the
    top of the disc at azimuth ``psi`` [rad] on the groove bottom, and leaves it tangentially
    for ``free_length`` [m] at ``free_angle`` [rad] from the downward vertical (away from
    the axis). Nodes are ``element_length`` [m] apart along the path (rounded to fit).
    """
    radius = pulley.radius
    wrap = math.pi - free_angle
    if not 0.0 < wrap <= math.pi:
        raise SceneError(f"free_angle must lie in [0, pi) [rad], got {shown(free_angle)}")
    inlet = pulley.inlet_array
    e_r = np.array([math.cos(psi), math.sin(psi), 0.0])
    e_z = np.array([0.0, 0.0, 1.0])
    total = winch_length + radius * wrap + free_length
    count = max(2, int(round(total / element_length)))
    points = []
    for arc in np.linspace(0.0, total, count + 1):
        if arc <= winch_length:
            points.append(inlet - (winch_length - arc) * e_z)
        elif arc <= winch_length + radius * wrap:
            phi = (arc - winch_length) / radius
            points.append(inlet + radius * e_r + radius * (-math.cos(phi) * e_r + math.sin(phi) * e_z))
        else:
            exit_point = inlet + radius * e_r + radius * (-math.cos(wrap) * e_r + math.sin(wrap) * e_z)
            direction = math.sin(free_angle) * e_r - math.cos(free_angle) * e_z
            points.append(exit_point + (arc - winch_length - radius * wrap) * direction)
    return np.array(points)
