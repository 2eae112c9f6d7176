"""A spatial cable over a swivel pulley in Exudyn.

:func:`add_swivel_pulley` adds, to a chain of :func:`cdpr_exu.builder.chain_3d.add_spatial_chain`,
the swivel coordinate psi [rad] (a ``NodeGenericODE2`` with one coordinate) and one
``ObjectGenericODE2`` over the chain's nodes and psi that carries the swivel's inertia
J_s (its mass matrix), its bearing damping d_s and the contact of
:mod:`cdpr_exu.physics.swivel_pulley`, with the sparse analytic Jacobian (psi rows and
columns included). :func:`cdpr_exu.run.dynamics.run_swivel_pendulum` is the measured scene: a
mass on a cable over the pulley, swinging around the axis. Units SI; z up.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import exudyn as exu
import exudyn.itemInterface as eii
import numpy as np

from cdpr_exu.physics import swivel_pulley as sp
from cdpr_exu.builder.chain_3d import SpatialChainItems, generic_state


@dataclass
class SwivelItems:
    """Item indices of a swivel pulley in Exudyn: the ``NodeGenericODE2`` ``node`` of psi, the
    ``ObjectGenericODE2`` ``obj`` over the chain's nodes and psi, ``psi_reference`` [rad] (Exudyn's
    coordinate is the displacement from it), the ``contact_nodes`` (C,) that can touch the pulley;
    ``user_functions`` keeps the Python callables alive as long as the model."""

    node: int
    obj: int
    psi_reference: float
    contact_nodes: np.ndarray
    user_functions: tuple = field(default_factory=tuple)


def _sparse(triplets, size):
    container = exu.MatrixContainer()
    container.SetWithSparseMatrix(np.asarray(triplets, dtype=float).reshape(-1, 3), numberOfRows=size,
                                  numberOfColumns=size, useDenseMatrix=False)
    return container


def add_swivel_pulley(mbs: exu.MainSystem, chain: SpatialChainItems, pulley: sp.SwivelPulley, psi: float = 0.0,
                      psi_rate: float = 0.0, contact_nodes=None) -> SwivelItems:
    """Add a swivel pulley under the nodes of ``chain``.

    ``psi``, ``psi_rate`` [rad, rad/s]: the initial swivel angle and rate; ``contact_nodes`` (C,):
    the chain nodes (0-based) that can touch the pulley, all by default.
    """
    n_points = len(chain.nodes)
    nodes = (np.arange(n_points) if contact_nodes is None else np.asarray(contact_nodes)).astype(np.int64)
    size = 3 * n_points + 1
    last = size - 1
    psi_node = mbs.AddNode(eii.NodeGenericODE2(numberOfODE2Coordinates=1, referenceCoordinates=[float(psi)],
                                                initialCoordinates=[0.0], initialCoordinates_t=[float(psi_rate)]))
    inlet = pulley.inlet_array
    args = (nodes, inlet, pulley.radius, pulley.groove_radius, pulley.flange_height, pulley.contact_stiffness,
            pulley.contact_damping, pulley.onset_band)
    reference = chain.reference
    positions = np.zeros(3 * n_points)
    velocities = np.zeros(3 * n_points)
    force = np.zeros(size)
    rows, columns = sp.swivel_contact_pattern(nodes, size)
    triplets = np.zeros((rows.size + 1, 3))
    triplets[:-1, 0], triplets[:-1, 1] = rows, columns
    triplets[-1, :2] = last
    values = np.zeros(rows.size)
    container = exu.MatrixContainer()
    bearing = pulley.bearing_damping
    psi_reference = float(psi)

    where = []

    def _state(mbs_, item):
        q, q_t = generic_state(mbs_, item, where)
        np.add(reference, q[:last], out=positions)
        velocities[:] = q_t[:last]
        return psi_reference + q[last], q_t[last]

    def force_function(mbs_, t, item, q, q_t):  # noqa: ARG001 - Exudyn's signature
        angle, rate = _state(mbs_, item)
        force[:] = 0.0
        sp.swivel_contact_force(positions, velocities, angle, rate, *args, force)
        force[last] -= bearing * rate
        return force.tolist()  # a list crosses into Exudyn faster than an array

    def jacobian_function(mbs_, t, item, q, q_t, f_q, f_q_t):  # noqa: ARG001
        angle, rate = _state(mbs_, item)
        triplets[:-1, 2] = sp.swivel_contact_values(positions, velocities, angle, rate, *args, float(f_q),
                                                    float(f_q_t), values)
        triplets[-1, 2] = float(f_q_t) * bearing
        container.SetWithSparseMatrix(triplets, numberOfRows=size, numberOfColumns=size, useDenseMatrix=False)
        return container

    mass = _sparse([[last, last, pulley.swivel_inertia]], size)
    obj = mbs.AddObject(eii.ObjectGenericODE2(nodeNumbers=list(chain.nodes) + [psi_node], massMatrix=mass,
                                               forceUserFunction=force_function,
                                               jacobianUserFunction=jacobian_function))
    return SwivelItems(psi_node, obj, psi_reference, nodes, (force_function, jacobian_function, container, mass))


def swivel_energy(items: SwivelItems, chain: SpatialChainItems, pulley: sp.SwivelPulley, q_chain: np.ndarray,
                  psi_displacement: float, psi_rate: float) -> float:
    """Energy [J] the swivel adds: contact potential and J_s psi_dot^2 / 2 (q_chain: displacements (3N,))."""
    positions = chain.reference + q_chain
    potential = sp.swivel_contact_energy(positions, items.psi_reference + psi_displacement, items.contact_nodes,
                                         pulley.inlet_array, pulley.radius, pulley.groove_radius,
                                         pulley.flange_height, pulley.contact_stiffness, pulley.onset_band)
    return potential + 0.5 * pulley.swivel_inertia * psi_rate**2
