"""Pulley rim contact on cable nodes, with a smooth onset: numba kernels.

A node at p within the disc of a pulley (centre c, radius r) is pushed out along the
outward normal n = (p - c) / d, d = |p - c|, with the normal force

    F = S(delta / b) * max(0, k_p delta + c_p delta_t),   delta = r - d,  delta_t = -n . v,

where S(x) = x^2 (3 - 2 x) on [0, 1] (1 beyond) switches the contact on over a
penetration band b (:data:`CONTACT_ONSET_DEPTH`). This is the law of the tension-only
elements (:func:`cdpr_exu.physics.axial.tension_law`, with the penetration as the extension),
and, for b -> 0, the law of Exudyn's ``ObjectContactSphereSphere`` (contact model "node"):
spring and damper in compression, never pulling the node into the pulley.

Measured (``benchmarks/bench_contact_models.py``, docs/accuracy.md), this smooth force does
not beat Exudyn's contact items, which freeze the contact status within Newton's iteration:
the contact is stiff (omega h = 200 on the paper circle at 1e-2 s), and an iteration that
starts outside the disc overshoots deep into it. So ``pulley_contact_model = "node_smooth"``
is an option, not the default. The Jacobian is analytic (2 x 2 per node, sparse triplets).

:class:`FrozenNodeContact` is the default "node" contact: the law of Exudyn's
``ObjectContactSphereSphere`` (linear, impact model 0, no friction), F = k_p (r_p + r_n - d) +
c_p delta_t, on wherever the gap d - r_p - r_n of the last switch is negative, even if the
node has left the disc since (it may then pull); the switch (:meth:`FrozenNodeContact.switch`)
runs after each Newton solve, as Exudyn's PostNewtonStep, and returns its discontinuous error.

Coordinates are flat arrays ``x0, y0, x1, y1, ...`` [m, m/s] over a global node list; each
contact node carries its own pulley. This module does not import Exudyn.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from cdpr_exu.physics.sparse_blocks import block_pattern
from cdpr_exu.physics.axial import tension_law
from cdpr_exu.core.errors import SceneError
from cdpr_exu.core.validation import per_item, points_per_item, shown, whole_array

__all__ = ["CONTACT_ONSET_DEPTH", "FrozenNodeContact", "NodePulleyContact", "node_contact_force_kernel",
           "node_contact_triplet_values"]

#: Penetration [m] over which the contact force switches on (C1 smoothstep): a hundredth
#: of the 1 mm accuracy the accuracy study aims at.
CONTACT_ONSET_DEPTH = 1.0e-5

#: Below this distance from the centre [m] the normal is undefined (a node at the centre).
_MIN_DISTANCE = 1.0e-12


@njit(cache=True)
def _node_state(positions, velocities, node, cx, cy):
    """(d, nx, ny, vx, vy): distance from the centre, outward normal, node velocity."""
    rx = positions[2 * node] - cx
    ry = positions[2 * node + 1] - cy
    d = np.sqrt(rx * rx + ry * ry)
    if d <= _MIN_DISTANCE:
        return d, 0.0, 0.0, 0.0, 0.0
    return d, rx / d, ry / d, velocities[2 * node], velocities[2 * node + 1]


@njit(cache=True)
def _contact_law(positions, velocities, k, nodes, centers, radii, stiffness, damping, band, gaps):
    """(on, d, nx, ny, vx, vy, F, dF/d delta, dF/d delta_t) of contact k: the smooth law inside the disc
    (``gaps`` None), else the frozen law wherever gaps[k] < 0 (``radii`` then r_p + r_n)."""
    d, nx, ny, vx, vy = _node_state(positions, velocities, nodes[k], centers[k, 0], centers[k, 1])
    off = (False, d, nx, ny, vx, vy, 0.0, 0.0, 0.0)
    if d <= _MIN_DISTANCE:
        return off
    if gaps is not None:
        if gaps[k] >= 0.0:
            return off
        force = stiffness[k] * (radii[k] - d) - damping[k] * (nx * vx + ny * vy)
        return True, d, nx, ny, vx, vy, force, stiffness[k], damping[k]
    if d >= radii[k]:
        return off
    force, slope, viscous = tension_law(radii[k] - d, -(nx * vx + ny * vy), stiffness[k], damping[k], band)
    return True, d, nx, ny, vx, vy, force, slope, viscous


@njit(cache=True)
def node_contact_force_kernel(positions, velocities, nodes, centers, radii, stiffness, damping, band, out, gaps=None):
    """Add the rim-contact forces of ``nodes`` to ``out`` (2N,) [N] and return it (unchecked).

    ``positions``, ``velocities`` (2N,) [m, m/s]; ``nodes`` (C,) global indices, ``centers`` (C, 2) [m],
    ``radii``, ``stiffness``, ``damping`` (C,) [m, N/m, N s/m] and ``gaps`` as :class:`NodePulleyContact`'s.
    """
    for k in range(nodes.shape[0]):
        on, _, nx, ny, _, _, force, _, _ = _contact_law(positions, velocities, k, nodes, centers, radii, stiffness,
                                                         damping, band, gaps)
        if on:
            out[2 * nodes[k]] += force * nx
            out[2 * nodes[k] + 1] += force * ny
    return out


@njit(cache=True)
def _node_block(positions, velocities, k, nodes, centers, radii, stiffness, damping, band, gaps,
                factor_position, factor_velocity, block):
    """``factor_position * K + factor_velocity * D`` of contact k (2 x 2) into ``block``; False if no force.

    With F_e = dF/d delta and F_r = dF/d delta_t, P = I - n n^T:
    K = -df/dp = n (F_e n + F_r P v / d)^T - F P / d,   D = -df/dv = F_r n n^T.
    """
    on, d, nx, ny, vx, vy, force, slope, viscous = _contact_law(positions, velocities, k, nodes, centers, radii,
                                                                stiffness, damping, band, gaps)
    if not on or (force == 0.0 and slope == 0.0 and viscous == 0.0):
        return False
    n = (nx, ny)
    projected = (vx - (nx * vx + ny * vy) * nx, vy - (nx * vx + ny * vy) * ny)  # P v
    for i in range(2):
        for j in range(2):
            p_ij = (1.0 if i == j else 0.0) - n[i] * n[j]
            stiff = n[i] * (slope * n[j] + viscous * projected[j] / d) - force * p_ij / d
            block[i, j] = factor_position * stiff + factor_velocity * viscous * n[i] * n[j]
    return True


@njit(cache=True)
def node_contact_triplet_values(positions, velocities, nodes, centers, radii, stiffness, damping, band, gaps,
                                factor_position, factor_velocity, out_values):
    """Values of ``factor_position * K + factor_velocity * D`` at
    :func:`~cdpr_exu.physics.sparse_blocks.block_pattern`'s places (overwrites ``out_values``, shape (4 C,))."""
    out_values[:] = 0.0
    block = np.empty((2, 2))
    for k in range(nodes.shape[0]):
        if _node_block(positions, velocities, k, nodes, centers, radii, stiffness, damping, band, gaps,
                       factor_position, factor_velocity, block):
            for i in range(2):
                for j in range(2):
                    out_values[4 * k + 2 * i + j] = block[i, j]
    return out_values


@njit(cache=True)
def node_contact_jacobian_kernel(positions, velocities, nodes, centers, radii, stiffness, damping, band, gaps,
                                 factor_position, factor_velocity, out):
    """Add ``factor_position * K + factor_velocity * D`` (2N, 2N) of the contacts to the dense ``out`` (unchecked)."""
    block = np.empty((2, 2))
    for k in range(nodes.shape[0]):
        node = nodes[k]
        if _node_block(positions, velocities, k, nodes, centers, radii, stiffness, damping, band, gaps,
                       factor_position, factor_velocity, block):
            for i in range(2):
                for j in range(2):
                    out[2 * node + i, 2 * node + j] += block[i, j]
    return out


class NodePulleyContact:
    """Rim contacts of a set of nodes with their pulleys, validated once, for the hot path.

    ``n_nodes`` of all cables (coordinates (2 n_nodes,)); ``nodes`` (C,) global contact nodes;
    ``centers`` (2,) or (C, 2) [m]; ``radii`` r_p, ``stiffness`` k_p and ``damping`` c_p per node or
    scalars [m, N/m, N s/m]; ``band`` [m] the onset band b (0 gives the sharp law).
    """

    def __init__(self, n_nodes, nodes, centers, radii, stiffness, damping, band=CONTACT_ONSET_DEPTH):
        self.n_coordinates = 2 * int(n_nodes)
        self.nodes = np.ascontiguousarray(whole_array("nodes", nodes), dtype=np.int64).reshape(-1)
        count = self.nodes.size
        if count and (self.nodes.min() < 0 or self.nodes.max() >= int(n_nodes)):
            raise SceneError(f"nodes must lie in 0..{int(n_nodes) - 1}; got {self.nodes.min()}..{self.nodes.max()}")
        self.centers = points_per_item("centers", centers, count)
        self.radii = per_item("radii", radii, count, positive=True)
        self.stiffness = per_item("stiffness", stiffness, count)
        self.damping = per_item("damping", damping, count)
        band = float(band)
        if not np.isfinite(band) or band < 0.0:
            raise SceneError(f"band must be a finite length >= 0 [m]; got {shown(band)}")
        self.band = band
        self.gaps = None  # the frozen law's state (FrozenNodeContact); None: the smooth law

    def add_force(self, positions, velocities, out):
        """Add the contact forces (2 n_nodes,) [N] to ``out`` and return it."""
        return node_contact_force_kernel(positions, velocities, self.nodes, self.centers, self.radii,
                                         self.stiffness, self.damping, self.band, out, self.gaps)

    def add_jacobian(self, positions, velocities, factor_position, factor_velocity, out):
        """Add ``factor_position * K + factor_velocity * D`` (2 n_nodes, 2 n_nodes) to ``out``."""
        return node_contact_jacobian_kernel(positions, velocities, self.nodes, self.centers, self.radii,
                                            self.stiffness, self.damping, self.band, self.gaps, float(factor_position),
                                            float(factor_velocity), out)

    def triplet_pattern(self):
        """Rows and columns of the sparse Jacobian, shape (4 C,) each."""
        return block_pattern(self.nodes.reshape(-1, 1), 2)

    def triplet_values(self, positions, velocities, factor_position, factor_velocity, out_values):
        """Values at :meth:`triplet_pattern`'s places (overwrites ``out_values``)."""
        return node_contact_triplet_values(positions, velocities, self.nodes, self.centers, self.radii,
                                           self.stiffness, self.damping, self.band, self.gaps, float(factor_position),
                                           float(factor_velocity), out_values)


@njit(cache=True)
def switch_contacts(positions, nodes, centers, reach, stiffness, gaps):
    """Exudyn's PostNewtonStep of the frozen contacts: overwrite ``gaps`` (C,) [m] with the gaps at
    ``positions``; return the discontinuous error [N], the largest k_p |gap| of a node whose side of the rim
    changed (0 if none)."""
    error = 0.0
    for k in range(nodes.shape[0]):
        rx = positions[2 * nodes[k]] - centers[k, 0]
        ry = positions[2 * nodes[k] + 1] - centers[k, 1]
        gap = np.sqrt(rx * rx + ry * ry) - reach[k]
        if (gap > 0.0) != (gaps[k] > 0.0):
            error = max(error, abs(gap) * stiffness[k])
        gaps[k] = gap
    return error


#: Radius of the node "sphere" [m] of Exudyn's contact items, kept in the frozen law's reach r_p + r_n.
NODE_CONTACT_RADIUS = 1.0e-9


class FrozenNodeContact(NodePulleyContact):
    """Exudyn's sphere contact law on nodes with the contact state frozen within Newton's iteration (module
    docstring). ``gaps`` (C,) [m]: the gaps of the last switch, the state the forces read; the caller keeps
    them where the solver restores a rejected step's (Exudyn's data coordinates). ``radii`` hold the reach
    r_p + r_n (:data:`NODE_CONTACT_RADIUS`)."""

    def __init__(self, n_nodes, nodes, centers, radii, stiffness, damping):
        super().__init__(n_nodes, nodes, centers, radii, stiffness, damping, band=0.0)
        self.radii = self.radii + NODE_CONTACT_RADIUS
        self.gaps = np.zeros(self.nodes.size)

    def switch(self, positions, gaps) -> float:
        """Overwrite ``gaps`` (C,) [m], the last switch's, with those at ``positions`` (2 n_nodes,) [m]; return
        the discontinuous error [N] (:func:`switch_contacts`)."""
        return switch_contacts(positions, self.nodes, self.centers, self.radii, self.stiffness, gaps)
