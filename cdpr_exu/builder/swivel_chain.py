"""A spatial cable over a swivel pulley in Exudyn.

:func:`add_swivel_pulley` adds, to a chain of :func:`cdpr_exu.builder.chain_3d.add_spatial_chain`,
the swivel coordinate psi [rad] (a ``NodeGenericODE2`` with one coordinate); the chain's
:class:`~cdpr_exu.builder.chain_3d.ChainForces`, made after it with the swivel, carries the swivel's
inertia J_s (its mass matrix), its bearing damping d_s and the contact of
:mod:`cdpr_exu.physics.swivel_pulley`, with the sparse analytic Jacobian (psi rows and columns
included), in the chains' one force call. :func:`cdpr_exu.run.dynamics.run_swivel_pendulum` is the
measured scene: a mass on a cable over the pulley, swinging around the axis. Units SI; z up.
"""

from __future__ import annotations

from dataclasses import dataclass

import exudyn as exu
import exudyn.itemInterface as eii
import numpy as np

from cdpr_exu.physics import swivel_pulley as sp
from cdpr_exu.builder.chain_3d import SpatialChainItems


@dataclass
class SwivelItems:
    """A swivel pulley in Exudyn: the ``NodeGenericODE2`` ``node`` of psi, ``psi_reference`` [rad] (Exudyn's
    coordinate is the displacement from it), the ``contact_nodes`` (C,) of ``chain`` that can touch the
    ``pulley`` (its forces are the ``ChainForces`` given this swivel)."""

    node: int
    psi_reference: float
    contact_nodes: np.ndarray
    chain: SpatialChainItems
    pulley: sp.SwivelPulley


def add_swivel_pulley(mbs: exu.MainSystem, chain: SpatialChainItems, pulley: sp.SwivelPulley, psi: float = 0.0,
                      psi_rate: float = 0.0, contact_nodes=None) -> SwivelItems:
    """Add a swivel pulley's angle under the nodes of ``chain``; give it to the chain's ``ChainForces``.

    ``psi``, ``psi_rate`` [rad, rad/s]: the initial swivel angle and rate; ``contact_nodes`` (C,):
    the chain nodes (0-based) that can touch the pulley, all by default.
    """
    nodes = np.arange(len(chain.nodes)) if contact_nodes is None else np.asarray(contact_nodes)
    psi_node = mbs.AddNode(eii.NodeGenericODE2(numberOfODE2Coordinates=1, referenceCoordinates=[float(psi)],
                                                initialCoordinates=[0.0], initialCoordinates_t=[float(psi_rate)]))
    return SwivelItems(psi_node, float(psi), nodes.astype(np.int64), chain, pulley)


def swivel_energy(items: SwivelItems, q_chain: np.ndarray, psi_displacement: float, psi_rate: float) -> float:
    """Energy [J] the swivel adds: contact potential and J_s psi_dot^2 / 2 (q_chain: its chain's displacements
    (3N,) [m])."""
    pulley = items.pulley
    positions = items.chain.reference + q_chain
    potential = sp.swivel_contact_energy(positions, items.psi_reference + psi_displacement, items.contact_nodes,
                                         pulley.inlet_array, pulley.radius, pulley.groove_radius,
                                         pulley.flange_height, pulley.contact_stiffness, pulley.onset_band)
    return potential + 0.5 * pulley.swivel_inertia * psi_rate**2
